"""Drawing helpers of the schematic and scene panels: boxes, arrows, bodies, pellets, walls and wedges.

Every helper draws on a given matplotlib axes in data coordinates (cm for scenes) and returns nothing; the
panels of :mod:`efish.figures.fig1` compose them. Nothing here computes a field: the stylised field lines of
a schematic are circles through the two EOD poles, a picture, not a solution.
"""

from __future__ import annotations

import numpy as np

from .style import NEUTRAL_COLOUR, PELLET_COLOUR

WALL_COLOUR = "0.25"


def blank(ax, xlim: tuple[float, float], ylim: tuple[float, float]) -> None:
    """A schematic canvas: equal aspect, these limits, no axes (a diagram has no units)."""
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_aspect("equal")
    ax.set_axis_off()


def box(ax, centre: tuple[float, float], width: float, height: float, text: str, colour: str,
        fontsize: float = 6.5) -> None:
    """A rounded box with centred text, tinted with ``colour``."""
    from matplotlib.patches import FancyBboxPatch

    x, y = centre[0] - width / 2, centre[1] - height / 2
    ax.add_patch(FancyBboxPatch((x, y), width, height, boxstyle="round,pad=0.02,rounding_size=0.25",
                                facecolor=colour, edgecolor=colour, alpha=0.18, lw=0.8))
    ax.add_patch(FancyBboxPatch((x, y), width, height, boxstyle="round,pad=0.02,rounding_size=0.25",
                                facecolor="none", edgecolor=colour, lw=0.9))
    ax.text(*centre, text, ha="center", va="center", fontsize=fontsize, linespacing=1.15)


def arrow(ax, start: tuple[float, float], end: tuple[float, float], text: str = "", colour: str = "0.3",
          rad: float = 0.0, fontsize: float = 6, offset: tuple[float, float] = (0.0, 0.0)) -> None:
    """An arrow from ``start`` to ``end`` (bent by ``rad``) with an optional label near its middle."""
    ax.annotate("", xy=end, xytext=start, arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 0.9, "shrinkA": 0,
                                                      "shrinkB": 0, "mutation_scale": 7,
                                                      "connectionstyle": f"arc3,rad={rad}"})
    if text:
        mid = (np.asarray(start) + np.asarray(end)) / 2 + np.asarray(offset)
        ax.text(*mid, text, ha="center", va="center", fontsize=fontsize, color=colour)


def body(ax, x: float, y: float, heading: float, radius: float, colour: str, emitting: bool = False,
         zorder: float = 4, pole_colour: str = "white") -> None:
    """A fish body: a disc of ``radius`` with a line to its nose; an emitter shows its EOD poles (+ ahead)."""
    from matplotlib.patches import Circle

    ax.add_patch(Circle((x, y), radius, facecolor=colour, edgecolor="black", lw=0.6, alpha=0.9, zorder=zorder))
    u = np.array([np.cos(heading), np.sin(heading)])
    ax.plot([x + radius * u[0], x + 1.6 * radius * u[0]], [y + radius * u[1], y + 1.6 * radius * u[1]],
            color="black", lw=0.9, solid_capstyle="round", zorder=zorder + 0.1)  # the nose: heading
    if emitting:
        for sign, mark in ((1, "+"), (-1, "\u2212")):
            ax.text(x + sign * 0.5 * radius * u[0], y + sign * 0.5 * radius * u[1], mark, ha="center",
                    va="center", fontsize=6, fontweight="bold", color=pole_colour, zorder=zorder + 0.2)


def pellet(ax, x: float, y: float, radius: float, zorder: float = 4) -> None:
    """A food pellet: a small brown disc."""
    from matplotlib.patches import Circle

    ax.add_patch(Circle((x, y), radius, facecolor=PELLET_COLOUR, edgecolor="black", lw=0.3, zorder=zorder))


def walls(ax, width: float, height: float, x0: float = 0.0, y0: float = 0.0, lw: float = 2.0) -> None:
    """The insulating walls of an arena [x0, x0 + width] x [y0, y0 + height]."""
    from matplotlib.patches import Rectangle

    ax.add_patch(Rectangle((x0, y0), width, height, fill=False, edgecolor=WALL_COLOUR, lw=lw, zorder=5))


def wedge(ax, x: float, y: float, direction: float, half_angle: float, radius: float, colour: str,
          alpha: float = 0.2) -> None:
    """A sector of ``radius`` around ``direction`` (rad), +-``half_angle``: a facing or eating cone."""
    from matplotlib.patches import Wedge

    lo, hi = np.degrees(direction - half_angle), np.degrees(direction + half_angle)
    ax.add_patch(Wedge((x, y), radius, lo, hi, facecolor=colour, edgecolor="none", alpha=alpha, zorder=1))


def dipole_sketch(ax, x: float, y: float, heading: float, half_separation: float, offsets, colour=NEUTRAL_COLOUR
                  ) -> None:
    """Stylised field lines of an EOD: circles through its two poles, centred ``offsets`` to either side."""
    from matplotlib.patches import Circle

    u = np.array([np.cos(heading), np.sin(heading)])
    n = np.array([-u[1], u[0]])
    for c in offsets:
        for side in (1, -1):
            centre = np.array([x, y]) + side * c * n
            ax.add_patch(Circle(tuple(centre), np.hypot(c, half_separation), fill=False, edgecolor=colour,
                                lw=0.5, ls=(0, (2, 1.5)), zorder=1))
