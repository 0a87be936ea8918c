"""What a decisive recipe verdict would cost, part by part, from a finished run's own tables.

For every part the recipe decides over seeds, the run's seeds give its variance components
(:func:`efish.claims.power.components`: the seeds' effects and their own standard errors, read back from their
intervals by the quantile each part's own test made them with, :func:`own_test`), and :mod:`efish.claims.power`
gives the chance that the recipe's decision settles, now and for more seeds, in the planner's two scenarios (an
effect of twice delta, no effect). The same within-seed spread sigma plans the selected seed's own verdict: its
part's own test over its episodes (``own_*`` columns), now and at the fewest episodes that reach the target. The
run's own Snakemake benchmark files price a design (:func:`run_costs`): a seed costs its training, its selection
episodes and its reruns of the claims' assays, and an episode what those reruns cost per episode, all measured in
this run on this machine. Only what is reported beside a verdict changes: no verdict rule reads this.

Pure pandas: it reads claim_parts tables and benchmark files, never the simulator.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd

from ..layout import (
    CLAIM_PARTS,
    DRAW,
    RANKING,
    Run,
    assay_folder,
    parse_recipe_draw,
    parse_table,
    seed_name,
    selection_table,
    top_seed_copy,
    top_seed_group,
    training_folder,
)
from .power import (
    FISHER_Z_TEST,
    MAX_SEEDS,
    MAX_UNITS,
    NORMAL,
    RANK_SUM,
    REGRESSION_T,
    SCENARIOS,
    SIGNED_RANK,
    T_TEST,
    TARGET,
    WELCH,
    Components,
    OwnTest,
    components,
    decision_probabilities,
    own_decision_probabilities,
    own_min_units,
    own_standard_error,
    scenario_verdict,
    seeds_needed,
    units_needed,
)
from .power import standard_error as interval_se
from .recipe import FISHER_Z, fisher_z
from .verdicts import interval_level

__all__ = ["CURVE_COLUMNS", "MORE_EPISODES", "OWN_PLAN_COLUMNS", "PLAN_COLUMNS", "STAGE_PLAN_COLUMNS", "PartModel",
           "RunCosts", "claim_curves", "own_test", "part_models", "plan_parts", "plan_table", "power_curves",
           "read_run", "run_costs", "with_stages"]

#: The column suffix of each of :data:`~efish.claims.power.SCENARIOS`, in its order.
SCENARIO_KEYS = ("holds_at_2delta", "absent_at_0")
#: The designs the figure draws: seeds at the run's episodes.
CURVE_SEEDS = (2, 3, 4, 5, 6, 8, 10, 12, 16, 20, 24, 32, 40, 50, 64, 80, 100, 128, 160, 200)
#: One row per plannable part and design: the chance of each scenario's verdict and the design's CPU-hours.
CURVE_COLUMNS = ["claim", "part", "seeds", "cpu_hours", *SCENARIO_KEYS]

#: The selected seed's own verdict planned (:func:`plan_part`): the test its part is decided by (``own_test``), its
#: units (``own_units``), the chance of each scenario's verdict at them, and the fewest episodes per condition that
#: reach :data:`~efish.claims.power.TARGET` with their CPU-hours (:meth:`RunCosts.episode_hours`).
OWN_PLAN_COLUMNS = ["own_test", "own_units", "own_now_holds_at_2delta", "own_now_absent_at_0",
                    "own_episodes_holds_at_2delta", "own_episodes_absent_at_0", "own_cpu_hours_holds_at_2delta",
                    "own_cpu_hours_absent_at_0"]
#: One row per part: the run's design (seeds, whether they are draws of the homing recipes, mean units per seed), the
#: variance components, the chance of each
#: scenario's recipe verdict now and the seeds (and CPU-hours) that reach :data:`~efish.claims.power.TARGET`, then
#: the selected seed's own verdict (:data:`OWN_PLAN_COLUMNS`).
PLAN_COLUMNS = ["claim", "part", "sign", "delta", "seeds", "draws", "units", "effect", "tau", "sigma",
                "now_holds_at_2delta", "now_absent_at_0", "seeds_holds_at_2delta", "seeds_absent_at_0",
                "cpu_hours_holds_at_2delta", "cpu_hours_absent_at_0", "seeds_holds_at_2delta_more_episodes",
                "cpu_hours_holds_at_2delta_more_episodes", *OWN_PLAN_COLUMNS, "note"]
#: A part's own test, by what its ``ci_method`` says (the first match, in this order): how its interval is made,
#: as :class:`~efish.claims.power.OwnTest` models it. "inverts the t-test" is C17's interaction, the t-test of
#: one coefficient of a four-coefficient regression; a method none names (C20's permutation p without an
#: interval) is not planned.
OWN_TESTS: tuple[tuple[str, OwnTest], ...] = (
    ("signed-rank", SIGNED_RANK), ("no difference to invert", SIGNED_RANK), ("Mann-Whitney", RANK_SUM),
    (FISHER_Z, FISHER_Z_TEST), ("Welch", WELCH), ("clustered t", T_TEST), ("jackknife", T_TEST),
    ("inverts the t-test", REGRESSION_T), ("bootstrap", NORMAL))
#: The other design the plan prices: every seed reruns the claims' assays at this many times the run's episodes.
#: Only the within-seed part of the spread (sigma^2 / n) shrinks with them; where the seeds differ (tau), it
#: needs about as many seeds as before, at a higher price.
MORE_EPISODES = 4
#: Where the run kept training stages (the claims along training), the plan gains the selected seed's effect at each
#: stage (``stage_effects``: "240k: 0.01, 480k: 0.05", env steps and effect) and the part's trend over them: an
#: effect still growing says longer training, not more seeds, is the lever.
STAGE_PLAN_COLUMNS = ["stage_effects", "trend"]


@functools.cache
def claim_assays(claim: str) -> frozenset[str]:
    """The assays whose tables ``claim`` reads (:data:`efish.claims.registry.CLAIMS`); none for a claim it does not
    list."""
    from .registry import CLAIMS

    found = CLAIMS.get(claim)
    return frozenset(t.assay for path in found.tables if (t := parse_table(path))) if found else frozenset()


class RunCosts(NamedTuple):
    """What one more seed costs in this run, in CPU-seconds: its training, its selection episodes, and its reruns of
    the claims' assays at the run's episodes (``rerun_s``, from the other top seeds' jobs); ``seeds_timed`` says how
    many seeds each mean is over; ``run_s`` is what the whole run cost. ``episodes``: the selected seed's episodes
    per assay condition (``scale.max_episodes``), ``rerun_episodes`` the reruns' (``scale.top_seed_episodes``, at
    most that): what :meth:`episode_hours` divides the reruns' cost by.

    A claim whose assays act with the homing recipes alone (``drawn_assays``) is decided over draws of those
    recipes, not over foraging seeds: one more draw costs training every drawn recipe again (``draw_train_s``) and
    a top seed's rerun of the drawn assays with it and their analyses (``draw_rerun_s``), and neither is in a
    foraging seed's price. ``rerun_assays``: the assays the other top seeds reran (None: not known, all of them)."""

    train_s: float
    selection_s: float
    rerun_s: float
    seeds_timed: str
    run_s: float = np.nan  # the whole run's CPU time (every job's benchmark file), for "x times this run"
    episodes: float = np.nan
    rerun_episodes: float = np.nan
    draw_train_s: float = np.nan
    draw_rerun_s: float = np.nan
    drawn_assays: tuple[str, ...] = ()
    rerun_assays: tuple[str, ...] | None = None

    def draws(self, claim: str | None) -> bool:
        """Whether ``claim``'s seeds are draws of the homing recipes: every assay it reads is a drawn one."""
        assays = claim_assays(claim) if claim else frozenset()
        return bool(assays) and assays <= set(self.drawn_assays)

    def design_hours(self, seeds: int | None, episodes: float = 1.0, claim: str | None = None) -> float:
        """CPU-hours of a design of ``seeds`` seeds, each rerunning the claims' assays at ``episodes`` times the run's
        episodes (training and selection do not grow with them; NaN when no design reaches it); of as many draws
        of the homing recipes where ``claim`` is decided over draws (:meth:`draws`)."""
        if self.draws(claim):
            per_seed = self.draw_train_s + episodes * self.draw_rerun_s
        else:
            per_seed = self.train_s + self.selection_s + episodes * self.rerun_s
        return np.nan if seeds is None else seeds * per_seed / 3600

    def episode_hours(self, episodes: int | None, claim: str | None = None) -> float:
        """CPU-hours of the selected seed's claims' assays rerun at ``episodes`` episodes per condition: a top seed's
        measured reruns (``rerun_s``: every claim's assay that acts with the seed, their analyses and its claims
        job, at ``rerun_episodes`` a condition) scaled in proportion, ``episodes / rerun_episodes`` times their
        cost; for a claim decided over draws (:meth:`draws`), its drawn assays' reruns (``draw_rerun_s``). A line
        through the one measured design and no cost at no episodes: exact at the reruns' episodes, and it counts
        each job's start-up and the claims job as if they grew with the episodes, so it overprices designs of more
        episodes a little (the laptop reruns' jobs start in seconds and run for minutes). The rerun is of every
        claim's assay, what ``scale.max_episodes`` asks the pipeline for, not the part's assay alone. NaN where no
        design reaches the target, the reruns were not measured, or no top seed reran ``claim``'s assays (the
        homing assays of a run without draws)."""
        rerun = self.draw_rerun_s if self.draws(claim) else self.rerun_s
        known = self.rerun_assays is None or not claim or claim_assays(claim) <= {*self.rerun_assays,
                                                                                   *self.drawn_assays}
        if episodes is None or not (known and rerun > 0 and self.rerun_episodes > 0):
            return np.nan
        return episodes * rerun / self.rerun_episodes / 3600


