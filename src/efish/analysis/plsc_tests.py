"""Calibrated PLSC tests (docs/methods/analyses.md#analysis-dynamics; Fig 6H, claim C20): how many dimensions two
agents' hidden states share, and whether fewer are shared far apart than close together.

Both tests take each agent's steps of one distance bin as a list of blocks, one
per episode (T_e x D arrays in time order, agent A's and B's rows paired); the
episode is the unit of every resampling, never the step.

**Why a new null.** :func:`efish.analysis.dynamics.plsc` (the paper's
procedure) shifts agent B's concatenated bin series circularly by a tenth to
nine tenths of its length. Hidden states are autocorrelated and differ from
episode to episode, so such a shift pairs one episode of A with the seam of two
episodes of B: it averages away the episode-to-episode covariation that the
observed pairing keeps, and its null is too narrow. And it compares the i-th
observed singular value with the i-th of the null: once the first components
carry real sharing, the next observed value is the *largest* noise value of the
rest and beats the null's i-th almost always, so counts run on past the true
number. :func:`shared_dimensions` fixes both: its null pairs A's block of
episode e with B's block of a randomly permuted episode (episode-swap, which
keeps each series' autocorrelation and episode structure; exact when episodes
are exchangeable and equally long), and it tests component k step-down, after
projecting the first k - 1 observed components out of both the observed and
every null cross-correlation (Winkler et al. 2020, NeuroImage 220:117065, for
CCA). tests/analysis/test_plsc_tests.py measures both nulls' false-positive
rates on independent autocorrelated series.
"""

from __future__ import annotations

import functools
import itertools

import numpy as np

from ._tables import DEFAULTS

#: Fewest steps an episode needs in both bins to be a unit of :func:`plsc_collapse` (as :func:`dynamics.plsc`
#: needs for a bin).
MIN_STEPS = 10
#: Relative tolerance under which a null singular value ties with the observed one (the identity permutation
#: recomputes the observed value in another summation order).
TIE = 1e-9


def _correlations(n: int, sa: np.ndarray, qa: np.ndarray, sb: np.ndarray, qb: np.ndarray,
                  m: np.ndarray) -> np.ndarray:
    """Cross-correlations of A's and B's units (the PLSC matrices of z-scored states) from sums over n paired steps:
    A's per-unit sums ``sa`` and sums of squares ``qa`` (D_a), and per pairing (leading axis) B's ``sb``, ``qb``
    (.. x D_b) and the cross-products ``m`` = A^T B (.. x D_a x D_b). 0 where a unit is constant: it carries no
    covariance."""
    cov = (m - sa[:, None] * sb[..., None, :] / n) / (n - 1)
    sd_a = np.sqrt(np.maximum(qa - sa ** 2 / n, 0.0) / (n - 1))
    sd_b = np.sqrt(np.maximum(qb - sb ** 2 / n, 0.0) / (n - 1))
    scale = sd_a[:, None] * sd_b[..., None, :]
    return np.divide(cov, scale, out=np.zeros_like(cov), where=scale > 0)


