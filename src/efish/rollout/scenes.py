"""Scenes of Fig 1 and the sensing-range maps: field maps on a grid, computed by the physics, as one table.

``efish scene <name>`` composes ``config/scene/<name>.yaml`` (a :class:`~efish.config.schema.SceneConfig`)
and writes ``scenes/<name>.parquet``; panels read that table and never compute a field themselves. Kinds:

- ``field``: the EOD field of the emitting agents on a grid, with the dipoles their EODs induce on the other
  bodies and, with ``walls``, every source's wall images (``physics.image_order``, ``image_scale``), beside the
  emitters' direct field in free space (``*_free`` columns): their difference is the distortion by objects
  and walls. The field vector (Ex, Ey) is what a panel's streamlines follow.
- ``sensing_range``: a pellet or an (emitting, facing) agent placed at log-spaced distances and even bearings
  around an emitting focal agent in free space; for each receptor class of the focal agent, the largest raw
  reading over its sensors divided by the class's threshold (E_min, or the Knollenorgan spike threshold),
  from the brute-force reference of the sensing code (exact, noise off). A ratio above 1 is detected.
- ``sensors``: where the sensors of each receptor class sit on the first agent's body.
- ``food_layouts``: the pellets of one episode of each named arena (``layouts``), from the env's generators.

Every table has the columns of :data:`COLUMNS` (the ones a kind does not use are NaN, "" or False), so one
schema check covers all scenes. Positions in cm, fields in V/m, angles in radians.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
import pandas as pd
import pyarrow as pa

from ..config import compose
from ..config.compose import compose_variants
from ..config.schema import EfishConfig, SceneConfig
from ..env.arenas import sample_arena, sample_pellets
from ..physics.fields import dipole_field, induced_dipole, monopole_field
from ..physics.geometry import ampullary_angles, knollenorgan_angles, mormyromast_angles, sensor_frame
from ..physics.images import image_sources
from ..physics.plan import EffectPlan, Scene, build_plan
from ..physics.reference import eod_monopoles
from ..physics.snapshot import Snapshot, SnapshotBatch
from ..senses import SENSES
from ..sensors.sense import raw_readings
from ..units import CM

F64, B, S = pa.float64(), pa.bool_(), pa.string()
RECEPTORS = tuple(s.name for s in SENSES)

# (name, type, one-line description): the one declaration of every column of a scene table
COLUMNS = [
    ("scene", S, "scene name (config/scene/<name>.yaml)"),
    ("variant", S, "sub-map: the food layout (food_layouts), the target (sensing_range), else ''"),
    ("element", S, ("grid (a field sample), arena, emitter (an emitting agent), agent (a silent one), pellet, "
                    "sensor")),
    ("x_cm", F64, "position, cm (arena: its lower-left corner)"), ("y_cm", F64, "position, cm"),
    ("heading_rad", F64, "agents: heading; pellets: orientation, rad"),
    ("radius_cm", F64, "body radius, cm"),
    ("width_cm", F64, "arena rows: width, cm"), ("height_cm", F64, "arena rows: height, cm"),
    ("walls", B, "arena rows: the sources are mirrored in its insulating walls"),
    ("receptor", S, "sensor and sensing_range rows: mormyromast, ampullary or knollenorgan"),
    ("angle_rad", F64, "sensor rows: angle on the body from the heading, rad"),
    ("ex_v_m", F64, "grid rows: field x component, every source (EODs, induced dipoles, wall images), V/m"),
    ("ey_v_m", F64, "grid rows: field y component, V/m"),
    ("ex_free_v_m", F64, "grid rows: x component of the emitters' direct EOD field in free space, V/m"),
    ("ey_free_v_m", F64, "grid rows: y component of the emitters' direct EOD field in free space, V/m"),
    ("inside_body", B, "grid rows: the point lies inside a body (no water there)"),
    ("distance_cm", F64, "sensing_range rows: target centre to the focal agent's centre, cm"),
    ("bearing_rad", F64, "sensing_range rows: target bearing from the focal agent's heading, rad"),
    ("ratio", F64, ("sensing_range rows: max |raw reading| over the class's sensors / its threshold (>= 1: "
                    "detected); NaN where the target would overlap the focal body")),
]
SCHEMA = pa.schema([(name, kind) for name, kind, _ in COLUMNS])


def build_scene(cfg: EfishConfig, overrides: Sequence[str] = ()) -> pd.DataFrame:
    """The table of scene ``cfg.scene`` (``overrides``: the command's, for the food layouts' arenas)."""
    kind = cfg.scene.kind
    if kind == "field":
        frame = field_table(cfg)
    elif kind == "sensing_range":
        frame = sensing_range_table(cfg)
    elif kind == "sensors":
        frame = sensor_table(cfg)
    else:
        frame = food_layout_table(cfg.scene, overrides)
    return conform(frame.assign(scene=cfg.scene.name))


def compose_scene(name: str, overrides: Sequence[str] = ()) -> EfishConfig:
    """The config with scene ``name`` (config/scene/<name>.yaml) chosen; overrides may set ``scene.*`` keys."""
    return compose([f"+scene={name}", *overrides])


def conform(frame: pd.DataFrame) -> pd.DataFrame:
    """Every column of :data:`COLUMNS` in order, the unused ones filled (NaN, '' or False); unknown ones refused."""
    extra = sorted(set(frame.columns) - set(SCHEMA.names))
    if extra:
        raise ValueError(f"scene table: unexpected columns {extra}")
    fill = {S: "", B: False}
    out = frame.copy()
    for name, kind, _ in COLUMNS:
        if name not in out:
            out[name] = fill.get(kind, np.nan)
    out = out[SCHEMA.names].reset_index(drop=True)
    for name, kind, _ in COLUMNS:
        out[name] = out[name].astype({S: object, B: bool}.get(kind, np.float64))
    return out


def to_arrow(frame: pd.DataFrame) -> pa.Table:
    """The scene table as Arrow with exactly :data:`SCHEMA` (what ``efish scene`` writes)."""
    return pa.Table.from_pandas(conform(frame), schema=SCHEMA, preserve_index=False)


# ----------------------------------------------------------------------- shared
def free_space(cfg: EfishConfig, walls: bool) -> EfishConfig:
    """``cfg`` itself with walls, else the same physics without wall images (image order 0)."""
    return cfg if walls else dataclasses.replace(cfg, physics=dataclasses.replace(cfg.physics, image_order=0))


def arena_row(width: float, height: float, walls: bool, **extra) -> pd.DataFrame:
    """The arena rectangle [0, width] x [0, height] as one row."""
    return pd.DataFrame([{"element": "arena", "x_cm": 0.0, "y_cm": 0.0, "width_cm": float(width),
                          "height_cm": float(height), "walls": bool(walls), **extra}])


def body_rows(scene: SceneConfig, cfg: EfishConfig) -> pd.DataFrame:
    """One row per agent (emitter or agent) and per pellet of the scene, with its radius."""
    agents = np.asarray(scene.agents, dtype=float).reshape(-1, 4)
    pellets = np.asarray(scene.pellets, dtype=float).reshape(-1, 3)
    return pd.DataFrame({
        "element": ["emitter" if e else "agent" for e in agents[:, 3]] + ["pellet"] * len(pellets),
        "x_cm": np.r_[agents[:, 0], pellets[:, 0]], "y_cm": np.r_[agents[:, 1], pellets[:, 1]],
        "heading_rad": np.r_[agents[:, 2], pellets[:, 2]],
        "radius_cm": np.r_[np.full(len(agents), cfg.physics.agent_radius_cm),
                           np.full(len(pellets), cfg.physics.pellet_radius_cm)]})


def _check_inside(scene: SceneConfig, bodies: pd.DataFrame) -> None:
    w, h = scene.arena_cm
    out = (bodies["x_cm"] < 0) | (bodies["x_cm"] > w) | (bodies["y_cm"] < 0) | (bodies["y_cm"] > h)
    if out.any():
        raise ValueError(f"scene {scene.name}: bodies at rows {list(np.flatnonzero(out))} lie outside the "
                         f"{w:g} x {h:g} cm arena")


# ------------------------------------------------------------------------ field
def grid_points(scene: SceneConfig) -> tuple[np.ndarray, np.ndarray]:
    """x (nx,) and y (ny,) of the field grid, cm: the window (default the arena), ends included."""
    x0, x1, y0, y1 = scene.window_cm or (0.0, scene.arena_cm[0], 0.0, scene.arena_cm[1])
    step = scene.resolution_cm
    xs, ys = np.arange(x0, x1 + step / 2, step), np.arange(y0, y1 + step / 2, step)
    if len(xs) * len(ys) > 4_000_000:
        raise ValueError(f"scene {scene.name}: a {len(xs)} x {len(ys)} grid is too fine; raise scene.resolution_cm")
    return xs, ys


def emitter_charges(bodies: pd.DataFrame, plan: EffectPlan, arena_m: tuple[float, float]
                    ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per emitter: its EOD monopoles with their wall images (positions m, charges C) and its body index."""
    out = []
    for i in np.flatnonzero(bodies["element"].to_numpy() == "emitter"):
        xy = bodies[["x_cm", "y_cm"]].to_numpy()[i] * CM
        pos, q = eod_monopoles(xy, bodies["heading_rad"].to_numpy()[i], plan)
        ipos, _, weight = image_sources(pos, None, *arena_m, plan.image_indices, plan.image_scale)
        out.append((ipos, np.tile(q, len(plan.image_indices)) * weight, i))
    return out


