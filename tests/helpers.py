"""Shared helpers of the efish tests: cached configs, scene builders, env drivers, invariants.

Test modules import these (``from ..helpers import cfg_with``); ``conftest.py``
only holds fixtures. Configs are composed once per distinct override set
(composition costs ~0.1 s).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from efish import Snapshot
from efish.config import compose
from efish.config.schema import EnvConfig
from efish.physics import Scene, build_plan
from efish.rollout.assay import condition_configs
from efish.rollout.conditions import conditions_table

RECEPTORS = ("mormyromast", "ampullary", "knollenorgan", "knollen_size")
BIG = 40.0  # raw action whose sigmoid / tanh is 1 to double precision


@functools.lru_cache(maxsize=None)
def conditions_of(assay: str, *overrides: str) -> pd.DataFrame:
    """``assays/<assay>/conditions.parquet`` as efish assay records it at the smoke scale under ``overrides``
    (e.g. ``env.fps=25``): every condition's resolved config. Shared: copy before editing."""
    return conditions_table(condition_configs(["scale=smoke", *overrides, f"assay={assay}"]))


def recorded_table(conditions: Iterable[str] | Mapping[str, Sequence[str]] = ("control", "treated"),
                   *overrides: str) -> pd.DataFrame:
    """``conditions.parquet`` as efish assay would record an assay of ``conditions`` (names, or name -> that
    condition's own overrides, e.g. ``{"slow": ["env.fps=41.5"]}``) at the smoke scale under ``overrides``: the
    record of synthetic rollout tables, whose condition names no assay file has. The first is the control."""
    own = dict(conditions) if isinstance(conditions, Mapping) else {c: () for c in conditions}
    listed = {name: [str(o) for o in extra] for name, extra in own.items()}
    configs = {}
    for name, extra in own.items():
        cfg = cfg_with("scale=smoke", *overrides, *extra)
        configs[name] = dataclasses.replace(cfg, assay=dataclasses.replace(cfg.assay, conditions=listed))
    return conditions_table(configs)


@functools.lru_cache(maxsize=None)
def _compose_cached(overrides: tuple[str, ...]):
    return compose(list(overrides))


def cfg_with(*overrides: str):
    """The default config with Hydra overrides, composed once per distinct override set.

    The returned object is shared: never mutate it.
    """
    return _compose_cached(tuple(overrides))


def random_snapshot(rng: np.random.Generator, n_agents: int, n_pellets: int, width: float = 70.0,
                    height: float = 70.0, emitting: np.ndarray | None = None, margin: float = 1.0) -> Snapshot:
    """A random arena: agents and pellets uniform in [margin, W - margin] x [margin, H - margin]."""
    def pts(k):
        return np.column_stack([rng.uniform(margin, width - margin, k), rng.uniform(margin, height - margin, k)])
    if emitting is None:
        emitting = rng.random(n_agents) < 0.5
    return Snapshot(agent_xy=pts(n_agents), agent_heading=rng.uniform(-np.pi, np.pi, n_agents),
                    agent_size=rng.uniform(0, 1, n_agents), agent_emitting=emitting,
                    pellet_xy=pts(n_pellets), pellet_orientation=rng.uniform(0, 2 * np.pi, n_pellets),
                    width=width, height=height)


def plan_for(cfg, snapshot: Snapshot, **kw):
    """The plan ``efish.sense`` would build for this snapshot."""
    return build_plan(cfg, Scene.of_batch(snapshot.as_batch()), **kw)


def assert_valid_readings(r: dict, n_agents: int) -> None:
    """Shapes, finiteness and ranges every ``efish.sense`` result must satisfy."""
    n = n_agents
    assert r["mormyromast"].shape == (n, 36)
    assert r["ampullary"].shape == (n, 24)
    assert r["knollenorgan"].shape == (n, n - 1, 12)
    assert r["knollen_size"].shape == (n, n - 1)
    for name in RECEPTORS:
        v = r[name]
        assert np.all(np.isfinite(v)), name
        assert np.all(np.abs(v) <= 1.0), name
    assert set(np.unique(r["knollenorgan"])) <= {-1.0, 0.0, 1.0}
    size = r["knollen_size"]
    assert np.all((size == 0) | ((size >= 0.5) & (size <= 1.0)))


