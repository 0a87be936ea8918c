"""What a decisive recipe verdict would cost, part by part, from a finished run's own tables.

For every part the recipe decides over seeds, the run's seeds give its variance components
(:func:`efish.claims.power.components`: the seeds' effects and their own standard errors, read back from their
intervals), and :mod:`efish.claims.power` gives the chance that the recipe's decision settles, now and for
more seeds, in the planner's two scenarios (an effect of twice delta, no effect). The run's own Snakemake
benchmark files price a design (:func:`run_costs`): a seed costs its training, its selection episodes and its
reruns of the claims' assays, all measured in this run on this machine. Only what is reported beside a verdict
changes: no verdict rule reads this.

Pure pandas: it reads claim_parts tables and benchmark files, never the simulator.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd

from ..layout import Run, seed_name, selection_table, top_seed_copy, training_folder
from .power import MAX_SEEDS, SCENARIOS, TARGET, components, decision_probabilities, scenario_verdict, seeds_needed
from .power import standard_error as interval_se
from .recipe import FISHER_Z, fisher_z
from .verdicts import interval_level

__all__ = ["PLAN_COLUMNS", "RunCosts", "plan_parts", "run_costs"]

#: One row per part: the run's design (seeds, mean units per seed), the variance components, the chance of each
#: scenario's verdict now and the seeds (and CPU-hours) that reach :data:`~efish.claims.power.TARGET`.
PLAN_COLUMNS = ["claim", "part", "sign", "delta", "seeds", "units", "effect", "tau", "sigma",
                "now_holds_at_2delta", "now_absent_at_0", "seeds_holds_at_2delta", "seeds_absent_at_0",
                "cpu_hours_holds_at_2delta", "cpu_hours_absent_at_0", "note"]


class RunCosts(NamedTuple):
    """What one more seed costs in this run, in CPU-seconds: its training, its selection episodes, and its reruns of
    the claims' assays at the run's episodes (``rerun_s``, from the other top seeds' jobs); ``seeds_timed`` says how
    many seeds each mean is over."""

    train_s: float
    selection_s: float
    rerun_s: float
    seeds_timed: str

    def design_hours(self, seeds: int | None) -> float:
        """CPU-hours of a design of ``seeds`` seeds at the run's episodes (NaN when no design reaches it)."""
        return np.nan if seeds is None else seeds * (self.train_s + self.selection_s + self.rerun_s) / 3600


def _cpu_seconds(path: Path) -> float:
    """A Snakemake benchmark file's CPU time (its last row; wall seconds where it has no cpu_time)."""
    row = pd.read_csv(path, sep="\t").iloc[-1]
    value = row.get("cpu_time", np.nan)
    return float(value) if pd.notna(value) and float(value) > 0 else float(row["s"])


def run_costs(run: Run, seeds: Sequence[int], other_top_seeds: int) -> RunCosts:
    """The run's measured cost of a seed, from its Snakemake benchmark files (:meth:`efish.layout.Run.benchmark`):
    the mean CPU time of the ``seeds``' training and selection jobs, and of everything the top seeds' reruns ran
    (every file in a folder of its own under the top seeds' benchmarks, however the workflow grouped them) over
    ``other_top_seeds``. One clear error when a run has no training benchmarks."""
    train = [p for s in seeds if (p := run.benchmark(training_folder(seed_name(s)))).exists()]
    if not train:
        raise ValueError(f"no training benchmarks under {run.benchmarks}: the planner prices a design with the "
                         "run's own job times (run the pipeline first)")
    selection = [p for s in seeds if (p := run.benchmark(str(Path(selection_table(s, "x")).parent))).exists()]
    top_seeds = run.benchmarks / Path(top_seed_copy(0)).parent  # each seed's or group's jobs in a folder of its own
    reruns = list(top_seeds.glob("*/**/*.tsv")) if top_seeds.is_dir() else []
    rerun_s = sum(map(_cpu_seconds, reruns)) / other_top_seeds if other_top_seeds and reruns else 0.0
    return RunCosts(float(np.mean([_cpu_seconds(p) for p in train])),
                    float(np.mean([_cpu_seconds(p) for p in selection])) if selection else 0.0, float(rerun_s),
                    f"training {len(train)}, selection {len(selection)}, reruns of {other_top_seeds} seeds")


def _seed_values(rows: pd.DataFrame, alpha: float, correlation: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The seeds' effects, standard errors (from each interval at its level, 1 - 2 alpha / family) and units, on
    the scale the recipe decides on (Fisher's z for a correlation)."""
    effect, low, high = (rows[c].astype(float).to_numpy() for c in ("effect", "ci_low", "ci_high"))
    if correlation:
        effect, low, high = (fisher_z(v) for v in (effect, low, high))
    ses = np.array([interval_se(lo, hi, interval_level(alpha, int(f)))
                    for lo, hi, f in zip(low, high, rows["family"], strict=True)])
    return effect, ses, rows["n"].astype(float).to_numpy()


def plan_part(rows: pd.DataFrame, alpha: float, costs: RunCosts) -> dict:
    """One row of :data:`PLAN_COLUMNS` for one part (``rows``: its claim_parts rows over the seeds, with effect,
    interval, n, family, sign, delta and ci_method)."""
    first = rows.iloc[0]
    sign = None if pd.isna(first["sign"]) else int(first["sign"])
    out = dict.fromkeys(PLAN_COLUMNS, np.nan) | {"claim": first["claim"], "part": first["part"],
                                                 "sign": first["sign"], "note": ""}
    use = rows[np.isfinite(rows["effect"].astype(float)) & np.isfinite(rows["delta"].astype(float))
               & (rows["verdict"] != "not run")]
    out["seeds"] = len(use)
    if len(use) < 2:
        return out | {"note": f"{len(use)} seed(s) carry an effect and a delta: no spread over seeds to plan from"}
    correlation = use["ci_method"].astype(str).str.contains(FISHER_Z).any()
    family = int(use["family"].max())
    delta = float(np.nanmedian(use["delta"].astype(float)))
    effect, ses, units = _seed_values(use, alpha, correlation)
    finite = np.isfinite(ses)
    notes = []
    if finite.sum() >= 2:
        comp = components(effect[finite], ses[finite], units[finite])._replace(effect=float(effect.mean()),
                                                                                seeds=len(use))
    else:  # no usable interval (unbounded rank intervals): all the spread counted as between seeds
        comp = components(effect, np.zeros_like(effect), units)
        notes.append("seeds' intervals unbounded: all spread counted as between seeds")
    planned_delta = float(fisher_z(delta)) if correlation else delta
    if not comp.seed_sd() > 0:
        return out | {"delta": delta, "units": comp.units, "effect": comp.effect, "tau": comp.tau,
                      "sigma": comp.sigma, "note": "every seed gave the same effect: no spread to plan from"}
    out.update(delta=delta, units=comp.units, effect=float(np.tanh(comp.effect)) if correlation else comp.effect,
               tau=comp.tau, sigma=comp.sigma)
    for (name, multiple, sought), key in zip(SCENARIOS, ("holds_at_2delta", "absent_at_0"), strict=True):
        verdict = scenario_verdict(sign, sought)
        theta = multiple * planned_delta * (-1 if sign is not None and sign < 0 else 1)
        now = decision_probabilities(theta, comp.seed_sd(), comp.seeds, sign, planned_delta, alpha, family)
        k = seeds_needed(comp, sign, planned_delta, alpha, theta, verdict, family)
        out[f"now_{key}"] = now[verdict]
        out[f"seeds_{key}"] = np.nan if k is None else k
        out[f"cpu_hours_{key}"] = costs.design_hours(k)
        if k is None:
            notes.append(f"{name}: not within {MAX_SEEDS} seeds")
    if correlation:
        notes.append("planned on Fisher's z scale")
    return out | {"note": "; ".join(notes)}


def plan_parts(parts_by_seed: Mapping[int, pd.DataFrame], alpha: float, costs: RunCosts) -> pd.DataFrame:
    """One row per part of the selected seed's claims (the first table of ``parts_by_seed``), planned over every
    seed's claim_parts rows of that part (:func:`plan_part`)."""
    order = list(parts_by_seed)
    stacked = pd.concat([parts_by_seed[s].assign(seed=s) for s in order], ignore_index=True)
    rows = [plan_part(group, alpha, costs) for (_, _), group in stacked.groupby(["claim", "part"], sort=False)
            if group["seed"].iloc[0] == order[0]]
    return pd.DataFrame(rows, columns=PLAN_COLUMNS)


def target_line() -> str:
    """The planner's question in one line, for a table's caption."""
    return (f"seeds for a {TARGET:.0%} chance that the recipe's verdict settles: holds if the true effect is twice "
            "delta, absent if there is none")
