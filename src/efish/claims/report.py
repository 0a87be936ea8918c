"""Claims tables for people: the markdown page of one run, and two runs side by side (``efish compare-claims``).

A claims table is the output of :func:`efish.claims.claims_table`
(``results/{run}/claims/claims.parquet``).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from ..io import read_parquet
from ..layout import CLAIMS_TABLE, RESULTS_ROOT, Run
from .verdicts import VERDICTS


def markdown_table(frame: pd.DataFrame) -> str:
    """A GitHub markdown table of ``frame`` (cells as given; '|' escaped)."""
    def cell(v) -> str:
        return str(v).replace("|", "\\|").replace("\n", " ")

    lines = ["| " + " | ".join(map(cell, frame.columns)) + " |", "|" + "---|" * len(frame.columns)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in frame.itertuples(index=False)]
    return "\n".join(lines) + "\n"


def _num(x: float) -> str:
    return f"{x:.3g}" if np.isfinite(x) else "-"


def _effects(table: pd.DataFrame, prefix: str = "") -> list[str]:
    """``effect [ci_low, ci_high]`` per row (of the ``prefix``ed columns, e.g. ``recipe_``), the effect alone where
    there is no interval."""
    return [f"{_num(e)} [{_num(lo)}, {_num(hi)}]" if np.isfinite(lo) else _num(e)
            for e, lo, hi in zip(table[f"{prefix}effect"], table[f"{prefix}ci_low"], table[f"{prefix}ci_high"],
                                 strict=True)]


def _counts(verdicts: pd.Series) -> str:
    counts = verdicts.value_counts()
    return ", ".join(f"{counts[v]} {v}" for v in VERDICTS if v in counts)


def has_recipe(table: pd.DataFrame) -> bool:
    """Whether a claims table carries the recipe's verdict (:mod:`efish.claims.recipe`)."""
    return "recipe_verdict" in table.columns


def claims_markdown(table: pd.DataFrame, header: str, trends: Mapping[str, str] | None = None) -> str:
    """The claims table as markdown under a ``header`` line.

    With the recipe's verdict (:mod:`efish.claims.recipe`) it is the headline: claim, panel, recipe verdict,
    recipe effect [CI] over its seeds and the tally of its parts' verdicts; then the selected seed's statistic, effect
    [CI] (each part's interval at level 1 - 2 alpha / family, the one its verdict reads), n, p, verdict and the
    tally of its parts' verdicts, seeds_agree (each top seed's own verdict, :mod:`efish.claims.seeds`) and the reasons (what
    docs/claims/results.md quotes and the Snakemake report shows). With ``trends`` (claim -> line,
    :func:`efish.claims.stages.trend_lines`) the section :func:`along_training` follows."""
    shown = pd.DataFrame({"claim": table["claim"], "panel": table["panel"]})
    recipe = has_recipe(table)
    if recipe:
        shown["recipe verdict"] = table["recipe_verdict"]
        if "recipe_parts" in table.columns:
            shown["recipe parts"] = table["recipe_parts"]
        shown["recipe effect [CI] (seeds)"] = [f"{e} ({k})" for e, k in zip(_effects(table, "recipe_"),
                                                                            table["recipe_seeds"], strict=True)]
    seed = "selected seed's " if recipe else ""
    shown = shown.assign(**{"statistic": table["statistic"], f"{seed}effect [CI]": _effects(table),
                            "n": table["n"], "p": [_num(p) for p in table["p"]], f"{seed}verdict": table["verdict"]})
    if "parts" in table.columns:
        shown[f"{seed}parts"] = table["parts"]
    if "seeds_agree" in table.columns:
        shown["seeds_agree"] = table["seeds_agree"]
    shown["reason"] = table["reason"]
    summary = _counts(table["verdict"])
    if recipe:
        shown["recipe reason"] = table["recipe_reason"]
        summary = f"The recipe (its top seeds together): {_counts(table['recipe_verdict'])}. The selected seed: {summary}"
    page = f"{header}\n\n{summary}.\n\n{markdown_table(shown)}"
    return page if trends is None else f"{page}\n{along_training(trends)}"


def along_training(lines: Mapping[str, str]) -> str:
    """The "Along training" section of claims.md: how the test reads, then one bullet per claim's trend line."""
    how = ("Each part's effect at the kept training stages (efish claims-by-stage): the weighted least-squares "
           "slope of the effect (of |effect| where the paper reports no difference or a difference of either sign) "
           "on log10 env steps, each stage weighted by its bootstrap interval, z-test at "
           "analysis.claims_trend_alpha; the slope's interval in brackets.")
    bullets = "\n".join(f"- {line}" for line in lines.values()) or "- no part has stages to compare"
    return f"## Along training\n\n{how}\n\n{bullets}\n"


