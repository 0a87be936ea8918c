"""The action distribution of one agent (docs/model/environment.md#actions-and-motion): a diagonal 2-D Gaussian (move,
turn) and two independent Bernoulli variables (EOD, bite) given as logits.

Log-probabilities are joint (sums over the four components) and computed from
logits with softplus, so logits of +-100 saturate without NaN or infinities.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch
import torch.nn.functional as F

LOG_SQRT_2PI = 0.5 * math.log(2 * math.pi)


@dataclass
class ActionDistribution:
    """mean, log_std: [..., 2]; logits: [..., 2] (EOD, bite). Actions are [..., 4]: raw move,
    raw turn (Gaussian samples, mapped by the env), eod and bite in {0, 1}."""

    mean: torch.Tensor
    log_std: torch.Tensor
    logits: torch.Tensor

    def to(self, dtype: torch.dtype) -> "ActionDistribution":
        """The same distribution with parameters cast (e.g. back to float32 after bf16 autocast)."""
        return ActionDistribution(self.mean.to(dtype), self.log_std.to(dtype), self.logits.to(dtype))

    def sample(self, generator: torch.Generator | None = None) -> torch.Tensor:
        """Stochastic actions (training). Noise is drawn on the generator's device (the CPU in training, whatever
        device the networks use) and moved to the parameters', so a run's random stream does not depend on it."""
        where = generator.device if generator is not None else self.mean.device
        noise = torch.randn(self.mean.shape, generator=generator, dtype=self.mean.dtype, device=where)
        gauss = self.mean + self.log_std.exp() * noise.to(self.mean.device)
        probs = torch.sigmoid(self.logits)
        uniform = torch.rand(probs.shape, generator=generator, dtype=probs.dtype, device=where)
        bern = uniform.to(probs.device) < probs
        return torch.cat([gauss, bern.to(gauss.dtype)], dim=-1)

    def mode(self) -> torch.Tensor:
        """Deterministic actions (evaluation): the Gaussian mean, Bernoulli thresholded at p > 0.5."""
        return torch.cat([self.mean, (self.logits > 0).to(self.mean.dtype)], dim=-1)

    def log_prob(self, actions: torch.Tensor) -> torch.Tensor:
        """Joint log-probability of [..., 4] actions, shape [...]."""
        z = (actions[..., :2] - self.mean) / self.log_std.exp()
        gauss = (-0.5 * z * z - self.log_std - LOG_SQRT_2PI).sum(-1)
        b = actions[..., 2:]
        bern = -(b * F.softplus(-self.logits) + (1 - b) * F.softplus(self.logits)).sum(-1)
        return gauss + bern

    def entropy(self) -> torch.Tensor:
        """Joint entropy, shape [...]."""
        gauss = (0.5 + LOG_SQRT_2PI + self.log_std).sum(-1).expand(self.mean.shape[:-1])
        p = torch.sigmoid(self.logits)
        bern = (p * F.softplus(-self.logits) + (1 - p) * F.softplus(self.logits)).sum(-1)
        return gauss + bern
