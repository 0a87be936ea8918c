"""Raw readings to the electric part of the observation in one pass (docs/model/sensors.md#normalisation).

The step of the environment needs, after the physics kernel: noise, log
normalisation, Knollenorgan binarisation, the size channel and the layout of
the observation (docs/model/environment.md#observation). Done as separate
numpy calls these are a dozen small passes with temporaries;
:func:`encode_readings` does them in one numba loop that writes straight into
the float32 observation. The unfused composition
(:func:`efish.sensors.sense.sense_batch`, i.e. ``apply_noise`` then ``normalise``)
stays as the public ``sense`` API and is the oracle this kernel is tested
against, bit for bit.

Noise uses the uniforms of :func:`efish.sensors.noise.noise_uniforms` (one
draw, same stream as ``apply_noise``); the factor is ``low + (high - low) * u``,
which is exactly how ``Generator.uniform`` maps its draws.
"""

from __future__ import annotations

import weakref

import numpy as np

from .._jit import njit
from ..physics.geometry import slot_agent
from ..physics.plan import EffectPlan
from ..physics.readings import RawReadings

# Indices into the float64 ``lin`` constants.
LO, SCALE, JAM_LO, JAM_SCALE, M_EMIN, M_EMAX, M_LMIN, M_SPAN, A_EMIN, A_EMAX, A_LMIN, A_SPAN, N_LIN = range(13)
# Indices into the ``flags`` array.
NOISE, MORM_ON, AMP_ON, KNOLL_ON, N_FLAGS = range(5)
# Indices into the ``typed`` constants (raw dtype: comparisons and the size channel happen in it, as in numpy).
THRESHOLD, HALF, N_TYPED = range(3)


def electric_width(n_morm: int, n_amp: int, n_knoll: int, slots: int) -> int:
    """Length of the electric block: Mormyromast | Ampullary | slots x Knollenorgan | slots size channels."""
    return n_morm + n_amp + slots * (n_knoll + 1)


_CONSTS: weakref.WeakKeyDictionary[EffectPlan, dict] = weakref.WeakKeyDictionary()


