"""Config composition and validation: every failure is one ConfigError line naming the key."""

from __future__ import annotations

import pytest

from efish.config import ConfigError, EfishConfig, compose, config_dir, to_yaml, validate
from efish.config.schema import (
    AnalysisConfig,
    ArenaConfig,
    AssayConfig,
    BenchConfig,
    EnvConfig,
    PhysicsConfig,
    ScaleConfig,
    SceneConfig,
    SensorsConfig,
    TrainConfig,
)

from ..helpers import cfg_with


def test_default_config_matches_the_spec(default_cfg):
    ph, se = default_cfg.physics, default_cfg.sensors
    assert isinstance(default_cfg, EfishConfig)
    assert ph.eps0 == 8.854e-12 and ph.eod_charge_c == 1.11e-15 and ph.eod_half_separation_cm == 0.5
    assert ph.agent_dipole_coulomb_metre == 1.11e-23 and ph.pellet_dipole_coulomb_metre == 1.11e-24
    assert ph.susceptibility == -0.5 and ph.agent_radius_cm == 1.0 and ph.pellet_radius_cm == 0.25
    assert ph.softening_m == 1e-5 and ph.image_order == 1 and ph.image_scale == 0.95
    assert (se.mormyromast.count, se.ampullary.count, se.knollenorgan.count) == (36, 24, 12)
    assert (se.mormyromast.e_min, se.mormyromast.e_max) == (5e-8, 5e-2)
    assert (se.ampullary.e_min, se.ampullary.e_max) == (2e-10, 2e-8)
    assert se.knollenorgan.threshold == 2e-7
    assert (se.mormyromast.g_self, se.mormyromast.g_cons, se.mormyromast.k_cons) == (1.0, 1.0, 100.0)
    assert not se.mormyromast.wall_distortion
    assert (se.noise.low, se.noise.high, se.noise.interference_low, se.noise.interference_high) == (0.95, 1.05, 0.0, 2.0)


def test_the_foraging_recipe_trains_in_the_papers_sampled_arenas(default_cfg):
    """policy=foraging (what efish train composes first) replaces the default assay's 70 x 70 patchy arena by the
    paper's training distribution (docs/model/environment.md#arenas-and-food): sides 40 + 260 u^3 cm,
    patchy : uniform 5 : 1, food multiplier log-uniform in 0.5-2."""
    assert default_cfg.arena.layout == "patchy"
    a = compose(["policy=foraging"]).arena
    assert a.layout == "training"
    assert (a.train_size_min_cm, a.train_size_span_cm, a.train_size_exponent) == (40.0, 260.0, 3.0)
    assert (a.train_patchy_weight, a.train_uniform_weight, a.train_none_weight) == (5.0, 1.0, 0.0)
    assert (a.train_multiplier_min, a.train_multiplier_max) == (0.5, 2.0)


def test_overrides_are_applied():
    cfg = cfg_with("physics.image_order=2", "sensors.knollenorgan.enabled=false", "physics.dtype=float32")
    assert cfg.physics.image_order == 2 and not cfg.sensors.knollenorgan.enabled
    assert cfg.physics.dtype == "float32"


def test_to_yaml_round_trips_the_values(default_cfg):
    text = to_yaml(default_cfg)
    assert "image_order: 1" in text and "threshold: 2.0e-07" in text


def one_line_error(overrides) -> str:
    with pytest.raises(ConfigError) as info:
        compose(overrides)
    msg = str(info.value)
    assert "\n" not in msg and msg.strip() == msg and msg
    return msg


@pytest.mark.parametrize("override, key", [
    ("physics.bogus=1", "physics.bogus"),
    ("sensors.mormyromast.bogus=3", "sensors.mormyromast.bogus"),
    ("nonsense=1", "nonsense"),
])
def test_unknown_key(override, key):
    msg = one_line_error([override])
    assert key in msg and "unknown" in msg


@pytest.mark.parametrize("override, key", [
    ("physics.image_order=5", "physics.image_order"),
    ("physics.image_order=-1", "physics.image_order"),
    ("physics.softening_m=-1", "physics.softening_m"),
    ("physics.image_scale=1.5", "physics.image_scale"),
    ("env.n_agents=0", "env.n_agents"),
    ("sensors.mormyromast.count=0", "sensors.mormyromast.count"),
])
def test_out_of_range_value(override, key):
    msg = one_line_error([override])
    assert key in msg and "range" in msg


@pytest.mark.parametrize("override, key", [
    ("physics.image_order=abc", "physics.image_order"),
    ("physics.tolerance=abc", "physics.tolerance"),
    ("physics.emission=maybe", "physics.emission"),
    ("sensors.noise.low=[1,2]", "sensors.noise.low"),
])
def test_bad_type(override, key):
    msg = one_line_error([override])
    assert key in msg


@pytest.mark.parametrize("override, key", [
    ("physics.dtype=float16", "physics.dtype"),
    ("sensors.perception=sonar", "sensors.perception"),
    ("sensors.mormyromast.g_self=0.5", "sensors.mormyromast.g_self"),
    ("env.task=hunting", "env.task"),
])
def test_bad_choice(override, key):
    msg = one_line_error([override])
    assert key in msg and "allowed" in msg


