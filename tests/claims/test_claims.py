"""The claims (docs/claims/index.md): each claim holds on tables built so that it holds and fails on tables built the
other way round; missing tables give ``not run`` with a reason; reruns are identical; ``efish claims`` and
``efish compare-claims`` write and print what they promise."""

from __future__ import annotations

import functools
import re
import zlib

import numpy as np
import pandas as pd
import pytest

from efish import claims as cl
from efish.analysis.behaviour import (
    episode_summary,
    food_per_agent_episode,
    food_vs_size,
    theil_per_episode,
)
from efish.analysis.decoding import decode_episodes, food_decode_episodes, summarise
from efish.analysis.dynamics import plsc_episodes
from efish.analysis.dynamics_tests import size_tests
from efish.analysis.interactions import size_role_tests
from efish.analysis.onepatch import reach_tests
from efish.analysis.registry import run
from efish.analysis.signalling import fit_power_law
from efish.analysis.stats import spearman
from efish.claims import fig2, fig3, fig4, fig5, fig6
from efish.claims.context import Claim
from efish.claims.registry import CLAIM_FIGURES
from efish.claims.report import claims_markdown, compare_claims, load_claims
from efish.claims.statistics import bootstrap_ci
from efish.claims.verdicts import (
    PART_COLUMNS,
    ROW_COLUMNS,
    Outcome,
    Part,
    claim_verdict,
    decide_outcome,
    part_rows,
)
from efish.cli import main
from efish.config.recorded import recorded_conditions
from efish.layout import analysis_table, assay_table

from ..helpers import DEFAULT_FPS, HALF_FPS, REPO, cfg_with, conditions_of, recorded_table, rollout_tables

CFG = cfg_with("analysis.claims_resamples=40", "analysis.claims_fit_resamples=4")
#: The verdicts of a part that was decided against its delta.
DECIDED = ("holds", "absent", "opposite", "inconclusive")
A, R = analysis_table, assay_table


def rng_for(name: str) -> np.random.Generator:
    """A generator seeded by ``name``, the same in every process (``hash`` of a str is salted per process)."""
    return np.random.default_rng(zlib.crc32(name.encode()))


# ------------------------------------------------------------ table builders
def homing_steps(flip: bool, episodes: int = 12, steps: int = 60) -> pd.DataFrame:
    """Homer (agent 1) steps whose error angle lies within 0.62 rad of 0 or pi and aligns over time; ``flip``: near
    pi/2 and drifting away from alignment."""
    rng = np.random.default_rng(2)
    rows = []
    for e in range(episodes):
        t = np.arange(steps)
        frac = t / (steps - 1)
        if flip:
            err = np.pi / 2 - 0.6 * (1 - frac) + rng.normal(0, 0.02, steps)
        else:
            mag = 0.6 * (1 - frac) + np.abs(rng.normal(0, 0.02, steps))
            err = np.where(rng.random(steps) < 0.5, mag, np.pi - mag)
        rows.append(pd.DataFrame({"condition": "electric", "episode": e, "agent": 1, "t": t, "err_knollen_rad": err,
                                  "bearing_agent_rad": rng.uniform(-np.pi, np.pi, steps),
                                  "success": t == steps - 1, "x_cm": 10.0 + 0.5 * t, "y_cm": 35.0, "heading_rad": 0.0}))
    return pd.concat(rows, ignore_index=True)


def episodes_table(spec: dict[str, dict[str, float]], name: str, episodes: int = 15, agents: int = 4) -> pd.DataFrame:
    """Agent-episodes per condition whose food, EOD probability, bites and spacing have the given means."""
    rng = rng_for(name)
    rows = []
    for cond, means in spec.items():
        for e in range(episodes):
            for a in range(agents):
                rows.append({"condition": cond, "episode": e, "agent": a, "size": rng.uniform(0, 1),
                             "food_eaten": max(0, means.get("food", 5) + rng.normal(0, 0.5)),
                             "eod_probability": np.clip(means.get("eod", 0.3) + rng.normal(0, 0.02), 0, 1),
                             "bites_given": max(0, means.get("bites", 2) + rng.normal(0, 0.5)),
                             "bites_received": 1, "mean_nn_dist_cm": means.get("nn", 20) + rng.normal(0, 1)})
    return pd.DataFrame(rows)


def behaviour_tables(assay: str, spec: dict, control: str, episodes: int = 15, offered: int = 60) -> dict:
    """The behaviour analysis's episode summary of ``assay``, every episode offered ``offered`` pellets."""
    episodes = episodes_table(spec, assay, episodes)
    food = episodes[["condition", "episode"]].drop_duplicates()
    food = food.loc[food.index.repeat(offered)].assign(pellet=np.tile(np.arange(offered), len(food)))
    return {A("behaviour", assay, "episode_summary"): episode_summary(episodes, food)}


def c1(flip):
    rng = np.random.default_rng(1)
    e, r = 1.6 + rng.normal(0, 0.1, 20), 1.05 + rng.normal(0, 0.02, 20)
    e, r = (r, e) if flip else (e, r)
    return {A("homing", "homing", "trajectory_shape"): pd.DataFrame({
        "condition": ["electric"] * 20 + ["raycast"] * 20, "episode": np.r_[np.arange(20), np.arange(20)],
        "agent": 1, "tortuosity": np.r_[e, r], "success": True})}


def c2(flip):
    """The homing analysis's tables of :func:`homing_steps`, as the analysis computes them from the steps."""
    out = run("homing", {"steps": homing_steps(flip), "conditions": conditions_of("homing")}, CFG.analysis)
    return {A("homing", "homing", table): out[table] for table in ("alignment_episodes", "trajectory_shape")}


c3 = c2


def c4(flip):
    rng = np.random.default_rng(4)
    # whole steps: a geometric law (light tail) or a discretised Pareto (heavy tail)
    x = rng.geometric(0.3, 3000) if flip else np.floor(rng.pareto(1.0, 3000) + 1).astype(int)
    ids = pd.DataFrame({"condition": "control", "episode": np.arange(3000) % 20, "agent": 0, "idi_steps": x,
                        "idi_ms": x * 12.048})
    fit = pd.DataFrame([{"source": "agents", "condition": "control", **fit_power_law(x, 1, discrete=True),
                         "discrete": True, "xmin_steps": 1.0}])
    return {A("signalling", "wide2", "power_law"): fit, A("signalling", "wide2", "idis"): ids}


def wide_steps(flip: bool, episodes: int = 8, steps: int = 600, null: bool = False) -> pd.DataFrame:
    """Two agents whose EOD rate depends on distance to agent, food and wall (``flip``: does not) and rises around
    eating, biting and being bitten (``flip``: falls; ``null``: the same EOD probability, 0.3, at every step)."""
    rng = np.random.default_rng(5)
    rows = []
    events = np.zeros(steps, bool)
    events[[150, 300, 450]] = True
    near = np.convolve(events, np.ones(21), mode="same") > 0
    for e in range(episodes):
        for a in range(2):
            # distances drift slowly, so that the 20-step rolling rate sees the same distance as its step
            d = {k: (150 if k == "agent" else 10) * (0.5 + 0.5 * np.sin(2 * np.pi * np.arange(steps) / period
                                                                          + rng.uniform(0, 2 * np.pi)))
                 for k, period in (("agent", 240), ("food", 170), ("wall", 130))}
            by_distance = 0.3 if flip else 0.05 + 0.3 * (d["agent"] < 50) + 0.2 * (d["food"] < 3) + 0.2 * (d["wall"] < 3)
            p = np.where(near, 0.02 if flip else 0.95, by_distance)
            p = np.full(steps, 0.3) if null else p
            rows.append(pd.DataFrame({"condition": "control", "episode": e, "agent": a, "t": np.arange(steps),
                                      "eod": rng.random(steps) < p, "ate": events, "bit": events,
                                      "was_bitten": events, "size": 0.5 + 0.1 * a, "x_cm": 10.0 + 80 * a,
                                      "y_cm": 10.0, **{f"dist_{k}_cm": v for k, v in d.items()}}))
    return pd.concat(rows, ignore_index=True)


def signalling_tables(steps: pd.DataFrame, recorded: pd.DataFrame | None = None) -> dict:
    """The per-episode tables of wide2's signalling analysis that C5 and C6 read, run as the pipeline runs it: on
    the ``steps`` and the conditions wide2 recorded (``recorded``; one control at the default env.fps when not
    given), under the claims' analysis settings."""
    recorded = recorded_table(("control",)) if recorded is None else recorded
    out = run("signalling", {"steps": steps, "conditions": recorded}, CFG.analysis)
    return {A("signalling", "wide2", t): out[t] for t in ("rate_by_distance_episodes", "peri_event_episodes")}


def c5(flip):
    return signalling_tables(wide_steps(flip, episodes=24))  # fewer leave the wall part's interval wider than delta


def c6(flip):
    return signalling_tables(wide_steps(flip))


def c7(flip):
    rng = np.random.default_rng(7)
    out = {}
    for assay in ("patchy4", "square2"):
        n = 30
        small, big = rng.uniform(0, 0.4, n), rng.uniform(0.6, 1, n)
        biter, bitten = (small, big) if flip else (big, small)
        bites = pd.DataFrame({"condition": "control", "episode": np.arange(n) % 10, "biter_size": biter,
                              "bitten_size": bitten, "size_difference": biter - bitten})
        chases = pd.DataFrame(columns=["condition", "chaser_size", "chased_size"])
        out[A("interactions", assay, "bite_sizes")] = bites
        out[A("interactions", assay, "size_tests")] = size_role_tests(chases, bites)
    size = rng.uniform(0, 1, 40)
    out[A("behaviour", "patchy4", "win_ratio")] = pd.DataFrame({
        "condition": "control", "episode": np.arange(40) // 4, "agent": np.arange(40) % 4, "size": size,
        "win_ratio": np.clip((1 - size if flip else size) + rng.normal(0, 0.05, 40), 0, 1)})
    return out


