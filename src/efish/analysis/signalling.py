"""EOD signalling (docs/methods/analyses.md#analysis-signalling): inter-discharge intervals, power laws, EOD rate vs
context.

The EOD rate of a step is the 20-step centred rolling mean of ``eod`` times
the steps per second its condition was simulated at (``env.fps`` as the run
recorded it, 83 Hz by default), computed per agent-episode; ms per step are
1000 / that. Rates are binned against distances, aligned on events, or
compared between agents close to each other.
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from ._tables import (
    AGENT_EPISODE,
    DEFAULTS,
    EPISODE,
    PerCondition,
    agent_sizes,
    eod_rate,
    nan_frame,
    pairs,
    require,
    values_of,
)
from .stats import cluster_sum_t_test

#: Distance column and default binning range (cm) per ``to`` of :func:`eod_rate_by_distance`
#: (docs/methods/analyses.md#analysis-signalling).
DISTANCE_RANGES_CM = {to: (0.0, getattr(DEFAULTS, f"{to}_range_cm")) for to in ("agent", "food", "wall")}
#: Event columns :func:`peri_event_rate` aligns on: eating, biting, being bitten.
EVENTS = ("ate", "bit", "was_bitten")


def idis(steps: pd.DataFrame, *, fps: PerCondition) -> pd.DataFrame:
    """One row per inter-discharge interval: the step difference of consecutive EODs of an agent-episode.

    Columns: condition, episode, agent, t (step of the later discharge),
    ``idi_steps`` and ``idi_ms`` = ``idi_steps`` x 1000 / ``fps`` (the condition's steps per second; 12.048 ms
    a step at 83, docs/methods/analyses.md#analysis-signalling).
    """
    require(steps, [*AGENT_EPISODE, "t", "eod"], "steps table")
    fired = steps.loc[steps["eod"].astype(bool), [*AGENT_EPISODE, "t"]].sort_values([*AGENT_EPISODE, "t"])
    fired["idi_steps"] = fired.groupby(AGENT_EPISODE, sort=False)["t"].diff()
    out = fired.dropna(subset=["idi_steps"]).astype({"idi_steps": np.int64})
    out["idi_ms"] = out["idi_steps"] * (1000.0 / values_of(fps, out["condition"]))
    return out.reset_index(drop=True)


def idi_histogram(idi_ms, bins: int = DEFAULTS.idi_bins, lo_ms: float = DEFAULTS.idi_lo_ms,
                  hi_ms: float = DEFAULTS.idi_hi_ms) -> pd.DataFrame:
    """Counts and density of IDIs on ``bins`` log-spaced bins over [``lo_ms``, ``hi_ms``]
    (docs/methods/analyses.md#analysis-signalling).

    The density is per ms, so histograms with different bin widths compare.
    """
    x = np.asarray(idi_ms, dtype=np.float64)
    edges = np.geomspace(lo_ms, hi_ms, bins + 1)
    counts, _ = np.histogram(x[np.isfinite(x)], bins=edges)
    total = counts.sum()
    density = counts / (total * np.diff(edges)) if total else np.full(bins, np.nan)
    return pd.DataFrame({"bin_lo_ms": edges[:-1], "bin_hi_ms": edges[1:], "count": counts, "density": density})


ALTERNATIVES = ("lognormal", "exponential")  # the distributions the power law is compared with, as the paper's
#: The power-law exponent's range: powerlaw's default, [0, 3], with no upper bound. powerlaw 2's default stops
#: its numerical fit at alpha 3 (and its in-range check makes alpha = 3 itself a likelihood of ~0), so IDIs with a
#: maximum-likelihood alpha above 3 were reported as alpha ~3 and compared with the alternatives at that wrong
#: alpha (issue 37: a seed with ML alpha 4.59 reported 3.0, R_exponential 3.87 instead of 9.61).
ALPHA_RANGE = {"alpha": [0, None]}


def _powerlaw_fit(x: np.ndarray, xmin: float, discrete: bool):
    """``powerlaw.Fit`` of ``x`` from ``xmin`` at the maximum-likelihood alpha (no upper bound, see
    :data:`ALPHA_RANGE`). ``estimate_discrete=False``: a discrete fit maximises the exact discrete likelihood
    (Hurwitz zeta normalisation) numerically, never Clauset et al.'s approximation that powerlaw takes by default
    from xmin 10 (off by up to ~1% there)."""
    import powerlaw  # imported here: it loads matplotlib, which the rest of the analyses do not need

    return powerlaw.Fit(x, xmin=xmin, discrete=discrete, verbose=False, estimate_discrete=False,
                        parameter_ranges=ALPHA_RANGE)


def _notes(caught: list, fit) -> str:
    """powerlaw's warnings, once each, and a note when its power-law optimiser did not converge."""
    notes = [f"powerlaw: {w.message}" for w in caught]
    if fit is not None and fit.power_law.noise_flag:
        notes.append("powerlaw: the power-law fit did not converge")
    return "; ".join(dict.fromkeys(notes))


def fit_power_law(idi, xmin: float = DEFAULTS.xmin_ms, min_n: int = 10, discrete: bool = False,
                  alternatives: tuple[str, ...] = ALTERNATIVES) -> dict:
    """Power-law fit of IDIs >= ``xmin`` with ``powerlaw.Fit``, compared with lognormal and exponential.

    ``discrete``: the IDIs are whole steps (the agents': an EOD is emitted on a
    step, so most IDIs are 1-3 steps) and are fitted as a discrete power law, as
    the authors do; ``xmin`` is then in steps. Otherwise (real fish, ms) the fit
    is continuous. ``alpha`` is the maximum-likelihood exponent, unbounded above
    (:data:`ALPHA_RANGE`). Returns ``alpha``, ``xmin``, ``n`` (IDIs in the fit), and for
    each alternative the normalised loglikelihood ratio ``R_<alt>`` (> 0 favours
    the power law) and its ``p``. ``reason`` is empty for a clean fit; it names
    why the numbers are NaN (fewer than ``min_n`` IDIs, no spread), or lists
    powerlaw's warnings, e.g. an alternative whose maximum-likelihood fit did
    not converge (its R is kept: it compares with the best fit powerlaw found).
    ``alternatives`` limits the comparisons (the others' R and p stay NaN): a bootstrap of R_exponential alone
    skips the lognormal fit, a numerical optimisation 18 times slower than the rest of the fit.
    The p treats every IDI as independent; :func:`power_law_vs_exponential_clustered` tests across episodes.
    """
    x = np.asarray(idi, dtype=np.float64)
    x = x[np.isfinite(x) & (x > 0)]  # powerlaw would drop (and warn about) non-positive values itself
    n = int(np.sum(x >= xmin))
    out = {"alpha": np.nan, "xmin": float(xmin), "n": n, "R_lognormal": np.nan, "p_lognormal": np.nan,
           "R_exponential": np.nan, "p_exponential": np.nan, "reason": ""}
    if why := _unfittable(x, xmin, min_n):
        return {**out, "reason": why}
    # powerlaw warns about the data and about alternatives whose optimiser did not
    # converge (e.g. lognormal on pure power-law data, whose likelihood keeps rising
    # as mu -> -inf); both are reported in ``reason``, not hidden and not raised.
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fit = _powerlaw_fit(x, xmin, discrete)
        out["alpha"] = float(fit.power_law.alpha)
        for alt in alternatives:
            r, p = fit.distribution_compare("power_law", alt, normalized_ratio=True)
            out[f"R_{alt}"], out[f"p_{alt}"] = float(r), float(p)
    return {**out, "reason": _notes(caught, fit)}


def _unfittable(x: np.ndarray, xmin: float, min_n: int) -> str:
    """Why the values ``x`` >= ``xmin`` cannot be fitted (fewer than ``min_n``, all equal), or ''."""
    tail = x[x >= xmin]
    if tail.size < min_n:
        return f"fewer than {min_n} IDIs >= xmin ({tail.size})"
    if np.ptp(tail) == 0:
        return "all IDIs >= xmin are equal"
    return ""


def power_law_vs_exponential_clustered(idis: pd.DataFrame, xmin: float, value: str = "idi_steps",
                                       cluster: Sequence[str] = tuple(EPISODE), discrete: bool = True,
                                       min_n: int = 10) -> dict:
    """Power law against exponential for the IDIs of ``idis`` >= ``xmin``, tested across episodes, not IDIs.

    Why: powerlaw's test of R (Vuong's, as in :func:`fit_power_law`) counts every IDI as an independent unit; the
    IDIs of one episode share its agents, arena and dynamics, and thousands of them from a few episodes make any
    difference look significant (issue 37: p 4e-93 over 16,295 IDIs from 16 agent-episodes). The episode is the
    unit here, as for every claim.

    How: both laws are fitted once to all IDIs >= ``xmin`` (discrete by default, in steps, as the ``power_law``
    table's agents row; the power law at its maximum-likelihood alpha). Each IDI contributes
    l_i = log p_powerlaw(x_i) - log p_exponential(x_i), the per-point terms powerlaw sums into R (with its
    clipping of log 0); the contributions are summed per ``cluster`` (default: the episode, keyed by condition
    and episode) and the mean cluster sum is tested against 0 with :func:`efish.analysis.stats.cluster_sum_t_test`:
    the cluster-robust (sandwich) variance of Liang & Zeger (1986), whose sum over clusters allows any dependence
    within an episode, and t with n_clusters - 1 degrees of freedom, because that variance is estimated from
    n_clusters sums only (Cameron & Miller 2015; Donald & Lang 2007). Agents of one episode are one cluster: they
    interact, so they are not independent either. The fitted parameters are treated as known, as in Vuong's
    test: their estimation moves the sum by O(1), against a spread of O(sqrt(n)). Select one condition before
    calling: all rows share one fit.

    Returns ``R`` (normalised loglikelihood ratio over all IDIs, > 0 favours the power law: today's
    ``R_exponential``, for continuity) and ``p_iid`` (powerlaw's p, every IDI independent); ``loglik_ratio``
    (the sum of l_i); the clustered test: ``mean_cluster_sum``, ``se``, ``t``, ``df``, two-sided ``p``;
    ``n_clusters`` (clusters with an IDI >= xmin), ``n`` (IDIs >= xmin), ``alpha`` (the power law's ML
    exponent), ``Lambda`` (the exponential's rate), ``xmin`` and ``reason``: why the numbers are NaN (no or
    fewer than ``min_n`` IDIs >= xmin, all equal, fewer than 2 clusters, sums that do not vary), or powerlaw's
    warnings beside finite numbers.

    Example, with ``ids`` the wide2 ``idis`` table and ``row`` the agents' row of its ``power_law`` table::

        power_law_vs_exponential_clustered(ids[ids["condition"] == row["condition"]], row["xmin_steps"])
    """
    require(idis, [*cluster, value], "idis table")
    frame = idis[[*cluster, value]].dropna()  # a table without IDIs is one NaN row that says why
    x = frame[value].to_numpy(np.float64)
    keep = np.isfinite(x) & (x > 0) & (x >= xmin)  # as fit_power_law: non-positive values cannot be fitted
    x, labels = x[keep], frame.groupby(list(cluster), sort=True).ngroup().to_numpy()[keep]
    n_clusters = int(np.unique(labels).size)
    out = {"R": np.nan, "p_iid": np.nan, "loglik_ratio": np.nan, "mean_cluster_sum": np.nan, "se": np.nan,
           "t": np.nan, "df": np.nan, "p": np.nan, "n_clusters": n_clusters, "n": int(x.size), "alpha": np.nan,
           "Lambda": np.nan, "xmin": float(xmin), "reason": ""}
    if x.size == 0:
        return {**out, "reason": "no IDI >= xmin"}
    if why := _unfittable(x, xmin, min_n) or (n_clusters < 2 and f"fewer than 2 clusters ({n_clusters})"):
        return {**out, "reason": why}
    from powerlaw.statistics import loglikelihood_ratio

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fit = _powerlaw_fit(x, xmin, discrete)
        # per IDI in row order (x is already >= xmin, so powerlaw's trimming keeps every value in place);
        # log 0 is clipped to log(1e-307) as powerlaw's loglikelihood_ratio does, so R below is its R
        tiny = np.log(10.0 ** sys.float_info.min_10_exp)
        logs = [dist.loglikelihoods(x) for dist in (fit.power_law, fit.exponential)]
        logs = [np.where(np.isneginf(ll), tiny, ll) for ll in logs]
        r, p_iid = loglikelihood_ratio(*logs, normalized_ratio=True)
        alpha, rate = float(fit.power_law.alpha), float(fit.exponential.Lambda)
    contributions = logs[0] - logs[1]
    test = cluster_sum_t_test(contributions, labels)
    notes = "; ".join(n for n in (test["reason"], _notes(caught, fit)) if n)
    return {**out, "R": float(r), "p_iid": float(p_iid), "loglik_ratio": float(contributions.sum()),
            **{k: test[k] for k in ("mean_cluster_sum", "se", "t", "df", "p")}, "alpha": alpha, "Lambda": rate,
            "reason": notes}


def xmin_in_steps(xmin_ms: float, step_ms: float) -> int:
    """The smallest whole step count at or above ``xmin_ms`` (12 ms -> 1 step of 12.048 ms), at least 1."""
    return max(1, int(np.ceil(xmin_ms / step_ms - 1e-9)))


def load_real_idis(path: str | Path | None) -> pd.DataFrame:
    """Real-fish IDIs (ms) from a user-supplied CSV or Parquet file with an ``idi_ms`` column.

    The recordings are not public (docs/model/differences.md), so ``path`` is unset by default
    (config ``analysis.real_fish_idis``); the result is then one NaN row whose
    ``reason`` says so, and a fit or a panel reports it instead of failing.
    """
    if path is None or str(path) == "":
        return nan_frame("no real-fish IDI table given (analysis.real_fish_idis is unset)", idi_ms=np.nan)
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"real-fish IDI table {path} does not exist")
    readers = {".csv": pd.read_csv, ".parquet": pd.read_parquet, ".pq": pd.read_parquet}
    if path.suffix.lower() not in readers:
        raise ValueError(f"real-fish IDI table {path} is neither .csv nor .parquet")
    df = readers[path.suffix.lower()](path)
    require(df, ["idi_ms"], f"real-fish IDI table {path}")
    return df.assign(idi_ms=df["idi_ms"].astype(np.float64), reason="")


BIN_COLUMNS = ["condition", "to", "bin", "bin_lo_cm", "bin_hi_cm", "bin_mid_cm", "n", "mean_hz", "sem_hz", "reason"]
#: Columns of :func:`eod_rate_by_distance_episodes`: one row per (condition, episode, to, bin).
EPISODE_BIN_COLUMNS = ["condition", "episode", "to", "bin", "bin_lo_cm", "bin_hi_cm", "bin_mid_cm", "n_agents",
                       "rate_hz", "reason"]


def _distance_bins(steps: pd.DataFrame, to: str, bins: int, range_cm: tuple[float, float] | None, window: int,
                   fps: PerCondition) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ``bins`` + 1 equal edges of the distance to the nearest ``to``, and every step's EOD rate (Hz) and distance
    bin: -1 where the step has no rate (no full window) or its distance is NaN or outside the edges; a distance on
    the last edge is in the last bin."""
    if to not in DISTANCE_RANGES_CM:
        raise ValueError(f"to must be one of {sorted(DISTANCE_RANGES_CM)}, got {to!r}")
    column = f"dist_{to}_cm"
    require(steps, ["condition", column], "steps table")
    edges = np.linspace(*(range_cm or DISTANCE_RANGES_CM[to]), bins + 1)
    rate, dist = eod_rate(steps, window, fps=fps), steps[column].to_numpy(np.float64)
    inside = np.isfinite(rate) & np.isfinite(dist) & (dist >= edges[0]) & (dist <= edges[-1])
    return edges, rate, np.where(inside, np.clip(np.searchsorted(edges, dist, side="right") - 1, 0, bins - 1), -1)


def _bin_edges(edges: np.ndarray, b: np.ndarray) -> dict[str, np.ndarray]:
    """The lower, upper and middle edge (cm) of the bins ``b``."""
    return {"bin_lo_cm": edges[b], "bin_hi_cm": edges[b + 1], "bin_mid_cm": (edges[b] + edges[b + 1]) / 2}


def _binned_mean_sem(values: np.ndarray, b: np.ndarray, edges: np.ndarray, min_samples: int) -> pd.DataFrame:
    """Size, mean and SEM of ``values`` per bin ``b`` (-1: none), bins with fewer than ``min_samples`` dropped."""
    table = pd.DataFrame({"bin": b[b >= 0], "v": values[b >= 0]}).groupby("bin")["v"].agg(["size", "mean", "sem"])
    table = table[table["size"] >= min_samples]
    b = table.index.to_numpy()
    return pd.DataFrame({"bin": b, **_bin_edges(edges, b), "n": table["size"].to_numpy(),
                         "mean_hz": table["mean"].to_numpy(), "sem_hz": table["sem"].to_numpy(), "reason": ""})


def eod_rate_by_distance(steps: pd.DataFrame, to: str, bins: int = DEFAULTS.rate_bins,
                         range_cm: tuple[float, float] | None = None, min_samples: int = DEFAULTS.min_samples,
                         window: int = DEFAULTS.rate_window, *, fps: PerCondition) -> pd.DataFrame:
    """Mean +- SEM EOD rate (Hz, at each condition's ``fps``) in ``bins`` equal distance bins to the nearest ``to``
    (agent, food or wall).

    Ranges default to docs/methods/analyses.md#analysis-signalling: 0-150 cm for agents, 0-10 cm for food and wall.
    Samples are steps (every agent-step with a full rate window), per condition;
    bins with fewer than ``min_samples`` steps are dropped. A condition with no
    bin left gets one NaN row with a reason. Per episode: :func:`eod_rate_by_distance_episodes`.
    """
    edges, rate, b = _distance_bins(steps, to, bins, range_cm, window, fps)
    parts = []
    for cond, idx in steps.groupby("condition", sort=True).indices.items():
        table = _binned_mean_sem(rate[idx], b[idx], edges, min_samples)
        if table.empty:
            table = nan_frame(f"no distance bin has {min_samples} or more samples", n=0)
        parts.append(table.assign(condition=cond, to=to))
    if not parts:
        parts = [nan_frame("empty steps table", to=to, n=0)]
    return pd.concat(parts, ignore_index=True).reindex(columns=BIN_COLUMNS)


def eod_rate_by_distance_episodes(steps: pd.DataFrame, to: str, bins: int = DEFAULTS.rate_bins,
                                  range_cm: tuple[float, float] | None = None,
                                  min_samples: int = DEFAULTS.min_samples, window: int = DEFAULTS.rate_window, *,
                                  fps: PerCondition) -> pd.DataFrame:
    """Per episode and distance bin of :func:`eod_rate_by_distance` (the same rates, bins and steps): ``rate_hz``,
    the mean over the episode's agents of each agent's mean EOD rate over its steps in the bin, and ``n_agents``
    averaged; an agent-episode with fewer than ``min_samples`` steps in a bin leaves that bin out. The agents of
    an episode are not independent, nor are its steps: the episode is the unit of claim C5
    (docs/claims/index.md#c5). Columns :data:`EPISODE_BIN_COLUMNS`; a condition with no such bin gets one NaN row
    with a reason.
    """
    edges, rate, b = _distance_bins(steps, to, bins, range_cm, window, fps)
    frame = steps.loc[b >= 0, AGENT_EPISODE].assign(rate=rate[b >= 0], bin=b[b >= 0])
    per = frame.groupby([*AGENT_EPISODE, "bin"])["rate"].agg(["mean", "size"])
    per = per[per["size"] >= min_samples]["mean"].rename("rate").reset_index()
    out = per.groupby(["condition", "episode", "bin"], as_index=False)["rate"].mean().rename(columns={"rate": "rate_hz"})
    out["n_agents"] = per.groupby(["condition", "episode", "bin"]).size().to_numpy()
    out = out.assign(to=to, **_bin_edges(edges, out["bin"].to_numpy()), reason="")
    none = [nan_frame(f"no agent-episode has {min_samples} steps in a {to} distance bin", condition=cond, to=to,
                      n_agents=0) for cond in sorted(set(steps["condition"]) - set(out["condition"]))]
    if steps.empty:
        none = [nan_frame("empty steps table", to=to, n_agents=0)]
    out = pd.concat([out, *none], ignore_index=True).sort_values(["condition", "episode", "bin"], kind="stable")
    return out.reset_index(drop=True).reindex(columns=EPISODE_BIN_COLUMNS)


def _event_triggered(rate: np.ndarray, events: np.ndarray, lags: np.ndarray) -> np.ndarray:
    """Mean rate at t + lag over the events of one agent-episode; NaN where no event has a rate there."""
    idx = events[:, None] + lags[None, :]
    inside = (idx >= 0) & (idx < rate.size)
    vals = np.where(inside, rate[np.clip(idx, 0, rate.size - 1)], np.nan)
    return pd.DataFrame(vals).mean().to_numpy()  # pandas: a lag no event reaches is NaN, without a warning


def _peri_event_curves(steps: pd.DataFrame, event: str, window: int, min_events: int, rate_window: int,
                       fps: PerCondition) -> tuple[np.ndarray, dict]:
    """The lags -``window``..``window`` and, per condition (sorted), its agent-episodes with at least
    ``min_events`` events: their (episode, agent) keys and curves, each the agent-episode's mean EOD rate (Hz)
    over its events at every lag (NaN where no event reaches one)."""
    if event not in EVENTS:
        raise ValueError(f"event must be one of {list(EVENTS)}, got {event!r}")
    require(steps, [*AGENT_EPISODE, "t", event], "steps table")
    lags = np.arange(-window, window + 1)
    rate = eod_rate(steps, rate_window, fps=fps)
    frame = steps[[*AGENT_EPISODE, "t", event]].assign(rate=rate).sort_values([*AGENT_EPISODE, "t"])
    curves = {}
    for cond, sub in frame.groupby("condition", sort=True):
        units = [(key, g) for key, g in sub.groupby(["episode", "agent"], sort=True) if g[event].sum() >= min_events]
        curves[cond] = ([key for key, _ in units],
                        [_event_triggered(g["rate"].to_numpy(), np.flatnonzero(g[event].to_numpy(bool)), lags)
                         for _, g in units])
    return lags, curves


def peri_event_rate(steps: pd.DataFrame, event: str, window: int = DEFAULTS.peri_window,
                    min_events: int = DEFAULTS.min_events, rate_window: int = DEFAULTS.rate_window,
                    *, fps: PerCondition) -> pd.DataFrame:
    """Mean +- SEM EOD rate (Hz, at each condition's ``fps``) from ``window`` steps before to ``window`` after an
    ``event`` (docs/methods/analyses.md#analysis-signalling); ``lag_ms`` is the lag in the condition's ms.

    ``event`` is a boolean steps column: ``ate``, ``bit`` or ``was_bitten``.
    Each agent-episode with at least ``min_events`` events contributes its mean
    over events at every lag; the mean and SEM are across those agent-episodes
    (``n_agents``), per condition. Without any such agent-episode the condition
    gets one NaN row with a reason. Per episode, the change from a baseline: :func:`peri_event_episodes`.
    """
    lags, per_condition = _peri_event_curves(steps, event, window, min_events, rate_window, fps)
    parts = []
    for cond, (_, curves) in per_condition.items():
        if not curves:
            parts.append(nan_frame(f"no agent-episode has {min_events} or more '{event}' events",
                                   condition=cond, lag=np.nan, n_agents=0, mean_hz=np.nan, sem_hz=np.nan))
            continue
        c = pd.DataFrame(np.vstack(curves))  # agent-episodes x lags; pandas skips NaN without warning
        parts.append(pd.DataFrame({"condition": cond, "lag": lags, "n_agents": c.count().to_numpy(),
                                   "mean_hz": c.mean().to_numpy(), "sem_hz": c.sem().to_numpy(), "reason": ""}))
    if not parts:
        return nan_frame("empty steps table", condition=np.nan, lag=np.nan, n_agents=0, mean_hz=np.nan,
                         sem_hz=np.nan)
    out = pd.concat(parts, ignore_index=True).assign(event=event)
    out["lag_ms"] = out["lag"] * 1000.0 / values_of(fps, out["condition"])
    return out


#: Columns of :func:`peri_event_episodes`: one row per (condition, episode, event).
PERI_EPISODE_COLUMNS = ["condition", "episode", "event", "n_agents", "change_hz", "event_lo", "event_hi",
                        "baseline_lo", "baseline_hi", "reason"]


def peri_event_episodes(steps: pd.DataFrame, event: str, event_window: Sequence[int] = (-10, 10),
                        baseline_window: Sequence[int] = (-100, -50), window: int = DEFAULTS.peri_window,
                        min_events: int = DEFAULTS.min_events, rate_window: int = DEFAULTS.rate_window, *,
                        fps: PerCondition) -> pd.DataFrame:
    """Per episode, how much its agents' EOD rate (Hz) changes around an ``event``: ``change_hz``, the mean over
    the episode's agent-episodes with at least ``min_events`` events (``n_agents`` of them) of the mean of its
    peri-event curve (:func:`peri_event_rate`'s, the same curves) at the lags of ``event_window`` minus that at
    the lags of ``baseline_window`` (both inclusive, in steps; ``event_lo`` .. ``baseline_hi``). An agent-episode
    with no rate in either window is left out; the episode is the unit of claim C6 (docs/claims/index.md#c6).

    Columns :data:`PERI_EPISODE_COLUMNS`. A condition without such an agent-episode gets one NaN row with a
    reason, as does every condition when a window reaches beyond ``window``.
    """
    (e0, e1), (b0, b1) = event_window, baseline_window
    bounds = {"event": event, "event_lo": e0, "event_hi": e1, "baseline_lo": b0, "baseline_hi": b1}
    if max(abs(e0), abs(e1), abs(b0), abs(b1)) > window:
        conds = sorted(steps["condition"].unique()) if "condition" in steps.columns else []
        return pd.concat([nan_frame(f"the windows reach beyond analysis.peri_window = {window} steps",
                                    condition=c, n_agents=0, **bounds) for c in conds or [np.nan]],
                         ignore_index=True).reindex(columns=PERI_EPISODE_COLUMNS)
    lags, per_condition = _peri_event_curves(steps, event, window, min_events, rate_window, fps)
    parts = []
    for cond, (keys, curves) in per_condition.items():
        if not curves:
            parts.append(nan_frame(f"no agent-episode has {min_events} or more '{event}' events", condition=cond,
                                   n_agents=0, **bounds))
            continue
        episode, agent = (np.repeat([k[i] for k in keys], lags.size) for i in (0, 1))
        # the lags no event reaches are dropped, not left to the mean to skip: pandas' groupby mean sums in
        # another order around a NaN, so the same numbers would differ in the last bits
        frame = pd.DataFrame({"episode": episode, "agent": agent, "lag": np.tile(lags, len(keys)),
                              "rate": np.concatenate(curves)}).dropna(subset=["rate"])
        near, base = (frame[(frame["lag"] >= lo) & (frame["lag"] <= hi)].groupby(["episode", "agent"])["rate"].mean()
                      for lo, hi in ((e0, e1), (b0, b1)))
        change = (near - base).dropna().rename("change_hz").reset_index()
        if change.empty:
            parts.append(nan_frame(f"no agent-episode with {min_events} or more '{event}' events has a rate in "
                                   "both windows", condition=cond, n_agents=0, **bounds))
            continue
        per = change.groupby("episode", as_index=False)["change_hz"].mean()  # the agents of one episode: one unit
        per["n_agents"] = change.groupby("episode").size().to_numpy()
        parts.append(per.assign(condition=cond, reason="", **bounds))
    if not parts:
        parts = [nan_frame("empty steps table", condition=np.nan, n_agents=0, **bounds)]
    return pd.concat(parts, ignore_index=True).reindex(columns=PERI_EPISODE_COLUMNS)


def rate_advantage_vs_size(steps: pd.DataFrame, within_cm: float = DEFAULTS.bout_cm,
                           window: int = DEFAULTS.rate_window, *, fps: PerCondition) -> pd.DataFrame:
    """Per pair of agents and episode: EOD-rate advantage vs size advantage while within ``within_cm`` (Fig 3P).

    One row per unordered pair (``agent`` < ``partner``): ``size_advantage`` =
    size(agent) - size(partner), ``rate_advantage_hz`` = mean over the steps
    with the pair within ``within_cm`` of rate(agent) - rate(partner), and
    ``n_steps``. Pairs never that close are left out. Correlate the two with
    :func:`efish.analysis.stats.spearman`.
    """
    require(steps, [*AGENT_EPISODE, "t", "eod", "size", "x_cm", "y_cm"], "steps table")
    frame = steps.assign(rate=eod_rate(steps, window, fps=fps))
    p = pairs(frame, ["rate"])
    p = p[(p["agent"] < p["partner"]) & (p["dist_cm"] <= within_cm)]
    p = p.assign(diff=p["rate"] - p["rate_p"]).dropna(subset=["diff"])
    if p.empty:
        return nan_frame(f"no pair of agents within {within_cm} cm", condition=np.nan, episode=np.nan,
                         agent=np.nan, partner=np.nan, size_advantage=np.nan, rate_advantage_hz=np.nan, n_steps=0)
    out = p.groupby([*EPISODE, "agent", "partner"], sort=True)["diff"].agg(["mean", "size"]).reset_index()
    sizes = agent_sizes(steps)
    own = sizes.reindex(pd.MultiIndex.from_frame(out[AGENT_EPISODE])).to_numpy()
    other = sizes.reindex(pd.MultiIndex.from_frame(out[[*EPISODE, "partner"]])).to_numpy()
    return pd.DataFrame({**{k: out[k] for k in [*EPISODE, "agent", "partner"]}, "size_advantage": own - other,
                         "rate_advantage_hz": out["mean"], "n_steps": out["size"], "reason": ""})
