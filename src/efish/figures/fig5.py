"""Fig 5: the one-patch intruder assay, the bot, chasing and biting by size (docs/methods/assays.md,
docs/methods/figures.md#panels).

Who is who comes from the conditions the run recorded (``assays/<assay>/conditions.parquet``,
read through :func:`~efish.figures.style.assay_conditions`), not from the condition names: the
one-patch conditions set ``env.roles`` (``resident`` = A at the patch,
``intruder`` = B), and the bot conditions set the bot (``env.bots``), the
size pair (``env.sizes``), the bot's EOD rate and whether it is frozen.
A lone agent is agent 0 whatever its role, so the alone conditions are
matched by role too, and each is matched to the size class whose role has its
size (:func:`matched_alone`: B alone at 0.75 is the control of B in A<B).
Size classes (and their labels) follow the recorded sizes of A and B and take
``style.ONEPATCH_CLASS_COLOURS``, an alone control a light tint of the class it is
matched to; in the bot assay the bot plays A (it sits at the patch), so
"bot < B" has the colour of "A < B".
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from .. import layout
from ..analysis.onepatch import ROLE_LETTERS, Configs, bot_conditions, matched_alone, onepatch_roles
from ..config.schema import EfishConfig
from .panel import Panel
from .style import (
    NEUTRAL_COLOUR,
    ONEPATCH_CLASS_COLOURS,
    agent_colour,
    annotate_stars,
    assay_conditions,
    box_strip,
    corner_note,
    finite,
    missing,
    stars_for,
    tint,
)

Tables = dict[str, pd.DataFrame]
ONEPATCH, BOT, PAIRS = "onepatch", "bot", "square2"

_ROLE_NAMES = {letter: role for role, letter in ROLE_LETTERS.items()}
#: Short labels of the one-patch conditions (config/assay/onepatch.yaml) where no recorded config says more
#: (captions); an unknown name is shown as is. On a panel, :func:`class_label` reads the label off the recorded
#: config. An alone control is labelled with the lone agent's size (on tick labels the size goes on a second line).
CLASS_LABELS = {"A_lt_B": "A<B", "A_eq_B": "A=B", "A_gt_B": "A>B",
                "A_alone_25": "A alone, 0.25", "A_alone_50": "A alone, 0.5", "A_alone_75": "A alone, 0.75",
                "B_alone_25": "B alone, 0.25", "B_alone_50": "B alone, 0.5", "B_alone_75": "B alone, 0.75"}
#: Size of A against size of B -> the one-patch size class (its colour in ONEPATCH_CLASS_COLOURS).
SIZE_CLASSES = {"<": "A_lt_B", "=": "A_eq_B", ">": "A_gt_B"}
#: Bot size relation -> the one-patch class whose colour it takes (the bot plays the resident A).
BOT_CLASSES = SIZE_CLASSES
#: Most bouts whose chaser and chased (or biter and bitten) are joined by a line in panels L and N.
MAX_PAIR_LINES = 200
TRAJECTORY_CONDITIONS = ("A_lt_B", "A_eq_B", "A_gt_B")
#: Colour of the first role (chaser, biter); the second (chased, bitten) takes NEUTRAL_COLOUR.
DARK_GREY = "#404040"


# ------------------------------------------------------------------ configs
def role_rows(table: pd.DataFrame, role: str, configs: Configs) -> pd.DataFrame:
    """The rows of ``table`` (with condition and agent columns) that belong to ``role`` ("A" or "B").

    Conditions without that role (e.g. "A alone" for B) are dropped; the
    ``condition`` column becomes an ordered categorical in the assay's order.
    """
    if role not in ROLE_LETTERS.values():
        raise ValueError(f"role must be one of {sorted(ROLE_LETTERS.values())}, got {role!r}")
    agents = {cond: roles[role] for cond, roles in onepatch_roles(configs).items() if role in roles}
    mine = table["agent"].to_numpy() == table["condition"].map(agents).to_numpy()
    out = table[mine].copy()
    out["condition"] = pd.Categorical(out["condition"], categories=list(agents), ordered=True)
    return out


def bot_classes(configs: Configs) -> pd.DataFrame:
    """The bot conditions (:func:`efish.analysis.onepatch.bot_conditions`) with the ``size_class`` whose colour
    each takes (bot vs B as A vs B) and its ``class_label``."""
    bots = bot_conditions(configs)
    relation = np.select([np.isclose(bots["bot_size"], bots["agent_size"]), bots["bot_size"] < bots["agent_size"]],
                         ["=", "<"], ">")
    return bots.assign(size_class=[BOT_CLASSES[r] for r in relation], class_label=[f"bot{r}B" for r in relation])


# ------------------------------------------------------------------ helpers
def _usable(ax, table: pd.DataFrame, column: str, what: str) -> pd.DataFrame | None:
    """The rows with a finite ``column``; if none, say so on ``ax`` (with the table's reason) and return None."""
    rows = table[np.isfinite(pd.to_numeric(table[column], errors="coerce"))] if column in table else table.iloc[:0]
    if rows.empty:
        reasons = [r for r in table.get("reason", pd.Series(dtype=str)).dropna().unique() if r]
        missing(ax, f"{what}: {reasons[0]}" if reasons else what)
        return None
    return rows


def _class_label(cond: str) -> str:
    """The label of a condition by its name alone (captions, written before any run)."""
    return CLASS_LABELS.get(cond, cond)


def size_class(cond: str, configs: Configs) -> str | None:
    """The size class (a key of :data:`SIZE_CLASSES`' values) of one-patch condition ``cond`` as the run recorded it:
    A's size against B's; None for a condition without both roles or without fixed sizes."""
    cfg = configs.get(cond)
    roles = onepatch_roles({cond: cfg})[cond] if cfg is not None else {}
    if len(roles) < 2 or not cfg.env.sizes:
        return None
    a, b = cfg.env.sizes[roles["A"]], cfg.env.sizes[roles["B"]]
    return SIZE_CLASSES["=" if np.isclose(a, b) else "<" if a < b else ">"]


def class_label(cond: str, configs: Configs) -> str:
    """Label of a one-patch condition from its recorded config: a social one ``A<B``, ``A=B`` or ``A>B`` (its
    :func:`size_class`), an alone control ``<role> alone, <size>``; anything else :func:`_class_label`."""
    if (key := size_class(cond, configs)) is not None:
        return CLASS_LABELS[key]
    cfg = configs.get(cond)
    roles = onepatch_roles({cond: cfg})[cond] if cfg is not None else {}
    if len(roles) == 1 and len(cfg.env.sizes) == 1:
        return f"{next(iter(roles))} alone, {float(cfg.env.sizes[0]):g}"
    return _class_label(cond)


def class_colours(role: str, conditions, configs: Configs) -> dict:
    """Colour per one-patch condition on the panels of ``role``: a social condition its recorded size class's
    colour, an alone control a light tint of the class it is matched to for ``role`` (:func:`matched_alone`);
    others their ONEPATCH_CLASS_COLOURS entry, else grey (empty slots)."""
    matched = {alone: social for (r, social), alone in matched_alone(configs).items() if r == role}
    out = {}
    for cond in conditions:
        key = size_class(cond, configs)
        base = size_class(matched[cond], configs) if key is None and cond in matched else None
        out[cond] = (ONEPATCH_CLASS_COLOURS[key] if key else tint(ONEPATCH_CLASS_COLOURS[base]) if base
                     else ONEPATCH_CLASS_COLOURS.get(cond, NEUTRAL_COLOUR))
    return out


def _class_legend(ax, keys: list, labels: list, title: str | None = None) -> None:
    from matplotlib.patches import Patch

    handles = [Patch(facecolor=ONEPATCH_CLASS_COLOURS[k], edgecolor="black", linewidth=0.4, label=lab)
               for k, lab in zip(keys, labels, strict=True)]
    ax.legend(handles=handles, title=title, fontsize=6, title_fontsize=6, loc="best", handlelength=1)


def _arena(ax, cfg: EfishConfig) -> None:
    """Arena walls and the central patch (radius ``arena.onepatch_radius_cm``) of the one-patch arena."""
    from matplotlib.patches import Circle, Rectangle

    w, h = cfg.arena.width_cm, cfg.arena.height_cm
    ax.add_patch(Rectangle((0, 0), w, h, fill=False, edgecolor="black", lw=0.8))
    ax.add_patch(Circle((w / 2, h / 2), cfg.arena.onepatch_radius_cm, fill=True, facecolor="#e5e5e5",
                        edgecolor=NEUTRAL_COLOUR, ls="--", lw=0.6, zorder=0))
    ax.set_xlim(-2, w + 2)
    ax.set_ylim(-2, h + 2)
    ax.set_aspect("equal")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")


def _example_episode(steps: pd.DataFrame, condition: str) -> pd.DataFrame:
    """The steps of the first episode of ``condition`` (the one a reader can find again by its number)."""
    runs = steps[steps["condition"] == condition]
    return runs[runs["episode"] == runs["episode"].min()] if len(runs) else runs


# ------------------------------------------------------------------ A: scene
def assay_scene(tables: Tables, ax) -> None:
    """Panel A: the one-patch arena at the first step of the first A<B episode: A at the patch, B facing it,
    the pellets at the start (inset), and B's start position in every social episode (grey)."""
    steps, food = tables["steps"], tables["food"]
    cfg = assay_conditions(tables, ONEPATCH)
    roles = onepatch_roles(cfg)
    social = [c for c, r in roles.items() if len(r) == 2 and c in set(steps["condition"])]
    if not social:
        missing(ax, "no social one-patch condition in the steps table")
        return
    first = steps[steps["t"] == steps.groupby(["condition", "episode"])["t"].transform("min")]
    starts = role_rows(first[first["condition"].isin(social)], "B", cfg)
    _arena(ax, cfg[social[0]])
    ax.scatter(starts["x_cm"], starts["y_cm"], s=4, color=NEUTRAL_COLOUR, alpha=0.6, edgecolors="none",
               label=f"B starts ({len(starts)} episodes)")
    scene = _example_episode(first, social[0])
    episode = int(scene["episode"].iloc[0])
    arena = cfg[social[0]].arena
    intruder = scene[scene["agent"] == roles[social[0]]["B"]].iloc[0]
    # the zoom on the patch goes to the quadrant diagonally opposite B, the legend beside it
    right, top = intruder["x_cm"] < arena.width_cm / 2, intruder["y_cm"] < arena.height_cm / 2
    inset = ax.inset_axes([0.64 if right else 0.02, 0.64 if top else 0.02, 0.34, 0.34])
    pellets = food[(food["condition"] == social[0]) & (food["episode"] == episode) & (food["t_spawned"] <= 0)]
    _arena(inset, cfg[social[0]])
    inset.scatter(pellets["x_cm"], pellets["y_cm"], s=3, color="black")
    for role, agent in roles[social[0]].items():
        body = scene[scene["agent"] == agent].iloc[0]
        # B's label points into the arena; A's (at the centre) goes above or below, away from the zoom
        offset = ((8 if body["x_cm"] < arena.width_cm / 2 else -8), -10) if role == "B" else (0, -14 if top else 11)
        _body(ax, body, agent_colour(agent), f"{role} ({_ROLE_NAMES[role]}), size {body['size']:.2f}",
              arrow_cm=12, label_offset=offset)
        _body(inset, body, agent_colour(agent), None, arrow_cm=3)
    half = 2 * arena.onepatch_radius_cm
    inset.set_xlim(arena.width_cm / 2 - half, arena.width_cm / 2 + half)
    inset.set_ylim(arena.height_cm / 2 - half, arena.height_cm / 2 + half)
    inset.set_xlabel("")
    inset.set_ylabel("")
    inset.set_xticks([])
    inset.spines[:].set_visible(True)
    inset.set_yticks([])
    inset.set_title(f"{len(pellets)} pellets at t=0", fontsize=6, pad=2)
    ax.indicate_inset_zoom(inset, edgecolor=NEUTRAL_COLOUR, lw=0.5)
    ax.legend(loc=f"{'upper' if top else 'lower'} {'left' if right else 'right'}", fontsize=6, markerscale=2)
    ax.set_title(f"One-patch assay ({class_label(social[0], cfg)}, episode {episode})")


def _body(ax, body: pd.Series, colour, text: str | None, arrow_cm: float, label_offset=(8, -10)) -> None:
    """One agent: a dot whose area grows with its size, an arrow along its heading, and a label beside it."""
    x, y, th = float(body["x_cm"]), float(body["y_cm"]), float(body["heading_rad"])
    ax.plot(x, y, "o", color=colour, ms=3 + 5 * float(body["size"]), mec="black", mew=0.4, zorder=4)
    ax.annotate("", (x + arrow_cm * np.cos(th), y + arrow_cm * np.sin(th)), (x, y), zorder=4,
                arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 0.8, "shrinkA": 0, "shrinkB": 0})
    if text:
        dx = label_offset[0]
        ax.annotate(text, (x, y), xytext=label_offset, textcoords="offset points", fontsize=6, color=colour,
                    ha="left" if dx > 0 else "right" if dx < 0 else "center")


