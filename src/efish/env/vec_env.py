"""``VecEnv``: B foraging arenas stepped in one call (DESIGN "Environment API").

State is struct-of-arrays with (env, agent) leading dimensions; the body
kernels are in :mod:`efish.env.dynamics`, sensing in :mod:`efish.sensing`.
One seed fixes food, spawn, sizes and noise: the root seed spawns one
generator per arena (food, spawn, sizes) and one for sensor noise.

    >>> from efish.config import compose
    >>> env = VecEnv(compose(["env.episode_steps=5"]), num_envs=2, seed=0)
    >>> obs = env.reset()
    >>> obs.shape
    (2, 4, 110)
"""

from __future__ import annotations

import copy

import numpy as np

from ..config.schema import EfishConfig
from ..physics.plan import build_plan
from ..physics.snapshot import SnapshotBatch
from ..sensing import raw_readings
from ..sensors.encode import electric_width, encode_readings
from ..sensors.layout import mormyromast_angles
from ..sensors.noise import noise_uniforms
from . import dynamics as dyn
from .arenas import drift_orientations, regrow_onepatch, sample_arena, sample_pellets, spawn_agents
from .bot import bot_actions
from .observe import TAIL_SIZES, tail_kernel
from .raycast import cast_rays
from .rewards import foraging_coefficients, foraging_rewards, homing_rewards

# Not part of state_dict: fixed by the config, or caches rebuilt from the state (see _refresh_caches).
_DERIVED = ("cfg", "plan", "params", "muted", "frozen", "bots", "homing", "target", "ray_angles", "autoreset",
            "reference", "reward_coef", "perception_width", "_v_max", "_w_max", "_drift_sd", "_regrowing",
            "_noise_u")


