"""Episode clips: one episode of an assay redrawn step by step from its rollout tables (``efish render``).

Each frame shows the arena walls, every body (a fish-shaped marker pointing
along its heading, larger for a larger size ``s``, with its path so far),
the pellets alive at that step (the food table's ``t_spawned``/``t_eaten``),
a ring around every agent that discharged an EOD at that step, a line from
biter to victim for every successful bite, and, on request, the magnitude of
the field of the EODs discharged at that step, computed by
:mod:`efish.physics` on a coarse grid (with the arena's wall images). Nothing
is simulated again: positions, headings, discharges and bites are the steps
table's. :func:`draw_frame` draws one step and returns its artists, so the
tests (and the clip writer) can count and remove them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..config.recorded import recorded_conditions
from ..config.schema import EfishConfig
from ..drawing import BODY_PT, FRAME_DPI, body_marker, draw_bodies, draw_pellets, draw_walls, frame_size
from ..io import atomic_path, read_parquet
from ..units import CM
from .clip_file import BlitFrames, clip_encoder, clip_file
from .style import HEATMAP_CMAP, NEUTRAL_COLOUR, PELLET_COLOUR, agent_colour, panel_style

#: GIF frame delays are whole centiseconds and browsers slow delays under 2 cs down, so a GIF plays at most
#: 50 frames per second: a clip of a faster simulation draws every k-th step to stay in real time.
GIF_MAX_FPS = 50.0
#: Frames of a clip by default at most (longer episodes draw every k-th step): a GIF of 400 frames of this
#: size is a few MB, small enough for the Snakemake report.
MAX_FRAMES = 400
FIELD_CELLS = 60  # cells of the field overlay along the arena's longer side


@dataclass(frozen=True)
class Episode:
    """One episode of one condition, as arrays over (frame step, agent); ``cfg`` is the condition's config as the
    run recorded it (arena size, fps, physics of the field overlay)."""

    assay: str
    condition: str
    episode: int
    cfg: EfishConfig
    t: np.ndarray            # int[T]      step index of each row of the arrays below
    agents: np.ndarray       # int[N]      agent ids
    xy: np.ndarray           # float[T, N, 2]  cm, NaN where an agent has no row
    heading: np.ndarray      # float[T, N]     rad
    size: np.ndarray         # float[T, N]     in [0, 1]
    eod: np.ndarray          # bool[T, N]      discharged at this step
    bit: np.ndarray          # bool[T, N]      bit another agent at this step
    bite_target: np.ndarray  # int[T, N]       column index (into agents) of the bitten agent, -1 none or unknown
    food: pd.DataFrame       # this episode's rows of the food table

    @property
    def fps(self) -> float:
        return float(self.cfg.env.fps)

    def pellets_at(self, t: int) -> pd.DataFrame:
        """Pellets alive after step ``t``: spawned at or before it and not eaten at or before it."""
        f = self.food
        return f[(f["t_spawned"] <= t) & ((f["t_eaten"] < 0) | (f["t_eaten"] > t))]

    def eaten_at(self, t: int) -> pd.DataFrame:
        """Pellets eaten at step ``t`` (drawn once more, as a ring in the eater's colour)."""
        return self.food[self.food["t_eaten"] == t]


# ------------------------------------------------------------------ loading
def load_episode(tables: Path, overrides: Sequence[str], cfg: EfishConfig, condition: str | None = None,
                 episode: int | None = None) -> Episode:
    """Episode ``episode`` of ``condition`` of the assay in ``cfg`` from ``tables/steps.parquet`` and
    ``food.parquet``, drawn with the condition's config as the run recorded it in ``tables/conditions.parquet``
    (with every override the run had); ``condition`` defaults to the assay's first, ``episode`` to the
    condition's first. ``cfg`` names the assay the tables must be; ``overrides`` is not used any more (nothing is
    composed: the record is the run's) and stays for the callers that pass it."""
    del overrides  # the recorded conditions carry the run's overrides
    tables = Path(tables)
    paths = {name: tables / f"{name}.parquet" for name in ("steps", "food")}
    absent = [str(p) for p in paths.values() if not p.is_file()]
    if absent:
        raise ValueError(f"missing rollout table(s) {', '.join(absent)}: run efish assay first or pass --tables")
    check_assay(tables, cfg.assay.name)
    configs = recorded_assay(tables, cfg.assay.name)
    steps = read_parquet(paths["steps"], "a steps table")
    food = read_parquet(paths["food"], "a food table")
    condition = condition if condition is not None else next(iter(configs), None)
    held = list(dict.fromkeys(steps["condition"]))
    if condition not in held:
        raise ValueError(f"unknown condition {condition!r}: the tables in {tables} hold "
                         f"{', '.join(map(str, held)) or 'no steps'}")
    rows = steps[steps["condition"] == condition]
    episodes = np.unique(rows["episode"].to_numpy())
    episode = int(episodes[0]) if episode is None else int(episode)
    if episode not in episodes:
        raise ValueError(f"condition {condition} has no episode {episode}: it has episodes {spans(episodes)}")
    return episode_from_tables(rows[rows["episode"] == episode],
                               food[(food["condition"] == condition) & (food["episode"] == episode)],
                               condition_config(configs, cfg.assay.name, condition), condition, episode)


def check_assay(tables: Path, assay: str) -> None:
    """The tables must be assay ``assay``'s: their folder's config.yaml (written beside them by efish assay)
    names the assay, and another assay's arena would put every body in the wrong place."""
    from omegaconf import OmegaConf

    path = tables / "config.yaml"
    if not path.is_file():
        return  # tables written by hand (tests, notebooks) carry no config to check against
    written = OmegaConf.select(OmegaConf.load(path), "assay.name")
    if written is not None and written != assay:
        raise ValueError(f"the tables in {tables} are assay {written}'s (its config.yaml), not {assay}'s: "
                         f"pass assay={written}")


def recorded_assay(tables: Path, assay: str) -> dict[str, EfishConfig]:
    """Condition -> its config as the run resolved it, in the assay's order, from ``tables/conditions.parquet``
    (written by efish assay beside steps and food). The record must be assay ``assay``'s: another assay's arena
    would put every body in the wrong place."""
    path = Path(tables) / "conditions.parquet"
    if not path.is_file():
        raise ValueError(f"missing {path}: the clip draws each condition as the run recorded it, and these tables "
                         "were written before efish assay recorded its conditions: rerun the assay")
    configs = dict(recorded_conditions(read_parquet(path, "a conditions table"), str(path)))
    written = {c.assay.name for c in configs.values()}
    if written and written != {assay}:
        raise ValueError(f"the tables in {tables} are assay {', '.join(sorted(written))}'s (its conditions.parquet), "
                         f"not {assay}'s: pass assay={min(written)}")
    return configs


def condition_config(configs: Mapping[str, EfishConfig], assay: str, condition: str) -> EfishConfig:
    """The recorded config of one condition of the assay (arena size, agents, physics differ between
    conditions); ``configs`` is :func:`recorded_assay`'s."""
    if condition not in configs:
        raise ValueError(f"condition {condition!r} is not one of assay {assay}'s recorded conditions "
                         f"({', '.join(configs)}): pass the assay of these tables (assay=<name>)")
    return configs[condition]


def episode_from_tables(steps: pd.DataFrame, food: pd.DataFrame, cfg: EfishConfig, condition: str,
                        episode: int) -> Episode:
    """Arrays of one episode's steps rows (one row per step and agent)."""
    if steps.empty:
        raise ValueError(f"condition {condition}, episode {episode}: the steps table has no rows")
    agents = np.unique(steps["agent"].to_numpy()).astype(np.int64)
    wide = steps.pivot(index="t", columns="agent")  # duplicate (t, agent) rows raise a ValueError here

    def grid(column: str, fill, dtype) -> np.ndarray:
        return wide[column].reindex(columns=agents).fillna(fill).to_numpy().astype(dtype)

    # bite_target holds agent ids; the arrays are indexed by column (-1: no bite, or an older table without it)
    target = grid("bite_target", -1, np.int64) if "bite_target" in steps else np.full((len(wide), len(agents)), -1)
    column = np.clip(np.searchsorted(agents, target), 0, len(agents) - 1)
    target = np.where((target >= 0) & (agents[column] == target), column, -1)
    return Episode(
        assay=cfg.assay.name, condition=condition, episode=int(episode), cfg=cfg,
        t=wide.index.to_numpy().astype(np.int64), agents=agents,
        xy=np.stack([grid("x_cm", np.nan, float), grid("y_cm", np.nan, float)], axis=-1),
        heading=grid("heading_rad", 0.0, float), size=grid("size", np.nan, float),
        eod=grid("eod", False, bool), bit=grid("bit", False, bool), bite_target=target,
        food=food.reset_index(drop=True))


def spans(values: Iterable[int]) -> str:
    """Integers as compact ranges: ``[0, 1, 2, 5]`` -> ``"0-2, 5"`` (an assay may hold 100 episodes)."""
    values = sorted(int(v) for v in values)
    parts, start = [], None
    for i, v in enumerate(values):
        start = v if start is None else start
        if i + 1 == len(values) or values[i + 1] != v + 1:
            parts.append(str(v) if v == start else f"{start}-{v}")
            start = None
    return ", ".join(parts)


# --------------------------------------------------------------- the field
class FieldOverlay:
    """log10 |E| on a coarse grid over the arena at a step: the field of the EODs discharged at that step,
    with the dipoles they induce on the other bodies and pellets and every source's wall images, computed by
    the physics as the Fig 1 scenes compute it (:func:`efish.rollout.scenes.scene_field`). The colour range
    runs from the Knollenorgan threshold (weaker fields stay clear: no conspecific hears them) to the
    Mormyromast range's upper end."""

    def __init__(self, ep: Episode, cells: int = FIELD_CELLS):
        cfg = ep.cfg
        self.width, self.height = float(cfg.arena.width_cm), float(cfg.arena.height_cm)
        step = max(self.width, self.height) / cells
        self.xs = np.arange(step / 2, self.width, step)
        self.ys = np.arange(step / 2, self.height, step)
        gx, gy = np.meshgrid(self.xs, self.ys)
        self.points_m = np.column_stack([gx.ravel(), gy.ravel()]) * CM
        self.vmin = math.log10(cfg.sensors.knollenorgan.threshold)
        self.vmax = math.log10(cfg.sensors.mormyromast.e_max)

    def log_magnitude(self, ep: Episode, i: int) -> np.ndarray:
        """log10 |E| (V/m) on the grid [ny, nx] at row ``i`` of ``ep`` (-inf where the field vanishes)."""
        from ..rollout.scenes import scene_field  # the simulator is loaded only for this overlay

        here = np.isfinite(ep.xy[i]).all(axis=1)
        pellets = ep.pellets_at(int(ep.t[i]))
        bodies = pd.DataFrame({
            "element": np.r_[np.where(ep.eod[i][here], "emitter", "agent"), np.full(len(pellets), "pellet")],
            "x_cm": np.r_[ep.xy[i][here, 0], pellets["x_cm"]], "y_cm": np.r_[ep.xy[i][here, 1], pellets["y_cm"]],
            "heading_rad": np.r_[ep.heading[i][here], np.zeros(len(pellets))]})
        total, _ = scene_field(self.points_m, bodies, ep.cfg, walls=True,
                               arena_m=(self.width * CM, self.height * CM))
        with np.errstate(divide="ignore"):
            return np.log10(np.hypot(total[:, 0], total[:, 1])).reshape(len(self.ys), len(self.xs))


# ----------------------------------------------------------------- drawing
def draw_arena(fig, ax, ep: Episode, overlay: FieldOverlay | None = None):
    """What stays the same in every frame: walls, axes, title, legend, the field's colour bar. Returns the
    text artist that shows the time (updated per frame)."""
    from matplotlib.lines import Line2D

    draw_walls(ax, float(ep.cfg.arena.width_cm), float(ep.cfg.arena.height_cm))
    ax.set_title(f"{ep.assay} · {ep.condition} · episode {ep.episode}", loc="left")
    # legend markers at one size: the body sizes are in the labels
    handles = [Line2D([], [], ls="", marker=body_marker(0.0), ms=BODY_PT, color=agent_colour(a), mec="black",
                      mew=0.5, label=f"agent {a}, size {s:.2f}") for a, s in zip(ep.agents, _first_finite(ep.size),
                                                                                strict=True)]
    handles.append(Line2D([], [], ls="", marker="o", color=NEUTRAL_COLOUR, alpha=0.3, ms=BODY_PT, label="EOD"))
    if len(ep.food):
        handles.append(Line2D([], [], ls="", marker=".", color=PELLET_COLOUR, label="pellet"))
    if ep.bit.any():
        handles.append(Line2D([], [], color="black", lw=1.2, marker="x", label="bite"))
    if _home_agent(ep) is not None:
        handles.append(Line2D([], [], ls="", marker="o", mfc="none", mec=NEUTRAL_COLOUR, ms=BODY_PT,
                              label=f"home ({ep.cfg.env.homing_radius_cm:g} cm)"))
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4), fontsize=6)
    if overlay is not None:
        import matplotlib as mpl

        scale = mpl.cm.ScalarMappable(mpl.colors.Normalize(overlay.vmin, overlay.vmax), HEATMAP_CMAP)
        fig.colorbar(scale, ax=ax, shrink=0.7, aspect=25, label="log$_{10}$ |E| of the EODs (V/m)")
    return ax.text(1.0, 1.01, _clock(ep, int(ep.t[-1])), transform=ax.transAxes, ha="right", va="bottom",
                   fontsize=7)


