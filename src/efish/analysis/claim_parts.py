"""Building blocks of :mod:`efish.analysis.claims`: a claim's tested parts, their verdicts, the bootstrap.

A claim of the paper (docs/claims/index.md) often says several things at once
(C10: two ablations cut food, a third keeps it and raises EOD probability...).
Each thing is one :class:`Part`: an effect with the paper's sign, a p-value, an
n, a bootstrap interval and a verdict; :func:`combine` makes the claim's one row
of them and :func:`part_rows` a row per part (``claim_parts.parquet``, which
keeps each part's effect and interval, e.g. to follow them along training).

Verdicts (docs/claims/index.md#verdicts): **holds** = the paper's sign and
p < alpha; **weaker** = the paper's sign but not significant (an effect of the
opposite sign that is not significant is also weaker: nothing refutes the claim,
and the reason says so); **fails** = the opposite sign and significant, or a
criterion that cannot hold; **not decidable** = the data cannot carry the test
(a condition at a ceiling or floor), with the reason; **not run** = no table or
no testable data, with the reason. A part the paper reports as *no difference*
(K-off food in C10) holds when it is *shown equivalent*: its two one-sided tests
(TOST) within the part's margin give p < alpha; it fails when the difference is
significant and larger than the margin; otherwise it is weaker. Every difference
test here is two-sided, so that an effect of the opposite sign can be
significant.

A part may be reported *beside* a claim without deciding it (``decides=False``,
e.g. the Methods' 4-agent mute design beside the Results' 2-agent one): its
verdict is shown in the reason, the claim's verdict ignores it.

Also here, the statistics a claim needs that no analysis table has: an OLS
slope with its p, a one-sample Wilcoxon (via :func:`efish.analysis.stats.wilcoxon_paired`),
Fisher's exact test of two rates and the held-out decoding skill per episode.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import stats as sps

from ..config.schema import EfishConfig
from ..layout import parse_table
from ._tables import AGENT_EPISODE
from .claim_stats import (
    at_ceiling,
    equivalence_margin,
    paired_vs_control,
    pooled_sd,
    tost_paired,
    tost_unpaired,
)
from .dynamics import units
from .stats import mann_whitney, spearman, wilcoxon_paired

VERDICTS = ("holds", "weaker", "fails", "not decidable", "not run")
ROW_COLUMNS = ["claim", "panel", "statistic", "effect", "ci_low", "ci_high", "n", "p", "verdict", "reason"]
#: One row per (claim, part) (:func:`part_rows`): the part's label, its statistic, the paper's sign (+1, -1; 0 for
#: "no difference"; NaN for "any difference" or a part that did not run), its effect, interval, n, the p its
#: verdict rests on, its verdict, whether it decides the claim, and its reason.
PART_COLUMNS = ["claim", "part", "statistic", "sign", "effect", "ci_low", "ci_high", "n", "p", "verdict", "decides",
                "reason"]
NAN_CI = (np.nan, np.nan)


class MissingTable(LookupError):
    """A table a claim needs is not in the results folder; the message names it and its assay."""

    def __init__(self, path: str):
        table = parse_table(path)
        what = (path if table is None else f"assay {table.assay}" if table.kind == "assays"
                else f"analysis {table.analysis} of assay {table.assay}")
        super().__init__(f"needs {path}, which this run lacks ({what} has not run at this scale)")


@dataclass(frozen=True)
class Outcome:
    """What a part computes: effect (paper's units), p, n, the paper's sign, interval, and a note or why-NaN reason.

    ``sign``: +1 or -1, the direction the paper reports; 0, the paper reports no
    difference (holds when n.s.); None, any difference (holds when significant).
    ``verdict`` overrides the rule for a part decided by a criterion, not a test
    (or "not decidable" at a ceiling). For ``sign`` 0, ``p_equiv`` is the TOST
    p within ``margin`` (in the effect's units) and ``p`` the difference test's.
    """

    effect: float
    p: float
    n: int
    sign: int | None
    ci: tuple[float, float] = NAN_CI
    reason: str = ""
    verdict: str | None = None
    p_equiv: float = np.nan
    margin: float = np.nan


@dataclass(frozen=True)
class Part:
    """One tested statement of a claim, with its verdict and the paper's sign (:class:`Outcome`; None when the
    part did not run)."""

    label: str
    statistic: str
    effect: float = np.nan
    ci: tuple[float, float] = NAN_CI
    n: int = 0
    p: float = np.nan
    verdict: str = "not run"
    reason: str = ""
    decides: bool = True
    sign: int | None = None


def judge(effect: float, p: float, sign: int | None, alpha: float, p_equiv: float = np.nan,
          margin: float = np.nan) -> tuple[str, str]:
    """Verdict and a short reason from an effect, its two-sided p and the paper's sign (module docstring).

    >>> judge(0.3, 0.01, +1, 0.05), judge(-0.3, 0.01, +1, 0.05)[0]
    (('holds', ''), 'fails')
    >>> [judge(e, p, 0, 0.05, pe, 1.0)[0] for e, p, pe in ((0.1, 0.6, 0.01), (2.0, 0.01, 0.9), (0.3, 0.6, 0.3))]
    ['holds', 'fails', 'weaker']
    """
    significant = p < alpha
    if sign is None:
        return ("holds", "") if significant else ("weaker", f"not significant (p = {p:.3g})")
    if sign == 0:
        within = f"within +-{margin:.3g}"
        if p_equiv < alpha:
            return "holds", f"shown equivalent {within} (TOST p = {p_equiv:.3g}; difference p = {p:.3g})"
        if significant and abs(effect) > margin:
            return "fails", f"a significant difference (p = {p:.3g}) beyond the margin {within}; the paper reports none"
        return "weaker", (f"neither shown equivalent {within} (TOST p = {p_equiv:.3g}) nor different beyond it "
                          f"(p = {p:.3g})")
    direction = np.sign(effect) * sign
    if direction > 0:
        return ("holds", "") if significant else ("weaker", f"the paper's sign, not significant (p = {p:.3g})")
    if direction < 0:
        return (("fails", f"opposite sign, significant (p = {p:.3g})") if significant
                else ("weaker", f"opposite sign, not significant (p = {p:.3g})"))
    return "weaker", "zero effect"


def evaluate(label: str, statistic: str, compute: Callable[[], Outcome], alpha: float, decides: bool = True) -> Part:
    """Run one part: a missing table or degenerate data (ValueError) is a ``not run`` part whose reason says why.

    The part's ``p`` is the one its verdict rests on: the TOST p for a "no
    difference" part (sign 0), else the difference test's.
    """
    try:
        out = compute()
    except (MissingTable, ValueError) as exc:
        return Part(label, statistic, reason=str(exc).strip("'\""), decides=decides)
    except KeyError as exc:  # a table from an older run without a column this claim reads
        return Part(label, statistic, reason=f"a table lacks the column or key {exc}", decides=decides)
    p = out.p_equiv if out.sign == 0 and out.verdict is None else out.p
    base = Part(label, statistic, float(out.effect), tuple(map(float, out.ci)), int(out.n), float(p), decides=decides,
                sign=out.sign)
    if out.verdict is not None:
        return Part(**{**base.__dict__, "verdict": out.verdict, "reason": out.reason})
    if not (np.isfinite(out.effect) and np.isfinite(p)):
        return Part(**{**base.__dict__, "verdict": "not run", "reason": out.reason or "no test result"})
    verdict, why = judge(out.effect, out.p, out.sign, alpha, out.p_equiv, out.margin)
    return Part(**{**base.__dict__, "verdict": verdict, "reason": "; ".join(r for r in (why, out.reason) if r)})


def combined_verdict(verdicts: Iterable[str]) -> str:
    """A claim's verdict from its deciding parts': any fails -> fails; all that could be decided hold -> holds;
    a part not run (a missing table) makes holds weaker; nothing decidable -> not decidable; none ran -> not run.

    >>> combined_verdict(["holds", "not decidable"]), combined_verdict(["holds", "not run"])
    ('holds', 'weaker')
    >>> combined_verdict(["not decidable", "not run"]), combined_verdict(["weaker", "fails"])
    ('not decidable', 'fails')
    """
    v = list(verdicts)
    decided = [x for x in v if x in ("holds", "weaker", "fails")]
    if not decided:
        return "not decidable" if "not decidable" in v else "not run"
    if "fails" in decided:
        return "fails"
    return "holds" if all(x in ("holds", "not decidable") for x in v) else "weaker"


def _fmt(x: float) -> str:
    return f"{x:.3g}" if np.isfinite(x) else "NaN"


def combine(claim: str, panel: str, parts: list[Part]) -> dict:
    """The claim's row: its verdict over all parts; effect, interval, n and p of the first part that ran.

    With several parts the reason lists each: ``label: verdict (effect, p)``
    and its own reason, so the row says which statement carried the verdict;
    a part reported beside the claim (``decides`` False) is marked so and does
    not enter the verdict.
    """
    deciding = [p for p in parts if p.decides] or parts
    shown = next((p for p in deciding if p.verdict not in ("not run", "not decidable")), deciding[0])
    if len(parts) == 1:
        reason = shown.reason
    else:
        reason = "; ".join(f"{p.label}{'' if p.decides else ' (beside, not deciding)'}: {p.verdict}"
                           + (f" (effect {_fmt(p.effect)}, p {_fmt(p.p)})" if np.isfinite(p.effect) else "")
                           + (f" [{p.reason}]" if p.reason else "") for p in parts)
    statistic = shown.statistic if len(parts) == 1 else f"{shown.label}: {shown.statistic}"
    return {"claim": claim, "panel": panel, "statistic": statistic, "effect": shown.effect,
            "ci_low": shown.ci[0], "ci_high": shown.ci[1], "n": shown.n, "p": shown.p,
            "verdict": combined_verdict(p.verdict for p in deciding), "reason": reason}


def part_rows(claim: str, parts: Iterable[Part]) -> list[dict]:
    """The claim's rows of :data:`PART_COLUMNS`, one per part in the claim's order (the row :func:`combine` makes
    summarises them in its reason; these keep each part's effect, interval and p, e.g. to follow them along
    training, :mod:`efish.analysis.claims_stages`)."""
    return [{"claim": claim, "part": p.label, "statistic": p.statistic,
             "sign": np.nan if p.sign is None else float(p.sign), "effect": p.effect, "ci_low": p.ci[0],
             "ci_high": p.ci[1], "n": p.n, "p": p.p, "verdict": p.verdict, "decides": p.decides, "reason": p.reason}
            for p in parts]


# ---------------------------------------------------------------- bootstrap
def bootstrap_ci(data: pd.DataFrame, stat: Callable[[pd.DataFrame], float], units: list[str],
                 resamples: int, rng: np.random.Generator, strata: str | None = None,
                 level: float = 0.95) -> tuple[float, float]:
    """Percentile interval of ``stat`` over resamples of ``data``'s units (e.g. episodes), drawn with replacement.

    A unit is a value of the ``units`` columns; every row of a drawn unit comes
    along (an episode's agents stay together). With ``strata`` (e.g. condition)
    each stratum's units are drawn separately, as many as it has. The resample
    gets a ``_draw`` column numbering the drawn units, so that a statistic that
    pairs rows can tell a unit drawn twice apart. NaN when fewer than half of the
    resamples give a finite value (the statistic is undefined too often).
    """
    if data.empty or resamples < 1:
        return NAN_CI
    keys = ([strata] if strata else []) + list(units)
    index = data.groupby(keys, sort=True, dropna=False).indices
    groups = list(index.values())
    stratum, _ = pd.factorize(pd.Series([k[0] for k in index] if strata else [0] * len(groups), dtype=object))
    pools = [np.flatnonzero(stratum == s) for s in range(stratum.max() + 1)]
    lengths = np.array([len(g) for g in groups])
    values = np.empty(resamples)
    for b in range(resamples):
        chosen = np.concatenate([rng.choice(pool, size=len(pool), replace=True) for pool in pools])
        rows = np.concatenate([groups[u] for u in chosen])
        sample = data.iloc[rows].assign(_draw=np.repeat(np.arange(len(chosen)), lengths[chosen]))
        values[b] = stat(sample)
    finite = values[np.isfinite(values)]
    if finite.size < resamples / 2:
        return NAN_CI
    tail = 100 * (1 - level) / 2
    lo, hi = np.percentile(finite, [tail, 100 - tail])
    return float(lo), float(hi)


# ---------------------------------------------------------------- statistics
def ols(x, y) -> tuple[float, float, int]:
    """Slope of y on x by least squares, its two-sided p (scipy.stats.linregress) and n; ValueError if undefined."""
    xy = np.column_stack([np.asarray(x, np.float64), np.asarray(y, np.float64)])
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    if len(xy) < 3:
        raise ValueError(f"fewer than 3 finite points for a slope ({len(xy)})")
    if np.ptp(xy[:, 0]) == 0:
        raise ValueError("the regressor is constant")
    if np.ptp(xy[:, 1]) == 0:
        raise ValueError("the response is constant")
    fit = sps.linregress(xy[:, 0], xy[:, 1])
    return float(fit.slope), float(fit.pvalue), len(xy)


def slope(x, y) -> float:
    """The OLS slope alone (NaN where undefined): the bootstrap's statistic for :func:`ols`."""
    try:
        return ols(x, y)[0]
    except ValueError:
        return np.nan


def wilcoxon_vs(values, reference: float) -> pd.Series:
    """Two-sided Wilcoxon signed-rank test of ``values`` against a constant: a :mod:`.stats` row.

    Effect = median of (value - reference). Built as a paired test against a
    column of the constant, so the tie and degenerate rules are those of
    :func:`efish.analysis.stats.wilcoxon_paired`.
    """
    v = np.asarray(values, np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        raise ValueError("no finite value to test")
    pair = np.arange(v.size)
    long = pd.DataFrame({"pair": np.r_[pair, pair], "role": ["value"] * v.size + ["reference"] * v.size,
                         "v": np.r_[v, np.full(v.size, float(reference))]})
    return wilcoxon_paired(long, "v", "role", "reference", "pair").iloc[0]


def heldout_skill(x: np.ndarray, targets: dict[str, tuple[np.ndarray, bool]], groups: np.ndarray,
                  folds: int) -> pd.DataFrame:
    """Held-out decoding skill of each target per group (episode): 1 - MSE(readout) / MSE(train mean).

    The readout is OLS from ``x`` (sklearn LinearRegression, all targets fitted
    jointly) under GroupKFold(``folds``) over ``groups``, like
    :func:`efish.analysis.dynamics.decode`; the skill is scored per held-out
    group instead of pooled, so two targets (or two subsets) can be compared
    paired over episodes. A circular target (radians) is (cos, sin), MSE summed.
    Rows with a non-finite value are dropped. Columns: group, target, n, skill.
    """
    from sklearn.linear_model import LinearRegression
    from sklearn.model_selection import GroupKFold

    x = np.asarray(x, np.float64)
    blocks, names = [], []
    for name, (y, circular) in targets.items():
        y = np.asarray(y, np.float64)
        blocks.append(np.column_stack([np.cos(y), np.sin(y)]) if circular else y[:, None])
        names += [name] * blocks[-1].shape[1]
    y, names = np.hstack(blocks), np.asarray(names)
    keep = np.all(np.isfinite(x), axis=1) & np.all(np.isfinite(y), axis=1)
    x, y, groups = x[keep], y[keep], np.asarray(groups)[keep]
    n_groups = len(np.unique(groups))
    if n_groups < 2:
        raise ValueError(f"fewer than 2 episodes with finite rows to decode ({n_groups})")
    rows = []
    for train, test in GroupKFold(n_splits=min(folds, n_groups)).split(x, y, groups):
        pred = LinearRegression().fit(x[train], y[train]).predict(x[test])
        err, base = (pred - y[test]) ** 2, (y[train].mean(axis=0) - y[test]) ** 2
        for g in np.unique(groups[test]):
            mine = groups[test] == g
            for name in targets:
                cols = names == name
                mse, mse0 = err[mine][:, cols].sum(axis=1).mean(), base[mine][:, cols].sum(axis=1).mean()
                rows.append({"group": g, "target": name, "n": int(mine.sum()),
                             "skill": 1 - mse / mse0 if mse0 > 0 else np.nan})
    return pd.DataFrame(rows, columns=["group", "target", "n", "skill"])


def markdown_table(frame: pd.DataFrame) -> str:
    """A GitHub markdown table of ``frame`` (cells as given; '|' escaped)."""
    def cell(v) -> str:
        return str(v).replace("|", "\\|").replace("\n", " ")

    lines = ["| " + " | ".join(map(cell, frame.columns)) + " |", "|" + "---|" * len(frame.columns)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in frame.itertuples(index=False)]
    return "\n".join(lines) + "\n"


# ------------------------------------------------------- claims and their context
Tables = Mapping[str, pd.DataFrame]


# ------------------------------------------------------------------ context
@dataclass
class Context:
    """What a claim's parts share: its tables, the config, the claim's own seeded generator."""

    claim: str
    tables: Tables
    cfg: EfishConfig
    rng: np.random.Generator = field(init=False)

    def __post_init__(self):
        # the claim's number joins the seed, so a claim's draws do not depend on which claims ran before it
        self.rng = np.random.default_rng([self.cfg.analysis.claims_seed, int(self.claim[1:])])

    def table(self, path: str) -> pd.DataFrame:
        """The table at ``path``; :class:`MissingTable` (a ``not run`` part) when the run lacks it."""
        if path not in self.tables:
            raise MissingTable(path)
        return self.tables[path]

    def ci(self, data: pd.DataFrame, stat: Callable[[pd.DataFrame], float], units_: Iterable[str] = ("episode",),
           strata: str | None = "condition", resamples: int | None = None) -> tuple[float, float]:
        """Bootstrap interval of ``stat`` over episodes (within each condition), seeded per claim."""
        strata = strata if strata in data.columns else None
        n = self.cfg.analysis.claims_resamples if resamples is None else resamples
        return bootstrap_ci(data, stat, list(units_), n, self.rng, strata)

    def part(self, label: str, statistic: str, compute: Callable[[], Outcome], decides: bool = True) -> Part:
        return evaluate(label, statistic, compute, self.cfg.analysis.claims_alpha, decides)


@dataclass(frozen=True)
class Claim:
    """A claim of the paper (docs/claims/index.md): id, figure panels, the tables it reads, and its function (tables,
    cfg) -> its parts.

    :meth:`assess` gives the claim's row and its parts from one computation; :meth:`run` the row alone.
    """

    id: str
    panel: str
    statement: str
    tables: tuple[str, ...]
    parts: Callable[[Tables, EfishConfig], list[Part]]

    def assess(self, tables: Tables, cfg: EfishConfig) -> tuple[dict, list[Part]]:
        """The claim's row (:data:`ROW_COLUMNS`, :func:`combine`) and the parts it combines."""
        found = self.parts(tables, cfg)
        return combine(self.id, self.panel, found), found

    def run(self, tables: Tables, cfg: EfishConfig) -> dict:
        """The claim's row (:data:`ROW_COLUMNS`)."""
        return self.assess(tables, cfg)[0]


CLAIMS: dict[str, Claim] = {}


def claim(cid: str, panel: str, statement: str, tables: Iterable[str]):
    """Register a claim: wraps ``parts(ctx) -> [Part]`` into ``fn(tables, cfg) -> [Part]``, lists it in CLAIMS
    and returns its :meth:`Claim.run` (``fn(tables, cfg) -> row``)."""
    def register(parts: Callable[[Context], list[Part]]) -> Callable[[Tables, EfishConfig], dict]:
        @functools.wraps(parts)
        def found(tables: Tables, cfg: EfishConfig) -> list[Part]:
            try:
                return parts(Context(cid, tables, cfg))
            except (MissingTable, ValueError) as exc:  # a part that could not even be set up
                return [Part(cid, statement, reason=str(exc))]

        CLAIMS[cid] = Claim(cid, panel, statement, tuple(tables), found)
        return CLAIMS[cid].run
    return register


# ---------------------------------------------------------- shared tests
def median_diff(value: str, group: str, a, b) -> Callable[[pd.DataFrame], float]:
    """median(value | group == a) - median(value | group == b); NaN if a group is empty."""
    def stat(d: pd.DataFrame) -> float:
        x, y = d.loc[d[group] == a, value].dropna(), d.loc[d[group] == b, value].dropna()
        return float(x.median() - y.median()) if len(x) and len(y) else np.nan
    return stat


def mean_diff(value: str, group: str, a, b) -> Callable[[pd.DataFrame], float]:
    def stat(d: pd.DataFrame) -> float:
        x, y = d.loc[d[group] == a, value].dropna(), d.loc[d[group] == b, value].dropna()
        return float(x.mean() - y.mean()) if len(x) and len(y) else np.nan
    return stat


def median_minus(value: str, reference: float) -> Callable[[pd.DataFrame], float]:
    return lambda d: float(np.nanmedian(d[value])) - reference if d[value].notna().any() else np.nan


def rho_of(x: str, y: str) -> Callable[[pd.DataFrame], float]:
    def stat(d: pd.DataFrame) -> float:
        xy = d[[x, y]].astype(np.float64).dropna()
        if len(xy) < 3 or xy[x].nunique() < 2 or xy[y].nunique() < 2:
            return np.nan
        return float(sps.spearmanr(xy[x], xy[y]).statistic)
    return stat


def present(frame: pd.DataFrame, column: str, values: Iterable, what: str) -> None:
    """ValueError naming the values of ``column`` that ``frame`` lacks (a condition with no data)."""
    if missing := [v for v in values if v not in set(frame[column].dropna())]:
        raise ValueError(f"no {what} for {column} {missing}")


def stat_row(rows: pd.DataFrame, **match) -> pd.Series:
    """The one statistic row matching ``match`` (e.g. measure='bite'); ValueError naming what is missing."""
    sel = rows
    for k, v in match.items():
        sel = sel[sel[k] == v] if k in sel.columns else sel.iloc[0:0]
    if sel.empty:
        raise ValueError(f"no statistic row with {match}")
    return sel.iloc[0]


def from_row(row: pd.Series, sign: int | None, ci: tuple[float, float], note: str = "") -> Outcome:
    """An :class:`Outcome` from a :mod:`efish.analysis.stats` row (effect, p, n, reason)."""
    reason = row.get("reason")
    reason = reason if isinstance(reason, str) else ""
    return Outcome(float(row["effect"]), float(row["p"]), int(row["n"]), sign, ci, reason or note)


def mann_whitney_part(ctx: Context, frame: pd.DataFrame, value: str, group: str, a, b, sign: int | None) -> Outcome:
    """Mann-Whitney of ``value``, group ``a`` vs ``b`` (effect: median difference a - b), interval over episodes."""
    present(frame, group, [a, b], f"finite {value}")
    sub = frame[frame[group].isin([a, b])]
    row = mann_whitney(sub, value, group, b).set_index("group").loc[a]
    ci = ctx.ci(sub, median_diff(value, group, a, b), strata=group)
    return from_row(row, sign, ci)



def spearman_part(ctx: Context, frame: pd.DataFrame, x: str, y: str, sign: int | None) -> Outcome:
    """Spearman rho of ``y`` with ``x`` over the rows of ``frame``, interval over episodes."""
    return from_row(spearman(frame, x, y).iloc[0], sign, ctx.ci(frame, rho_of(x, y)))


def one_sample_part(ctx: Context, frame: pd.DataFrame, value: str, reference: float, sign: int,
                units_: Iterable[str] = ("episode",)) -> Outcome:
    """Wilcoxon of ``value`` against ``reference`` (effect: median - reference), interval over ``units_``."""
    row = wilcoxon_vs(frame[value], reference)
    return from_row(row, sign, ctx.ci(frame, median_minus(value, reference), units_))


def ols_part(ctx: Context, frame: pd.DataFrame, x: str, y: str, sign: int) -> Outcome:
    """OLS slope of ``y`` on ``x`` with its p, interval over episodes."""
    b, p, n = ols(frame[x], frame[y])
    return Outcome(b, p, n, sign, ctx.ci(frame, lambda d: slope(d[x], d[y])))



def joined(ctx: Context, hidden: str, steps: str, columns: list[str]) -> tuple[pd.DataFrame, list[str]]:
    """Hidden rows joined with ``columns`` of the steps table (keys condition, episode, agent, t), and the units."""
    h, s = ctx.table(hidden), ctx.table(steps)
    keys = [*AGENT_EPISODE, "t"]
    return h.merge(s[keys + columns], on=keys).sort_values(keys, kind="stable"), units(h)


def paired_difference(ctx: Context, long: pd.DataFrame, better: str, worse: str, value: str = "skill",
                      key: str = "target", unit: str = "group", sign: int = +1) -> Outcome:
    """Paired Wilcoxon over ``unit`` (episodes) of ``value`` where ``key`` is ``better`` minus where it is ``worse``
    (e.g. two decoding targets' held-out skill), with an interval over the units."""
    long = long.rename(columns={unit: "episode", key: "target", value: "skill"})
    row = wilcoxon_paired(long, "skill", "target", worse, "episode").set_index("group").loc[better]
    wide = long.pivot(index="episode", columns="target", values="skill")
    diff = (wide[better] - wide[worse]).dropna().rename("diff").reset_index()
    return from_row(row, sign, ctx.ci(diff, median_minus("diff", 0.0), strata=None))


# ------------------------------------------------- paired and equivalence parts (paired tests, equivalence, ceilings)
def margin_for(ctx: Context, control: np.ndarray, other: np.ndarray) -> tuple[float, str]:
    """The equivalence margin of an "n.s." part from the config (:func:`efish.analysis.claim_stats.equivalence_margin`)."""
    a = ctx.cfg.analysis
    c, o = (np.asarray(v, np.float64) for v in (control, other))
    sd = pooled_sd(c[np.isfinite(c)], o[np.isfinite(o)])
    return equivalence_margin(c, sd, a.claims_margin_fraction, a.claims_margin_sd)


def paired_part(ctx: Context, summary: pd.DataFrame, measure: str, condition: str, control: str,
                sign: int, family: Iterable[str] | None = None) -> Outcome:
    """``condition`` vs ``control`` paired over their shared episodes: Wilcoxon signed-rank, Holm-adjusted
    over ``family`` (default: every condition of ``summary``) compared with the same control; effect = median paired
    difference with a bootstrap interval over episodes. For ``sign`` 0 also the paired TOST within the margin."""
    present(summary, "condition", [condition, control], f"episodes with {measure}")
    family = list(summary["condition"].unique()) if family is None else [*family, control]
    rows = paired_vs_control(summary[summary["condition"].isin(family)], measure, control)
    row = rows.set_index("group").loc[condition]
    wide = summary[summary["condition"].isin([condition, control])].pivot(index="episode", columns="condition",
                                                                          values=measure).astype(np.float64)
    both = wide[[condition, control]].dropna()
    diff = (both[condition] - both[control]).rename("diff").reset_index()
    ci = ctx.ci(diff, median_minus("diff", 0.0), strata=None)
    note = f"paired over {len(both)} shared episodes, Holm over {len(rows)} conditions vs {control}"
    out = from_row(row, sign, ci)
    if out.reason.startswith("all paired differences are zero"):  # e.g. no condition ate anything: no evidence
        return dataclasses.replace(out, verdict="not decidable", reason=f"{out.reason} ({note})")
    if sign == 0:
        margin, how = margin_for(ctx, both[control].to_numpy(), both[condition].to_numpy())
        out = dataclasses.replace(out, p_equiv=tost_paired(diff["diff"].to_numpy(), margin), margin=margin)
        note += f"; margin {margin:.3g} = {how}"
    return dataclasses.replace(out, reason="; ".join(r for r in (out.reason, note) if r))


def unpaired_equivalence(ctx: Context, frame: pd.DataFrame, value: str, group: str, a, b) -> Outcome:
    """Mann-Whitney of ``value``, ``a`` vs ``b`` (the control), and the unpaired TOST within the margin."""
    out = mann_whitney_part(ctx, frame, value, group, a, b, 0)
    x, c = (frame.loc[frame[group] == g, value].to_numpy(np.float64) for g in (a, b))
    margin, how = margin_for(ctx, c, x)
    return dataclasses.replace(out, p_equiv=tost_unpaired(x, c, margin), margin=margin,
                               reason="; ".join(r for r in (out.reason, f"margin {margin:.3g} = {how}") if r))


def ceiling(ctx: Context, summary: pd.DataFrame, food: pd.DataFrame, conditions: Iterable[str]) -> Outcome | None:
    """A "not decidable" outcome when one of ``conditions`` ate every pellet in most episodes (a ceiling), else None."""
    share = ctx.cfg.analysis.claims_ceiling_share
    for condition in conditions:
        full, how = at_ceiling(summary, food, condition, share)
        if full:
            return Outcome(np.nan, np.nan, int((summary["condition"] == condition).sum()), None,
                           verdict="not decidable", reason=f"at a ceiling: {how}, so no food difference can appear")
    return None
