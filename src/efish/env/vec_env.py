"""``VecEnv``: B arenas stepped in one call (docs/architecture.md#environment-api).

The engine: bodies move, eat and bite (numba kernels in :mod:`efish.env.dynamics`),
sense (:mod:`efish.sensors.sense`) and observe (:mod:`efish.env.observe`). It
knows no task: placement at reset, rewards and termination come from the task
of ``env.task`` (:mod:`efish.env.tasks`). All that changes during episodes is
one :class:`~efish.env.state.EnvState`. One seed fixes food, spawn, sizes and
noise: the root seed spawns one generator per arena (food, spawn, sizes) and
one for sensor noise and pellet drift.

    >>> from efish.config import compose
    >>> env = VecEnv(compose(["env.episode_steps=5"]), num_envs=2, seed=0)
    >>> obs = env.reset()
    >>> obs.shape
    (2, 4, 110)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..config.schema import EfishConfig
from ..physics.geometry import mormyromast_angles
from ..physics.plan import Scene, build_plan
from ..physics.snapshot import SnapshotBatch
from ..sensors.encode import encode_readings
from ..sensors.noise import noise_uniforms
from ..sensors.sense import raw_readings
from . import dynamics as dyn
from .arenas import drift_orientations, regrow_onepatch, sample_arena, sample_pellets
from .bot import bot_actions
from .observe import TAIL_SIZES, perception_width, tail_kernel
from .raycast import cast_rays
from .state import EnvState
from .tasks import StepEvents, Task, make_task


def scene_of(cfg: EfishConfig, task: Task | None = None) -> Scene:
    """What the fields of this env's episodes can hold: its agents, whether any may emit, whether food exists."""
    task = task or make_task(cfg)
    may_emit = ~np.isin(np.arange(task.n), cfg.env.muted) | task.forced_eod
    return Scene(agents=task.n, emitters=bool(may_emit.any()), pellets=cfg.arena.layout != "none")


