"""Run a policy in the env and record the rollout tables of SPEC/DESIGN "Tables"."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..config.schema import EfishConfig
from ..env.geometry import nearest_pellet
from ..env.observe import observation_slices
from ..env.vec_env import VecEnv


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2 * np.pi) - np.pi


def nearest(env: VecEnv) -> dict[str, np.ndarray]:
    """Distance (cm) and bearing (rad, from the heading) to the nearest agent, pellet and wall; [B, N] each."""
    s = env.state
    xy, h = s.xy, s.heading
    d = xy[:, None, :, :] - xy[:, :, None, :]                       # [B, N(i), N(j), 2]: j - i
    dist = np.linalg.norm(d, axis=-1) + np.where(np.eye(env.n, dtype=bool), np.inf, 0.0)
    j = dist.argmin(axis=-1)
    pick = np.take_along_axis(d, j[..., None, None], axis=2)[:, :, 0]
    out = {"dist_agent_cm": dist.min(axis=-1), "bearing_agent_rad": _wrap(np.arctan2(pick[..., 1], pick[..., 0]) - h)}
    if env.n == 1:
        out["dist_agent_cm"][:], out["bearing_agent_rad"][:] = np.nan, np.nan
    dist_food, k = np.empty(h.shape), np.empty(h.shape, np.int64)
    nearest_pellet(xy, s.pellet_xy, s.alive, dist_food, k)
    pk = np.take_along_axis(s.pellet_xy, np.maximum(k, 0)[..., None], axis=1) - xy   # [B, N, 2]
    out["dist_food_cm"] = dist_food
    out["bearing_food_rad"] = np.where(k >= 0, _wrap(np.arctan2(pk[..., 1], pk[..., 0]) - h), np.nan)
    walls = np.stack([xy[..., 0], s.width[:, None] - xy[..., 0], xy[..., 1], s.height[:, None] - xy[..., 1]], -1)
    w = walls.argmin(axis=-1)
    out["dist_wall_cm"] = walls.min(axis=-1)
    out["bearing_wall_rad"] = _wrap(np.array([np.pi, 0.0, -np.pi / 2, np.pi / 2])[w] - h)
    return out


def run_episodes(cfg: EfishConfig, policy, episodes: int, condition: str = "control", seed: int = 0,
                 deterministic: bool = True) -> dict[str, pd.DataFrame]:
    """``episodes`` episodes in parallel arenas; returns the ``steps``, ``episodes`` and ``food`` tables.

    An arena is recorded up to the step its episode ends (the task's
    termination, e.g. homing's success, or the time limit) and not after it:
    its ``steps`` and ``return`` count only those steps.

    ``policy`` has ``initial_hidden(B, N)`` and ``act(obs, hidden, starts, deterministic)`` like
    :class:`efish.rl.policy.Policy`.
    """
    env = VecEnv(cfg, num_envs=episodes, seed=seed, autoreset=False)
    obs = env.reset()
    hidden, starts = policy.initial_hidden(episodes, env.n), np.ones(episodes)
    T, B, N = cfg.env.episode_steps, episodes, env.n
    sl = observation_slices(len(env.plan.morm_angles), len(env.plan.amp_angles), len(env.plan.knollen_angles),
                            cfg.env.obs_agents)
    electric = cfg.sensors.perception == "electric"
    food = FoodLog(env)
    steps, bites_recv = [], np.zeros((B, N), int)
    running = np.ones(B, bool)  # arenas whose episode has not ended: only they are recorded
    for t in range(T):
        actions, hidden = policy.act(obs, hidden, starts, deterministic)
        alive_before = env.state.alive.copy()
        obs, reward, term, trunc, info = env.step(actions)
        food.update(env, alive_before, t, running)
        success = env.task.success(env.state)
        row = {
            "episode": np.repeat(np.arange(B), N), "t": np.full(B * N, t), "agent": np.tile(np.arange(N), B),
            "x_cm": env.state.xy[..., 0].ravel(), "y_cm": env.state.xy[..., 1].ravel(),
            "heading_rad": env.state.heading.ravel(), "size": env.state.size.ravel(), "move": info["move"].ravel(),
            "turn": info["turn"].ravel(), "eod": info["eod"].ravel(), "bite": info["bite"].ravel(),
            "ate": info["ate"].ravel(), "bit": info["bit"].ravel(), "was_bitten": info["was_bitten"].ravel(),
            "collided": info["collided"].ravel(), "reward": reward.ravel(),
            "terminated": np.repeat(term, N), "success": np.repeat(term & success, N),
            **{k: v.ravel() for k, v in nearest(env).items()},
            "morm_abs_mean": np.abs(obs[..., sl["mormyromast"]]).mean(-1).ravel() if electric else np.nan,
            "amp_abs_mean": np.abs(obs[..., sl["ampullary"]]).mean(-1).ravel() if electric else np.nan,
            "knollen_spikes": (obs[..., sl["knollenorgan"]] != 0).sum(-1).ravel() if electric else 0,
        }
        steps.append(pd.DataFrame(row)[np.repeat(running, N)])
        bites_recv += info["bitten_by"] * running[:, None]
        starts = np.zeros(B)
        running &= ~(term | trunc)
        if not running.any():
            break
    steps_df = pd.concat(steps, ignore_index=True)
    steps_df.insert(0, "condition", condition)
    steps_df.insert(3, "t_ms", steps_df["t"] * 1000.0 / cfg.env.fps)
    g = steps_df.groupby(["episode", "agent"], sort=True)
    episodes_df = pd.DataFrame({
        "size": g["size"].first(), "food_eaten": g["ate"].sum(), "eod_probability": g["eod"].mean(),
        "bites_given": g["bit"].sum(), "mean_nn_dist_cm": g["dist_agent_cm"].mean(), "return": g["reward"].sum(),
        "steps": g["t"].count(), "terminated": g["terminated"].any(), "success": g["success"].any()}).reset_index()
    episodes_df["bites_received"] = bites_recv[episodes_df["episode"], episodes_df["agent"]]
    episodes_df.insert(0, "condition", condition)
    food_df = food.table()
    food_df.insert(0, "condition", condition)
    return {"steps": steps_df, "episodes": episodes_df, "food": food_df}


class FoodLog:
    """One record per pellet that ever existed: where, when it appeared, when it was eaten (-1: never).

    Pellet slots are reused by regrowth, so records follow slots, not the reverse.
    A pellet that regrows and is eaten within the same step is not seen (one-patch only).
    """

    def __init__(self, env: VecEnv):
        self.records: list[list] = []              # [episode, pellet id, x, y, t_spawned, t_eaten]
        self.slot = np.full(env.state.alive.shape, -1)  # record index currently in each slot
        self.count = np.zeros(env.state.alive.shape[0], int)  # pellets seen so far per episode
        for b, k in zip(*np.nonzero(env.state.alive)):
            self._spawn(env, b, k, 0)

    def _spawn(self, env: VecEnv, b: int, k: int, t: int) -> None:
        self.slot[b, k] = len(self.records)
        self.records.append([b, self.count[b], env.state.pellet_xy[b, k, 0], env.state.pellet_xy[b, k, 1], t, -1])
        self.count[b] += 1

    def update(self, env: VecEnv, alive_before: np.ndarray, t: int, running: np.ndarray) -> None:
        """Record pellets eaten and regrown during step ``t`` in the arenas still ``running`` (bool[B])."""
        alive = env.state.alive
        alive_before = alive_before | ~running[:, None]  # ended arenas: nothing changes in the record
        alive = alive | ~running[:, None]
        for b, k in zip(*np.nonzero(alive_before & ~alive)):
            self.records[self.slot[b, k]][5] = t
        for b, k in zip(*np.nonzero(~alive_before & alive)):
            self._spawn(env, b, k, t)

    def table(self) -> pd.DataFrame:
        return pd.DataFrame(self.records, columns=["episode", "pellet", "x_cm", "y_cm", "t_spawned", "t_eaten"])
