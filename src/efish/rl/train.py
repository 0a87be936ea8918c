"""``train(cfg, out_dir)``: recurrent MAPPO on the VecEnv, resumable (docs/methods/training.md#mappo,
docs/architecture.md#training).

Readable top to bottom: collect a rollout with the current policy, compute
advantages, run the PPO epochs, log one metrics row (metrics.parquet, rewritten
atomically every update, and the live logs of ``train.loggers``,
:mod:`efish.rl.loggers`), checkpoint every ``train.checkpoint_every`` updates. A checkpoint
holds the networks, optimisers, value normaliser, every RNG state, the
environment state and the precision the run computes in, so a resumed run ends
with the same weights as an uninterrupted one. The networks and the update run
on ``train.device``; the environment and every random draw stay on the CPU.
``train.keep_stages`` keeps the policy at fractions of the run as ``stage_<k>.pt``
(:func:`stage_updates` says where), a checkpoint each: training is unchanged.
The checkpoint carries a copy of each stage it has passed, because a workflow
removes the outputs of an interrupted job before it reruns it: the rerun writes
those stages again from the copy instead of failing.
"""

from __future__ import annotations

import copy
import logging
import math
import time
from pathlib import Path

import pandas as pd
import torch

from ..config.schema import (
    EfishConfig,
    config_differences,
    result_neutral_keys,
    training_config,
    with_current_key_names,
)
from ..env.vec_env import VecEnv
from ..io import atomic_path, remove_partial_writes
from ..layout import FINAL_POLICY, TRAINING_METRICS, stage_file
from .collect import carry_to, collect, initial_carry
from .compute import Compute, resolve_compute, resolve_device
from .loggers import Loggers, check_loggers
from .mappo import ppo_update
from .networks import Actor, Critic
from .value_norm import ValueNormalizer

CHECKPOINT = "checkpoint.pt"
LOG = logging.getLogger(__name__)
FINAL = FINAL_POLICY  # the finished run: what the pipeline declares as the training output
METRICS = TRAINING_METRICS
STAGE_COPIES = "stage_copies"  # checkpoint key: {k: stage file contents} of the stages the run has passed
CPU = torch.device("cpu")


class Learner:
    """Networks, optimisers and value normaliser of one seed."""

    def __init__(self, cfg: EfishConfig, obs_dim: int, n_agents: int, device: torch.device = CPU):
        t = cfg.train
        torch.manual_seed(t.seed)
        self.device = device
        # initialised on the CPU and then moved, so every device starts from the same weights
        self.actor = Actor(obs_dim, t.hidden, t.head_gain).to(device)
        self.critic = Critic(obs_dim * n_agents, t.hidden, t.head_gain).to(device)
        self.value_norm = ValueNormalizer().to(device)
        self.actor_opt = torch.optim.Adam(self.actor.parameters(), lr=t.lr, eps=t.adam_eps, weight_decay=t.weight_decay)
        self.critic_opt = torch.optim.Adam(self.critic.parameters(), lr=t.lr, eps=t.adam_eps, weight_decay=t.weight_decay)
        self.architecture = {"obs_dim": obs_dim, "n_agents": n_agents, "hidden": t.hidden}