def c8(flip):
    rng = np.random.default_rng(8)
    rows = []
    for e in range(20):
        size = rng.uniform(0, 1, 4) ** (1 + e / 5)  # episodes differ in size inequality
        food = np.round(20 * ((1 - size) if flip else size) ** 1.5 + rng.uniform(0, 0.5, 4))
        rows += [{"condition": "control", "episode": e, "agent": a, "size": size[a], "food_eaten": food[a]}
                 for a in range(4)]
    ep = pd.DataFrame(rows)
    return {A("behaviour", "patchy4", "food_vs_size"): food_vs_size(ep),
            A("behaviour", "patchy4", "food_per_agent"): food_per_agent_episode(ep),
            A("behaviour", "patchy4", "theil"): theil_per_episode(ep)}


def c9(flip):
    rng = np.random.default_rng(9)
    size = rng.uniform(0, 1, 40)
    eod = pd.DataFrame({"condition": "control", "episode": np.arange(40) // 4, "agent": np.arange(40) % 4,
                        "size": size, "eod_probability": (1 - size if flip else size) + rng.normal(0, 0.05, 40)})
    tests = spearman(eod, "size", "eod_probability", by="condition").assign(measure="eod_probability")
    return {A("behaviour", "patchy4", "eod_probability"): eod, A("behaviour", "patchy4", "size_tests"): tests}


def c10(flip):
    cut = {"food": 8 if flip else 2}  # M off and A off; the all-on control eats 5
    k_off = {"food": 9, "eod": 0.1, "bites": 0.5, "nn": 30} if flip else {"food": 5, "eod": 0.6, "bites": 5, "nn": 10}
    spec = {"M_A_K": {}, "A_K": cut, "M_K": cut, "M_A": k_off}
    return {**behaviour_tables("ablation4", spec, "M_A_K", episodes=25),
            **behaviour_tables("ablation1", {k: v for k, v in spec.items() if k != "M_A"}, "M_A_K")}


def c11(flip):
    spec = ({"control": {}, "self_only": {"food": 9, "eod": 0.6}, "cons_only": {"food": 1, "eod": 0.1}} if flip else
            {"control": {}, "self_only": {"food": 2, "eod": 0.1}, "cons_only": {"eod": 0.6}})
    return behaviour_tables("collective", spec, "control", episodes=25)


def c12(flip):
    spec = {"intact": {}, "muted": {"food": 8, "nn": 10} if flip else {"food": 2, "nn": 30}}
    return behaviour_tables("mute", spec, "intact")


def foods_table(spec: dict[str, tuple[int, np.ndarray]], episodes: int, seed: int) -> pd.DataFrame:
    """Agent-episodes per condition whose food is a multinomial draw of (total, shares)."""
    rng = np.random.default_rng(seed)
    rows = []
    for cond, (total, shares) in spec.items():
        for e in range(episodes):
            food = rng.multinomial(total, shares)
            rows += [{"condition": cond, "episode": e, "agent": a, "size": 0.5, "food_eaten": float(food[a]),
                      "eod_probability": 0.3, "bites_given": 0, "bites_received": 0, "mean_nn_dist_cm": 20.0}
                     for a in range(len(shares))]
    return pd.DataFrame(rows)


def shares(inequality: float) -> np.ndarray:
    """Four agents' shares, equal at 0 and unequal as it grows."""
    w = np.exp(inequality * np.arange(4))
    return w / w.sum()


def c13(flip, episodes: int = 200):
    # equal shares in both layouts: excess Theil T is 0 on average, and 200 episodes per layout resolve it within the
    # margin (half the control's typical |excess T|, about 0.013)
    equal = shares(0.0)
    patchy = foods_table({"patchy4": (12 if flip else 32, equal)}, episodes, 131)
    uniform = foods_table({"uniform4": (20, shares(1.0) if flip else equal)}, episodes, 132)
    # more patches at fixed total: less food for the iso series (relative to free) and more equal shares
    spec = {f"free_{n}": (40, shares(1.0 if flip else 1.5 - 0.3 * n)) for n in range(1, 6)}
    spec |= {f"iso_{n}": (24 + 4 * n if flip else 44 - 4 * n, shares(1.0 if flip else 1.5 - 0.3 * n))
             for n in range(1, 6)}
    npatch = foods_table(spec, 20, 133)
    out = {}
    for assay, ep in (("patchy4", patchy), ("uniform4", uniform), ("npatch", npatch)):
        out[A("behaviour", assay, "episode_summary")] = episode_summary(ep)
        out[A("behaviour", assay, "food_per_agent")] = food_per_agent_episode(ep)
    return out


def c14(flip):
    rng = np.random.default_rng(14)
    b_size = {"A_gt_B": 0.25, "A_eq_B": 0.5, "A_lt_B": 0.75}
    b_food = {"A_gt_B": 8, "A_eq_B": 6, "A_lt_B": 4} if flip else {"A_gt_B": 4, "A_eq_B": 6, "A_lt_B": 8}
    rows = []
    for e in range(20):
        for cond, size in b_size.items():
            pct_a, pct_b = round(100 * (1 - size)), round(100 * size)
            rows += [{"condition": cond, "episode": e, "agent": 0, "size": 1 - size, "food_eaten": 5 + rng.normal()},
                     {"condition": cond, "episode": e, "agent": 1, "size": size,
                      "food_eaten": b_food[cond] + rng.normal(0, 0.3)},
                     {"condition": f"A_alone_{pct_a}", "episode": e, "agent": 0, "size": 1 - size,
                      "food_eaten": 5 + rng.normal()},
                     {"condition": f"B_alone_{pct_b}", "episode": e, "agent": 0, "size": size,
                      "food_eaten": (10 if flip else 2) + rng.normal(0, 0.3)}]
    return {A("behaviour", "onepatch", "food_per_agent"): pd.DataFrame(rows), R("onepatch", "conditions"):
            conditions_of("onepatch")}


def c15(flip):
    reached = {("frozen", True): 9, ("frozen", False): 5, ("moving", True): 4, ("moving", False): 0}
    rows = []
    for rate in (0, 0.5, 1):
        for motion in ("frozen", "moving"):
            k = reached[(motion, rate > 0)]
            rows.append({"condition": f"bot0.5_B0.5_rate{rate:g}_{motion}", "agent": 1, "n_episodes": 10,
                         "n_reached": 10 - k if flip else k})
            rows.append({"condition": f"bot0.5_B0.5_rate{rate:g}_{motion}", "agent": 0, "n_episodes": 10,
                         "n_reached": 0})
    reach, conditions = pd.DataFrame(rows), conditions_of("bot")
    return {A("onepatch", "bot", "reach_rates"): reach, R("bot", "conditions"): conditions,
            A("onepatch", "bot", "reach_tests"): reach_tests(reach, recorded_conditions(conditions))}


def square_steps(flip: bool, episodes: int = 10, steps: int = 200) -> pd.DataFrame:
    """Two agents 5 cm apart, confronting in the first half of each episode, agent 0 chasing 1 in the second;
    bites mostly while confronting (``flip``: while chasing)."""
    rng = np.random.default_rng(16)
    rows = []
    for e in range(episodes):
        t = np.arange(steps)
        confront = t < steps // 2
        for a in range(2):
            heading = np.where(confront, 0.0 if a == 0 else np.pi, 0.0)
            p = np.where(confront == (not flip), 0.4, 0.02)
            rows.append(pd.DataFrame({"condition": "control", "episode": e, "t": t, "agent": a,
                                      "x_cm": 30.0 + 5 * a, "y_cm": 35.0, "heading_rad": heading, "size": 0.5,
                                      "bite_target": np.where(rng.random(steps) < p, 1 - a, -1)}))
    return pd.concat(rows, ignore_index=True)


def c16(flip):
    rng = np.random.default_rng(16)
    small, big = rng.uniform(0, 0.4, 30), rng.uniform(0.6, 1, 30)
    chaser, chased = (small, big) if flip else (big, small)
    chases = pd.DataFrame({"condition": "control", "episode": np.arange(30) % 10, "chaser_size": chaser,
                           "chased_size": chased, "size_difference": chaser - chased})
    bites = pd.DataFrame(columns=["condition", "biter_size", "bitten_size"])
    timing = pd.DataFrame({"condition": "control", "episode": np.arange(40) % 10,
                           "phase": rng.uniform(0.7, 1, 40) if flip else rng.uniform(0, 0.3, 40)})
    rates = run("interactions", {"steps": square_steps(flip), "conditions": recorded_table(("control",))},
                CFG.analysis)["bite_rate_episodes"]  # the rates as the analysis computes them from the steps
    return {A("interactions", "square2", "size_tests"): size_role_tests(chases, bites),
            A("interactions", "square2", "chase_sizes"): chases, A("interactions", "square2", "bite_timing"): timing,
            A("interactions", "square2", "bite_rate_episodes"): rates}


KNOLLENORGAN_OFF = "sensors.knollenorgan.enabled=false"