def _cpu_seconds(path: Path) -> float:
    """A Snakemake benchmark file's CPU time (its last row; wall seconds where it has no cpu_time)."""
    row = pd.read_csv(path, sep="\t").iloc[-1]
    value = row.get("cpu_time", np.nan)
    return float(value) if pd.notna(value) and float(value) > 0 else float(row["s"])


def _draw_costs(run: Run, reruns: Sequence[Path]) -> tuple[float, float, tuple[str, ...], list[Path], str]:
    """What one more draw of the homing recipes costs (:class:`RunCosts`): the mean over the draws k of the
    trainings of every drawn recipe (``train/<recipe>_draw_<k>``), and the mean over the top seeds that reran an
    assay with a draw (a job of their own, ``seeds/seed_<n>/assays/<assay>``: every other rerun runs in a group)
    of those reruns and their analyses; the drawn assays, those rerun files (not a foraging seed's) and a note."""
    top_seeds = run.benchmarks / Path(top_seed_copy(0)).parent
    own = [p for p in reruns if p.relative_to(top_seeds).parts[0].startswith(seed_name(""))]
    trainings = [p for p in run.benchmark(training_folder("x")).parent.glob(f"*{DRAW}*.tsv")
                 if parse_recipe_draw(p.stem)[1] > 1]
    drawn = tuple(sorted({p.stem for p in own if p.parent.name == Path(assay_folder("x")).parent.name})
                  if trainings else ())  # without a draw trained, no rerun is a draw's
    draw_reruns = [p for p in own if p.stem in drawn]
    draws = {parse_recipe_draw(p.stem)[1] for p in trainings}
    rerun_seeds = {p.relative_to(top_seeds).parts[0] for p in draw_reruns}
    train_s = sum(map(_cpu_seconds, trainings)) / len(draws) if draws else np.nan
    rerun_s = sum(map(_cpu_seconds, draw_reruns)) / len(rerun_seeds) if rerun_seeds else np.nan
    note = f"; homing draws: training {len(draws)}, reruns {len(rerun_seeds)}" if draws or rerun_seeds else ""
    return float(train_s), float(rerun_s), drawn, draw_reruns, note


