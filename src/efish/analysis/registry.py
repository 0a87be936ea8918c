"""Every analysis ``efish analyze`` runs: the rollout tables it reads, the assays it belongs to, the tables it writes.

The workflow reads :data:`ANALYSES` to make one job per (analysis, assay of
the scale), writing ``results/{run}/analysis/<analysis>/<assay>/<table>.parquet``;
adding an analysis means one compute function and one entry here. An analysis
reads two things only: the assay's record, its rollout tables with the
conditions it recorded (``conditions.parquet``, read back by
:func:`efish.config.recorded.recorded_conditions`: each condition's frame rate
``env.fps`` for ms per step and rates in Hz, its arena for the one-patch
centre, its roles, which condition is the control), and the analysis settings
of the job (``cfg.analysis``, which ``efish analyze`` records beside the tables
as ``analysis_settings.parquet``); never a config composed afresh. Each compute
function passes their values to the pure functions of the ``efish.analysis``
modules; a statistic table (:attr:`Analysis.stats`) carries the columns of
:data:`efish.analysis.stats.STAT_COLUMNS`. A table whose input columns the
rollout tables lack (a run recorded before a column existed) is one NaN row
whose ``reason`` names them, so every declared table is always written.

>>> [a.name for a in analyses_for("homing", tables_written(AssayConfig(name="homing")))]
['homing']
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..config.recorded import recorded_conditions, step_rates
from ..config.schema import AnalysisConfig, AssayConfig, EfishConfig
from ..io import read_parquet
from ..layout import ANALYSIS_SETTINGS, ROLLOUT_TABLES
from ._tables import EPISODE, nan_frame, or_nan_row, require
from .behaviour import (
    bite_matrix,
    eod_probability,
    episode_summary,
    food_per_agent_episode,
    food_time_course,
    food_vs_size,
    nearest_neighbour,
    reach_rates,
    theil_per_episode,
    win_ratios,
)
from .decoding import decode_episodes, food_decode_episodes, summarise
from .dynamics import dynamics_table, plsc_collapse_table, plsc_episodes, plsc_table, subsample_table
from .dynamics_tests import power_near_far, power_roles, power_tests, size_tests
from .homing import (
    ALIGNMENT_COLUMNS,
    ERROR_COLUMNS,
    alignment_episodes,
    compare_perception,
    error_histogram,
    error_vs_time,
    trajectory_shape,
)
from .interactions import bite_rate_by_class, bite_sizes, bite_timing, bouts, chase_sizes, label_counts, size_role_tests
from .onepatch import food_from_steps, reach_tests, role_tests
from .signalling import (
    EVENTS,
    eod_rate_by_distance,
    eod_rate_by_distance_episodes,
    fit_power_law,
    idi_histogram,
    idis,
    load_real_idis,
    peri_event_episodes,
    peri_event_rate,
    rate_advantage_vs_size,
    xmin_in_steps,
)
from .stats import STAT_COLUMNS, dunnett_by_measure, spearman

Tables = dict[str, pd.DataFrame]
#: Condition -> its config as the assay's run resolved it, in the assay's order (the first is the control).
Conditions = Mapping[str, EfishConfig]
#: Per-episode measures of :func:`efish.analysis.behaviour.episode_summary` compared between conditions.
SUMMARY_MEASURES = ["food_total", "theil_t", "eod_probability", "mean_nn_dist_cm", "bites"]
#: Per-agent-episode measures of :func:`efish.analysis.dynamics.dynamics_table` compared between conditions.
DYNAMICS_MEASURES = ["d_eff", "pcs_for_variance", "wideband_power"]


@dataclass(frozen=True)
class Analysis:
    """One analysis: its compute function (of the rollout tables, the job's analysis settings and the recorded
    conditions), the rollout tables it reads (always ``conditions``), its assays (docs/methods/assays.md) and output
    tables."""

    name: str
    compute: Callable[[Tables, AnalysisConfig, Conditions], Tables]
    reads: tuple[str, ...]
    assays: tuple[str, ...]
    outputs: tuple[str, ...]
    stats: tuple[str, ...] = ()  # outputs that are statistic tables (STAT_COLUMNS)

    def __post_init__(self):
        if "conditions" not in self.reads:  # what the run simulated is read from its record, nowhere else
            raise ValueError(f"analysis {self.name!r} must read 'conditions' (the assay's recorded conditions): "
                             f"it reads {list(self.reads)}")
        if ANALYSIS_SETTINGS in self.outputs:
            raise ValueError(f"analysis {self.name!r}: {ANALYSIS_SETTINGS!r} is the job's settings table, no output")

    @property
    def written(self) -> tuple[str, ...]:
        """Every table its job writes: the :attr:`outputs`, then the analysis settings it ran with
        (:data:`~efish.layout.ANALYSIS_SETTINGS`)."""
        return (*self.outputs, ANALYSIS_SETTINGS)


# ------------------------------------------------------------------ helpers
def control_condition(present: Iterable, conditions: Conditions):
    """The condition others are compared with: the first of the assay's recorded conditions (in its order) that is
    ``present`` in a table; the first recorded when none is."""
    present = set(present)
    return next((c for c in conditions if c in present), next(iter(conditions), None))


def _lacking(table: pd.DataFrame, columns: Iterable[str], outputs: Iterable[str], stats: Iterable[str] = ()) -> Tables:
    """One NaN row per output, whose reason names the ``columns`` the table lacks (empty dict: none lacking)."""
    missing = sorted(set(columns) - set(table.columns))
    if not missing:
        return {}
    row = nan_frame(f"the rollout table lacks columns {missing}")
    return {name: row.reindex(columns=STAT_COLUMNS) if name in stats else row for name in outputs}


def _homer(cfg: EfishConfig | None) -> int | None:
    """The homing agent (the one that is not the target) of a two-agent homing condition; None otherwise."""
    if cfg is None or cfg.env.task != "homing" or cfg.env.n_agents != 2:
        return None
    return 1 - cfg.env.homing_target


# ------------------------------------------------------------- signalling
def _idi_samples(ids: pd.DataFrame, present: Iterable, a: AnalysisConfig) -> dict[tuple, np.ndarray | str]:
    """IDIs per (source, condition): the agents' in whole steps, the real fish's in ms, or why there are none."""
    samples = {("agents", c): ids.loc[ids["condition"] == c, "idi_steps"].to_numpy() for c in sorted(present)}
    real = load_real_idis(a.real_fish_idis)
    samples["real_fish", np.nan] = real["reason"].iloc[0] or real["idi_ms"].to_numpy()
    return samples


def _idi_tables(ids: pd.DataFrame, present: Iterable, a: AnalysisConfig, fps: Mapping[str, float]) -> Tables:
    """IDI histograms and power-law fits per source and condition (Fig 3C,D; supplement).

    The agents' IDIs are whole steps and are fitted as a discrete power law from
    ``analysis.xmin_ms`` rounded up to steps of their condition (1000 / its
    recorded ``fps`` ms; as the authors fit them); the real fish's are fitted
    continuously in ms. ``xmin`` is in ms in both rows.
    """
    hist, fits = [], []
    for (source, cond), x in _idi_samples(ids, present, a).items():
        keys = {"source": source, "condition": cond}
        discrete = source == "agents"
        scale = 1000.0 / fps[cond] if discrete else 1.0  # ms of one unit of x: a step of the condition, or 1 ms
        xmin = xmin_in_steps(a.xmin_ms, scale) if discrete else a.xmin_ms
        extra = {"discrete": discrete, "xmin_steps": float(xmin) if discrete else np.nan}
        if isinstance(x, str):  # no sample: say why
            hist.append(nan_frame(x, **keys))
            fits.append({**keys, **fit_power_law([], xmin), **extra, "xmin": xmin * scale, "reason": x})
            continue
        h = idi_histogram(np.asarray(x, np.float64) * scale, a.idi_bins, a.idi_lo_ms, a.idi_hi_ms)
        hist.append(h.assign(**keys, reason="" if h["count"].sum() else "no IDI in the histogram range"))
        fits.append({**keys, **fit_power_law(x, xmin, discrete=discrete), **extra, "xmin": xmin * scale})
    return {"idi_histogram": pd.concat(hist, ignore_index=True), "power_law": pd.DataFrame(fits)}


def _signalling(t: Tables, a: AnalysisConfig, conditions: Conditions) -> Tables:
    """IDIs, their histograms and power laws, EOD rate vs distance and around events, also per episode (claims C5,
    C6), rate vs size (Fig 3C-J,P), each condition in its recorded steps per second."""
    steps, fps = t["steps"], step_rates(conditions)
    ranges = {"agent": a.agent_range_cm, "food": a.food_range_cm, "wall": a.wall_range_cm}
    ids, advantage = idis(steps, fps=fps), rate_advantage_vs_size(steps, a.bout_cm, a.rate_window, fps=fps)

    def by_distance(per) -> pd.DataFrame:
        return pd.concat([per(steps, to, a.rate_bins, (0.0, hi), a.min_samples, a.rate_window, fps=fps)
                          for to, hi in ranges.items()], ignore_index=True)
    return {
        "idis": or_nan_row(ids, "no agent discharged twice"),
        **_idi_tables(ids, steps["condition"].unique(), a, fps),
        "rate_by_distance": by_distance(eod_rate_by_distance),
        "rate_by_distance_episodes": by_distance(eod_rate_by_distance_episodes),
        "peri_event": pd.concat([peri_event_rate(steps, e, a.peri_window, a.min_events, a.rate_window, fps=fps)
                                 for e in EVENTS], ignore_index=True),
        "peri_event_episodes": pd.concat([peri_event_episodes(steps, e, a.claims_event_window,
                                                              a.claims_baseline_window, a.peri_window, a.min_events,
                                                              a.rate_window, fps=fps) for e in EVENTS],
                                         ignore_index=True),
        "rate_advantage": advantage,
        "rate_tests": spearman(advantage, "size_advantage", "rate_advantage_hz", by="condition"),
    }


# -------------------------------------------------------------- behaviour
def _behaviour(t: Tables, a: AnalysisConfig, conditions: Conditions) -> Tables:
    """Food, food vs size, Theil T, win ratios, bites by size, spacing, EOD probability, condition tests (Figs 3-4)."""
    episodes, steps = t["episodes"], t["steps"]
    wins, eod, summary = win_ratios(episodes), eod_probability(steps), episode_summary(episodes, t["food"])
    control = control_condition(summary["condition"], conditions)
    bites = _lacking(steps, ["bite_target"], ["bite_matrix"]) or {"bite_matrix": bite_matrix(steps)}
    theil = theil_per_episode(episodes)
    return {
        "food_per_agent": food_per_agent_episode(episodes), "food_vs_size": food_vs_size(episodes),
        "theil": theil, "win_ratio": wins, **bites,
        "nearest_neighbour": nearest_neighbour(steps), "eod_probability": eod, "episode_summary": summary,
        "size_tests": pd.concat([spearman(wins, "size", "win_ratio", by="condition").assign(measure="win_ratio"),
                                 spearman(eod, "size", "eod_probability", by="condition")
                                 .assign(measure="eod_probability"),
                                 spearman(theil, "size_theil_t", "theil_t", by="condition")  # Fig 3N
                                 .assign(measure="theil_t")], ignore_index=True),
        "condition_tests": dunnett_by_measure(summary, SUMMARY_MEASURES, "condition", control, a.seed),
    }


# ----------------------------------------------------------- interactions
BITE_OUTPUTS = ("bouts", "chase_sizes", "bite_sizes", "bite_timing", "bite_rate_by_class", "bite_rate_episodes",
                "size_tests")


def _interactions(t: Tables, a: AnalysisConfig, conditions: Conditions) -> Tables:
    """Ethogram of pair labels, bouts, chaser and biter sizes, bite timing and rate by class, also per episode (Figs
    3A, 5K-P)."""
    steps = t["steps"]
    labels = {"labels": label_counts(steps, a.facing_rad, a.away_rad)}
    if lacking := _lacking(steps, ["bite_target"], BITE_OUTPUTS, ["size_tests"]):
        return {**labels, **lacking}
    b = bouts(steps, a.bout_cm, a.contact_cm, a.facing_rad, a.away_rad)
    chases, bites = chase_sizes(steps, bout_table=b), bite_sizes(steps)
    return {**labels, "bouts": or_nan_row(b, "no bouts"), "chase_sizes": or_nan_row(chases, "no chasing bout"),
            "bite_sizes": or_nan_row(bites, "no bites"),
            "bite_timing": or_nan_row(bite_timing(steps, bout_table=b), "no bite within a bout"),
            "bite_rate_by_class": bite_rate_by_class(steps, a.bout_cm, a.facing_rad, a.away_rad),
            "bite_rate_episodes": bite_rate_by_class(steps, a.bout_cm, a.facing_rad, a.away_rad, by=EPISODE),
            "size_tests": size_role_tests(chases, bites)}


# ----------------------------------------------------------------- homing
def _homing(t: Tables, a: AnalysisConfig, conditions: Conditions) -> Tables:
    """Error-angle histograms and time courses, their alignment per agent-episode, trajectory shape, electric vs ray
    casting (Fig 2B-D); the homer is the control condition's, as the run recorded it."""
    steps = t["steps"]
    needs_one = [] if set(ERROR_COLUMNS.values()) & set(steps.columns) else ERROR_COLUMNS.values()
    errors = _lacking(steps, needs_one, ["error_histogram", "error_vs_time"]) or {
        "error_histogram": error_histogram(steps), "error_vs_time": error_vs_time(steps)}
    lacking = _lacking(steps, [*needs_one, "bearing_agent_rad", "success"], ["alignment_episodes"])
    alignment = (lacking["alignment_episodes"].reindex(columns=ALIGNMENT_COLUMNS) if lacking
                 else alignment_episodes(steps, a.claims_aligned_rad))
    control = control_condition(steps["condition"], conditions)
    return {**errors, "alignment_episodes": alignment, "trajectory_shape": trajectory_shape(steps),
            "perception": compare_perception(steps, control, None, _homer(conditions.get(control)))}