def train(cfg: EfishConfig, out_dir: str | Path, progress=None, restart: bool = False) -> pd.DataFrame:
    """Train one seed into ``out_dir`` (checkpoint.pt, metrics.parquet, and final.pt at the end; stage_<k>.pt on
    the way for ``train.keep_stages``, see :func:`stages_to_write`; metrics.csv and tensorboard/ for
    ``train.loggers``).

    Resumes from a checkpoint there only when it was written under the same
    config (apart from the schema's result-neutral keys: threads, device,
    checkpoint interval, a longer ``total_steps``) and computes in the same
    precision (``precision=auto`` takes the checkpoint's); any other difference
    is one clear error. ``restart`` discards the folder's checkpoint and starts
    afresh. A finished run is written out again (final.pt, metrics.parquet)
    without further updates. The returned metrics carry the resolved device
    and precision, with the GEMM rates auto measured, in
    ``.attrs["compute"]`` (for provenance.json).
    """
    out = Path(out_dir)
    t_cfg = cfg.train
    torch.set_num_threads(t_cfg.threads)
    resolve_device(t_cfg.device)  # a device this machine lacks fails here, before anything is touched
    check_loggers(t_cfg.loggers)  # so does a logger whose package is missing
    env = VecEnv(cfg, num_envs=t_cfg.num_envs, seed=t_cfg.seed)
    obs = env.reset()  # bad env settings fail here, before anything is written
    remove_partial_writes(out)  # temporaries of a killed run
    if restart:
        for name in (CHECKPOINT, FINAL, METRICS):
            (out / name).unlink(missing_ok=True)
        for path in out.glob(stage_file("*")):
            path.unlink()
    state = read_checkpoint(out / CHECKPOINT) if (out / CHECKPOINT).exists() else None
    compute = resolve_compute(cfg, recorded_precision(state) if state else None)
    LOG.info("networks on %s, precision %s (%s%s)", compute.device, compute.precision, compute.chosen_by,
             "".join(f", {k} GEMM {v / 1e9:.1f} GFLOP/s" for k, v in compute.gemm_flops.items()))
    learner = Learner(cfg, obs.shape[-1], env.n, compute.device)
    carry = initial_carry(obs, t_cfg.hidden, compute.device)
    generator = torch.Generator().manual_seed(t_cfg.seed)
    steps_per_update = t_cfg.rollout_steps * t_cfg.num_envs
    total_updates = t_cfg.total_updates()
    plan = stage_plan(t_cfg.keep_stages, total_updates, steps_per_update)
    rows, update = [], 0
    if state is not None:
        update, rows = restore_checkpoint(state, out / CHECKPOINT, cfg, compute, learner, env, carry, generator,
                                          total_updates)
        LOG.info("resumed from %s at update %d (%d env steps)", out / CHECKPOINT, update, update * steps_per_update)
    out.mkdir(parents=True, exist_ok=True)
    todo = stages_to_write(out, plan, state, cfg, compute)  # before training: ``state`` still holds its update
    passed = stages_passed(out, plan, state)
    stage_at = {stage["update"] for stage in plan}
    start = time.perf_counter()
    with Loggers(t_cfg.loggers, out, rows) as loggers:  # opened after the restore: they start from its rows
        while update < total_updates:
            t0 = time.perf_counter()
            ro, episode = collect(cfg, env, learner, carry, generator)
            losses = ppo_update(t_cfg, learner.actor, learner.critic, learner.actor_opt, learner.critic_opt,
                                learner.value_norm, ro, generator, compute)
            update += 1
            seconds = time.perf_counter() - t0
            rows.append({"update": update, "total_updates": total_updates, "env_steps": update * steps_per_update,
                         "wall_s": time.perf_counter() - start, **episode, **losses,
                         "env_steps_per_s": steps_per_update / seconds})
            loggers.log(rows[-1])
            # every update, atomically: a reader (efish watch) sees the run as it goes and never a torn table
            write_metrics(out / METRICS, rows)
            if progress:
                progress(rows[-1], total_updates)
            # a stage's update is always checkpointed, so a killed run resumes at or before it and never skips it
            if update % t_cfg.checkpoint_every == 0 or update == total_updates or update in stage_at:
                saved = checkpoint_state(cfg, compute, learner, env, carry, generator, update, rows)
                due = [stage for stage in todo if stage["update"] == update]
                # a copy: ``saved`` shares memory with the live networks, and ``passed`` outlives this update
                passed.update({stage["k"]: stage_contents(copy.deepcopy(saved), stage) for stage in due})
                write_checkpoint(out / CHECKPOINT, {**saved, STAGE_COPIES: passed})
                for stage in due:
                    write_stage(out / stage_file(stage["k"]), passed[stage["k"]])
    # Written at the end, atomically: a killed job never leaves a final.pt, so the workflow reruns it and the
    # rerun resumes from checkpoint.pt; a finished run rerun with its config writes both outputs again.
    write_metrics(out / METRICS, rows)
    final = read_checkpoint(out / CHECKPOINT)
    final.pop(STAGE_COPIES, None)  # the final policy alone; its stage copies stay in the checkpoint
    with atomic_path(out / FINAL) as tmp:
        torch.save(final, tmp)
    df = pd.DataFrame(rows)
    df.attrs["compute"] = compute.record()
    return df


def stage_updates(keep_stages, total_updates: int) -> list[int]:
    """The update at which each fraction of ``train.keep_stages`` is kept: the first whose env steps reach that
    fraction of the run's env steps (``total_updates`` updates: ``train.total_steps`` rounded down to whole
    updates), ``ceil(fraction * total_updates)``; fraction 1.0 is the last update, the policy of final.pt. Close
    fractions of a short run may share an update (their files then hold the same policy)."""
    return [max(1, math.ceil(round(f * total_updates, 9))) for f in keep_stages]  # round: 0.3 * 10 is update 3


