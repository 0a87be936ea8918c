"""The training recipe's verdict: each part's effect over the top seeds, seed as a random effect.

Training is chaotic: the same recipe on another CPU, or with another seed, is
another draw of the policy, so one seed's verdict is one draw. The recipe's
verdict asks whether the effect holds for the recipe, over the draws the run
made: the selected seed and the other ``scale.top_seeds`` best-ranked seeds,
each of which computes every claim (``claim_parts.parquet``).

For each part, the seeds' effects ``y_1..y_k`` (each the seed's own estimate
over its episodes, in the part's units; a correlation on Fisher's z scale, its
delta too) are combined by the two-stage random-effects summary (the
summary-statistics approach of group analyses): the recipe's effect is their
mean and its interval the t interval over seeds at level 1 - 2 alpha / family
(:func:`efish.claims.decision.over_seeds`; ``family`` the part's Bonferroni
share, as a seed's interval), which covers its level at 4-10 seeds where a
percentile bootstrap covered 80-90%. It is the Hartung-Knapp-Sidik-Jonkman
random-effects meta-analysis with equal weights: the seeds' per-seed standard
errors are not needed (a rank test's interval at a few episodes can be
unbounded), and seed heterogeneity widens the interval: seeds with opposite
effects give a mean near 0 with a wide interval, never "holds".

The part is decided against its smallest effect of interest by the rules of a
seed's parts (:func:`efish.claims.decision.decide`; delta the median of the
seeds' deltas, which differ where delta is relative to each seed's reference
median), and the claim's recipe verdict combines its parts by
:func:`~efish.claims.verdicts.claim_verdict` (Holm over the parts' p of "beyond
delta the other way", :attr:`~efish.claims.decision.SeedsDecision.p_opposite`).
The ``p`` column is the t-test of the seeds' mean against 0 (times ``family``;
information, not what the verdict rests on).

A seed counts for a part when its effect is finite and the part ran there (a
seed at a ceiling or floor has no effect and is left out and named). Fewer than
:data:`MIN_SEEDS` seeds: the recipe's part is not decidable (a seed was) or not
run. A claim no other seed runs at all (the homing claims, whose policies are
trained once and not per seed) keeps the selected seed's parts, marked as one
draw; a run with no other top seed decides no recipe part (each is not run, or
not decidable where the seed's was).

Pure pandas and scipy: it reads claim_parts tables, never the simulator.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

import numpy as np
import pandas as pd
from scipy import stats

from .decision import SeedsDecision, over_seeds
from .seeds import seed_list
from .verdicts import NAN_CI, PART_COLUMNS, Part, combine

__all__ = ["MIN_SEEDS", "RECIPE_COLUMNS", "RECIPE_PART_COLUMNS", "pooled", "recipe_parts", "with_recipe_verdicts"]

#: The fewest seeds whose effects a recipe part combines (a t interval over seeds needs two).
MIN_SEEDS = 2
#: One row per (claim, part) of :func:`recipe_parts`: the part as the seeds decide it together. ``n`` is the
#: number of seeds combined, ``seeds`` lists them, ``seed_effects`` their effects in the seeds' order, ``tau``
#: the SD of the seeds' effects (the heterogeneity the interval carries), ``ci_method`` how the interval is made,
#: ``delta`` the smallest effect of interest it is decided against and ``p_opposite`` its one-sided p of "beyond
#: delta against the paper".
RECIPE_PART_COLUMNS = ["claim", "part", "statistic", "sign", "effect", "ci_low", "ci_high", "ci_method", "n", "p",
                       "family", "tau", "delta", "p_opposite", "verdict", "decides", "seeds", "seed_effects",
                       "reason"]
#: The columns :func:`with_recipe_verdicts` adds to a claims table, right before the selected seed's ``statistic``.
RECIPE_COLUMNS = ["recipe_verdict", "recipe_parts", "recipe_effect", "recipe_ci_low", "recipe_ci_high", "recipe_p",
                  "recipe_seeds", "recipe_reason"]
FISHER_Z = "Fisher-z"  # a part whose interval inverts Fisher's z is a correlation: combined on the z scale


def fisher_z(r):
    """Fisher's z of correlations (arrays or floats), a seed at |rho| = 1 kept finite (clipped to 0.999)."""
    return np.arctanh(np.clip(r, -0.999, 0.999))



class Pooled(NamedTuple):
    """A part over the seeds (:func:`pooled`): the decision of the seeds' effects (mean, interval, verdict,
    p of "beyond delta the other way"), the t-test p of their mean against 0, and ``tau``, their SD."""

    decision: SeedsDecision
    p: float
    tau: float