def load_claims(where: str | Path, results_root: str | Path = RESULTS_ROOT) -> tuple[str, pd.DataFrame]:
    """A claims table and its run's name from a claims.parquet path, a claims folder, or a run name.

    A run name ``NAME`` means ``<results_root>/NAME/claims/claims.parquet``.
    ValueError (one line) when none of these is a file.
    """
    where = Path(where)
    candidates = [where, where / "claims.parquet", Run(str(where), results_root=Path(results_root)).path(CLAIMS_TABLE)]
    path = next((c for c in candidates if c.is_file()), None)
    if path is None:
        raise ValueError(f"no claims table for {str(where)!r}: tried {', '.join(map(str, candidates))} "
                         "(run efish claims first)")
    run = path.parent.parent.name if path.parent.name == "claims" else path.parent.name
    table = read_parquet(path, f"the claims table {path}")
    table.attrs[ALPHA_ATTR] = recorded_alpha(path)
    return run, table


#: Where :func:`load_claims` keeps the alpha the table was computed at (``analysis.claims_alpha``; None if unknown).
ALPHA_ATTR = "claims_alpha"


def recorded_setting(path: Path, group: str, key: str, kind: type = float):
    """``group.key`` of the config.yaml efish claims writes beside a claims table, as ``kind``: what the run's claims
    were computed under; None without it."""
    import yaml

    config = path.parent / "config.yaml"
    try:
        return kind(yaml.safe_load(config.read_text())[group][key])
    except (OSError, KeyError, TypeError, ValueError, yaml.YAMLError):
        return None


def recorded_alpha(path: Path) -> float | None:
    """``analysis.claims_alpha`` of the config.yaml efish claims writes beside a claims table; None without it."""
    return recorded_setting(path, "analysis", "claims_alpha")


def interval_header(table: pd.DataFrame) -> str:
    """``effect [CI, alpha 0.05]``: the effect column's header, naming the alpha its intervals are at (each part's
    interval is at level 1 - 2 alpha / family, the one its verdict reads); ``effect [CI]`` when it is unknown."""
    alpha = table.attrs.get(ALPHA_ATTR)
    return "effect [CI]" if alpha is None else f"effect [CI, alpha {alpha:g}]"


def compare_claims(a: pd.DataFrame, b: pd.DataFrame, names: tuple[str, str] = ("A", "B")) -> pd.DataFrame:
    """Two claims tables side by side, one row per claim: each run's recipe verdict (its top seeds together,
    :mod:`efish.claims.recipe`; '-' for a run whose table has none), its selected seed's verdict, seeds_agree (the
    verdicts across its top seeds; '-' where absent), effect [CI, alpha a] (the selected seed's, at the level its
    verdict reads, :func:`interval_header`) and n, and whether a verdict moved: ``moved``
    marks the recipe verdict when both runs have one, else the selected seed's. A claim only one table has shows '-'
    on the other side."""
    def side(t: pd.DataFrame, name: str) -> pd.DataFrame:
        agree = t["seeds_agree"] if "seeds_agree" in t.columns else "-"
        recipe = t["recipe_verdict"] if has_recipe(t) else "-"
        return pd.DataFrame({"claim": t["claim"], "panel": t["panel"], f"{name} recipe": recipe,
                             f"{name} verdict": t["verdict"], f"{name} seeds_agree": agree,
                             f"{name} {interval_header(t)}": _effects(t), f"{name} n": t["n"]})

    if names[0] == names[1]:
        names = (f"{names[0]} (A)", f"{names[1]} (B)")
    out = side(a, names[0]).merge(side(b, names[1]).drop(columns="panel"), on="claim", how="outer")
    out["panel"] = out["panel"].fillna(out["claim"].map(dict(zip(b["claim"], b["panel"], strict=True))))
    number = out["claim"].str.extract(r"(\d+)$")[0].astype(float)  # C2 before C10
    out = out.assign(_order=number).sort_values(["_order", "claim"]).drop(columns="_order")
    out = out.astype(object).where(out.notna(), "-").reset_index(drop=True)  # a claim one run lacks: '-'
    headline = "recipe" if has_recipe(a) and has_recipe(b) else "verdict"
    out["moved"] = np.where(out[f"{names[0]} {headline}"] == out[f"{names[1]} {headline}"], "", "*")
    return out


def agreement_lines(a: pd.DataFrame, b: pd.DataFrame, names: tuple[str, str] = ("A", "B")) -> list[str]:
    """How far two claims tables agree, one line per kind of verdict both have (the recipe's, the selected
    seed's): on how many of the claims both list the verdict is the same, and the claims that hold in one and
    are opposite in the other (what the stability run of docs/claims/results.md reports)."""
    both = a.merge(b, on="claim", suffixes=("_a", "_b"))
    lines = []
    for column, what in (("recipe_verdict", "recipe verdicts"), ("verdict", "selected seeds' verdicts")):
        if not (has_recipe(a) and has_recipe(b)) and column == "recipe_verdict":
            continue
        x, y = both[f"{column}_a"], both[f"{column}_b"]
        flips = both.loc[((x == "holds") & (y == "opposite")) | ((x == "opposite") & (y == "holds")), "claim"].tolist()
        lines.append(f"{what}: the same for {int((x == y).sum())} of {len(both)} claims; holds in one and opposite in "
                     f"the other: {', '.join(flips) if flips else 'none'} ({names[0]} vs {names[1]})")
    return lines