# ----------------------------------------------------------- B-D: trajectories
def trajectory_panel(condition: str) -> Callable[[Tables, object], None]:
    """Panels B-D: the paths of A and B in the first episode of one-patch ``condition``, eating marked."""

    def draw(tables: Tables, ax) -> None:
        run = _example_episode(tables["steps"], condition)
        if run.empty:
            missing(ax, f"no {condition} episode in the onepatch steps table")
            return
        configs = assay_conditions(tables, ONEPATCH)
        _arena(ax, configs[condition])
        for role, agent in onepatch_roles(configs)[condition].items():
            path = run[run["agent"] == agent].sort_values("t")
            if path.empty:
                continue
            colour = agent_colour(agent)
            ax.plot(path["x_cm"], path["y_cm"], color=colour, lw=0.7,
                    label=f"{role}, size {path['size'].iloc[0]:.2f}")
            ax.plot(path["x_cm"].iloc[0], path["y_cm"].iloc[0], "o", color=colour, ms=3.5, mec="black", mew=0.4)
            ate = path[path["ate"].astype(bool)]
            ax.plot(ate["x_cm"], ate["y_cm"], "*", color=colour, ms=5, mec="black", mew=0.3, ls="none")
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=6, title="o start, * ate", title_fontsize=6,
                  frameon=False)  # beside the arena: the paths cover all of it
        ax.set_title(f"{class_label(condition, configs)}, episode {int(run['episode'].iloc[0])}")

    draw.__doc__ = f"Panel: paths of A and B in the first {condition} episode of the one-patch assay."
    return draw


