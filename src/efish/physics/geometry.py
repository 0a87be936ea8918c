"""Where the sensors sit on the body (docs/model/sensors.md): angles from the heading, radians; the conspecific slot
order."""

from __future__ import annotations

import numpy as np

from .._jit import njit
from ..config.schema import AmpullaryConfig, KnollenorganConfig, MormyromastConfig


def mormyromast_angles(cfg: MormyromastConfig) -> np.ndarray:
    """Chin arc of ``chin_count`` sensors over +-half angle, the rest evenly over the body.

    With the defaults: 10 sensors at linspace(-30, 30, 10) degrees, then 26 at
    30 + k * 300/27 degrees for k = 1..26, so neither chin end is repeated.

    >>> a = np.degrees(mormyromast_angles(MormyromastConfig()))
    >>> print(len(a), f"{a[0]:.1f} {a[9]:.1f} {a[10]:.3f}")
    36 -30.0 30.0 41.111
    """
    half = cfg.chin_half_angle_deg
    chin = np.linspace(-half, half, cfg.chin_count) if cfg.chin_count > 1 else np.zeros(cfg.chin_count)
    rest = cfg.count - cfg.chin_count
    span = 360.0 - 2.0 * half
    body = half + np.arange(1, rest + 1) * span / (rest + 1)
    return np.radians(np.concatenate([chin, body]))


def even_angles(count: int) -> np.ndarray:
    """``count`` angles evenly spaced from 0 (the heading), radians."""
    return np.arange(count) * (2.0 * np.pi / count)


def ampullary_angles(cfg: AmpullaryConfig) -> np.ndarray:
    """24 sensors at 0, 15, ..., 345 degrees by default."""
    return even_angles(cfg.count)


def knollenorgan_angles(cfg: KnollenorganConfig) -> np.ndarray:
    """12 sensors at 0, 30, ..., 330 degrees by default."""
    return even_angles(cfg.count)


def sensor_frame(xy: np.ndarray, heading: np.ndarray, angles: np.ndarray, radius: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Sensor positions and outward normals for bodies at ``xy`` (..., 2) with ``heading`` (...).

    Returns positions (..., S, 2) in the units of ``xy``/``radius`` and unit normals (..., S, 2).
    """
    world = heading[..., None] + angles
    normals = np.stack([np.cos(world), np.sin(world)], axis=-1)
    return xy[..., None, :] + radius * normals, normals


@njit(cache=True)
def slot_agent(agent: int, slot: int) -> int:
    """The agent heard in conspecific ``slot`` of ``agent``: the other agents in id order, ``agent`` skipped.

    The one definition of the slot order (docs/model/sensors.md#knollenorgans) for Knollenorgans, their
    size channels and the critic's agent-centric state.
    """
    return slot if slot < agent else slot + 1


def conspecific_slots(n: int) -> np.ndarray:
    """int64[n, n - 1]: row a lists the agents in a's conspecific slots (:func:`slot_agent`).

    >>> conspecific_slots(3).tolist()
    [[1, 2], [0, 2], [0, 1]]
    """
    return np.array([[slot_agent(a, j) for j in range(n - 1)] for a in range(n)], dtype=np.int64).reshape(n, n - 1)