class VecEnv:
    """B foraging environments with N agents each, stepped together.

    ``reset() -> obs float32[B, N, D]``; ``step(actions float[B, N, 4])`` with
    actions (a_move, a_turn, eod, bite): a_move and a_turn are raw Gaussian
    samples mapped by sigmoid and tanh, eod and bite are 0/1. Returns
    ``obs, reward[B, N], terminated[B], truncated[B], info``. Arenas that end
    are reset in the same call; their last observation is in ``info["final_obs"]``
    (with ``autoreset=False`` they are left as they ended, for recording).
    ``reference=True`` senses through the brute-force physics oracle
    (benchmarks and tests only, never training).
    """

    def __init__(self, cfg: EfishConfig, num_envs: int, seed: int, autoreset: bool = True, reference: bool = False):
        if num_envs < 1:
            raise ValueError(f"num_envs must be >= 1, got {num_envs}")
        self.cfg, self.num_envs, self.n = cfg, int(num_envs), cfg.env.n_agents
        self.autoreset, self.reference = autoreset, reference
        root = np.random.SeedSequence(seed)
        children = root.spawn(num_envs + 1)
        self.rngs = [np.random.default_rng(s) for s in children[:-1]]
        self.noise_rng = np.random.default_rng(children[-1])
        self.plan = build_plan(cfg, n_agents=self.n)
        e = cfg.env
        self.params = np.zeros(dyn.N_PARAMS)
        self.params[dyn.EAT_R2], self.params[dyn.BITE_R2] = e.eat_radius_cm ** 2, e.bite_radius_cm ** 2
        self.params[dyn.EAT_COS] = np.cos(np.radians(e.eat_half_angle_deg))
        self.params[dyn.BITE_COS] = np.cos(np.radians(e.bite_half_angle_deg))
        self.params[dyn.MIN_SEP2], self.params[dyn.WALL] = (2 * e.body_radius_cm) ** 2, e.body_radius_cm
        self.params[dyn.EAT_CD], self.params[dyn.BITE_CD] = e.eat_cooldown, e.bite_cooldown
        self.muted = np.isin(np.arange(self.n), e.muted)
        self.frozen = np.isin(np.arange(self.n), e.frozen)
        self.bots = np.isin(np.arange(self.n), e.bots)
        self.homing = e.task == "homing"
        self.target = np.arange(self.n) == e.homing_target if self.homing else np.zeros(self.n, bool)
        self.ray_angles = mormyromast_angles(cfg.sensors.mormyromast)[: cfg.sensors.ray_count]
        self.reward_coef = foraging_coefficients(e)
        self.perception_width = 2 * len(self.ray_angles) if cfg.sensors.perception == "raycast" else electric_width(
            len(self.plan.morm_angles), len(self.plan.amp_angles), len(self.plan.knollen_angles), e.obs_agents - 1)
        self._noise_u = None  # scratch for the noise draws, reused every step
        self._allocate(pellet_capacity=1)
        self._refresh_caches()

    # ------------------------------------------------------------------ state
    def _allocate(self, pellet_capacity: int) -> None:
        b, n = self.num_envs, self.n
        self.xy = np.zeros((b, n, 2))                 # cm
        self.heading = np.zeros((b, n))               # rad
        self.size = np.zeros((b, n))                  # [0, 1]
        self.eat_cd = np.zeros((b, n), np.int64)      # steps left
        self.bite_cd = np.zeros((b, n), np.int64)
        self.last_action = np.zeros((b, n, 4))        # move, turn, eod, bite after mapping
        self.was_bitten = np.zeros((b, n), bool)
        self.displacement = np.zeros((b, n, 2))       # last step, body frame, cm
        self.d_food = np.full((b, n), np.nan)         # cm to the nearest pellet
        self.width, self.height = np.zeros(b), np.zeros(b)
        self.arena = [self.cfg.arena] * b
        self.t = np.zeros(b, np.int64)
        self.home_steps = np.zeros((b, n), np.int64)   # consecutive steps at home (homing)
        self._pellets(pellet_capacity)

    def _pellets(self, capacity: int) -> None:
        b = self.num_envs
        self.pellet_xy = np.zeros((b, capacity, 2))
        self.pellet_phi = np.zeros((b, capacity))
        self.alive = np.zeros((b, capacity), bool)

    def _grow_pellets(self, capacity: int) -> None:
        if capacity <= self.pellet_xy.shape[1]:
            return
        old = (self.pellet_xy, self.pellet_phi, self.alive)
        self._pellets(capacity)
        k = old[0].shape[1]
        self.pellet_xy[:, :k], self.pellet_phi[:, :k], self.alive[:, :k] = old

    def _reset_env(self, b: int) -> None:
        rng, e = self.rngs[b], self.cfg.env
        arena = sample_arena(self.cfg.arena, rng)
        self.arena[b] = arena
        self.width[b], self.height[b] = arena.width_cm, arena.height_cm
        pellets = sample_pellets(arena, rng)
        cap = len(pellets) + (arena.onepatch_cap if arena.layout == "onepatch" else 0)
        self._grow_pellets(max(cap, 1))
        self.alive[b] = False
        self.pellet_xy[b, : len(pellets)] = pellets
        self.pellet_phi[b, : len(pellets)] = rng.uniform(0, 2 * np.pi, len(pellets))
        self.alive[b, : len(pellets)] = True
        if e.starts:
            starts = np.asarray(e.starts, dtype=float)
            r = e.body_radius_cm
            if np.any(starts[:, :2] < r) or np.any(starts[:, :2] > [arena.width_cm - r, arena.height_cm - r]):
                raise ValueError(f"env.starts has a position outside the {arena.width_cm:g} x {arena.height_cm:g} cm "
                                 f"arena (less than {r:g} cm from a wall)")
            self.xy[b], self.heading[b] = starts[:, :2], starts[:, 2]
        else:
            self.xy[b] = spawn_agents(self.n, arena.width_cm, arena.height_cm, arena.wall_margin_cm, rng)
            self.heading[b] = rng.uniform(-np.pi, np.pi, self.n)
        self.size[b] = e.sizes if e.sizes else rng.uniform(0, 1, self.n)
        self.eat_cd[b] = self.bite_cd[b] = 0
        self.last_action[b] = 0.0
        self.was_bitten[b] = False
        self.displacement[b] = 0.0
        self.home_steps[b] = 0
        self.t[b] = 0

    # ------------------------------------------------------------------- API
    def reset(self) -> np.ndarray:
        """Start a new episode in every arena; observations float32[B, N, D]."""
        for b in range(self.num_envs):
            self._reset_env(b)
        self._refresh_caches()
        self._distances(self.d_food)
        return self._observe(np.zeros((self.num_envs, self.n), bool) | self.target)

    def v_max(self) -> np.ndarray:
        """Largest step per agent, cm (SPEC 5): speed * gain * (1 + size) / fps; 0 when frozen."""
        e = self.cfg.env
        v = e.speed_m_s * e.speed_gain * (1 + self.size) * 100.0 / e.fps
        return np.where(self.frozen, 0.0, v)

    def w_max(self) -> np.ndarray:
        """Largest turn per agent, rad (SPEC 5); 0 when frozen."""
        e = self.cfg.env
        return np.where(self.frozen, 0.0, e.turn_rad_s * e.turn_gain * (1 + self.size) / e.fps)

    def step(self, actions: np.ndarray):
        """Advance every arena by one step (SPEC 6). See the class docstring."""
        actions = np.asarray(actions, dtype=np.float64)
        if actions.shape != (self.num_envs, self.n, 4):
            raise ValueError(f"actions must have shape ({self.num_envs}, {self.n}, 4), got {actions.shape}")
        shape = (self.num_envs, self.n)
        move, turn = np.empty(shape), np.empty(shape)  # kernel-filled
        eod, bite, no_eating = np.empty(shape, bool), np.empty(shape, bool), np.empty(shape, bool)
        if not dyn.map_actions(actions, self.bots, self.muted, self.target, self.homing, move, turn, eod, bite,
                               no_eating):
            raise ValueError("actions contain NaN or infinite values")
        e = self.cfg.env
        # 1. food dynamics
        self._food_dynamics()
        # 2. map actions (above; bots override theirs), eat, move
        if self.bots.any():
            self._drive_bots(move, turn, eod)
        old_xy = self.xy.copy()
        ate, collided, can_bite = np.empty(shape, bool), np.empty(shape, bool), np.empty(shape, bool)  # kernel-filled
        dyn.eat_and_move(self.xy, self.heading, self.eat_cd, self.bite_cd, move, turn, no_eating, self._v_max,
                         self._w_max, self.pellet_xy, self.alive, self.width, self.height, self.params,
                         ate, collided, can_bite)
        # 4. bites, simultaneously, on post-move positions (3. sensing happens in _observe)
        bit, bitten_by, penalty = np.empty(shape, bool), np.empty(shape, np.int64), np.empty(shape)  # kernel-filled
        dyn.resolve_bites(self.xy, self.heading, self.size, bite, can_bite, self.bite_cd, self.params,
                          bitten_by, bit, penalty)
        # 5. rewards
        d_prev = self.d_food.copy()
        self._distances(self.d_food)
        if self.homing:
            rewards = homing_rewards(e, d_prev, self.d_food, 2 * (self.width + self.height), self.target)
            at_home = (self.d_food <= e.homing_radius_cm) & ~self.target
            self.home_steps = np.where(at_home, self.home_steps + 1, 0)
        else:
            rewards = foraging_rewards(e, ate, d_prev, self.d_food, self.width, self.height, penalty, bit, collided,
                                       move, turn, self.reward_coef)
        # 6. observations
        dyn.record_motion(self.xy, old_xy, self.heading, move, turn, eod, bite, self.displacement, self.last_action)
        self.was_bitten = bitten_by > 0
        info = {"ate": ate, "bit": bit, "was_bitten": self.was_bitten.copy(), "bitten_by": bitten_by,
                "collided": collided, "eod": eod, "move": move, "turn": turn, "bite": bite,
                "reward_parts": rewards, ("d_target_cm" if self.homing else "d_food_cm"): self.d_food.copy()}
        obs = self._observe(eod)
        # 7. time limit: truncation, then same-step reset
        self.t += 1
        truncated = self.t >= e.episode_steps
        terminated = (self.home_steps >= e.homing_success_steps).any(axis=1) if self.homing \
            else np.zeros(self.num_envs, bool)
        done = truncated | terminated
        if done.any() and self.autoreset:
            info["final_obs"] = obs.copy()
            for b in np.flatnonzero(done):
                self._reset_env(b)
            self._refresh_caches()
            self._distances(self.d_food)
            obs[done] = self._observe(np.zeros((self.num_envs, self.n), bool) | self.target)[done]
        return obs, rewards["total"], terminated, truncated, info

    def state_dict(self) -> dict:
        """A deep copy of the mutable state (arrays, arenas, generators) for checkpoints."""
        return copy.deepcopy({k: v for k, v in self.__dict__.items() if k not in _DERIVED})

    def load_state_dict(self, state: dict) -> None:
        """Restore what :meth:`state_dict` returned."""
        self.__dict__.update(copy.deepcopy(state))
        self._refresh_caches()

    def _refresh_caches(self) -> None:
        """Rebuild what only changes at resets: speed limits (sizes) and the food dynamics of each arena."""
        self._v_max, self._w_max = self.v_max(), self.w_max()
        self._drift_sd = np.array([a.orientation_drift_rad for a in self.arena])[:, None]
        self._regrowing = [b for b, a in enumerate(self.arena) if a.layout == "onepatch"]

    # --------------------------------------------------------------- helpers
    def _food_dynamics(self) -> None:
        """Orientation drift of every pellet (one draw for the batch), then one-patch regrowth."""
        drift_orientations(self.pellet_phi, self._drift_sd, self.noise_rng, out=self.pellet_phi)
        n_alive = self.alive.sum(axis=1) if self._regrowing else None  # one count for the batch, not one per arena
        for b in self._regrowing:
            arena, rng = self.arena[b], self.rngs[b]
            new = regrow_onepatch(arena, int(n_alive[b]), rng)
            if len(new):
                free = np.flatnonzero(~self.alive[b])[: len(new)]
                self.pellet_xy[b, free] = new[: len(free)]
                self.pellet_phi[b, free] = rng.uniform(0, 2 * np.pi, len(free))
                self.alive[b, free] = True

    def snapshot(self, eod: np.ndarray) -> SnapshotBatch:
        """The current state as the sensing input."""
        return SnapshotBatch(agent_xy=self.xy, agent_heading=self.heading, agent_size=self.size,
                             agent_emitting=eod, pellet_xy=self.pellet_xy, pellet_orientation=self.pellet_phi,
                             pellet_alive=self.alive, width=self.width, height=self.height)

    def _distances(self, out: np.ndarray) -> None:
        """Distance driving the shaping reward: nearest pellet (foraging) or the target (homing)."""
        if self.homing:
            out[:] = np.linalg.norm(self.xy - self.xy[:, self.target], axis=-1)
        else:
            dyn.nearest_pellet_distance(self.xy, self.pellet_xy, self.alive, out)

    def _drive_bots(self, move: np.ndarray, turn: np.ndarray, eod: np.ndarray) -> None:
        e, ids, w_max = self.cfg.env, np.flatnonzero(self.bots), self._w_max
        for b in range(self.num_envs):
            centre = np.array([self.width[b], self.height[b]]) / 2
            m, t, f = bot_actions(self.xy[b, ids], self.heading[b, ids], w_max[b, ids], centre, e.bot_radius_cm,
                                  e.bot_eod_rate, self.rngs[b])
            move[b, ids], turn[b, ids], eod[b, ids] = m, t, (f & ~self.muted[ids]) | self.target[ids]

    def _perceive(self, eod: np.ndarray, out: np.ndarray) -> None:
        """Write the sensory part of the observation into ``out[..., :perception_width]``: receptors or rays."""
        if self.cfg.sensors.perception == "raycast":
            shape = (self.num_envs, self.n, len(self.ray_angles))
            prox, kind = np.zeros(shape), np.zeros(shape)
            cast_rays(self.xy, self.heading, self.pellet_xy, self.alive, self.width, self.height, self.ray_angles,
                      self.cfg.sensors.ray_length_cm, self.cfg.env.body_radius_cm, self.cfg.physics.pellet_radius_cm,
                      prox, kind)
            out[..., : shape[2]], out[..., shape[2]: 2 * shape[2]] = prox, kind
            return
        raw = raw_readings(self.snapshot(eod), self.plan, reference=self.reference)
        if self.plan.noise:
            self._noise_u = noise_uniforms(raw, self.noise_rng, out=self._noise_u)
        encode_readings(raw, self._noise_u if self.plan.noise else None, eod & self.plan.on("eod_emission"),
                        self.size, self.plan, self.cfg.env.obs_agents - 1, out)

    def _observe(self, eod: np.ndarray) -> np.ndarray:
        """Observations float32[B, N, D] (SPEC 4): perception, then the tail, written into one fresh array."""
        e, p = self.cfg.env, self.perception_width
        obs = np.empty((self.num_envs, self.n, p + sum(TAIL_SIZES)), np.float32)
        self._perceive(eod, obs)
        tail_kernel(self.last_action, self.was_bitten, self.size, self.bite_cd, self.eat_cd, self.displacement,
                    self._v_max, e.eat_cooldown, e.bite_cooldown, obs, p)
        return obs
