"""PettingZoo ``ParallelEnv`` adapter: one arena, agents as ``fish_0 .. fish_{N-1}``.

    >>> env = parallel_env(**{"env.episode_steps": 3})
    >>> obs, infos = env.reset(seed=0)
    >>> sorted(obs), obs["fish_0"].shape
    (['fish_0', 'fish_1', 'fish_2', 'fish_3'], (110,))
    >>> env.state().shape, env.state_space.shape   # every agent's observation, in id order
    ((440,), (440,))
"""

from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from ..config import EfishConfig, compose
from ..drawing import arena_image
from .observe import observation_size
from .vec_env import VecEnv

RENDER_MODES = ["rgb_array"]


def parallel_env(cfg: EfishConfig | None = None, render_mode: str | None = None,
                 **overrides) -> "EfishParallelEnv":
    """A PettingZoo ParallelEnv of one foraging arena.

    ``overrides`` are config keys with their values, e.g.
    ``parallel_env(**{"env.n_agents": 2, "arena": "uniform70"})``; ``render_mode`` is ``None`` or
    ``"rgb_array"``.
    """
    if cfg is None:
        cfg = compose([f"{k}={_hydra_value(v)}" for k, v in overrides.items()])
    elif overrides:
        raise ValueError("pass either a composed cfg or overrides, not both")
    return EfishParallelEnv(cfg, render_mode=render_mode)


def _hydra_value(v) -> str:
    if isinstance(v, (list, tuple)):
        return "[" + ",".join(_hydra_value(x) for x in v) + "]"
    return str(v).lower() if isinstance(v, bool) else str(v)


class EfishParallelEnv(ParallelEnv):
    """Actions per agent: ``{"move_turn": Box(2) raw Gaussian samples, "eod_bite": MultiBinary(2)}``.

    Observations lie in Box(-1, 1): every block is normalised into it (log-compressed readings, Knollenorgan slots
    in {-1, 0, 1}, 0/1 flags, size, cooldown fractions, the displacement clipped to +-1, move and turn after
    sigmoid and tanh; docs/model/environment.md#observation). ``state()`` is the global state of a centralised critic; ``render()`` draws the arena
    when ``render_mode="rgb_array"``.
    """

    metadata = {"name": "efish_foraging_v0", "render_modes": RENDER_MODES}

    def __init__(self, cfg: EfishConfig, render_mode: str | None = None):
        if render_mode is not None and render_mode not in RENDER_MODES:
            raise ValueError(f"unknown render_mode {render_mode!r}: choose None or one of {', '.join(RENDER_MODES)}")
        self.cfg = cfg
        self.render_mode = render_mode
        self.possible_agents = [f"fish_{i}" for i in range(cfg.env.n_agents)]
        self.agents: list[str] = []
        self._vec = self._engine(seed=0)
        self._obs: np.ndarray | None = None  # float32[N, D], the observations last returned; None before reset
        self._events: dict[str, np.ndarray] = {}  # the last step's eod, bit and bite_target [1, N], for render
        self._episode = -1  # index of the current episode (0 after the first reset), in the rendered title
        dim = observation_size(cfg)
        self._obs_space = spaces.Box(-1.0, 1.0, (dim,), np.float32)
        self.state_space = spaces.Box(-1.0, 1.0, (len(self.possible_agents) * dim,), np.float32)
        self._act_space = spaces.Dict({"move_turn": spaces.Box(-np.inf, np.inf, (2,), np.float32),
                                       "eod_bite": spaces.MultiBinary(2)})

    def observation_space(self, agent: str) -> spaces.Space:
        return self._obs_space

    def action_space(self, agent: str) -> spaces.Space:
        return self._act_space

    def _engine(self, seed: int) -> VecEnv:
        """One arena that stays as it ended (no autoreset), so ``state()`` and ``render()`` after the last step
        show the end of the episode, not the start of a next one."""
        return VecEnv(self.cfg, num_envs=1, seed=seed, autoreset=False)

    def reset(self, seed: int | None = None, options: dict | None = None):
        if seed is not None:
            self._vec = self._engine(seed)
        self._obs = self._vec.reset()[0]
        n = len(self.possible_agents)
        self._events = {"eod": self._vec.task.forced_eod[None].copy(), "bit": np.zeros((1, n), bool),
                        "bite_target": np.full((1, n), -1)}
        self._episode += 1
        self.agents = list(self.possible_agents)
        return {a: self._obs[i] for i, a in enumerate(self.agents)}, {a: {} for a in self.agents}

    def step(self, actions: dict):
        if not self.agents:
            raise RuntimeError("step() called after the episode ended; call reset()")
        arr = np.zeros((1, len(self.possible_agents), 4))
        for i, a in enumerate(self.possible_agents):
            act = actions[a]
            arr[0, i, :2] = act["move_turn"]
            arr[0, i, 2:] = act["eod_bite"]
        obs, reward, terminated, truncated, info = self._vec.step(arr)
        self._obs = obs[0]
        self._events = {k: info[k] for k in ("eod", "bit", "bite_target")}
        agents = self.agents
        keys = ("ate", "bit", "was_bitten", "collided", "eod")
        infos = {a: {k: bool(info[k][0, i]) for k in keys} for i, a in enumerate(agents)}
        out = ({a: obs[0, i] for i, a in enumerate(agents)}, {a: float(reward[0, i]) for i, a in enumerate(agents)},
               {a: bool(terminated[0]) for a in agents}, {a: bool(truncated[0]) for a in agents}, infos)
        if terminated[0] or truncated[0]:
            self.agents = []
        return out

    def state(self) -> np.ndarray:
        """The global state for a centralised critic, float32[N * D] in ``state_space``: every agent's last
        observation concatenated in id order (``fish_0`` first).

        This is agent 0's row of :func:`efish.rl.collect.agent_centric_state`, the critic input of efish's own
        MAPPO, which gives every agent a view of its own (its own observation first, then the others'): apply that
        function to the stacked observations for the per-agent views. After the last step it is the state the episode ended in, as PettingZoo's state test
        expects; before ``reset()`` there is none.
        """
        if self._obs is None:
            raise RuntimeError("state() called before reset()")
        return self._obs.reshape(-1).copy()

    def render(self) -> np.ndarray | None:
        """The arena now as uint8 RGB [H, W, 3]: walls, pellets, fish, the last step's EOD rings and bites,
        drawn as ``efish render``'s clips draw them (:mod:`efish.drawing`); None, with a warning, when the env was
        made without a render mode."""
        if self.render_mode is None:
            gymnasium.logger.warn("render() called without a render mode: pass render_mode='rgb_array'")
            return None
        if self._obs is None:
            raise RuntimeError("render() called before reset()")
        s, ev = self._vec.state, self._events
        title = f"{self.metadata['name']} · episode {self._episode} · step {int(s.t[0])}"
        return arena_image(float(s.width[0]), float(s.height[0]), s.pellet_xy[0, s.alive[0]], s.xy[0], s.heading[0],
                           s.size[0], ev["eod"][0], ev["bit"][0], ev["bite_target"][0], title)
