"""Every column of every rollout table, declared once (docs/architecture.md#tables).

Columns are snake_case with units in the name where they have one. Tables are
validated against these schemas before they are written; readers can rely on
names, order and types.
"""

from __future__ import annotations

import pandas as pd
import pyarrow as pa

F32, F64, I16, I32, B = pa.float32(), pa.float64(), pa.int16(), pa.int32(), pa.bool_()

# (name, type, one-line description): the one declaration of every column
KEYS = [("condition", pa.string(), "condition of the assay (config/assay/<name>.yaml)"),
        ("episode", I32, "episode index within the condition")]
STEP_KEYS = [("t", I32, "step index within the episode"),
             ("t_ms", F64, "time since the episode's start, ms (t / fps)"),
             ("agent", I16, "agent id")]

STEP_COLUMNS = KEYS + STEP_KEYS + [
    ("x_cm", F32, "position after the step, cm"), ("y_cm", F32, "position after the step, cm"),
    ("heading_rad", F32, "heading after the step, rad"), ("size", F32, "body size in [0, 1]"),
    ("move", F32, "move command in [0, 1] after mapping"), ("turn", F32, "turn command in [-1, 1] after mapping"),
    ("turn_rad", F32, "realised change of heading this step, rad"),
    ("eod", B, "emitted an EOD this step"), ("bite", B, "chose to bite"), ("ate", B, "ate a pellet"),
    ("bit", B, "bit another agent"), ("bite_target", I16, "the agent bitten this step, -1 for none"),
    ("was_bitten", B, "was bitten this step"), ("collided", B, "a move was cancelled by another body"),
    ("reward", F32, "reward of this step"),
    ("terminated", B, "the task ended the episode on this step (homing: 5 steps at home)"),
    ("success", B, "the episode ended on this step with its goal reached"),
    ("dist_agent_cm", F32, "distance to the nearest agent, cm (NaN alone)"),
    ("bearing_agent_rad", F32, "bearing of the nearest agent from the heading, rad"),
    ("dist_agent2_cm", F32, "distance to the second-nearest agent, cm (NaN with fewer than 3 agents)"),
    ("size_agent1", F32, "size of the nearest agent"), ("size_agent2", F32, "size of the second-nearest agent"),
    ("dist_food_cm", F32, "distance to the nearest live pellet, cm (NaN without food)"),
    ("bearing_food_rad", F32, "bearing of the nearest pellet from the heading, rad"),
    ("dist_wall_cm", F32, "distance to the nearest wall, cm"),
    ("bearing_wall_rad", F32, "bearing of the nearest wall's normal from the heading, rad"),
    ("food_count_5cm", I16, "live pellets within 5 cm"),
    ("food_front_5cm", I16, "of them within pi/4 of the heading"), ("food_left_5cm", I16, "of them on the left"),
    ("food_back_5cm", I16, "of them behind"), ("food_right_5cm", I16, "of them on the right"),
    ("n_knollen_agents", I16, "conspecifics whose EOD crosses the Knollenorgan threshold (heard)"),
    ("n_agents_100cm", I16, ("other agents whose centre is closer than sensors.knollenorgan.range_cm (default "
                             "100 cm): in Knollenorgan range, emitting or not")),
    ("morm_abs_mean", F32, "mean |normalised Mormyromast reading|"),
    ("amp_abs_mean", F32, "mean |normalised Ampullary reading|"),
    ("knollen_spikes", I16, "Knollenorgan sensors spiking, all slots"),
    ("log_morm_field", F32, ("log10 |E| (V/m) at the body centre of the dipoles the own EOD induces on others "
                             "(geometric: the own EOD taken as on, free space)")),
    ("log_morm_sensed", F32, ("log10 (V/m) of the largest Mormyromast reading as sensed (after the baseline "
                              "subtraction, so the self image only when emitting; noise, clip at E_max), from the "
                              "observation; NaN when no sensor reads above E_min")),
    ("log_amp_field", F32, "log10 |E| (V/m) at the body centre of the other bodies' intrinsic dipoles"),
    ("err_morm_rad", F32, "homing: heading minus the direction of the target's induced-dipole field, rad"),
    ("err_amp_rad", F32, "homing: heading minus the direction of the target's intrinsic field, rad"),
    ("err_knollen_rad", F32, "homing: heading minus the direction of the target's EOD field, rad"),
]

EPISODE_COLUMNS = KEYS + [
    ("agent", I16, "agent id"), ("size", F32, "body size in [0, 1]"),
    ("food_eaten", I32, "pellets eaten"), ("eod_probability", F32, "fraction of steps with an EOD"),
    ("bites_given", I32, "bites given"), ("bites_received", I32, "bites received"),
    ("mean_nn_dist_cm", F32, "mean distance to the nearest agent, cm"),
    ("return", F32, "sum of rewards up to the episode's end"), ("steps", I32, "steps up to the episode's end"),
    ("terminated", B, "ended by the task before the time limit"), ("success", B, "ended with its goal reached"),
]

FOOD_COLUMNS = KEYS + [
    ("pellet", I32, "pellet index within the episode, in order of appearance"),
    ("x_cm", F32, "position, cm"), ("y_cm", F32, "position, cm"),
    ("t_spawned", I32, "step it appeared (0 at the start)"), ("t_eaten", I32, "step it was eaten, -1 never"),
    ("eaten_by", I16, "agent that ate it, -1 never"),
]

