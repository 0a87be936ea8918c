"""Grouped rollouts: several policies (a recipe's seeds) run the same episodes in one env, one table set each.

An assay's step costs mostly the same whatever the number of arenas: the
env's and the recording's Python work per step, a network call per policy.
So the top seeds' reruns, which run the same episodes with K policies, run
them as the K members of one :class:`~efish.env.vec_env.VecEnv`: member k's
arenas are drawn exactly as its own env would draw them, policy k acts on
them alone (a call of the same shape as alone, so the same arithmetic), and
member k's tables are split off at the end. Each policy's tables thus equal,
bit for bit, what :func:`~efish.rollout.run.run_episodes` gives that policy
alone, whichever policies share its group (tested).

Actions must be deterministic: sampled ones would draw from one random stream
shared by the group, so a policy's draws would depend on its companions.

    >>> import numpy as np
    >>> from efish.config import compose
    >>> class Still:  # a policy that stands still and never emits
    ...     def initial_hidden(self, b, n): return np.zeros((b, n, 1), np.float32)
    ...     def act(self, obs, hidden, starts, deterministic=True):
    ...         return np.full(obs.shape[:2] + (4,), -5.0), hidden
    >>> cfg = compose(["env.episode_steps=3"])
    >>> first, second = run_group(cfg, [Still(), Still()], episodes=2)
    >>> first["episodes"]["episode"].unique().tolist(), len(first["steps"]) == len(second["steps"])
    ([0, 1], True)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from ..config.schema import EfishConfig
from .run import run_episodes


class PolicyGroup:
    """K policies acting as one on a VecEnv of K members of ``episodes`` arenas each: rows ``k * episodes`` ...
    ``(k + 1) * episodes - 1`` of every [B, N, ...] array are policy k's. Their hidden states must have one size
    (the policies of one recipe), so that the group's is one [B, N, H] array."""

    def __init__(self, policies: Sequence, episodes: int):
        self.policies, self.episodes = list(policies), int(episodes)

    def _rows(self, k: int) -> slice:
        return slice(k * self.episodes, (k + 1) * self.episodes)

    def initial_hidden(self, num_envs: int, n_agents: int) -> np.ndarray:
        """Each policy's zero state for its member's arenas, stacked: [K x episodes, N, H]."""
        if num_envs != len(self.policies) * self.episodes:
            raise ValueError(f"a group of {len(self.policies)} policies x {self.episodes} episodes acts in "
                             f"{len(self.policies) * self.episodes} arenas, not {num_envs}")
        states = [p.initial_hidden(self.episodes, n_agents) for p in self.policies]
        if len({s.shape[-1] for s in states}) > 1:
            raise ValueError(f"the policies of a group must have one hidden size, got "
                             f"{[s.shape[-1] for s in states]}")
        return np.concatenate(states)

    def act(self, obs: np.ndarray, hidden: np.ndarray, starts: np.ndarray, deterministic: bool = True
            ) -> tuple[np.ndarray, np.ndarray]:
        """Each policy on its member's rows of ``obs`` [B, N, D], ``hidden`` [B, N, H] and ``starts`` [B]."""
        actions, states = [], []
        for k, policy in enumerate(self.policies):
            rows = self._rows(k)
            a, h = policy.act(obs[rows], hidden[rows], starts[rows], deterministic)
            actions.append(a)
            states.append(h)
        return np.concatenate(actions), np.concatenate(states)


def member_tables(tables: dict[str, pd.DataFrame], member: int, episodes: int) -> dict[str, pd.DataFrame]:
    """Member ``member``'s rows of a grouped run's tables (episodes ``member * episodes`` ...), numbered from 0 as
    its run alone numbers them; the row order is kept (within a member, the grouped run's)."""
    lo = member * episodes
    out = {}
    for name, table in tables.items():
        mine = table[(table["episode"] >= lo) & (table["episode"] < lo + episodes)].reset_index(drop=True)
        mine["episode"] = mine["episode"] - lo
        out[name] = mine
    return out


def run_group(cfg: EfishConfig, policies: Sequence, episodes: int, condition: str = "control", seed: int = 0,
              deterministic: bool = True, record_hidden: bool = False) -> list[dict[str, pd.DataFrame]]:
    """:func:`~efish.rollout.run.run_episodes` of each of ``policies`` on the same ``episodes`` episodes, in one env:
    one table set per policy, in their order, each equal to that policy's run alone (module docstring)."""
    if not policies:
        raise ValueError("a group needs at least one policy")
    if not deterministic:
        raise ValueError("grouped rollouts need deterministic actions (assay.deterministic=true): sampled actions "
                         "would share one random stream across the group")
    group = PolicyGroup(policies, episodes)
    tables = run_episodes(cfg, group, episodes, condition=condition, seed=seed, deterministic=True,
                          record_hidden=record_hidden, members=len(group.policies))
    return [member_tables(tables, k, episodes) for k in range(len(group.policies))]
