"""``efish bench physics``: sensing throughput of the fast path against the reference."""

from __future__ import annotations

import numpy as np

from ..config.schema import EfishConfig
from ..physics.plan import build_plan
from ..sensors.sense import sense_batch
from .scenes import benchmark_batch
from .timing import best_time, best_times_interleaved, machine, machine_line

READING_KEYS = ("mormyromast", "ampullary", "knollenorgan", "knollen_size")


def max_reading_difference(a: dict, b: dict) -> float:
    """Largest |difference| over every normalised reading of two sense outputs."""
    return max(float(np.max(np.abs(np.asarray(a[k], np.float64) - b[k]), initial=0.0)) for k in READING_KEYS)


def bench_physics(cfg: EfishConfig) -> dict:
    """Time the fast path and the reference on the benchmark scenes; one thread.

    Returns agent-steps/s of both, their ratio and the max |difference| of
    normalised readings (fast at the configured tolerance vs reference), with
    the CPU's ``cpu`` and ``cpu_capability``.
    """
    bc = cfg.bench
    batch = benchmark_batch(cfg, bc.scenes, bc.seed)
    plan = build_plan(cfg)
    b, n, p = batch.shape
    ref_batch = batch.select(slice(0, min(bc.reference_scenes, b)))
    fast_s = best_time(lambda: sense_batch(batch, plan), bc.repeats)
    # the ratio from runs in turn: this machine's speed drifts from minute to minute
    fast_turns, ref_s = best_times_interleaved(
        [lambda: sense_batch(batch, plan), lambda: sense_batch(ref_batch, plan, reference=True)],
        bc.reference_rounds, warmup=False)
    fast_s = min(fast_s, fast_turns)
    fast_rate = b * n / fast_s
    ref_rate = ref_batch.shape[0] * n / ref_s
    diff = max_reading_difference(sense_batch(ref_batch, plan), sense_batch(ref_batch, plan, reference=True))
    return {
        "scene": f"{n} agents, {cfg.arena.width_cm:g}x{cfg.arena.height_cm:g} cm {cfg.arena.layout}, "
                 f"{int(batch.pellet_alive.sum(axis=1).mean())} pellets on average",
        "snapshots": b, "tolerance": plan.tolerance, "dtype": plan.dtype, "image_order": cfg.physics.image_order,
        "fast_agent_steps_per_s": fast_rate, "reference_agent_steps_per_s": ref_rate,
        "speedup": fast_rate / ref_rate, "max_abs_diff_normalised": diff,
        "fast_us_per_agent_step": 1e6 / fast_rate, "reference_us_per_agent_step": 1e6 / ref_rate, **machine(),
    }


def format_physics(r: dict) -> str:
    """The result as an aligned table under the machine's line."""
    rows = [
        ("scene", r["scene"]), ("snapshots", r["snapshots"]),
        ("dtype / tolerance / image order", f"{r['dtype']} / {r['tolerance']:g} / {r['image_order']}"),
        ("fast path", f"{r['fast_agent_steps_per_s']:,.0f} agent-steps/s ({r['fast_us_per_agent_step']:.2f} us each)"),
        ("reference", f"{r['reference_agent_steps_per_s']:,.0f} agent-steps/s ({r['reference_us_per_agent_step']:.1f} us each)"),
        ("speed-up", f"{r['speedup']:,.0f}x"),
        ("max |fast - reference| (normalised)", f"{r['max_abs_diff_normalised']:.2e}"),
    ]
    width = max(len(k) for k, _ in rows)
    return "\n".join([machine_line(r), *(f"{k:<{width}}  {v}" for k, v in rows)])
