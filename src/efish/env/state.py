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
    noise_rngs: list[np.random.Generator]  # [K], sensor noise and pellet drift of each member's B / K arenas
    capacity: np.ndarray      # int64[K], the pellet slots each member's arenas have needed (its drift draws)
    task: dict[str, np.ndarray] = field(default_factory=dict)  # the task's own arrays, leading dims (B, N)

    @classmethod
    def empty(cls, b: int, n: int, arena: ArenaConfig, rngs: list[np.random.Generator],
              noise_rngs: list[np.random.Generator]) -> "EnvState":
        """Zeroed state for ``b`` arenas of ``n`` agents with room for one pellet per arena, in ``len(noise_rngs)``
        members of equal size (:class:`~efish.env.vec_env.VecEnv`)."""
        return cls(xy=np.zeros((b, n, 2)), heading=np.zeros((b, n)), size=np.zeros((b, n)),
                   eat_cd=np.zeros((b, n), np.int64), bite_cd=np.zeros((b, n), np.int64),
                   last_action=np.zeros((b, n, 4)), was_bitten=np.zeros((b, n), bool),
                   displacement=np.zeros((b, n, 2)), goal_dist=np.full((b, n), np.nan),
                   width=np.zeros(b), height=np.zeros(b), t=np.zeros(b, np.int64),
                   pellet_xy=np.zeros((b, 1, 2)), pellet_phi=np.zeros((b, 1)), alive=np.zeros((b, 1), bool),
                   arena=[arena] * b, rngs=rngs, noise_rngs=list(noise_rngs),
                   capacity=np.ones(len(noise_rngs), np.int64))

    def grow_pellets(self, capacity: int, member: int = 0) -> None:
        """Make room for ``capacity`` pellets per arena, keeping the current ones; ``member`` (whose arena needs
        them) records it in its ``capacity``, which its drift draws cover whatever the other members need."""
        self.capacity[member] = max(self.capacity[member], capacity)
        b, k = self.alive.shape
        if capacity <= k:
            return
        xy, phi, alive = np.zeros((b, capacity, 2)), np.zeros((b, capacity)), np.zeros((b, capacity), bool)
        xy[:, :k], phi[:, :k], alive[:, :k] = self.pellet_xy, self.pellet_phi, self.alive
        self.pellet_xy, self.pellet_phi, self.alive = xy, phi, alive

    def __setstate__(self, state: dict) -> None:
        """Unpickle, reading a state saved before members (one batch-wide ``noise_rng``) as one member."""
        if "noise_rng" in state:
            state["noise_rngs"] = [state.pop("noise_rng")]
            state["capacity"] = np.array([state["alive"].shape[1]], np.int64)
        self.__dict__.update(state)

    def copy(self) -> "EnvState":
        """A deep copy (arrays, arenas and generators), for checkpoints."""
        return copy.deepcopy(self)
