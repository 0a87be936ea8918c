"""PettingZoo ``ParallelEnv`` adapter: one arena, agents as ``fish_0 .. fish_{N-1}``.

    >>> env = parallel_env(**{"env.episode_steps": 3})
    >>> obs, infos = env.reset(seed=0)
    >>> sorted(obs), obs["fish_0"].shape
    (['fish_0', 'fish_1', 'fish_2', 'fish_3'], (110,))
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from ..config import EfishConfig, compose
from .vec_env import VecEnv


def parallel_env(cfg: EfishConfig | None = None, **overrides) -> "EfishParallelEnv":
    """A PettingZoo ParallelEnv of one foraging arena.

    ``overrides`` are config keys with their values, e.g.
    ``parallel_env(**{"env.n_agents": 2, "arena": "uniform70"})``.
    """
    if cfg is None:
        cfg = compose([f"{k}={_hydra_value(v)}" for k, v in overrides.items()])
    elif overrides:
        raise ValueError("pass either a composed cfg or overrides, not both")
    return EfishParallelEnv(cfg)


def _hydra_value(v) -> str:
    if isinstance(v, (list, tuple)):
        return "[" + ",".join(_hydra_value(x) for x in v) + "]"
    return str(v).lower() if isinstance(v, bool) else str(v)


class EfishParallelEnv(ParallelEnv):
    """Actions per agent: ``{"move_turn": Box(2) raw Gaussian samples, "eod_bite": MultiBinary(2)}``."""

    metadata = {"name": "efish_foraging_v0", "render_modes": []}

    def __init__(self, cfg: EfishConfig):
        self.cfg = cfg
        self.possible_agents = [f"fish_{i}" for i in range(cfg.env.n_agents)]
        self.agents: list[str] = []
        self._vec = VecEnv(cfg, num_envs=1, seed=0)
        dim = self._vec.reset().shape[-1]
        self._obs_space = spaces.Box(-1.0, 1.0, (dim,), np.float32)
        self._act_space = spaces.Dict({"move_turn": spaces.Box(-np.inf, np.inf, (2,), np.float32),
                                       "eod_bite": spaces.MultiBinary(2)})

    def observation_space(self, agent: str) -> spaces.Space:
        return self._obs_space

    def action_space(self, agent: str) -> spaces.Space:
        return self._act_space

    def reset(self, seed: int | None = None, options: dict | None = None):
        if seed is not None:
            self._vec = VecEnv(self.cfg, num_envs=1, seed=seed)
        obs = self._vec.reset()[0]
        self.agents = list(self.possible_agents)
        return {a: obs[i] for i, a in enumerate(self.agents)}, {a: {} for a in self.agents}

    def step(self, actions: dict):
        if not self.agents:
            raise RuntimeError("step() called after the episode ended; call reset()")
        arr = np.zeros((1, len(self.possible_agents), 4))
        for i, a in enumerate(self.possible_agents):
            act = actions[a]
            arr[0, i, :2] = act["move_turn"]
            arr[0, i, 2:] = act["eod_bite"]
        obs, reward, terminated, truncated, info = self._vec.step(arr)
        if terminated[0] or truncated[0]:
            obs = info["final_obs"]
        agents = self.agents
        keys = ("ate", "bit", "was_bitten", "collided", "eod")
        infos = {a: {k: bool(info[k][0, i]) for k in keys} for i, a in enumerate(agents)}
        out = ({a: obs[0, i] for i, a in enumerate(agents)}, {a: float(reward[0, i]) for i, a in enumerate(agents)},
               {a: bool(terminated[0]) for a in agents}, {a: bool(truncated[0]) for a in agents}, infos)
        if terminated[0] or truncated[0]:
            self.agents = []
        return out
