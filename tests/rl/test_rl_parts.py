"""Distributions, GAE, value normalisation and the recurrent networks (docs/methods/training.md#mappo)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from efish.rl.advantages import gae
from efish.rl.distributions import ActionDistribution
from efish.rl.networks import Actor, Critic
from efish.rl.value_norm import ValueNormalizer


def random_dist(gen: torch.Generator, shape=(5, 3), scale=3.0) -> ActionDistribution:
    return ActionDistribution(torch.randn(*shape, 2, generator=gen, dtype=torch.float64),
                              0.5 * torch.randn(*shape, 2, generator=gen, dtype=torch.float64),
                              scale * torch.randn(*shape, 2, generator=gen, dtype=torch.float64))


def test_log_prob_and_entropy_match_torch_distributions():
    gen = torch.Generator().manual_seed(0)
    d = random_dist(gen)
    a = d.sample(gen)
    normal = torch.distributions.Normal(d.mean, d.log_std.exp())
    bern = torch.distributions.Bernoulli(logits=d.logits)
    expected = normal.log_prob(a[..., :2]).sum(-1) + bern.log_prob(a[..., 2:]).sum(-1)
    torch.testing.assert_close(d.log_prob(a), expected)
    torch.testing.assert_close(d.entropy(), normal.entropy().sum(-1) + bern.entropy().sum(-1))


def test_bernoulli_heads_saturate_without_nan():
    d = ActionDistribution(torch.zeros(4, 2), torch.zeros(4, 2), torch.tensor([[100.0, -100.0]] * 4))
    a = torch.tensor([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0], [0.0, 0.0, 0.0, 0.0]])
    lp = d.log_prob(a)
    assert torch.isfinite(lp).all() and torch.isfinite(d.entropy()).all()
    assert lp[0] == pytest.approx(-2 * 0.5 * np.log(2 * np.pi), abs=1e-6)  # the likely outcome costs nothing
    assert lp[1] < -190  # the impossible outcome costs about 200 nats, not -inf
    assert torch.equal(d.mode()[:, 2:], torch.tensor([[1.0, 0.0]] * 4))


def test_gae_matches_a_hand_computed_example_with_truncation_and_termination():
    r = torch.tensor([[1.0], [2.0], [3.0], [4.0]])
    v = torch.tensor([[0.5], [1.0], [1.5], [2.0]])
    nv = torch.tensor([[1.0], [1.5], [9.0], [7.0]])  # step 2 terminated (9 is ignored), step 3 truncated
    term = torch.tensor([[False], [False], [True], [False]])
    trunc = torch.tensor([[False], [False], [False], [True]])
    g, lam = 0.9, 0.8
    d3 = 4 + g * 7 - 2.0
    d2 = 3 - 1.5
    d1 = 2 + g * 1.5 - 1.0
    d0 = 1 + g * 1.0 - 0.5
    expected = torch.tensor([[d0 + g * lam * (d1 + g * lam * d2)], [d1 + g * lam * d2], [d2], [d3]])
    adv, ret = gae(r, v, nv, term, trunc, g, lam)
    torch.testing.assert_close(adv, expected)
    torch.testing.assert_close(ret, expected + v)


def test_value_normalizer_tracks_exact_running_moments():
    vn = ValueNormalizer(eps=0.0)
    data = np.random.default_rng(0).normal(3.0, 2.0, 1000)
    for chunk in np.split(data, [100, 350, 351, 900]):
        vn.update(torch.tensor(chunk))
    assert float(vn.mean) == pytest.approx(data.mean(), rel=1e-12)
    assert float(vn.var) == pytest.approx(data.var(), rel=1e-12)
    x = torch.tensor(data[:10])
    torch.testing.assert_close(vn.denormalize(vn.normalize(x)), x)


@pytest.mark.parametrize("net", ["actor", "critic"])
def test_chunked_forward_equals_step_by_step_with_episode_resets(net):
    torch.manual_seed(0)
    model = Actor(7, 16) if net == "actor" else Critic(7, 16)
    steps, batch = 12, 3
    x = torch.randn(steps, batch, 7)
    starts = torch.zeros(steps, batch)
    starts[5, 0] = starts[0, :] = starts[9, 2] = 1.0
    h0 = torch.randn(batch, 16)

    def out_of(result):
        return result[0].mean if net == "actor" else result[0]

    full = model(x, h0, starts)
    h, step_outs = h0, []
    for t in range(steps):
        r = model(x[t:t + 1], h, starts[t:t + 1])
        step_outs.append(out_of(r))
        h = r[1]
    torch.testing.assert_close(out_of(full), torch.cat(step_outs))
    torch.testing.assert_close(full[1], h)


def test_episode_start_forgets_the_hidden_state():
    torch.manual_seed(1)
    actor = Actor(5, 8)
    x = torch.randn(1, 2, 5)
    starts = torch.ones(1, 2)
    a = actor(x, torch.randn(2, 8), starts)[0].mean
    b = actor(x, torch.zeros(2, 8), starts)[0].mean
    torch.testing.assert_close(a, b)


def test_heads_start_small():
    actor = Actor(110, 64)
    assert actor.head.weight.abs().max() < 0.05 and torch.all(actor.log_std == 0)


def test_micro_batches_give_the_same_update_as_one_pass():
    """Gradient accumulation over micro-batches is a compute choice: the weights after an update match
    those of one pass over the whole minibatch (to float32 summation order)."""
    import copy
    import dataclasses

    from efish.config import compose
    from efish.rl.mappo import Rollout, ppo_update

    T, S, D, N, H = 8, 12, 6, 2, 16
    g = torch.Generator().manual_seed(0)
    ro = Rollout(obs=torch.randn(T, S, D, generator=g), state=torch.randn(T, S, D * N, generator=g),
                 actions=torch.rand(T, S, 4, generator=g).round(), logp=-torch.rand(T, S, generator=g),
                 values=torch.randn(T, S, generator=g), advantages=torch.randn(T, S, generator=g),
                 returns=torch.randn(T, S, generator=g), starts=(torch.rand(T, S, generator=g) < 0.1).float(),
                 h_actor=torch.zeros(2, S, H), h_critic=torch.zeros(2, S, H))
    base = compose(["train.chunk=4", "train.rollout_steps=8", "train.epochs=2", "train.minibatches=2"]).train
    torch.manual_seed(1)
    actor0, critic0 = Actor(D, H), Critic(D * N, H)
    results = []
    for micro in (1000, 5):  # one pass per minibatch of 12 sequences, or passes of 5 + 5 + 2
        cfg = dataclasses.replace(base, micro_sequences=micro, hidden=H)
        actor, critic = copy.deepcopy(actor0), copy.deepcopy(critic0)
        opt_a, opt_c = torch.optim.Adam(actor.parameters(), lr=1e-3), torch.optim.Adam(critic.parameters(), lr=1e-3)
        stats = ppo_update(cfg, actor, critic, opt_a, opt_c, ValueNormalizer(), ro, torch.Generator().manual_seed(2))
        results.append((actor.state_dict(), critic.state_dict(), stats))
    (a1, c1, s1), (a2, c2, s2) = results
    for key in a1:
        torch.testing.assert_close(a1[key], a2[key], rtol=1e-4, atol=1e-5)
    for key in c1:
        torch.testing.assert_close(c1[key], c2[key], rtol=1e-4, atol=1e-5)
    for key in s1:
        assert s1[key] == pytest.approx(s2[key], rel=1e-4, abs=1e-6), key
    assert any(not torch.equal(a1[k], v) for k, v in actor0.state_dict().items())  # the update moved the weights


def test_folded_input_layer_is_the_layernorm_then_the_linear():
    """The input LayerNorm's affine part folded into the first Linear computes the same function of the same
    parameters, with the same gradients for all four of them (to float32 rounding)."""
    from efish.rl.networks import RecurrentTrunk

    torch.manual_seed(3)
    trunk = RecurrentTrunk(11, 8)
    norm, first = trunk.mlp[0], trunk.mlp[1]
    with torch.no_grad():  # away from the initial 1 and 0, so that the fold is exercised
        norm.weight.uniform_(0.5, 2.0)
        norm.bias.normal_()
    x = torch.randn(5, 3, 11) * 4 + 2
    upstream = torch.randn(5, 3, 8)
    params = [norm.weight, norm.bias, first.weight, first.bias]

    def grads(out):
        return torch.autograd.grad((out * upstream).sum(), params)

    explicit = first(norm(x))
    folded = trunk.input_layer(trunk.standardize(x))
    torch.testing.assert_close(folded, explicit, rtol=1e-5, atol=1e-5)
    for a, b in zip(grads(folded), grads(explicit), strict=True):
        torch.testing.assert_close(a, b, rtol=1e-4, atol=1e-4)


def test_standardized_inputs_give_the_same_outputs():
    torch.manual_seed(4)
    actor, critic = Actor(6, 8), Critic(12, 8)
    obs, state = torch.randn(4, 2, 6), torch.randn(4, 2, 12)
    h, starts = torch.zeros(2, 8), torch.zeros(4, 2)
    torch.testing.assert_close(actor(actor.trunk.standardize(obs), h, starts, standardized=True)[0].mean,
                               actor(obs, h, starts)[0].mean)
    torch.testing.assert_close(critic(critic.trunk.standardize(state), h, starts, standardized=True)[0],
                               critic(state, h, starts)[0])


def test_a_micro_batch_of_every_sequence_is_the_data_itself():
    """A micro-batch is a set of sequences: taken in increasing order, and without a copy when it holds them all."""
    from efish.rl.mappo import micro_batch

    data = {"obs": torch.arange(24.0).reshape(2, 4, 3)}
    h_a, h_c = torch.arange(8.0).reshape(4, 2), -torch.arange(8.0).reshape(4, 2)
    batch, ha, hc = micro_batch(data, h_a, h_c, torch.tensor([2, 0, 3, 1]))
    assert batch is data and ha is h_a and hc is h_c
    batch, ha, hc = micro_batch(data, h_a, h_c, torch.tensor([3, 1]))
    torch.testing.assert_close(batch["obs"], data["obs"][:, [1, 3]])
    torch.testing.assert_close(ha, h_a[[1, 3]])
    torch.testing.assert_close(hc, h_c[[1, 3]])