def make_env(*overrides: str, num_envs: int = 1, seed: int = 0):
    """A ``VecEnv`` of the default config with overrides."""
    from efish.env import VecEnv

    return VecEnv(compose(list(overrides)), num_envs=num_envs, seed=seed)


class Killed(Exception):
    """Raised by :func:`kill_at`'s callback: training stops as a killed job would, after an update's logs."""


def kill_at(update: int):
    """A ``progress`` callback for :func:`efish.rl.train.train` that stops the run once ``update`` is logged
    (metrics written, the checkpoint only if that update is a checkpoint's)."""
    def progress(row: dict, total: int) -> None:
        if row["update"] == update:
            raise Killed(f"killed at update {update} of {total}")
    return progress


def actions(env, move=-BIG, turn=0.0, eod=0, bite=0) -> np.ndarray:
    """The same raw action for every agent of every arena: float64[B, N, 4]."""
    a = np.zeros((env.num_envs, env.n, 4))
    a[..., 0], a[..., 1], a[..., 2], a[..., 3] = move, turn, eod, bite
    return a


def random_actions(rng: np.random.Generator, num_envs: int, n_agents: int) -> np.ndarray:
    """Gaussian move/turn and 0/1 eod/bite for every agent: float64[B, N, 4]."""
    return np.concatenate([rng.normal(size=(num_envs, n_agents, 2)), rng.integers(0, 2, (num_envs, n_agents, 2))],
                          axis=-1)


def rollout_tables(seed: int = 0, conditions=("control", "treated"), episodes: int = 3, n_agents: int = 4,
                   steps: int = 120, units: int = 8, bite_target: bool = True, error_angles: bool = False,
                   arena_cm: float = 70.0) -> dict:
    """Synthetic rollout tables with the columns of ``efish.rollout.schema`` (steps, episodes, food), a
    ``hidden`` table keyed like steps (``h_0 .. h_{units-1}``), the ``conditions`` record of ``conditions`` at
    the default settings (:func:`recorded_table`) and, by choice, the columns the assays issue adds
    (``bite_target``; ``err_*_rad``). Agents random-walk in the middle 30 cm so that pairs meet, bite and
    chase; bigger agents discharge and eat more, so that size effects exist."""
    import pandas as pd

    rng = np.random.default_rng(seed)
    frames, hidden, food = [], [], []
    for cond in conditions:
        for e in range(episodes):
            frames.append(_episode_steps(rng, cond, e, n_agents, steps, arena_cm))
            latent = np.cumsum(rng.normal(size=(steps * n_agents, 3)), axis=0)
            h = latent @ rng.normal(size=(3, units)) + 0.1 * rng.normal(size=(steps * n_agents, units))
            hidden.append(frames[-1][["condition", "episode", "t", "agent"]].assign(
                **{f"h_{i}": h[:, i].astype(np.float32) for i in range(units)}))
            food.append(pd.DataFrame({"condition": cond, "episode": e, "pellet": np.arange(5),
                                      "x_cm": rng.uniform(0, arena_cm, 5), "y_cm": rng.uniform(0, arena_cm, 5),
                                      "t_spawned": 0, "t_eaten": -1, "eaten_by": -1}))
    s = pd.concat(frames, ignore_index=True)
    if not bite_target:
        s = s.drop(columns="bite_target")
    if error_angles:
        s = s.assign(**{c: rng.vonmises(0.0, 2.0, len(s)) for c in ("err_morm_rad", "err_amp_rad", "err_knollen_rad")})
    return {"steps": s, "episodes": _episodes_of(s), "food": pd.concat(food, ignore_index=True),
            "hidden": pd.concat(hidden, ignore_index=True), "conditions": recorded_table(conditions)}


#: Steps per second of env.fps's default (83) and half of it: the frame rates of :func:`planted_rate_tables`.
DEFAULT_FPS = float(EnvConfig().fps)
HALF_FPS = DEFAULT_FPS / 2