class VecEnv:
    """B environments with N agents each, stepped together.

    ``seed`` fixes every random draw. A sequence of K seeds makes K *members*
    of ``num_envs`` arenas each (B = K x num_envs, member k's arenas
    ``k * num_envs`` ...): member k's arenas, their food, spawns, sizes, sensor
    noise and pellet drift are drawn exactly as ``VecEnv(cfg, num_envs,
    seed=seeds[k])`` draws them, so under the same actions each member steps
    as it would alone, whatever the other members do. So several policies
    (seeds of a recipe, on the same seeds' episodes) act in one env call, whose
    cost per step is mostly fixed.

    ``reset() -> obs float32[B, N, D]``; ``step(actions float[B, N, 4])`` with
    actions (a_move, a_turn, eod, bite): a_move and a_turn are raw Gaussian
    samples mapped by sigmoid and tanh, eod and bite are 0/1. Returns
    ``obs, reward[B, N], terminated[B], truncated[B], info``. Arenas that end
    are reset in the same call; their last observation is in ``info["final_obs"]``
    (with ``autoreset=False`` they are left as they ended, for recording).
    ``reference=True`` senses through the brute-force physics oracle
    (benchmarks and tests only, never training). The state is ``env.state``.
    """

    def __init__(self, cfg: EfishConfig, num_envs: int, seed: int | Sequence[int], autoreset: bool = True,
                 reference: bool = False):
        if num_envs < 1:
            raise ValueError(f"num_envs must be >= 1, got {num_envs}")
        seeds = [int(seed)] if np.ndim(seed) == 0 else [int(s) for s in seed]
        if not seeds:
            raise ValueError("seed must be a seed or a non-empty sequence of seeds")
        self.members, self.member_envs = len(seeds), int(num_envs)
        self.cfg, self.num_envs, self.n = cfg, len(seeds) * int(num_envs), cfg.env.n_agents
        self.autoreset, self.reference = autoreset, reference
        self.task = make_task(cfg)
        self.plan = build_plan(cfg, scene_of(cfg, self.task))
        e = cfg.env
        self.params = dyn.body_params(e, cfg.physics.agent_radius_cm)
        self.muted = np.isin(np.arange(self.n), e.muted)
        self.frozen = np.isin(np.arange(self.n), e.frozen)
        self.bots = np.isin(np.arange(self.n), e.bots)
        self.no_bite = self.bots | (not self.task.bite_allowed)
        self.ray_angles = mormyromast_angles(cfg.sensors.mormyromast)[: cfg.sensors.ray_count]
        self.perception_width = perception_width(cfg)
        # each member: its root seed spawns one generator per arena and one for its noise and drift
        children = [np.random.SeedSequence(s).spawn(self.member_envs + 1) for s in seeds]
        self.state = EnvState.empty(self.num_envs, self.n, cfg.arena,
                                    [np.random.default_rng(c) for member in children for c in member[:-1]],
                                    [np.random.default_rng(member[-1]) for member in children])
        self.state.task = self.task.new_state(self.num_envs)
        self._noise_u = None  # scratch for the noise draws, reused every step
        self._refresh_caches()

    # ------------------------------------------------------------------- API
    def reset(self) -> np.ndarray:
        """Start a new episode in every arena; observations float32[B, N, D]."""
        for b in range(self.num_envs):
            self._reset_arena(b)
        self._refresh_caches()
        self.task.goal_distance(self.state, self.state.goal_dist)
        return self._observe(self._forced_eod())

    def step(self, actions: np.ndarray):
        """Advance every arena by one step (docs/model/environment.md#step-order). See the class docstring."""
        actions = np.asarray(actions, dtype=np.float64)
        if actions.shape != (self.num_envs, self.n, 4):
            raise ValueError(f"actions must have shape ({self.num_envs}, {self.n}, 4), got {actions.shape}")
        s, shape = self.state, (self.num_envs, self.n)
        move, turn = np.empty(shape), np.empty(shape)  # kernel-filled
        eod, bite, no_eating = np.empty(shape, bool), np.empty(shape, bool), np.empty(shape, bool)
        if not dyn.map_actions(actions, self.bots, self.muted, self.task.forced_eod, self.no_bite, move, turn, eod,
                               bite, no_eating):
            raise ValueError("actions contain NaN or infinite values")
        # 1. food dynamics
        self._food_dynamics()
        # 2. map actions (above; bots override theirs), eat, move
        if self.bots.any():
            self._drive_bots(move, turn, eod)
        old_xy = s.xy.copy()
        ate, collided, can_bite = np.empty(shape, bool), np.empty(shape, bool), np.empty(shape, bool)  # kernel-filled
        eaten = np.empty(shape, np.int64)
        dyn.eat_and_move(s.xy, s.heading, s.eat_cd, s.bite_cd, move, turn, no_eating, self._v_max, self._w_max,
                         s.pellet_xy, s.alive, s.width, s.height, self.params, ate, collided, can_bite, eaten)
        # 4. bites, simultaneously, on post-move positions (3. sensing happens in _observe)
        bit, bitten_by, penalty = np.empty(shape, bool), np.empty(shape, np.int64), np.empty(shape)  # kernel-filled
        bite_target = np.empty(shape, np.int64)
        dyn.resolve_bites(s.xy, s.heading, s.size, bite, can_bite, s.bite_cd, self.params, bitten_by, bit, penalty,
                          bite_target)
        # 5. rewards
        d_prev = s.goal_dist.copy()
        self.task.goal_distance(s, s.goal_dist)
        rewards = self.task.rewards(s, StepEvents(move=move, turn=turn, ate=ate, bit=bit, collided=collided,
                                                  penalty_bitten=penalty), d_prev)
        # 6. observations
        dyn.record_motion(s.xy, old_xy, s.heading, move, turn, eod, bite, s.displacement, s.last_action)
        s.was_bitten = bitten_by > 0
        info = {"ate": ate, "eaten_slot": eaten, "bit": bit, "bite_target": bite_target,
                "was_bitten": s.was_bitten.copy(), "bitten_by": bitten_by,
                "collided": collided, "eod": eod, "move": move, "turn": turn, "bite": bite,
                "reward_parts": rewards, self.task.distance_key: s.goal_dist.copy()}
        obs = self._observe(eod)
        # 7. time limit: truncation, then same-step reset
        s.t += 1
        truncated = s.t >= self.cfg.env.episode_steps
        terminated = self.task.terminated(s)
        done = truncated | terminated
        if done.any() and self.autoreset:
            info["final_obs"] = obs.copy()
            for b in np.flatnonzero(done):
                self._reset_arena(b)
            self._refresh_caches()
            self.task.goal_distance(s, s.goal_dist)
            # noise for the members with an ended arena only: alone, a member without one would draw none here
            ended = sorted({self.member_of(b) for b in np.flatnonzero(done)})
            obs[done] = self._observe(self._forced_eod(), ended)[done]
        return obs, rewards["total"], terminated, truncated, info

    def v_max(self) -> np.ndarray:
        """Largest step per agent, cm (docs/model/environment.md#actions-and-motion): speed * gain * (1 + size) / fps; 0
        when frozen."""
        e = self.cfg.env
        v = e.speed_m_s * e.speed_gain * (1 + self.state.size) * 100.0 / e.fps
        return np.where(self.frozen, 0.0, v)

    def w_max(self) -> np.ndarray:
        """Largest turn per agent, rad (docs/model/environment.md#actions-and-motion); 0 when frozen."""
        e = self.cfg.env
        return np.where(self.frozen, 0.0, e.turn_rad_s * e.turn_gain * (1 + self.state.size) / e.fps)

    def member_of(self, b: int) -> int:
        """The member whose arena ``b`` is."""
        return b // self.member_envs

    def member_slice(self, k: int) -> slice:
        """Member ``k``'s arenas, along the first axis of every state array."""
        return slice(k * self.member_envs, (k + 1) * self.member_envs)

    def state_dict(self) -> dict:
        """A deep copy of the state (arrays, arenas, generators) for checkpoints."""
        return {"state": self.state.copy()}

    def load_state_dict(self, state: dict) -> None:
        """Restore what :meth:`state_dict` returned."""
        self.state = state["state"].copy()
        self._refresh_caches()

    def snapshot(self, eod: np.ndarray) -> SnapshotBatch:
        """The current state as the sensing input."""
        s = self.state
        return SnapshotBatch(agent_xy=s.xy, agent_heading=s.heading, agent_size=s.size, agent_emitting=eod,
                             pellet_xy=s.pellet_xy, pellet_orientation=s.pellet_phi, pellet_alive=s.alive,
                             width=s.width, height=s.height)

    # --------------------------------------------------------------- helpers
    def _forced_eod(self) -> np.ndarray:
        """bool[B, N]: who emits on a step without actions (a reset): the task's forced emitters."""
        return np.zeros((self.num_envs, self.n), bool) | self.task.forced_eod

    def _reset_arena(self, b: int) -> None:
        s, e = self.state, self.cfg.env
        rng = s.rngs[b]
        arena = sample_arena(self.cfg.arena, rng)
        s.arena[b] = arena
        s.width[b], s.height[b] = arena.width_cm, arena.height_cm
        pellets = sample_pellets(arena, rng)
        cap = len(pellets) + (arena.onepatch_cap if arena.layout == "onepatch" else 0)
        s.grow_pellets(max(cap, 1), self.member_of(b))
        s.alive[b] = False
        s.pellet_xy[b, : len(pellets)] = pellets
        s.pellet_phi[b, : len(pellets)] = rng.uniform(0, 2 * np.pi, len(pellets))
        s.alive[b, : len(pellets)] = True
        self.task.place(s, b, arena, rng)
        s.size[b] = e.sizes if e.sizes else rng.uniform(0, 1, self.n)
        s.eat_cd[b] = s.bite_cd[b] = 0
        s.last_action[b] = 0.0
        s.was_bitten[b] = False
        s.displacement[b] = 0.0
        self.task.reset_arena(s, b)
        s.t[b] = 0

    def _refresh_caches(self) -> None:
        """Rebuild what only changes at resets: speed limits (sizes) and the food dynamics of each arena."""
        self._v_max, self._w_max = self.v_max(), self.w_max()
        self._drift_sd = np.array([a.orientation_drift_rad for a in self.state.arena])[:, None]
        self._regrowing = [b for b, a in enumerate(self.state.arena) if a.layout == "onepatch"]

    def _food_dynamics(self) -> None:
        """Orientation drift of every pellet (one draw per member, over the pellet slots it has needed), then
        one-patch regrowth."""
        s = self.state
        for k in range(self.members):
            rows, cap = self.member_slice(k), s.capacity[k]
            s.pellet_phi[rows, :cap] = drift_orientations(s.pellet_phi[rows, :cap], self._drift_sd[rows],
                                                          s.noise_rngs[k])
        n_alive = s.alive.sum(axis=1) if self._regrowing else None  # one count for the batch, not one per arena
        for b in self._regrowing:
            arena, rng = s.arena[b], s.rngs[b]
            new = regrow_onepatch(arena, int(n_alive[b]), rng)
            if len(new):
                free = np.flatnonzero(~s.alive[b])[: len(new)]
                s.pellet_xy[b, free] = new[: len(free)]
                s.pellet_phi[b, free] = rng.uniform(0, 2 * np.pi, len(free))
                s.alive[b, free] = True

    def _drive_bots(self, move: np.ndarray, turn: np.ndarray, eod: np.ndarray) -> None:
        s, e, ids, w_max = self.state, self.cfg.env, np.flatnonzero(self.bots), self._w_max
        forced = self.task.forced_eod[ids]
        for b in range(self.num_envs):
            centre = np.array([s.width[b], s.height[b]]) / 2
            m, t, f = bot_actions(s.xy[b, ids], s.heading[b, ids], w_max[b, ids], centre, e.bot_radius_cm,
                                  e.bot_eod_rate, s.rngs[b])
            move[b, ids], turn[b, ids], eod[b, ids] = m, t, (f & ~self.muted[ids]) | forced

    def _perceive(self, eod: np.ndarray, out: np.ndarray, members: Sequence[int] | None = None) -> None:
        """Write the sensory part of the observation into ``out[..., :perception_width]``: receptors or rays; the
        sensor noise is drawn for ``members`` (all by default), and the others' rows are not to be used."""
        s = self.state
        if self.cfg.sensors.perception == "raycast":
            shape = (self.num_envs, self.n, len(self.ray_angles))
            prox, kind = np.zeros(shape), np.zeros(shape)
            cast_rays(s.xy, s.heading, s.pellet_xy, s.alive, s.width, s.height, self.ray_angles,
                      self.cfg.sensors.ray_length_cm, self.cfg.physics.agent_radius_cm,
                      self.cfg.physics.pellet_radius_cm, prox, kind)
            out[..., : shape[2]], out[..., shape[2]: 2 * shape[2]] = prox, kind
            return
        raw = raw_readings(self.snapshot(eod), self.plan, reference=self.reference)
        if self.plan.noise:
            rngs = [rng if members is None or k in members else None for k, rng in enumerate(s.noise_rngs)]
            self._noise_u = noise_uniforms(raw, rngs, out=self._noise_u)
        encode_readings(raw, self._noise_u if self.plan.noise else None, eod & self.plan.on("eod_emission"),
                        s.size, self.plan, self.cfg.env.obs_agents - 1, out)

    def _observe(self, eod: np.ndarray, members: Sequence[int] | None = None) -> np.ndarray:
        """Observations float32[B, N, D] (docs/model/environment.md#observation): perception, then the tail, written
        into one fresh array; valid for the arenas of ``members`` (all by default)."""
        e, p, s = self.cfg.env, self.perception_width, self.state
        obs = np.empty((self.num_envs, self.n, p + sum(TAIL_SIZES)), np.float32)
        self._perceive(eod, obs, members)
        tail_kernel(s.last_action, s.was_bitten, s.size, s.bite_cd, s.eat_cd, s.displacement,
                    self._v_max, e.eat_cooldown, e.bite_cooldown, obs, p)
        return obs
