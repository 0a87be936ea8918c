"""The food log's records follow pellet slots, including a pellet that regrows and is eaten within one step."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from efish.rollout.run import FoodLog


def arenas(alive) -> SimpleNamespace:
    """A stand-in env with the state the food log reads: which slots hold a pellet, and where."""
    alive = np.array(alive, bool)
    xy = np.arange(alive.size * 2, dtype=float).reshape(*alive.shape, 2)
    return SimpleNamespace(state=SimpleNamespace(alive=alive, pellet_xy=xy))


def test_a_pellet_regrown_and_eaten_in_one_step_gets_its_own_record_in_its_own_arena():
    # two arenas, two slots; slot 1 of arena 1 regrows at step 1 (a record), slot 1 of arena 0 regrows and is
    # eaten by agent 2 within step 2: before the fix, slot -1 read the list's last record, arena 1's pellet
    env = arenas([[True, False], [True, False]])
    log = FoodLog(env)
    before = env.state.alive.copy()
    env.state.alive[1, 1] = True
    log.update(env, before, 1, np.ones(2, bool), np.full((2, 3), -1))
    before = env.state.alive.copy()
    eaten = np.full((2, 3), -1)
    eaten[0, 2] = 1
    log.update(env, before, 2, np.ones(2, bool), eaten)  # alive[0, 1] stays False: regrown, then eaten
    table = log.table()
    assert table[["episode", "pellet", "t_spawned", "t_eaten", "eaten_by"]].values.tolist() == [
        [0, 0, 0, -1, -1], [1, 0, 0, -1, -1], [1, 1, 1, -1, -1], [0, 1, 2, 2, 2]]
    assert table.iloc[3][["x_cm", "y_cm"]].tolist() == env.state.pellet_xy[0, 1].tolist()


def test_a_pellet_eaten_later_is_marked_on_its_spawn_record():
    env = arenas([[True, True]])
    log = FoodLog(env)
    before = env.state.alive.copy()
    env.state.alive[0, 0] = False
    eaten = np.array([[0, -1]])
    log.update(env, before, 5, np.ones(1, bool), eaten)
    assert log.table()[["pellet", "t_eaten", "eaten_by"]].values.tolist() == [[0, 5, 0], [1, -1, -1]]
