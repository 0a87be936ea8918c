"""Fig 1: the model: training loop and sensing schematics, food layouts, fields of EODs distorted by objects and walls,
sensor layout, a scene and its EOD raster (docs/methods/figures.md#panels).

Field panels read the scene tables that ``efish scene`` computes with the physics (``scenes/<name>.parquet``,
columns in :mod:`efish.rollout.scenes`); they reshape and draw, never compute a field. Also here: the
supplement's sensing-range map and interaction sketch, which share these helpers.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import layout
from ..config.schema import AnalysisConfig, EnvConfig, SensorsConfig
from ..senses import SENSES
from . import schematics as sk
from .panel import Panel
from .style import FIELD_CMAP, HEATMAP_CMAP, NEUTRAL_COLOUR, PELLET_COLOUR, RECEPTOR_COLOURS, agent_colour, missing

RECEPTOR_LABELS = {s.name: s.label for s in SENSES}
TARGET_STYLES = {"agent": "-", "pellet": "--"}
#: Sensor rings of panel F, cm outside the body circle: the classes share the circle, drawn apart to be seen.
SENSOR_RINGS_CM = {"mormyromast": 0.0, "ampullary": 0.25, "knollenorgan": 0.5}
SENSOR_MARKERS = {s.name: s.marker for s in SENSES}
TRAIL_STEPS = 40  # panel H: steps of path drawn behind each agent


def scene_input(name: str) -> dict[str, str]:
    """A panel's input: the scene table ``scenes/<name>.parquet``."""
    return {"scene": layout.scene_table(name)}


# ------------------------------------------------------------------- scene rows
def field_grid(scene: pd.DataFrame) -> dict[str, np.ndarray]:
    """The grid rows of a field scene as 2-D arrays (ny, nx): x, y, ex, ey, ex_free, ey_free; NaN inside bodies."""
    grid = scene[scene["element"] == "grid"].sort_values(["y_cm", "x_cm"])
    xs, ys = np.unique(grid["x_cm"]), np.unique(grid["y_cm"])
    if len(grid) != len(xs) * len(ys) or len(grid) == 0:
        raise ValueError(f"scene {scene['scene'].iloc[0]!r} has no regular field grid ({len(grid)} grid rows)")
    water = ~grid["inside_body"].to_numpy()
    out = {"x": xs, "y": ys}
    for key in ("ex", "ey", "ex_free", "ey_free"):
        out[key] = np.where(water, grid[f"{key}_v_m"].to_numpy(), np.nan).reshape(len(ys), len(xs))
    return out


def draw_bodies(ax, scene: pd.DataFrame, label: bool = True) -> None:
    """Agents (colour per agent, in table order; emitters with their poles) and pellets of a scene table."""
    agents = scene[scene["element"].isin(["emitter", "agent"])]
    for i, row in enumerate(agents.itertuples()):
        sk.body(ax, row.x_cm, row.y_cm, row.heading_rad, row.radius_cm, agent_colour(i),
                emitting=row.element == "emitter")
        if label:
            ax.annotate("emitting" if row.element == "emitter" else "silent", (row.x_cm, row.y_cm),
                        xytext=(0, -2.2 * row.radius_cm), textcoords="offset fontsize", ha="center", fontsize=5.5)
    for row in scene[scene["element"] == "pellet"].itertuples():
        sk.pellet(ax, row.x_cm, row.y_cm, row.radius_cm)


def draw_arena(ax, scene: pd.DataFrame) -> None:
    """The arena's walls when the scene mirrors its sources in them; limits to the grid either way."""
    arena = scene[scene["element"] == "arena"]
    grid = scene[scene["element"] == "grid"]
    if len(arena) and bool(arena["walls"].iloc[0]):
        sk.walls(ax, float(arena["width_cm"].iloc[0]), float(arena["height_cm"].iloc[0]))
    ax.set_xlim(grid["x_cm"].min(), grid["x_cm"].max())
    ax.set_ylim(grid["y_cm"].min(), grid["y_cm"].max())
    ax.set_aspect("equal")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")


def log_magnitude(f: dict[str, np.ndarray], free: bool = False) -> np.ndarray:
    """log10 |E| (V/m) on the grid (NaN inside bodies)."""
    ex, ey = (f["ex_free"], f["ey_free"]) if free else (f["ex"], f["ey"])
    with np.errstate(divide="ignore"):
        return np.log10(np.hypot(ex, ey))


