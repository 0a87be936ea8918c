"""How one arena looks at one instant: walls, pellets, bodies, EOD rings and bites, drawn with matplotlib.

The episode clips of ``efish render`` (:mod:`efish.figures.episode`, from the rollout tables) and the live
PettingZoo env's ``render()`` (:mod:`efish.env.pz`, from the engine's state) draw an arena with these functions,
so a live frame looks like a clip's. They sit in the ground layer because the env may not import the figures and
the figures may not load the simulator; matplotlib is imported only when something is drawn.
"""

from __future__ import annotations

import numpy as np

#: One colour per agent id, the same in every panel, clip and rendered frame.
AGENT_COLOURS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#000000")
#: Food pellets wherever they are drawn (episode clips, scenes, rendered frames): brown, apart from every agent colour.
PELLET_COLOUR = "#8c564b"
#: Body marker length in points at size 0 (at size s: times 1 + s); bodies are drawn at a fixed display size
#: because the true 1 cm radius is a few pixels in a 150 cm arena.
BODY_PT = 9.0
FRAME_WIDTH_IN = 4.5
FRAME_DPI = 100


def agent_colour(agent: int) -> str:
    """The colour of agent ``agent`` in every panel."""
    return AGENT_COLOURS[int(agent) % len(AGENT_COLOURS)]


def frame_size(width_cm: float, height_cm: float, colour_bar: bool = False) -> tuple[float, float]:
    """A frame's figure size in inches: FRAME_WIDTH_IN wide, the arena keeping its aspect (at most 1.5 tall to
    wide); about 1.3 in hold the title, the x axis and a legend, 0.8 in a colour bar beside the arena."""
    axes_width = 0.85 * FRAME_WIDTH_IN - (0.8 if colour_bar else 0.0)
    return FRAME_WIDTH_IN, axes_width * min(height_cm / width_cm, 1.5) + 1.3


def body_marker(heading: float):
    """A fish-shaped marker (pointed snout at +x) turned to ``heading``; display angles equal data angles
    because the arena is drawn with equal aspect."""
    from matplotlib.markers import MarkerStyle
    from matplotlib.path import Path as MplPath
    from matplotlib.transforms import Affine2D

    outline = MplPath([(1.0, 0.0), (0.35, 0.42), (-0.55, 0.32), (-1.0, 0.0), (-0.55, -0.32), (0.35, -0.42),
                       (1.0, 0.0)], closed=True)
    return MarkerStyle(outline, transform=Affine2D().rotate(heading))


def draw_walls(ax, width_cm: float, height_cm: float) -> None:
    """The arena's walls, with a small margin around them, at equal aspect and labelled in cm."""
    from matplotlib.patches import Rectangle

    ax.add_patch(Rectangle((0, 0), width_cm, height_cm, fill=False, lw=1.5, color="black", zorder=5))
    pad = 0.02 * max(width_cm, height_cm)
    ax.set_xlim(-pad, width_cm + pad)
    ax.set_ylim(-pad, height_cm + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")


def draw_pellets(ax, xy: np.ndarray):
    """The pellets at ``xy`` (cm, [P, 2]) as one scatter, returned (its offsets are the pellets drawn)."""
    return ax.scatter(xy[:, 0], xy[:, 1], s=6, color=PELLET_COLOUR, lw=0, zorder=2)


def draw_bodies(ax, agents: np.ndarray, xy: np.ndarray, heading: np.ndarray, size: np.ndarray, eod: np.ndarray,
                bit: np.ndarray, bite_target: np.ndarray) -> dict[str, list]:
    """Every agent with a finite position at one instant: a ring for a discharged EOD (``flashes``), a line from
    biter to victim and a mark on the victim for a successful bite (``bites``; ``bite_target`` is an index into
    these arrays, -1 none), and its body in its id's colour, larger for a larger size (``bodies``). Arrays are
    [N] (``xy`` [N, 2]); ``agents`` holds the ids that pick the colours. Returns the artists by kind."""
    here = np.isfinite(xy).all(axis=1)
    out: dict[str, list] = {"flashes": [], "bites": [], "bodies": []}
    for k in np.flatnonzero(here):
        colour, s = agent_colour(agents[k]), size[k]
        if eod[k]:
            out["flashes"] += ax.plot(*xy[k], ls="", marker="o", mfc=colour, mec=colour, alpha=0.3,
                                      ms=BODY_PT * (1 + s) * 2, mew=1.5, zorder=3)
        victim = bite_target[k]
        if bit[k] and victim >= 0 and here[victim]:
            out["bites"] += ax.plot(*np.stack([xy[k], xy[victim]]).T, color="black", lw=1.2, zorder=4)
            out["bites"] += ax.plot(*xy[victim], ls="", marker="x", color="black", ms=7, mew=1.5, zorder=6)
        out["bodies"] += ax.plot(*xy[k], ls="", marker=body_marker(heading[k]), ms=BODY_PT * (1 + s),
                                 color=colour, mec="black", mew=0.5, zorder=5)
    return out


def arena_image(width_cm: float, height_cm: float, pellets: np.ndarray, xy: np.ndarray, heading: np.ndarray,
                size: np.ndarray, eod: np.ndarray, bit: np.ndarray, bite_target: np.ndarray,
                title: str) -> np.ndarray:
    """One arena at one instant as uint8 RGB [H, W, 3]: walls, ``pellets`` ([P, 2] cm) and the bodies of
    :func:`draw_bodies` (agent ids 0..N-1), titled ``title``, at a clip frame's size and resolution. Drawn on
    a figure of its own (no pyplot), so it neither needs nor disturbs a display backend."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=frame_size(width_cm, height_cm), dpi=FRAME_DPI, layout="constrained")
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    draw_walls(ax, width_cm, height_cm)
    ax.set_title(title, loc="left", fontsize=9)
    draw_pellets(ax, pellets)
    draw_bodies(ax, np.arange(len(xy)), xy, heading, size, eod, bit, bite_target)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()