def stage_plan(keep_stages, total_updates: int, steps_per_update: int) -> list[dict]:
    """One record per stage, as a stage file stores it (key ``stage``): ``k`` (1..K in the order of the
    fractions), ``fraction``, ``update``, ``env_steps`` (at the end of that update) and the run's
    ``total_updates``."""
    return [{"k": k, "fraction": float(f), "update": u, "env_steps": u * steps_per_update,
             "total_updates": total_updates}
            for k, (f, u) in enumerate(zip(keep_stages, stage_updates(keep_stages, total_updates), strict=True), start=1)]


def stage_paths(out_dir: str | Path, keep_stages) -> list[Path]:
    """``<out_dir>/stage_<k>.pt`` for k = 1..K: the files a training run with these ``train.keep_stages`` writes
    (the last one is the final policy when its fraction is 1.0)."""
    return [Path(out_dir) / stage_file(k) for k in range(1, len(keep_stages) + 1)]


def stages_to_write(out: Path, plan: list[dict], state: dict | None, cfg: EfishConfig, compute: Compute
                    ) -> list[dict]:
    """The stages this run still has to write when it reaches their updates.

    A fresh run writes every stage (over any file left in the folder). A resumed run keeps, and never rewrites,
    each stage file it finds written at the same fraction and update under its config. One that is missing or
    from another plan is written again now when the checkpoint can recreate it: from the copy the checkpoint
    carries of each stage it passed (a workflow removes an interrupted job's outputs before it reruns it), or
    from the checkpoint itself when the stage is due at its update (a run killed between its checkpoint and its
    stage, or a finished run rerun). One due before the checkpoint's update that it holds no copy of (the
    checkpoint was written without these stages, or a longer ``total_steps`` moved the stage behind it) is one
    clear error, before any training.
    """
    if state is None:
        return list(plan)
    todo = []
    passed = state.get(STAGE_COPIES, {})
    for stage in plan:
        path = out / stage_file(stage["k"])
        copied = passed.get(stage["k"], {}).get("stage", {})  # the record of the checkpoint's copy, if any
        if _stage_is_kept(path, stage, cfg, compute):
            continue
        if stage["update"] > state["update"]:
            todo.append(stage)
        elif _same_stage(copied, stage):
            write_stage(path, passed[stage["k"]])
        elif stage["update"] == state["update"]:
            write_stage(path, stage_contents(state, stage))
        else:
            raise ValueError(f"{path} (train.keep_stages fraction {stage['fraction']:g}, update {stage['update']}) "
                             f"is missing or from another plan, and the checkpoint is past it at update "
                             f"{state['update']}, so it cannot be recreated: run again with --restart to start "
                             "afresh, or with other train.keep_stages")
    return todo


def stages_passed(out: Path, plan: list[dict], state: dict | None) -> dict[int, dict]:
    """The contents of the plan's stages at or before the checkpoint's update, read from their files (which
    :func:`stages_to_write` has made sure of): what the checkpoint carries on, keyed by ``k``."""
    if state is None:
        return {}
    return {stage["k"]: torch.load(out / stage_file(stage["k"]), weights_only=False, map_location="cpu")
            for stage in plan if stage["update"] <= state["update"]}


def _same_stage(record: dict, stage: dict) -> bool:
    """Whether a stored stage record is this stage of the plan (the same fraction kept at the same update)."""
    return (record.get("fraction"), record.get("update")) == (stage["fraction"], stage["update"])


def _stage_is_kept(path: Path, stage: dict, cfg: EfishConfig, compute: Compute) -> bool:
    """Whether ``path`` is this stage (fraction and update) of a run under this config."""
    if not path.exists():
        return False
    try:
        saved = torch.load(path, weights_only=False, map_location="cpu")
        record = saved["stage"]
        differ = _config_differences(saved, cfg, compute)
    except Exception:  # truncated or foreign: written again when due, or one clear error when passed
        return False
    return _same_stage(record, stage) and not differ


def stage_contents(state: dict, stage: dict) -> dict:
    """What a stage file holds: the checkpoint ``state`` of the stage's update (so :func:`~efish.rl.policy.
    load_policy` reads it), without the stage copies it carries, and the stage's record under ``stage``."""
    return {**{k: v for k, v in state.items() if k != STAGE_COPIES}, "stage": dict(stage)}


def write_stage(path: Path, contents: dict) -> None:
    """A stage file (:func:`stage_contents`), atomically."""
    stage = contents["stage"]
    with atomic_path(path) as tmp:
        torch.save(contents, tmp)
    LOG.info("kept stage %d (fraction %g) at update %d (%d env steps): %s", stage["k"], stage["fraction"],
             stage["update"], stage["env_steps"], path)


def write_metrics(path: Path, rows: list[dict]) -> None:
    """The metrics table, one row per update, written atomically."""
    with atomic_path(path) as tmp:
        pd.DataFrame(rows).to_parquet(tmp, index=False)


