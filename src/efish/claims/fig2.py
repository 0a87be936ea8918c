"""The claims of Fig 2 (C1-C3): electric homing paths, and the Knollenorgan error angle along them.

Condition names are those of ``config/assay/homing.yaml``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from ..analysis._tables import AGENT_EPISODE
from ..analysis.homing import error_angles
from ..analysis.stats import spearman
from ..layout import analysis_table, assay_table
from .context import Context, claim
from .parts import (
    mann_whitney_part,
    one_sample_part,
)
from .verdicts import Outcome, Part

HOMING_ELECTRIC, HOMING_RAYCAST = "electric", "raycast"  # config/assay/homing.yaml
TRAJECTORY = analysis_table("homing", "homing", "trajectory_shape")
HOMING_STEPS = assay_table("homing", "steps")


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


def _knollen_errors(ctx: Context) -> pd.DataFrame:
    """The homer's Knollenorgan error angles (long table of :func:`error_angles`) in the electric condition."""
    steps = ctx.table(HOMING_STEPS)
    steps = steps[steps["condition"] == HOMING_ELECTRIC]
    err = error_angles(steps) if "err_knollen_rad" in steps.columns else pd.DataFrame()
    err = err[err["channel"] == "knollen"] if len(err) else err
    if err.empty:
        raise ValueError("no finite Knollenorgan error angle in the electric homing steps")
    return err



@claim("C2", "2C", "the error angle is bimodal near parallel and anti-parallel to the target's field",
       [HOMING_STEPS])
def c2(ctx: Context) -> list[Part]:
    a = ctx.cfg.analysis.claims_aligned_rad

    def compute() -> Outcome:
        err = _knollen_errors(ctx)
        steps = ctx.table(HOMING_STEPS)[[*AGENT_EPISODE, "t", "success", "bearing_agent_rad"]]
        err = _successful(err.merge(steps, on=[*AGENT_EPISODE, "t"]))
        if err.empty:
            raise ValueError("no successful electric homing episode")
        # a homer heading straight at the target from the same position: heading + bearing to the target, so
        # its error angle is the observed one plus the bearing (the geometric null of this statistic)
        straight = err["err_rad"] + err["bearing_agent_rad"]
        per = (err.assign(observed=np.abs(np.cos(err["err_rad"])) > np.cos(a),
                          straight=np.abs(np.cos(straight)) > np.cos(a))
               .groupby(["episode", "agent"], as_index=False)[["observed", "straight"]].mean())
        per = per.assign(excess=per["observed"] - per["straight"])
        out = one_sample_part(ctx, per, "excess", 0.0, +1)
        note = (f"median aligned fraction {per['observed'].median():.3f} vs {per['straight'].median():.3f} for a "
                f"straight homer on the same positions, over {len(per)} successful episodes")
        return dataclasses.replace(out, reason="; ".join(r for r in (out.reason, note) if r))
    return [ctx.part("aligned beyond straight homing", f"Hodges-Lehmann estimate over successful episodes of the fraction of steps "
                     f"with |cos(err_knollen)| > cos({a:.3g}) minus that of a homer heading straight at the target "
                     "from the same positions; Wilcoxon vs 0", compute)]


@claim("C3", "2D", "error angles align progressively during successful episodes", [HOMING_STEPS])
def c3(ctx: Context) -> list[Part]:
    def compute() -> Outcome:
        err = _successful(_knollen_errors(ctx).merge(
            ctx.table(HOMING_STEPS)[[*AGENT_EPISODE, "t", "success"]], on=[*AGENT_EPISODE, "t"]))
        if err.empty:
            raise ValueError("no successful electric homing episode")
        err = err.assign(abs_sin=np.abs(np.sin(err["err_rad"])), unit=err["episode"] * 1000 + err["agent"])
        rho = spearman(err, "t_norm", "abs_sin", by="unit")
        rho = rho.assign(episode=rho["group"] // 1000)[np.isfinite(rho["effect"])]
        return one_sample_part(ctx, rho, "effect", 0.0, -1)
    return [ctx.part("alignment", "Hodges-Lehmann estimate over successful episodes of Spearman rho(|sin err_knollen|, normalised "
                     "time); Wilcoxon vs 0", compute)]