def draw_frame(ax, ep: Episode, i: int, overlay: FieldOverlay | None = None) -> dict[str, list]:
    """Draw row ``i`` of ``ep`` (step ``ep.t[i]``) on ``ax``; return the artists by kind (``field``,
    ``trails``, ``pellets``, ``eaten``, ``home``, ``flashes``, ``bites``, ``bodies``), so a caller can check
    or remove them. Pellets are one scatter (its offsets are the pellets alive after the step)."""
    from matplotlib.patches import Circle

    t = int(ep.t[i])
    xy = ep.xy[i]
    here = np.isfinite(xy).all(axis=1)
    out: dict[str, list] = {k: [] for k in ("field", "trails", "pellets", "eaten", "home", "flashes", "bites",
                                            "bodies")}
    emit = ep.eod[i] & here
    if overlay is not None and emit.any():
        field = np.ma.masked_less(overlay.log_magnitude(ep, i), overlay.vmin)
        out["field"].append(ax.imshow(field, origin="lower", extent=(0, overlay.width, 0, overlay.height),
                                      cmap=HEATMAP_CMAP, vmin=overlay.vmin, vmax=overlay.vmax, alpha=0.7,
                                      interpolation="bilinear", zorder=0))
    for k, agent in enumerate(ep.agents):
        out["trails"] += ax.plot(ep.xy[: i + 1, k, 0], ep.xy[: i + 1, k, 1], color=agent_colour(agent), lw=0.6,
                                 alpha=0.4, zorder=1)
    out["pellets"].append(draw_pellets(ax, ep.pellets_at(t)[["x_cm", "y_cm"]].to_numpy(float)))
    for _, row in ep.eaten_at(t).iterrows():
        out["eaten"] += ax.plot(row["x_cm"], row["y_cm"], ls="", marker="o", mfc="none", ms=6, mew=1.2,
                                mec=agent_colour(row["eaten_by"]), zorder=2)
    target = _home_agent(ep)
    if target is not None and here[target]:
        out["home"].append(ax.add_patch(Circle(xy[target], ep.cfg.env.homing_radius_cm, fill=False, ls="--",
                                               lw=0.8, color=NEUTRAL_COLOUR, zorder=1)))
    out.update(draw_bodies(ax, ep.agents, xy, ep.heading[i], ep.size[i], emit, ep.bit[i], ep.bite_target[i]))
    return out