def run_costs(run: Run, seeds: Sequence[int], other_top_seeds: int,
              episodes: tuple[float, float] = (np.nan, np.nan)) -> RunCosts:
    """The run's measured cost of a seed, from its Snakemake benchmark files (:meth:`efish.layout.Run.benchmark`):
    the mean CPU time of the ``seeds``' training and selection jobs, and of everything the top seeds' reruns ran
    (every file in a folder of its own under the top seeds' benchmarks, however the workflow grouped them) over
    ``other_top_seeds``, but their reruns with a draw of the homing recipes, which price a draw with those draws'
    trainings (:func:`_draw_costs`); ``episodes``: the selected seed's and the reruns' episodes per condition
    (:class:`RunCosts`). A run without training benchmarks gets NaN costs (its designs are planned, not priced)."""
    train = [p for s in seeds if (p := run.benchmark(training_folder(seed_name(s)))).exists()]
    if not train:  # a run whose training is another's (a sweep's point that copies it) or was not run by Snakemake
        return RunCosts(np.nan, np.nan, np.nan, f"no training benchmark under {run.benchmarks}: designs unpriced",
                        episodes=episodes[0], rerun_episodes=episodes[1])
    selection = [p for s in seeds if (p := run.benchmark(str(Path(selection_table(s, "x")).parent))).exists()]
    top_seeds = run.benchmarks / Path(top_seed_copy(0)).parent  # each seed's or group's jobs in a folder of its own
    reruns = list(top_seeds.glob("*/**/*.tsv")) if top_seeds.is_dir() else []
    draw_train_s, draw_rerun_s, drawn, draw_reruns, draw_note = _draw_costs(run, reruns)
    foraging = [p for p in reruns if p not in draw_reruns]
    rerun_s = sum(map(_cpu_seconds, foraging)) / other_top_seeds if other_top_seeds and foraging else 0.0
    groups = top_seeds / Path(top_seed_group("x")).parent.name
    return RunCosts(float(np.mean([_cpu_seconds(p) for p in train])),
                    float(np.mean([_cpu_seconds(p) for p in selection])) if selection else 0.0, float(rerun_s),
                    f"training {len(train)}, selection {len(selection)}, reruns of {other_top_seeds} seeds"
                    + draw_note, float(sum(map(_cpu_seconds, run.benchmarks.rglob("*.tsv")))), *episodes,
                    draw_train_s, draw_rerun_s, drawn, tuple(sorted(p.stem for p in groups.glob("*.tsv"))))


