"""The training recipe's verdict: each part's effect over the top seeds, seed as a random effect.

Training is chaotic: the same recipe on another CPU, or with another seed, is
another draw of the policy, so one seed's verdict is one draw. The recipe's
verdict asks whether the effect holds for the recipe, over the draws the run
made: the selected seed and the other ``scale.top_seeds`` best-ranked seeds,
each of which computes every claim (``claim_parts.parquet``).

For each part, the seeds' effects ``y_1..y_k`` (each the seed's own estimate
over its episodes, in the part's units; a correlation on Fisher's z scale) are
combined by the two-stage random-effects test (the summary-statistics approach
of group analyses): the recipe's effect is their mean, its standard error their
SD over sqrt(k), tested by t with k - 1 degrees of freedom (where every seed
gave the same effect, e.g. one pellet, t is undefined and the exact sign test
of k seeds on one side decides: p = 2 / 2^k). It is the
Hartung-Knapp-Sidik-Jonkman random-effects meta-analysis with equal weights:
the seeds' per-seed standard errors are not needed, which matters because a
rank test's interval at a few episodes can be unbounded; and the variance of
the seeds' effects estimates the variance of their mean without bias even when
seeds differ in precision (fewer episodes for the non-selected ones). Seed
heterogeneity widens the interval: seeds with opposite effects give a mean
near 0 with a wide interval, never "holds".

The same rules as a seed's verdict (:func:`efish.claims.verdicts.judge`):
holds = the paper's sign and p < alpha, where p is multiplied by the part's
Holm family size (Bonferroni, the bound Holm's step-down is at most: the
seeds' families cannot be re-ranked from pooled p's one part at a time) and
the interval is at level 1 - alpha / family; a "no difference" part holds when
the TOST (t, k - 1 df) within the seeds' median margin gives p < alpha. A seed
counts for a part when its effect is finite and its verdict is holds, weaker,
fails, or not decidable *only* because its n could not reach significance (the
recipe pools what one seed could not carry); a seed where the part did not run
or the data could not carry it (a ceiling, a floor) is left out and named.
Fewer than :data:`MIN_SEEDS` seeds: the recipe's part is not decidable (a seed
was at a ceiling or floor) or not run. A claim no other seed runs at all (the
homing claims, whose policies are trained once and not per seed) keeps the
selected seed's parts, marked as one draw; a run with no other top seed decides
no recipe part (each is not run, or not decidable where the seed's was). The claim's recipe verdict combines its
parts' by :func:`~efish.claims.verdicts.combined_verdict`.

Pure pandas and scipy: it reads claim_parts tables, never the simulator.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

import numpy as np
import pandas as pd
from scipy import stats

from .seeds import seed_list
from .verdicts import NAN_CI, PART_COLUMNS, Part, combine, judge, unreachable

__all__ = ["MIN_SEEDS", "RECIPE_COLUMNS", "RECIPE_PART_COLUMNS", "decide", "recipe_parts", "pooled",
           "with_recipe_verdicts"]

#: The fewest seeds whose effects a recipe part combines (a t-test over seeds needs two).
MIN_SEEDS = 2
#: One row per (claim, part) of :func:`recipe_parts`: the part as the seeds decide it together. ``n`` is the
#: number of seeds combined, ``seeds`` lists them, ``seed_effects`` their effects in the seeds' order, ``tau``
#: the SD of the seeds' effects (the heterogeneity the interval carries), ``ci_method`` how the interval is made.
RECIPE_PART_COLUMNS = ["claim", "part", "statistic", "sign", "effect", "ci_low", "ci_high", "ci_method", "n", "p",
                       "family", "tau", "margin", "verdict", "decides", "seeds", "seed_effects", "reason"]
#: The columns :func:`with_recipe_verdicts` adds to a claims table, right before the selected seed's ``statistic``.
RECIPE_COLUMNS = ["recipe_verdict", "recipe_effect", "recipe_ci_low", "recipe_ci_high", "recipe_p", "recipe_seeds",
                  "recipe_reason"]
FISHER_Z = "Fisher-z"  # a part whose interval inverts Fisher's z is a correlation: combined on the z scale
DECIDED = ("holds", "weaker", "fails")


class Pooled(NamedTuple):
    """The seeds' mean effect and its t-test (:func:`pooled`); ``tau`` is the SD of the seeds' effects."""

    effect: float
    low: float
    high: float
    p: float
    tau: float


def pooled(effects, alpha: float, family: int = 1, correlation: bool = False, excess: bool = False) -> Pooled:
    """The recipe's effect over the seeds' ``effects``: their mean, tested against 0 by t with k - 1 df, the p
    multiplied by ``family`` (capped at 1) and the interval at level 1 - alpha / family. A ``correlation`` is
    averaged on Fisher's z scale and the mean and interval are returned as correlations.

    ``excess``: the effects are a statistic's excess over its null expectation, where every departure from the
    null raises the statistic (an "any difference" part: Kendall's W - 1/n of a Friedman test, whose own test is
    its upper tail). A mean below 0 is then no evidence of a difference, and the p counts only the upper side:
    twice the upper one-sided p (the two-sided p when the mean is above 0, 1 otherwise), so that the part holds
    exactly when the interval lies above 0. Under the null such seeds' effects are skewed to the right, and a
    two-sided t-test rejects on the lower side about as often as the whole alpha, on the upper side less often
    (simulated with no effect at 4-6 seeds: 0.9-1.7% of runs at alpha 0.05).

    >>> [round(v, 3) for v in pooled([0.4, 0.6, 0.5], 0.05)[:4]]
    [0.5, 0.252, 0.748, 0.013]
    >>> pooled([-0.4, -0.6, -0.5], 0.05, excess=True).p
    1.0
    """
    y = np.asarray(effects, np.float64)
    if y.size < MIN_SEEDS or not np.isfinite(y).all():
        raise ValueError(f"a t-test over seeds needs {MIN_SEEDS} finite effects, got {y.tolist()}")
    if correlation:
        y = np.arctanh(np.clip(y, -0.999, 0.999))  # a seed at |rho| = 1 stays finite on the z scale
    k, mean, sd = y.size, float(y.mean()), float(y.std(ddof=1))
    se = sd / np.sqrt(k)
    below = excess and mean <= 0  # an excess at or below its null expectation: no difference shown
    if se == 0:  # every seed gave the same effect (a discrete one, e.g. one pellet): t is undefined, so the exact
        p = 1.0 if mean == 0 or below else float(min(1.0, family * 2 * 0.5 ** k))  # sign test, k on one side
    else:
        p = 1.0 if below else float(min(1.0, family * 2 * stats.t.sf(abs(mean) / se, k - 1)))
    half = float(stats.t.ppf(1 - alpha / (2 * family), k - 1)) * se
    low, high = mean - half, mean + half
    back = np.tanh if correlation else float
    return Pooled(float(back(mean)), float(back(low)), float(back(high)), p, sd)


def tost_over_seeds(effects, margin: float) -> float:
    """The TOST p that the seeds' mean effect lies within +-``margin``: the larger of the two one-sided t-tests,
    k - 1 df (0 when every seed's effect is the same and inside the margin)."""
    y = np.asarray(effects, np.float64)
    mean, se = float(y.mean()), float(y.std(ddof=1)) / np.sqrt(y.size)
    if se == 0:  # every seed the same effect: the exact sign test that all k lie inside the margin
        return float(min(1.0, 0.5 ** y.size)) if abs(mean) < margin else 1.0
    df = y.size - 1
    return float(max(stats.t.sf((mean + margin) / se, df), stats.t.sf((margin - mean) / se, df)))


class Decision(NamedTuple):
    """A part decided over the seeds (:func:`decide`): the t-test over their effects, the p the verdict rests on
    (the TOST p of a "no difference" part), the verdict and its reason."""

    pooled: Pooled
    p: float
    verdict: str
    why: str


def decide(effects, sign: int | None, alpha: float, family: int = 1, correlation: bool = False,
           margin: float = np.nan) -> Decision:
    """The verdict over the seeds' ``effects`` of a part with the paper's ``sign``, by the rules of a seed's parts
    (:func:`~efish.claims.verdicts.judge`): the t-test of :func:`pooled` (its upper side for an "any difference"
    part, sign None, whose effect is an excess over its null expectation); for a "no difference" part (sign 0)
    the TOST over seeds within ``margin``, not decidable where even a zero mean with the seeds' spread could not
    be shown equivalent (:func:`~efish.claims.verdicts.unreachable`)."""
    y = np.asarray(effects, np.float64)
    found = pooled(y, alpha, family, correlation, excess=sign is None)
    p_equiv, p_zero = np.nan, 0.0
    if sign == 0 and np.isfinite(margin):
        z = np.arctanh(np.clip(y, -0.999, 0.999)) if correlation else y
        p_equiv = tost_over_seeds(z, margin)
        p_zero = tost_over_seeds(z - z.mean(), margin)  # the TOST p a zero mean with the seeds' spread gives
    verdict, why = judge(found.effect, found.p, sign, alpha, p_equiv, margin)
    if unreachable(verdict, p_zero, alpha, sign):
        verdict, why = "not decidable", (f"the margin +-{margin:.3g} cannot be shown over {y.size} seeds: a zero "
                                         f"mean with the seeds' spread gives a TOST p of {p_zero:.3g}; {why}")
    return Decision(found, found.p if sign != 0 or not np.isfinite(p_equiv) else p_equiv, verdict, why)


def _usable(rows: pd.DataFrame, alpha: float) -> pd.Series:
    """Whether each seed's part enters the recipe: a finite effect, decided, or not decidable only because its n
    cannot reach significance (``p_floor`` >= alpha; a ceiling or floor has no effect, or a lower p_floor)."""
    too_small = (rows["verdict"] == "not decidable") & (rows["p_floor"].astype(float) >= alpha)
    return np.isfinite(rows["effect"].astype(float)) & (rows["verdict"].isin(DECIDED) | too_small)


def _recipe_part(rows: pd.DataFrame, selected: int, alpha: float) -> tuple[Part, float]:
    """One part over the seeds (``rows``: its claim_parts rows with a ``seed`` column, the selected seed first),
    and the SD of the seeds' effects."""
    first = rows.iloc[0]
    sign = None if pd.isna(first["sign"]) else int(first["sign"])
    use = _usable(rows, alpha)
    taken, left = rows[use], rows[~use]
    left_out = "; ".join(f"seed {int(s)}: {v}" for s, v in zip(left["seed"], left["verdict"], strict=True))
    label, statistic, decides = str(first["part"]), str(first["statistic"]), bool(first["decides"])
    if len(taken) < MIN_SEEDS:
        verdict = "not decidable" if (rows["verdict"] == "not decidable").any() else "not run"
        return Part(label, statistic, n=len(taken), verdict=verdict, decides=decides, sign=sign,
                    reason=f"{len(taken)} of {len(rows)} seeds carry an effect (a test over seeds needs "
                           f"{MIN_SEEDS})" + (f"; left out: {left_out}" if left_out else "")), np.nan
    family = int(taken["family"].max())
    correlation = taken["ci_method"].astype(str).str.contains(FISHER_Z).any()
    y = taken["effect"].to_numpy(np.float64)
    margin = float(np.nanmedian(taken["margin"].astype(float))) if taken["margin"].notna().any() else np.nan
    found = decide(y, sign, alpha, family, correlation, margin)
    (effect, low, high, _, tau), verdict, why = found.pooled, found.verdict, found.why
    notes = [why, seed_list([int(s) for s in taken["seed"]], selected)]
    if left_out:
        notes.append(f"left out: {left_out}")
    method = (f"t over {len(taken)} seeds' effects{' on the Fisher-z scale' if correlation else ''}"
              + (f", Bonferroni over {family}" if family > 1 else "")
              + ("; p of the upper side (an excess over its null expectation)" if sign is None else ""))
    return Part(label, statistic, effect, (low, high) if np.isfinite([low, high]).all() else NAN_CI,
                len(taken), found.p, verdict, "; ".join(n for n in notes if n), decides, sign, method,
                margin if sign == 0 else np.nan, family=family, p_floor=np.nan), tau


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
                     "p": found.p, "family": found.family, "tau": tau, "margin": found.margin,
                     "verdict": found.verdict, "decides": found.decides,
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
            "margin": row["margin"], "verdict": row["verdict"], "decides": bool(row["decides"]),
            "seeds": str(int(row["seed"])), "seed_effects": f"{row['effect']:.3g}",
            "reason": "; ".join(r for r in (note, row["reason"]) if isinstance(r, str) and r)}


