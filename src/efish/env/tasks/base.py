"""The contract between the engine and a task (VMAS scenarios are the model).

The engine (:class:`~efish.env.vec_env.VecEnv`) moves bodies, resolves eating
and biting, senses and observes; it knows no task. A task says where agents
start, who must emit or may not bite, which distance its shaping follows, what
each step is worth and when an episode ends. Adding a task is adding a module
in ``env/tasks/`` and one entry in ``TASKS``; the engine does not change.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...config.schema import ArenaConfig, EfishConfig
from ..arenas import spawn_agents
from ..state import EnvState
from .placement import place_roles


@dataclass
class StepEvents:
    """What happened to every agent in one step, float or bool [B, N] each: what rewards are made of."""

    move: np.ndarray            # mapped move command in [0, 1]
    turn: np.ndarray            # mapped turn command in [-1, 1]
    ate: np.ndarray             # ate a pellet
    bit: np.ndarray             # bit another agent
    collided: np.ndarray        # a move was cancelled by another body
    penalty_bitten: np.ndarray  # sum of 1 + s_biter - s_victim over the bites received


class Task:
    """Base task: random or fixed starts, no forced emitters, biting allowed, never terminates.

    Subclasses set ``name`` and ``reward_parts`` (the keys of :meth:`rewards`,
    ``total`` last) and override what differs.
    """

    name = "task"
    reward_parts: tuple[str, ...] = ("total",)
    distance_key = "d_goal_cm"  # info key of the distance the shaping follows

    def __init__(self, cfg: EfishConfig, n_agents: int):
        self.cfg, self.n = cfg, n_agents
        self.forced_eod = np.zeros(n_agents, bool)  # agents that emit every step whatever they choose
        self.bite_allowed = True

    # ---------------------------------------------------------------- reset
    def new_state(self, num_envs: int) -> dict[str, np.ndarray]:
        """The task's own arrays for ``num_envs`` arenas (kept in ``EnvState.task``)."""
        return {}

    def place(self, state: EnvState, b: int, arena: ArenaConfig, rng: np.random.Generator) -> None:
        """Positions and headings of arena ``b`` at reset: ``env.starts`` if given, else by ``env.roles``
        (:mod:`.placement`), else uniform without overlap."""
        starts, r = self.cfg.env.starts, self.cfg.physics.agent_radius_cm
        if self.cfg.env.roles and not starts:
            place_roles(self.cfg, self.cfg.env.roles, state, b, arena, rng)
            return
        if starts:
            starts = np.asarray(starts, dtype=float)
            if np.any(starts[:, :2] < r) or np.any(starts[:, :2] > [arena.width_cm - r, arena.height_cm - r]):
                raise ValueError(f"env.starts has a position outside the {arena.width_cm:g} x {arena.height_cm:g} cm "
                                 f"arena (less than {r:g} cm from a wall)")
            state.xy[b], state.heading[b] = starts[:, :2], starts[:, 2]
        else:
            state.xy[b] = spawn_agents(self.n, arena.width_cm, arena.height_cm, arena.wall_margin_cm, r, rng)
            state.heading[b] = rng.uniform(-np.pi, np.pi, self.n)

    def reset_arena(self, state: EnvState, b: int) -> None:
        """Clear the task's arrays of arena ``b`` at its reset."""
        for value in state.task.values():
            value[b] = 0

    # ----------------------------------------------------------------- step
    def goal_distance(self, state: EnvState, out: np.ndarray) -> None:
        """Write the distance (cm) the shaping reward follows into ``out`` [B, N]."""
        out[:] = np.nan

    def rewards(self, state: EnvState, events: StepEvents, d_prev: np.ndarray) -> dict[str, np.ndarray]:
        """Reward components [B, N] of one step, ``total`` their sum."""
        return {"total": np.zeros_like(d_prev)}

    def terminated(self, state: EnvState) -> np.ndarray:
        """bool[B]: arenas whose episode ends by the task's rule (the time limit is the engine's)."""
        return np.zeros(state.t.shape[0], bool)

    def success(self, state: EnvState) -> np.ndarray:
        """bool[B]: arenas whose goal is reached now; by default the task ends episodes only on success."""
        return self.terminated(state)
