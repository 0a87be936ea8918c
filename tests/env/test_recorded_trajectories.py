"""Recorded 40-step trajectories of the shipped configs: a restructuring must not change behaviour.

``tests/data/trajectories.npz`` holds, per config, what 3 arenas did over 40
steps of seeded random actions (positions, headings, rewards, events and a
per-agent summary of every observation). Regenerate it only for an intended
change of behaviour, and say so in the commit:

    python tests/env/test_recorded_trajectories.py --write [NAME ...]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

try:
    from ..helpers import random_actions
except ImportError:  # run as a script to regenerate the record
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from helpers import random_actions

DATA = Path(__file__).resolve().parents[1] / "data" / "trajectories.npz"
STEPS, ENVS = 40, 3
# Short episodes so that autoreset happens inside the record.
CONFIGS = {
    "patchy4": ["env.episode_steps=15"],
    "training": ["arena=training", "env.episode_steps=15"],
    "homing": ["env=homing", "arena=homing_train", "env.episode_steps=15"],
    "homing_assay": ["assay=homing"],
    "onepatch_bot": ["arena=onepatch", "env.n_agents=2", "env.bots=[0]", "env.bot_eod_rate=0.5"],
    "raycast": ["sensors.perception=raycast", "arena=uniform70"],
    "mute": ["assay=mute"],
    "self_only_no_knollen": ["sensors.mormyromast.g_cons=0", "sensors.knollenorgan.enabled=false"],
    "float32_exact": ["physics.dtype=float32", "physics.tolerance=0", "arena=collective"],
    "wide_starts": ["arena=wide", "env.n_agents=2", "env.starts=[[20,20,0],[140,20,3.14159]]",
                    "env.sizes=[0.25,0.75]"],
}


def record(overrides: list[str]) -> dict[str, np.ndarray]:
    """What ``VecEnv`` does with seeded random actions, step by step."""
    from efish.config import compose
    from efish.env import VecEnv

    env = VecEnv(compose(overrides), num_envs=ENVS, seed=7)
    obs = env.reset()
    rng = np.random.default_rng(11)
    out: dict[str, list] = {k: [] for k in ("obs_sum", "obs_abs", "xy", "heading", "reward", "terminated",
                                            "truncated", "ate", "bit", "eod", "collided")}
    out["obs_sum"].append(obs.astype(np.float64).sum(-1))
    out["obs_abs"].append(np.abs(obs.astype(np.float64)).sum(-1))
    for _ in range(STEPS):
        obs, reward, term, trunc, info = env.step(random_actions(rng, ENVS, env.n))
        out["obs_sum"].append(obs.astype(np.float64).sum(-1))
        out["obs_abs"].append(np.abs(obs.astype(np.float64)).sum(-1))
        out["xy"].append(env.state.xy.copy())
        out["heading"].append(env.state.heading.copy())
        for k, v in (("reward", reward), ("terminated", term), ("truncated", trunc)):
            out[k].append(np.asarray(v))
        for k in ("ate", "bit", "eod", "collided"):
            out[k].append(np.asarray(info[k]))
    return {k: np.stack(v) for k, v in out.items()}


@pytest.mark.parametrize("name", sorted(CONFIGS))
def test_trajectory_matches_the_record(name):
    with np.load(DATA) as data:
        want = {k.split("/", 1)[1]: data[k] for k in data.files if k.startswith(name + "/")}
    got = record(CONFIGS[name])
    assert set(got) == set(want)
    for key in ("terminated", "truncated", "ate", "bit", "eod", "collided"):
        np.testing.assert_array_equal(got[key], want[key], err_msg=f"{name}: {key}")
    for key in ("xy", "heading", "reward"):
        # float64 state: bit-identical on the machine that recorded it; other CPUs may round kernels differently
        np.testing.assert_allclose(got[key], want[key], rtol=1e-9, atol=1e-9, err_msg=f"{name}: {key}")
    for key in ("obs_sum", "obs_abs"):
        # sums of up to 110 float32 observations: a CPU without AVX-512 rounds the float32 encoding differently
        # (measured up to 1.2e-6 against a record made with AVX-512), far below any behavioural change
        np.testing.assert_allclose(got[key], want[key], rtol=1e-6, atol=1e-5, err_msg=f"{name}: {key}")


def write(path: Path = DATA, names: list[str] | None = None) -> None:
    """Record every config (or only ``names``, keeping the others' records) into ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    names = list(CONFIGS) if not names else names
    kept = {}
    if path.is_file():
        with np.load(path) as old:
            kept = {k: old[k] for k in old.files if k.split("/", 1)[0] not in names}
    arrays = {f"{name}/{k}": v for name in names for k, v in record(CONFIGS[name]).items()}
    np.savez_compressed(path, **kept, **arrays)
    print(f"wrote {len(names)} trajectories to {path}")


if __name__ == "__main__":
    # python tests/env/test_recorded_trajectories.py --write [NAME ...]: every config, or only those named
    if "--write" in sys.argv:
        write(DATA, sys.argv[sys.argv.index("--write") + 1:])