class _Blocks:
    """Agent A's and agent B's blocks, and the sums of any A block paired with any B block, computed once.

    A block i paired with its own B block is the observed pairing. Paired with
    another B block j, B's block is read cyclically from an offset (fixed per
    pair, from ``seed``) for as many steps as A's block has: a longer block is
    cut, a shorter one wraps, so that every step of A has a partner. Sums add
    over blocks, so a null's cross-correlation is a sum of cached blocks, not a
    pass over the steps.
    """

    def __init__(self, a: list[np.ndarray], b: list[np.ndarray], seed: int):
        # centred on each agent's overall mean so that sums of squares do not cancel
        mean_a, mean_b = np.mean(np.concatenate(a), axis=0), np.mean(np.concatenate(b), axis=0)
        self.a, self.b = [x - mean_a for x in a], [x - mean_b for x in b]
        self.seed, self.cache = seed, {}

    def _pair(self, i: int, j: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """B's per-unit sums and sums of squares, and A^T B, of A block i paired with B block j."""
        if (i, j) not in self.cache:
            a, b = self.a[i], self.b[j]
            if i != j:
                offset = np.random.default_rng((self.seed, i, j)).integers(len(b))
                b = b[(offset + np.arange(len(a))) % len(b)]
            self.cache[i, j] = (b.sum(0), (b * b).sum(0), a.T @ b)
        return self.cache[i, j]

    def correlations(self, members: list[int], orders: np.ndarray) -> np.ndarray:
        """Cross-correlation of A's blocks ``members`` each paired with B's block at position ``order[pos]``, for
        each row of ``orders`` (permutations of the positions): orders x D_a x D_b."""
        a = [self.a[i] for i in members]
        n, sa, qa = sum(len(x) for x in a), sum(x.sum(0) for x in a), sum((x * x).sum(0) for x in a)
        grid = [[self._pair(i, j) for j in members] for i in members]
        sb, qb, m = (np.array([[g[k] for g in row] for row in grid]) for k in range(3))
        pos = np.arange(len(members))
        return _correlations(n, sa, qa, sb[pos, orders].sum(1), qb[pos, orders].sum(1), m[pos, orders].sum(1))


def _step_down(observed: np.ndarray, null: np.ndarray, alpha: float) -> tuple[np.ndarray, np.ndarray, int]:
    """Singular values of the ``observed`` cross-correlation, the step-down p of each component and their count.

    Component k (from 1) is tested against the largest singular value of each
    ``null`` matrix (draws x D_a x D_b) after projecting the observed first
    k - 1 components out of both sides: under "only k - 1 shared dimensions",
    the observed s_k is the largest of the rest, so the null must be the
    largest too. p = (1 + #null >= s_k) / (1 + draws). Components count until the
    first with p >= alpha (then p is NaN beyond it): a fixed-sequence test, so
    the chance of counting more than the true number is at most alpha.
    """
    u, s, vt = np.linalg.svd(observed)
    p = np.full(len(s), np.nan)
    for k in range(len(s)):
        keep_a = np.eye(len(u)) - u[:, :k] @ u[:, :k].T
        keep_b = np.eye(len(vt)) - vt[:k].T @ vt[:k]
        largest = np.linalg.svd(keep_a @ null @ keep_b, compute_uv=False)[:, 0]
        p[k] = (1 + np.sum(largest >= s[k] * (1 - TIE))) / (1 + len(null))
        if p[k] >= alpha:
            return s, p, k
    return s, p, len(s)


def _graded_count(blocks: _Blocks, members: list[int], orders: np.ndarray, alpha: float) -> tuple[int, float]:
    """Significant shared dimensions of the blocks ``members`` (one per episode) under the episode-swap null, and
    the graded count: the count plus (1 - p) / (1 - alpha) of the first component that failed, in [0, 1].

    The graded count orders sets with the same count by the evidence for one
    dimension more. A count changes in whole steps, so most relabellings of a
    few episodes leave it where it was; without grading, those ties would cap
    how small :func:`plsc_collapse`'s p can get however clear the difference.
    """
    corr = blocks.correlations(members, np.vstack([np.arange(len(members)), orders]))
    _, p, count = _step_down(corr[0], corr[1:], alpha)
    return count, count + ((1 - p[count]) / (1 - alpha) if count < len(p) else 0.0)


def _check(a: list[np.ndarray], b: list[np.ndarray]) -> str:
    """Why paired blocks cannot be tested ('' when they can)."""
    if len(a) != len(b):
        raise ValueError(f"agent A has {len(a)} blocks, agent B {len(b)}")
    for x, y in zip(a, b, strict=True):
        if len(x) != len(y):
            raise ValueError(f"paired blocks differ in length: {len(x)} vs {len(y)}")
    n = sum(len(x) for x in a)
    if any(len(x) == 0 for x in a):
        return "an episode's block has no steps"
    if len(a) < 2:
        return f"fewer than 2 episodes ({len(a)}): no episode-swap null"
    if n < MIN_STEPS:
        return f"fewer than {MIN_STEPS} steps ({n})"
    if not all(np.all(np.isfinite(x)) for x in [*a, *b]):
        return "non-finite values"
    return ""


def shared_dimensions(a: list[np.ndarray], b: list[np.ndarray], draws: int = DEFAULTS.plsc_null_draws,
                      alpha: float = DEFAULTS.claims_alpha,
                      rng: np.random.Generator | int | None = None) -> dict:
    """Significant shared dimensions of two agents' hidden states under an episode-swap null, tested step-down.

    ``a``, ``b``: one T_e x D block per episode of each agent, rows paired.
    The statistic is each singular value of the cross-correlation of the
    pooled blocks (the PLSC of z-scored states). The null draws ``draws``
    uniformly random permutations of the episodes and pairs A's block of each
    episode with B's block of the episode the permutation assigns (B's block
    cut or wrapped cyclically to A's length; a permutation that maps an episode
    to itself pairs it as observed, which keeps the test exact and lets few
    episodes give only large p). Components are tested in order as in
    :func:`_step_down`.

    Returns ``n_significant`` (NaN when untestable), ``singular_values``,
    ``p_values`` (NaN after the first p >= ``alpha``), ``n_steps``,
    ``n_episodes`` and ``reason``.

    >>> rng = np.random.default_rng(0)
    >>> noise = [rng.normal(size=(200, 4)) for _ in range(12)]
    >>> shared_dimensions(noise[:6], noise[6:], draws=99, rng=1)["n_significant"]
    0
    """
    reason = _check(a, b)
    out = {"n_steps": sum(len(x) for x in a), "n_episodes": len(a), "reason": reason}
    if reason:
        return {**out, "n_significant": np.nan, "singular_values": np.empty(0), "p_values": np.empty(0)}
    rng = np.random.default_rng(rng)
    blocks = _Blocks(a, b, int(rng.integers(2 ** 32)))
    orders = np.array([np.arange(len(a)), *(rng.permutation(len(a)) for _ in range(draws))])
    corr = blocks.correlations(list(range(len(a))), orders)
    s, p, n_sig = _step_down(corr[0], corr[1:], alpha)
    return {**out, "n_significant": n_sig, "singular_values": s, "p_values": p}


def _windows(n_long: int, m: int, count: int, rng: np.random.Generator) -> list[slice]:
    """``count`` random windows of ``m`` consecutive steps in a series of ``n_long`` (one when it has exactly m)."""
    if n_long == m:
        return [slice(0, m)]
    return [slice(s, s + m) for s in rng.integers(0, n_long - m + 1, count)]


def _label_swap_test(statistic, n: int, swaps: int, rng: np.random.Generator) -> tuple[float, float, int, bool]:
    """Two-sided and one-sided ("at most the observed") permutation p of ``statistic`` (a function of which of
    the ``n`` units have their labels swapped, antisymmetric: swapping all negates it), the assignments it is
    over and whether that is all 2^n of them. Half the assignments are computed, the rest are their negations:
    all when 2^n <= ``swaps`` (exact), else ``swaps`` / 2 random ones (a Monte Carlo p, counting the observed
    assignment once more)."""
    observed = statistic(np.zeros(n, bool))
    exact = 2 ** n <= swaps
    if exact:  # every assignment whose first unit keeps its labels
        half = [np.array([False, *bits]) for bits in itertools.product([False, True], repeat=n - 1)]
    else:
        half = list(rng.random((swaps // 2, n)) < 0.5)
    t = np.array([statistic(z) for z in half])
    null = np.concatenate([t, -t])
    tol, extra = TIE * max(1.0, abs(observed)), 0 if exact else 1
    p = (extra + np.sum(np.abs(null) >= abs(observed) - tol)) / (extra + len(null))
    p_less = (extra + np.sum(null <= observed + tol)) / (extra + len(null))
    return float(p), float(p_less), len(null), exact


def plsc_collapse(near_a: list[np.ndarray], near_b: list[np.ndarray], far_a: list[np.ndarray],
                  far_b: list[np.ndarray], draws: int = DEFAULTS.plsc_null_draws,
                  alpha: float = DEFAULTS.claims_alpha, windows: int = 1,
                  swaps: int = DEFAULTS.plsc_label_swaps, rng: np.random.Generator | int | None = None) -> dict:
    """Are fewer dimensions shared far apart than near, at equal steps? A permutation test over episodes.

    ``near_a[e]``, ``near_b[e]``: agent A's and B's steps of episode e in the
    near bin (T x D, time order; 0 rows when it has none), ``far_*`` likewise.
    An episode with at least :data:`MIN_STEPS` steps in both bins is a unit;
    the others are left out.

    *Equal size.* The number of significant dimensions grows with the steps,
    so each unit contributes the same m_e = min(near, far) steps to both bins:
    all of its smaller bin and a random window of m_e consecutive steps of its
    larger bin (consecutive, to keep the autocorrelation the null relies on).

    *Statistic.* T = graded count far - graded count near, each counted by
    :func:`shared_dimensions`'s step-down test (one set of ``draws`` episode
    permutations for every count, so that a count is a function of its blocks
    alone) and graded by :func:`_graded_count` (the count plus the evidence
    for one dimension more, in [0, 1]).

    *Test.* Under "sharing does not depend on the bin", an episode's m_e near
    steps and m_e far steps are exchangeable, so swapping them within any set
    of episodes leaves T's distribution unchanged: a paired permutation test
    with the episode as the unit (:func:`_label_swap_test`). ``p`` is
    two-sided, ``p_less`` one-sided (T at most the observed: the paper's
    "fewer far"). With n units the smallest two-sided p is 2 / 2^n.

    *Windows.* The test is exact for one window per unit: T then sees m_e
    steps of each bin. Averaging T over several windows of the larger bin
    would not be: T would see more of the larger bin than of the smaller, and
    the larger bin is the near one in every episode, so a swap would no longer
    leave T's distribution unchanged (measured: 10% of 200 datasets p_less >
    0.95 at the 5% level with 3 windows, 5.5% with one). So ``windows``
    independent windows each give an exact test, and for more than one the
    p's combine as twice their median, which is a p for any dependence between
    them (Vovk and Wang 2020, Biometrika 107:791); effect and counts are the
    medians and means over windows. The factor 2 costs power: on 12 datasets
    with 3 dimensions shared near only, 10 were significant with one window and
    5 with three. So the analysis uses one window (drawn from its seed).

    Returns ``effect`` (T), ``p``, ``p_less``, ``near_significant`` and
    ``far_significant`` (the observed counts, mean over windows),
    ``count_difference`` (far - near of those), ``n_episodes``, ``n_steps``
    (steps of each bin at equal size), ``n_assignments``, ``exact`` and
    ``reason`` (why NaN).
    """
    if not len(near_a) == len(near_b) == len(far_a) == len(far_b):
        raise ValueError("near and far blocks of both agents must have one entry per episode")
    keep = [e for e in range(len(near_a)) if min(len(near_a[e]), len(far_a[e])) >= MIN_STEPS]
    out = {"effect": np.nan, "p": np.nan, "p_less": np.nan, "count_difference": np.nan, "near_significant": np.nan,
           "far_significant": np.nan, "n_episodes": len(keep), "n_steps": 0, "n_assignments": 0, "exact": False,
           "reason": ""}
    if len(keep) < 2:
        return {**out, "reason": f"fewer than 2 episodes with >= {MIN_STEPS} steps in both bins ({len(keep)})"}
    rng = np.random.default_rng(rng)
    a, b = [], []
    ids: dict[str, list[list[int]]] = {"near": [], "far": []}  # ids[bin][unit][window] -> index of its block
    for e in keep:
        m = min(len(near_a[e]), len(far_a[e]))
        for name, xa, xb in (("near", near_a[e], near_b[e]), ("far", far_a[e], far_b[e])):
            cuts = _windows(len(xa), m, windows, rng)  # the smaller bin is one block, the same in every window
            ids[name].append([len(a) + (w if len(cuts) > 1 else 0) for w in range(windows)])
            a.extend(np.asarray(xa, float)[c] for c in cuts)
            b.extend(np.asarray(xb, float)[c] for c in cuts)
        out["n_steps"] += m
    if reason := _check(a, b):
        return {**out, "reason": reason}
    blocks = _Blocks(a, b, int(rng.integers(2 ** 32)))
    orders = np.array([rng.permutation(len(keep)) for _ in range(draws)])
    cache: dict[tuple[int, ...], tuple[int, float]] = {}

    def counts(members: tuple[int, ...]) -> tuple[int, float]:
        if members not in cache:
            cache[members] = _graded_count(blocks, list(members), orders, alpha)
        return cache[members]

    def sides(w: int, swapped: np.ndarray) -> tuple[tuple[int, float], tuple[int, float]]:
        """Far and near (count, graded count) of window ``w`` with the units ``swapped`` relabelled."""
        far = counts(tuple(ids["near" if s else "far"][u][w] for u, s in enumerate(swapped)))
        near = counts(tuple(ids["far" if s else "near"][u][w] for u, s in enumerate(swapped)))
        return far, near

    def difference(w: int, swapped: np.ndarray) -> float:
        """T of window ``w``: graded count far minus near."""
        far, near = sides(w, swapped)
        return far[1] - near[1]

    n, effects, tests, observed = len(keep), [], [], []
    for w in range(windows):
        far, near = sides(w, np.zeros(n, bool))
        observed.append((far[0], near[0]))
        effects.append(far[1] - near[1])
        tests.append(_label_swap_test(functools.partial(difference, w), n, swaps, rng))
    p, p_less = (np.median([t[i] for t in tests]) * (2 if windows > 1 else 1) for i in (0, 1))
    far_count, near_count = np.mean(observed, axis=0)
    return {**out, "effect": float(np.median(effects)), "p": float(min(1.0, p)), "p_less": float(min(1.0, p_less)),
            "count_difference": float(far_count - near_count), "near_significant": float(near_count),
            "far_significant": float(far_count), "n_assignments": tests[0][2], "exact": tests[0][3]}