def pooled(effects, sign: int | None, delta: float, alpha: float, family: int = 1,
           correlation: bool = False) -> Pooled:
    """The recipe's part over the seeds' ``effects``: :func:`efish.claims.decision.over_seeds` against ``delta``
    (a ``correlation`` and its delta on Fisher's z scale, the mean and interval returned as correlations) and the
    two-sided t-test of the mean against 0, its p times ``family`` (capped at 1; 1 where every seed gave 0).

    >>> found = pooled([0.4, 0.6, 0.5], +1, 0.1, 0.05)
    >>> found.decision.decision, [round(v, 3) for v in found.decision[:3]], round(found.p, 3)
    ('holds', [0.5, 0.331, 0.669], 0.013)
    """
    y = np.asarray(effects, np.float64)
    if y.size < MIN_SEEDS or not np.isfinite(y).all():
        raise ValueError(f"a t interval over seeds needs {MIN_SEEDS} finite effects, got {y.tolist()}")
    if correlation:  # a seed at |rho| = 1 stays finite on the z scale
        y, delta = fisher_z(y), float(fisher_z(delta))
    found = over_seeds(y, sign, delta, alpha, family)
    se = float(y.std(ddof=1)) / np.sqrt(y.size)
    if se > 0:
        p = float(min(1.0, family * 2 * stats.t.sf(abs(y.mean()) / se, y.size - 1)))
    else:  # every seed the same effect: t is undefined; the exact sign test of k seeds on one side
        p = 1.0 if y.mean() == 0 else float(min(1.0, family * 2 * 0.5 ** y.size))
    if correlation:
        found = found._replace(effect=float(np.tanh(found.effect)), low=float(np.tanh(found.low)),
                               high=float(np.tanh(found.high)))
    return Pooled(found, p, float(y.std(ddof=1)))


def _recipe_part(rows: pd.DataFrame, selected: int, alpha: float) -> tuple[Part, float]:
    """One part over the seeds (``rows``: its claim_parts rows with a ``seed`` column, the selected seed first),
    and the SD of the seeds' effects."""
    first = rows.iloc[0]
    sign = None if pd.isna(first["sign"]) else int(first["sign"])
    use = np.isfinite(rows["effect"].astype(float)) & (rows["verdict"] != "not run")
    taken, left = rows[use], rows[~use]
    left_out = "; ".join(f"seed {int(s)}: {v}" for s, v in zip(left["seed"], left["verdict"], strict=True))
    label, statistic, decides = str(first["part"]), str(first["statistic"]), bool(first["decides"])
    deltas = taken["delta"].astype(float)
    if len(taken) < MIN_SEEDS or not np.isfinite(deltas).any():
        verdict = "not decidable" if (rows["verdict"] == "not decidable").any() else "not run"
        return Part(label, statistic, n=len(taken), verdict=verdict, decides=decides, sign=sign,
                    reason=f"{len(taken)} of {len(rows)} seeds carry an effect (a t interval over seeds needs "
                           f"{MIN_SEEDS})" + (f"; left out: {left_out}" if left_out else "")), np.nan
    family = int(taken["family"].max())
    correlation = taken["ci_method"].astype(str).str.contains(FISHER_Z).any()
    delta = float(np.nanmedian(deltas))
    found = pooled(taken["effect"].to_numpy(np.float64), sign, delta, alpha, family, correlation)
    d = found.decision
    level = 1 - 2 * alpha / family
    notes = [f"{level:.3g} t interval against delta {delta:.3g}", seed_list([int(s) for s in taken["seed"]], selected)]
    if left_out:
        notes.append(f"left out: {left_out}")
    method = (f"t over {len(taken)} seeds' effects, level {level:.3g}"
              + (" on the Fisher-z scale" if correlation else "") + (f" (Bonferroni over {family})" if family > 1 else ""))
    interval = (d.low, d.high) if np.isfinite([d.low, d.high]).all() else NAN_CI
    return Part(label, statistic, d.effect, interval, len(taken), found.p, d.decision, "; ".join(notes), decides,
                sign, method, family=family, delta=delta, p_opposite=d.p_opposite), found.tau


