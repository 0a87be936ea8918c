"""Hidden-state dynamics (docs/methods/analyses.md#analysis-dynamics; Fig 6): dimensionality, shared dimensions
(PLSC), power; decoding is :mod:`efish.analysis.decoding`.

Functions on matrices take a T x D array ``h`` (time x units, e.g. one
agent-episode of the ``hidden`` table, see :func:`hidden_matrix`). Scalar
results are NaN when the input cannot give an answer; :func:`degenerate_reason`
says why, and the table functions put it in a ``reason`` column.
"""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
from scipy import signal

from ._tables import AGENT_EPISODE, DEFAULTS, EPISODE, PerCondition, nan_frame, require, value_of
from .plsc_tests import plsc_collapse, shared_dimensions

SUBSAMPLE_FRACTIONS = tuple(DEFAULTS.subsample_fractions)


def units(hidden: pd.DataFrame) -> list[str]:
    """The unit columns ``h_0 .. h_{D-1}`` of a hidden-state frame, in unit order."""
    found = sorted((c for c in hidden.columns if c.startswith("h_") and c[2:].isdigit()), key=lambda c: int(c[2:]))
    if not found:
        raise ValueError("hidden table has no h_<i> columns")
    return found


def hidden_matrix(hidden: pd.DataFrame) -> np.ndarray:
    """The ``h_0 .. h_{D-1}`` columns of a hidden-state frame as a T x D float64 array, rows in t order."""
    frame = hidden.sort_values("t", kind="stable") if "t" in hidden else hidden
    return frame[units(hidden)].to_numpy(np.float64)


def degenerate_reason(h: np.ndarray, min_rows: int = 2) -> str:
    """Why ``h`` cannot give a dimensionality or power ('' when it can): too few rows, non-finite, no variance."""
    h = np.asarray(h, dtype=np.float64)
    if h.ndim != 2 or h.shape[0] < min_rows or h.shape[1] == 0:
        return f"need a T x D matrix with T >= {min_rows} and D >= 1, got shape {h.shape}"
    if not np.all(np.isfinite(h)):
        return "non-finite values"
    if not np.any(np.ptp(h, axis=0) > 0):
        return "no unit varies"
    return ""


def pca_variances(h: np.ndarray) -> np.ndarray:
    """Normalised PCA variances (sum 1, descending) of the rows of ``h``; empty when ``h`` is degenerate."""
    if degenerate_reason(h):
        return np.empty(0)
    s = np.linalg.svd(np.asarray(h, dtype=np.float64) - np.mean(h, axis=0), compute_uv=False)
    var = s ** 2
    return var / var.sum()


def effective_dimensionality(h: np.ndarray) -> float:
    """D_eff = 1 / sum(lambda_i^2) of the normalised PCA variances lambda_i
    (docs/methods/analyses.md#analysis-dynamics); NaN when degenerate.

    Computed without a decomposition: the PCA variances are the eigenvalues of the centred Gram matrix
    G = Hc^T Hc, so their sum is trace(G) and the sum of their squares is the sum of G's squared entries, and
    D_eff = trace(G)^2 / ||G||_F^2 (:func:`gram_dimensionality`); the same number as from the singular values,
    to rounding, at a fraction of an SVD's cost.

    >>> rng = np.random.default_rng(0)
    >>> round(effective_dimensionality(np.outer(rng.normal(size=50), [1.0, 2.0, 3.0])), 6)
    1.0
    """
    if degenerate_reason(h):
        return np.nan
    return gram_dimensionality(centred_gram(h))


def centred_gram(h: np.ndarray) -> np.ndarray:
    """G = Hc^T Hc of the column-centred ``h`` (D x D). A subset of units' Gram matrix is G's block on them:
    centring is per column, so choosing units commutes with it."""
    hc = np.asarray(h, dtype=np.float64) - np.mean(h, axis=0)
    return hc.T @ hc


def gram_dimensionality(gram: np.ndarray) -> float:
    """D_eff = trace(G)^2 / ||G||_F^2 of a centred Gram matrix: (sum lambda)^2 / sum lambda^2 of its eigenvalues."""
    return float(np.trace(gram) ** 2 / np.sum(gram * gram))