# --------------------------------------------------------------- onepatch
def _onepatch(t: Tables, a: AnalysisConfig, conditions: Conditions) -> Tables:
    """Cumulative food over time, reach rates of the arena's central patch, and the tests by role (Fig 5E-J); who
    is A, B, the bot or alone, and each condition's arena, come from the conditions the run recorded."""
    steps, arenas = t["steps"], {c: cfg.arena for c, cfg in conditions.items()}
    centre = ({c: arena.width_cm / 2 for c, arena in arenas.items()},
              {c: arena.height_cm / 2 for c, arena in arenas.items()})
    reach = reach_rates(steps, centre, {c: arena.onepatch_radius_cm for c, arena in arenas.items()})
    return {"food_time_course": food_time_course(steps), "reach_rates": reach,
            "role_tests": role_tests(food_from_steps(steps), conditions),
            "reach_tests": reach_tests(reach, conditions)}


# --------------------------------------------------------------- dynamics
def _dynamics(t: Tables, a: AnalysisConfig, conditions: Conditions) -> Tables:
    """Hidden-state dimensionality, power, unit subsampling, decoding per episode and its mean over episodes (also of
    food near and far; homing: the homer's states), PLSC of agents 0 and 1 (also its first component per episode
    and distance bin) with the test of fewer shared dimensions far than near, wideband power by context and by
    size, and the tests of D_eff against group size and of wideband power (Fig 6), each condition's power per Hz of
    its recorded steps per second."""
    hidden, steps, fps = t["hidden"], t["steps"], step_rates(conditions)
    rng = np.random.default_rng(a.seed)
    dims = dynamics_table(hidden, a.variance_fraction, a.spectrogram_window, a.spectrogram_overlap, fps=fps)
    control = control_condition(dims["condition"], conditions)
    homer = _homer(conditions.get(control))
    decoded = decode_episodes(hidden, steps, folds=a.decode_folds, agent=homer)
    food = food_decode_episodes(hidden, steps, a.claims_food_near_cm, a.decode_folds, homer)
    return {"dimensionality": dims,
            "subsampling": subsample_table(hidden, a.subsample_fractions, a.subsample_draws, rng),
            "decoding": summarise(decoded), "decoding_episodes": decoded,
            "food_decoding": summarise(food, by=("food",)), "food_decoding_episodes": food,
            "plsc": plsc_table(hidden, steps, (0, 1), a.plsc_edges_cm, a.plsc_shifts, rng, a.plsc_percentile,
                               a.plsc_null_draws, a.claims_alpha),
            "plsc_episodes": plsc_episodes(hidden, steps, (0, 1), a.plsc_edges_cm),
            "plsc_collapse": plsc_collapse_table(hidden, steps, (0, 1), a.plsc_edges_cm, a.plsc_null_draws,
                                                 a.claims_alpha, swaps=a.plsc_label_swaps, rng=rng),
            "condition_tests": dunnett_by_measure(dims, DYNAMICS_MEASURES, "condition", control, a.seed),
            "size_tests": size_tests(dims, conditions), **_power(hidden, steps, dims, a, fps)}