def planted_rate_tables(period: int = 5, leader_period: int | None = None, seed: int = 7) -> dict:
    """Rollout tables of one assay with two conditions that hold the same steps and hidden states: ``default``,
    recorded at env.fps's default (83), and ``slow``, recorded at half of it (its ``conditions`` record, as efish
    assay writes it). Every agent discharges on every ``period``-th step (agent 0 on every ``leader_period``-th,
    when given) and eats at steps 30, 60 and 90: a known EOD probability per step, 1 / period, so a known rate in
    Hz, fps / period, at each condition's recorded rate."""
    tables = rollout_tables(seed=seed, conditions=("default",), episodes=3, n_agents=4, steps=120)
    steps = tables["steps"]
    every = np.where(steps["agent"] == 0, leader_period or period, period)
    steps = steps.assign(eod=steps["t"] % every == 0, ate=steps["t"].isin([30, 60, 90]))

    def both(table: pd.DataFrame) -> pd.DataFrame:
        return pd.concat([table, table.assign(condition="slow")], ignore_index=True)
    steps = both(steps)
    return {"steps": steps, "episodes": _episodes_of(steps), "food": both(tables["food"]),
            "hidden": both(tables["hidden"]),
            "conditions": recorded_table({"default": [], "slow": [f"env.fps={HALF_FPS:g}"]})}


def _episode_steps(rng, cond: str, episode: int, n: int, steps: int, arena_cm: float):
    """Steps of one episode: (t, agent) rows, t-major, with every steps column of the rollout schema."""
    import pandas as pd

    size = rng.uniform(0, 1, n)
    centre = arena_cm / 2
    xy = np.clip(centre + np.cumsum(rng.normal(0, 1.0, (steps, n, 2)), axis=0), centre - 15, centre + 15)
    d = np.linalg.norm(xy[:, :, None] - xy[:, None], axis=-1) + np.where(np.eye(n, dtype=bool), np.inf, 0)
    nearest = d.argmin(axis=-1)
    bit = (d.min(axis=-1) < 5) & (rng.random((steps, n)) < 0.2 + 0.3 * size)
    was_bitten = np.zeros((steps, n), bool)
    for t, i in zip(*np.nonzero(bit), strict=True):
        was_bitten[t, nearest[t, i]] = True
    wall = np.minimum(xy, arena_cm - xy).min(axis=-1)
    cols = {"heading_rad": rng.uniform(-np.pi, np.pi, (steps, n)), "size": np.broadcast_to(size, (steps, n)),
            "move": rng.uniform(-1, 1, (steps, n)), "turn": rng.uniform(-1, 1, (steps, n)),
            "eod": rng.random((steps, n)) < 0.1 + 0.5 * size, "bite": bit | (rng.random((steps, n)) < 0.05),
            "ate": rng.random((steps, n)) < 0.02 + 0.1 * size, "bit": bit, "was_bitten": was_bitten,
            "collided": np.zeros((steps, n), bool), "reward": rng.normal(size=(steps, n)),
            "terminated": np.zeros((steps, n), bool), "success": np.zeros((steps, n), bool),
            "dist_agent_cm": d.min(axis=-1), "bearing_agent_rad": rng.uniform(-np.pi, np.pi, (steps, n)),
            "dist_food_cm": rng.uniform(0, 12, (steps, n)), "bearing_food_rad": rng.uniform(-np.pi, np.pi, (steps, n)),
            "dist_wall_cm": wall, "bearing_wall_rad": rng.uniform(-np.pi, np.pi, (steps, n)),
            "morm_abs_mean": rng.random((steps, n)), "amp_abs_mean": rng.random((steps, n)),
            "knollen_spikes": rng.integers(0, 12, (steps, n)), "bite_target": np.where(bit, nearest, -1),
            "turn_rad": rng.uniform(-0.3, 0.3, (steps, n)), "dist_agent2_cm": np.sort(d, axis=-1)[..., min(1, n - 1)],
            "size_agent1": size[nearest], "size_agent2": np.full((steps, n), np.nan),
            **{f"food_{k}5cm": rng.integers(0, 3, (steps, n)) for k in ("count_", "front_", "left_", "back_",
                                                                       "right_")},
            "n_knollen_agents": rng.integers(0, n, (steps, n)), "log_morm_field": rng.normal(-6, 1, (steps, n)),
            "log_amp_field": rng.normal(-10, 1, (steps, n)), "n_agents_100cm": (d < 100).sum(-1),
            "log_morm_sensed": np.where(rng.random((steps, n)) < 0.5, rng.uniform(-7.3, -1.3, (steps, n)), np.nan),
            **{f"err_{c}_rad": np.full((steps, n), np.nan) for c in ("morm", "amp", "knollen")}}
    t, agent = np.repeat(np.arange(steps), n), np.tile(np.arange(n), steps)
    return pd.DataFrame({"condition": cond, "episode": episode, "t": t, "t_ms": t * 1000.0 / 83.0, "agent": agent,
                         "x_cm": xy[..., 0].ravel(), "y_cm": xy[..., 1].ravel(),
                         **{k: np.asarray(v).ravel() for k, v in cols.items()}})


