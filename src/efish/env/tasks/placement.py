"""Starts that depend on other bodies: where each agent begins an episode, by role (docs/methods/assays.md).

``env.roles`` gives each agent a role; tasks place their agents through
:func:`place_roles` (the homing task has its own constrained starts). Roles:

- ``random``: uniform in the arena with the wall margin, not overlapping the agents placed before it;
- ``resident``: at the arena centre (where the one-patch layouts put the patch), heading U(-pi, pi);
- ``intruder``: ``env.intruder_distance_cm`` (uniform in [min, max]) from the resident, or from the
  centre when there is none, inside the arena, facing it;
- ``approach``: one of ``env.approach_distances_cm`` from the arena centre, facing it.

Every draw comes from the arena's generator, in agent order.
"""

from __future__ import annotations

import numpy as np

from ...config.schema import ArenaConfig, EfishConfig
from ..arenas import spawn_agents
from ..state import EnvState

ROLES = ("random", "resident", "intruder", "approach")


def place_roles(cfg: EfishConfig, roles: list[str], state: EnvState, b: int, arena: ArenaConfig,
                rng: np.random.Generator) -> None:
    """Positions and headings of arena ``b``'s agents from their ``roles``."""
    e, r = cfg.env, cfg.physics.agent_radius_cm
    w, h = arena.width_cm, arena.height_cm
    centre = np.array([w, h]) / 2
    anchor = centre
    for i, role in enumerate(roles):
        if role == "resident":
            xy, heading = centre.copy(), rng.uniform(-np.pi, np.pi)
            anchor = xy
        elif role == "intruder":
            xy = point_at_distance(anchor, *e.intruder_distance_cm, w, h, arena.wall_margin_cm, rng)
            heading = facing(xy, anchor)
        elif role == "approach":
            d = float(rng.choice(e.approach_distances_cm))
            xy = point_at_distance(centre, d, d, w, h, arena.wall_margin_cm, rng)
            heading = facing(xy, centre)
        else:
            xy = spawn_agents(i + 1, w, h, arena.wall_margin_cm, r, rng, first=state.xy[b, :i])[-1]
            heading = rng.uniform(-np.pi, np.pi)
        state.xy[b, i], state.heading[b, i] = xy, heading


def point_at_distance(anchor: np.ndarray, lo: float, hi: float, width: float, height: float, margin: float,
                      rng: np.random.Generator, tries: int = 10_000) -> np.ndarray:
    """A point at a distance U(lo, hi) from ``anchor`` in a uniform direction, inside the arena's margin."""
    for _ in range(tries):
        d, angle = rng.uniform(lo, hi), rng.uniform(-np.pi, np.pi)
        p = anchor + d * np.array([np.cos(angle), np.sin(angle)])
        if margin <= p[0] <= width - margin and margin <= p[1] <= height - margin:
            return p
    raise ValueError(f"no point {lo:g}-{hi:g} cm from ({anchor[0]:g}, {anchor[1]:g}) lies inside the "
                     f"{width:g} x {height:g} cm arena")


def facing(xy: np.ndarray, target: np.ndarray) -> float:
    """The heading (rad) from ``xy`` towards ``target``."""
    return float(np.arctan2(target[1] - xy[1], target[0] - xy[0]))