# ---------------------------------------------------------- E,F: food per role
def class_slots(role: str, present, configs: Configs) -> list[str]:
    """The x slots of panels E-H for ``role``: each size class of the config present, then its size-matched alone
    control (if present), an empty slot between classes; alone conditions matched to no class last. An empty slot
    is a blank name, one space more for each (seaborn needs distinct categories)."""
    present, roles = set(present), onepatch_roles(configs)
    matched = matched_alone(configs)
    socials = [c for c, r in roles.items() if len(r) == 2 and c in present]
    rest = [c for c, r in roles.items() if role in r and c in present and c not in socials
            and c not in (matched.get((role, s)) for s in socials)]
    groups = [[c, *([matched[role, c]] if matched.get((role, c)) in present else [])] for c in socials]
    slots: list[str] = []
    for i, group in enumerate([*groups, *([rest] if rest else [])]):
        slots += [" " * i] * (i > 0) + group
    return slots


def _tick_label(cond: str, configs: Configs) -> str:
    return class_label(cond, configs).replace(", ", "\n") if cond.strip() else ""


def food_by_role(role: str) -> Callable[[Tables, object], None]:
    """Panels E (B) and F (A): food eaten per episode by ``role`` in each size class, beside ``role`` alone at the
    size it has in that class; a bracket carries the class's Mann-Whitney stars (onepatch role_tests)."""

    def draw(tables: Tables, ax) -> None:
        food = _usable(ax, tables["food"], "food_eaten", "onepatch food_per_agent")
        if food is None:
            return
        configs = assay_conditions(tables, ONEPATCH)
        rows = role_rows(food, role, configs)
        order = class_slots(role, rows["condition"].astype(str), configs)
        if not order:
            missing(ax, f"no agent of role {role} in the onepatch food table")
            return
        data = rows.assign(condition=rows["condition"].astype(str))
        palette = class_colours(role, order, configs)
        if not box_strip(ax, data, "condition", "food_eaten", order, palette,
                         labels={c: _tick_label(c, configs) for c in order}):
            return
        tests = tables["tests"]
        tests = tests[tests["role"] == role] if "role" in tests.columns else tests.iloc[:0]
        values = finite(data["food_eaten"])
        lo, hi = float(values.min()), float(values.max())
        pad = (hi - lo) * 0.06 or max(abs(hi), 1.0) * 0.06
        matched = matched_alone(configs)
        for i, cond in enumerate(order):
            alone = matched.get((role, cond))
            if alone is None or i + 1 >= len(order) or order[i + 1] != alone:
                continue
            # the class vs the alone control at the same size: the row of role_tests with this class as group
            top = finite(data.loc[data["condition"].isin([cond, alone]), "food_eaten"])
            annotate_stars(ax, i, (top.max() if top.size else hi) + pad, stars_for(tests, group=cond), x2=i + 1)
        ax.set_ylim(top=hi + 4 * pad)
        ax.set_xlabel("size class of A vs B, and alone at the same size")
        ax.set_ylabel(f"food eaten by {role} (pellets / episode)")
        ax.set_title(f"Food of {role}: social vs alone")

    draw.__doc__ = f"Panel: food eaten per episode by {role}, per size class and size-matched alone control."
    return draw