def field_lines(ax, f: dict[str, np.ndarray], colour: str = "white", density: float = 1.0) -> None:
    """Streamlines of the total field (Ex, Ey): the field lines."""
    ax.streamplot(f["x"], f["y"], np.ma.masked_invalid(f["ex"]), np.ma.masked_invalid(f["ey"]), color=colour,
                  density=density, linewidth=0.45, arrowsize=0.45, broken_streamlines=True, zorder=2)


def magnitude_map(ax, f: dict[str, np.ndarray], alpha: float = 1.0):
    """log10 |E| as a colour map; limits from the 1st-99th percentiles of the water points."""
    import seaborn as sns

    z = log_magnitude(f)
    lo, hi = np.nanpercentile(z[np.isfinite(z)], [1, 99])
    return ax.pcolormesh(f["x"], f["y"], z, cmap=sns.color_palette(HEATMAP_CMAP, as_cmap=True), vmin=lo, vmax=hi,
                         shading="nearest", alpha=alpha, rasterized=True, zorder=0)


def _colourbar(ax, mappable, label: str, ticks=None, ticklabels=None) -> None:
    bar = ax.figure.colorbar(mappable, ax=ax, shrink=0.8, pad=0.02, aspect=25, ticks=ticks)
    bar.set_label(label, fontsize=6.5)
    bar.ax.tick_params(labelsize=6)
    if ticklabels is not None:
        bar.ax.set_yticklabels(ticklabels)


def _scene_or_missing(tables: dict[str, pd.DataFrame], ax) -> pd.DataFrame | None:
    scene = tables["scene"]
    if scene.empty:
        missing(ax, "the scene table is empty")
        return None
    return scene