def _clock(ep: Episode, t: int) -> str:
    return f"step {t} · {t / ep.fps:.2f} s"


def _first_finite(values: np.ndarray) -> np.ndarray:
    """Each agent's first finite value over the episode (sizes are constant within an episode)."""
    ok = np.isfinite(values)
    return np.where(ok.any(axis=0), values[ok.argmax(axis=0), np.arange(values.shape[1])], np.nan)


def _home_agent(ep: Episode) -> int | None:
    """Column of the homing target (drawn with its home radius), None outside the homing task."""
    if ep.cfg.env.task != "homing":
        return None
    hits = np.flatnonzero(ep.agents == ep.cfg.env.homing_target)
    return int(hits[0]) if len(hits) else None


# ----------------------------------------------------------------- writing
def frame_rows(ep: Episode, every: int | None, suffix: str) -> np.ndarray:
    """Rows of ``ep`` drawn as frames: every ``every``-th step and the last; by default the smallest stride that
    keeps a GIF in real time (at most GIF_MAX_FPS) and the clip near MAX_FRAMES frames."""
    if every is None:
        every = max(1, math.ceil(len(ep.t) / MAX_FRAMES),
                    math.ceil(ep.fps / GIF_MAX_FPS) if suffix == ".gif" else 1)
    if every < 1:
        raise ValueError(f"--every must be at least 1, got {every}")
    return np.unique(np.r_[np.arange(0, len(ep.t), every), len(ep.t) - 1])  # the last step too: how it ends


