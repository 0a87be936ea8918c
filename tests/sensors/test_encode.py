"""The fused encoder (noise + normalisation + binarisation + layout in one pass) against the unfused numpy oracle.

Oracle: ``apply_noise`` then ``efish.sensors.sense.normalise`` (what ``sense_batch``
does), Knollenorgan slots padded to the layout, cast to float32. Known answers
are required bit for bit, -0.0 included.
"""

from __future__ import annotations

import numpy as np
import pytest

from efish.physics import Scene, build_plan
from efish.physics.readings import RawReadings
from efish.sensors.encode import electric_width, encode_readings
from efish.sensors.noise import apply_noise, noise_uniforms
from efish.sensors.sense import normalise

from ..helpers import cfg_with


def assert_bits(got: np.ndarray, want: np.ndarray) -> None:
    """Equal dtype, shape and bit patterns (so 0.0 != -0.0)."""
    assert got.dtype == want.dtype and got.shape == want.shape
    np.testing.assert_array_equal(got.view(np.uint32 if got.dtype == np.float32 else np.uint64),
                                  want.view(np.uint32 if want.dtype == np.float32 else np.uint64))


def random_raw(rng: np.random.Generator, b: int, n: int, plan, dtype) -> RawReadings:
    """Readings log-uniform over 1e-12 .. 1 V/m with random signs, some exact zeros and some exactly at the
    class thresholds, so every branch of the normalisation and binarisation is taken."""
    def block(shape, specials):
        v = rng.choice([-1.0, 1.0], shape) * 10 ** rng.uniform(-12, 0, shape)
        v[rng.random(shape) < 0.1] = 0.0
        pick = rng.random(shape) < 0.1
        v[pick] = rng.choice(specials, pick.sum())
        return v.astype(dtype)
    k = plan.knollen_threshold
    return RawReadings(
        mormyromast=block((b, n, len(plan.morm_angles)), [*plan.morm_range, -plan.morm_range[0]]),
        ampullary=block((b, n, len(plan.amp_angles)), [*plan.amp_range, -plan.amp_range[1]]),
        knollenorgan=block((b, n, n - 1, len(plan.knollen_angles)), [k, -k, k / 1.05, k / 0.95]))


def oracle(raw: RawReadings, emitting, size, plan, slots, rng) -> np.ndarray:
    """The unfused composition the env used before the encoder: sense_batch's steps + padding + float32."""
    noisy = apply_noise(raw, emitting, plan, rng) if rng is not None else raw
    r = normalise(noisy, size, plan)
    b, n, _ = r["mormyromast"].shape
    knoll = np.zeros((b, n, slots, r["knollenorgan"].shape[3]), np.float32)
    knoll[:, :, : n - 1] = r["knollenorgan"]
    sizes = np.zeros((b, n, slots), np.float32)
    sizes[:, :, : n - 1] = r["knollen_size"]
    return np.concatenate([r["mormyromast"], r["ampullary"], knoll.reshape(b, n, -1), sizes], -1).astype(np.float32)


def encoded(raw, emitting, size, plan, slots, rng, width_extra=3) -> np.ndarray:
    b, n, _ = raw.mormyromast.shape
    out = np.full((b, n, electric_width(len(plan.morm_angles), len(plan.amp_angles), len(plan.knollen_angles),
                                        slots) + width_extra), np.nan, np.float32)
    u = noise_uniforms(raw, rng) if rng is not None else None
    encode_readings(raw, u, emitting, size, plan, slots, out)
    assert np.all(np.isnan(out[..., out.shape[2] - width_extra:]))  # nothing written past the electric block
    return out[..., : out.shape[2] - width_extra]


@pytest.mark.parametrize("dtype", ["float64", "float32"])
@pytest.mark.parametrize("n, slots", [(4, 3), (2, 1), (3, 5), (1, 3), (1, 0)])
@pytest.mark.parametrize("noise", [True, False])
def test_encoder_equals_the_unfused_composition_bit_for_bit(dtype, n, slots, noise):
    rng = np.random.default_rng(n * 10 + slots)
    plan = build_plan(cfg_with(), Scene(agents=n), dtype=dtype)
    for _ in range(3):
        raw = random_raw(rng, 5, n, plan, dtype)
        emitting = rng.random((5, n)) < 0.5
        size = rng.uniform(0, 1, (5, n))
        seed = int(rng.integers(1 << 30))
        rngs = (np.random.default_rng(seed), np.random.default_rng(seed)) if noise else (None, None)
        assert_bits(encoded(raw, emitting, size, plan, slots, rngs[0]),
                    oracle(raw, emitting, size, plan, slots, rngs[1]))
        if noise:  # both consumed the same draws
            assert rngs[0].random() == rngs[1].random()


@pytest.mark.parametrize("off", ["sensors.mormyromast.enabled=false", "sensors.ampullary.enabled=false",
                                 "sensors.knollenorgan.enabled=false", "sensors.noise.enabled=false"])
def test_encoder_follows_the_plan_switches(off):
    rng = np.random.default_rng(1)
    plan = build_plan(cfg_with(off), Scene(agents=4))
    raw = random_raw(rng, 3, 4, plan, np.float64)
    emitting, size = rng.random((3, 4)) < 0.5, rng.uniform(0, 1, (3, 4))
    noise = np.random.default_rng(2) if plan.noise else None
    want = oracle(raw, emitting, size, plan, 3, np.random.default_rng(2) if plan.noise else None)
    assert_bits(encoded(raw, emitting, size, plan, 3, noise), want)


def test_noise_uniforms_reproduce_the_four_uniform_calls_of_the_spec():
    # the noise of docs/model/sensors.md#noise as four Generator.uniform calls (Mormyromast, Ampullary, interference,
    # Knollenorgan): one rng.random call with low + (high - low) * u gives the same numbers and leaves the same state.
    plan = build_plan(cfg_with(), Scene(agents=3))
    raw = random_raw(np.random.default_rng(0), 2, 3, plan, np.float64)
    (lo, hi), (jlo, jhi) = plan.noise_range, plan.interference_range
    a, b = np.random.default_rng(9), np.random.default_rng(9)
    want = np.concatenate([a.uniform(lo, hi, raw.mormyromast.size), a.uniform(lo, hi, raw.ampullary.size),
                           a.uniform(jlo, jhi, raw.ampullary.size), a.uniform(lo, hi, raw.knollenorgan.size)])
    u = noise_uniforms(raw, b)
    ends = np.cumsum([raw.mormyromast.size, raw.ampullary.size, raw.ampullary.size])
    lows, highs = [lo, lo, jlo, lo], [hi, hi, jhi, hi]
    got = np.concatenate([low + (high - low) * part for low, high, part in zip(lows, highs, np.split(u, ends), strict=True)])
    assert_bits(got, want)
    assert a.random() == b.random()


def test_encoder_rejects_bad_buffers():
    plan = build_plan(cfg_with(), Scene(agents=4))
    raw = random_raw(np.random.default_rng(0), 1, 4, plan, np.float64)
    e, s = np.zeros((1, 4), bool), np.zeros((1, 4))
    with pytest.raises(TypeError, match="float32"):
        encode_readings(raw, None, e, s, plan, 3, np.zeros((1, 4, 99)))
    with pytest.raises(ValueError, match="slots"):
        encode_readings(raw, None, e, s, plan, 2, np.zeros((1, 4, 99), np.float32))
    with pytest.raises(ValueError, match="uniforms"):
        encode_readings(raw, np.zeros(5), e, s, plan, 3, np.zeros((1, 4, 99), np.float32))