def _power(hidden: pd.DataFrame, steps: pd.DataFrame, dims: pd.DataFrame, a: AnalysisConfig,
           fps: Mapping[str, float]) -> Tables:
    """Wideband power near vs far from the nearest conspecific, of the smaller and the larger agents, and their tests
    (Fig 6I,J); NaN rows without the steps columns it needs."""
    if lacking := _lacking(steps, ["dist_agent_cm", "size"], ["power_near_far", "power_roles", "power_tests"],
                           ["power_tests"]):
        return lacking
    near_far = power_near_far(hidden, steps, a.claims_near_cm, a.claims_far_cm, a.spectrogram_window,
                              a.spectrogram_overlap, fps)
    return {"power_near_far": or_nan_row(near_far, "no agent-episode with a hidden state"),
            "power_roles": power_roles(dims, steps), "power_tests": power_tests(near_far, dims, steps)}


#: The assays whose food, bites, spacing and EOD probability the behaviour analysis summarises (Figs 3-5).
FORAGING = ("patchy4", "uniform4", "ablation4", "ablation1", "collective", "mute", "npatch", "food_scarcity",
            "groupsize", "onepatch")
ANALYSES: dict[str, Analysis] = {a.name: a for a in [
    Analysis("signalling", _signalling, ("steps", "conditions"), ("patchy4", "wide2"),
             ("idis", "idi_histogram", "power_law", "rate_by_distance", "rate_by_distance_episodes", "peri_event",
              "peri_event_episodes", "rate_advantage", "rate_tests"), ("rate_tests",)),
    Analysis("behaviour", _behaviour, ("steps", "episodes", "food", "conditions"), FORAGING,
             ("food_per_agent", "food_vs_size", "theil", "win_ratio", "bite_matrix", "nearest_neighbour",
              "eod_probability", "episode_summary", "size_tests", "condition_tests"),
             ("food_vs_size", "size_tests", "condition_tests")),
    Analysis("interactions", _interactions, ("steps", "conditions"), ("patchy4", "square2"),
             ("labels", *BITE_OUTPUTS), ("size_tests",)),
    Analysis("homing", _homing, ("steps", "conditions"), ("homing",),
             ("error_histogram", "error_vs_time", "alignment_episodes", "trajectory_shape", "perception"),
             ("perception",)),
    Analysis("onepatch", _onepatch, ("steps", "conditions"), ("onepatch", "bot"),
             ("food_time_course", "reach_rates", "role_tests", "reach_tests"), ("role_tests", "reach_tests")),
    Analysis("dynamics", _dynamics, ("hidden", "steps", "conditions"),
             ("patchy4", "wide2", "homing", "groupsize", "square2"),
             ("dimensionality", "subsampling", "decoding", "decoding_episodes", "food_decoding",
              "food_decoding_episodes", "plsc", "plsc_episodes", "plsc_collapse", "condition_tests", "size_tests",
              "power_near_far", "power_roles", "power_tests"), ("condition_tests", "size_tests", "power_tests")),
]}