# ------------------------------------------------------- G,H: food time course
def food_course_by_role(role: str) -> Callable[[Tables, object], None]:
    """Panels G (B) and H (A): mean +- SEM cumulative food of ``role`` over time, per size class (solid) and its
    size-matched alone control (dashed, a tint of the class's colour)."""

    def draw(tables: Tables, ax) -> None:
        course = _usable(ax, tables["course"], "mean_food", "onepatch food_time_course")
        if course is None:
            return
        configs = assay_conditions(tables, ONEPATCH)
        rows = role_rows(course, role, configs)
        matched = matched_alone(configs)
        alone = {a for (r, _), a in matched.items() if r == role}
        slots = [c for c in class_slots(role, rows["condition"].astype(str), configs) if c.strip()]
        colours = class_colours(role, slots, configs)
        yellow = ONEPATCH_CLASS_COLOURS["A_gt_B"]
        for cond in slots:
            c = rows[rows["condition"] == cond].sort_values("t")
            colour = colours[cond]
            # steps to seconds at the frame rate the run simulated this condition at
            t, mean, sem = c["t"] / configs[cond].env.fps, c["mean_food"], c["sem_food"].fillna(0)
            ax.fill_between(t, mean - sem, mean + sem, color=colour, alpha=0.25, lw=0)
            light = colour in (yellow, tint(yellow))  # the faint yellow class and its control
            ax.plot(t, mean, color=colour, lw=1.0, ls="--" if cond in alone else "-",
                    label=class_label(cond, configs), path_effects=_outline() if light else None)
        ax.set_xlabel("time (s)")
        ax.set_ylabel(f"cumulative food of {role} (pellets)")
        ax.set_title(f"Food of {role} over time")
        ax.legend(loc="best", fontsize=6)

    draw.__doc__ = f"Panel: cumulative food of {role} over time, per size class and size-matched alone control."
    return draw


