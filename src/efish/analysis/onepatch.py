"""The one-patch intruder and bot assays (docs/methods/assays.md; Fig 5E-J): who is A and who is B, and the tests by
role.

Who is who comes from the conditions the run recorded (``assays/<assay>/conditions.parquet``, read back with
:func:`efish.config.recorded.recorded_conditions`), never from the condition names, so an assay file or a run
override that changes sizes or roles changes the tests with it. In ``config/assay/onepatch.yaml`` a social
condition sets ``env.roles`` (``resident`` = A at the patch, ``intruder`` = B) and the sizes of both; an alone
condition has one agent (agent 0 whatever its role). The alone controls are matched by role and size (claim
C14): per social condition and role, the alone condition whose lone agent has that role and the size the role
has in the social condition (:func:`matched_alone`), so that "B with A" and "B alone" compare one size. In
``config/assay/bot.yaml`` the bot is ``env.bots[0]`` and the trained agent is the other
(:func:`bot_conditions` reads the bot's EOD rate and whether it is frozen).

:func:`role_tests` and :func:`reach_tests` are the statistic tables of the
``onepatch`` analysis (columns of :data:`efish.analysis.stats.STAT_COLUMNS`
plus ``role`` or ``contrast``); Fig 5 and the claims C14 and C15 read them.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from ..config.schema import EfishConfig
from ._tables import AGENT_EPISODE, require
from .stats import fisher_row, mann_whitney, nan_stat_row

#: Condition -> its recorded config, in the assay's order (:func:`efish.config.recorded.recorded_conditions`).
Configs = Mapping[str, EfishConfig]
#: The one-patch roles (``env.roles``) and the letter each has in the paper.
ROLE_LETTERS = {"resident": "A", "intruder": "B"}
#: contrast -> (group, control) of :func:`reach_tests`: the bot frozen vs moving, emitting vs silent.
REACH_CONTRASTS = {"mobility": ("frozen", "moving"), "eod": ("emitting", "silent")}


def onepatch_roles(configs: Configs) -> dict[str, dict[str, int]]:
    """Per condition: role letter ("A", "B") -> agent index, from each recorded condition's ``env.roles``."""
    return {cond: {ROLE_LETTERS[r]: i for i, r in enumerate(cfg.env.roles) if r in ROLE_LETTERS}
            for cond, cfg in configs.items()}


def social_conditions(configs: Configs) -> list[str]:
    """The conditions where both A and B take part, B's recorded size rising (ties in the assay's order)."""
    roles = onepatch_roles(configs)
    social = [c for c, r in roles.items() if len(r) == 2 and configs[c].env.sizes]
    return sorted(social, key=lambda c: configs[c].env.sizes[roles[c]["B"]])


def alone_conditions(configs: Configs) -> dict[str, tuple[str, float]]:
    """The conditions with one agent that plays A or B: condition -> (its role letter, its recorded size)."""
    out = {}
    for cond, r in onepatch_roles(configs).items():
        env = configs[cond].env
        if env.n_agents == 1 and len(r) == 1 and len(env.sizes) == 1:
            out[cond] = (next(iter(r)), float(env.sizes[0]))
    return out


def matched_alone(configs: Configs) -> dict[tuple[str, str], str]:
    """(role letter, social condition) -> the alone condition whose lone agent has that role and the size the role
    has in the social condition (the first such in the assay's order); a pair without one is absent."""
    roles, alone = onepatch_roles(configs), alone_conditions(configs)
    out = {}
    for social in social_conditions(configs):
        sizes = configs[social].env.sizes
        for letter, agent in roles[social].items():
            match = [a for a, (lone, size) in alone.items() if lone == letter and np.isclose(size, sizes[agent])]
            if match:
                out[letter, social] = match[0]
    return out


def food_from_steps(steps: pd.DataFrame) -> pd.DataFrame:
    """Pellets eaten per agent-episode (the sum of ``ate`` over its steps): condition, episode, agent, food_eaten."""
    require(steps, [*AGENT_EPISODE, "ate"], "steps table")
    food = steps.groupby(AGENT_EPISODE, sort=True)["ate"].sum().astype(np.float64)
    return food.rename("food_eaten").reset_index()


def roles(food: pd.DataFrame, configs: Configs) -> pd.DataFrame:
    """Rows of the one-patch conditions with ``role`` (A or B) and ``setting`` (the social condition, or ``alone``).

    ``food``: rows with condition and agent; ``configs``: the assay's recorded conditions. Rows of a condition that
    is neither social nor alone (the bot assay's), or of an agent without a role, are dropped.
    """
    require(food, ["condition", "agent"], "table")
    social, alone = social_conditions(configs), alone_conditions(configs)
    agents = onepatch_roles(configs)
    letter = {(cond, agent): r for cond in social for r, agent in agents[cond].items()}
    letter |= {(cond, 0): r for cond, (r, _) in alone.items()}
    keys = pd.MultiIndex.from_arrays([food["condition"].astype(str), food["agent"].astype(int)])
    role = pd.Series(keys.map(letter.get), index=food.index)
    mine = food[role.notna()]
    return mine.assign(role=role[role.notna()],
                       setting=np.where(mine["condition"].isin(list(alone)), "alone", mine["condition"]))