def recipe_parts(parts_by_seed: Mapping[int, pd.DataFrame], selected: int, alpha: float) -> pd.DataFrame:
    """One row per part of the selected seed's claims (:data:`RECIPE_PART_COLUMNS`): the part decided over every
    seed's ``claim_parts`` table (``parts_by_seed``: seed -> table of
    :data:`~efish.claims.verdicts.PART_COLUMNS`; the selected seed's must be there). A part a seed lacks counts as
    not run there."""
    if selected not in parts_by_seed:
        raise ValueError(f"the selected seed {selected} has no claim_parts table")
    for seed, table in parts_by_seed.items():
        if missing := [c for c in PART_COLUMNS if c not in table.columns]:
            raise ValueError(f"seed {seed}'s claim_parts table lacks columns {missing}: rerun its claims "
                             "(efish claims) with this efish version")
    order = [selected, *[s for s in parts_by_seed if s != selected]]
    stacked = pd.concat([parts_by_seed[s].assign(seed=s) for s in order], ignore_index=True)
    others_ran = set(stacked.loc[(stacked["seed"] != selected) & (stacked["verdict"] != "not run"), "claim"])
    rows = []
    for (claim, part), group in stacked.groupby(["claim", "part"], sort=False):
        if group["seed"].iloc[0] != selected:
            continue  # a part only another seed has: the selected seed's claims set the list
        if len(order) > 1 and claim not in others_ran:  # other seeds ran, not this claim (homing): one draw
            rows.append(_one_draw(group.iloc[0]))
            continue
        missing = [s for s in order if s not in set(group["seed"])]
        group = pd.concat([group, pd.DataFrame({"claim": claim, "part": part, "seed": missing, "verdict": "not run",
                                                "effect": np.nan, "p_floor": np.nan})], ignore_index=True)
        group = group.assign(statistic=group["statistic"].iloc[0], sign=group["sign"].iloc[0],
                             decides=group["decides"].iloc[0])
        found, tau = _recipe_part(group, selected, alpha)
        rows.append({"claim": claim, "part": found.label, "statistic": found.statistic,
                     "sign": np.nan if found.sign is None else float(found.sign), "effect": found.effect,
                     "ci_low": found.ci[0], "ci_high": found.ci[1], "ci_method": found.ci_method, "n": found.n,
                     "p": found.p, "family": found.family, "tau": tau, "delta": found.delta,
                     "p_opposite": found.p_opposite, "verdict": found.verdict, "decides": found.decides,
                     "seeds": ", ".join(str(int(s)) for s in group["seed"]),
                     "seed_effects": ", ".join(f"{e:.3g}" for e in group["effect"].astype(float)),
                     "reason": found.reason})
    return pd.DataFrame(rows, columns=RECIPE_PART_COLUMNS).astype({"n": "int64", "family": "int64",
                                                                   "decides": bool})


def _one_draw(row: pd.Series) -> dict:
    """The recipe row of a part only the selected seed ran, because no other seed runs its claim (the homing
    claims: their policies are trained once, not per seed): that one draw's verdict, said to be one draw."""
    note = "one draw: no other seed runs this claim (its policies do not depend on the seed)"
    return {"claim": row["claim"], "part": row["part"], "statistic": row["statistic"], "sign": row["sign"],
            "effect": row["effect"], "ci_low": row["ci_low"], "ci_high": row["ci_high"],
            "ci_method": row["ci_method"], "n": 1, "p": row["p"], "family": int(row["family"]), "tau": np.nan,
            "delta": row["delta"], "p_opposite": row["p_opposite"], "verdict": row["verdict"], "decides": bool(row["decides"]),
            "seeds": str(int(row["seed"])), "seed_effects": f"{row['effect']:.3g}",
            "reason": "; ".join(r for r in (note, row["reason"]) if isinstance(r, str) and r)}


def _as_part(row: pd.Series) -> Part:
    return Part(row["part"], row["statistic"], row["effect"], (row["ci_low"], row["ci_high"]), int(row["n"]),
                row["p"], row["verdict"], row["reason"], bool(row["decides"]),
                None if pd.isna(row["sign"]) else int(row["sign"]), row["ci_method"], delta=row["delta"],
                p_opposite=row["p_opposite"])


def with_recipe_verdicts(table: pd.DataFrame, recipe: pd.DataFrame, alpha: float) -> pd.DataFrame:
    """The claims table with :data:`RECIPE_COLUMNS` before ``statistic``: each claim's recipe verdict (its
    recipe parts combined as a seed's parts are, :func:`~efish.claims.verdicts.claim_verdict` at ``alpha``), the
    tally of its parts' verdicts, the effect, interval and p of the part the row shows, the number of seeds, and
    the reason. A claim with no recipe part is not run there."""
    out = table.drop(columns=[c for c in RECIPE_COLUMNS if c in table.columns]).reset_index(drop=True)
    rows = []
    for claim, panel in zip(out["claim"], out["panel"], strict=True):
        mine = recipe[recipe["claim"] == claim]
        if mine.empty:
            rows.append({"verdict": "not run", "parts": "", "effect": np.nan, "ci_low": np.nan, "ci_high": np.nan,
                         "p": np.nan, "n": 0, "reason": "no seed's parts"})
            continue
        rows.append(combine(claim, panel, [_as_part(r) for _, r in mine.iterrows()], alpha))
    at = list(out.columns).index("statistic")
    for i, name in enumerate(RECIPE_COLUMNS):
        key = "n" if name == "recipe_seeds" else name.removeprefix("recipe_")
        out.insert(at + i, name, [r[key] for r in rows])
    return out.astype({"recipe_seeds": "int64"})