# then h_0 .. h_{H-1}, float32: the GRU state that has taken in the observation step t returned (the world of the
# steps row t) and produced none of row t's actions; see efish.rollout.run.hidden_table
HIDDEN_COLUMNS = KEYS + STEP_KEYS[:1] + STEP_KEYS[2:]
HIDDEN_UNITS = ("the policy's GRU state after taking in the observation of step t (the world of the steps row "
                "with the same keys), before acting on it; one column per unit")

# One row per condition of an assay: what it resolved to in this run (every override applied), so that panels,
# clips and claims read the run's own record instead of composing configs again (efish.config.recorded).
CONDITION_COLUMNS = [
    ("condition", pa.string(), "condition of the assay (config/assay/<name>.yaml)"),
    ("position", I16, "its place in the assay's list; 0 is the control"),
    ("overrides", pa.list_(pa.string()), "the condition's own config overrides (its interventions)"),
    ("policy", pa.string(), "the trained policy that acts (selected, or a recipe of config/policy/)"),
    ("episodes", I32, "episodes run"), ("seed", I32, "seed of the first episode"),
    ("n_agents", I16, "agents per arena"),
    ("sizes", pa.list_(F32), "fixed body size per agent; empty: U(0, 1) per episode"),
    ("roles", pa.list_(pa.string()), "start placement per agent (random, resident, intruder, ...)"),
    ("muted", pa.list_(I16), "agents that never emit"), ("frozen", pa.list_(I16), "agents that never move"),
    ("bots", pa.list_(I16), "agents driven by the random-walk bot"),
    ("bot_eod_rate", F32, "bot: probability of an EOD each step"),
    ("arena_layout", pa.string(), "food layout of the arena"),
    ("arena_width_cm", F32, "arena width, cm"), ("arena_height_cm", F32, "arena height, cm"),
    ("fps", F64, "steps per second"), ("episode_steps", I32, "steps per episode (the scale's cap applied)"),
    ("config", pa.string(), "the condition's whole resolved config as JSON (efish.config.recorded reads it back)"),
]

COLUMNS = {"steps": STEP_COLUMNS, "episodes": EPISODE_COLUMNS, "food": FOOD_COLUMNS, "hidden": HIDDEN_COLUMNS,
           "conditions": CONDITION_COLUMNS}


def arrow_schema(columns: list[tuple]) -> pa.Schema:
    return pa.schema([(name, kind) for name, kind, _ in columns])


STEPS, EPISODES, FOOD = arrow_schema(STEP_COLUMNS), arrow_schema(EPISODE_COLUMNS), arrow_schema(FOOD_COLUMNS)
SCHEMAS = {"steps": STEPS, "episodes": EPISODES, "food": FOOD, "conditions": arrow_schema(CONDITION_COLUMNS)}


def hidden_schema(width: int) -> pa.Schema:
    """hidden.parquet: the keys, then one float32 column per GRU unit (``h_0`` ...)."""
    return pa.schema([(n, k) for n, k, _ in HIDDEN_COLUMNS] + [(f"h_{i}", F32) for i in range(width)])


def describe(name: str) -> str:
    """The columns of table ``name`` with their types and descriptions, one per line (``efish schema``)."""
    if name not in COLUMNS:
        raise ValueError(f"unknown table {name!r}: choose one of {', '.join(COLUMNS)}")
    rows = [(n, str(k), d) for n, k, d in COLUMNS[name]]
    if name == "hidden":
        rows.append(("h_0 .. h_{H-1}", "float", HIDDEN_UNITS))
    width, kind = max(len(n) for n, _, _ in rows), max(len(k) for _, k, _ in rows)
    return "\n".join(f"{n:<{width}}  {k:<{kind}}  {d}" for n, k, d in rows)


def to_table(df: pd.DataFrame, name: str) -> pa.Table:
    """The frame as an Arrow table of schema ``name``; one clear error if a column is missing or extra."""
    schema = schema_of(df, name)
    missing = [f.name for f in schema if f.name not in df.columns]
    extra = [c for c in df.columns if c not in schema.names]
    if missing or extra:
        raise ValueError(f"table {name!r}: missing columns {missing}, unexpected columns {extra}")
    return pa.Table.from_pandas(df[schema.names], schema=schema, preserve_index=False)


def schema_of(df: pd.DataFrame, name: str) -> pa.Schema:
    """The schema table ``name`` must have (hidden: as wide as ``df``'s GRU state)."""
    if name == "hidden":
        return hidden_schema(sum(c.startswith("h_") for c in df.columns))
    return SCHEMAS[name]


def check_file(path, name: str) -> None:
    """Raise ValueError unless the Parquet file at ``path`` has exactly schema ``name``."""
    import pyarrow.parquet as pq

    got = pq.read_schema(path)
    want = hidden_schema(sum(n.startswith("h_") for n in got.names)) if name == "hidden" else SCHEMAS[name]
    if not got.remove_metadata().equals(want):
        raise ValueError(f"{path} does not match schema {name!r}: {got.names} vs {want.names}")