def induced_moments(bodies: pd.DataFrame, emitters: list, plan: EffectPlan, eps0: float) -> np.ndarray:
    """Dipole (K, 2) C*m induced on every body by the EODs (with images) of every emitter but itself: the
    physics' :func:`~efish.physics.fields.induced_dipole` of each emitter's field, summed
    (docs/model/physics.md#induction)."""
    xy = bodies[["x_cm", "y_cm"]].to_numpy() * CM
    alpha = np.where(bodies["element"].isin(["emitter", "agent"]), plan.alpha_agent, plan.alpha_pellet)
    moments = np.zeros((len(bodies), 2))
    for positions, charges, own in emitters:
        e = monopole_field(xy, positions, charges, softening=np.sqrt(plan.softening2), eps0=eps0)
        moments += induced_dipole(alpha, e, own=own)
    return moments


def scene_field(points_m: np.ndarray, bodies: pd.DataFrame, cfg: EfishConfig, walls: bool,
                arena_m: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Total field (M, 2) and the emitters' direct free-space field (M, 2) at ``points_m``, V/m."""
    cfg = free_space(cfg, walls)
    plan = build_plan(cfg, Scene(agents=2, emitters=True, pellets=True), tolerance=0.0)
    soft, eps0 = np.sqrt(plan.softening2), cfg.physics.eps0
    emitters = emitter_charges(bodies, plan, arena_m)
    free = np.zeros_like(points_m)
    total = np.zeros_like(points_m)
    for positions, charges, _ in emitters:  # image-major: the first two rows are the emitter's own monopoles
        free += monopole_field(points_m, positions[:2], charges[:2], softening=soft, eps0=eps0)
        total += monopole_field(points_m, positions, charges, softening=soft, eps0=eps0)
    moments = induced_moments(bodies, emitters, plan, eps0)
    if np.any(moments):
        ipos, imom, _ = image_sources(bodies[["x_cm", "y_cm"]].to_numpy() * CM, moments, *arena_m,
                                      plan.image_indices, plan.image_scale)
        total += dipole_field(points_m, ipos, imom, softening=soft, eps0=eps0)
    return total, free


def field_table(cfg: EfishConfig) -> pd.DataFrame:
    """Grid rows with the total and the free field, then the bodies and the arena (kind ``field``)."""
    scene = cfg.scene
    bodies = body_rows(scene, cfg)
    _check_inside(scene, bodies)
    xs, ys = grid_points(scene)
    gx, gy = (a.ravel() for a in np.meshgrid(xs, ys))
    total, free = scene_field(np.stack([gx, gy], axis=1) * CM, bodies, cfg, scene.walls,
                              (scene.arena_cm[0] * CM, scene.arena_cm[1] * CM))
    d2 = (gx[:, None] - bodies["x_cm"].to_numpy()) ** 2 + (gy[:, None] - bodies["y_cm"].to_numpy()) ** 2
    grid = pd.DataFrame({"element": "grid", "x_cm": gx, "y_cm": gy, "ex_v_m": total[:, 0], "ey_v_m": total[:, 1],
                         "ex_free_v_m": free[:, 0], "ey_free_v_m": free[:, 1],
                         "inside_body": np.any(d2 < bodies["radius_cm"].to_numpy() ** 2, axis=1)})
    return pd.concat([grid, bodies, arena_row(*scene.arena_cm, scene.walls)], ignore_index=True)


# ---------------------------------------------------------------- sensing range
def target_positions(scene: SceneConfig) -> tuple[np.ndarray, np.ndarray]:
    """Distances (R,) cm, log-spaced over ``range_cm``, and bearings (A,) rad from 0, evenly round the circle."""
    lo, hi = scene.range_cm
    return np.geomspace(lo, hi, scene.range_points), np.arange(scene.bearings) * (2 * np.pi / scene.bearings)


def _target_snapshot(target: str, centre: float, xy: np.ndarray, bearing: float) -> Snapshot:
    """The focal agent (emitting, heading 0) at the centre and one target at ``xy``; an agent target emits
    and faces the focal agent, a pellet has orientation 0."""
    focal = [[centre, centre]]
    if target == "agent":
        return Snapshot(agent_xy=focal + [list(xy)], agent_heading=[0.0, bearing + np.pi], agent_size=[0.5, 0.5],
                        agent_emitting=[True, True], width=2 * centre, height=2 * centre)
    return Snapshot(agent_xy=focal, agent_heading=[0.0], agent_size=[0.5], agent_emitting=[True],
                    pellet_xy=[list(xy)], pellet_orientation=[0.0], width=2 * centre, height=2 * centre)


def detection_ratios(batch: SnapshotBatch, plan: EffectPlan) -> dict[str, np.ndarray]:
    """Per receptor class, the focal agent's (agent 0's) max |raw reading| / threshold for each arena (B,)."""
    raw = raw_readings(batch, plan, reference=True)
    ratios = {"mormyromast": np.abs(raw.mormyromast[:, 0]).max(axis=1) / plan.morm_range[0],
              "ampullary": np.abs(raw.ampullary[:, 0]).max(axis=1) / plan.amp_range[0]}
    if batch.shape[1] > 1:
        ratios["knollenorgan"] = np.abs(raw.knollenorgan[:, 0, 0]).max(axis=1) / plan.knollen_threshold
    return {k: v for k, v in ratios.items() if plan.on(k)}


def sensing_range_table(cfg: EfishConfig) -> pd.DataFrame:
    """Detection ratio of each receptor class per target, distance and bearing (kind ``sensing_range``)."""
    scene = cfg.scene
    cfg = free_space(cfg, walls=False)
    distances, bearings = target_positions(scene)
    dist, bear = (a.ravel() for a in np.meshgrid(distances, bearings, indexing="ij"))
    centre = distances[-1] + 2 * cfg.physics.agent_radius_cm  # the arena only bounds positions: no walls
    xy = centre + dist[:, None] * np.stack([np.cos(bear), np.sin(bear)], axis=1)
    frames = []
    for target in scene.targets:
        batch = SnapshotBatch.stack([_target_snapshot(target, centre, p, b) for p, b in zip(xy, bear, strict=True)])
        plan = build_plan(cfg, Scene.of_batch(batch), tolerance=0.0)
        radius = cfg.physics.agent_radius_cm if target == "agent" else cfg.physics.pellet_radius_cm
        overlap = dist < cfg.physics.agent_radius_cm + radius
        for receptor, ratio in detection_ratios(batch, plan).items():
            frames.append(pd.DataFrame({
                "variant": target, "element": "grid", "receptor": receptor, "x_cm": xy[:, 0] - centre,
                "y_cm": xy[:, 1] - centre, "distance_cm": dist, "bearing_rad": bear,
                "ratio": np.where(overlap, np.nan, ratio)}))
    focal = pd.DataFrame([{"element": "emitter", "x_cm": 0.0, "y_cm": 0.0, "heading_rad": 0.0,
                           "radius_cm": cfg.physics.agent_radius_cm}])
    return pd.concat(frames + [focal], ignore_index=True)


# ---------------------------------------------------------------------- sensors
def sensor_table(cfg: EfishConfig) -> pd.DataFrame:
    """Every sensor of each receptor class on the first agent's body (kind ``sensors``); the body as a row."""
    scene = cfg.scene
    bodies = body_rows(scene, cfg).iloc[:1]
    xy, heading = bodies[["x_cm", "y_cm"]].to_numpy()[0], float(bodies["heading_rad"].iloc[0])
    se, radius = cfg.sensors, cfg.physics.agent_radius_cm
    frames = [bodies]
    for receptor, angles in (("mormyromast", mormyromast_angles(se.mormyromast)),
                             ("ampullary", ampullary_angles(se.ampullary)),
                             ("knollenorgan", knollenorgan_angles(se.knollenorgan))):
        pos, _ = sensor_frame(xy, np.asarray(heading), angles, radius)
        frames.append(pd.DataFrame({"element": "sensor", "receptor": receptor, "angle_rad": angles,
                                    "x_cm": pos[:, 0], "y_cm": pos[:, 1]}))
    return pd.concat(frames, ignore_index=True)


# ----------------------------------------------------------------- food layouts
def food_layout_table(scene: SceneConfig, overrides: Sequence[str]) -> pd.DataFrame:
    """Pellets at the start of one episode of each layout, drawn by the env's arena generators (Fig 1C).

    Each layout composes the command's config with its own overrides (``scene.layouts``) and draws with
    its own generator seeded by (scene.seed, layout index), so a layout's pellets do not depend on the others.
    """
    if not scene.layouts:
        raise ValueError(f"scene {scene.name}: food_layouts needs scene.layouts ([name, override, ...] per layout)")
    configs = compose_variants(list(overrides), {name: list(extra) for name, *extra in scene.layouts}, label="layout")
    frames = []
    for i, (layout, cfg) in enumerate(configs.items()):
        rng = np.random.default_rng([scene.seed, i])
        arena = sample_arena(cfg.arena, rng)
        pellets = sample_pellets(arena, rng)
        frames += [arena_row(arena.width_cm, arena.height_cm, True, variant=layout),
                   pd.DataFrame({"variant": layout, "element": "pellet", "x_cm": pellets[:, 0],
                                 "y_cm": pellets[:, 1], "radius_cm": cfg.physics.pellet_radius_cm})]
    return pd.concat(frames, ignore_index=True)
