"""The hidden table's rows are paired with the world they have observed, never with the action they produced
(decoding rule: sensed variables only, docs/claims/index.md#rule-7); and the decoding targets the rollout records for
that pairing."""

from __future__ import annotations

import numpy as np
import pytest

from efish.analysis.decoding import heldout_skill
from efish.config import compose
from efish.rollout.measures import log_morm_sensed
from efish.rollout.run import run_episodes
from efish.sensors.normalize import log_normalize

KEYS = ["condition", "episode", "t", "agent"]
EPISODES, STEPS, UNITS = 4, 40, 4


class FreshState:
    """A test double whose state ignores its input: each call draws a fresh state from its own seeded generator,
    and its turn is a function of that state alone (raw turn = h_0, so the env's turn = tanh(h_0)); move, EOD and
    bite are constant. The action of step t therefore comes from the state drawn at call t and from nothing else,
    and the state returned at call t + 1 (which takes in step t's observation) is independent of it."""

    def __init__(self, seed: int = 7):
        self.rng = np.random.default_rng(seed)
        self.calls = 0

    def initial_hidden(self, b, n):
        return np.zeros((b, n, UNITS), np.float32)

    def act(self, obs, hidden, starts, deterministic=True):
        self.calls += 1
        h = self.rng.normal(0.0, 0.5, obs.shape[:2] + (UNITS,)).astype(np.float32)
        a = np.zeros(obs.shape[:2] + (4,))
        a[..., 0], a[..., 1], a[..., 2], a[..., 3] = 0.0, h[..., 0], 1.0, -1.0
        return a, h


@pytest.fixture(scope="module")
def run():
    cfg = compose(["scale=smoke", "assay=wide2", f"env.episode_steps={STEPS}"])
    policy = FreshState()
    tables = run_episodes(cfg, policy, EPISODES, condition="control", seed=3, record_hidden=True)
    return tables, policy


def test_hidden_rows_are_the_steps_rows(run):
    (tables, policy), steps = run, run[0]["steps"]
    hidden = tables["hidden"]
    assert hidden[KEYS].reset_index(drop=True).equals(steps[KEYS].reset_index(drop=True))
    assert len(steps) == EPISODES * STEPS * 2
    assert policy.calls == STEPS + 1  # one act per step, and one more on the final observation


def test_the_action_of_a_step_is_not_decodable_from_that_steps_hidden_row(run):
    tables, _ = run
    joined = tables["hidden"].merge(tables["steps"][[*KEYS, "turn"]], on=KEYS)
    h = joined[[f"h_{i}" for i in range(UNITS)]].to_numpy(np.float64)
    turn, n = joined["turn"].to_numpy(np.float64), len(joined)
    # under independence each correlation is ~N(0, 1/n): 4 / sqrt(n) is a 4-sigma bound (n = 320 here: 0.22)
    r = [np.corrcoef(h[:, i], turn)[0, 1] for i in range(UNITS)]
    assert max(abs(x) for x in r) < 4 / np.sqrt(n)
    held_out = heldout_skill(h, turn, joined["episode"].to_numpy())
    assert held_out["n"].sum() == n and held_out["skill"].mean() < 0.05  # chance: about -UNITS / n


def test_the_old_alignment_would_decode_the_action_exactly(run):
    """The state that produced the action of step t is hidden row t - 1: pairing the two (what the table held
    before, row t = the state returned with action t) reads the action off the state exactly."""
    tables, _ = run
    hidden, steps = tables["hidden"], tables["steps"]
    produced = hidden.assign(t=hidden["t"] + 1).merge(steps[[*KEYS, "turn"]], on=KEYS)
    assert len(produced) == EPISODES * (STEPS - 1) * 2
    np.testing.assert_allclose(produced["turn"], np.tanh(produced["h_0"].to_numpy(np.float64)), rtol=0, atol=1e-12)
    h = produced[[f"h_{i}" for i in range(UNITS)]].to_numpy(np.float64)
    assert heldout_skill(h, produced["turn"].to_numpy(np.float64), produced["episode"].to_numpy())["skill"].min() > 0.95


def test_agents_in_knollenorgan_range_count_the_others_closer_than_the_range(run):
    steps = run[0]["steps"]
    # two agents: the other one is in range exactly when the nearest agent is closer than 100 cm
    np.testing.assert_array_equal(steps["n_agents_100cm"], (steps["dist_agent_cm"] < 100.0).astype(int))
    assert set(steps["n_agents_100cm"]) == {0, 1}  # the wide2 starts are 120 cm apart, and the agents move


def test_the_sensed_mormyromast_log_reading_inverts_the_log_normalisation():
    e_min, e_max = 5e-8, 5e-2
    s = np.array([[[3e-6, -2e-4, 1e-9]], [[1e-9, -1e-10, 0.0]], [[1.0, 1e-7, 0.0]]])  # [B=3, N=1, M=3]
    got = log_morm_sensed(log_normalize(s, e_min, e_max), e_min, e_max)
    np.testing.assert_allclose(got[0], np.log10(2e-4))     # the strongest reading, whatever its sign
    assert np.isnan(got[1]).all()                           # nothing above E_min: not sensed
    np.testing.assert_allclose(got[2], np.log10(e_max))    # saturated: clipped at E_max


def test_the_sensed_mormyromast_log_reading_is_within_the_range_or_nan(run):
    m = compose(["scale=smoke"]).sensors.mormyromast
    values = run[0]["steps"]["log_morm_sensed"].to_numpy(np.float64)
    finite = values[np.isfinite(values)]
    assert finite.size and (finite >= np.log10(m.e_min)).all() and (finite <= np.log10(m.e_max) + 1e-9).all()
    off = compose(["scale=smoke", "assay=wide2", "env.episode_steps=3", "sensors.mormyromast.enabled=false"])
    ablated = run_episodes(off, FreshState(), 1, seed=3)["steps"]
    assert ablated["log_morm_sensed"].isna().all()
    assert (ablated["n_agents_100cm"] >= 0).all()
