"""``run_assay``: every condition of an assay config, each batched in one env, one table set
(docs/methods/assays.md)."""

from __future__ import annotations

import dataclasses
import time
from typing import Callable, Mapping, Sequence

import pandas as pd

from ..config.compose import compose_variants
from ..config.schema import EfishConfig
from ..env.observe import observation_size
from .conditions import conditions_table
from .group import run_group
from .run import run_episodes


def condition_configs(overrides: Sequence[str]) -> dict[str, EfishConfig]:
    """Each condition's config: the assay's, with the condition's overrides on top and the scale's caps on
    episode length applied. A condition whose overrides do not compose is one clear error naming it."""
    name = next((o.split("=", 1)[1] for o in reversed(overrides) if o.startswith("assay=")), "")
    configs = compose_variants(overrides, label=f"assay {name}, condition" if name else "condition")
    return {name: dataclasses.replace(cfg, env=dataclasses.replace(
        cfg.env, episode_steps=min(cfg.env.episode_steps, cfg.scale.max_episode_steps))) for name, cfg in configs.items()}


def policies_needed(configs: Mapping[str, EfishConfig]) -> dict[str, list[str]]:
    """Policy name -> the conditions it acts in."""
    needed: dict[str, list[str]] = {}
    for name, cfg in configs.items():
        needed.setdefault(cfg.assay.policy, []).append(name)
    return needed


def check_observation_sizes(configs: Mapping[str, EfishConfig], sizes: Mapping[str, int]) -> None:
    """One clear error when a condition's observation does not fit its policy (``sizes``: policy -> input size)."""
    for name, cfg in configs.items():
        want, got = sizes[cfg.assay.policy], observation_size(cfg)
        if want != got:
            raise ValueError(f"assay {cfg.assay.name}, condition {name}: its observation has {got} values but "
                             f"policy {cfg.assay.policy!r} takes {want} (another perception or layout)")


def run_assay(overrides: Sequence[str], policies: Mapping, progress: Callable | None = None
              ) -> tuple[dict[str, pd.DataFrame], dict]:
    """Run every condition for ``min(assay.episodes, scale.max_episodes)`` episodes in parallel arenas.

    ``policies``: policy name (``selected``, ``homing``, ...) -> a policy with ``obs_dim``, ``initial_hidden``
    and ``act`` (:class:`efish.rl.policy.Policy`). Returns the concatenated tables (``hidden`` too when
    ``assay.record_hidden``; ``conditions``: what each condition resolved to) and run statistics (env steps,
    seconds, env-steps/s). Everything is checked before the first step: unknown policies and observation sizes
    that do not fit.
    """
    tables, stats = run_assay_group(overrides, policies, [{}], progress)
    return tables[0], stats


def run_assay_group(overrides: Sequence[str], shared: Mapping, members: Sequence[Mapping],
                    progress: Callable | None = None) -> tuple[list[dict[str, pd.DataFrame]], dict]:
    """:func:`run_assay` for several members at once, e.g. the top seeds' reruns: each member names its own
    policies (``{"selected": seed k's policy}``), every member the same names, and ``shared`` the policies common
    to all (the recipe policies). A condition that acts with a member's policy runs every member's in one env
    (:func:`~efish.rollout.group.run_group`); one that acts with a shared policy runs once, its tables the same
    for every member, as each member's run alone would make them. Returns one table set per member, each equal to
    :func:`run_assay` with ``{**shared, **member}``, and the statistics of the whole (env steps over members)."""
    if not members:
        raise ValueError("a group of assay runs needs at least one member")
    own = set(members[0])
    if any(set(m) != own for m in members):
        raise ValueError(f"every member must name the same policies, got {[sorted(m) for m in members]}")
    configs = condition_configs(overrides)
    missing = sorted(set(policies_needed(configs)) - set(shared) - own)
    if missing:
        raise ValueError(f"the assay needs policies {', '.join(missing)}: pass --policy NAME=PATH for each")
    for policies in ({**shared, **m} for m in members):
        check_observation_sizes(configs, {k: p.obs_dim for k, p in policies.items()})
    parts, env_steps, start = [], 0, time.perf_counter()
    for name, cfg in configs.items():
        episodes, who = min(cfg.assay.episodes, cfg.scale.max_episodes), cfg.assay.policy
        run = dict(condition=name, seed=cfg.assay.seed, deterministic=cfg.assay.deterministic,
                   record_hidden=cfg.assay.record_hidden)
        grouped = who in own and len(members) > 1
        if grouped:
            part = run_group(cfg, [m[who] for m in members], episodes, **run)
        else:
            part = [run_episodes(cfg, {**shared, **members[0]}[who], episodes, **run)] * len(members)
        ran = part if grouped else part[:1]  # the episodes the env stepped
        env_steps += sum(int(p["episodes"].groupby("episode")["steps"].max().sum()) for p in ran)
        parts.append(part)
        if progress:
            progress(name)
    seconds = time.perf_counter() - start
    conditions = conditions_table(configs)
    tables = []
    for k in range(len(members)):
        mine = [part[k] for part in parts]
        tables.append({**{t: pd.concat([p[t] for p in mine], ignore_index=True) for t in mine[0]},
                       "conditions": conditions})
    return tables, {"env_steps": env_steps, "seconds": seconds, "env_steps_per_s": env_steps / seconds}