@pytest.mark.parametrize("overrides, key", [
    (["sensors.mormyromast.e_min=1"], "sensors.mormyromast.e_min"),
    (["sensors.ampullary.e_max=1e-12"], "sensors.ampullary.e_min"),
    (["sensors.mormyromast.chin_count=40"], "sensors.mormyromast.chin_count"),
    (["sensors.noise.low=1.2"], "sensors.noise.low"),
])
def test_inconsistent_values(overrides, key):
    assert key in one_line_error(overrides)


def test_missing_config_group_option_is_one_line():
    msg = one_line_error(["arena=nope"])
    assert "arena" in msg


def test_validate_names_the_key_of_a_mutated_tree(default_cfg):
    from copy import deepcopy
    cfg = deepcopy(default_cfg)
    cfg.sensors.ampullary.count = 0
    with pytest.raises(ConfigError, match=r"sensors\.ampullary\.count"):
        validate(cfg)


def test_config_error_is_a_value_error():
    assert issubclass(ConfigError, ValueError)


GROUPS = {"physics": PhysicsConfig, "sensors": SensorsConfig, "arena": ArenaConfig, "env": EnvConfig,
          "train": TrainConfig, "assay": AssayConfig, "bench": BenchConfig, "scale": ScaleConfig,
          "analysis": AnalysisConfig, "scene": SceneConfig}


def _leaves(node, prefix=""):
    """(dotted key, value) of every leaf of a YAML mapping, interpolations unresolved."""
    for key, value in node.items():
        if isinstance(value, dict):
            yield from _leaves(value, f"{prefix}{key}.")
        else:
            yield f"{prefix}{key}", value


def _default(group: str, key: str):
    obj = GROUPS[group]()
    for part in key.split("."):
        obj = getattr(obj, part)
    return obj


@pytest.mark.parametrize("path", sorted(config_dir().glob("*/*.yaml")), ids=lambda p: f"{p.parent.name}/{p.name}")
def test_yaml_files_set_only_what_differs_from_the_schema(path):
    """One copy of every default: the dataclasses hold them; a YAML value equal to its default is a second copy.

    An assay file's own ``assay:`` block is exempt: it describes that assay in
    full (episodes, seed, policy) so a reader sees the protocol in one place.
    """
    import yaml

    data = yaml.safe_load(path.read_text()) or {}
    data.pop("defaults", None)
    package_global = path.read_text().startswith("# @package _global_")
    roots = data.items() if package_global else [(path.parent.name, data)]
    for group, node in roots:
        if path.parent.name == "assay" and group == "assay":
            continue
        for key, value in _leaves(node):
            if isinstance(value, str) and value.startswith("${"):
                continue  # an interpolation: read from another group, not a copy
            assert value != _default(group, key), f"{path.name}: {group}.{key}={value!r} repeats the schema default"


@pytest.mark.parametrize("assay", ["mute", "npatch", "homing", "bot"])
def test_compose_variants_equals_composing_each_condition_in_full(assay):
    from efish.config.compose import compose_variants

    base = compose([f"assay={assay}", "scale=smoke"])
    fast = compose_variants([f"assay={assay}", "scale=smoke"])
    assert list(fast) == list(base.assay.conditions)
    for name, extra in base.assay.conditions.items():
        assert to_yaml(fast[name]) == to_yaml(compose([f"assay={assay}", "scale=smoke", *extra])), name


def test_a_bad_variant_is_one_line_naming_it():
    from efish.config.compose import compose_variants

    with pytest.raises(ConfigError, match=r"^condition x: unknown config key 'env.nonsense'$"):
        compose_variants(["assay=mute"], {"x": ["env.nonsense=1"]}, label="condition")