def pcs_for_variance(h: np.ndarray, fraction: float = DEFAULTS.variance_fraction) -> float:
    """Fewest principal components whose variances add up to ``fraction`` (90%,
    docs/methods/analyses.md#analysis-dynamics); NaN if degenerate."""
    lam = pca_variances(h)
    if not lam.size:
        return np.nan
    # the tolerance keeps fraction = 1 reachable despite rounding in the cumulative sum
    return float(np.searchsorted(np.cumsum(lam), fraction - 1e-12) + 1)


def subsample_units(h: np.ndarray, fractions=SUBSAMPLE_FRACTIONS, draws: int = DEFAULTS.subsample_draws,
                    rng: np.random.Generator | int | None = None) -> pd.DataFrame:
    """D_eff of random subsets of units (fractions .05 .15 .25 .5 .75 1, 30 draws each;
    docs/methods/analyses.md#analysis-dynamics), Fig 6C.

    Each draw keeps round(fraction x D) units (at least 1) without replacement.
    Columns: fraction, n_units, draw, d_eff, reason.
    """
    rng = np.random.default_rng(rng)
    h = np.asarray(h, dtype=np.float64)
    # each draw's D_eff from its block of the whole Gram matrix (centred_gram), computed once; a unit with a
    # non-finite value spoils only its own row and column of it, as it would spoil only the draws that hold it
    finite, varies = np.all(np.isfinite(h), axis=0), np.ptp(h, axis=0) > 0
    gram = centred_gram(h)
    rows = []
    for f in fractions:
        k = max(1, round(f * h.shape[1]))
        for d in range(draws):
            chosen = rng.choice(h.shape[1], size=k, replace=False)
            reason = subset_reason(h.shape[0], finite[chosen], varies[chosen])
            d_eff = gram_dimensionality(gram[np.ix_(chosen, chosen)]) if not reason else np.nan
            rows.append({"fraction": f, "n_units": k, "draw": d, "d_eff": d_eff, "reason": reason})
    return pd.DataFrame(rows)


def subset_reason(rows: int, finite: np.ndarray, varies: np.ndarray) -> str:
    """:func:`degenerate_reason` of a subset of units from its units' flags (all values finite, some variation):
    the same answer without copying the subset."""
    if rows < 2 or len(finite) == 0:
        return f"need a T x D matrix with T >= 2 and D >= 1, got shape ({rows}, {len(finite)})"
    if not finite.all():
        return "non-finite values"
    return "" if varies.any() else "no unit varies"


def wideband_power(h: np.ndarray, window: int = DEFAULTS.spectrogram_window,
                   overlap: int = DEFAULTS.spectrogram_overlap, *, fs: float) -> float:
    """Mean spectrogram power over units, windows and frequencies (20-step windows, 10 overlap;
    docs/methods/analyses.md#analysis-dynamics).

    scipy.signal.spectrogram with its defaults otherwise (Tukey window,
    constant detrend, power spectral density at sampling rate ``fs``: the steps per second the run simulated
    ``h`` at, so the power is per Hz); NaN when
    ``h`` is degenerate or shorter than one window.
    """
    if degenerate_reason(h, min_rows=window):
        return np.nan
    _, _, sxx = signal.spectrogram(np.asarray(h, dtype=np.float64).T, fs=fs, nperseg=window, noverlap=overlap)
    return float(sxx.mean())


def dynamics_table(hidden: pd.DataFrame, fraction: float = DEFAULTS.variance_fraction,
                   window: int = DEFAULTS.spectrogram_window, overlap: int = DEFAULTS.spectrogram_overlap,
                   *, fps: PerCondition) -> pd.DataFrame:
    """Per agent-episode of a hidden table: its hidden units (``n_units``: the width of the policy that acted, so a
    reader needs no config to put D_eff in proportion), D_eff, PCs for ``fraction`` of the variance, wideband power
    (at its condition's ``fps``), reason."""
    require(hidden, [*AGENT_EPISODE, "t"], "hidden table")
    rows = []
    for keys, sub in hidden.groupby(AGENT_EPISODE, sort=True):
        h = hidden_matrix(sub)
        rows.append({**dict(zip(AGENT_EPISODE, keys, strict=True)), "n_steps": len(h), "n_units": h.shape[1],
                     "d_eff": effective_dimensionality(h), "pcs_for_variance": pcs_for_variance(h, fraction),
                     "wideband_power": wideband_power(h, window, overlap, fs=value_of(fps, keys[0])),
                     "reason": degenerate_reason(h)})
    return pd.DataFrame(rows, columns=[*AGENT_EPISODE, "n_steps", "n_units", "d_eff", "pcs_for_variance",
                                       "wideband_power", "reason"])


