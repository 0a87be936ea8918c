"""The claims along training: each part's effect at the kept training stages, and whether it is still moving.

Training keeps the selected seed's policy at a few stages (fractions of its env
steps); the claims' assays and analyses run again per stage and ``efish
claims`` writes each stage's parts table (``claim_parts.parquet``,
:data:`efish.claims.verdicts.PART_COLUMNS`). Here:

- :func:`claims_by_stage` stacks the stages' parts with each stage's env steps
  (and episodes per condition, so the table says when an early stage ran
  fewer): one row per (claim, part, stage);
- :func:`stage_trends` tests, per part, whether its effect moves toward the
  paper's sign, away from it, or neither (the test and why: its docstring);
- :func:`trend_lines` says so in one line per claim, for claims.md
  (:func:`efish.claims.report.along_training`).

Pure pandas and scipy: it reads tables, never the simulator.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
from scipy import stats as sps

__all__ = ["STAGE_COLUMNS", "TREND_COLUMNS", "TRENDS", "claims_by_stage", "stage_trends", "trend_lines",
           "wls_slope"]

#: The columns of a stacked table (:func:`claims_by_stage`); ``episodes`` (per condition) follows when given.
STAGE_COLUMNS = ["claim", "part", "stage", "env_steps", "effect", "ci_low", "ci_high", "n", "p", "verdict", "sign",
                 "family"]
#: What a stage's parts table must hold (efish claims' claim_parts.parquet).
_PART_NEEDS = ["claim", "part", "effect", "ci_low", "ci_high", "n", "p", "verdict", "sign", "family"]
TOWARD, STABLE, AWAY, UNDECIDED = TRENDS = ("moving toward the paper's sign", "stable", "moving away",
                                            "not decidable")
TREND_COLUMNS = ["claim", "part", "trend", "slope", "slope_ci_low", "slope_ci_high", "p", "test", "n_stages",
                 "reason"]
#: A trend needs this many stages with a finite effect and interval (two points always lie on a line).
MIN_STAGES = 3


# ------------------------------------------------------------------ stacking
def _by_stage(what: str, values: Mapping, stages: list[int]) -> dict[int, int]:
    """``values`` keyed by int stage, covering exactly ``stages``; ValueError naming what is missing or extra."""
    got = {int(k): int(v) for k, v in values.items()}
    if missing := sorted(set(stages) - set(got)):
        raise ValueError(f"no {what} for stages {missing} (the parts tables' stages are {stages})")
    if extra := sorted(set(got) - set(stages)):
        raise ValueError(f"{what} for stages {extra}, which have no parts table (stages {stages})")
    return got


def _check_parts(table: pd.DataFrame, stage: int) -> None:
    if missing := [c for c in _PART_NEEDS if c not in table.columns]:
        raise ValueError(f"stage {stage}'s table has no column {', '.join(missing)}: is it a parts table "
                         "(efish claims writes claim_parts.parquet)?")
    if (twice := table.duplicated(["claim", "part"])).any():
        pairs = sorted(map(tuple, table.loc[twice, ["claim", "part"]].to_numpy()))
        raise ValueError(f"stage {stage}'s parts table lists {pairs} twice")


def claims_by_stage(parts_by_stage: Mapping[int, pd.DataFrame], env_steps: Mapping[int, int],
                    episodes: Mapping[int, int] | None = None) -> pd.DataFrame:
    """The stages' parts tables stacked: one row per (claim, part, stage), columns :data:`STAGE_COLUMNS` (and
    ``episodes`` per condition when given), in the claims' order (C2 before C10), each claim's parts in the order
    the stages list them, stages ascending.

    ``parts_by_stage``: stage k -> its parts table (``claim_parts.parquet``); ``env_steps`` (and ``episodes``):
    stage k -> the env steps trained at that stage (the episodes per condition its assays ran). The stages' env
    steps must be positive and grow with k. A part that did not run at a stage keeps its row (NaN effect, its
    verdict), so the table says so; a part a stage's table lacks has no row there.
    """
    tables = {int(k): v for k, v in parts_by_stage.items()}
    stages = sorted(tables)
    if not stages:
        raise ValueError("no stage to stack")
    steps = _by_stage("env steps", env_steps, stages)
    counts = None if episodes is None else _by_stage("episodes", episodes, stages)
    ordered = [steps[k] for k in stages]
    if ordered[0] <= 0 or any(a >= b for a, b in zip(ordered, ordered[1:], strict=False)):
        raise ValueError(f"the env steps must be positive and grow with the stage: {steps}")
    frames = []
    for k in stages:
        _check_parts(tables[k], k)
        extra = {} if counts is None else {"episodes": counts[k]}
        frames.append(tables[k][_PART_NEEDS].assign(stage=k, env_steps=steps[k], **extra))
    out = pd.concat(frames, ignore_index=True)
    rank = {key: i for i, key in enumerate(dict.fromkeys(zip(out["claim"], out["part"], strict=True)))}
    order = pd.DataFrame({"number": out["claim"].str.extract(r"(\d+)$")[0].astype(float),
                          "claim": out["claim"], "part": [rank[k] for k in zip(out["claim"], out["part"], strict=True)],
                          "stage": out["stage"]})
    out = out.loc[order.sort_values(["number", "claim", "part", "stage"], kind="stable").index]
    columns = STAGE_COLUMNS + ["episodes"] * (counts is not None)
    return out[columns].reset_index(drop=True).astype({"stage": "int64", "env_steps": "int64", "sign": "float64"})


# ------------------------------------------------------------------ trends
def wls_slope(x, y, se) -> tuple[float, float, float]:
    """Weighted least-squares slope of ``y`` on ``x`` with weights 1 / ``se``^2, its standard error and the
    dispersion factor: the slope's SE is sqrt(1 / sum w (x - xbar)^2) (the points' SEs taken as known) times
    sqrt(max(1, chi^2 / (k - 2))), chi^2 the weighted residual sum of squares over k points, so that points
    scattered about the line beyond their intervals widen the slope's interval and never narrow it (the
    multiplicative dispersion of meta-regression). Returns (slope, its SE, the factor)."""
    x, y, w = (np.asarray(v, np.float64) for v in (x, y, 1 / np.asarray(se, np.float64) ** 2))
    xbar, ybar = np.average(x, weights=w), np.average(y, weights=w)
    sxx = float(np.sum(w * (x - xbar) ** 2))
    if sxx <= 0:
        raise ValueError("the stages share one env-step count")
    b = float(np.sum(w * (x - xbar) * (y - ybar)) / sxx)
    chi2 = float(np.sum(w * (y - ybar - b * (x - xbar)) ** 2))
    factor = max(1.0, chi2 / (len(x) - 2)) if len(x) > 2 else 1.0
    return b, float(np.sqrt(factor / sxx)), float(np.sqrt(factor))


def _paper_sign(signs: pd.Series) -> int | None:
    """The part's sign: the first finite one over its stages (a stage where it did not run has NaN), or None
    (the paper reports some difference, no direction)."""
    finite = signs[np.isfinite(signs.astype(np.float64))]
    return None if finite.empty else int(finite.iloc[0])


def _standard_errors(g: pd.DataFrame, claims_alpha: float) -> np.ndarray:
    """Each stage's standard error of the effect: its interval's half-width over the normal quantile of the
    interval's level, 1 - 2 ``claims_alpha`` / family (:func:`efish.claims.verdicts.interval_level`; a family of
    NaN, or none in the table, counts as 1)."""
    family = g["family"].astype(np.float64).fillna(1.0).to_numpy() if "family" in g else np.ones(len(g))
    half = (g["ci_high"] - g["ci_low"]).to_numpy(np.float64) / 2
    return half / sps.norm.ppf(1 - claims_alpha / family)


def _part_trend(g: pd.DataFrame, alpha: float, claims_alpha: float) -> dict:
    """One part's row of :data:`TREND_COLUMNS` (without claim and part) from its stages' rows."""
    sign = _paper_sign(g["sign"])
    absolute = sign in (0, None)
    response = "|effect|" if absolute else "effect"
    # the slope's sign that moves toward the paper: the paper's sign; a shrinking |effect| where the paper reports
    # no difference; a growing |effect| where it reports a difference of either sign
    toward = {None: +1, 0: -1}.get(sign, sign)
    se = _standard_errors(g, claims_alpha)
    ok = (np.isfinite(g[["effect", "ci_low", "ci_high"]].to_numpy(np.float64)).all(axis=1) & (se > 0)
          & (g["env_steps"].to_numpy(np.float64) > 0))
    row = {"trend": UNDECIDED, "slope": np.nan, "slope_ci_low": np.nan, "slope_ci_high": np.nan, "p": np.nan,
           "test": f"WLS slope of {response} on log10 env steps", "n_stages": int(ok.sum()), "reason": ""}
    if ok.sum() < MIN_STAGES:
        return {**row, "reason": f"{int(ok.sum())} of {len(g)} stages have a finite effect and a non-empty interval, "
                                 f"a trend needs {MIN_STAGES}"}
    effect = g["effect"].to_numpy(np.float64)[ok]
    try:
        b, se, factor = wls_slope(np.log10(g["env_steps"].to_numpy(np.float64)[ok]),
                                  np.abs(effect) if absolute else effect, se[ok])
    except ValueError as exc:
        return {**row, "reason": str(exc)}
    p = float(2 * sps.norm.sf(abs(b) / se))
    z = float(sps.norm.ppf(1 - alpha / 2))
    trend = STABLE if not p < alpha else TOWARD if b * toward > 0 else AWAY
    reason = f"stages scatter beyond their intervals: the slope's SE x {factor:.3g}" if factor > 1 else ""
    return {**row, "trend": trend, "slope": b, "slope_ci_low": b - z * se, "slope_ci_high": b + z * se, "p": p,
            "reason": reason}


def stage_trends(stacked: pd.DataFrame, alpha: float = 0.05, claims_alpha: float = 0.05) -> pd.DataFrame:
    """Per part of a stacked table (:func:`claims_by_stage`), whether its effect is still moving: one row of
    :data:`TREND_COLUMNS`, trend one of :data:`TRENDS`.

    The test: the weighted least-squares slope of the part's effect against log10 env steps, each stage weighted
    by 1 / SE^2 with SE = its interval's half-width over the normal quantile of the interval's level (1 - 2
    ``claims_alpha`` / family, ``analysis.claims_alpha``; the normal approximation), a two-sided z-test of the slope at ``alpha`` (``analysis.claims_trend_alpha``), and a 1 - alpha
    interval of it (:func:`wls_slope`, which widens the SE when the stages scatter beyond their intervals).
    Significant in the paper's sign: *moving toward the paper's sign*; significant against it: *moving away*;
    else *stable* (no trend this test can see). For a part the paper reports as no difference (sign 0) the
    response is |effect| and shrinking is toward the paper; for "any difference" (no sign) it is |effect| and
    growing is toward it. *not decidable* when fewer than 3 stages have a finite effect and a non-empty interval
    (or they share one env-step count).

    Why this test: with 3-5 stages a rank test cannot reach p < 0.05 at all (Spearman with 4 points has a
    smallest two-sided p of 0.083), and an unweighted regression of 3-5 effects throws away what each stage
    knows about its own precision. The stages' effects come from independent evaluation episodes, so given the
    policies their sampling errors are independent, and each stage's interval measures its own error:
    weighting by it lets a tight late stage count more than a noisy early one (an early stage may run fewer
    episodes). Log env steps because learning curves move by orders of magnitude of experience (stages at 1/4,
    1/2, 3/4, 1 of the steps). The folded |effect| of a sign-0 part is biased away from 0 near 0; it only makes
    shrinking harder to show.
    """
    missing = [c for c in ("claim", "part", "env_steps", "effect", "ci_low", "ci_high", "sign") if c not in stacked]
    if missing:
        raise ValueError(f"the stacked table has no column {', '.join(missing)}: is it claims_by_stage's?")
    rows = [{"claim": claim, "part": part, **_part_trend(g, alpha, claims_alpha)}
            for (claim, part), g in stacked.groupby(["claim", "part"], sort=False)]
    return pd.DataFrame(rows, columns=TREND_COLUMNS).astype({"n_stages": "int64"})


def _num(x: float) -> str:
    return f"{x:.3g}" if np.isfinite(x) else "NaN"


def _describe(row) -> str:
    """``trend (test slope [lo, hi], p p)``; ``not decidable (why)``."""
    if row.trend == UNDECIDED:
        return f"{row.trend} ({row.reason})"
    return (f"{row.trend} ({row.test} {_num(row.slope)} [{_num(row.slope_ci_low)}, {_num(row.slope_ci_high)}], "
            f"p {_num(row.p)})")


def trend_lines(trends: pd.DataFrame) -> dict[str, str]:
    """One line per claim of a trends table (:func:`stage_trends`), in its order, e.g. ``"C3 (alignment): moving
    toward the paper's sign (WLS slope of effect on log10 env steps 0.12 [0.05, 0.19], p 0.002)"``; a claim of
    several parts names each: ``"C5: agent: stable (...); food: moving away (...)"``."""
    if missing := [c for c in TREND_COLUMNS if c not in trends.columns]:
        raise ValueError(f"the trends table has no column {', '.join(missing)}: is it claims_trends.parquet?")
    lines = {}
    for claim, g in trends.groupby("claim", sort=False):
        if len(g) == 1:
            row = next(g.itertuples(index=False))
            label = f"{claim}" if row.part == claim else f"{claim} ({row.part})"
            lines[claim] = f"{label}: {_describe(row)}"
        else:
            lines[claim] = f"{claim}: " + "; ".join(f"{row.part}: {_describe(row)}" for row in g.itertuples(index=False))
    return lines