# ------------------------------------------------------------------- API
def get(name: str) -> Analysis:
    """The registered analysis ``name``; an unknown name is one ValueError listing the known ones."""
    if name not in ANALYSES:
        raise ValueError(f"unknown analysis {name!r}: choose one of {', '.join(ANALYSES)}")
    return ANALYSES[name]


def tables_written(assay: AssayConfig) -> tuple[str, ...]:
    """The rollout tables an assay writes: steps, episodes, food, conditions, and hidden when it sets
    ``record_hidden``."""
    return ROLLOUT_TABLES + (("hidden",) if getattr(assay, "record_hidden", False) else ())


def analyses_for(assay: str, tables: Iterable[str]) -> list[Analysis]:
    """The analyses of ``assay`` whose input tables are all among the ``tables`` it writes (what the DAG schedules)."""
    return [a for a in ANALYSES.values() if assay in a.assays and set(a.reads) <= set(tables)]


def read_tables(name: str, folder: str | Path) -> Tables:
    """The rollout tables analysis ``name`` reads from ``folder``; a missing one is one ValueError naming it."""
    folder = Path(folder)
    paths = {t: folder / f"{t}.parquet" for t in get(name).reads}
    if missing := [str(p) for p in paths.values() if not p.is_file()]:
        raise ValueError(f"analysis {name!r} needs {', '.join(missing)}, which does not exist (run the assay first)")
    return {t: read_parquet(p, f"the {t} table") for t, p in paths.items()}