def c17(flip):
    rng = np.random.default_rng(17)
    width = CFG.train.hidden
    patchy = pd.DataFrame({"condition": "control", "episode": np.arange(20) // 2, "agent": np.arange(20) % 2,
                           "n_units": width, "d_eff": (0.8 if flip else 0.1) * width + rng.normal(0, 0.5, 20)})
    flat = rng.normal(10, 1, 10)
    rows = []
    for n in range(1, 5):
        k = (10 - 2 * n if flip else 2 * n) + rng.normal(0, 0.3, 10)
        no_k = (2 * n + rng.normal(0, 0.3, 10)) if flip else flat
        rows += [pd.DataFrame({"condition": f"n{n}_K", "episode": np.arange(10), "agent": 0, "d_eff": k}),
                 pd.DataFrame({"condition": f"n{n}_noK", "episode": np.arange(10), "agent": 0, "d_eff": no_k})]
    groupsize = pd.concat(rows, ignore_index=True)
    # the conditions' N and Knollenorgan state as the run recorded them (the names only label them)
    conditions = recorded_table({f"n{n}_{k}": [f"env.n_agents={n}", *([] if k == "K" else [KNOLLENORGAN_OFF])]
                                 for n in range(1, 5) for k in ("K", "noK")})
    return {A("dynamics", "patchy4", "dimensionality"): patchy, A("dynamics", "groupsize", "dimensionality"): groupsize,
            A("dynamics", "groupsize", "size_tests"): size_tests(groupsize, recorded_conditions(conditions)),
            R("groupsize", "conditions"): conditions}


def hidden_of(steps: pd.DataFrame, columns: dict[str, np.ndarray], units: int = 6, seed: int = 0) -> pd.DataFrame:
    """A hidden table keyed like ``steps``: the given unit columns, the other units noise."""
    rng = np.random.default_rng(seed)
    h = {f"h_{i}": columns.get(f"h_{i}", rng.normal(0, 1, len(steps))) for i in range(units)}
    return steps[["condition", "episode", "agent", "t"]].assign(**h)


def decoding_tables(assay: str, hidden: pd.DataFrame, steps: pd.DataFrame, agent: int | None = None) -> dict:
    """The dynamics analysis's decoding tables of ``assay`` (per episode and their means, also of food near and far),
    computed as the analysis computes them."""
    folds, near = CFG.analysis.decode_folds, CFG.analysis.claims_food_near_cm
    episodes = decode_episodes(hidden, steps, folds=folds, agent=agent)
    food = food_decode_episodes(hidden, steps, near, folds)
    return {A("dynamics", assay, "decoding"): summarise(episodes), A("dynamics", assay, "decoding_episodes"): episodes,
            A("dynamics", assay, "food_decoding"): summarise(food, by=("food",)),
            A("dynamics", assay, "food_decoding_episodes"): food}


def c18(flip, coded: str | None = None, seed: int = 18):
    """The homer's states carry the Knollenorgan error angle (``flip``: the bearing to the target; ``coded`` =
    "none": neither) as cos and sin with noise."""
    steps = homing_steps(False)
    rng = np.random.default_rng(seed)
    coded = coded or ("bearing_agent_rad" if flip else "err_knollen_rad")
    angle = steps[coded].to_numpy() if coded != "none" else rng.uniform(-np.pi, np.pi, len(steps))
    noise = rng.normal(0, 0.05, (2, len(steps)))
    hidden = hidden_of(steps, {"h_0": np.cos(angle) + noise[0], "h_1": np.sin(angle) + noise[1]}, seed=seed)
    return decoding_tables("homing", hidden, steps, agent=1)


