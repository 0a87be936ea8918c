"""``efish bench multipole``: its expansion is right to within its bound, its quadtree covers every source once."""

from __future__ import annotations

import numpy as np
import pytest

from efish.bench.multipole import (
    bench_multipole,
    cell_moments,
    coulomb_derivatives,
    format_multipole,
    multi_indices,
    multipole_readings,
    quadtree_cost,
    truncation_bound,
)

from ..helpers import cfg_with

SOFT2 = 1e-10


def derivatives(x, y, order):
    out = np.zeros((order + 1, order + 1, len(x)))
    coulomb_derivatives(np.asarray(x, float), np.asarray(y, float), SOFT2, order, out)
    return out


def test_derivatives_match_closed_forms_and_each_other_by_differences():
    rng = np.random.default_rng(0)
    x, y = rng.uniform(-2, 2, (2, 50))
    x[np.hypot(x, y) < 0.3] += 1.0
    d = derivatives(x, y, 6)
    rho2 = x * x + y * y + SOFT2
    np.testing.assert_allclose(d[0, 0], rho2 ** -0.5, rtol=1e-12)
    np.testing.assert_allclose(d[1, 0], -x * rho2 ** -1.5, rtol=1e-12)
    np.testing.assert_allclose(d[1, 1], 3 * x * y * rho2 ** -2.5, rtol=1e-10)
    np.testing.assert_allclose(d[2, 0], 3 * x * x * rho2 ** -2.5 - rho2 ** -1.5, rtol=1e-10, atol=1e-12)
    h = 1e-5
    ddx = (derivatives(x + h, y, 6) - derivatives(x - h, y, 6)) / (2 * h)
    ddy = (derivatives(x, y + h, 6) - derivatives(x, y - h, 6)) / (2 * h)
    for t in range(6):
        for u in range(6 - t):
            scale = np.abs(d[t + 1, u]).max()
            np.testing.assert_allclose(ddx[t, u], d[t + 1, u], atol=1e-5 * scale)
            np.testing.assert_allclose(ddy[t, u], d[t, u + 1], atol=1e-5 * np.abs(d[t, u + 1]).max())


def direct_reading(point, normal, xy, m):
    d = point - xy
    rho2 = (d ** 2).sum(1) + SOFT2
    field = (3 * (m * d).sum(1)[:, None] * d / rho2[:, None] - m) / rho2[:, None] ** 1.5
    return float((field @ normal).sum())


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_expansion_matches_the_direct_sum_within_its_bound_and_converges(seed):
    rng = np.random.default_rng(seed)
    radius, centre = 0.1, rng.uniform(-1, 1, 2)
    offsets = rng.uniform(-radius / np.sqrt(2), radius / np.sqrt(2), (40, 2))
    m = rng.normal(size=(40, 2))
    angle = rng.uniform(0, 2 * np.pi)
    distance = rng.uniform(0.3, 0.8)
    point = centre + distance * np.array([np.cos(angle), np.sin(angle)])
    normal = np.array([np.cos(angle + 1.0), np.sin(angle + 1.0)])
    exact = direct_reading(point, normal, centre + offsets, m)
    errors = []
    for order in range(9):
        moments = cell_moments(offsets[:, 0], offsets[:, 1], m[:, 0], m[:, 1], order)
        both = np.repeat(moments[:, None, :, None], 2, axis=1)  # [term, column, component, cell]
        out = np.zeros((2, 1))
        multipole_readings(np.array([point[0] - centre[0]]), np.array([point[1] - centre[1]]), SOFT2, both,
                           normal[0], normal[1], order, np.zeros((order + 3, order + 3, 1)), out)
        error = abs(out[0, 0] - exact)
        assert out[0, 0] == out[1, 0]
        assert error <= truncation_bound(order, radius, distance, np.hypot(m[:, 0], m[:, 1]).sum())
        errors.append(error)
    assert errors[8] < errors[2] / 100


def test_multi_indices_count_the_terms_of_each_order():
    assert [len(multi_indices(p)) for p in range(5)] == [1, 3, 6, 10, 15]


def test_quadtree_covers_every_source_once_and_its_limits_are_the_known_cases():
    rng = np.random.default_rng(3)
    xy = rng.uniform(0, 4, (3000, 2))
    moment = np.full(3000, 1e-3)
    agent, box = np.array([2.0, 2.0]), (0.0, 0.0, 4.0)
    cells, in_cells, direct = quadtree_cost(xy, moment, agent, 1e-6, 4, 0.01, box)
    assert cells > 0 and in_cells + direct == 3000
    assert quadtree_cost(xy, moment, agent, 0.0, 4, 0.01, box) == (0, 0, 3000)  # no cell is ever good enough
    far = np.array([50.0, 50.0])  # far outside: the whole box is one cell at a loose threshold
    assert quadtree_cost(xy, moment, far, 1.0, 4, 0.01, box) == (1, 3000, 0)
    on_the_agent = np.repeat(agent[None], 40, axis=0)  # coinciding sources at the agent end as direct ones
    assert quadtree_cost(on_the_agent, np.ones(40), agent, 1e-6, 4, 0.01, box) == (0, 0, 40)


def test_bench_reports_costs_per_order_and_agent():
    cfg = cfg_with("bench.scaling_n_agents=2")
    df = bench_multipole(cfg, orders=(2, 4), width_cm=60.0, repeats=1)
    assert len(df) == 4 and set(df["order"]) == {2, 4}
    assert (df[["cell_ns", "direct_ns", "quadtree_us", "direct_us"]] > 0).all().all()
    assert (df["cells"] >= 0).all() and (df["direct_sources"] <= df["sources"]).all()
    assert "direct far field" in format_multipole(df)


def test_no_orders_is_a_clear_error():
    with pytest.raises(ValueError, match="orders"):
        bench_multipole(cfg_with(), orders=())


def test_efish_bench_multipole_prints_its_table_and_rejects_a_bad_width(capsys):
    from efish.cli import main

    assert main(["bench", "multipole", "bench.scaling_n_agents=1", "--orders", "2", "--width", "50"]) == 0
    assert "ns/cell-point" in capsys.readouterr().out
    assert main(["bench", "multipole", "--width", "-5"]) == 2
    assert capsys.readouterr().err.strip() == "efish: error: width_cm must be positive, got -5.0"


def test_the_orders_and_width_are_config_fields_the_flags_override(capsys):
    import json

    from efish.cli import main

    sizes = ["bench.scaling_n_agents=1", "bench.multipole_orders=[2]", "bench.multipole_width_cm=50"]
    assert main(["bench", "multipole", *sizes, "--json"]) == 0
    assert {r["order"] for r in json.loads(capsys.readouterr().out)} == {2}
    assert main(["bench", "multipole", *sizes, "--orders", "3", "--json"]) == 0
    assert {r["order"] for r in json.loads(capsys.readouterr().out)} == {3}
    assert main(["bench", "multipole", "bench.multipole_width_cm=-1"]) == 2  # the schema's range
    assert "bench.multipole_width_cm=-1" in capsys.readouterr().err
