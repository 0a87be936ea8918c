"""``efish.sense``: from a snapshot of an arena to normalised receptor readings.

Pipeline: effect plan -> raw fields at the sensors (fast numba path or the
brute-force reference) -> optional seeded noise -> log normalisation and
Knollenorgan binarisation (docs/model/sensors.md).
"""

from __future__ import annotations

import numpy as np

from ..config import EfishConfig, compose
from ..physics.fast import fast_raw
from ..physics.geometry import conspecific_slots
from ..physics.plan import EffectPlan, Scene, build_plan
from ..physics.readings import RawReadings
from ..physics.reference import reference_raw
from ..physics.snapshot import Snapshot, SnapshotBatch
from .noise import apply_noise
from .normalize import binarize, knollen_size_channel, log_normalize

_DEFAULT_CFG: EfishConfig | None = None


def default_config() -> EfishConfig:
    """The composed default config, cached (composition costs ~0.1 s)."""
    global _DEFAULT_CFG
    if _DEFAULT_CFG is None:
        _DEFAULT_CFG = compose()
    return _DEFAULT_CFG


def raw_readings(batch: SnapshotBatch, plan: EffectPlan, *, reference: bool = False) -> RawReadings:
    """Raw E.n readings (V/m) of every receptor, fast path or reference."""
    return reference_raw(batch, plan) if reference else fast_raw(batch, plan)


def normalise(raw: RawReadings, agent_size: np.ndarray, plan: EffectPlan) -> dict[str, np.ndarray]:
    """Log-normalised Mormyromast/Ampullary readings, Knollenorgan spikes and size channel.

    ``agent_size``: float[B, N]; the size channel of slot j of agent a reports
    the size of the j-th other agent. Disabled receptor classes read all zeros.
    """
    n = agent_size.shape[1]
    dtype = raw.mormyromast.dtype
    spikes = binarize(raw.knollenorgan, plan.knollen_threshold)
    slot_sizes = agent_size[:, conspecific_slots(n)].astype(dtype)                          # [B, N, N-1]
    out = {
        "mormyromast": log_normalize(raw.mormyromast, *plan.morm_range),
        "ampullary": log_normalize(raw.ampullary, *plan.amp_range),
        "knollenorgan": spikes,
        "knollen_size": knollen_size_channel(spikes, slot_sizes),
    }
    for name in ("mormyromast", "ampullary", "knollenorgan"):
        if not plan.on(name):
            out[name] = np.zeros_like(out[name])
    if not plan.on("knollenorgan"):
        out["knollen_size"] = np.zeros_like(out["knollen_size"])
    return out


def sense_batch(batch: SnapshotBatch, plan: EffectPlan, *, reference: bool = False,
                rng: np.random.Generator | None = None, return_raw: bool = False) -> dict[str, np.ndarray]:
    """Normalised readings for B arenas: arrays with leading dims (B, N). Noise only with ``rng``."""
    raw = raw_readings(batch, plan, reference=reference)
    noisy = apply_noise(raw, batch.agent_emitting & plan.on("eod_emission"), plan, rng) if (rng is not None and plan.noise) else raw
    out = normalise(noisy, batch.agent_size, plan)
    if return_raw:
        out.update({f"{k}_raw": v for k, v in (("mormyromast", raw.mormyromast), ("ampullary", raw.ampullary),
                                               ("knollenorgan", raw.knollenorgan))})
    return out


def sense(snapshot: Snapshot, cfg: EfishConfig | None = None, *, tolerance: float | None = None,
          reference: bool = False, rng: np.random.Generator | None = None,
          return_raw: bool = False) -> dict[str, np.ndarray]:
    """What every receptor of every agent in ``snapshot`` reads, normalised to [-1, 1].

    Returns ``mormyromast (N, 36)``, ``ampullary (N, 24)``, ``knollenorgan
    (N, N-1, 12)`` (spikes in {-1, 0, 1}) and ``knollen_size (N, N-1)``; with
    ``return_raw`` also the raw V/m readings as ``<class>_raw``. ``reference``
    uses the brute-force oracle; noise is off when ``rng`` is None.

    >>> s = Snapshot(agent_xy=[[20, 20], [30, 20]], agent_heading=[0, 3.14159],
    ...              agent_size=[0.5, 0.5], agent_emitting=[True, True],
    ...              pellet_xy=[[23, 20]], pellet_orientation=[0], width=70, height=70)
    >>> r = sense(s)
    >>> r["mormyromast"].shape, r["knollenorgan"].shape
    ((2, 36), (2, 1, 12))
    """
    cfg = cfg or default_config()
    batch = snapshot.as_batch()
    plan = build_plan(cfg, Scene.of_batch(batch), tolerance=tolerance)
    out = sense_batch(batch, plan, reference=reference, rng=rng, return_raw=return_raw)
    return {k: v[0] for k, v in out.items()}
