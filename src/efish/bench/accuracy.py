"""``efish bench accuracy``: what accuracy costs in time.

Sweeps the knobs of the field computation (culling tolerance x image order x
dtype at the default softening, then softening at the defaults) and, for each
setting, measures the time per agent-step of the fast path and the error of
its normalised readings against a high-accuracy reference: float64, tolerance
0, image order 3, default softening (``max_abs_error`` and the fractions), and
against the exact result of the same model, i.e. the same image order and
softening at float64 and tolerance 0 (``max_abs_error_same_model``: the error
that culling and dtype alone cost). Writes one row per setting.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd

from ..config.schema import EfishConfig
from ..physics.plan import build_plan
from ..sensors.sense import sense_batch
from .physics import READING_KEYS
from .scenes import benchmark_batch
from .timing import best_time

REFERENCE_IMAGE_ORDER = 3
COLUMNS = ("tolerance", "image_order", "dtype", "softening_m", "far_field", "is_default", "us_per_agent_step",
           "agent_steps_per_s", "max_abs_error", "mean_abs_error", "sign_change_fraction",
           "threshold_cross_fraction", "max_abs_error_same_model")


def _with_physics(cfg: EfishConfig, **changes) -> EfishConfig:
    return dataclasses.replace(cfg, physics=dataclasses.replace(cfg.physics, **changes))


def compare_readings(approx: dict, exact: dict) -> dict:
    """Error statistics of normalised readings over every receptor class.

    ``sign_change_fraction``: readings whose sign differs where both are non-zero;
    ``threshold_cross_fraction``: readings that are zero in one and non-zero in
    the other (a detection gained or lost).
    """
    a = np.concatenate([np.asarray(approx[k], np.float64).ravel() for k in READING_KEYS])
    e = np.concatenate([np.asarray(exact[k], np.float64).ravel() for k in READING_KEYS])
    err = np.abs(a - e)
    both = (a != 0) & (e != 0)
    return {
        "max_abs_error": float(err.max(initial=0.0)), "mean_abs_error": float(err.mean()) if err.size else 0.0,
        "sign_change_fraction": float(np.mean(both & (np.sign(a) != np.sign(e)))),
        "threshold_cross_fraction": float(np.mean((a == 0) != (e == 0))),
    }


def accuracy_settings(cfg: EfishConfig) -> list[dict]:
    """The swept settings: tolerance x image order x dtype, then softening, then the
    default tolerance without far-field interpolation (what interpolation buys)."""
    bc, ph = cfg.bench, cfg.physics
    base = dict(tolerance=ph.tolerance, image_order=ph.image_order, dtype=ph.dtype, softening_m=ph.softening_m,
                far_field=True)
    grid = [{**base, "tolerance": float(t), "image_order": int(o), "dtype": str(d)}
            for t in bc.tolerances for o in bc.image_orders for d in bc.dtypes]
    grid += [{**base, "softening_m": float(s)} for s in bc.softenings_m if s != ph.softening_m]
    if ph.far_field_levels:
        grid.append({**base, "far_field": False})
    return grid


def _setting_config(cfg: EfishConfig, s: dict) -> EfishConfig:
    levels = cfg.physics.far_field_levels if s["far_field"] else []
    return _with_physics(cfg, tolerance=s["tolerance"], image_order=s["image_order"], dtype=s["dtype"],
                         softening_m=s["softening_m"], far_field_levels=levels)


def bench_accuracy(cfg: EfishConfig, progress=None) -> pd.DataFrame:
    """Run the sweep on the benchmark scenes; one row per setting (see ``COLUMNS``)."""
    bc, ph = cfg.bench, cfg.physics
    batch = benchmark_batch(cfg, bc.scenes, bc.seed)
    b, n, _ = batch.shape
    ref_cfg = _with_physics(cfg, image_order=REFERENCE_IMAGE_ORDER, tolerance=0.0, dtype="float64")
    exact = sense_batch(batch, build_plan(ref_cfg))
    same_model: dict[tuple, dict] = {}  # exact readings per (image order, softening)
    rows = []
    settings = accuracy_settings(cfg)
    for s in (progress(settings) if progress else settings):
        plan = build_plan(_setting_config(cfg, s))
        seconds = best_time(lambda plan=plan: sense_batch(batch, plan), bc.repeats)
        model = (s["image_order"], s["softening_m"])
        if model not in same_model:
            exact_cfg = _with_physics(cfg, image_order=model[0], softening_m=model[1], tolerance=0.0, dtype="float64")
            same_model[model] = sense_batch(batch, build_plan(exact_cfg))
        approx = sense_batch(batch, plan)
        rows.append({
            **s, "is_default": (s["tolerance"] == ph.tolerance and s["image_order"] == ph.image_order
                                and s["dtype"] == ph.dtype and s["softening_m"] == ph.softening_m
                                and s["far_field"]),
            "us_per_agent_step": 1e6 * seconds / (b * n), "agent_steps_per_s": b * n / seconds,
            **compare_readings(approx, exact),
            "max_abs_error_same_model": compare_readings(approx, same_model[model])["max_abs_error"]})
    return pd.DataFrame(rows, columns=list(COLUMNS))


def pareto_front(df: pd.DataFrame) -> np.ndarray:
    """Boolean mask of settings not beaten in both time and max error by another setting."""
    t, e = df["us_per_agent_step"].to_numpy(), df["max_abs_error"].to_numpy()
    beaten = [(((t <= t[i]) & (e <= e[i])) & ((t < t[i]) | (e < e[i]))).any() for i in range(len(df))]
    return ~np.array(beaten, dtype=bool)


def plot_accuracy(df: pd.DataFrame, path: str | Path) -> None:
    """Time per agent-step against max error, in two panels.

    Left: against the high-accuracy reference (model + numerical error); right:
    against the exact result of the same image order and softening (what culling,
    far-field interpolation and dtype cost). Pareto fronts dashed, default ringed.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    floor = 1e-17  # exact agreement would vanish on a log axis
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8), constrained_layout=True, sharex=True)
    panels = (("max_abs_error", "vs high-accuracy reference (float64, tol 0, image order 3)"),
              ("max_abs_error_same_model", "vs exact result of the same image order and softening"))
    markers = {"float64": "o", "float32": "s"}
    for ax, (column, title) in zip(axes, panels, strict=True):
        err = df[column].clip(lower=floor)
        for (dtype, order), g in df.groupby(["dtype", "image_order"]):
            ax.scatter(g["us_per_agent_step"], err[g.index], marker=markers.get(dtype, "o"),
                       label=f"{dtype}, image order {order}", alpha=0.8)
        front = df.assign(max_abs_error=err)[pareto_front(df.assign(max_abs_error=err))].sort_values("us_per_agent_step")
        ax.plot(front["us_per_agent_step"], err[front.index], "k--", lw=1, label="Pareto front")
        default = df[df["is_default"]]
        ax.scatter(default["us_per_agent_step"], err[default.index], s=220, facecolors="none",
                   edgecolors="red", linewidths=2, label="default")
        ax.axhline(1e-6, color="grey", lw=0.8, ls=":")
        ax.set(xscale="log", yscale="log", xlabel="time per agent-step (us, one thread)",
               ylabel=f"max |error| of normalised readings (floor {floor:g})", title=title)
    base = df[df.is_default].iloc[0] if df["is_default"].any() else None
    series = df.iloc[:0] if base is None else df[
        (df["image_order"] == base["image_order"]) & (df["dtype"] == base["dtype"])
        & (df["softening_m"] == base["softening_m"]) & df["far_field"]]
    for _, row in series.iterrows():
        axes[1].annotate(f"tol {row.tolerance:g}", (row.us_per_agent_step, max(row.max_abs_error_same_model, floor)),
                         fontsize=6, xytext=(3, 3), textcoords="offset points")
    axes[0].legend(fontsize=7, ncol=2)
    fig.suptitle("What accuracy costs in time")
    fig.savefig(path, dpi=150)
    plt.close(fig)