def _episodes_of(steps):
    """The episodes table (one row per agent-episode) that goes with a steps table."""
    g = steps.groupby(["condition", "episode", "agent"], sort=True)
    out = g.agg(size=("size", "first"), food_eaten=("ate", "sum"), eod_probability=("eod", "mean"),
                bites_given=("bit", "sum"), bites_received=("was_bitten", "sum"),
                mean_nn_dist_cm=("dist_agent_cm", "mean"), **{"return": ("reward", "sum")}, steps=("t", "size"),
                terminated=("terminated", "any"), success=("success", "any"))
    return out.reset_index()


def _canonical_cell(value) -> str:
    """One cell of a list or nested column as text that is equal exactly when the values are: arrays and lists
    element by element (an array read back from Parquet equals the list written), NaN equal to NaN, -0.0 to 0.0."""
    if isinstance(value, np.ndarray | list | tuple):
        return "[" + ",".join(_canonical_cell(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ",".join(f"{k!r}:{_canonical_cell(v)}" for k, v in sorted(value.items())) + "}"
    if isinstance(value, float | np.floating):
        return "nan" if np.isnan(value) else repr(float(value) + 0.0)  # + 0.0 turns -0.0 into 0.0
    return repr(value.item() if isinstance(value, np.generic) else value)


def _canonical_column(column: pd.Series) -> pd.Series:
    """A column that ``pd.util.hash_pandas_object`` can hash and whose hash follows the values: floats with one
    NaN and one zero, object columns holding lists or arrays (e.g. conditions.parquet) as canonical text."""
    if pd.api.types.is_float_dtype(column.dtype) and isinstance(column.dtype, np.dtype):
        values = column.to_numpy() + column.dtype.type(0.0)  # -0.0 + 0.0 == +0.0
        return pd.Series(np.where(np.isnan(values), column.dtype.type(np.nan), values), name=column.name)
    if column.dtype == object and any(isinstance(v, np.ndarray | list | tuple | dict) for v in column):
        return column.map(_canonical_cell)
    return column


def table_digest(table: pd.DataFrame, ignore: Iterable[str] = ()) -> str:
    """sha256 of a table's column names and values, the columns in sorted order and ``ignore`` left out.

    Two tables get the same digest exactly when they hold the same values in the same rows: NaN equals NaN and
    -0.0 equals 0.0 (as in ``pd.testing.assert_frame_equal``), and list or array cells compare element by element.
    The index is not part of it."""
    columns = sorted(set(table.columns) - set(ignore))
    digest = hashlib.sha256(repr([(c, str(table[c].dtype)) for c in columns]).encode())
    for c in columns:
        digest.update(pd.util.hash_pandas_object(_canonical_column(table[c]), index=False).to_numpy().tobytes())
    return digest.hexdigest()


REPO = Path(__file__).resolve().parents[1]


def scratch_workflow(folder: Path) -> Path:
    """A copy of the workflow files (Snakefile, workflow/, config/) in ``folder``, to run the pipeline in."""
    import shutil

    folder.mkdir(parents=True, exist_ok=True)
    for name in ("Snakefile", "workflow", "config"):
        src = REPO / name
        (shutil.copytree if src.is_dir() else shutil.copy)(src, folder / name)
    return folder


def smoke_env(work: Path) -> dict:
    """The environment of a pipeline run in the scratch copy ``work``: efish reads that copy's config."""
    import os

    return {**os.environ, "EFISH_CONFIG_DIR": str(work / "config")}


def draw_panel_axes(key: str, tables: dict):
    """Draw registered panel ``key`` from ``tables`` on a fresh axes; returns the axes (figure closed, still readable)."""
    from efish.figures.registry import PANELS
    from efish.figures.style import panel_style

    with panel_style() as plt:
        fig = plt.figure()
        ax = fig.add_subplot()
        PANELS[key].draw(tables, ax)
        plt.close(fig)
    return ax


def panel_texts(ax) -> list[str]:
    """Every text drawn on ``ax``."""
    return [t.get_text() for t in ax.texts]