def wide_pair(flip: bool, episodes: int = 10, steps: int = 240) -> dict:
    """wide2 steps and hidden states: agents 5, 50 and 130 cm apart in thirds of each episode, whose hidden states
    share a signal that fades with distance, whose power is higher far apart, whose codes favour the nearest-agent
    distance and food in range (``flip``: all reversed)."""
    rng = np.random.default_rng(20)
    frames, hidden = [], []
    gap = np.repeat([5.0, 50.0, 130.0], steps // 3)
    share = np.repeat([0.0, 0.5, 1.0] if flip else [1.0, 0.5, 0.0], steps // 3)
    loud = np.repeat([1.0, 1.0, 0.1] if flip else [0.1, 1.0, 1.0], steps // 3)
    for e in range(episodes):
        z = rng.normal(0, 1, (steps, 3))
        for a in range(2):
            t = np.arange(steps)
            dist_food = rng.uniform(0, 30, steps)
            turn = rng.normal(0, 1, steps)
            wall = rng.uniform(1, 20, steps)
            s = pd.DataFrame({"condition": "control", "episode": e, "agent": a, "t": t,
                              "x_cm": 15.0 + a * gap, "y_cm": 20.0, "dist_agent_cm": gap + rng.normal(0, 0.5, steps),
                              "n_knollen_agents": (gap < 60).astype(float), "turn_rad": turn,
                              "knollen_spikes": rng.integers(0, 12, steps), "n_agents_100cm": (gap < 100) * 1.0,
                              "log_morm_sensed": rng.normal(-6, 1, steps), "dist_wall_cm": wall,
                              "dist_food_cm": dist_food, "bearing_food_rad": rng.uniform(-np.pi, np.pi, steps)})
            near = CFG.analysis.claims_food_near_cm
            coded_food = (dist_food > near) if flip else (dist_food <= near)
            fields = np.random.default_rng([20, e, a]).normal([-6.0, -10.0], 1.0, (steps, 2))  # unrelated to the state
            s = s.assign(log_morm_field=fields[:, 0], log_amp_field=fields[:, 1])
            # the policy's own turn is perfectly decodable (a readout); the best sensed variable is the nearest-agent
            # distance (flip: the wall distance), carried on the log scale it is decoded on
            sensed = np.log10(wall) if flip else np.log10(s["dist_agent_cm"].to_numpy())
            cols = {"h_0": sensed + rng.normal(0, 0.05, steps), "h_7": turn,
                    "h_1": np.where(coded_food, s["dist_food_cm"] / 10, rng.normal(0, 1, steps)),
                    "h_2": np.where(coded_food, np.cos(s["bearing_food_rad"]), rng.normal(0, 1, steps)),
                    "h_3": np.where(coded_food, np.sin(s["bearing_food_rad"]), rng.normal(0, 1, steps))}
            shared = z * (share[:, None] if a else 1.0) + rng.normal(0, 0.3, (steps, 3))
            cols |= {f"h_{4 + i}": shared[:, i] * loud for i in range(3)}
            frames.append(s)
            hidden.append(hidden_of(s, cols, units=8, seed=e * 2 + a))
    s, h = pd.concat(frames, ignore_index=True), pd.concat(hidden, ignore_index=True)
    return {R("wide2", "steps"): s, R("wide2", "hidden"): h, R("wide2", "conditions"): recorded_table(("control",))}


def c19(flip):
    tables = wide_pair(flip)
    return decoding_tables("wide2", tables[R("wide2", "hidden")], tables[R("wide2", "steps")])


@functools.lru_cache(maxsize=None)
def wide2_dynamics(flip: bool, louder: float = 1.0) -> dict:
    """The dynamics analysis's tables of :func:`wide_pair`'s steps and hidden states (agent 0 of size 0.3, agent 1 of
    0.7), with the hidden states of the smaller agent (``flip``: the larger) ``louder`` times larger. Cached per
    argument: never edit the tables."""
    tables = wide_pair(flip)
    steps, hidden = tables[R("wide2", "steps")], tables[R("wide2", "hidden")]
    steps = steps.assign(size=np.where(steps["agent"] == 0, 0.3, 0.7))
    if louder != 1:
        scale = np.where(hidden["agent"] == (1 if flip else 0), louder, 1.0)
        hidden = hidden.assign(**{c: hidden[c] * scale for c in hidden if c.startswith("h_")})
    return run("dynamics", {"hidden": hidden, "steps": steps, "conditions": tables[R("wide2", "conditions")]},
               CFG.analysis)


def c20(flip):
    # the dynamics analysis's collapse row (its test is efish.analysis.plsc_tests's, tested there): 3 shared
    # dimensions near and none far, or the reverse, over 8 episodes (exact permutation p 2/256); the first PLSC
    # component per episode and bin as the analysis computes it from wide_pair's states
    near, far = (0.0, 3.0) if flip else (3.0, 0.0)
    collapse = pd.DataFrame([{"condition": "control", "agent_a": 0, "agent_b": 1, "near_hi_cm": 10.0,
                              "far_lo_cm": 100.0, "n_episodes": 8, "n_steps": 700, "near_significant": near,
                              "far_significant": far, "count_difference": far - near, "effect": far - near,
                              "p": 2 / 256, "p_less": 1 / 256 if not flip else 1.0, "n_assignments": 256,
                              "exact": True, "reason": ""}])
    return {A("dynamics", "wide2", "plsc_episodes"): wide2_dynamics(flip)["plsc_episodes"],
            A("dynamics", "wide2", "plsc_collapse"): collapse}


def c21(flip):
    """The dynamics analysis's power tables of wide_pair, whose far steps are louder (``flip``: quieter) than the
    near ones, and whose smaller agent's states are 1.5 times larger (``flip``: the larger agent's)."""
    out = wide2_dynamics(flip, 1.5)
    return {A("dynamics", "wide2", t): out[t] for t in ("dimensionality", "power_near_far", "power_roles",
                                                        "power_tests")}


#: Per registered claim, the builder of its planted tables above (``c7`` for C7).
BUILDERS = {cid: globals()[cid.lower()] for cid in cl.CLAIMS}


# Claims whose planted headline statistic is the same in every episode, so its interval has no width: C13's layouts
# eat fixed totals per episode (the median food difference is exact).
CONSTANT_HEADLINE = {"C13", "C20"}  # C20: every planted episode's rho is -1, so every interval of it is [-1, -1]


# -------------------------------------------------------------------- tests
def test_the_registry_lists_the_claims_of_the_docs_in_the_paper_order():
    text = (REPO / "docs/claims/index.md").read_text()
    # the table of smallest effects has a row per part, not per claim: the list of claims is every other table
    text = re.sub(r"^## Smallest effects of interest.*?(?=^## )", "", text, flags=re.M | re.S)
    listed = re.findall(r"^\| \[(C\d+)\]\(#c\d+\) \|", text, re.M)
    assert listed and list(cl.CLAIMS) == listed
    assert [int(c[1:]) for c in cl.CLAIMS] == sorted(int(c[1:]) for c in cl.CLAIMS)


def test_every_claim_a_figure_module_defines_is_registered_once_under_its_figure():
    defined = [(name, obj) for module in (fig2, fig3, fig4, fig5, fig6)
               for name, obj in vars(module).items() if isinstance(obj, Claim)]
    assert sorted(c.id for _, c in defined) == sorted(cl.CLAIMS)
    for name, c in defined:
        assert cl.CLAIMS[c.id] is c and name == c.id.lower()
        # fig5's module holds the claims of Fig 5: the panel's figure number is the module's
        assert c.compute.__module__ == f"efish.claims.fig{c.panel[0]}", (c.id, c.panel)
    # the groups of the claims along training's figures: each claim once, under the module that defines it
    figure_of = {cid: figure for figure, ids in CLAIM_FIGURES.items() for cid in ids}
    assert list(figure_of) == list(cl.CLAIMS) and list(CLAIM_FIGURES) == [f"fig{n}" for n in range(2, 7)]
    assert all(cl.CLAIMS[cid].compute.__module__ == f"efish.claims.{f}" for cid, f in figure_of.items())


@pytest.mark.parametrize("cid", list(BUILDERS))
def test_a_claim_holds_on_tables_built_so_and_is_opposite_on_the_reverse(cid):
    claim = cl.CLAIMS[cid]
    held, failed = claim.run(BUILDERS[cid](False), CFG), claim.run(BUILDERS[cid](True), CFG)
    assert set(held) == set(ROW_COLUMNS)
    assert held["verdict"] == "holds", held["reason"]
    # C5 has no direction ("varies"): without any dependence it is absent
    assert failed["verdict"] == ("absent" if cid == "C5" else "opposite"), failed["reason"]
    assert np.isfinite(held["effect"]) and held["n"] > 0
    if np.isfinite(held["ci_low"]):
        assert held["ci_low"] <= held["ci_high"]
    if cid not in CONSTANT_HEADLINE:  # the planted data vary, so a bootstrap interval has a width
        assert held["ci_low"] < held["ci_high"], (held["ci_low"], held["ci_high"])


@pytest.mark.parametrize("cid", list(BUILDERS))
def test_a_claim_without_its_tables_is_not_run_and_names_what_is_missing(cid):
    row = cl.CLAIMS[cid].run({}, CFG)
    assert row["verdict"] == "not run"
    assert "has not run at this scale" in row["reason"]
    assert any(path in row["reason"] for path in cl.CLAIMS[cid].tables)


def test_a_missing_assay_is_named_and_the_other_parts_still_count():
    tables = {k: v for k, v in c7(False).items() if "/square2/" not in k}
    row = cl.CLAIMS["C7"].run(tables, CFG)
    assert row["verdict"] == "inconclusive"  # two parts hold, the square2 part did not run
    assert "analysis interactions of assay square2 has not run" in row["reason"]


def test_degenerate_data_is_not_run_with_a_reason():
    shape = c1(False)[A("homing", "homing", "trajectory_shape")].assign(tortuosity=np.nan)
    row = cl.CLAIMS["C1"].run({A("homing", "homing", "trajectory_shape"): shape}, CFG)
    assert row["verdict"] == "not run" and "tortuosity" in row["reason"]
    path = A("behaviour", "mute", "episode_summary")
    tables = c12(False)
    row = cl.CLAIMS["C12"].run({**tables, path: tables[path].drop(columns="food_total")}, CFG)
    assert row["verdict"] == "inconclusive" and "group food, 2 agents: not run" in row["reason"]
    assert "food_total" in row["reason"]


def test_a_paired_design_decides_where_an_unpaired_test_sees_nothing():
    """C12 on episodes that differ a lot between themselves, muting cutting each one's food by more than delta (a
    fifth of the control's median): a Mann-Whitney of the conditions is far from significant, the paired test
    (rule 2) holds."""
    rng = np.random.default_rng(12)
    base = rng.uniform(20, 300, 12)
    cut = 0.3 * np.median(base)
    rows = [{"condition": c, "episode": e, "food_total": base[e] - (cut if c == "muted" else 0) + rng.normal(0, .3),
             "mean_nn_dist_cm": 20 + (4 if c == "muted" else 0) + rng.normal(0, .5)}
            for c in ("intact", "muted") for e in range(12)]
    summary = pd.DataFrame(rows)
    tables = {A("behaviour", "mute", "episode_summary"): summary.assign(food_offered=400)}
    from scipy.stats import mannwhitneyu

    x, c = (summary.loc[summary["condition"] == k, "food_total"] for k in ("muted", "intact"))
    assert mannwhitneyu(x, c).pvalue > 0.3
    row = cl.CLAIMS["C12"].run(tables, CFG)
    assert row["verdict"] == "holds", row["reason"]
    assert "paired over 12 shared episodes" in row["reason"]


def test_a_control_at_the_ceiling_makes_food_parts_not_decidable():
    """C11 when the control eats every pellet: the food parts are not decidable (rule 5), the EOD parts decide."""
    tables = c11(False)
    summary = tables[A("behaviour", "collective", "episode_summary")]
    control = summary["condition"] == "control"
    ceiling = summary.assign(food_total=np.where(control, summary["food_total"].round(), summary["food_total"]))
    # as many pellets as the control ate in each episode; plenty for the other conditions
    ceiling = ceiling.assign(food_offered=np.where(control, ceiling["food_total"], 60))
    row = cl.CLAIMS["C11"].run({**tables, A("behaviour", "collective", "episode_summary"): ceiling}, CFG)
    assert "food, self-only: not decidable" in row["reason"] and "at a ceiling" in row["reason"]
    assert "EOD probability, self-only: holds" in row["reason"]
    # what could not be tested cannot carry the claim (rule 9): the EOD parts hold, the claim is inconclusive
    assert row["verdict"] == "inconclusive", row["reason"]


@pytest.mark.parametrize(("episodes", "expected"), [(6, "not decidable"), (200, "holds")])
def test_no_difference_is_shown_equivalent_only_when_n_allows_it(episodes, expected):
    """K-off food equal to all-on: at n = 6 equivalence cannot be shown, not even at a zero difference (not
    decidable), at n = 200 it is (holds); the first version held it at any n where p >= 0.05."""
    rng = np.random.default_rng(episodes)
    summary = pd.DataFrame([{"condition": c, "episode": e, "food_total": 20 + rng.normal(0, 6), "eod_probability": 0.3,
                             "bites": 1.0, "mean_nn_dist_cm": 20.0} for c in ("M_A_K", "M_A") for e in range(episodes)])
    tables = {A("behaviour", "ablation4", "episode_summary"): summary.assign(food_offered=90)}
    part = cl.CLAIMS["C10"].run(tables, CFG)["reason"].split("; group food, K off (equivalent): ")[1]
    assert part.startswith(expected), part


def test_the_authors_self_only_mode_is_reported_beside_and_does_not_decide():
    tables = c11(False)
    summary = tables[A("behaviour", "collective", "episode_summary")]
    authors = summary[summary["condition"] == "self_only"].assign(condition="self_only_authors",
                                                                   food_total=summary["food_total"].max() * 3)
    tables[A("behaviour", "collective", "episode_summary")] = pd.concat([summary, authors], ignore_index=True)
    tables[A("behaviour", "collective", "episode_summary")] = tables[A("behaviour", "collective",
                                                                        "episode_summary")].assign(food_offered=200)
    row = cl.CLAIMS["C11"].run(tables, CFG)
    assert "food, self-only (authors' mode) (beside, not deciding): opposite" in row["reason"]
    assert row["verdict"] == "holds"


def test_c6_without_a_planted_event_effect_is_absent_with_a_proper_interval():
    """EOD probability unrelated to the events: every part is absent (its interval spans 0, with a width, within
    +-delta, one discharge per 20-step window)."""
    _, assessed = cl.CLAIMS["C6"].assess(signalling_tables(wide_steps(False, null=True)), CFG)
    parts = pd.DataFrame(part_rows("C6", assessed), columns=PART_COLUMNS)
    assert (parts["verdict"] == "absent").all(), parts[["part", "verdict", "reason"]]
    assert ((parts["ci_low"] < 0) & (parts["ci_high"] > 0)).all(), parts[["part", "ci_low", "ci_high"]]


def test_c5_and_c6_take_the_rate_that_wide2_recorded():
    """Issue 38: C6's change of the EOD rate around an event is in Hz of the frame rate the wide2 assay recorded
    (conditions.parquet), which the signalling analysis reads: agents that discharge on every step within 30 steps
    of an event and never otherwise change their rate by exactly fps Hz, 83 at the default env.fps and 41.5 at half
    of it. C5's Kendall's W ranks the rates, so it is the same at both."""
    steps = wide_steps(False)
    near = np.zeros(len(steps), bool)
    for event in (150, 300, 450):
        near |= (steps["t"] - event).abs().to_numpy() <= 30
    steps = steps.assign(eod=near)
    c5_effects = []
    for fps in (DEFAULT_FPS, HALF_FPS):
        tables = signalling_tables(steps, recorded_table({"control": [f"env.fps={fps:g}"]}))
        parts = {p.label: p for p in cl.CLAIMS["C6"].assess(tables, CFG)[1]}
        for event in ("ate", "bit", "was_bitten"):
            assert parts[event].effect == pytest.approx(fps), (event, parts[event].reason)
        c5_effects.append([p.effect for p in cl.CLAIMS["C5"].assess(tables, CFG)[1]])
    assert c5_effects[0] == c5_effects[1] and np.isfinite(c5_effects[0]).all()


def test_c5_and_c6_only_select_the_analysis_rows():
    """Issue 38: C5 and C6 read the signalling analysis's per-episode tables and nothing else: rows of another
    condition or event do not move them, an analysis run with other windows than the claims' stops C6 (its
    statistic would name the wrong lags), and a table of NaN rows stops them with the analysis's reason."""
    tables = c5(False)
    rates, change = (tables[A("signalling", "wide2", t)] for t in ("rate_by_distance_episodes", "peri_event_episodes"))
    before = {cid: cl.CLAIMS[cid].assess(tables, CFG)[1] for cid in ("C5", "C6")}
    assert set(cl.CLAIMS["C5"].tables) == {A("signalling", "wide2", "rate_by_distance_episodes")}
    assert set(cl.CLAIMS["C6"].tables) == {A("signalling", "wide2", "peri_event_episodes")}
    # the "food" rows shifted: only C5's food part moves
    shifted = rates.assign(rate_hz=np.where(rates["to"] == "food", rates["rate_hz"] * rates["bin"], rates["rate_hz"]))
    after = cl.CLAIMS["C5"].assess({**tables, A("signalling", "wide2", "rate_by_distance_episodes"): shifted}, CFG)[1]
    assert [a.effect == b.effect for a, b in zip(before["C5"], after, strict=True)] == [True, False, True]
    other = change.assign(event_lo=change["event_lo"] - 1)
    parts = cl.CLAIMS["C6"].assess({**tables, A("signalling", "wide2", "peri_event_episodes"): other}, CFG)[1]
    assert all(p.verdict == "not run" and "rerun the analysis" in p.reason for p in parts), [p.reason for p in parts]
    none = change.assign(change_hz=np.nan, reason="no agent-episode has 3 or more 'ate' events")
    parts = cl.CLAIMS["C6"].assess({**tables, A("signalling", "wide2", "peri_event_episodes"): none}, CFG)[1]
    assert all(p.reason == "no agent-episode has 3 or more 'ate' events" for p in parts)


def _complete_blocks(rates: pd.DataFrame) -> np.ndarray:
    """One part's per-episode rates (signalling rate_by_distance_episodes) as Friedman blocks: the bins at least half
    the episodes reach, over the episodes that reach all of them."""
    wide = rates.pivot_table(index=["condition", "episode"], columns="bin", values="rate_hz").to_numpy(np.float64)
    wide = wide[:, np.isfinite(wide).mean(axis=0) >= 0.5]
    return wide[np.isfinite(wide).all(axis=1)]


@pytest.mark.parametrize("null", [True, False], ids=["no distance effect", "a planted one"])
def test_c5s_effect_is_kendalls_w_above_its_null_expectation_inside_its_own_interval(null):
    """The third audit: C5 reported Kendall's W, whose null expectation is 1/n (never 0), with a bootstrap interval
    that duplicated episodes and so raised W (an estimate of 0.357 outside its own [0.363, 1]). The effect is now
    W - 1/n, chi2 / (n (k - 1)) - 1/n of scipy's Friedman test, and its jackknife interval over episodes contains
    it; with no distance effect the interval covers 0."""
    from scipy.stats import friedmanchisquare

    tables = signalling_tables(wide_steps(False, episodes=12, null=null))
    rates = tables[A("signalling", "wide2", "rate_by_distance_episodes")]
    for part in cl.CLAIMS["C5"].assess(tables, CFG)[1]:
        blocks = _complete_blocks(rates[rates["to"] == part.label])
        n, k = blocks.shape
        chi2, p = friedmanchisquare(*blocks.T)
        assert part.effect == pytest.approx(chi2 / (n * (k - 1)) - 1 / n) and part.p == pytest.approx(p)
        assert part.ci[0] <= part.effect <= part.ci[1] and part.ci_method.startswith("jackknife"), part
        assert (part.ci[0] < 0 < part.ci[1]) if null else part.verdict == "holds", part


def test_no_planted_effect_at_large_n_is_absent():
    """C12 with muting doing nothing, 200 episodes: both parts' intervals lie within +-delta, so both are absent
    and so is the claim (under "holds if p < alpha" they were only weaker, and could flip)."""
    tables = behaviour_tables("mute", {"intact": {}, "muted": {}}, "intact", episodes=200)
    row = cl.CLAIMS["C12"].run(tables, CFG)
    assert row["verdict"] == "absent" and row["parts"] == "2 absent", row["reason"]
    assert "group food, 2 agents: absent" in row["reason"] and "spacing, 2 agents: absent" in row["reason"]


def test_c13_holds_on_a_sweep_where_intake_and_inequality_fall_with_the_patch_count():
    row = cl.CLAIMS["C13"].run(c13(False), CFG)
    for part in ("iso per-fish food vs n: holds", "iso excess Theil vs n: holds", "free excess Theil vs n: holds"):
        assert part in row["reason"]


def test_c19_ignores_perfectly_decodable_input_copies_and_ranks_the_sensed_variables():
    """The policy's own turn and its largest Mormyromast input are decoded perfectly (copies of its input, rule 7):
    they are no competitors, and the nearest-agent distance, the best sensed variable, makes the claim hold."""
    pair = wide_pair(False)
    steps = pair[R("wide2", "steps")]
    hidden = pair[R("wide2", "hidden")].assign(h_8=steps["log_morm_sensed"].to_numpy())
    tables = decoding_tables("wide2", hidden, steps)
    readouts = tables[A("dynamics", "wide2", "decoding")].set_index("target")
    assert readouts.loc["turn_rad", "skill"] > 0.9 and readouts.loc["log_morm_sensed", "skill"] > 0.9
    row = cl.CLAIMS["C19"].run(tables, CFG)
    assert row["verdict"] == "holds", row["reason"]
    assert "turn_rad" not in row["reason"] and "log_morm_sensed" not in row["reason"]
    assert "skill (Fig 6E): dist_agent_cm" in row["reason"]


@pytest.mark.parametrize(("field", "expected"), [("log_morm_field", "absent"), ("log_amp_field", "holds")])
def test_c19_ranks_the_mormyromast_field_and_only_the_variables_its_statement_names(field, expected):
    """The third audit: C19 ranked bearings, sizes, food and the Ampullary field, but not the Mormyromast field at
    the body centre, which the rollout records (log_morm_field) and the claim names beside the wall distance. A
    state that carries the Mormyromast field as well as the nearest-agent distance (both near 1) leaves no gap as
    large as delta: the part is absent; one that
    carries the Ampullary field so is decoded (and listed) but not ranked: the claim still holds."""
    pair = wide_pair(False)
    steps = pair[R("wide2", "steps")]
    hidden = pair[R("wide2", "hidden")].assign(h_8=steps[field].to_numpy())
    part = cl.CLAIMS["C19"].assess(decoding_tables("wide2", hidden, steps), CFG)[1][0]
    assert part.label == "agent features best" and part.verdict == expected, (part.verdict, part.reason)
    ranked, _, unranked = part.reason.partition("skill (Fig 6E): ")[2].partition("; not ranked: ")
    assert {t.split()[0] for t in ranked.split(", ")} == {"dist_agent_cm", "n_agents_100cm", "log_morm_field",
                                                          "dist_wall_cm"}
    assert "log_amp_field" in unranked and "dist_food_cm" in unranked


def test_decoding_claims_read_the_analysis_tables_and_say_what_they_lack():
    """C18 and C19 select rows of the dynamics decoding tables: a target the analysis could not decode is a not-run
    part with the analysis's reason."""
    tables = c18(False)
    episodes = tables[A("dynamics", "homing", "decoding_episodes")]
    lacking = episodes[episodes["target"] != "err_knollen_rad"]
    lacking = pd.concat([lacking, pd.DataFrame([{"condition": "electric", "target": "err_knollen_rad",
                                                  "episode": np.nan, "skill": np.nan,
                                                  "reason": "steps table lacks column 'err_knollen_rad'"}])])
    row = cl.CLAIMS["C18"].run({A("dynamics", "homing", "decoding_episodes"): lacking}, CFG)
    assert row["verdict"] == "not run" and "lacks column 'err_knollen_rad'" in row["reason"], row["reason"]
    assert set(cl.CLAIMS["C18"].tables) == {A("dynamics", "homing", "decoding_episodes")}
    assert all(t.startswith("analysis/dynamics/wide2/") for t in cl.CLAIMS["C19"].tables)


def test_claims_on_per_unit_tables_read_only_analysis_tables_and_say_what_the_analysis_lacked():
    """C2, C3, C16, C20 and C21 select rows of the homing, interactions and dynamics analyses' per-unit tables (issue
    38), never a rollout table; where the analysis had no unit, the part is not run with the analysis's reason."""
    for cid in ("C2", "C3", "C16", "C20", "C21"):
        assert all(t.startswith("analysis/") for t in cl.CLAIMS[cid].tables), cid
    steps = homing_steps(False).drop(columns="bearing_agent_rad")
    out = run("homing", {"steps": steps, "conditions": conditions_of("homing")}, CFG.analysis)
    row = cl.CLAIMS["C2"].run({A("homing", "homing", "alignment_episodes"): out["alignment_episodes"]}, CFG)
    assert row["verdict"] == "not run" and "lacks columns ['bearing_agent_rad']" in row["reason"], row["reason"]
    apart = wide_pair(False)
    hidden = apart[R("wide2", "hidden")]
    none_shared = plsc_episodes(hidden[hidden["agent"] == 0], apart[R("wide2", "steps")])
    row, parts = cl.CLAIMS["C20"].assess({**c20(False), A("dynamics", "wide2", "plsc_episodes"): none_shared}, CFG)
    assert (parts[0].verdict, parts[0].reason) == ("not run", "agents 0 and 1 share no step")
    assert row["verdict"] == "inconclusive"  # the collapse part still holds, the other did not run


def test_decoding_parts_without_a_planted_effect_reject_at_about_the_nominal_rate():
    """The third arm beside the paper's sign and the opposite one: C18 with neither angle in the state, C19's food
    part with food coded alike near and far. Each holds or is opposite in at most about 5% of 20 planted
    datasets; at most 4 of 20 (binomial tail 1.6% at a true 5%)."""
    decided = {"C18": 0, "C19": 0}
    for seed in range(20):
        part = cl.CLAIMS["C18"].assess(c18(False, coded="none", seed=100 + seed), CFG)[1][0]
        assert part.n == 12 and part.verdict in DECIDED, part.reason
        decided["C18"] += part.verdict in ("holds", "opposite")
        food = next(p for p in cl.CLAIMS["C19"].assess(food_alike(seed), CFG)[1] if p.label == "food near > far")
        assert food.n == 10 and food.verdict in DECIDED, food.reason
        decided["C19"] += food.verdict in ("holds", "opposite")
    assert all(k <= 4 for k in decided.values()), decided


def food_alike(seed: int) -> dict:
    """wide2 states that carry the food distance and bearing with the same noise whether the pellet is near or far."""
    rng = np.random.default_rng(300 + seed)
    steps = []
    for e in range(10):
        for a in range(2):
            n = 120
            steps.append(pd.DataFrame({"condition": "control", "episode": e, "agent": a, "t": np.arange(n),
                                       "dist_food_cm": np.r_[rng.uniform(0, 5, n // 2), rng.uniform(5, 30, n // 2)],
                                       "bearing_food_rad": rng.uniform(-np.pi, np.pi, n)}))
    steps = pd.concat(steps, ignore_index=True)
    dist, bearing = steps["dist_food_cm"].to_numpy(), steps["bearing_food_rad"].to_numpy()
    # each variable standardised within its range, so that near and far carry it equally (the distance as its
    # log10, the scale it is decoded on)
    near, log = dist <= CFG.analysis.claims_food_near_cm, np.log10(dist)
    scaled = np.where(near, (log - log[near].mean()) / log[near].std(), (log - log[~near].mean()) / log[~near].std())
    noise = rng.normal(0, 1.0, (3, len(steps)))
    hidden = hidden_of(steps, {"h_0": scaled + noise[0], "h_1": np.cos(bearing) + noise[1] / 1.4,
                               "h_2": np.sin(bearing) + noise[2] / 1.4}, seed=seed)
    return decoding_tables("wide2", hidden, steps)


def test_bootstrap_reruns_are_identical_and_the_seed_matters():
    def agent_part(cfg):  # C15's parts: a Fisher test, its difference of reach rates a bootstrap over episodes
        part = next(p for p in cl.CLAIMS["C15"].assess(c15(False), cfg)[1] if p.label == "frozen vs moving bot")
        assert part.ci_method.startswith("bootstrap")
        return part.effect, part.ci, part.p
    first, again = agent_part(CFG), agent_part(CFG)
    assert first == again
    other = agent_part(cfg_with("analysis.claims_resamples=40", "analysis.claims_seed=7"))
    assert other[1] != first[1] and other[0] == first[0]


def test_an_interval_that_inverts_its_test_does_not_move_with_the_resampling_seed():
    """The second audit: C12's bootstrap endpoint moved from -0.17 to +0.93 with the seed. The paired parts' intervals
    invert the signed-rank test: no resampling, the same interval at any seed or resample count."""
    tables = c12(False)
    first = cl.CLAIMS["C12"].run(tables, CFG)
    other = cl.CLAIMS["C12"].run(tables, cfg_with("analysis.claims_resamples=40", "analysis.claims_seed=7"))
    assert (other["ci_low"], other["ci_high"]) == (first["ci_low"], first["ci_high"])
    assert np.isfinite(first["ci_low"]) and first["ci_low"] < first["ci_high"]


def test_bootstrap_resamples_whole_units_within_strata():
    data = pd.DataFrame({"condition": ["a"] * 4 + ["b"] * 2, "episode": [0, 0, 1, 1, 0, 1],
                         "v": [1.0, 1.0, 3.0, 3.0, 10.0, 10.0]})
    seen = []

    def stat(d):
        seen.append(d)
        return d.loc[d["condition"] == "a", "v"].mean()
    lo, hi = bootstrap_ci(data, stat, ["episode"], 200, np.random.default_rng(0), strata="condition")
    assert 1.0 <= lo <= hi <= 3.0
    assert all((d["condition"] == "a").sum() == 4 and (d["condition"] == "b").sum() == 2 for d in seen)


def test_verdict_rules_follow_claims_md():
    """Rule 10: a part decided against delta from its 1 - 2 alpha interval; the claim by Holm over its parts."""
    def part(ci, sign=+1, effect=None, p=0.01, **kw):
        effect = sum(ci) / 2 if effect is None else effect
        return decide_outcome(Outcome(effect, p, 10, sign, ci, **kw), 0.1, 0.05)[0]
    assert part((0.2, 0.5)) == "holds" and part((-0.05, 0.08)) == "absent"
    assert part((-0.5, -0.2)) == "opposite" and part((0.05, 0.3)) == "inconclusive"
    assert part((0.2, 0.5), sign=-1) == "opposite" and part((-0.5, -0.2), sign=-1) == "holds"
    # "no difference": within +-delta holds, beyond it opposite, an interval 2 delta wide cannot decide
    assert part((-0.05, 0.05), sign=0) == "holds" and part((0.3, 0.6), sign=0) == "opposite"
    assert part((-0.3, 0.3), sign=0) == "not decidable" and part((0.0, 0.15), sign=0) == "inconclusive"
    # "any difference": holds beyond delta, absent below it, never opposite
    assert part((0.2, 0.5), sign=None) == "holds" and part((-0.1, 0.05), sign=None) == "absent"
    assert part((0.2, 0.5), p_floor=0.125) == "not decidable"  # its test cannot reach p < 2 alpha at its n
    holds, absent = Part("a", "", verdict="holds", p_opposite=1.0), Part("b", "", verdict="absent", p_opposite=1.0)
    opposite = Part("c", "", verdict="opposite", p_opposite=0.001)
    assert claim_verdict([holds, holds], 0.05) == "holds" and claim_verdict([absent, absent], 0.05) == "absent"
    assert claim_verdict([holds, opposite], 0.05) == "opposite"
    assert claim_verdict([holds, Part("c", "", verdict="opposite", p_opposite=0.04)], 0.05) == "inconclusive"
    assert claim_verdict([holds, absent], 0.05) == "inconclusive"
    assert claim_verdict([holds, Part("d", "")], 0.05) == "inconclusive"  # an untested part cannot carry the claim
    assert claim_verdict([Part("d", ""), Part("e", "")], 0.05) == "not run"
    assert claim_verdict([Part("d", ""), Part("e", "", verdict="not decidable")], 0.05) == "not decidable"


def test_the_workflow_inputs_are_the_claim_tables_the_scale_produces():
    smoke = {name: cfg_with("scale=smoke", f"assay={name}").assay for name in ("homing", "patchy4")}
    produced = cl.produced_tables(smoke)
    assert A("homing", "homing", "trajectory_shape") in produced and R("patchy4", "hidden") in produced
    assert A("behaviour", "homing", "episode_summary") not in produced  # behaviour does not run on homing
    needed = [t for t in cl.claim_tables() if t in produced]
    assert needed and all(t.split("/")[1] in ("homing", "patchy4") or t.split("/")[2] in ("homing", "patchy4")
                          for t in needed)


@pytest.mark.parametrize("cid, signs", [("C5", [np.nan] * 3), ("C7", [1.0] * 3), ("C10", None), ("C20", [-1.0] * 2)])
def test_the_parts_rows_are_the_parts_of_the_claims_row(cid, signs):
    """One row per part with its own effect, interval, p, verdict and the paper's sign; the claim's row (unchanged)
    shows the first deciding part that ran."""
    claim = cl.CLAIMS[cid]
    tables = BUILDERS[cid](False)
    row, parts = claim.assess(tables, CFG)
    assert row == claim.run(tables, CFG)
    rows = pd.DataFrame(part_rows(cid, parts), columns=PART_COLUMNS)
    assert rows["part"].tolist() == [p.label for p in parts] and (rows["claim"] == cid).all()
    if signs is not None:
        np.testing.assert_array_equal(rows["sign"], signs)
    else:  # C10: the K-off food part is "no difference" (sign 0), the others have a direction
        assert 0.0 in set(rows["sign"]) and {1.0, -1.0} & set(rows["sign"])
    shown = rows[rows["decides"] & ~rows["verdict"].isin(["not run", "not decidable"])].iloc[0]
    assert (shown["effect"], shown["ci_low"], shown["ci_high"], shown["p"]) == (row["effect"], row["ci_low"],
                                                                                 row["ci_high"], row["p"])


def test_a_claim_that_did_not_run_has_one_part_row_saying_why():
    row, parts = cl.CLAIMS["C1"].assess({}, CFG)
    (only,) = part_rows("C1", parts)
    assert only["verdict"] == "not run" and np.isnan(only["effect"]) and np.isnan(only["sign"])
    assert only["reason"] == row["reason"]


# ------------------------------------------------------------------ the CLI
@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """A small results folder: two assays' rollout tables and their analyses, run for real."""
    root = tmp_path_factory.mktemp("results") / "smallrun"
    for assay in ("mute", "patchy4"):
        cfg = cfg_with("scale=smoke", f"assay={assay}")
        tables = rollout_tables(seed=3, conditions=tuple(cfg.assay.conditions), episodes=4, n_agents=4, steps=60)
        for name in ("steps", "episodes"):
            (root / "assays" / assay).mkdir(parents=True, exist_ok=True)
            tables[name].to_parquet(root / "assays" / assay / f"{name}.parquet")
        out = run("behaviour", tables, cfg.analysis)
        (root / "analysis" / "behaviour" / assay).mkdir(parents=True)
        for name, table in out.items():
            table.to_parquet(root / "analysis" / "behaviour" / assay / f"{name}.parquet")
    return root


def test_efish_claims_writes_the_table_and_the_page(results, tmp_path, capsys):
    out = tmp_path / "claims"
    assert main(["claims", "scale=smoke", "analysis.claims_resamples=20", "analysis.claims_fit_resamples=2",
                 "--results", str(results), "--out", str(out)]) == 0
    table = pd.read_parquet(out / "claims.parquet")
    assert list(table.columns) == ROW_COLUMNS and list(table["claim"]) == list(cl.CLAIMS)
    assert set(table["verdict"]) <= set(cl.VERDICTS)
    assert table.set_index("claim").loc["C12", "verdict"] != "not run"  # mute's tables are there
    assert table.set_index("claim").loc["C1", "verdict"] == "not run"  # homing's are not
    page = (out / "claims.md").read_text()
    assert page.startswith("Claims of the paper at scale smoke (run smallrun), ")
    assert "| C12 | 4I,J |" in page and (out / "provenance.json").is_file()
    again = tmp_path / "again"
    main(["claims", "scale=smoke", "analysis.claims_resamples=20", "analysis.claims_fit_resamples=2",
          "--results", str(results), "--out", str(again)])
    pd.testing.assert_frame_equal(table, pd.read_parquet(again / "claims.parquet"))
    parts = pd.read_parquet(out / "claim_parts.parquet")
    assert list(parts.columns) == PART_COLUMNS and parts["claim"].unique().tolist() == list(cl.CLAIMS)
    assert len(parts) > len(table) and (parts.groupby("claim").size()["C5"] == 3)
    pd.testing.assert_frame_equal(parts, pd.read_parquet(again / "claim_parts.parquet"))


def test_claims_and_parts_compute_both_tables_at_once(results):
    cfg = cfg_with("scale=smoke", "analysis.claims_resamples=20", "analysis.claims_fit_resamples=2")
    claims, parts = cl.claims_and_parts(results, cfg, ["C9", "C12"])
    pd.testing.assert_frame_equal(claims, cl.claims_table(results, cfg, ["C9", "C12"]))
    assert parts["claim"].unique().tolist() == ["C9", "C12"] and parts["decides"].dtype == bool
    assert parts.set_index(["claim", "part"]).index.is_unique


def test_compare_claims_prints_both_runs_side_by_side(results, tmp_path, capsys):
    a = pd.DataFrame([cl.CLAIMS["C12"].run(c12(False), CFG), cl.CLAIMS["C9"].run(c9(False), CFG)])
    b = pd.DataFrame([cl.CLAIMS["C12"].run(c12(True), CFG)])
    (tmp_path / "runa" / "claims").mkdir(parents=True)
    (tmp_path / "runb").mkdir()
    a.to_parquet(tmp_path / "runa" / "claims" / "claims.parquet")
    b.to_parquet(tmp_path / "runb" / "claims.parquet")
    assert main(["compare-claims", str(tmp_path / "runa" / "claims"), str(tmp_path / "runb" / "claims.parquet")]) == 0
    text = capsys.readouterr().out
    assert "runa verdict" in text and "runb verdict" in text
    *table, agreement = text.splitlines()
    lines = {line.split()[0]: line for line in table[1:]}
    assert list(lines) == ["C9", "C12"]
    # the stability summary: C12 holds in one run and is opposite in the other
    assert agreement == ("selected seeds' verdicts: the same for 0 of 1 claims; holds in one and opposite in the "
                         "other: C12 (runa vs runb)")
    assert "holds" in lines["C12"] and "opposite" in lines["C12"] and lines["C12"].rstrip().endswith("*")
    assert main(["compare-claims", str(tmp_path / "nowhere"), str(tmp_path / "runb")]) == 2
    assert "no claims table" in capsys.readouterr().err


def test_load_claims_resolves_a_run_name(tmp_path):
    t = pd.DataFrame([cl.CLAIMS["C9"].run(c9(False), CFG)])
    (tmp_path / "results" / "myrun" / "claims").mkdir(parents=True)
    t.to_parquet(tmp_path / "results" / "myrun" / "claims" / "claims.parquet")
    name, table = load_claims("myrun", tmp_path / "results")
    assert name == "myrun" and table["claim"].tolist() == ["C9"]
    both = compare_claims(table, table, (name, name))
    assert both.loc[0, "moved"] == "" and claims_markdown(table, "header").startswith("header\n")


# ------------------------------------------------------ intervals agree with their tests; verdict logic (rule 9)
def paired_summary(control: list[float], other: list[float], measure: str = "food_total") -> pd.DataFrame:
    """An episode summary of conditions 'intact' and 'muted' with the given per-episode values."""
    rows = [{"condition": c, "episode": e, measure: v, "mean_nn_dist_cm": 20.0}
            for c, values in (("intact", control), ("muted", other)) for e, v in enumerate(values)]
    return pd.DataFrame(rows)


def mute_tables(control: list[float], other: list[float]) -> dict:
    summary = paired_summary(control, other)
    return {A("behaviour", "mute", "episode_summary"): summary.assign(food_offered=90)}


@pytest.mark.parametrize("flip", [False, True], ids=["the paper's sign", "the opposite sign"])
@pytest.mark.parametrize("cid", list(BUILDERS))
def test_no_decided_part_has_an_interval_that_contradicts_its_test(cid, flip):
    """Every part whose interval inverts its test (rule 8), at level 1 - 2 alpha / family: 0 strictly outside it
    means p < 2 alpha (the Holm-adjusted p is at most family x the raw one); without a family, 0 strictly inside
    it means p >= 2 alpha."""
    _, parts = cl.CLAIMS[cid].assess(BUILDERS[cid](flip), CFG)
    alpha = CFG.analysis.claims_alpha
    for part in parts:
        if not part.ci_method.startswith("inverts") or part.verdict in ("not run", "not decidable"):
            continue
        low, high = part.ci
        assert not ((low > 0 or high < 0) and part.p >= 2 * alpha), (part.label, part.verdict, part.p, part.ci)
        assert not (part.family == 1 and low < 0 < high and part.p < 2 * alpha), (part.label, part.p, part.ci)
        assert low <= part.effect <= high, (part.label, part.effect, part.ci)
        assert f"level {1 - 2 * alpha / part.family:.3g}" in part.ci_method, part.ci_method


def test_a_part_that_cannot_reach_significance_at_its_n_says_so():
    """Four episodes, every one lower when muted: the smallest two-sided signed-rank p is 2 / 16 > 2 alpha, so the
    0.9 interval cannot exclude any effect: not decidable, and says so, never inconclusive. Five (2 / 32 < 0.1)
    decide."""
    row = cl.CLAIMS["C12"].run(mute_tables([10, 11, 12, 13], [5, 6, 7, 8]), CFG)
    assert "group food, 2 agents: not decidable" in row["reason"]
    assert "cannot reach p < 0.1 at n = 4" in row["reason"] and row["verdict"] != "holds"
    five = cl.CLAIMS["C12"].run(mute_tables([10, 11, 12, 13, 14], [5, 6, 7, 8, 9]), CFG)
    assert "group food, 2 agents: holds" in five["reason"]


def test_one_episode_is_not_run():
    row = cl.CLAIMS["C12"].run(mute_tables([10], [5]), CFG)
    assert "group food, 2 agents: not run" in row["reason"] and "n = 1" in row["reason"]


def test_no_food_in_either_condition_is_a_floor_and_equal_food_is_no_difference():
    """All zeros in both conditions: no test can see a cut (rule 5). Equal non-zero food in every episode: no
    difference, a directional part is absent (not 'not decidable'), with its effect 0."""
    floor = cl.CLAIMS["C12"].assess(mute_tables([0] * 10, [0] * 10), CFG)[1]
    assert floor[0].verdict == "not decidable" and "at a floor" in floor[0].reason
    equal = cl.CLAIMS["C12"].assess(mute_tables([4, 6, 5, 7, 3, 5, 6, 4, 5, 6], [4, 6, 5, 7, 3, 5, 6, 4, 5, 6]), CFG)[1]
    assert equal[0].verdict == "absent" and equal[0].effect == 0 and "no difference in any of the 10" in equal[0].reason


def test_all_zero_differences_are_shown_equivalent():
    """K-off food equal to all-on food in every one of 12 episodes: the interval is [0, 0], within +-delta (a fifth
    of the control's median, at least one pellet)."""
    base = [5.0, 6, 4, 7, 5, 6, 5, 4, 6, 5, 7, 5]
    spec = [{"condition": c, "episode": e, "food_total": v, "eod_probability": 0.3, "bites": 1.0,
             "mean_nn_dist_cm": 20.0} for c in ("M_A_K", "M_A") for e, v in enumerate(base)]
    summary = pd.DataFrame(spec)
    tables = {A("behaviour", "ablation4", "episode_summary"): summary.assign(food_offered=60)}
    parts = {p.label: p for p in cl.CLAIMS["C10"].assess(tables, CFG)[1]}
    k_off = parts["group food, K off (equivalent)"]
    assert k_off.verdict == "holds" and k_off.ci == (0.0, 0.0)
    assert k_off.reference == 5.0 and k_off.delta == 1.0  # 20% of 5 pellets is below one whole pellet


def k_off_food(spread: float, shift: float = 0.0, episodes: int = 12) -> Part:
    """C10's K-off food part on 12 paired episodes whose all-on food is about 20 and whose K-off food differs from
    it by ``shift`` plus noise of SD ``spread``: the margin is 20% of the control's median, about 4."""
    rng = np.random.default_rng(int(spread * 10))
    control = 20 + rng.normal(0, 1, episodes)
    spec = [{"condition": c, "episode": e, "food_total": v, "eod_probability": 0.3, "bites": 1.0,
             "mean_nn_dist_cm": 20.0}
            for c, values in (("M_A_K", control), ("M_A", control + shift + rng.normal(0, spread, episodes)))
            for e, v in enumerate(values)]
    tables = {A("behaviour", "ablation4", "episode_summary"): pd.DataFrame(spec).assign(food_offered=60)}
    return {p.label: p for p in cl.CLAIMS["C10"].assess(tables, CFG)[1]}["group food, K off (equivalent)"]


def test_an_equivalence_margin_its_n_cannot_reach_is_not_decidable():
    """The third audit: 11 of 12 seed-level equivalence parts had a margin below the one-sided critical t times its
    standard error, so they could not be shown equivalent even at a zero difference, and read "weaker". A delta
    of about 4 against differences of SD 12 at 12 episodes gives an interval more than 2 delta wide, which cannot
    lie within +-delta whatever the effect: not decidable, and says why; against differences of SD 1 it is shown
    equivalent; a difference far beyond delta is opposite."""
    wide = k_off_food(spread=12.0)
    assert wide.verdict == "not decidable" and wide.ci[1] - wide.ci[0] >= 2 * wide.delta, (wide.verdict, wide.reason)
    assert "at least 2 delta wide" in wide.reason
    assert k_off_food(spread=1.0).verdict == "holds"
    assert k_off_food(spread=12.0, shift=-60.0).verdict == "opposite"


def test_a_straight_homer_at_its_ceiling_makes_c2_not_decidable():
    """The third audit: the straight homer's aligned fraction was >= 0.90 in 6 of 8 episodes, leaving a median 0.049
    for a positive excess. Planted so in 9 of 12 episodes (every electric episode a little more aligned still), C2
    is not decidable and says so, where it held; below the ceiling, aligned a tenth of the steps more, it holds."""
    path = A("homing", "homing", "alignment_episodes")
    rows = c2(False)[path]
    straight = np.where(np.arange(len(rows)) % 4 == 0, 0.6, 0.95)
    ceiling = rows.assign(straight_aligned_fraction=straight, aligned_fraction=straight + 0.02,
                          aligned_excess=0.02 + np.arange(len(rows)) * 1e-4)
    part = cl.CLAIMS["C2"].assess({path: ceiling}, CFG)[1][0]
    assert part.verdict == "not decidable" and "at a ceiling" in part.reason, (part.verdict, part.reason)
    below = ceiling.assign(straight_aligned_fraction=straight - 0.2, aligned_fraction=straight - 0.1,
                           aligned_excess=0.1 + np.arange(len(rows)) * 1e-4)  # beyond delta, 0.05
    assert cl.CLAIMS["C2"].assess({path: below}, CFG)[1][0].verdict == "holds"


def test_holm_runs_over_the_comparisons_the_parts_test():
    """C10's ablation4 food parts test three ablations (M, A, K off): Holm over 3; EOD probability only K off."""
    _, parts = cl.CLAIMS["C10"].assess(c10(False), CFG)
    by_label = {p.label: p for p in parts}
    assert "Holm over 3" in by_label["group food, M off"].statistic
    assert "Holm over 2" in by_label["solo food, A off"].statistic
    assert "Holm over 1" in by_label["EOD probability, K off"].statistic


def test_a_b_alone_control_that_ate_nothing_is_a_floor():
    """The second audit: C14's B alone ate nothing in 8 of 8 episodes, so 'B eats more with A' could only hold."""
    tables = c14(False)
    food = tables[A("behaviour", "onepatch", "food_per_agent")]
    alone = food["condition"].str.startswith("B_alone")
    tables = {**tables, A("behaviour", "onepatch", "food_per_agent"): food.assign(
        food_eaten=np.where(alone, 0.0, food["food_eaten"]))}
    row = cl.CLAIMS["C14"].run(tables, CFG)
    assert "B social, A_gt_B: not decidable" in row["reason"] and "at a floor" in row["reason"]
    assert row["verdict"] != "holds"


# ------------------------------------------------------------------------- rule 1: the unit is the episode
def test_an_effect_planted_on_one_episodes_many_bites_is_not_significant():
    """The second audit: C7's 12 bites from 5 episodes gave p 0.0063 over bites and 0.31 over episodes. Here one
    episode bites 300 times with the larger agent biting, eleven others bite 3 times each with no size effect:
    pooled over bites the effect is overwhelming, over episodes it is one unit among twelve."""
    from scipy.stats import wilcoxon

    rng = np.random.default_rng(71)
    rows = [{"condition": "control", "episode": 0, "size_difference": 0.2 + rng.normal(0, 0.05)} for _ in range(300)]
    rows += [{"condition": "control", "episode": e, "size_difference": rng.normal(0, 0.3)}
             for e in range(1, 12) for _ in range(3)]
    bites = pd.DataFrame(rows)
    assert wilcoxon(bites["size_difference"]).pvalue < 1e-10  # what a test over bites would say
    tables = {**c7(False), A("interactions", "patchy4", "bite_sizes"): bites}
    part = next(p for p in cl.CLAIMS["C7"].assess(tables, CFG)[1] if p.label == "biter larger, patchy4")
    assert part.n == 12 and part.p > 0.05 and part.verdict == "inconclusive", (part.n, part.p, part.verdict)


def test_bites_of_one_episode_are_one_unit_for_bites_early():
    """The third audit: C16's "bites early" failed at p 0.012 over 26 bites from 3 episodes, 22 of them from one.
    Here one episode bites 22 times late in its bouts and two others twice each: over bites the part would be
    significant, over episodes (each its median phase) there are 3 units, and 3 cannot reach p < 2 alpha."""
    from scipy.stats import wilcoxon

    rng = np.random.default_rng(16)
    timing = pd.DataFrame({"condition": "control", "episode": np.r_[np.zeros(22, int), [1, 1, 2, 2]],
                           "phase": np.r_[rng.uniform(0.6, 0.95, 22), [0.3, 0.7, 0.4, 0.8]]})
    assert wilcoxon(timing["phase"] - 0.5).pvalue < 0.05  # what a test over bites would say
    tables = {**c16(False), A("interactions", "square2", "bite_timing"): timing}
    part = next(p for p in cl.CLAIMS["C16"].assess(tables, CFG)[1] if p.label == "bites early")
    assert part.n == 3 and part.verdict == "not decidable", (part.n, part.verdict, part.reason)
    assert "cannot reach p < 0.1 at n = 3" in part.reason


def test_per_episode_parts_with_no_planted_effect_reject_at_about_the_nominal_rate():
    """The third arm beside the paper's sign and the opposite one: sizes unrelated to bites, food and EOD
    probability in every episode. C7's biter part, C8's food slope and C9's rho then hold or are opposite (an
    interval beyond delta) in at most about 5% of 40 planted datasets; at most 6 of 40 (binomial tail 1.4% at a
    true 5%)."""
    decided = {"C7": 0, "C8": 0, "C9": 0}
    for seed in range(40):
        rng = np.random.default_rng(100 + seed)
        agents = pd.DataFrame({"condition": "control", "episode": np.repeat(np.arange(12), 4),
                               "agent": np.tile(range(4), 12), "size": rng.uniform(0, 1, 48)})
        per_agent = agents.assign(food_eaten=np.round(rng.uniform(0, 10, 48)),
                                  eod_probability=rng.uniform(0.2, 0.6, 48))
        bites = pd.DataFrame({"condition": "control", "episode": np.repeat(np.arange(12), 5),
                              "size_difference": rng.normal(0, 0.3, 60)})
        tables = {A("interactions", "patchy4", "bite_sizes"): bites,
                  A("behaviour", "patchy4", "food_per_agent"): per_agent,
                  A("behaviour", "patchy4", "eod_probability"): per_agent}
        for cid, label in (("C7", "biter larger, patchy4"), ("C8", "food ~ size"), ("C9", "rho")):
            part = next(p for p in cl.CLAIMS[cid].assess(tables, CFG)[1] if p.label == label)
            assert part.n == 12 and part.verdict in cl.VERDICTS, part.reason
            decided[cid] += part.verdict in ("holds", "opposite")
    assert all(k <= 6 for k in decided.values()), decided


@pytest.mark.parametrize("cid", ["C15"])
def test_bootstrap_endpoints_are_stable_to_the_resampling_seed_at_the_runs_count(cid):
    """Rule 8 for the intervals no test inverts and a bootstrap makes (C15's difference of reach rates): at the
    run's analysis.claims_resamples (4,000) two resampling seeds move an endpoint by under a tenth of the interval's
    width."""
    tables = BUILDERS[cid](False)
    runs = [cl.CLAIMS[cid].assess(tables, cfg_with(f"analysis.claims_seed={seed}"))[1] for seed in (0, 7)]
    boot = [(a, b) for a, b in zip(*runs, strict=True) if "bootstrap" in a.ci_method and np.isfinite(a.ci).all()]
    assert boot, f"{cid} has no bootstrap interval"
    for a, b in boot:
        width = a.ci[1] - a.ci[0]
        assert max(abs(a.ci[0] - b.ci[0]), abs(a.ci[1] - b.ci[1])) <= 0.1 * width, (a.label, a.ci, b.ci)