def _zscore(h: np.ndarray) -> np.ndarray:
    """Columns centred and scaled to unit variance; constant columns become 0 (they carry no covariance)."""
    h = np.asarray(h, dtype=np.float64)
    sd = h.std(axis=0)
    return np.divide(h - h.mean(axis=0), sd, out=np.zeros_like(h), where=sd > 0)


def _plsc_spectrum(za: np.ndarray, zb: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Top-k singular values of the cross-covariance and the correlations of the paired component scores."""
    u, s, vt = np.linalg.svd(za.T @ zb / (len(za) - 1), full_matrices=False)
    a, b = za @ u[:, :k], zb @ vt[:k].T
    sa, sb = a.std(axis=0), b.std(axis=0)
    r = np.divide((a * b).mean(axis=0) - a.mean(axis=0) * b.mean(axis=0), sa * sb, out=np.zeros(k),
                  where=(sa > 0) & (sb > 0))
    return s[:k], r


def _standardised(h_a: np.ndarray, h_b: np.ndarray) -> tuple[np.ndarray, np.ndarray, str]:
    """Two agents' T x D hidden states z-scored per unit (:func:`_zscore`) and ''; when either has fewer than 10 steps
    or is degenerate (:func:`degenerate_reason`), the states as given and why."""
    h_a, h_b = np.asarray(h_a, dtype=np.float64), np.asarray(h_b, dtype=np.float64)
    if len(h_a) != len(h_b):
        raise ValueError(f"h_a and h_b differ in length: {len(h_a)} vs {len(h_b)}")
    # at least 10 steps, so that the null's shifts (T/10 to 9T/10) are never 0
    if reason := degenerate_reason(h_a, 10) or degenerate_reason(h_b, 10):
        return h_a, h_b, reason
    return _zscore(h_a), _zscore(h_b), ""


def plsc(h_a: np.ndarray, h_b: np.ndarray, shifts: int = DEFAULTS.plsc_shifts,
         rng: np.random.Generator | int | None = None, percentile: float = DEFAULTS.plsc_percentile) -> dict:
    """Partial least squares correlation of two agents' hidden states with a circular-shift null
    (docs/methods/analyses.md#analysis-dynamics).

    Both T x D matrices are z-scored per unit; the SVD of their
    cross-covariance gives singular values and paired components. The null
    recomputes both after circularly shifting ``h_b`` in time by ``shifts``
    random offsets in [T/10, 9T/10] (which keeps each series' autocorrelation and
    breaks their alignment). Component i is significant when its singular value
    and its score correlation both exceed the ``percentile`` of the i-th null
    values; ``n_significant`` counts significant components up to the first that is not.
    """
    za, zb, reason = _standardised(h_a, h_b)
    k = min(za.shape[-1], zb.shape[-1])
    if reason:
        nan = np.full(k, np.nan)
        return {"singular_values": nan, "correlations": nan, "null_singular_values": nan,
                "null_correlations": nan, "n_significant": np.nan, "reason": reason}
    s, r = _plsc_spectrum(za, zb, k)
    rng = np.random.default_rng(rng)
    t = len(za)
    null = [_plsc_spectrum(za, np.roll(zb, rng.integers(t // 10, t - t // 10 + 1), axis=0), k) for _ in range(shifts)]
    s_null = np.percentile([n[0] for n in null], percentile, axis=0)
    r_null = np.percentile([n[1] for n in null], percentile, axis=0)
    passed = (s > s_null) & (r > r_null)
    n_sig = int(np.argmin(passed)) if not passed.all() else k
    return {"singular_values": s, "correlations": r, "null_singular_values": s_null, "null_correlations": r_null,
            "n_significant": n_sig, "reason": ""}


def plsc_by_distance(h_a: np.ndarray, h_b: np.ndarray, dist_cm: np.ndarray, edges_cm=tuple(DEFAULTS.plsc_edges_cm),
                     shifts: int = DEFAULTS.plsc_shifts, rng: np.random.Generator | int | None = None,
                     percentile: float = DEFAULTS.plsc_percentile, episodes: np.ndarray | None = None,
                     draws: int = DEFAULTS.plsc_null_draws, alpha: float = DEFAULTS.claims_alpha) -> pd.DataFrame:
    """:func:`plsc` on the steps whose inter-agent distance falls in each bin (<= 10, 10-100, > 100 cm;
    docs/methods/analyses.md#analysis-dynamics).

    The steps of a bin are taken in time order and the null shifts them as one
    series. One row per bin: ``lo_cm``, ``hi_cm`` (bins are (lo, hi], the first
    from 0 inclusive), ``n_steps``, ``n_significant`` (the paper's procedure),
    the largest singular value ``s_1``, ``n_shared`` and ``n_episodes`` and a
    reason (e.g. a bin with fewer than 10 steps).

    ``n_shared`` is the calibrated count of
    :func:`efish.analysis.plsc_tests.shared_dimensions` (episode-swap null,
    step-down, ``draws`` permutations, level ``alpha``) over the bin's steps
    split by ``episodes`` (one label per step); NaN without ``episodes``. Its
    draws come from a stream spawned from ``rng``, so ``n_significant`` is
    the same with or without it.
    """
    dist = np.asarray(dist_cm, dtype=np.float64)
    if not len(dist) == len(h_a) == len(h_b):
        raise ValueError(f"h_a, h_b and dist_cm differ in length: {len(h_a)}, {len(h_b)}, {len(dist)}")
    rng = np.random.default_rng(rng)
    calibrated = rng.spawn(1)[0]
    bounds = [-np.inf, *edges_cm, np.inf]
    rows = []
    for lo, hi in itertools.pairwise(bounds):
        keep = (dist > lo) & (dist <= hi)
        res = plsc(np.asarray(h_a)[keep], np.asarray(h_b)[keep], shifts, rng, percentile)
        shared = {"n_significant": np.nan, "n_episodes": 0, "reason": ""}  # NaN without episode labels
        if episodes is not None:
            a, b = (by_episode(np.asarray(h)[keep], np.asarray(episodes)[keep]) for h in (h_a, h_b))
            shared = shared_dimensions(a, b, draws, alpha, calibrated)
        rows.append({"lo_cm": max(lo, 0.0), "hi_cm": hi, "n_steps": int(keep.sum()),
                     "n_significant": res["n_significant"], "s_1": res["singular_values"][0],
                     "n_shared": shared["n_significant"], "n_episodes": shared["n_episodes"],
                     "reason": res["reason"] or (f"n_shared: {shared['reason']}" if shared["reason"] else "")})
    return pd.DataFrame(rows)


def by_episode(h: np.ndarray, episodes: np.ndarray) -> list[np.ndarray]:
    """The rows of ``h`` split by ``episodes`` (one label per row), each in its original order; episodes sorted."""
    return [h[episodes == e] for e in np.unique(episodes)]


def subsample_table(hidden: pd.DataFrame, fractions=SUBSAMPLE_FRACTIONS, draws: int = DEFAULTS.subsample_draws,
                    rng: np.random.Generator | int | None = None) -> pd.DataFrame:
    """:func:`subsample_units` of every agent-episode of a hidden table (Fig 6C), keyed by condition, episode, agent."""
    require(hidden, [*AGENT_EPISODE, "t"], "hidden table")
    rng = np.random.default_rng(rng)
    parts = [subsample_units(hidden_matrix(sub), fractions, draws, rng).assign(**dict(zip(AGENT_EPISODE, keys,
                                                                                           strict=True)))
             for keys, sub in hidden.groupby(AGENT_EPISODE, sort=True)]
    if not parts:
        return nan_frame("empty hidden table", fraction=np.nan, n_units=0, draw=np.nan, d_eff=np.nan)
    return pd.concat(parts, ignore_index=True)


def _with_steps(hidden: pd.DataFrame, steps: pd.DataFrame, columns: list[str]) -> pd.DataFrame:
    """Hidden rows joined with ``columns`` of the steps table on (condition, episode, agent, t), in that order."""
    keys = [*AGENT_EPISODE, "t"]
    require(hidden, keys, "hidden table")
    require(steps, [*keys, *columns], "steps table")
    return hidden.merge(steps[[*keys, *columns]], on=keys).sort_values(keys, kind="stable")


def _pair_states(hidden: pd.DataFrame, steps: pd.DataFrame,
                 agents: tuple[int, int]) -> tuple[pd.DataFrame, pd.DataFrame, np.ndarray] | None:
    """Two agents' hidden rows at the steps both have one (same order: condition, episode, t) and their distance
    from the steps table's positions; None when they share no step."""
    keys = [*EPISODE, "t"]
    pos = _with_steps(hidden, steps, ["x_cm", "y_cm"])
    a, b = (pos[pos["agent"] == i].set_index(keys).sort_index() for i in agents)
    shared = a.index.intersection(b.index)
    if shared.empty:
        return None
    a, b = a.loc[shared], b.loc[shared]
    dist = np.hypot(a["x_cm"].to_numpy(np.float64) - b["x_cm"].to_numpy(np.float64),
                    a["y_cm"].to_numpy(np.float64) - b["y_cm"].to_numpy(np.float64))
    return a, b, dist


def plsc_table(hidden: pd.DataFrame, steps: pd.DataFrame, agents: tuple[int, int] = (0, 1),
               edges_cm=tuple(DEFAULTS.plsc_edges_cm), shifts: int = DEFAULTS.plsc_shifts,
               rng: np.random.Generator | int | None = None, percentile: float = DEFAULTS.plsc_percentile,
               draws: int = DEFAULTS.plsc_null_draws, alpha: float = DEFAULTS.claims_alpha) -> pd.DataFrame:
    """:func:`plsc_by_distance` of two agents' hidden states per condition (Fig 6G,H), with the calibrated
    ``n_shared`` over their episodes.

    Uses the steps at which both ``agents`` have a hidden state, episode after
    episode in time order; their distance comes from the steps table's
    positions. One row per condition and distance bin, with ``agent_a`` and
    ``agent_b``; without a shared step, one NaN row with a reason.
    """
    pair = _pair_states(hidden, steps, agents)
    if pair is None:
        return nan_frame(f"agents {agents[0]} and {agents[1]} share no step", condition=np.nan, n_steps=0)
    a, b, dist = pair
    h, rng = units(hidden), np.random.default_rng(rng)
    condition, episode = (a.index.get_level_values(k).to_numpy() for k in EPISODE)
    parts = [plsc_by_distance(a[h].to_numpy()[condition == c], b[h].to_numpy()[condition == c],
                              dist[condition == c], edges_cm, shifts, rng, percentile, episode[condition == c],
                              draws, alpha).assign(condition=c)
             for c in sorted(set(condition))]
    return pd.concat(parts, ignore_index=True).assign(agent_a=agents[0], agent_b=agents[1])


#: Columns of :func:`plsc_episodes` (docs/methods/analyses.md#analysis-dynamics).
PLSC_EPISODE_COLUMNS = ["condition", "episode", "agent_a", "agent_b", "bin", "lo_cm", "hi_cm", "n_steps", "s_1", "r_1",
                        "reason"]


def plsc_episodes(hidden: pd.DataFrame, steps: pd.DataFrame, agents: tuple[int, int] = (0, 1),
                  edges_cm=tuple(DEFAULTS.plsc_edges_cm)) -> pd.DataFrame:
    """The first PLSC component of two agents' hidden states per episode and distance bin (Fig 6G; claim C20): one
    row per episode and bin (columns :data:`PLSC_EPISODE_COLUMNS`).

    The steps of the episode at which both ``agents`` have a hidden state, with their distance in the bin (bins as
    :func:`plsc_by_distance`'s: ``bin`` 0 the nearest, (``lo_cm``, ``hi_cm``]), in time order: the first singular
    value ``s_1`` of the cross-covariance of their z-scored states and ``r_1``, the correlation of the paired
    component scores (:func:`plsc` without its null); NaN with a reason under 10 steps or when degenerate. Without
    a shared step, one NaN row that says so.
    """
    pair = _pair_states(hidden, steps, agents)
    if pair is None:
        return nan_frame(f"agents {agents[0]} and {agents[1]} share no step").reindex(columns=PLSC_EPISODE_COLUMNS)
    a, b, dist = pair
    h = units(hidden)
    h_a, h_b = a[h].to_numpy(), b[h].to_numpy()
    bounds = list(itertools.pairwise([-np.inf, *edges_cm, np.inf]))
    rows = []
    for (condition, episode), idx in a.groupby(level=EPISODE, sort=True).indices.items():
        d = dist[idx]
        for k, (lo, hi) in enumerate(bounds):
            keep = idx[(d > lo) & (d <= hi)]
            za, zb, reason = _standardised(h_a[keep], h_b[keep])
            s, r = (np.full(1, np.nan),) * 2 if reason else _plsc_spectrum(za, zb, min(za.shape[1], zb.shape[1]))
            rows.append({"condition": condition, "episode": episode, "agent_a": agents[0], "agent_b": agents[1],
                         "bin": k, "lo_cm": max(lo, 0.0), "hi_cm": hi, "n_steps": len(keep), "s_1": s[0],
                         "r_1": r[0], "reason": reason})
    return pd.DataFrame(rows, columns=PLSC_EPISODE_COLUMNS)


#: Columns of :func:`plsc_collapse_table` (docs/methods/analyses.md#analysis-dynamics).
COLLAPSE_COLUMNS = ["condition", "agent_a", "agent_b", "near_hi_cm", "far_lo_cm", "n_episodes", "n_steps",
                    "near_significant", "far_significant", "count_difference", "effect", "p", "p_less",
                    "n_assignments", "exact", "reason"]


def plsc_collapse_table(hidden: pd.DataFrame, steps: pd.DataFrame, agents: tuple[int, int] = (0, 1),
                        edges_cm=tuple(DEFAULTS.plsc_edges_cm), draws: int = DEFAULTS.plsc_null_draws,
                        alpha: float = DEFAULTS.claims_alpha, windows: int = 1,
                        swaps: int = DEFAULTS.plsc_label_swaps,
                        rng: np.random.Generator | int | None = None) -> pd.DataFrame:
    """:func:`efish.analysis.plsc_tests.plsc_collapse` of two agents' hidden states per condition (Fig 6H, claim
    C20): fewer shared dimensions in the farthest distance bin (> last edge) than in the nearest (<= first edge)?

    Each episode's steps in each bin are taken in time order. ``windows``
    windows of each episode's larger bin (one in the analysis: see
    :func:`~efish.analysis.plsc_tests.plsc_collapse` for why). One row per
    condition (columns :data:`COLLAPSE_COLUMNS`); without a shared step or
    an edge, one NaN row with a reason.
    """
    pair = _pair_states(hidden, steps, agents) if len(edges_cm) else None
    if pair is None:
        reason = f"agents {agents[0]} and {agents[1]} share no step" if len(edges_cm) else "no distance bin edges"
        return nan_frame(reason).reindex(columns=COLLAPSE_COLUMNS)
    a, b, dist = pair
    h, rng = units(hidden), np.random.default_rng(rng)
    condition, episode = (a.index.get_level_values(k).to_numpy() for k in EPISODE)
    rows = []
    for c in sorted(set(condition)):
        here = condition == c
        ha, hb, d, ep = a[h].to_numpy()[here], b[h].to_numpy()[here], dist[here], episode[here]
        near, far = d <= edges_cm[0], d > edges_cm[-1]
        # every episode of the condition, so that near and far lists line up (an empty block where a bin has none)
        blocks = [[x[mask & (ep == e)] for e in np.unique(ep)] for mask in (near, far) for x in (ha, hb)]
        res = plsc_collapse(*blocks, draws=draws, alpha=alpha, windows=windows, swaps=swaps, rng=rng)
        rows.append({"condition": c, "agent_a": agents[0], "agent_b": agents[1], "near_hi_cm": edges_cm[0],
                     "far_lo_cm": edges_cm[-1], **res})
    return pd.DataFrame(rows, columns=COLLAPSE_COLUMNS)