def own_test(methods: Sequence[str]) -> OwnTest | None:
    """The test a part's intervals were made by, from the first of ``methods`` (their ``ci_method``) that
    :data:`OWN_TESTS` names; None where none does."""
    for method in methods:
        for words, test in OWN_TESTS:
            if words in str(method):
                return test
    return None


def _standard_error(low: float, high: float, n: float, family: int, alpha: float, test: OwnTest | None) -> float:
    """One seed's SE from its interval: by its own test's critical value (:func:`~efish.claims.power.
    own_standard_error`, so that SE^2 n estimates the sigma that test's plan assumes), or the normal quantile of its
    level where the test is unknown."""
    if test is None or not n >= own_min_units(test):
        return interval_se(low, high, interval_level(alpha, family))
    return own_standard_error(low, high, test, int(n), alpha, family)


def _seed_values(rows: pd.DataFrame, alpha: float, correlation: bool, test: OwnTest | None = None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The seeds' effects, standard errors (from each interval at its level, 1 - 2 alpha / family, as ``test``
    made it: :func:`_standard_error`) and units, on the scale the recipe decides on (Fisher's z for a
    correlation)."""
    effect, low, high = (rows[c].astype(float).to_numpy() for c in ("effect", "ci_low", "ci_high"))
    if correlation:
        effect, low, high = (fisher_z(v) for v in (effect, low, high))
    units = rows["n"].astype(float).to_numpy()
    ses = np.array([_standard_error(lo, hi, n, int(f), alpha, test)
                    for lo, hi, n, f in zip(low, high, units, rows["family"], strict=True)])
    return effect, ses, units


class Own(NamedTuple):
    """The selected seed's own test of a part, as the planner plans it: the test (:func:`own_test`), its units, its
    Holm family, its delta on the scale decided on (Fisher's z for a correlation) and the per-unit SD sigma (the
    seeds' pooled one, or the selected seed's own where it is the only seed with an interval)."""

    test: OwnTest
    units: int
    family: int
    delta: float
    sigma: float


class PartModel(NamedTuple):
    """A part's seeds reduced to what the planner needs (:func:`model_part`): its sign, smallest effect of interest
    (``delta`` as reported; ``planned_delta`` on the scale decided on, Fisher's z for a correlation), Holm family,
    the variance components over the seeds (None where they cannot be had; ``note`` says why), notes, and the
    selected seed's own test (``own``: None where it cannot be planned; ``own_note`` says why)."""

    claim: str
    part: str
    sign: int | None
    delta: float
    planned_delta: float
    family: int
    seeds: int
    correlation: bool
    comp: Components | None
    note: str
    own: Own | None = None
    own_note: str = ""

    def theta(self, multiple: float, delta: float | None = None) -> float:
        """A true effect of ``multiple`` deltas (``delta``, default the planned one) in the paper's direction, on
        the scale decided on."""
        delta = self.planned_delta if delta is None else delta
        return multiple * delta * (-1 if self.sign is not None and self.sign < 0 else 1)


def _own(first: pd.Series, test: OwnTest | None, sigma: float, alpha: float, correlation: bool
         ) -> tuple[Own | None, str]:
    """The selected seed's own test of a part (its claim_parts row ``first``), planned at the per-unit SD ``sigma``
    (NaN: read from its own interval); (None, why) where it cannot be planned."""
    n, family, delta = float(first["n"]), int(first["family"]), float(first["delta"])
    if test is None:
        return None, "its own test makes no interval to plan from"
    if first["verdict"] == "not run" or not n >= own_min_units(test) or not np.isfinite(delta):
        return None, "the selected seed did not test it (or has no delta)"
    delta = float(fisher_z(delta)) if correlation else delta
    if not np.isfinite(sigma):  # no pooled sigma: the selected seed's own interval
        effect, se, units = _seed_values(first.to_frame().T, alpha, correlation, test)
        sigma = float(se[0] * np.sqrt(units[0])) if np.isfinite(effect[0]) else np.nan
    if not (sigma > 0 or test == FISHER_Z_TEST):
        return None, "no within-seed spread to plan its own test from"
    return Own(test, int(n), family, delta, sigma), ""


def model_part(rows: pd.DataFrame, alpha: float) -> PartModel:
    """One part's :class:`PartModel` from its claim_parts rows over the seeds (effect, interval, n, family, sign,
    delta, ci_method, verdict), the selected seed's first; seeds that did not run it, or carry no effect or delta,
    are left out."""
    first = rows.iloc[0]
    sign = None if pd.isna(first["sign"]) else int(first["sign"])
    use = rows[np.isfinite(rows["effect"].astype(float)) & np.isfinite(rows["delta"].astype(float))
               & (rows["verdict"] != "not run")]
    test = own_test(rows["ci_method"].astype(str))
    correlation = bool(rows["ci_method"].astype(str).str.contains(FISHER_Z).any())
    blank = PartModel(str(first["claim"]), str(first["part"]), sign, np.nan, np.nan, 1, len(use), False, None, "")
    if len(use) < 2:
        own, why = _own(first, test, np.nan, alpha, correlation)
        return blank._replace(note=f"{len(use)} seed(s) carry an effect and a delta: no spread over seeds to plan "
                                   "from", own=own, own_note=why)
    delta = float(np.nanmedian(use["delta"].astype(float)))
    model = blank._replace(delta=delta, planned_delta=float(fisher_z(delta)) if correlation else delta,
                           family=int(use["family"].max()), correlation=correlation)
    effect, ses, units = _seed_values(use, alpha, correlation, test)
    finite = np.isfinite(ses)
    notes = ["planned on Fisher's z scale"] * correlation
    if finite.sum() >= 2:
        comp = components(effect[finite], ses[finite], units[finite])._replace(effect=float(effect.mean()),
                                                                                seeds=len(use))
    else:  # no usable interval (unbounded rank intervals): all the spread counted as between seeds
        comp = components(effect, np.zeros_like(effect), units)
        notes.insert(0, "seeds' intervals unbounded: all spread counted as between seeds")
    if not comp.seed_sd() > 0:
        notes = ["every seed gave the same effect: no spread to plan from"]
    own, why = _own(first, test, comp.sigma if finite.sum() >= 2 else np.nan, alpha, correlation)
    return model._replace(comp=comp, note="; ".join(notes), own=own, own_note=why)


def _plannable(model: PartModel) -> bool:
    return model.comp is not None and model.comp.seed_sd() > 0


def _plan_own(model: PartModel, alpha: float, costs: RunCosts) -> dict:
    """The :data:`OWN_PLAN_COLUMNS` of one part: the chance of each scenario's verdict of the selected seed's own
    test at its units, and the fewest episodes per condition that reach the target with their CPU-hours. Units
    become episodes at the selected seed's own ratio (``costs.episodes`` over its units: a part over successful
    episodes has fewer units than episodes, one over two conditions' episodes more), rounded up."""
    out: dict = {"own_test": "" if model.own is None else model.own.test.name}
    own = model.own
    if own is None:
        return out
    per_unit = costs.episodes / own.units if costs.episodes > 0 else 1.0
    out["own_units"] = own.units
    for (_, multiple, sought), key in zip(SCENARIOS, SCENARIO_KEYS, strict=True):
        verdict = scenario_verdict(model.sign, sought)
        theta = model.theta(multiple, own.delta)
        out[f"own_now_{key}"] = own_decision_probabilities(theta, own.sigma, own.units, own.test, model.sign,
                                                           own.delta, alpha, own.family)[verdict]
        n = units_needed(theta, own.sigma, own.test, model.sign, own.delta, alpha, verdict, own.family)
        episodes = None if n is None else int(np.ceil(n * per_unit - 1e-9))
        out[f"own_episodes_{key}"] = np.nan if episodes is None else episodes
        out[f"own_cpu_hours_{key}"] = costs.episode_hours(episodes, model.claim)
    return out


def plan_part(model: PartModel, alpha: float, costs: RunCosts) -> dict:
    """One row of :data:`PLAN_COLUMNS` for one part."""
    out = dict.fromkeys(PLAN_COLUMNS, np.nan) | {"claim": model.claim, "part": model.part,
                                                 "sign": np.nan if model.sign is None else float(model.sign),
                                                 "delta": model.delta, "seeds": model.seeds, "note": model.note,
                                                 "draws": costs.draws(model.claim)}
    out |= _plan_own(model, alpha, costs)
    if model.own is None and model.own_note:
        out["note"] = "; ".join(n for n in (model.note, f"selected seed: {model.own_note}") if n)
    elif model.own is not None and np.isnan(out["own_episodes_holds_at_2delta"]):
        out["note"] = "; ".join(n for n in (model.note, f"selected seed: not within {MAX_UNITS:,} units") if n)
    if model.comp is None:
        return out
    comp = model.comp
    out.update(units=comp.units, effect=float(np.tanh(comp.effect)) if model.correlation else comp.effect,
               tau=comp.tau, sigma=comp.sigma)
    if not _plannable(model):
        return out
    notes = [out["note"]] if out["note"] else []
    for (name, multiple, sought), key in zip(SCENARIOS, SCENARIO_KEYS, strict=True):
        verdict = scenario_verdict(model.sign, sought)
        theta = model.theta(multiple)
        now = decision_probabilities(theta, comp.seed_sd(), comp.seeds, model.sign, model.planned_delta, alpha,
                                     model.family)
        k = seeds_needed(comp, model.sign, model.planned_delta, alpha, theta, verdict, model.family)
        out[f"now_{key}"] = now[verdict]
        out[f"seeds_{key}"] = np.nan if k is None else k
        out[f"cpu_hours_{key}"] = costs.design_hours(k, claim=model.claim)
        if k is None:
            notes.append(f"{name}: not within {MAX_SEEDS} seeds")
        if key == SCENARIO_KEYS[0]:  # the same question with more episodes per seed
            more = seeds_needed(comp, model.sign, model.planned_delta, alpha, theta, verdict, model.family,
                                units=MORE_EPISODES * comp.units)
            out[f"seeds_{key}_more_episodes"] = np.nan if more is None else more
            out[f"cpu_hours_{key}_more_episodes"] = costs.design_hours(more, MORE_EPISODES, model.claim)
    return out | {"note": "; ".join(notes)}


def part_models(parts_by_seed: Mapping[int, pd.DataFrame], alpha: float) -> list[PartModel]:
    """A :class:`PartModel` per part of the selected seed's claims (the first table of ``parts_by_seed``), from
    every seed's claim_parts rows of that part, in the selected seed's order."""
    order = list(parts_by_seed)
    stacked = pd.concat([parts_by_seed[s].assign(seed=s) for s in order], ignore_index=True)
    return [model_part(group, alpha) for (_, _), group in stacked.groupby(["claim", "part"], sort=False)
            if group["seed"].iloc[0] == order[0]]


def plan_table(models: Sequence[PartModel], alpha: float, costs: RunCosts) -> pd.DataFrame:
    """:data:`PLAN_COLUMNS`, one row per part of ``models``."""
    return pd.DataFrame([plan_part(m, alpha, costs) for m in models], columns=PLAN_COLUMNS)


def plan_parts(parts_by_seed: Mapping[int, pd.DataFrame], alpha: float, costs: RunCosts) -> pd.DataFrame:
    """One row of :data:`PLAN_COLUMNS` per part of the selected seed's claims (the first table of
    ``parts_by_seed``), planned over every seed's claim_parts rows of that part."""
    return plan_table(part_models(parts_by_seed, alpha), alpha, costs)


def power_curves(models: Sequence[PartModel], alpha: float, costs: RunCosts,
                 seeds: Sequence[int] = CURVE_SEEDS) -> pd.DataFrame:
    """:data:`CURVE_COLUMNS`: each plannable part's chance of each scenario's verdict at every design of ``seeds``
    seeds (at the run's episodes), with the design's CPU-hours: the rows of the figure of what a decisive verdict
    costs."""
    rows = []
    for m in filter(_plannable, models):
        sd = m.comp.seed_sd()
        for k in seeds:
            row = {"claim": m.claim, "part": m.part, "seeds": k, "cpu_hours": costs.design_hours(k, claim=m.claim)}
            for (_, multiple, sought), key in zip(SCENARIOS, SCENARIO_KEYS, strict=True):
                row[key] = decision_probabilities(m.theta(multiple), sd, k, m.sign, m.planned_delta, alpha,
                                                  m.family)[scenario_verdict(m.sign, sought)]
            rows.append(row)
    return pd.DataFrame(rows, columns=CURVE_COLUMNS)


def claim_curves(curves: pd.DataFrame) -> pd.DataFrame:
    """Per claim and design, the chance of its weakest part (the minimum over its parts): a claim's verdict is its
    weakest deciding part's, so this bounds the chance that the claim's verdict settles from above."""
    return curves.groupby(["claim", "seeds"], sort=False, as_index=False).agg(
        cpu_hours=("cpu_hours", "first"), **{key: (key, "min") for key in SCENARIO_KEYS})


def _steps(n: float) -> str:
    """Env steps in short: 240000 -> 240k, 3000000 -> 3M."""
    return f"{n / 1e6:.3g}M" if n >= 1e6 else f"{n / 1e3:.3g}k" if n >= 1e3 else f"{n:.0f}"


def with_stages(plan: pd.DataFrame, stacked: pd.DataFrame, trends: pd.DataFrame) -> pd.DataFrame:
    """``plan`` with :data:`STAGE_PLAN_COLUMNS` from the claims along training (``stacked``: claims_by_stage.parquet,
    ``trends``: claims_trends.parquet); a part they do not hold gets empty cells."""
    effects = {key: ", ".join(f"{_steps(r.env_steps)}: {r.effect:.3g}" for r in rows.sort_values("env_steps")
                              .itertuples(index=False))
               for key, rows in stacked.groupby(["claim", "part"], sort=False)}
    trend = {(r.claim, r.part): r.trend for r in trends.itertuples(index=False)}
    keys = list(zip(plan["claim"], plan["part"], strict=True))
    return plan.assign(stage_effects=[effects.get(k, "") for k in keys], trend=[trend.get(k, "") for k in keys])


def read_run(run: Run, alpha: float, episodes: tuple[float, float] = (np.nan, np.nan)
             ) -> tuple[dict[int, pd.DataFrame], RunCosts]:
    """A finished run's parts tables (the selected seed's first, then the other top seeds' that exist, in ranking
    order) and its :class:`RunCosts` (``episodes``: the selected seed's and the reruns' episodes per condition);
    one clear error for a run without claims or a ranking."""
    from ..io import read_parquet

    for needed, what in ((RANKING, "seed ranking"), (CLAIM_PARTS, "claims' parts table")):
        if not run.path(needed).is_file():
            raise ValueError(f"no {what} at {run.path(needed)}: run the pipeline (or efish claims) first")
    ranking = [int(s) for s in read_parquet(run.path(RANKING), "the seed ranking")["seed"]]
    tables = {ranking[0]: read_parquet(run.path(CLAIM_PARTS), "the selected seed's parts table")}
    for seed in ranking[1:]:
        if (path := run.top_seed(seed).path(CLAIM_PARTS)).is_file():
            tables[seed] = read_parquet(path, f"seed {seed}'s parts table")
    return tables, run_costs(run, ranking, len(tables) - 1, episodes)


def target_line() -> str:
    """The planner's question in one line, for a table's caption."""
    return (f"seeds for a {TARGET:.0%} chance that the recipe's verdict settles: holds if the true effect is twice "
            "delta, absent if there is none")