def role_tests(food: pd.DataFrame, configs: Configs) -> pd.DataFrame:
    """Mann-Whitney of each role's food in each social condition vs that role alone at the same size.

    ``food``: one row per agent-episode with ``food_eaten`` (:func:`food_from_steps`); ``configs``: the assay's
    recorded conditions. Rows: per ``role`` (B, then A) and social condition (:func:`social_conditions`):
    group = the social condition, control = the matched alone condition (:func:`matched_alone`, e.g. B in
    A_lt_B vs ``B_alone_75``); effect = median difference (social minus alone), two-sided. A pair without
    episodes of either side, or without an alone condition at the role's size, is one NaN row that says so.
    """
    require(food, ["condition", "agent", "food_eaten"], "food table")
    social, matched = social_conditions(configs), matched_alone(configs)
    people = roles(food, configs)
    if not social:
        return nan_stat_row("no one-patch condition where A and B both take part", role=np.nan)
    out = []
    for role in ("B", "A"):
        mine = people[people["role"] == role]
        for cond in social:
            if (role, cond) not in matched:
                out.append(nan_stat_row(f"no {role} alone condition at {role}'s size in {cond}", role=role,
                                        group=cond, control=np.nan))
                continue
            alone = matched[role, cond]
            pair = mine[mine["condition"].isin([cond, alone])]
            if lacking := [c for c in (cond, alone) if c not in set(pair["condition"])]:
                out.append(nan_stat_row(f"no {' or '.join(lacking)} episode with {role}'s food", role=role,
                                        group=cond, control=alone))
                continue
            out.append(mann_whitney(pair, "food_eaten", "condition", alone).assign(role=role))
    return pd.concat(out, ignore_index=True)


def bot_conditions(configs: Configs) -> pd.DataFrame:
    """One row per condition with a bot (``configs``: the bot assay's recorded conditions): the trained ``agent``
    (the first that is not a bot), ``bot_size``, ``agent_size``, the bot's EOD rate, and ``mobility`` (frozen or
    moving)."""
    rows = []
    for cond, cfg in configs.items():
        env = cfg.env
        if not env.bots:
            continue
        bot = env.bots[0]
        agent = next(i for i in range(env.n_agents) if i not in env.bots)
        rows.append({"condition": cond, "agent": agent, "bot_size": float(env.sizes[bot]),
                     "agent_size": float(env.sizes[agent]), "bot_eod_rate": float(env.bot_eod_rate),
                     "mobility": "frozen" if bot in env.frozen else "moving"})
    return pd.DataFrame(rows, columns=["condition", "agent", "bot_size", "agent_size", "bot_eod_rate", "mobility"])


def bot_reach_counts(reach: pd.DataFrame, configs: Configs, contrast: str) -> pd.DataFrame:
    """Episodes and reaches of the trained agent pooled over the bot conditions per group of ``contrast``.

    ``reach``: :func:`efish.analysis.behaviour.reach_rates` of the bot assay; ``configs``: its recorded
    conditions. ``contrast`` ``mobility`` groups frozen / moving, ``eod`` emitting (bot EOD rate > 0) / silent.
    Index: the groups present; columns n_reached, n_episodes.
    """
    if contrast not in REACH_CONTRASTS:
        raise ValueError(f"contrast must be one of {sorted(REACH_CONTRASTS)}, got {contrast!r}")
    require(reach, ["condition", "agent", "n_reached", "n_episodes"], "reach table")
    r = reach.merge(bot_conditions(configs), on=["condition", "agent"])  # the trained agent's rows only
    group = r["mobility"] if contrast == "mobility" else np.where(r["bot_eod_rate"] > 0, "emitting", "silent")
    return r.assign(group=group).groupby("group")[["n_reached", "n_episodes"]].sum().astype(np.int64)


def reach_tests(reach: pd.DataFrame, configs: Configs) -> pd.DataFrame:
    """Fisher exact tests of the trained agent's reach counts (Fig 5I,J): bot frozen vs moving, emitting vs silent.

    One row per ``contrast`` (:data:`REACH_CONTRASTS`); effect = reach rate
    difference, statistic = odds ratio. Without bot conditions (or a group) the
    row is NaN and says so.
    """
    out = []
    for contrast, (group, control) in REACH_CONTRASTS.items():
        counts = bot_reach_counts(reach, configs, contrast)
        if missing := [g for g in (group, control) if g not in counts.index]:
            out.append(nan_stat_row(f"no bot episode of the trained agent with the bot {' or '.join(missing)}",
                                    contrast=contrast, group=group, control=control))
            continue
        out.append(fisher_row(group, control, *counts.loc[group], *counts.loc[control]).assign(contrast=contrast))
    return pd.concat(out, ignore_index=True)
