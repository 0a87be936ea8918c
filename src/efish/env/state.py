"""The mutable state of a :class:`~efish.env.vec_env.VecEnv`: one dataclass of arrays, shapes written down.

Leading dimensions are (B arenas, N agents) or (B, P pellet slots). Everything
here changes during episodes and is what ``VecEnv.state_dict`` saves; what the
config fixes (speed limits of sizes, the plan, reward weights) is derived from
it, never saved. A new field is checkpointed because it is declared here.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numpy as np

from ..config.schema import ArenaConfig


@dataclass
class EnvState:
    """Bodies, food, clocks and generators of B arenas."""

    xy: np.ndarray            # float64[B, N, 2], cm
    heading: np.ndarray       # float64[B, N], rad
    size: np.ndarray          # float64[B, N], in [0, 1]
    eat_cd: np.ndarray        # int64[B, N], steps of eat cooldown left
    bite_cd: np.ndarray       # int64[B, N], steps of bite cooldown left
    last_action: np.ndarray   # float64[B, N, 4], move, turn, eod, bite after mapping
    was_bitten: np.ndarray    # bool[B, N], bitten in the last step
    displacement: np.ndarray  # float64[B, N, 2], last step in the body frame (forward, left), cm
    goal_dist: np.ndarray     # float64[B, N], cm to what the task's shaping follows (nearest pellet, target)
    width: np.ndarray         # float64[B], cm
    height: np.ndarray        # float64[B], cm
    t: np.ndarray             # int64[B], steps since the arena's reset
    pellet_xy: np.ndarray     # float64[B, P, 2], cm (P grows as needed)
    pellet_phi: np.ndarray    # float64[B, P], rad
    alive: np.ndarray         # bool[B, P], False for eaten pellets and padding
    arena: list[ArenaConfig]  # [B], each arena's episode config (training samples one per episode)
    rngs: list[np.random.Generator]  # [B], food, spawn and sizes of each arena
    noise_rng: np.random.Generator   # sensor noise and pellet drift of the whole batch
    task: dict[str, np.ndarray] = field(default_factory=dict)  # the task's own arrays, leading dims (B, N)

    @classmethod
    def empty(cls, b: int, n: int, arena: ArenaConfig, rngs: list[np.random.Generator],
              noise_rng: np.random.Generator) -> "EnvState":
        """Zeroed state for ``b`` arenas of ``n`` agents with room for one pellet per arena."""
        return cls(xy=np.zeros((b, n, 2)), heading=np.zeros((b, n)), size=np.zeros((b, n)),
                   eat_cd=np.zeros((b, n), np.int64), bite_cd=np.zeros((b, n), np.int64),
                   last_action=np.zeros((b, n, 4)), was_bitten=np.zeros((b, n), bool),
                   displacement=np.zeros((b, n, 2)), goal_dist=np.full((b, n), np.nan),
                   width=np.zeros(b), height=np.zeros(b), t=np.zeros(b, np.int64),
                   pellet_xy=np.zeros((b, 1, 2)), pellet_phi=np.zeros((b, 1)), alive=np.zeros((b, 1), bool),
                   arena=[arena] * b, rngs=rngs, noise_rng=noise_rng)

    def grow_pellets(self, capacity: int) -> None:
        """Make room for ``capacity`` pellets per arena, keeping the current ones."""
        b, k = self.alive.shape
        if capacity <= k:
            return
        xy, phi, alive = np.zeros((b, capacity, 2)), np.zeros((b, capacity)), np.zeros((b, capacity), bool)
        xy[:, :k], phi[:, :k], alive[:, :k] = self.pellet_xy, self.pellet_phi, self.alive
        self.pellet_xy, self.pellet_phi, self.alive = xy, phi, alive

    def copy(self) -> "EnvState":
        """A deep copy (arrays, arenas and generators), for checkpoints."""
        return copy.deepcopy(self)
