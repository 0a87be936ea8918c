"""Actor and critic (docs/methods/training.md#mappo): LayerNorm(input) -> [Linear-ReLU-LayerNorm] x 2 -> GRU ->
LayerNorm -> head.

Both step one time step at a time (rollouts) and run whole chunks of a
sequence (BPTT in training); masks zero the hidden state at episode starts in
both, so the two give the same outputs for the same sequence.
"""

from __future__ import annotations

import itertools
import math

import torch
import torch.nn.functional as F
from torch import nn

from ..config.schema import TrainConfig
from .distributions import ActionDistribution

HEAD_GAIN = TrainConfig().head_gain  # the schema's train.head_gain: the default of both heads


def _orthogonal(layer: nn.Linear, gain: float) -> nn.Linear:
    nn.init.orthogonal_(layer.weight, gain)
    nn.init.zeros_(layer.bias)
    return layer


class RecurrentTrunk(nn.Module):
    """Feature MLP and GRU shared by actor and critic (separate instances, separate weights)."""

    def __init__(self, input_dim: int, hidden: int):
        super().__init__()
        relu_gain = math.sqrt(2)
        self.mlp = nn.Sequential(
            nn.LayerNorm(input_dim),
            _orthogonal(nn.Linear(input_dim, hidden), relu_gain), nn.ReLU(), nn.LayerNorm(hidden),
            _orthogonal(nn.Linear(hidden, hidden), relu_gain), nn.ReLU(), nn.LayerNorm(hidden),
        )
        self.gru = nn.GRU(hidden, hidden)
        for name, p in self.gru.named_parameters():
            if "weight" in name:
                nn.init.orthogonal_(p)
            else:
                nn.init.zeros_(p)
        self.out_norm = nn.LayerNorm(hidden)
        self.hidden = hidden

    def standardize(self, x: torch.Tensor) -> torch.Tensor:
        """The input LayerNorm without its affine part: each row to mean 0 and variance 1. It has no parameters, so
        the PPO update computes it once per rollout (:meth:`forward` with ``standardized=True``) instead of once
        per epoch."""
        norm = self.mlp[0]
        return F.layer_norm(x, norm.normalized_shape, eps=norm.eps)

    def input_layer(self, z: torch.Tensor) -> torch.Tensor:
        """The first Linear applied to the input LayerNorm's affine map of standardized rows ``z``, folded into one
        Linear: weight W diag(g), bias W b + c (g, b the LayerNorm's; W, c the Linear's). The same function of the
        same parameters; its backward needs no gradient with respect to the [rows, input] activations (the
        LayerNorm's affine would), a GEMM as large as the forward's that ran at a fifth of the CPU's GEMM rate."""
        norm, first = self.mlp[0], self.mlp[1]
        return F.linear(z, first.weight * norm.weight, torch.addmv(first.bias, first.weight, norm.bias))

    def hidden_states(self, x: torch.Tensor, h: torch.Tensor, starts: torch.Tensor, standardized: bool = False
                      ) -> tuple[torch.Tensor, torch.Tensor]:
        """The GRU's hidden state after each step: x [T, B, D] (already :meth:`standardize`-d when
        ``standardized``), h [B, H] before the chunk, starts [T, B] (1 where an episode begins) -> [T, B, H], and
        the last of them [B, H]. A rollout reads them to bootstrap a truncated episode from the hidden state of its
        step (:func:`efish.rl.collect.collect`)."""
        z = x if standardized else self.standardize(x)
        feats = self.mlp[2:](self.input_layer(z))
        keep = (1.0 - starts.to(feats.dtype)).unsqueeze(-1)
        if x.shape[0] == 1:  # a rollout step: the GRU cell gives the same numbers without nn.GRU's overhead
            g = self.gru
            h = torch.gru_cell(feats[0], h * keep[0], g.weight_ih_l0, g.weight_hh_l0, g.bias_ih_l0, g.bias_hh_l0)
            return h.unsqueeze(0), h
        # One fused GRU call per stretch without episode starts (in training usually the whole
        # chunk); the hidden state is zeroed where a sequence starts, as a step-by-step loop would.
        cuts = torch.nonzero(starts.any(dim=1)).flatten().tolist()
        bounds = sorted(set([0, x.shape[0]] + cuts))
        outs = []
        for a, b in itertools.pairwise(bounds):
            out, h_next = self.gru(feats[a:b], (h * keep[a]).unsqueeze(0))
            h = h_next.squeeze(0)
            outs.append(out)
        return torch.cat(outs), h

    def forward(self, x: torch.Tensor, h: torch.Tensor, starts: torch.Tensor, standardized: bool = False
                ) -> tuple[torch.Tensor, torch.Tensor]:
        """x [T, B, D] (already :meth:`standardize`-d when ``standardized``), h [B, H] before the chunk, starts
        [T, B] (1 where an episode begins).

        Returns features [T, B, H] and the hidden state after the chunk [B, H].
        """
        states, h = self.hidden_states(x, h, starts, standardized)
        return self.out_norm(states), h


class Actor(nn.Module):
    """Policy: trunk -> (move/turn means, EOD/bite logits); log-std state-independent, init 0."""

    def __init__(self, obs_dim: int, hidden: int, head_gain: float = HEAD_GAIN):
        super().__init__()
        self.trunk = RecurrentTrunk(obs_dim, hidden)
        self.head = _orthogonal(nn.Linear(hidden, 4), head_gain)
        self.log_std = nn.Parameter(torch.zeros(2))

    def forward(self, obs: torch.Tensor, h: torch.Tensor, starts: torch.Tensor, standardized: bool = False
                ) -> tuple[ActionDistribution, torch.Tensor, torch.Tensor]:
        """obs [T, B, D] -> distribution over [T, B] actions, final hidden [B, H], features [T, B, H]
        (``standardized``: obs is already :meth:`RecurrentTrunk.standardize`-d)."""
        feats, h = self.trunk(obs, h, starts, standardized)
        out = self.head(feats)
        return ActionDistribution(out[..., :2], self.log_std.expand_as(out[..., :2]), out[..., 2:]), h, feats


class Critic(nn.Module):
    """Centralised value: trunk over the concatenated observations of all agents -> scalar."""

    def __init__(self, state_dim: int, hidden: int, head_gain: float = HEAD_GAIN):
        super().__init__()
        self.trunk = RecurrentTrunk(state_dim, hidden)
        self.head = _orthogonal(nn.Linear(hidden, 1), head_gain)

    def forward(self, state: torch.Tensor, h: torch.Tensor, starts: torch.Tensor, standardized: bool = False
                ) -> tuple[torch.Tensor, torch.Tensor]:
        """state [T, B, N*D] -> values [T, B], final hidden [B, H] (``standardized`` as for the actor)."""
        feats, h = self.trunk(state, h, starts, standardized)
        return self.head(feats).squeeze(-1), h

    def values_along(self, state: torch.Tensor, h: torch.Tensor, starts: torch.Tensor
                     ) -> tuple[torch.Tensor, torch.Tensor]:
        """state [T, B, N*D] -> values [T, B] and the hidden state after each step [T, B, H]: a whole rollout's
        values in one pass, the same numbers as stepping through it (up to rounding)."""
        states, _ = self.trunk.hidden_states(state, h, starts)
        return self.head(self.trunk.out_norm(states)).squeeze(-1), states