def _as_part(row: pd.Series) -> Part:
    return Part(row["part"], row["statistic"], row["effect"], (row["ci_low"], row["ci_high"]), int(row["n"]),
                row["p"], row["verdict"], row["reason"], bool(row["decides"]),
                None if pd.isna(row["sign"]) else int(row["sign"]), row["ci_method"])


def with_recipe_verdicts(table: pd.DataFrame, recipe: pd.DataFrame) -> pd.DataFrame:
    """The claims table with :data:`RECIPE_COLUMNS` before ``statistic``: each claim's recipe verdict (its
    recipe parts combined as a seed's parts are), the effect, interval and p of the part the row shows, the
    number of seeds, and the reason. A claim with no recipe part is not run there."""
    out = table.drop(columns=[c for c in RECIPE_COLUMNS if c in table.columns]).reset_index(drop=True)
    rows = []
    for claim, panel in zip(out["claim"], out["panel"], strict=True):
        mine = recipe[recipe["claim"] == claim]
        if mine.empty:
            rows.append({"verdict": "not run", "effect": np.nan, "ci_low": np.nan, "ci_high": np.nan, "p": np.nan,
                         "n": 0, "reason": "no seed's parts"})
            continue
        rows.append(combine(claim, panel, [_as_part(r) for _, r in mine.iterrows()]))
    at = list(out.columns).index("statistic")
    for i, name in enumerate(RECIPE_COLUMNS):
        key = "n" if name == "recipe_seeds" else name.removeprefix("recipe_")
        out.insert(at + i, name, [r[key] for r in rows])
    return out.astype({"recipe_seeds": "int64"})