def _outline() -> list:
    """A thin dark edge around a light line (the yellow of the largest class is faint on white)."""
    from matplotlib import patheffects

    return [patheffects.withStroke(linewidth=1.8, foreground="#404040"), patheffects.Normal()]


# ---------------------------------------------------------- I,J: bot reach rate
def bot_reach(contrast: str) -> Callable[[Tables, object], None]:
    """Panels I (``mobility``: frozen vs moving bot) and J (``eod``: silent vs discharging bot): B's reach rate.

    Each point is one bot condition (its reach rate over its episodes), boxes per size class.
    """
    if contrast not in ("mobility", "eod"):
        raise ValueError(f"contrast must be 'mobility' or 'eod', got {contrast!r}")

    def draw(tables: Tables, ax) -> None:
        rates = _usable(ax, tables["reach"], "reach_rate", "bot reach_rates")
        if rates is None:
            return
        rows = rates.merge(bot_classes(assay_conditions(tables, BOT)), on=["condition", "agent"])  # B only
        if rows.empty:
            missing(ax, "no reach rate of the trained agent in the bot table")
            return
        if contrast == "mobility":
            groups, xlabel = rows["mobility"], "bot"
            names = ["frozen", "moving"]
        else:
            groups, xlabel = pd.Series(np.where(rows["bot_eod_rate"] > 0, "on", "silent"), index=rows.index), "bot EOD"
            names = ["silent", "on"]
        classes = [c for c in BOT_CLASSES.values() if c in set(rows["size_class"])]
        # one box per (group, size class), an empty slot between the two groups
        rows = rows.assign(box=groups + "|" + rows["size_class"])
        order = [f"{names[0]}|{c}" for c in classes] + [""] + [f"{names[1]}|{c}" for c in classes]
        box_strip(ax, rows, "box", "reach_rate", order,
                  {b: ONEPATCH_CLASS_COLOURS[b.split("|")[1]] for b in order if b} | {"": NEUTRAL_COLOUR})
        centre = (len(classes) - 1) / 2
        ax.set_xticks([centre, centre + len(classes) + 1], names)
        labels = rows.drop_duplicates("size_class").set_index("size_class")["class_label"]
        _class_legend(ax, classes, [labels[c] for c in classes])
        # one bracket over the two groups: the onepatch analysis's Fisher exact test of the pooled counts
        tests = tables["tests"]
        stars = stars_for(tests[tests["contrast"] == contrast] if "contrast" in tests.columns else tests.iloc[:0])
        annotate_stars(ax, centre, 1.12, stars, x2=centre + len(classes) + 1)
        ax.set_ylim(-0.05, 1.3)
        ax.set_xlabel(xlabel)
        ax.set_ylabel("B reached the patch (fraction)")
        ax.set_title("Bot frozen vs moving" if contrast == "mobility" else "Bot EOD silent vs on")

    draw.__doc__ = f"Panel: the trained agent's patch reach rate in the bot assay by {contrast}."
    return draw