def checkpoint_state(cfg: EfishConfig, compute: Compute, learner: Learner, env: VecEnv, carry: dict,
                     generator: torch.Generator, update: int, rows: list[dict]) -> dict:
    """Everything a resumed run needs to continue bit for bit, the config it ran under and the precision it
    computed in (tensors on the CPU, so any device can resume it; they may share memory with the live networks:
    write it before training goes on)."""
    state = {
        "architecture": learner.architecture, "config": training_config(cfg), "precision": compute.precision,
        "update": update, "metrics": rows,
        "actor": learner.actor.state_dict(), "critic": learner.critic.state_dict(),
        "value_norm": learner.value_norm.state_dict(),
        "actor_opt": learner.actor_opt.state_dict(), "critic_opt": learner.critic_opt.state_dict(),
        "torch_rng": torch.get_rng_state(), "generator": generator.get_state(),
        "env": env.state_dict(), "carry": carry,
    }
    return _to_cpu(state)


def write_checkpoint(path: Path, state: dict) -> None:
    """A checkpoint (:func:`checkpoint_state`, with the stage copies under ``stage_copies``), atomically."""
    with atomic_path(path) as tmp:
        torch.save(state, tmp)


def _to_cpu(obj):
    """A nested structure of dicts and lists with every tensor moved to the CPU."""
    if isinstance(obj, torch.Tensor):
        return obj.cpu()
    if isinstance(obj, dict):
        return {k: _to_cpu(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_to_cpu(v) for v in obj]
    return obj


def read_checkpoint(path: Path) -> dict:
    """A checkpoint's contents (on the CPU); one clear error if it cannot be read."""
    try:
        state = torch.load(path, weights_only=False, map_location="cpu")
        state["config"]
    except Exception as exc:  # truncated, foreign, or from before configs were recorded
        raise ValueError(f"cannot read checkpoint {path} ({type(exc).__name__}): delete it, or run again with "
                         "--restart to start afresh") from None
    return state


def recorded_precision(state: dict) -> str:
    """The precision a checkpoint's run computed in (checkpoints from before train.precision: its bf16 flag)."""
    return state.get("precision") or ("bf16" if state["config"]["train"].get("bf16") else "fp32")


def _with_precision(config: dict, precision: str) -> dict:
    """A recorded training config with train.precision replaced by the precision actually used: what a resume
    must match (auto and an explicit value agree when auto chose that value). The retired train.bf16 flag of older
    checkpoints is dropped: :func:`recorded_precision` has read it."""
    train = {k: v for k, v in config["train"].items() if k != "bf16"}
    return {**config, "train": {**train, "precision": precision}}


def _config_differences(state: dict, cfg: EfishConfig, compute: Compute) -> list[str]:
    """The result-relevant keys in which a checkpoint's (or stage's) run differs from this one; a checkpoint written
    under a key's deprecated name is read under its new name."""
    recorded = _with_precision(with_current_key_names(state["config"]), recorded_precision(state))
    return config_differences(recorded, _with_precision(training_config(cfg), compute.precision),
                              result_neutral_keys())


def restore_checkpoint(state: dict, path: Path, cfg: EfishConfig, compute: Compute, learner: Learner, env: VecEnv,
                       carry: dict, generator: torch.Generator, total_updates: int) -> tuple[int, list[dict]]:
    """Restore a read checkpoint into live objects; one clear error if it does not fit this config."""
    differ = _config_differences(state, cfg, compute)
    if differ:
        raise ValueError(f"checkpoint {path} was written under another config ({', '.join(differ)} differ): run "
                         "again with --restart to start afresh, or use another --out")
    if state["update"] > total_updates:
        raise ValueError(f"checkpoint {path} is at update {state['update']}, past this run's {total_updates} "
                         "updates (train.total_steps): run again with --restart to start afresh")
    if state.get("architecture") != learner.architecture:
        raise ValueError(f"checkpoint {path} is for architecture {state.get('architecture')}, "
                         f"not {learner.architecture}")
    learner.actor.load_state_dict(state["actor"])
    learner.critic.load_state_dict(state["critic"])
    learner.value_norm.load_state_dict(state["value_norm"])
    learner.actor_opt.load_state_dict(state["actor_opt"])  # moves the moments to the parameters' device
    learner.critic_opt.load_state_dict(state["critic_opt"])
    torch.set_rng_state(state["torch_rng"])
    generator.set_state(state["generator"])
    env.load_state_dict(state["env"])
    carry.update(carry_to(state["carry"], learner.device))
    return state["update"], list(state["metrics"])