def recorded(tables: Tables) -> Conditions:
    """The conditions an assay's ``conditions`` table records, checked to name every condition of its other
    ``tables``: a row of a condition the run did not record has no frame rate or arena to be read in."""
    conditions = recorded_conditions(tables["conditions"], "the assay's conditions table")
    for name, table in tables.items():
        if name != "conditions" and "condition" in table.columns:
            if unknown := sorted(set(table["condition"].dropna()) - set(conditions), key=str):
                raise ValueError(f"the {name} table holds conditions {unknown} that the assay's conditions table "
                                 f"does not record ({', '.join(conditions)}): the tables are of different runs")
    return conditions


def run(name: str, tables: Tables, settings: AnalysisConfig) -> Tables:
    """The output tables of analysis ``name`` (:attr:`Analysis.outputs`, in order) from its input ``tables`` (the
    assay's rollout tables with its recorded ``conditions``) under the analysis ``settings`` (``cfg.analysis``)."""
    analysis = get(name)
    if missing := [t for t in analysis.reads if t not in tables]:
        raise ValueError(f"analysis {name!r} needs the tables {missing}")
    out = analysis.compute(tables, settings, recorded({t: tables[t] for t in analysis.reads}))
    if set(out) != set(analysis.outputs):
        raise RuntimeError(f"analysis {name!r} returned {sorted(out)}, declared {sorted(analysis.outputs)}")
    for table in analysis.stats:
        require(out[table], STAT_COLUMNS, f"statistic table {name}/{table}")
    return {table: out[table].reset_index(drop=True) for table in analysis.outputs}