# ------------------------------------------------------ K-N: chaser / biter size
ROLES = {"chase": ("chaser", "chased"), "bite": ("biter", "bitten")}


def size_difference(measure: str) -> Callable[[Tables, object], None]:
    """Panels K (``chase``) and M (``bite``): histogram of the per-event size difference (chaser - chased,
    biter - bitten), with the median and the Wilcoxon stars of ``size_tests``."""
    role, other = ROLES[measure]

    def draw(tables: Tables, ax) -> None:
        import seaborn as sns

        events = _usable(ax, tables["events"], "size_difference", f"square2 {role} sizes")
        if events is None:
            return
        hue = "condition" if events["condition"].nunique() > 1 else None
        sns.histplot(data=events, x="size_difference", hue=hue, bins=np.linspace(-1, 1, 21), ax=ax,
                     color=NEUTRAL_COLOUR, edgecolor="black", linewidth=0.5)
        ax.axvline(0, color="black", lw=0.6, ls=":")
        notes = []
        for cond in sorted(events["condition"].unique()):
            test = tables["tests"]
            test = test[(test["measure"] == measure) & (test["condition"] == cond)]
            median = test["effect"].iloc[0] if len(test) else np.nan
            stars = stars_for(test, group=role)
            prefix = f"{cond}: " if hue else ""
            notes.append(f"{prefix}median {median:+.2f} {stars}" if np.isfinite(median) else f"{prefix}{stars}")
        corner_note(ax, "\n".join(notes))
        ax.set_xlim(-1, 1)
        ax.set_xlabel(f"{role} size - {other} size")
        ax.set_ylabel("bouts" if measure == "chase" else "bites")
        ax.set_title(f"{role.capitalize()} minus {other} size")

    draw.__doc__ = f"Panel: histogram of {role} minus {other} size per {measure} event."
    return draw


def role_sizes(measure: str) -> Callable[[Tables, object], None]:
    """Panels L (``chase``) and N (``bite``): sizes of chaser and chased (biter and bitten), pairs joined,
    with the Wilcoxon signed-rank stars of ``size_tests`` on a bracket."""
    role, other = ROLES[measure]

    def draw(tables: Tables, ax) -> None:
        events = _usable(ax, tables["events"], "size_difference", f"square2 {role} sizes")
        if events is None:
            return
        conditions = sorted(events["condition"].unique())
        many = len(conditions) > 1
        long, order = [], []
        for cond in conditions:
            sub = events[events["condition"] == cond]
            for r in (role, other):
                group = f"{cond}\n{r}" if many else r
                order.append(group)
                long.append(pd.DataFrame({"group": group, "size": sub[f"{r}_size"].to_numpy(float)}))
        data = pd.concat(long, ignore_index=True)
        # grey shades, not agent colours: the roles are not agents A and B of the other panels
        palette = {g: DARK_GREY if g.endswith(role) else NEUTRAL_COLOUR for g in order}
        box_strip(ax, data, "group", "size", order, palette)
        tests = tables["tests"]
        for i, cond in enumerate(conditions):
            sub = events[events["condition"] == cond]
            if len(sub) <= MAX_PAIR_LINES:
                ax.plot([2 * i, 2 * i + 1], sub[[f"{role}_size", f"{other}_size"]].to_numpy(float).T,
                        color=NEUTRAL_COLOUR, lw=0.3, alpha=0.5, zorder=1)
            test = tests[(tests["measure"] == measure) & (tests["condition"] == cond)]
            annotate_stars(ax, 2 * i, 1.05, stars_for(test, group=role), x2=2 * i + 1)
        ax.set_ylim(-0.05, 1.2)
        ax.set_xlabel("role in the bout" if measure == "chase" else "role in the bite")
        ax.set_ylabel("body size")
        ax.set_title(f"{role.capitalize()} vs {other} size (n={len(events)})")

    draw.__doc__ = f"Panel: {role} and {other} sizes with the paired test's stars."
    return draw