# --------------------------------------------------------------- schematics A, B
def training_loop(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel A: the training loop: arenas -> observations -> shared recurrent actor -> actions -> arenas, with
    rewards and all agents' observations feeding the centralised critic and the MAPPO update."""
    sk.blank(ax, (0, 10), (0, 8))
    blue, orange, green, grey = RECEPTOR_COLOURS["mormyromast"], agent_colour(1), agent_colour(2), NEUTRAL_COLOUR
    sk.box(ax, (2.0, 6.6), 3.6, 1.4, "Arenas (vectorised)\nfish, food, walls,\nelectric fields", grey)
    sk.box(ax, (8.0, 6.6), 3.4, 1.4, "Observation per fish\nelectrosensory +\nproprioceptive", blue)
    sk.box(ax, (8.0, 3.6), 3.4, 1.5, "Shared actor\nLayerNorm-MLP-GRU\n(one per fish)", green)
    sk.box(ax, (2.0, 3.6), 3.6, 1.5, "Actions\nmove, turn,\nEOD, bite", orange)
    sk.box(ax, (5.0, 0.9), 5.6, 1.2, "Centralised critic (all observations)\n+ PPO update (GAE, clipping)", grey)
    sk.arrow(ax, (3.85, 6.6), (6.25, 6.6), "sense", offset=(0, 0.35))
    sk.arrow(ax, (8.0, 5.85), (8.0, 4.4))
    sk.arrow(ax, (6.25, 3.6), (3.85, 3.6), "sample", offset=(0, 0.35))
    sk.arrow(ax, (2.0, 4.4), (2.0, 5.85), "step", offset=(-0.55, 0))
    sk.arrow(ax, (1.5, 2.8), (3.0, 1.55), "rewards", rad=0.2, offset=(-0.9, -0.1))
    sk.arrow(ax, (7.0, 1.55), (8.0, 2.8), "gradients", rad=0.2, offset=(0.95, -0.1))
    ax.set_title("Multi-agent training loop (recurrent MAPPO)")


def sensing_schematic(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel B: the three senses of the focal fish (blue, emitting): its own EOD distorted by a pellet and a
    fish (Mormyromasts, active), their intrinsic fields (Ampullary organs, passive), and a conspecific's EOD
    (Knollenorgans). Receptor counts are the config defaults (docs/model/sensors.md)."""
    se = SensorsConfig()
    sk.blank(ax, (-4.0, 14.0), (-6.6, 6.6))
    fy, cx, cy, px, py = 1.5, 10.5, 3.0, 4.2, 2.3  # focal height, conspecific and pellet positions
    sk.dipole_sketch(ax, 0, fy, 0.0, 0.5, (0.5, 1.2, 2.2))
    sk.body(ax, 0, fy, 0.0, 1.0, agent_colour(0), emitting=True)
    for receptor, angle in (("mormyromast", 0.0), ("ampullary", 1.9), ("knollenorgan", -1.9)):
        ax.plot(np.cos(angle), fy + np.sin(angle), SENSOR_MARKERS[receptor], color=RECEPTOR_COLOURS[receptor],
                ms=3.5, mec="black", mew=0.3, zorder=6)
    sk.pellet(ax, px, py, 0.3)
    ax.text(px, py + 0.6, "pellet", ha="center", fontsize=6)
    sk.dipole_sketch(ax, cx, cy, np.pi, 0.5, (0.5, 1.3), colour=agent_colour(1))
    sk.body(ax, cx, cy, np.pi, 1.0, agent_colour(1), emitting=True)
    ax.text(cx, cy + 2.9, "conspecific", ha="center", fontsize=6)
    sk.arrow(ax, (px - 0.4, py - 0.4), (1.3, fy - 0.1), colour=RECEPTOR_COLOURS["mormyromast"])
    sk.arrow(ax, (px - 0.4, py + 0.1), (-0.1, fy + 1.3), colour=RECEPTOR_COLOURS["ampullary"], rad=0.3)
    sk.arrow(ax, (cx - 1.2, cy - 0.6), (0.0, fy - 1.3), colour=RECEPTOR_COLOURS["knollenorgan"], rad=-0.25)
    notes = (("mormyromast", f"Mormyromasts ({se.mormyromast.count}): own EOD distorted by objects (active)"),
             ("ampullary", f"Ampullary ({se.ampullary.count}): intrinsic fields of prey and fish (passive)"),
             ("knollenorgan", f"Knollenorgans ({se.knollenorgan.count} per fish): conspecific EODs"))
    for i, (receptor, text) in enumerate(notes):
        y = -4.0 - 1.0 * i
        ax.plot(-3.4, y, SENSOR_MARKERS[receptor], color=RECEPTOR_COLOURS[receptor], ms=3.5, mec="black", mew=0.3)
        ax.text(-2.9, y, text, va="center", fontsize=5.8)
    ax.set_title("Active, passive and communication senses")


# ------------------------------------------------------------ C: food layouts
def food_layouts(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel C: pellets at the start of one episode of each arena layout, drawn by the env's generators
    (scene food_layouts), each in its own frame at its own scale."""
    scene = _scene_or_missing(tables, ax)
    if scene is None:
        return
    arenas = scene[scene["element"] == "arena"]
    _frame_only(ax, "x (cm)", "y (cm)")
    n = len(arenas)
    cols = 2 if n > 1 else 1
    rows = int(np.ceil(n / cols))
    for i, arena in enumerate(arenas.itertuples()):
        r, c = divmod(i, cols)
        inset = ax.inset_axes([c / cols + 0.06, 1 - (r + 1) / rows + 0.1, 1 / cols - 0.1, 1 / rows - 0.2])
        pellets = scene[(scene["element"] == "pellet") & (scene["variant"] == arena.variant)]
        sk.walls(inset, arena.width_cm, arena.height_cm, lw=1.0)
        inset.scatter(pellets["x_cm"], pellets["y_cm"], s=1.2, color=PELLET_COLOUR, lw=0)
        inset.set_xlim(0, arena.width_cm)
        inset.set_ylim(0, arena.height_cm)
        inset.set_aspect("equal")
        inset.tick_params(labelsize=5, length=2, pad=1)
        inset.set_title(f"{arena.variant}\n{arena.width_cm:.0f} x {arena.height_cm:.0f} cm, {len(pellets)} pellets",
                        fontsize=5.5, pad=2, linespacing=1.1)
    ax.set_title("Food layouts", pad=10)


def _frame_only(ax, xlabel: str, ylabel: str) -> None:
    """An axes that only carries the axis labels for the insets drawn in it."""
    ax.set_xticks([])
    ax.set_yticks([])
    for spine in ax.spines.values():
        spine.set_visible(False)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)


# ------------------------------------------------------------ D, E, G: fields
def field_distortion(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel D: how much objects (pellets, a silent fish) and insulating walls change the EOD field:
    log2 of |E| over the emitter's free-space |E| (scene eod_objects), with the total field's lines."""
    scene = _scene_or_missing(tables, ax)
    if scene is None:
        return
    from matplotlib.colors import Normalize

    f = field_grid(scene)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.log2(np.hypot(f["ex"], f["ey"]) / np.hypot(f["ex_free"], f["ey_free"]))
    mesh = ax.pcolormesh(f["x"], f["y"], z, cmap=FIELD_CMAP, norm=Normalize(-1, 1), shading="nearest",
                         rasterized=True, zorder=0)
    field_lines(ax, f, colour="0.35", density=0.9)
    draw_bodies(ax, scene)
    draw_arena(ax, scene)
    _colourbar(ax, mesh, "|E| / |E free space|", ticks=[-1, -0.5, 0, 0.5, 1],
               ticklabels=["x0.5", "x0.71", "x1", "x1.41", "x2"])
    ax.set_title("EOD field distorted by objects and walls")


def dipole_landscape(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel E: the EOD of one fish near a corner of an arena with insulating walls (scene eod_walls):
    log10 |E| and the field lines, bent by the walls' images."""
    scene = _scene_or_missing(tables, ax)
    if scene is None:
        return
    f = field_grid(scene)
    mesh = magnitude_map(ax, f)
    field_lines(ax, f, colour="white", density=1.1)
    draw_bodies(ax, scene, label=False)
    draw_arena(ax, scene)
    _colourbar(ax, mesh, "log10 |E| (V/m)")
    ax.set_title("EOD dipole field with walls")


def full_scene(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel G: every element at once (scene full_scene): emitting (+/- poles) and silent fish, pellets,
    walls, the summed EOD field (log10 |E|) and its field lines, and the focal fish's eating cone."""
    scene = _scene_or_missing(tables, ax)
    if scene is None:
        return
    f = field_grid(scene)
    mesh = magnitude_map(ax, f, alpha=0.85)
    field_lines(ax, f, colour="white", density=1.2)
    focal = scene[scene["element"].isin(["emitter", "agent"])].iloc[0]
    env = EnvConfig()
    sk.wedge(ax, focal["x_cm"], focal["y_cm"], focal["heading_rad"], np.radians(env.eat_half_angle_deg),
             env.eat_radius_cm + focal["radius_cm"], "white", alpha=0.5)
    draw_bodies(ax, scene, label=False)  # emitters carry their poles (+ ahead); a label would hide the field
    draw_arena(ax, scene)
    _colourbar(ax, mesh, "log10 |E| (V/m)")
    ax.set_title("Scene: fish, food, walls, fields")


# ------------------------------------------------------------ F: sensor layout
def sensor_layout(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel F: where each receptor class sits on the body (scene sensor_layout, from the physics' sensor
    geometry); all sit on the body circle, drawn on rings SENSOR_RINGS_CM outside it to be told apart."""
    scene = _scene_or_missing(tables, ax)
    if scene is None:
        return
    fish = scene[scene["element"].isin(["emitter", "agent"])].iloc[0]
    cx, cy, radius = fish["x_cm"], fish["y_cm"], fish["radius_cm"]
    sk.body(ax, 0.0, 0.0, fish["heading_rad"], radius, "0.9", emitting=True, zorder=2, pole_colour="black")
    for receptor, rows in scene[scene["element"] == "sensor"].groupby("receptor", sort=False):
        scale = (radius + SENSOR_RINGS_CM[receptor]) / radius
        ax.scatter((rows["x_cm"] - cx) * scale, (rows["y_cm"] - cy) * scale, s=9, marker=SENSOR_MARKERS[receptor],
                   color=RECEPTOR_COLOURS[receptor], edgecolors="black", linewidths=0.2, zorder=5,
                   label=f"{RECEPTOR_LABELS[receptor]} ({len(rows)})")
    reach = radius + max(SENSOR_RINGS_CM.values()) + 0.4
    ax.set_xlim(-reach, reach + 1.8)
    ax.set_ylim(-reach, reach)
    ax.set_aspect("equal")
    ax.set_xlabel("x, body frame (cm)")
    ax.set_ylabel("y, body frame (cm)")
    ax.legend(loc="center right", fontsize=5.5, handletextpad=0.2, borderaxespad=0.1)
    ax.set_title("Sensor layout (heading +x)")


# --------------------------------------------------- H: snapshot and EOD raster
def snapshot_raster(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel H: one patchy4 episode (first condition, first episode): the agents and live pellets at its
    middle step with their recent paths (left) and every agent's EODs over time (right; dashed: that step)."""
    steps, food = tables["steps"], tables["food"]
    if steps.empty:
        missing(ax, "the patchy4 steps table is empty")
        return
    condition = min(steps["condition"].unique())
    episode = steps.loc[steps["condition"] == condition, "episode"].min()
    run = steps[(steps["condition"] == condition) & (steps["episode"] == episode)].sort_values("t")
    t_snap = int(run["t"].quantile(0.5, interpolation="nearest"))
    ax.set_axis_off()
    left, right = ax.inset_axes([0.0, 0.0, 0.47, 0.92]), ax.inset_axes([0.62, 0.0, 0.38, 0.92])
    pellets = food[(food["condition"] == condition) & (food["episode"] == episode)]
    _snapshot(left, run, pellets, t_snap)
    _raster(right, run, t_snap)
    left.set_title(f"patchy4 {condition} ep. {episode}, t = "
                   f"{run.loc[run['t'] == t_snap, 't_ms'].iloc[0] / 1000:.2f} s", fontsize=7, pad=3)


def _snapshot(ax, run: pd.DataFrame, pellets: pd.DataFrame, t: int) -> None:
    alive = pellets[(pellets["t_spawned"] <= t) & ((pellets["t_eaten"] < 0) | (pellets["t_eaten"] > t))]
    ax.scatter(alive["x_cm"], alive["y_cm"], s=2, color=PELLET_COLOUR, lw=0, zorder=1)
    for agent, path in run.groupby("agent"):
        trail = path[(path["t"] <= t) & (path["t"] > t - TRAIL_STEPS)]
        ax.plot(trail["x_cm"], trail["y_cm"], color=agent_colour(agent), lw=0.6, alpha=0.7)
        now = trail[trail["t"] == t]
        if len(now):  # a marker on top of the true-size body: a 1 cm fish is a dot in a 70 cm arena
            x, y, heading = now["x_cm"].iloc[0], now["y_cm"].iloc[0], now["heading_rad"].iloc[0]
            ax.plot(x, y, "o", ms=4, color=agent_colour(agent), mec="black", mew=0.4, zorder=4)
            ax.annotate("", xy=(x + 4 * np.cos(heading), y + 4 * np.sin(heading)), xytext=(x, y),
                        arrowprops={"arrowstyle": "-|>", "lw": 0.6, "color": "black", "mutation_scale": 5}, zorder=5)
    xy = pd.concat([run[["x_cm", "y_cm"]], pellets[["x_cm", "y_cm"]]])
    ax.set_xlim(xy["x_cm"].min() - 2, xy["x_cm"].max() + 2)
    ax.set_ylim(xy["y_cm"].min() - 2, xy["y_cm"].max() + 2)
    ax.set_aspect("equal")
    ax.tick_params(labelsize=6)
    ax.set_xlabel("x (cm)", fontsize=7)
    ax.set_ylabel("y (cm)", fontsize=7)


def _raster(ax, run: pd.DataFrame, t: int) -> None:
    agents = sorted(run["agent"].unique())
    times = [run.loc[(run["agent"] == a) & run["eod"], "t_ms"].to_numpy() / 1000 for a in agents]
    ax.eventplot(times, lineoffsets=range(len(agents)), linelengths=0.7, linewidths=0.5,
                 colors=[agent_colour(a) for a in agents])
    ax.axvline(run.loc[run["t"] == t, "t_ms"].iloc[0] / 1000, color="black", ls="--", lw=0.6)
    ax.set_yticks(range(len(agents)), [str(a) for a in agents])
    ax.set_xlim(0, run["t_ms"].max() / 1000)
    ax.tick_params(labelsize=6)
    ax.set_xlabel("time (s)", fontsize=7)
    ax.set_ylabel("agent (EODs)", fontsize=7)


# ------------------------------------------------------------- supplement
def sensing_range(tables: dict[str, pd.DataFrame], ax) -> None:
    """Supplement: where each receptor class of an emitting fish (centre, heading +x) detects a pellet
    (dashed) or an emitting fish facing it (solid): the contour max |reading| = threshold (scene
    sensing_range, brute-force physics, noise off); the inset zooms out to the Knollenorgan range."""
    scene = _scene_or_missing(tables, ax)
    if scene is None:
        return
    grid = scene[scene["element"] == "grid"]
    near = grid[grid["receptor"] != "knollenorgan"]
    reach_near = 1.3 * _detected_reach(near)
    _range_contours(ax, grid[grid["receptor"] != "knollenorgan"])
    sk.body(ax, 0, 0, 0.0, 1.0, "0.85", emitting=True)
    ax.set_xlim(-reach_near, reach_near)
    ax.set_ylim(-reach_near, reach_near)
    ax.set_aspect("equal")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")
    far = grid[grid["receptor"] == "knollenorgan"]
    if len(far):
        inset = ax.inset_axes([1.08, 0.5, 0.5, 0.5])
        _range_contours(inset, grid)
        reach_far = 1.2 * _detected_reach(far)
        inset.set_xlim(-reach_far, reach_far)
        inset.set_ylim(-reach_far, reach_far)
        inset.set_aspect("equal")
        inset.tick_params(labelsize=5, length=2, pad=1)
        inset.set_title("zoomed out (cm)", fontsize=6, pad=2)
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=RECEPTOR_COLOURS[r], label=RECEPTOR_LABELS[r]) for r in RECEPTOR_LABELS
               if r in set(grid["receptor"])]
    handles += [Line2D([], [], color="black", ls=ls, label=t) for t, ls in TARGET_STYLES.items()
                if t in set(grid["variant"])]
    ax.legend(handles=handles, loc="lower left", bbox_to_anchor=(1.02, 0.0), fontsize=6, handlelength=1.8,
              borderaxespad=0.0)
    ax.set_title("Detection range")


def _detected_reach(grid: pd.DataFrame) -> float:
    """Largest target distance still detected (ratio >= 1) in ``grid``, cm (the farthest sampled if none)."""
    hit = grid[grid["ratio"] >= 1]
    return float(hit["distance_cm"].max() if len(hit) else grid["distance_cm"].max())


def _range_contours(ax, grid: pd.DataFrame) -> None:
    """The ratio = 1 contour of each (receptor, target) on its polar grid (distance x bearing), closed."""
    for (receptor, target), rows in grid.groupby(["receptor", "variant"]):
        rows = rows.sort_values(["distance_cm", "bearing_rad"])
        n_r, n_a = rows["distance_cm"].nunique(), rows["bearing_rad"].nunique()
        shape = (n_r, n_a)
        x, y, z = (rows[c].to_numpy().reshape(shape) for c in ("x_cm", "y_cm", "ratio"))
        x, y, z = (np.concatenate([a, a[:, :1]], axis=1) for a in (x, y, z))  # close the circle
        with np.errstate(divide="ignore", invalid="ignore"):
            ax.contour(x, y, np.log10(z), levels=[0.0], colors=[RECEPTOR_COLOURS[receptor]],
                       linestyles=[TARGET_STYLES.get(target, "-")], linewidths=0.9)


def interaction_sketch(tables: dict[str, pd.DataFrame], ax) -> None:
    """Supplement: the pair labels of the interaction analysis (docs/methods/analyses.md#analysis-interactions): i faces
    j when |heading - bearing to j| <= facing_rad (shaded cone), faces away when >= away_rad; thresholds are
    the analysis defaults."""
    cfg = AnalysisConfig()
    sk.blank(ax, (-3.0, 21.0), (-11.5, 5.0))
    cases = (("confronting", 0.0, np.pi), ("chasing: i chases,\nj flees", 0.0, 0.0),
             ("dispersing", np.pi, 0.0), ("unaligned", np.pi / 2, np.pi))
    gap = 6.0  # cm between i and j
    for k, (label, heading_i, heading_j) in enumerate(cases):
        x0, y0 = 12.0 * (k % 2), -8.0 * (k // 2)
        ax.plot([x0, x0 + gap], [y0, y0], color=NEUTRAL_COLOUR, lw=0.5, ls=":", zorder=0)
        for name, x, heading, colour in (("i", x0, heading_i, agent_colour(0)),
                                         ("j", x0 + gap, heading_j, agent_colour(1))):
            sk.wedge(ax, x, y0, heading, cfg.facing_rad, 2.5, colour, alpha=0.25)
            sk.body(ax, x, y0, heading, 0.8, colour)
            ax.text(x, y0 + (-1.9 if np.sin(heading) > 0.5 else 1.3), name, ha="center", fontsize=6.5)
        ax.text(x0 + gap / 2, y0 - 2.2, label, ha="center", va="top", fontsize=6.5)
    ax.text(9.0, 4.6, f"shaded: facing cone, |heading - bearing to partner| <= {np.degrees(cfg.facing_rad):.0f} deg"
            f"\nfacing away: >= {np.degrees(cfg.away_rad):.0f} deg", ha="center", va="top", fontsize=6)
    ax.set_title("Interaction labels of a pair")


PANELS: list[Panel] = [
    Panel("fig1", "A", training_loop, {}, "Schematic of the training loop: vectorised arenas give every fish an "
          "observation; one shared recurrent actor acts for all; a centralised critic and the PPO update learn from "
          "the rewards (docs/methods/training.md#mappo). No table."),
    Panel("fig1", "B", sensing_schematic, {}, "Schematic of the three senses: the focal fish's own EOD distorted "
          "by objects (Mormyromasts), intrinsic fields (Ampullary organs) and a conspecific's EOD (Knollenorgans); "
          "receptor counts are the config defaults (docs/model/sensors.md). No table."),
    Panel("fig1", "C", food_layouts, scene_input("food_layouts"), "Pellets at the start of one episode of each "
          "arena layout (training, patchy, uniform, N-patch), drawn by the environment's generators; table "
          "scenes/food_layouts.parquet (efish scene food_layouts)."),
    Panel("fig1", "D", field_distortion, scene_input("eod_objects"), "Field of an emitting fish near a wall with "
          "three pellets and a silent fish: colour = |E| with induced dipoles and wall images over the emitter's "
          "free-space |E| (log scale), lines = field lines; table scenes/eod_objects.parquet, computed by the "
          "physics (efish scene eod_objects)."),
    Panel("fig1", "E", dipole_landscape, scene_input("eod_walls"), "EOD dipole landscape of a fish near a corner "
          "of an arena with insulating walls: log10 |E| (V/m) and field lines; table scenes/eod_walls.parquet "
          "(efish scene eod_walls)."),
    Panel("fig1", "F", sensor_layout, scene_input("sensor_layout"), "Positions of the Mormyromasts, Ampullary "
          "organs and Knollenorgans on the body circle (docs/model/sensors.md), drawn on offset rings to tell them "
          "apart; table scenes/sensor_layout.parquet (efish scene sensor_layout)."),
    Panel("fig1", "G", full_scene, scene_input("full_scene"), "A scene with every element: two emitting fish "
          "(+/- poles), a silent one, pellets, walls, the summed EOD field (log10 |E|) with field lines and the focal fish's eating "
          "cone; table scenes/full_scene.parquet (efish scene full_scene)."),
    Panel("fig1", "H", snapshot_raster, {"steps": layout.assay_table("patchy4", "steps"),
                                         "food": layout.assay_table("patchy4", "food")},
          "One patchy4 episode (first condition and episode): positions, recent paths and live pellets at its middle "
          "step, and the EOD raster of every agent; tables assays/patchy4/steps.parquet and food.parquet."),
    Panel("supp", "sensing_range", sensing_range, scene_input("sensing_range"), "Detection range of each receptor "
          "class around an emitting fish: contour where the largest raw reading equals the class's threshold (E_min; "
          "Knollenorgan spike threshold) for a pellet (dashed) or a facing, emitting fish (solid); inset: the "
          "Knollenorgan range; table scenes/sensing_range.parquet (efish scene sensing_range, noise off)."),
    Panel("supp", "interaction_sketch", interaction_sketch, {}, "Schematic of the pair labels of the interaction "
          "analysis (docs/methods/analyses.md#analysis-interactions): confronting, chasing / fleeing, dispersing "
          "and unaligned, from each fish's heading relative to the bearing of the other (facing cone pi/4, facing "
          "away 3 pi/4). No table."),
]
