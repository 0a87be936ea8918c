"""Numba kernels of one step of the bodies: eating, motion, bites (docs/model/environment.md#actions-and-motion).

Agents act in id order within an arena (eating and moving are sequential, as
the "per agent" step of docs/model/environment.md#step-order says); bites are
resolved simultaneously after every agent has moved. Pure functions of arrays;
(B, N) leading dimensions.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit

# Indices into the ``p`` parameter array.
EAT_R2, EAT_COS, BITE_R2, BITE_COS, MIN_SEP2, WALL, EAT_CD, BITE_CD, N_PARAMS = range(9)


def body_params(env, body_radius_cm: float) -> np.ndarray:
    """float64[N_PARAMS]: the eat and bite zones, separations and cooldowns the kernels read (``env``: EnvConfig)."""
    p = np.zeros(N_PARAMS)
    p[EAT_R2], p[BITE_R2] = env.eat_radius_cm ** 2, env.bite_radius_cm ** 2
    p[EAT_COS] = np.cos(np.radians(env.eat_half_angle_deg))
    p[BITE_COS] = np.cos(np.radians(env.bite_half_angle_deg))
    p[MIN_SEP2], p[WALL] = (2 * body_radius_cm) ** 2, body_radius_cm
    p[EAT_CD], p[BITE_CD] = env.eat_cooldown, env.bite_cooldown
    return p


@njit(cache=True)
def map_actions(actions, bots, muted, forced_eod, no_bite, move, turn, eod, bite, no_eating):
    """Raw policy outputs to commands for B arenas (docs/model/environment.md#actions-and-motion); returns False if any
    action is not finite.

    ``actions`` float64[B, N, 4] (a_move, a_turn, eod, bite): move = sigmoid(a_move),
    turn = tanh(a_turn), eod = (eod > 0.5) unless muted, always for agents the
    task forces to emit; bite = bite > 0.5, never for agents in ``no_bite``
    (bots, and every agent of a task without biting). Bots enter
    eating as if biting (``no_eating``): they never eat. One pass instead of a
    dozen small numpy calls, which cost more than the work at this size.
    """
    finite = True
    for b in range(actions.shape[0]):
        for i in range(actions.shape[1]):
            a = actions[b, i]
            finite = finite and np.isfinite(a[0]) and np.isfinite(a[1]) and np.isfinite(a[2]) and np.isfinite(a[3])
            move[b, i] = 0.5 * (1.0 + np.tanh(0.5 * a[0]))  # overflow-free logistic
            turn[b, i] = np.tanh(a[1])
            eod[b, i] = (a[2] > 0.5 and not muted[i]) or forced_eod[i]
            bite[b, i] = a[3] > 0.5 and not no_bite[i]
            no_eating[b, i] = bite[b, i] or bots[i]
    return finite


@njit(cache=True)
def in_cone(dx, dy, heading, r2_max, cos_half):
    """Squared distance of (dx, dy) if it lies within the cone (radius, +-half angle) of ``heading``, else inf."""
    d2 = dx * dx + dy * dy
    if d2 > r2_max:
        return np.inf
    if d2 == 0.0:
        return 0.0
    if (dx * np.cos(heading) + dy * np.sin(heading)) < cos_half * np.sqrt(d2):
        return np.inf
    return d2


@njit(cache=True)
def eat_and_move(xy, heading, eat_cd, bite_cd, move, turn, bite, v_max, w_max, pellet_xy, alive,
                 width, height, p, ate, collided, can_bite, eaten):
    """Eating and motion of every agent, in id order, for B arenas (updates arrays in place).

    An agent frozen by its eat cooldown neither eats nor moves. Otherwise, unless
    it bites, it eats the nearest live pellet in its eat zone; then it turns and
    moves; a move that would bring two centres closer than the minimum separation
    is cancelled (the turn is kept) and flags a collision; centres are clipped to
    the walls. Counters count down here; ``can_bite`` reports who may bite and
    ``eaten`` (int64[B, N]) the pellet slot each agent ate, -1 for none.
    """
    b_count, n = xy.shape[0], xy.shape[1]
    for b in range(b_count):
        for i in range(n):
            frozen = eat_cd[b, i] > 0
            can_bite[b, i] = bite_cd[b, i] == 0
            eat_cd[b, i] = max(eat_cd[b, i] - 1, 0)
            bite_cd[b, i] = max(bite_cd[b, i] - 1, 0)
            ate[b, i] = False
            eaten[b, i] = -1
            collided[b, i] = False
            if frozen:
                continue
            if not bite[b, i]:
                best, best_k = np.inf, -1
                for k in range(pellet_xy.shape[1]):
                    if alive[b, k]:
                        d2 = in_cone(pellet_xy[b, k, 0] - xy[b, i, 0], pellet_xy[b, k, 1] - xy[b, i, 1],
                                     heading[b, i], p[EAT_R2], p[EAT_COS])
                        if d2 < best:
                            best, best_k = d2, k
                if best_k >= 0:
                    alive[b, best_k] = False
                    ate[b, i] = True
                    eaten[b, i] = best_k
                    eat_cd[b, i] = int(p[EAT_CD])
            theta = heading[b, i] + turn[b, i] * w_max[b, i]
            theta = (theta + np.pi) % (2 * np.pi) - np.pi  # efish.units.wrap, inline: a numba kernel cannot call it
            heading[b, i] = theta
            step = move[b, i] * v_max[b, i]
            x = min(max(xy[b, i, 0] + step * np.cos(theta), p[WALL]), width[b] - p[WALL])
            y = min(max(xy[b, i, 1] + step * np.sin(theta), p[WALL]), height[b] - p[WALL])
            blocked = False
            for j in range(n):
                if j != i and (x - xy[b, j, 0]) ** 2 + (y - xy[b, j, 1]) ** 2 < p[MIN_SEP2]:
                    blocked = True
            if blocked:
                collided[b, i] = step > 0
            else:
                xy[b, i, 0], xy[b, i, 1] = x, y


@njit(cache=True)
def resolve_bites(xy, heading, size, bite, can_bite, bite_cd, p, bitten_by, bit, penalty_bitten, target):
    """Simultaneous bites after motion: each willing, able agent bites the nearest agent in its bite zone.

    Writes ``bit`` (bool[B, N]), ``target`` (int64[B, N], the victim of each
    biter, -1 for none), ``bitten_by`` (int[B, N], how many bites each
    received) and ``penalty_bitten`` (float[B, N], sum of 1 + s_biter - s_victim).
    """
    b_count, n = xy.shape[0], xy.shape[1]
    for b in range(b_count):
        for i in range(n):
            bitten_by[b, i] = 0
            penalty_bitten[b, i] = 0.0
            bit[b, i] = False
            target[b, i] = -1
        for i in range(n):
            if not (bite[b, i] and can_bite[b, i]):
                continue
            best, victim = np.inf, -1
            for j in range(n):
                if j != i:
                    d2 = in_cone(xy[b, j, 0] - xy[b, i, 0], xy[b, j, 1] - xy[b, i, 1], heading[b, i],
                                 p[BITE_R2], p[BITE_COS])
                    if d2 < best:
                        best, victim = d2, j
            if victim >= 0:
                bit[b, i] = True
                target[b, i] = victim
                bite_cd[b, i] = int(p[BITE_CD])
                bitten_by[b, victim] += 1
                penalty_bitten[b, victim] += 1.0 + size[b, i] - size[b, victim]


@njit(cache=True)
def record_motion(xy, old_xy, heading, move, turn, eod, bite, displacement, last_action):
    """What the next observation reports about this step, written in place.

    ``displacement`` float64[B, N, 2]: the move in the frame of the new heading
    (forward, left), cm; ``last_action`` float64[B, N, 4]: move, turn, eod, bite.
    """
    for b in range(xy.shape[0]):
        for i in range(xy.shape[1]):
            c, s = np.cos(heading[b, i]), np.sin(heading[b, i])
            dx, dy = xy[b, i, 0] - old_xy[b, i, 0], xy[b, i, 1] - old_xy[b, i, 1]
            displacement[b, i, 0] = c * dx + s * dy
            displacement[b, i, 1] = -s * dx + c * dy
            last_action[b, i, 0], last_action[b, i, 1] = move[b, i], turn[b, i]
            last_action[b, i, 2], last_action[b, i, 3] = eod[b, i], bite[b, i]