def encoding_constants(plan: EffectPlan, dtype) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``lin`` (float64), ``typed`` (raw dtype) and ``flags`` (int64) of a plan; built once per plan and dtype.

    The log10 terms are computed with numpy exactly as :func:`log_normalize` does.
    """
    per_plan = _CONSTS.setdefault(plan, {})
    dtype = np.dtype(dtype)
    if dtype not in per_plan:
        lin = np.zeros(N_LIN)
        (lo, hi), (jlo, jhi) = plan.noise_range, plan.interference_range
        lin[LO], lin[SCALE], lin[JAM_LO], lin[JAM_SCALE] = lo, hi - lo, jlo, jhi - jlo
        for (e_min, e_max), base in ((plan.morm_range, M_EMIN), (plan.amp_range, A_EMIN)):
            if not 0 < e_min < e_max:
                raise ValueError(f"log normalisation needs 0 < e_min < e_max, got e_min={e_min}, e_max={e_max}")
            lin[base], lin[base + 1] = e_min, e_max
            lin[base + 2], lin[base + 3] = np.log10(e_min), np.log10(e_max) - np.log10(e_min)
        typed = np.zeros(N_TYPED, dtype)
        typed[THRESHOLD], typed[HALF] = plan.knollen_threshold, 0.5
        flags = np.array([plan.noise, plan.on("mormyromast"), plan.on("ampullary"), plan.on("knollenorgan")],
                         dtype=np.int64)
        per_plan[dtype] = (lin, typed, flags)
    return per_plan[dtype]


def noise_draw_count(raw: RawReadings) -> int:
    """How many uniforms one step of noise takes (see ``noise_uniforms``)."""
    return raw.mormyromast.size + 2 * raw.ampullary.size + raw.knollenorgan.size


@njit(cache=True, error_model="numpy")
def clip_noisy(s, u, lo, scale, e_min, e_max, mag, sgn):
    """mag = clip(|s * f|, e_min, e_max), sgn = sign(s * f) with f = lo + scale * u (f = 1 when ``u`` is empty).

    One agent's row of one receptor class: contiguous 1-D arrays and no
    branches in the loop, so it vectorises. The factor is rounded to the raw
    dtype before multiplying, as numpy's ``astype`` does in ``apply_noise``.
    """
    as_raw = s.dtype.type
    if u.shape[0] == 0:
        for k in range(s.shape[0]):
            v = np.float64(s[k])
            mag[k] = min(max(abs(v), e_min), e_max)
            sgn[k] = np.sign(v)
    else:
        for k in range(s.shape[0]):
            v = np.float64(s[k] * as_raw(lo + scale * u[k]))
            mag[k] = min(max(abs(v), e_min), e_max)
            sgn[k] = np.sign(v)


@njit(cache=True)
def noisy_kernel(morm, amp, knoll, u, emitting, size, lin, typed, flags, slots, mag, sgn, out):
    """Noise on every reading; Knollenorgan spikes and size channels into ``out``; log inputs into ``mag``/``sgn``.

    morm float[B, N, M], amp float[B, N, A], knoll float[B, N, N-1, K] (raw, one dtype);
    u float64[flat, order of ``noise_uniforms``]; emitting bool[B, N]; size float64[B, N];
    mag, sgn float64[B, N, M + A]: clip(|s|, E_min, E_max) and sign(s) of the noisy
    Mormyromast then Ampullary readings (the log is taken by numpy, see ``encode_readings``);
    out float32[B, N, D]: Knollenorgan block at M + A, slots x K spikes then slots size channels.
    Slots past N-1 and a disabled Knollenorgan read 0.
    """
    b_count, n, n_m = morm.shape
    n_a, n_k = amp.shape[2], knoll.shape[3]
    noisy, knoll_on = flags[NOISE] != 0, flags[KNOLL_ON] != 0
    as_raw = morm.dtype.type  # rounds a float64 factor to the raw dtype, as numpy's astype does
    u_amp, u_jam, u_knoll = morm.size, morm.size + amp.size, morm.size + 2 * amp.size
    none = u[:0]
    k0 = n_m + n_a
    s0 = k0 + slots * n_k
    for b in range(b_count):
        emitters = 0
        for j in range(n):
            emitters += emitting[b, j]
        for i in range(n):
            row = b * n + i
            mag_row, sgn_row = mag[b, i], sgn[b, i]
            clip_noisy(morm[b, i], u[row * n_m:(row + 1) * n_m] if noisy else none, lin[LO], lin[SCALE],
                       lin[M_EMIN], lin[M_EMAX], mag_row[:n_m], sgn_row[:n_m])
            if emitters - emitting[b, i] > 0:  # a conspecific emits: EOD interference
                lo, scale, first = lin[JAM_LO], lin[JAM_SCALE], u_jam + row * n_a
            else:
                lo, scale, first = lin[LO], lin[SCALE], u_amp + row * n_a
            clip_noisy(amp[b, i], u[first:first + n_a] if noisy else none, lo, scale, lin[A_EMIN], lin[A_EMAX],
                       mag_row[n_m:], sgn_row[n_m:])
            for j in range(slots):
                heard = False
                for k in range(n_k):
                    spike = 0.0
                    if j < n - 1 and knoll_on:
                        s = knoll[b, i, j, k]
                        if noisy:
                            s = s * as_raw(lin[LO] + lin[SCALE] * u[u_knoll + (row * (n - 1) + j) * n_k + k])
                        if abs(s) > typed[THRESHOLD]:
                            spike = np.sign(s)
                    heard = heard or spike != 0.0
                    out[b, i, k0 + j * n_k + k] = spike
                if heard:
                    out[b, i, s0 + j] = typed[HALF] + typed[HALF] * as_raw(size[b, slot_agent(i, j)])
                else:
                    out[b, i, s0 + j] = 0.0


@njit(cache=True, error_model="numpy")
def scale_log(log_mag, sgn, l_min, span, out):
    """out = sgn * (log_mag - l_min) / span, rounded to float32: one row, vectorised."""
    for k in range(out.shape[0]):
        out[k] = sgn[k] * (log_mag[k] - l_min) / span


@njit(cache=True)
def log_kernel(log_mag, sgn, n_m, lin, flags, out):
    """Mormyromast and Ampullary readings into ``out[..., :M + A]`` from log10 of the clipped magnitude.

    y = sign(s) * (log10 m - log10 E_min) / (log10 E_max - log10 E_min), the
    operations and order of ``log_normalize``; disabled classes read 0.
    """
    n_ma = log_mag.shape[2]
    for b in range(out.shape[0]):
        for i in range(out.shape[1]):
            row = out[b, i]
            if flags[MORM_ON]:
                scale_log(log_mag[b, i, :n_m], sgn[b, i, :n_m], lin[M_LMIN], lin[M_SPAN], row[:n_m])
            else:
                row[:n_m] = 0.0
            if flags[AMP_ON]:
                scale_log(log_mag[b, i, n_m:], sgn[b, i, n_m:], lin[A_LMIN], lin[A_SPAN], row[n_m:n_ma])
            else:
                row[n_m:n_ma] = 0.0


def encode_readings(raw: RawReadings, u: np.ndarray | None, emitting: np.ndarray, size: np.ndarray,
                    plan: EffectPlan, slots: int, out: np.ndarray) -> None:
    """Write the electric block of the observation (docs/model/environment.md#observation) for every agent into
    ``out[..., :E]`` (float32[B, N, D]).

    ``u``: the step's noise uniforms (``noise_uniforms``), or None for no noise;
    ``emitting`` bool[B, N] (already gated by the plan); ``slots`` Knollenorgan
    slots in the layout (obs_agents - 1 >= N - 1). Equals ``sense_batch`` +
    padding + float32 cast, bit for bit. The log10 is numpy's (one vectorised
    call between the two kernels): it is the oracle's own function and several
    times faster than the scalar libm call a numba loop makes.
    """
    if out.dtype != np.float32:
        raise TypeError(f"out must be float32, got {out.dtype}")  # the kernels round once, to float32
    if slots < raw.knollenorgan.shape[2]:
        raise ValueError(f"{slots} Knollenorgan slots cannot hold {raw.knollenorgan.shape[2]} conspecifics")
    lin, typed, flags = encoding_constants(plan, raw.mormyromast.dtype)
    if u is None:
        flags = flags.copy()
        flags[NOISE] = 0
        u = np.zeros(0)
    elif u.size != noise_draw_count(raw):
        raise ValueError(f"expected {noise_draw_count(raw)} noise uniforms, got {u.size}")
    b, n, n_m = raw.mormyromast.shape
    mag, sgn = np.empty((2, b, n, n_m + raw.ampullary.shape[2]))
    noisy_kernel(raw.mormyromast, raw.ampullary, raw.knollenorgan, u, emitting, np.asarray(size, np.float64),
                 lin, typed, flags, slots, mag, sgn, out)
    log_kernel(np.log10(mag, out=mag), sgn, n_m, lin, flags, out)
