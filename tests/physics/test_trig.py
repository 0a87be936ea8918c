"""The vectorised sin/cos used for body moments agrees with numpy to 2 ulp."""

import numpy as np

from efish.physics.trig import PIO2_1, PIO2_2, PIO2_3, sincos


def test_pi_over_two_split_sums_to_pi_over_two_and_its_heads_are_short():
    assert PIO2_1 + PIO2_2 + PIO2_3 == np.pi / 2
    for head in (PIO2_1, PIO2_2):  # 30 significant bits: j * head is exact for |j| < 2^23
        mantissa, _ = np.frexp(head)
        assert float(mantissa * 2**30).is_integer()


def test_sincos_matches_numpy_within_two_ulp():
    rng = np.random.default_rng(0)
    x = np.concatenate([rng.uniform(-1000, 1000, 200_000), rng.uniform(0, 2 * np.pi, 200_000),
                        np.arange(-8, 9) * np.pi / 4, [0.0, -0.0, 1e-300, np.pi, 2 * np.pi]])
    s, c = np.empty_like(x), np.empty_like(x)
    sincos(x, s, c)
    ulp = np.spacing(1.0)  # values are in [-1, 1]: an absolute bound of 2 ulp of 1
    assert np.max(np.abs(s - np.sin(x))) <= 2 * ulp
    assert np.max(np.abs(c - np.cos(x))) <= 2 * ulp