# ------------------------------------------------------------ O: bite timing
def bite_timing(tables: Tables, ax) -> None:
    """Panel O: where in its bout each bite falls (phase 0 = bout start, 1 = end), stacked by bout class."""
    import seaborn as sns

    bites = _usable(ax, tables["timing"], "phase", "square2 bite_timing")
    if bites is None:
        return
    hue = "label" if bites["label"].nunique() > 1 else None
    sns.histplot(data=bites, x="phase", hue=hue, multiple="stack", bins=np.linspace(0, 1, 11), ax=ax,
                 color=NEUTRAL_COLOUR, edgecolor="black", linewidth=0.5)
    ax.set_xlim(0, 1)
    ax.set_xlabel("phase of the bout (0 start, 1 end)")
    ax.set_ylabel("bites")
    ax.set_title(f"Bite timing in bouts ({len(bites)} bites)")


# ------------------------------------------------------ P: bite rate by class
def bite_rate(tables: Tables, ax) -> None:
    """Panel P: bites per pair-step within bout range, by the biter's per-step label (n/a: label never seen)."""
    import seaborn as sns

    from ..analysis.interactions import LABELS

    table = tables["rate"]
    if _usable(ax, table, "rate", "square2 bite_rate_by_class") is None:
        return
    data = table.assign(label=pd.Categorical(table["label"], categories=LABELS))
    hue = "condition" if data["condition"].nunique() > 1 else None
    sns.barplot(data=data, x="label", y="rate", hue=hue, order=list(LABELS), ax=ax, color=NEUTRAL_COLOUR,
                edgecolor="black", linewidth=0.5)
    for i, label in enumerate(LABELS):
        if not len(finite(data.loc[data["label"] == label, "rate"])):
            ax.text(i, 0, "n/a", ha="center", va="bottom", fontsize=6, color=NEUTRAL_COLOUR)
    ax.tick_params(axis="x", labelrotation=30)
    ax.set_xlabel("biter's label towards the partner")
    ax.set_ylabel("bites per pair-step")
    ax.set_title("Bite rate by interaction class")


# --------------------------------------------------------------------- panels
_STEPS, _PELLETS = layout.assay_table(ONEPATCH, "steps"), layout.assay_table(ONEPATCH, "food")
_FOOD = layout.analysis_table("behaviour", ONEPATCH, "food_per_agent")
_COURSE = layout.analysis_table("onepatch", ONEPATCH, "food_time_course")
_REACH = layout.analysis_table("onepatch", BOT, "reach_rates")
_ROLE_TESTS = layout.analysis_table("onepatch", ONEPATCH, "role_tests")
_REACH_TESTS = layout.analysis_table("onepatch", BOT, "reach_tests")


def _pairs(table: str) -> str:
    return layout.analysis_table("interactions", PAIRS, table)


