"""The ordered tuple of the fish's senses and every spelling of each (see :mod:`efish.senses`).

The order is the model's: Mormyromasts, Ampullary organs, Knollenorgans, as the observation lays out their
readings and the noise draws them. A figure's colour and line style of a sense live here too, so that every
panel draws a sense alike.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass


@dataclass(frozen=True)
class Sense:
    """One sense and its spellings.

    ``name`` is its config group under ``sensors.`` and its value in the tables' ``receptor`` columns; ``short`` its
    infix in measure columns (``err_<short>_rad``) and its ``channel`` in the homing analysis; ``letter`` its mark in
    an ablation condition's name (the senses left on, ``M_A_K``); ``label`` its name on a figure; ``colour``,
    ``line`` and ``marker`` how a figure draws it (Okabe-Ito colours)."""

    name: str
    short: str
    letter: str
    label: str
    colour: str
    line: str
    marker: str


#: Every sense, in the model's order.
SENSES: tuple[Sense, ...] = (
    Sense("mormyromast", "morm", "M", "Mormyromast", "#0072B2", "-", "o"),
    Sense("ampullary", "amp", "A", "Ampullary", "#009E73", "--", "s"),
    Sense("knollenorgan", "knollen", "K", "Knollenorgan", "#D55E00", ":", "^"),
)


def sense(spelling: str) -> Sense:
    """The sense any of whose spellings (name, short, letter) is ``spelling``; a KeyError naming them otherwise."""
    for s in SENSES:
        if spelling in (s.name, s.short, s.letter):
            return s
    raise KeyError(f"no sense is spelt {spelling!r}: the senses are {', '.join(s.name for s in SENSES)}")


def error_column(s: Sense) -> str:
    """The steps table's column of the homer's heading error against this sense's field (``err_morm_rad``)."""
    return f"err_{s.short}_rad"


def condition_name(on: Iterable[Sense]) -> str:
    """An ablation condition's name from the senses left on, in the model's order: ``M_A_K``, ``A_K``, ``K``;
    ``none`` when every sense is off."""
    kept = set(on)
    letters = [s.letter for s in SENSES if s in kept]
    return "_".join(letters) if letters else "none"