def test_the_compose_cache_serves_equal_configs_and_follows_every_edit_of_the_tree(tmp_path, monkeypatch):
    import importlib
    import shutil

    composer = importlib.import_module("efish.config.compose")  # the module; efish.config.compose is the function

    tree = tmp_path / "config"
    shutil.copytree(composer.config_dir(), tree)
    monkeypatch.setenv("EFISH_CONFIG_DIR", str(tree))
    monkeypatch.setenv("EFISH_CACHE_DIR", str(tmp_path / "cache"))
    first = composer.compose(["scale=smoke"])
    assert list((tmp_path / "cache" / "compose").glob("*.pkl"))  # kept on disk
    again = composer.compose(["scale=smoke"])
    assert again == first and again is not first  # a fresh object: callers may change it
    smoke = tree / "scale" / "smoke.yaml"
    assert "\n  seeds: 2\n" in smoke.read_text()
    smoke.write_text(smoke.read_text().replace("\n  seeds: 2\n", "\n  seeds: 7\n"))
    edited = composer.compose(["scale=smoke"])
    assert edited.scale.seeds == 7 and first.scale.seeds != 7  # an edit of the tree gives a new key
    monkeypatch.setenv("EFISH_CACHE_DIR", "off")
    assert composer.cache_folder() is None and composer.compose(["scale=smoke"]).scale.seeds == 7
    monkeypatch.delenv("EFISH_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))  # without it: beside numba's kernels
    assert composer.cache_folder() == tmp_path / "xdg" / "efish" / "compose"


def test_the_compose_cache_is_keyed_by_the_schema_this_process_loaded(tmp_path, monkeypatch):
    """A process started before schema.py was edited builds configs of the schema it loaded: its entries carry the
    digest of the sources it imported, so a process of the edited schema never reads them (and the reverse)."""
    import importlib

    composer = importlib.import_module("efish.config.compose")
    monkeypatch.setenv("EFISH_CACHE_DIR", str(tmp_path / "cache"))
    composer.compose(["scale=smoke"])
    entries = set((tmp_path / "cache" / "compose").glob("*.pkl"))
    assert len(entries) == 1
    monkeypatch.setattr(composer, "_SOURCES_DIGEST", "the digest of another schema")
    composer.compose(["scale=smoke"])
    assert len(set((tmp_path / "cache" / "compose").glob("*.pkl"))) == 2  # composed afresh under its own key


# ------------------------------------------------------------------ renamed keys (one release of the old names)
@pytest.mark.parametrize(("old", "new", "value"), [("agent_dipole_cm", "agent_dipole_coulomb_metre", 2.5e-23),
                                                   ("pellet_dipole_cm", "pellet_dipole_coulomb_metre", 3e-24)])
def test_a_deprecated_key_on_the_command_line_warns_and_sets_the_new_one(old, new, value):
    for _ in range(2):  # the second composition is served from the cache and warns all the same
        with pytest.warns(FutureWarning, match=rf"^physics\.{old} is deprecated .* set physics\.{new} instead$"):
            cfg = compose([f"physics.{old}={value}"])
        assert getattr(cfg.physics, new) == value and getattr(cfg.physics, old) is None


def test_a_deprecated_key_in_a_yaml_file_warns_and_sets_the_new_one(tmp_path, monkeypatch):
    import shutil

    tree = tmp_path / "config"
    shutil.copytree(config_dir(), tree)
    (tree / "physics" / "old_names.yaml").write_text("agent_dipole_cm: 2.0e-23\n")
    monkeypatch.setenv("EFISH_CONFIG_DIR", str(tree))
    with pytest.warns(FutureWarning, match="physics.agent_dipole_coulomb_metre"):
        cfg = compose(["physics=old_names"])
    assert cfg.physics.agent_dipole_coulomb_metre == 2.0e-23


def test_a_deprecated_key_in_an_assay_condition_sets_the_new_one():
    from efish.config.compose import compose_variants

    with pytest.warns(FutureWarning, match="physics.pellet_dipole_coulomb_metre"):
        cfgs = compose_variants(["assay=mute"], {"old": ["physics.pellet_dipole_cm=4e-24"], "plain": []})
    assert cfgs["old"].physics.pellet_dipole_coulomb_metre == 4e-24
    assert cfgs["plain"].physics.pellet_dipole_coulomb_metre == PhysicsConfig().pellet_dipole_coulomb_metre


def test_a_deprecated_key_and_its_new_name_together_are_one_error():
    with pytest.raises(ConfigError, match=r"^physics\.agent_dipole_cm and physics\.agent_dipole_coulomb_metre are "
                                          r"both set: .*; set only physics\.agent_dipole_coulomb_metre$"):
        compose(["physics.agent_dipole_cm=2e-23", "physics.agent_dipole_coulomb_metre=3e-23"])


def test_a_config_recorded_under_the_old_names_reads_back_under_the_new(default_cfg):
    """conditions.parquet of a run before the rename holds physics.agent_dipole_cm; a checkpoint's training config
    too, and it still resumes (rl.train compares it under the current names)."""
    import dataclasses
    import json

    from efish.config.recorded import config_json, from_json
    from efish.config.schema import config_differences, training_config, with_current_key_names

    record = json.loads(config_json(default_cfg))
    physics = record["physics"]
    physics["agent_dipole_cm"] = physics.pop("agent_dipole_coulomb_metre") * 2
    physics.pop("pellet_dipole_coulomb_metre")
    physics.pop("pellet_dipole_cm")
    with pytest.warns(FutureWarning, match="physics.agent_dipole_coulomb_metre"):
        cfg = from_json(json.dumps(record))
    assert cfg.physics.agent_dipole_coulomb_metre == 2.22e-23
    assert cfg.physics.pellet_dipole_coulomb_metre == PhysicsConfig().pellet_dipole_coulomb_metre

    old_checkpoint = training_config(EfishConfig())
    old_physics = old_checkpoint["physics"]
    old_physics["agent_dipole_cm"] = old_physics.pop("agent_dipole_coulomb_metre")
    old_physics["pellet_dipole_cm"] = old_physics.pop("pellet_dipole_coulomb_metre")
    assert config_differences(old_checkpoint, training_config(EfishConfig()))  # as recorded: names differ
    assert not config_differences(with_current_key_names(old_checkpoint), training_config(EfishConfig()))
    assert dataclasses.asdict(EfishConfig())["physics"]["agent_dipole_cm"] is None
