"""``load_policy``: a trained actor the rollout code can step, hidden states exposed."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from .networks import Actor
from .train import CHECKPOINT, FINAL


class Policy:
    """Steps the actor for [B, N] agents; ``act`` returns actions and the new hidden state.

    Hidden states are numpy arrays [B, N, H] so rollout tables can store them.
    """

    def __init__(self, actor: Actor, n_agents: int):
        self.actor = actor.eval()
        self.n_agents = n_agents
        self.hidden_size = actor.trunk.hidden
        self.obs_dim = actor.trunk.mlp[0].normalized_shape[0]

    def initial_hidden(self, num_envs: int, n_agents: int | None = None) -> np.ndarray:
        """Zero hidden states [B, N, H]; the shared weights act for any number of agents."""
        return np.zeros((num_envs, n_agents or self.n_agents, self.hidden_size), dtype=np.float32)

    @torch.no_grad()
    def act(self, obs: np.ndarray, hidden: np.ndarray, starts: np.ndarray, deterministic: bool = True,
            generator: torch.Generator | None = None) -> tuple[np.ndarray, np.ndarray]:
        """obs [B, N, D], hidden [B, N, H], starts [B] or [B, N] (1 on an episode's first step) ->
        (actions [B, N, 4], hidden [B, N, H])."""
        b, n, d = obs.shape
        if d != self.obs_dim:
            raise ValueError(f"the policy expects observations of {self.obs_dim} values, the env gives {d} "
                             "(another perception or agent count than in training?)")
        starts = np.broadcast_to(np.asarray(starts, dtype=np.float32).reshape(b, -1), (b, n))
        dist, h, _ = self.actor(torch.as_tensor(obs, dtype=torch.float32).reshape(1, b * n, -1),
                                torch.as_tensor(hidden).reshape(b * n, -1),
                                torch.as_tensor(starts.reshape(1, b * n).copy()))
        actions = dist.mode() if deterministic else dist.sample(generator)
        return actions.reshape(b, n, 4).numpy(), h.reshape(b, n, -1).numpy()


def load_policy(path: str | Path) -> Policy:
    """The actor of a checkpoint: a file (final.pt, checkpoint.pt, a stage_<k>.pt of ``train.keep_stages``), or a
    training folder (its final.pt, else its latest checkpoint.pt)."""
    path = Path(path)
    if path.is_dir():
        path = path / FINAL if (path / FINAL).exists() else path / CHECKPOINT
    try:
        state = torch.load(path, weights_only=False, map_location="cpu")  # a policy trained on a GPU acts on CPUs
        arch = state["architecture"]
        actor = Actor(arch["obs_dim"], arch["hidden"])
        actor.load_state_dict(state["actor"])
    except FileNotFoundError:
        raise ValueError(f"no checkpoint at {path}") from None
    except Exception as exc:
        raise ValueError(f"cannot load a policy from {path}: {type(exc).__name__}") from None
    return Policy(actor, arch["n_agents"])


def read_stage(path: str | Path) -> dict:
    """The record of a stage file (``train.keep_stages``): ``k``, ``fraction``, ``update``, ``env_steps`` (at the
    end of that update) and the run's ``total_updates``; one clear error for any other file."""
    path = Path(path)
    try:
        record = torch.load(path, weights_only=False, map_location="cpu")["stage"]
    except FileNotFoundError:
        raise ValueError(f"no stage file at {path}") from None
    except Exception as exc:
        raise ValueError(f"{path} is not a training stage (train.keep_stages): {type(exc).__name__}") from None
    return dict(record)
