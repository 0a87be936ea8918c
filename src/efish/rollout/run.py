"""Run a policy in the env and record the rollout tables (docs/architecture.md#tables)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..config.schema import EfishConfig
from ..env.observe import observation_slices
from ..env.vec_env import VecEnv
from ..units import wrap
from .measures import (
    agents_in_range,
    food_counts,
    homing_errors,
    knollen_agents,
    log_fields,
    log_morm_sensed,
    nearest,
)


def run_episodes(cfg: EfishConfig, policy, episodes: int, condition: str = "control", seed: int = 0,
                 deterministic: bool = True, record_hidden: bool = False, members: int = 1) -> dict[str, pd.DataFrame]:
    """``episodes`` episodes in parallel arenas; returns the ``steps``, ``episodes`` and ``food`` tables
    (and ``hidden``, the policy's GRU state per step and agent, with ``record_hidden``).

    An arena is recorded up to the step its episode ends (the task's
    termination, e.g. homing's success, or the time limit) and not after it:
    its ``steps`` and ``return`` count only those steps.

    The ``hidden`` row (episode, t, agent) is the state that has taken in the
    observation step t returned, i.e. the world the ``steps`` row t describes,
    and has not yet acted on it (see :func:`hidden_table`): it is the state the
    next ``act`` call returns. So that the last recorded step has one too, the
    policy is called once more on the final observation; that call's actions
    are discarded, and nothing else (actions, steps, food) depends on it.

    ``policy`` has ``initial_hidden(B, N)`` and ``act(obs, hidden, starts, deterministic)`` like
    :class:`efish.rl.policy.Policy`. ``members`` > 1 runs the episodes that many times side by side, as the
    members of one env (:class:`~efish.env.vec_env.VecEnv`, each seeded by ``seed``): episode ``k * episodes +
    e`` is member k's episode e, and ``policy`` acts for all of them (:class:`efish.rollout.group.PolicyGroup`).
    """
    env = VecEnv(cfg, num_envs=episodes, seed=[seed] * members, autoreset=False)
    obs = env.reset()
    B, N = env.num_envs, env.n
    hidden, starts = policy.initial_hidden(B, N), np.ones(B)
    T = cfg.env.episode_steps
    food = FoodLog(env)
    steps, states, bites_recv = [], [], np.zeros((B, N), int)
    running = np.ones(B, bool)  # arenas whose episode has not ended: only they are recorded
    seen = None  # rows recorded at the previous step: the state act returns next has taken in their observation
    for t in range(T):
        actions, hidden = policy.act(obs, hidden, starts, deterministic)
        if record_hidden and seen is not None:
            states.append(hidden.reshape(B * N, -1)[seen].astype(np.float32))
        alive_before, heading_before = env.state.alive.copy(), env.state.heading.copy()
        obs, reward, term, trunc, info = env.step(actions)
        food.update(env, alive_before, t, running, info["eaten_slot"])
        seen = np.repeat(running, N)
        steps.append({k: v[seen] for k, v in step_columns(env, obs, reward, term, info, heading_before, t).items()})
        bites_recv += info["bitten_by"] * running[:, None]
        starts = np.zeros(B)
        running &= ~(term | trunc)
        if not running.any():
            break
    if record_hidden:
        # the state that has taken in the last step's observation; deterministic, so that the discarded action
        # draws from no random stream a later sampling call would use
        _, hidden = policy.act(obs, hidden, starts, True)
        states.append(hidden.reshape(B * N, -1)[seen].astype(np.float32))
    # one frame per table at the end: building a frame per step costs more than the step itself
    steps_df = pd.DataFrame({k: np.concatenate([step[k] for step in steps]) for k in steps[0]})
    steps_df.insert(0, "condition", condition)
    steps_df.insert(3, "t_ms", steps_df["t"] * 1000.0 / cfg.env.fps)
    tables = {"steps": steps_df, "episodes": episode_table(steps_df, bites_recv), "food": food.table()}
    if record_hidden:
        tables["hidden"] = hidden_table(steps_df[["episode", "t", "agent"]], np.concatenate(states))
    for name in ("food", "hidden"):
        if name in tables:
            tables[name].insert(0, "condition", condition)
    return tables


def step_columns(env: VecEnv, obs: np.ndarray, reward: np.ndarray, term: np.ndarray, info: dict,
                 heading_before: np.ndarray, t: int) -> dict[str, np.ndarray]:
    """Every steps-table column of one step except the condition and t_ms, flat over (arena, agent)."""
    s, cfg = env.state, env.cfg
    B, N = s.heading.shape
    electric = cfg.sensors.perception == "electric"
    slots = cfg.env.obs_agents - 1
    sl = observation_slices(cfg.sensors.mormyromast.count, cfg.sensors.ampullary.count,
                            cfg.sensors.knollenorgan.count, cfg.env.obs_agents)
    success = env.task.success(s)
    knoll = obs[..., sl["knollenorgan"]] if electric else None
    columns = {
        "episode": np.repeat(np.arange(B), N), "t": np.full(B * N, t), "agent": np.tile(np.arange(N), B),
        "x_cm": s.xy[..., 0], "y_cm": s.xy[..., 1], "heading_rad": s.heading, "size": s.size,
        "move": info["move"], "turn": info["turn"], "turn_rad": wrap(s.heading - heading_before),
        "eod": info["eod"], "bite": info["bite"], "ate": info["ate"], "bit": info["bit"],
        "bite_target": info["bite_target"], "was_bitten": info["was_bitten"], "collided": info["collided"],
        "reward": reward, "terminated": np.repeat(term, N).reshape(B, N),
        "success": np.repeat(term & success, N).reshape(B, N),
        **nearest(env), **food_counts(env),
        "n_knollen_agents": knollen_agents(knoll, slots) if electric else np.zeros((B, N), int),
        "n_agents_100cm": agents_in_range(env, cfg.sensors.knollenorgan.range_cm),
        "morm_abs_mean": np.abs(obs[..., sl["mormyromast"]]).mean(-1) if electric else np.full((B, N), np.nan),
        "amp_abs_mean": np.abs(obs[..., sl["ampullary"]]).mean(-1) if electric else np.full((B, N), np.nan),
        "knollen_spikes": (knoll != 0).sum(-1) if electric else np.zeros((B, N), int),
        "log_morm_sensed": (log_morm_sensed(obs[..., sl["mormyromast"]], cfg.sensors.mormyromast.e_min,
                                            cfg.sensors.mormyromast.e_max) if electric else np.full((B, N), np.nan)),
        **log_fields(env), **homing_errors(env),
    }
    return {k: np.ravel(v) for k, v in columns.items()}


def hidden_table(keys: pd.DataFrame, hidden: np.ndarray) -> pd.DataFrame:
    """The GRU states [rows, H] beside their keys (episode, t, agent), float32 columns h_0 ... h_{H-1}.

    Convention: the state of row t has taken in the observation that step t
    returned (the world after step t, which the ``steps`` row t describes) and
    has produced none of row t's actions (those came from the state before).
    Merging ``hidden`` and ``steps`` on (condition, episode, t, agent) thus
    pairs each state with the world it has observed (docs/claims/index.md#rule-7), never with
    the action it produced.
    """
    units = pd.DataFrame(hidden, columns=[f"h_{i}" for i in range(hidden.shape[1])])
    return pd.concat([keys.reset_index(drop=True), units], axis=1)


def episode_table(steps: pd.DataFrame, bites_received: np.ndarray) -> pd.DataFrame:
    """One row per (episode, agent) summarising its recorded steps."""
    g = steps.groupby(["episode", "agent"], sort=True)
    table = pd.DataFrame({
        "size": g["size"].first(), "food_eaten": g["ate"].sum(), "eod_probability": g["eod"].mean(),
        "bites_given": g["bit"].sum(), "mean_nn_dist_cm": g["dist_agent_cm"].mean(), "return": g["reward"].sum(),
        "steps": g["t"].count(), "terminated": g["terminated"].any(), "success": g["success"].any()}).reset_index()
    table["bites_received"] = bites_received[table["episode"], table["agent"]]
    table.insert(0, "condition", steps["condition"].iloc[0])
    return table


class FoodLog:
    """One record per pellet that ever existed: where, when it appeared, when it was eaten (-1: never).

    Pellet slots are reused by regrowth, so records follow slots, not the reverse. A pellet that regrows and is
    eaten within the same step (regrowth comes first in a step: one-patch arenas) gets a record of its own,
    spawned and eaten at that step.
    """

    def __init__(self, env: VecEnv):
        self.records: list[list] = []              # [episode, pellet id, x, y, t_spawned, t_eaten, eaten_by]
        self.slot = np.full(env.state.alive.shape, -1)  # record index currently in each slot
        self.count = np.zeros(env.state.alive.shape[0], int)  # pellets seen so far per episode
        for b, k in zip(*np.nonzero(env.state.alive), strict=True):
            self._spawn(env, b, k, 0)

    def _spawn(self, env: VecEnv, b: int, k: int, t: int) -> None:
        self.slot[b, k] = len(self.records)
        self.records.append([b, self.count[b], env.state.pellet_xy[b, k, 0], env.state.pellet_xy[b, k, 1], t, -1, -1])
        self.count[b] += 1

    def update(self, env: VecEnv, alive_before: np.ndarray, t: int, running: np.ndarray, eaten_slot: np.ndarray
               ) -> None:
        """Record pellets eaten (by whom: ``eaten_slot`` [B, N], the slot each agent ate, -1 none) and regrown
        during step ``t`` in the arenas still ``running`` (bool[B])."""
        alive = env.state.alive
        alive_before = alive_before | ~running[:, None]  # ended arenas: nothing changes in the record
        alive = alive | ~running[:, None]
        for b, i in zip(*np.nonzero(eaten_slot >= 0), strict=True):
            if running[b]:
                k = eaten_slot[b, i]
                if not alive_before[b, k]:  # regrown and eaten in this step: no record holds it yet
                    self._spawn(env, b, k, t)
                record = self.records[self.slot[b, k]]
                record[5], record[6] = t, i
        for b, k in zip(*np.nonzero(~alive_before & alive), strict=True):
            self._spawn(env, b, k, t)

    def table(self) -> pd.DataFrame:
        return pd.DataFrame(self.records, columns=["episode", "pellet", "x_cm", "y_cm", "t_spawned", "t_eaten",
                                                   "eaten_by"])
