"""What the field computation needs to know about an arena at one instant.

:class:`Snapshot` is one arena, validated at construction (the user-facing
boundary). :class:`SnapshotBatch` is the struct-of-arrays form the kernels and
the vector env use: B arenas with the same number of agents, pellets padded to
a common count and masked by ``pellet_alive``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config.schema import ArenaConfig

_ARENA = ArenaConfig()  # the default arena size is the schema's (arena.width_cm, height_cm)


def _float_array(name: str, value, shape_tail: tuple[int, ...], ndim: int) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if a.ndim != ndim or a.shape[1:] != shape_tail:
        want = "(n" + "".join(f", {s}" for s in shape_tail) + ")"
        raise ValueError(f"{name} must have shape {want}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return a


@dataclass(frozen=True)
class Snapshot:
    """One arena at one instant. Lengths in cm, angles in radians.

    agent_xy: float64[N, 2]  # cm, inside [0, width] x [0, height]
    agent_heading: float64[N]  # rad, body +x
    agent_size: float64[N]  # in [0, 1]
    agent_emitting: bool[N]  # EOD this step
    pellet_xy: float64[P, 2]  # cm
    pellet_orientation: float64[P]  # rad
    width, height: float  # cm, > 0

    >>> s = Snapshot(agent_xy=[[10, 10]], agent_heading=[0], agent_size=[0.5],
    ...              agent_emitting=[True], pellet_xy=[[14, 10]], pellet_orientation=[0],
    ...              width=70, height=70)
    >>> s.n_agents, s.n_pellets
    (1, 1)
    """

    agent_xy: np.ndarray
    agent_heading: np.ndarray
    agent_size: np.ndarray
    agent_emitting: np.ndarray
    pellet_xy: np.ndarray = None
    pellet_orientation: np.ndarray = None
    width: float = _ARENA.width_cm
    height: float = _ARENA.height_cm

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        xy = _float_array("agent_xy", self.agent_xy, (2,), 2)
        n = xy.shape[0]
        if n < 1:
            raise ValueError("agent_xy must hold at least one agent")
        set_(self, "agent_xy", xy)
        for name in ("agent_heading", "agent_size"):
            a = _float_array(name, getattr(self, name), (), 1)
            if a.shape != (n,):
                raise ValueError(f"{name} must have shape ({n},) to match agent_xy, got {a.shape}")
            set_(self, name, a)
        if np.any((self.agent_size < 0) | (self.agent_size > 1)):
            raise ValueError("agent_size must lie in [0, 1]")
        emitting = np.asarray(self.agent_emitting)
        if emitting.shape != (n,):
            raise ValueError(f"agent_emitting must have shape ({n},) to match agent_xy, got {emitting.shape}")
        if emitting.dtype != bool and not np.all(np.isin(emitting, (0, 1))):
            raise ValueError("agent_emitting must hold booleans (or 0/1)")
        set_(self, "agent_emitting", emitting.astype(bool))
        pxy = np.zeros((0, 2)) if self.pellet_xy is None else self.pellet_xy
        pxy = _float_array("pellet_xy", np.reshape(pxy, (-1, 2)) if np.size(pxy) == 0 else pxy, (2,), 2)
        set_(self, "pellet_xy", pxy)
        phi = np.zeros(pxy.shape[0]) if self.pellet_orientation is None else self.pellet_orientation
        phi = _float_array("pellet_orientation", phi, (), 1)
        if phi.shape != (pxy.shape[0],):
            raise ValueError(f"pellet_orientation must have shape ({pxy.shape[0]},) to match pellet_xy, got {phi.shape}")
        set_(self, "pellet_orientation", phi)
        for name in ("width", "height"):
            v = float(getattr(self, name))
            if not np.isfinite(v) or v <= 0:
                raise ValueError(f"{name} must be a positive finite length in cm, got {getattr(self, name)}")
            set_(self, name, v)
        _check_inside("agent_xy", xy, self.width, self.height)
        _check_inside("pellet_xy", pxy, self.width, self.height)

    @property
    def n_agents(self) -> int:
        return self.agent_xy.shape[0]

    @property
    def n_pellets(self) -> int:
        return self.pellet_xy.shape[0]

    def as_batch(self) -> "SnapshotBatch":
        """This snapshot as a batch of one."""
        return SnapshotBatch(
            agent_xy=self.agent_xy[None], agent_heading=self.agent_heading[None],
            agent_size=self.agent_size[None], agent_emitting=self.agent_emitting[None],
            pellet_xy=self.pellet_xy[None], pellet_orientation=self.pellet_orientation[None],
            pellet_alive=np.ones((1, self.n_pellets), dtype=bool),
            width=np.array([self.width]), height=np.array([self.height]))


def _check_inside(name: str, xy: np.ndarray, width: float, height: float) -> None:
    if xy.size and (np.any(xy < 0) or np.any(xy[:, 0] > width) or np.any(xy[:, 1] > height)):
        raise ValueError(f"{name} has positions outside the arena [0, {width:g}] x [0, {height:g}] cm")


@dataclass
class SnapshotBatch:
    """B arenas as struct-of-arrays; the form the kernels consume.

    agent_xy: float64[B, N, 2]  # cm
    agent_heading: float64[B, N]  # rad
    agent_size: float64[B, N]  # [0, 1]
    agent_emitting: bool[B, N]
    pellet_xy: float64[B, P, 2]  # cm, padded
    pellet_orientation: float64[B, P]  # rad
    pellet_alive: bool[B, P]  # False for padding and eaten pellets
    width, height: float64[B]  # cm
    """

    agent_xy: np.ndarray
    agent_heading: np.ndarray
    agent_size: np.ndarray
    agent_emitting: np.ndarray
    pellet_xy: np.ndarray
    pellet_orientation: np.ndarray
    pellet_alive: np.ndarray
    width: np.ndarray
    height: np.ndarray

    @property
    def shape(self) -> tuple[int, int, int]:
        """(B, N, P)."""
        return self.agent_xy.shape[0], self.agent_xy.shape[1], self.pellet_xy.shape[1]

    @classmethod
    def stack(cls, snapshots: list[Snapshot]) -> "SnapshotBatch":
        """Stack snapshots with equal agent counts, padding pellets."""
        n = {s.n_agents for s in snapshots}
        if len(n) != 1:
            raise ValueError(f"snapshots in a batch need the same number of agents, got {sorted(n)}")
        b, p = len(snapshots), max(s.n_pellets for s in snapshots)
        pxy, phi, alive = np.zeros((b, p, 2)), np.zeros((b, p)), np.zeros((b, p), dtype=bool)
        for i, s in enumerate(snapshots):
            pxy[i, :s.n_pellets], phi[i, :s.n_pellets], alive[i, :s.n_pellets] = s.pellet_xy, s.pellet_orientation, True
        return cls(
            agent_xy=np.stack([s.agent_xy for s in snapshots]),
            agent_heading=np.stack([s.agent_heading for s in snapshots]),
            agent_size=np.stack([s.agent_size for s in snapshots]),
            agent_emitting=np.stack([s.agent_emitting for s in snapshots]),
            pellet_xy=pxy, pellet_orientation=phi, pellet_alive=alive,
            width=np.array([s.width for s in snapshots]), height=np.array([s.height for s in snapshots]))

    def select(self, index) -> "SnapshotBatch":
        """A sub-batch (numpy index or slice over B)."""
        return SnapshotBatch(**{k: np.asarray(v)[index] for k, v in self.__dict__.items()})
