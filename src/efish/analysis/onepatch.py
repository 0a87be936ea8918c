"""The one-patch intruder and bot assays (SPEC 11; Fig 5E-J): who is A and who is B, and the tests by role.

Roles follow ``config/assay/onepatch.yaml``: in the social conditions agent 0
is the resident A (at the patch) and agent 1 the intruder B; in an alone
condition (``A_alone_<s>``, ``B_alone_<s>``, ``s`` = 100 x the lone agent's
size) the single agent (0) is the letter the condition names. The alone
controls are matched by size (claim C14): each social condition (size class)
has, per role, the alone condition at the size that role has in it
(:data:`MATCHED_ALONE`), so that "B with A" and "B alone" compare one size.
In ``config/assay/bot.yaml`` the bot is agent 0 and the trained agent B is
agent 1; a bot condition's name ends in ``rate<EOD rate>_<frozen|moving>``.

:func:`role_tests` and :func:`reach_tests` are the statistic tables of the
``onepatch`` analysis (columns of :data:`efish.analysis.stats.STAT_COLUMNS`
plus ``role`` or ``contrast``); Fig 5 and the claims C14 and C15 read them.
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

from ._tables import AGENT_EPISODE, require
from .stats import fisher_row, mann_whitney, nan_stat_row

#: The social conditions (size classes), B's size rising, and the sizes (A, B) each sets (``env.sizes``).
SOCIAL_SIZES = {"A_gt_B": (0.75, 0.25), "A_eq_B": (0.5, 0.5), "A_lt_B": (0.25, 0.75)}
SOCIAL = tuple(SOCIAL_SIZES)
#: The lone-agent conditions: condition -> (the role its agent plays, the agent's size).
ALONE = {"A_alone_25": ("A", 0.25), "A_alone_50": ("A", 0.5), "A_alone_75": ("A", 0.75),
         "B_alone_25": ("B", 0.25), "B_alone_50": ("B", 0.5), "B_alone_75": ("B", 0.75)}
#: (role, social condition) -> the alone condition at the size that role has in the social condition.
MATCHED_ALONE = {("A", "A_gt_B"): "A_alone_75", ("A", "A_eq_B"): "A_alone_50", ("A", "A_lt_B"): "A_alone_25",
                 ("B", "A_gt_B"): "B_alone_25", ("B", "A_eq_B"): "B_alone_50", ("B", "A_lt_B"): "B_alone_75"}
#: Alone condition -> the size class (social condition) it is the control of.
ALONE_CLASS = {alone: social for (_, social), alone in MATCHED_ALONE.items()}
RESIDENT = 0  # agent index of A in a social condition
#: The trained agent B of the bot assay (the bot is agent 0).
BOT_TRAINED = 1
BOT_CONDITION = re.compile(r"rate([0-9.]+)_(frozen|moving)$")
#: contrast -> (group, control) of :func:`reach_tests`: the bot frozen vs moving, emitting vs silent.
REACH_CONTRASTS = {"mobility": ("frozen", "moving"), "eod": ("emitting", "silent")}


def food_from_steps(steps: pd.DataFrame) -> pd.DataFrame:
    """Pellets eaten per agent-episode (the sum of ``ate`` over its steps): condition, episode, agent, food_eaten."""
    require(steps, [*AGENT_EPISODE, "ate"], "steps table")
    food = steps.groupby(AGENT_EPISODE, sort=True)["ate"].sum().astype(np.float64)
    return food.rename("food_eaten").reset_index()


def roles(food: pd.DataFrame) -> pd.DataFrame:
    """Rows of the one-patch conditions with ``role`` (A or B), ``setting`` (the social condition or ``alone``) and
    ``size_class`` (the social condition; for an alone row, the social condition it is matched to by size).

    B in A_lt_B and B alone at 0.75 share ``size_class`` A_lt_B. Rows of other conditions are dropped (the bot
    assay has none).
    """
    require(food, ["condition", "agent"], "table")
    food = food[food["condition"].isin([*SOCIAL, *ALONE])]
    alone = food["condition"].isin(list(ALONE)).to_numpy()
    lone_role = food["condition"].map({c: r for c, (r, _) in ALONE.items()})
    role = np.where(alone, lone_role, np.where(food["agent"] == RESIDENT, "A", "B"))
    size_class = np.where(alone, food["condition"].map(ALONE_CLASS), food["condition"])
    return food.assign(role=role, setting=np.where(alone, "alone", food["condition"]), size_class=size_class)


def role_tests(food: pd.DataFrame) -> pd.DataFrame:
    """Mann-Whitney of each role's food in each social condition vs that role alone at the same size.

    ``food``: one row per agent-episode with ``food_eaten`` (:func:`food_from_steps`).
    Rows: per ``role`` (B, then A) and social condition (:data:`SOCIAL`):
    group = the social condition, control = the matched alone condition
    (:data:`MATCHED_ALONE`, e.g. B in A_lt_B vs ``B_alone_75``); effect =
    median difference (social minus alone), two-sided. A pair without
    episodes of either side is one NaN row that says so.
    """
    require(food, ["condition", "agent", "food_eaten"], "food table")
    people = roles(food)
    if people.empty:
        return nan_stat_row(f"no one-patch condition ({', '.join([*SOCIAL, *ALONE])})", role=np.nan)
    out = []
    for role in ("B", "A"):
        mine = people[people["role"] == role]
        for social in SOCIAL:
            alone = MATCHED_ALONE[role, social]
            pair = mine[mine["size_class"] == social]
            if lacking := [c for c in (social, alone) if c not in set(pair["condition"])]:
                out.append(nan_stat_row(f"no {' or '.join(lacking)} episode with {role}'s food", role=role,
                                        group=social, control=alone))
                continue
            out.append(mann_whitney(pair, "food_eaten", "condition", alone).assign(role=role))
    return pd.concat(out, ignore_index=True)


def bot_reach_counts(reach: pd.DataFrame, contrast: str, agent: int = BOT_TRAINED) -> pd.DataFrame:
    """Episodes and reaches of ``agent`` pooled over the bot conditions per group of ``contrast``.

    ``reach``: :func:`efish.analysis.behaviour.reach_rates` of the bot assay.
    ``contrast`` ``mobility`` groups frozen / moving, ``eod`` emitting (bot EOD
    rate > 0) / silent. Index: the groups present; columns n_reached, n_episodes.
    """
    if contrast not in REACH_CONTRASTS:
        raise ValueError(f"contrast must be one of {sorted(REACH_CONTRASTS)}, got {contrast!r}")
    require(reach, ["condition", "agent", "n_reached", "n_episodes"], "reach table")
    r = reach[reach["agent"] == agent]
    m = r["condition"].astype(str).str.extract(BOT_CONDITION)
    r = r.assign(rate=pd.to_numeric(m[0]), motion=m[1]).dropna(subset=["rate"])
    group = r["motion"] if contrast == "mobility" else np.where(r["rate"] > 0, "emitting", "silent")
    return r.assign(group=group).groupby("group")[["n_reached", "n_episodes"]].sum().astype(np.int64)


def reach_tests(reach: pd.DataFrame, agent: int = BOT_TRAINED) -> pd.DataFrame:
    """Fisher exact tests of ``agent``'s reach counts (Fig 5I,J): bot frozen vs moving, emitting vs silent.

    One row per ``contrast`` (:data:`REACH_CONTRASTS`); effect = reach rate
    difference, statistic = odds ratio. Without bot conditions (or a group) the
    row is NaN and says so.
    """
    out = []
    for contrast, (group, control) in REACH_CONTRASTS.items():
        counts = bot_reach_counts(reach, contrast, agent)
        if missing := [g for g in (group, control) if g not in counts.index]:
            out.append(nan_stat_row(f"no bot episode of agent {agent} with the bot {' or '.join(missing)}",
                                 contrast=contrast, group=group, control=control))
            continue
        out.append(fisher_row(group, control, *counts.loc[group], *counts.loc[control]).assign(contrast=contrast))
    return pd.concat(out, ignore_index=True)
