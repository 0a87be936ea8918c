"""The claims of Fig 2 (C1-C3): electric homing paths, and the Knollenorgan error angle along them.

Condition names are those of ``config/assay/homing.yaml``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from ..analysis._tables import AGENT_EPISODE
from ..layout import analysis_table
from .context import Context, claim
from .parts import (
    mann_whitney_part,
    one_sample_part,
)
from .verdicts import Outcome, Part

HOMING_ELECTRIC, HOMING_RAYCAST = "electric", "raycast"  # config/assay/homing.yaml
TRAJECTORY = analysis_table("homing", "homing", "trajectory_shape")
ALIGNMENT = analysis_table("homing", "homing", "alignment_episodes")


def _successful(frame: pd.DataFrame) -> pd.DataFrame:
    """Rows of agent-episodes that ended with their goal reached (every row when there is no success column)."""
    if "success" not in frame.columns:
        return frame
    ok = frame.groupby(AGENT_EPISODE)["success"].transform("any").astype(bool)
    return frame[ok.to_numpy()]


@claim("C1", "2B", "electric homing paths are curvilinear, ray-casting paths straight", [TRAJECTORY])
def c1(ctx: Context) -> list[Part]:
    def compute() -> Outcome:
        shape = ctx.table(TRAJECTORY)
        shape = shape[np.isfinite(shape["tortuosity"])]  # the frozen target never moves: no tortuosity
        if (shape := _successful(shape)).empty:
            raise ValueError("no successful homing episode with a tortuosity")
        return mann_whitney_part(ctx, shape, "tortuosity", "condition", HOMING_ELECTRIC, HOMING_RAYCAST, +1)
    return [ctx.part("tortuosity", "Hodges-Lehmann shift of the tortuosity (path / displacement) of successful homing episodes, "
                     "electric minus raycast; Mann-Whitney", compute)]


def _aligned(ctx: Context) -> pd.DataFrame:
    """The homing analysis's alignment rows (alignment_episodes) of the Knollenorgan error angle in the successful
    agent-episodes of the electric condition (the homer's: the frozen target senses no error angle)."""
    rows = ctx.table(ALIGNMENT)
    rows = rows[(rows["condition"] == HOMING_ELECTRIC) & (rows["channel"] == "knollen")]
    if rows.empty:
        why = "; ".join(sorted({r for r in ctx.table(ALIGNMENT)["reason"] if isinstance(r, str) and r}))
        raise ValueError("no finite Knollenorgan error angle in the electric homing steps" + (f" ({why})" if why else ""))
    if (rows := rows[rows["success"].astype(bool)]).empty:
        raise ValueError("no successful electric homing episode")
    return rows


#: The straight homer's aligned fraction at which its reference is at a ceiling (rule 5): aligned on 90% of its
#: steps or more, it leaves at most a tenth of the steps to align beyond it, so an excess the part tests cannot
#: appear (the third audit: a median room of 0.049). The counterpart of a control eating every pellet, counted
#: over episodes by the same ``analysis.claims_ceiling_share``.
REFERENCE_CEILING = 0.9


def reference_ceiling(ctx: Context, per: pd.DataFrame) -> Outcome | None:
    """A "not decidable" outcome when the straight homer's aligned fraction (``straight_aligned_fraction`` of the
    episodes ``per``) is at least :data:`REFERENCE_CEILING` in at least ``analysis.claims_ceiling_share`` of the
    episodes (rule 5: a reference at its ceiling leaves no room for a positive excess), else None."""
    reference = per["straight_aligned_fraction"].to_numpy(np.float64)
    reference = reference[np.isfinite(reference)]
    full = float(np.mean(reference >= REFERENCE_CEILING)) if reference.size else 0.0
    if full < ctx.cfg.analysis.claims_ceiling_share:
        return None
    return Outcome(np.nan, np.nan, len(per), +1, verdict="not decidable",
                   reason=f"at a ceiling: a homer heading straight at the target is aligned on at least "
                          f"{REFERENCE_CEILING:.0%} of the steps in {full:.0%} of the {reference.size} successful "
                          f"episodes (median room above it {np.median(1 - reference):.3g}), so no excess alignment "
                          "can appear")


@claim("C2", "2C", "the error angle is bimodal near parallel and anti-parallel to the target's field", [ALIGNMENT])
def c2(ctx: Context) -> list[Part]:
    a = ctx.cfg.analysis.claims_aligned_rad

    def compute() -> Outcome:
        per = _aligned(ctx)
        if (full := reference_ceiling(ctx, per)) is not None:
            return full
        out = one_sample_part(ctx, per, "aligned_excess", 0.0, +1)
        note = (f"median aligned fraction {per['aligned_fraction'].median():.3f} vs "
                f"{per['straight_aligned_fraction'].median():.3f} for a straight homer on the same positions, over "
                f"{len(per)} successful episodes")
        return dataclasses.replace(out, reason="; ".join(r for r in (out.reason, note) if r))
    return [ctx.part("aligned beyond straight homing", f"Hodges-Lehmann estimate over successful episodes of the fraction of steps "
                     f"with |cos(err_knollen)| > cos({a:.3g}) minus that of a homer heading straight at the target "
                     "from the same positions; Wilcoxon vs 0", compute)]


@claim("C3", "2D", "error angles align progressively during successful episodes", [ALIGNMENT])
def c3(ctx: Context) -> list[Part]:
    def compute() -> Outcome:
        rho = _aligned(ctx)
        return one_sample_part(ctx, rho[np.isfinite(rho["alignment_rho"])], "alignment_rho", 0.0, -1)
    return [ctx.part("alignment", "Hodges-Lehmann estimate over successful episodes of Spearman rho(|sin err_knollen|, normalised "
                     "time); Wilcoxon vs 0", compute)]
