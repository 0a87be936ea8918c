"""The senses registry: every spelling of a sense comes from it, and the tables and configs agree with it."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from efish.config.schema import EfishConfig
from efish.rollout.schema import COLUMNS
from efish.senses import SENSES, condition_name, error_column, sense

REPO = Path(__file__).resolve().parents[1]


def test_each_spelling_names_one_sense_and_reads_back():
    spellings = [v for s in SENSES for v in (s.name, s.short, s.letter)]
    assert len(spellings) == len(set(spellings)) == 3 * len(SENSES)
    for s in SENSES:
        assert sense(s.name) is sense(s.short) is sense(s.letter) is s
    with pytest.raises(KeyError, match="no sense is spelt 'lateral_line'"):
        sense("lateral_line")


def test_every_sense_is_a_config_group_and_records_its_error_column():
    sensors = EfishConfig().sensors
    assert all(hasattr(sensors, s.name) for s in SENSES)
    steps = {name for name, *_ in COLUMNS["steps"]}
    assert {error_column(s) for s in SENSES} <= steps


def test_the_ablation_assays_conditions_are_named_as_the_registry_names_them():
    """Each condition of ablation4 turns off the senses its name leaves out, and its name is the registry's."""
    conditions = yaml.safe_load((REPO / "config/assay/ablation4.yaml").read_text())["assay"]["conditions"]
    for name, overrides in conditions.items():
        off = {o.split(".")[1] for o in overrides if o.endswith(".enabled=false")}
        assert condition_name(s for s in SENSES if s.name not in off) == name
    assert condition_name(SENSES) == "M_A_K" and condition_name([]) == "none"