def render_clip(ep: Episode, out: Path, every: int | None = None, fps: float | None = None, field: bool = False,
                progress: Callable[[list], Iterable] | None = None) -> int:
    """Write ``ep`` as an animation to ``out`` (``.gif`` with Pillow, ``.mp4`` with ffmpeg), atomically;
    ``fps`` defaults to real time (env.fps over the stride). ``progress`` wraps the list of frames (a bar).
    Each frame is drawn over the figure's saved background (:class:`~efish.figures.clip_file.BlitFrames`).
    Returns the number of frames."""
    out = Path(out)
    clip_encoder(out)
    rows = frame_rows(ep, every, out.suffix.lower())
    fps = ep.fps * len(rows) / len(ep.t) if fps is None else float(fps)
    if not fps > 0:
        raise ValueError(f"--fps must be positive, got {fps}")
    overlay = FieldOverlay(ep) if field else None
    with panel_style() as plt:
        fig = plt.figure(figsize=frame_size(float(ep.cfg.arena.width_cm), float(ep.cfg.arena.height_cm), field),
                         dpi=FRAME_DPI, layout="constrained")
        ax = fig.add_subplot()
        clock = draw_arena(fig, ax, ep, overlay)
        fig.canvas.draw()
        fig.set_layout_engine("none")  # lay out once: the axes must not move between frames
        frames = BlitFrames(fig, ax, moving=[clock])
        with atomic_path(out) as tmp:
            writer = clip_file(tmp, fps)
            for i in (progress(list(rows)) if progress else rows):
                artists = [a for group in draw_frame(ax, ep, int(i), overlay).values() for a in group]
                clock.set_text(_clock(ep, int(ep.t[i])))
                writer.write(frames.grab(artists))
                for artist in artists:
                    artist.remove()
            writer.close()
        plt.close(fig)
    return len(rows)