PANELS: list[Panel] = [
    Panel("fig5", "A", assay_scene,
          {"steps": _STEPS, "food": _PELLETS},
          "One-patch assay scene (onepatch steps at t=0 and food table): resident A at the central patch, "
          "intruder B facing it, pellets at the start (inset), grey: B's start in every social episode."),
    *[Panel("fig5", letter, trajectory_panel(cond), {"steps": _STEPS},
            f"Paths of A and B in the first {_class_label(cond)} episode of the onepatch assay (steps table); "
            "o marks the start, * each pellet eaten; dashed circle: the patch.")
      for letter, cond in zip("BCD", TRAJECTORY_CONDITIONS, strict=True)],
    Panel("fig5", "E", food_by_role("B"), {"food": _FOOD, "tests": _ROLE_TESTS},
          "Food eaten per episode by the intruder B in each size class (A<B, A=B, A>B), each beside B alone at the "
          "size B has in that class (0.75, 0.5, 0.25; lighter box) (onepatch, behaviour food_per_agent); box and "
          "every episode. Brackets: Mann-Whitney of B's food in the class vs B alone at the same size (onepatch "
          "role_tests, role B, group = the class)."),
    Panel("fig5", "F", food_by_role("A"), {"food": _FOOD, "tests": _ROLE_TESTS},
          "Food eaten per episode by the resident A in each size class, each beside A alone at the size A has in "
          "that class (0.25, 0.5, 0.75; lighter box) (onepatch, behaviour food_per_agent); box and every episode. "
          "Brackets: Mann-Whitney of A's food in the class vs A alone at the same size (onepatch role_tests, role "
          "A, group = the class)."),
    Panel("fig5", "G", food_course_by_role("B"), {"course": _COURSE},
          "Cumulative food of B over time, mean +- SEM over episodes, per size class (solid) and B alone at the "
          "class's size of B (dashed, lighter) (onepatch, onepatch food_time_course)."),
    Panel("fig5", "H", food_course_by_role("A"), {"course": _COURSE},
          "Cumulative food of A over time, mean +- SEM over episodes, per size class (solid) and A alone at the "
          "class's size of A (dashed, lighter) (onepatch, onepatch food_time_course)."),
    Panel("fig5", "I", bot_reach("mobility"), {"reach": _REACH, "tests": _REACH_TESTS},
          "Fraction of episodes in which the trained agent B reached the patch, bot frozen vs moving, per size "
          "pair; each point one bot EOD rate (bot assay, onepatch reach_rates). Stars: Fisher exact test of B's "
          "reach counts pooled over sizes and rates, frozen vs moving (onepatch reach_tests, contrast mobility)."),
    Panel("fig5", "J", bot_reach("eod"), {"reach": _REACH, "tests": _REACH_TESTS},
          "Fraction of episodes in which B reached the patch, bot silent (EOD rate 0) vs discharging (rates "
          "0.25-1), per size pair; each point one bot condition (bot assay, onepatch reach_rates). Stars: Fisher "
          "exact test of B's pooled reach counts, emitting vs silent (onepatch reach_tests, contrast eod)."),
    Panel("fig5", "K", size_difference("chase"),
          {"events": _pairs("chase_sizes"), "tests": _pairs("size_tests")},
          "Chaser minus chased body size per chasing bout (square2, interactions chase_sizes), with the median "
          "paired difference and Wilcoxon signed-rank stars (interactions size_tests, measure chase)."),
    Panel("fig5", "L", role_sizes("chase"),
          {"events": _pairs("chase_sizes"), "tests": _pairs("size_tests")},
          "Sizes of chaser and chased per chasing bout, pairs joined (square2, interactions chase_sizes); stars: "
          "Wilcoxon signed-rank chaser vs chased (interactions size_tests)."),
    Panel("fig5", "M", size_difference("bite"),
          {"events": _pairs("bite_sizes"), "tests": _pairs("size_tests")},
          "Biter minus bitten body size per bite (square2, interactions bite_sizes), with the median paired "
          "difference and Wilcoxon signed-rank stars (interactions size_tests, measure bite)."),
    Panel("fig5", "N", role_sizes("bite"),
          {"events": _pairs("bite_sizes"), "tests": _pairs("size_tests")},
          "Sizes of biter and bitten per bite, pairs joined (square2, interactions bite_sizes); stars: Wilcoxon "
          "signed-rank biter vs bitten (interactions size_tests)."),
    Panel("fig5", "O", bite_timing, {"timing": _pairs("bite_timing")},
          "Phase within its bout of every bite inside a bout, stacked by bout class (square2, interactions "
          "bite_timing)."),
    Panel("fig5", "P", bite_rate, {"rate": _pairs("bite_rate_by_class")},
          "Bites per ordered pair-step within bout range, by the biter's per-step interaction label (square2, "
          "interactions bite_rate_by_class)."),
]
