"""What the workflow builds for a run: the planning behind the Snakemake rules, as tested Python.

The rules (``Snakefile``, ``workflow/rules/*.smk``) are glue: they ask one :class:`RunPlan` what to build and turn
its answers into rule definitions, wildcard constraints and shell lines. The plan knows

- the run that ``--config`` asks for (scale, overrides, folder name), with one-line errors (:class:`PlanError`);
- which assays the scale runs, which other assay files may be asked for, and which policies each assay's
  conditions act with, every condition checked before any job runs (:func:`checked_policies`, cached);
- what the other top seeds and the training stages rerun for their own claims, and the draws of the homing
  recipes the top seeds rerun homing with (``scale.homing_seeds``);
- the kept training stages (:class:`Stages`);
- the panels the scale draws, grouped by figure as ``efish.figures.registry`` groups them;
- the targets of ``rule all``.

Every path comes from ``efish.layout``. A ``run`` argument is a :class:`~efish.layout.Run`: a run's own folders
(``Run("laptop")``) or the rules' pattern (``Run("{run}")``), possibly a copy of the layout inside the run.
"""

from __future__ import annotations

import functools
import hashlib
import json
import re
import shlex
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ._numba_cache import source_digest
from .analysis.registry import Analysis, analyses_for, tables_written
from .claims.registry import CLAIM_FIGURES, claim_tables, produced_tables
from .config import ConfigError, compose, config_dir, run_name
from .config.schema import AssayConfig, EfishConfig
from .env.observe import observation_size
from .figures import registry as panel_registry
from .figures.panel import Panel
from .figures.render import input_paths
from .io import read_parquet, write_text_atomic
from .layout import (
    CLAIM_PARTS,
    CLAIMS_BY_STAGE,
    CLAIMS_PAGE,
    CLAIMS_TABLE,
    CLAIMS_TRENDS,
    CLAIMS_TRENDS_PAGE,
    FIGURE_FORMATS,
    POWER_CLAIMS,
    POWER_CURVES,
    POWER_FIGURE,
    POWER_PAGE,
    POWER_TABLE,
    ROLLOUT_TABLES,
    Run,
    analysis_table,
    assay_table,
    bench_file,
    claims_by_stage_stem,
    parse_recipe_draw,
    recipe_draw,
    seed_name,
    stacked_seeds_table,
    training_file,
)
from .rollout.assay import check_observation_sizes, condition_configs, policies_needed

#: The keys ``--config`` takes: the scale, extra Hydra overrides for every efish call, the run's folder name, and a
#: grid of overrides with one run per point (:mod:`efish.sweep`).
CONFIG_KEYS = ("scale", "overrides", "run", "sweep")
DEFAULT_SCALE = "laptop"
#: Where :func:`checked_policies` keeps its answers, relative to Snakemake's working directory.
CACHE = Path(".snakemake") / "efish"
#: The policy an assay condition acts with unless it names a recipe of ``config/policy/``: the selected seed.
SELECTED = "selected"
_FOLDER_NAME = re.compile(r"[A-Za-z0-9_.\-]+")
# The benchmarks in rule all: their tables (results/<run>/bench/) and figures (figures/<run>/bench/).
BENCH_TABLES = ("bench_physics.json", "bench_accuracy.parquet", "bench_scaling.parquet")
BENCH_FIGURES = ("bench_accuracy", "bench_scaling")


class PlanError(Exception):
    """Bad input to the workflow, in one line: the rules print it and stop before any job runs."""


# ------------------------------------------------------------------ the run --config asks for
def run_settings(config: Mapping[str, object]) -> tuple[str, tuple[str, ...], str]:
    """The scale, its overrides and the run's folder name from Snakemake's ``--config``.

    The folder is the scale as shipped, else the scale and a hash of the overrides, or ``run=NAME``: two configs
    never share a folder. A misspelt key, a run name that is no folder name, or a run name with a sweep (whose
    points each get their own folder) is a :class:`PlanError`.
    """
    if unknown := sorted(set(config) - set(CONFIG_KEYS)):
        raise PlanError(f"unknown --config key(s) {', '.join(unknown)}: the allowed keys are {', '.join(CONFIG_KEYS)}")
    if "sweep" in config and config.get("run"):
        raise PlanError("run= names one folder and a sweep makes one per point: leave run= out of a sweep")
    scale = str(config.get("scale", DEFAULT_SCALE))
    overrides = tuple(shlex.split(str(config.get("overrides", ""))))  # e.g. overrides="physics.tolerance=1e-6"
    run = str(config.get("run") or run_name(scale, overrides))
    if not _FOLDER_NAME.fullmatch(run):
        raise PlanError(f"run={run!r} is not a folder name: use letters, digits, '_', '.' and '-'")
    return scale, overrides, run


def composed(overrides: Sequence[str]) -> EfishConfig:
    """The validated efish config of ``overrides``; a bad one is a :class:`PlanError` with efish's one line."""
    try:
        return compose(list(overrides))
    except ConfigError as exc:
        raise PlanError(f"efish config: {exc}") from None


def config_files(group: str) -> list[str]:
    """The options of a config group: the names of the YAML files in ``config/<group>/``, sorted."""
    return sorted(p.stem for p in (config_dir() / group).glob("*.yaml"))


# ------------------------------------------------------------------ assays and their policies
def policy_observation_sizes(base: Sequence[str]) -> Callable[[str], int]:
    """Policy name -> the observation size it takes: the scale's foraging config for ``selected``, the recipe
    ``policy=<name>`` for any other (each composed once)."""

    @functools.cache
    def size(policy: str) -> int:
        return observation_size(composed([*base, *([] if policy == SELECTED else [f"policy={policy}"])]))

    return size


def assay_policies(base: Sequence[str], name: str, recipes: Iterable[str],
                   observation_sizes: Callable[[str], int]) -> dict[str, list[str]]:
    """Policy name -> the conditions of assay ``name`` it acts in (``base``: the scale and the run's overrides).

    Every condition must compose, name ``selected`` or a policy recipe (``recipes``), and give an observation
    that fits its policy; else a :class:`PlanError` naming the assay (and the condition).
    """
    try:
        configs = condition_configs([*base, f"assay={name}"])
        needed = policies_needed(configs)
        if unknown := sorted(set(needed) - {SELECTED, *recipes}):
            raise ValueError(f"assay {name} asks for policies {', '.join(unknown)}: choose selected or one of "
                             f"{', '.join(recipes)} (files in config/policy/)")
        check_observation_sizes(configs, {policy: observation_sizes(policy) for policy in needed})
    except (ConfigError, ValueError) as exc:
        raise PlanError(str(exc)) from None
    return needed


def checked_policies(scale: str, overrides: Sequence[str], assays: Sequence[str], asked: Sequence[str],
                     recipes: Sequence[str], cache: Path | None = CACHE) -> dict[str, dict[str, list[str]]]:
    """:func:`assay_policies` of every assay, the scale's (``assays``) and the others (``asked``).

    Composing every condition of every assay file costs seconds, and every Snakemake call parses the workflow
    again (each cluster job too), so the answer is kept in ``cache`` (None: not kept) under a hash of everything
    it depends on: the scale, the overrides, the assays, the efish sources and every file of the config tree.
    Only a full answer is kept: a bad assay is found again on every call.
    """
    digest = hashlib.sha256(repr((scale, list(overrides), list(assays), list(asked), source_digest())).encode())
    for path in sorted(config_dir().rglob("*.yaml")):
        digest.update(path.read_bytes())
    kept = cache / f"assays-{digest.hexdigest()[:16]}.json" if cache is not None else None
    if kept is not None and kept.is_file():
        return json.loads(kept.read_text())
    base = [f"scale={scale}", *overrides]
    sizes = policy_observation_sizes(base)
    checked = {name: assay_policies(base, name, recipes, sizes) for name in [*assays, *asked]}
    if kept is not None:
        write_text_atomic(kept, json.dumps(checked))  # whole or absent: concurrent parses may read it
    return checked


# ------------------------------------------------------------------ training stages
@dataclass(frozen=True)
class Stages:
    """The kept training stages and what the claims along training do at each.

    Every seed keeps its policy at the fractions ``train.keep_stages`` of its training (``stage_<k>.pt``,
    k = 1..K). At each kept stage the selected seed's policy reruns every claim's assay, at most
    ``stage_episodes`` episodes per condition, in its own copy of the layout. A last stage at fraction 1 is the
    final policy: the run's own claims (at ``max_episodes``) stand for it, so it gets no copy.
    """

    kept: tuple[int, ...]
    last_is_final: bool
    stage_episodes: int
    max_episodes: int

    @classmethod
    def of(cls, fractions: Sequence[float], stage_episodes: int, max_episodes: int) -> Stages:
        """The stages of ``train.keep_stages`` = ``fractions``, with the scale's episode caps."""
        kept = tuple(range(1, len(fractions) + 1))
        return cls(kept, bool(kept) and fractions[-1] == 1.0, stage_episodes, max_episodes)

    @property
    def rerun(self) -> tuple[int, ...]:
        """The stages whose assays, analyses and claims run in their own copy of the layout."""
        return self.kept[:-1] if self.last_is_final else self.kept

    @property
    def episodes(self) -> tuple[int, ...]:
        """The cap on the episodes per assay condition at each kept stage, in stage order."""
        return (self.stage_episodes,) * len(self.rerun) + (self.max_episodes,) * self.last_is_final

    def parts(self, run: Run) -> list[str]:
        """Each kept stage's claim_parts.parquet in stage order: its copy's, or the run's own for a last stage at
        fraction 1."""
        own = [str(run.path(CLAIM_PARTS))] if self.last_is_final else []
        return [str(run.stage(k).path(CLAIM_PARTS)) for k in self.rerun] + own

    def targets(self, run: Run) -> list[str]:
        """The ``learning`` target: the claims along training. Without kept stages a :class:`PlanError` (the
        target would otherwise train and assay for nothing before failing)."""
        if not self.kept:
            raise PlanError("the learning target needs scale.keep_stages, e.g. "
                            "--config overrides=\"scale.keep_stages=[0.5,1.0]\"")
        return list(learning_outputs(run).values())


def keyed(keys: Sequence[int], values: Sequence[object] | str) -> str:
    """``1=a 2=b ...``: efish claims-by-stage's K=VALUE arguments, one per key in order. A string (Snakemake's
    placeholder for an input behind a checkpoint that has not run yet) is passed through."""
    if isinstance(values, str):
        return values
    return " ".join(f"{k}={v}" for k, v in zip(keys, values, strict=True))


# ------------------------------------------------------------------ the seed selection's record
def top_seeds(ranking: str | Path, n: int) -> list[int]:
    """The ``n`` best-ranked seeds, best first, from the select_seed checkpoint's ranking table."""
    return [int(s) for s in read_parquet(ranking, "the seed ranking")["seed"].head(n)]


def selected_seed(path: str | Path) -> int:
    """The seed the select_seed checkpoint chose (its ``selected_seed.txt``)."""
    return int(Path(path).read_text().strip())


# ------------------------------------------------------------------ outputs by name
def analysis_outputs(analysis: Analysis, run: Run, assay: str = "{assay}") -> dict[str, str]:
    """The tables ``analysis`` writes for ``assay`` in ``run``, by name: its outputs and the settings it ran with."""
    return {t: str(run.path(analysis_table(analysis.name, assay, t))) for t in analysis.written}


def learning_outputs(run: Run) -> dict[str, str]:
    """What claims-by-stage writes: the stacked parts, the trends, the claims page with its trend lines, and one
    figure per figure of the paper's claims (``CLAIM_FIGURES``), named ``<ext>_<figure>`` (``png_fig3``,
    ``pdf_fig3``)."""
    tables = {"table": CLAIMS_BY_STAGE, "trends": CLAIMS_TRENDS, "page": CLAIMS_TRENDS_PAGE}
    figures = {f"{ext}_{group}": str(run.figures / f"{claims_by_stage_stem(group)}.{ext}")
               for group in CLAIM_FIGURES for ext in FIGURE_FORMATS}
    return {name: str(run.path(path)) for name, path in tables.items()} | figures


def power_outputs(run: Run) -> dict[str, str]:
    """What ``efish power`` writes for ``run``: the plan, its curves, its page and its figure (png, pdf)."""
    tables = {"table": POWER_TABLE, "curves": POWER_CURVES, "claims": POWER_CLAIMS, "page": POWER_PAGE}
    figure = {ext: str(run.figures / f"{POWER_FIGURE}.{ext}") for ext in FIGURE_FORMATS}
    return {name: str(run.path(path)) for name, path in tables.items()} | figure


# ------------------------------------------------------------------ the plan
@dataclass(frozen=True)
class RunPlan:
    """What the workflow builds for one run. Build it with :meth:`from_config`; it is read-only."""

    scale: str
    overrides: tuple[str, ...]
    run: str  # the folder name: results/<run>/, figures/<run>/
    cfg: EfishConfig  # the scale with the run's overrides
    assays: tuple[str, ...]  # the scale's assays: in the default target
    asked_assays: tuple[str, ...]  # every other file of config/assay/: built when its tables are asked for
    policy_recipes: tuple[str, ...]  # the files of config/policy/
    assay_settings: Mapping[str, AssayConfig]  # every assay above (and each top seed's), as composed
    assay_policies: Mapping[str, Mapping[str, list[str]]]  # assay -> policy -> the conditions it acts in

    @classmethod
    def from_config(cls, config: Mapping[str, object], cache: Path | None = CACHE) -> RunPlan:
        """The plan of Snakemake's ``--config``; bad input (a key, a run name, a config, an assay) is one
        :class:`PlanError`. ``cache``: where :func:`checked_policies` keeps its answers (None: nowhere)."""
        scale, overrides, run = run_settings(config)
        base = [f"scale={scale}", *overrides]
        cfg = composed(base)
        settings = {}
        for name in cfg.scale.assays:
            assay = composed([*base, f"assay={name}"]).assay
            settings[assay.name] = assay
        assays = tuple(settings)
        asked = tuple(name for name in config_files("assay") if name not in assays)
        recipes = tuple(config_files("policy"))
        # A new assay file that does not compose stops every run: checked with the scale's, before they are read.
        policies = checked_policies(scale, overrides, assays, asked, recipes, cache)
        for name in [*asked, *cfg.scale.top_seed_assays]:
            settings.setdefault(name, composed([*base, f"assay={name}"]).assay)
        plan = cls(scale, overrides, run, cfg, assays, asked, recipes, settings, policies)
        plan.check_groups()
        plan.check_draws()
        return plan

    # -------------------------------------------------------------- the run
    @property
    def args(self) -> str:
        """The scale and the run's overrides, shell-quoted: what every efish call of the run is given."""
        return " ".join(shlex.quote(o) for o in [f"scale={self.scale}", *self.overrides])

    @property
    def stage_args(self) -> str:
        """:attr:`args` for a training stage's assays: capped at ``scale.stage_episodes`` episodes per condition."""
        return " ".join([self.args, shlex.quote(f"scale.max_episodes={self.cfg.scale.stage_episodes}")])

    @property
    def policy_args(self) -> str:
        """:attr:`args` for training the policy recipes (homing): with a ``scale.seed_offset`` they train with seed
        ``seed_offset + 1``, the first of the run's seeds, so that a second run with an offset draws its homing
        policies anew as well as its foraging seeds; without one, :attr:`args` itself (the recipe's own seed)."""
        offset = self.cfg.scale.seed_offset
        return self.args if offset == 0 else " ".join([self.args, shlex.quote(f"train.seed={offset + 1}")])

    @property
    def top_seed_args(self) -> str:
        """:attr:`args` for the top seeds' reruns: capped at ``scale.top_seed_episodes`` episodes per condition
        (:attr:`args` itself where that cap is no lower than ``scale.max_episodes``)."""
        scale = self.cfg.scale
        if scale.top_seed_episodes >= scale.max_episodes:
            return self.args
        return " ".join([self.args, shlex.quote(f"scale.max_episodes={scale.top_seed_episodes}")])

    @property
    def seeds(self) -> list[int]:
        """The foraging seeds trained (:meth:`efish.config.schema.ScaleConfig.seed_numbers`)."""
        return self.cfg.scale.seed_numbers()

    @functools.cached_property
    def stages(self) -> Stages:
        """The kept training stages of ``train.keep_stages`` (which reads ``scale.keep_stages``)."""
        return Stages.of(list(self.cfg.train.keep_stages), self.cfg.scale.stage_episodes,
                         self.cfg.scale.max_episodes)

    # -------------------------------------------------------------- assays
    def records_hidden(self, assay: str) -> bool:
        """Whether ``assay`` records the policy's GRU state (``hidden.parquet``)."""
        return bool(self.assay_settings[assay].record_hidden)

    def by_hidden(self, assays: Iterable[str], hidden: bool) -> list[str]:
        """The assays among ``assays`` that record the GRU state (``hidden``) or do not: the two assay rules."""
        return [name for name in assays if self.records_hidden(name) == hidden]

    @property
    def buildable_assays(self) -> list[str]:
        """Every assay whose tables the rules may build: the scale's and any other asked for."""
        return [*self.assays, *self.asked_assays]

    @property
    def hidden_assays(self) -> list[str]:
        """The scale's assays that record the GRU state: their hidden.parquet is a target."""
        return self.by_hidden(self.assays, True)

    def policies_of(self, assay: str) -> list[str]:
        """The policies assay ``assay``'s conditions act with (``selected`` for a name the plan does not know)."""
        return list(self.assay_policies.get(assay, [SELECTED]))

    @functools.cached_property
    def assay_analyses(self) -> dict[str, list[Analysis]]:
        """The analyses of each of the scale's assays whose input tables it writes (dynamics needs hidden)."""
        return {name: analyses_for(name, tables_written(self.assay_settings[name])) for name in self.assays}

    @property
    def clip_assays(self) -> list[str]:
        """The assays of ``scale.clip_assays`` the scale runs: one clip each."""
        return [name for name in self.cfg.scale.clip_assays if name in self.assays]

    # -------------------------------------------------------------- claims, top seeds
    def claims_read(self, assays: Iterable[str]) -> list[str]:
        """The tables the claims read among those ``assays`` write, relative to a run's results folder."""
        produced = produced_tables({name: self.assay_settings[name] for name in assays})
        return [path for path in claim_tables() if path in produced]

    @functools.cached_property
    def claim_tables(self) -> list[str]:
        """The tables the run's own claims read: those of :meth:`claims_read` for the scale's assays."""
        return self.claims_read(self.assays)

    @functools.cached_property
    def seed_claim_assays(self) -> list[str]:
        """The assays each other top seed (and each training stage) reruns for its own claims: every assay of the
        scale that some claim reads and whose conditions act, at least in part, with the selected policy. An
        assay acted only by recipes (homing) gives the same tables for every seed: a stage does not rerun it, and a
        top seed only with a draw of those recipes of its own (:attr:`drawn_assays`)."""
        return [name for name in self.assays if SELECTED in self.assay_policies[name] and self.claims_read([name])]

    @functools.cached_property
    def seed_claim_tables(self) -> list[str]:
        """The tables the claims read among those the rerun assays write (a top seed's, a stage's claims)."""
        return self.claims_read(self.seed_claim_assays)

    def seed_analysis_assays(self, analysis: Analysis, assays: Sequence[str] | None = None) -> list[str]:
        """The rerun assays (``assays``; default :attr:`seed_claim_assays`, a training stage's) whose ``analysis``
        tables some claim reads (only those analyses are rerun)."""
        assays = self.seed_claim_assays if assays is None else list(assays)
        tables = self.claims_read(assays)
        return [name for name in assays
                if any(analysis_table(analysis.name, name, t) in tables for t in analysis.outputs)]

    def top_seed_analysis_assays(self, analysis: Analysis) -> list[str]:
        """:meth:`seed_analysis_assays` of a top seed's copy: the claims' assays it reruns, homing included where
        some top seed reruns it with a draw of the homing recipes."""
        return self.seed_analysis_assays(analysis, [*self.seed_claim_assays, *self.drawn_assays])

    @property
    def top_seed_assays(self) -> list[str]:
        """Every assay a top seed may run in its copy of the layout: the claims' and ``scale.top_seed_assays``."""
        return sorted({*self.seed_claim_assays, *self.cfg.scale.top_seed_assays})

    def group_seeds(self, assay: str, top: Sequence[int]) -> list[int]:
        """The top seeds (``top``, best first: the selected seed, then the others) that rerun ``assay``, all in one
        job (``efish assay --group``): every top seed for ``scale.top_seed_assays`` (the supplement's panels), the
        others for a claim's assay (their own claims)."""
        if assay in self.cfg.scale.top_seed_assays:
            return list(top)
        return list(top[1:]) if assay in self.seed_claim_assays else []

    def check_groups(self) -> None:
        """A :class:`PlanError` for an assay the top seeds rerun that cannot run as a group: in a group each seed
        acts as the assay's own policy (``assay.policy``), and deterministically (sampled actions would share one
        random stream, :func:`efish.rollout.group.run_group`)."""
        for name in self.top_seed_assays if self.cfg.scale.top_seeds else []:
            assay = self.assay_settings[name]
            if assay.policy != SELECTED:
                raise PlanError(f"assay {name}: the top seeds rerun it with each seed as its own policy, but its "
                                f"assay.policy is {assay.policy!r}: set assay.policy={SELECTED} (a condition may "
                                f"still name a recipe) or leave it out of scale.top_seed_assays")
            if not assay.deterministic:
                raise PlanError(f"assay {name}: the top seeds rerun it as one group, which needs "
                                f"assay.deterministic=true")

    # -------------------------------------------------------------- the homing recipes' draws
    @functools.cached_property
    def recipe_claim_assays(self) -> list[str]:
        """The scale's assays that some claim reads and whose conditions act with policy recipes only (homing): the
        same tables for every foraging seed, so a top seed reruns them only with a draw of those recipes of its
        own (``scale.homing_seeds``)."""
        return [name for name in self.assays
                if SELECTED not in self.assay_policies[name] and self.claims_read([name])]

    @functools.cached_property
    def drawn_recipes(self) -> list[str]:
        """The recipes :attr:`recipe_claim_assays` act with (homing, homing_raycast): each is drawn
        ``scale.homing_seeds`` times."""
        return sorted({p for name in self.recipe_claim_assays for p in self.assay_policies[name]} - {SELECTED})

    @property
    def draws(self) -> tuple[int, ...]:
        """The draws k = 2..``scale.homing_seeds`` of the homing recipes (draw 1 is the run's own): the k-th top
        seed reruns :attr:`recipe_claim_assays` with draw k. None where no claim's assay acts with recipes alone."""
        return tuple(range(2, self.cfg.scale.homing_seeds + 1)) if self.drawn_recipes else ()

    @property
    def drawn_assays(self) -> list[str]:
        """The assays the top seeds of :meth:`draw_seeds` rerun solo, each with its own draw of the recipes."""
        return list(self.recipe_claim_assays) if self.draws else []

    @property
    def draw_trainings(self) -> list[str]:
        """The training folder of every draw k >= 2 of every drawn recipe (``homing_draw_2``, ...), draw by draw."""
        return [recipe_draw(recipe, k) for k in self.draws for recipe in self.drawn_recipes]

    def draw_args(self, k: int) -> str:
        """:attr:`args` for training the k-th draw of a policy recipe: :attr:`policy_args` for draw 1 (the run's
        own), the seed ``seed_offset + k`` for a later one."""
        if k == 1:
            return self.policy_args
        return " ".join([self.args, shlex.quote(f"train.seed={self.cfg.scale.seed_offset + k}")])

    def recipe_training(self, folder: str) -> tuple[str, str]:
        """(recipe, args) of the train_policy job of training folder ``folder``: a recipe of ``config/policy/``
        (draw 1) or one of :attr:`draw_trainings`."""
        recipe, k = parse_recipe_draw(folder)
        return recipe, self.draw_args(k)

    def draw_seeds(self, top: Sequence[int]) -> dict[int, int]:
        """Top seed -> the draw of the homing recipes it reruns :attr:`drawn_assays` with: the k-th of ``top`` (best
        first, the selected seed first) reruns them with draw k, k = 2..``scale.homing_seeds``; a top seed beyond
        those does not rerun them (its homing parts are not run)."""
        return {seed: k for k, seed in enumerate(top, start=1) if k in self.draws}

    def top_seed_claim_tables(self, drawn: bool) -> list[str]:
        """The tables a top seed's claims read in its copy: :attr:`seed_claim_tables`, and those of
        :attr:`drawn_assays` where it reruns them (``drawn``: it is one of :meth:`draw_seeds`)."""
        return self.claims_read([*self.seed_claim_assays, *self.drawn_assays]) if drawn else self.seed_claim_tables

    def check_draws(self) -> None:
        """A :class:`PlanError` for more draws of the homing recipes than top seeds to rerun homing with them (a
        scale without a claim's assay acted by recipes alone ignores ``scale.homing_seeds``)."""
        scale = self.cfg.scale
        if self.drawn_recipes and scale.homing_seeds > max(1, scale.top_seeds):
            raise PlanError(f"scale.homing_seeds={scale.homing_seeds} exceeds scale.top_seeds={scale.top_seeds}: the "
                            f"k-th top seed reruns homing with the k-th draw of its recipes, so set "
                            f"scale.homing_seeds at most {max(1, scale.top_seeds)}")

    # -------------------------------------------------------------- figures
    @functools.cached_property
    def drawable(self) -> list[Panel]:
        """The panels the scale draws (its assays; its top seeds' where it runs them), in registry order."""
        return panel_registry.drawable(self.cfg.scale)

    @functools.cached_property
    def figure_panels(self) -> dict[str, list[Panel]]:
        """The drawable panels by figure: one job per figure draws them and the figure's page."""
        return panel_registry.figures(self.drawable)

    def figure_inputs(self, figure: str, run: Run) -> list[str]:
        """Every table the panels of ``figure`` read in ``run`` (the expansion efish figure uses), sorted."""
        return sorted({str(path) for panel in self.figure_panels[figure]
                       for paths in input_paths(panel, run.results, self.seeds).values() for path in paths})

    def figure_outputs(self, figure: str, run: Run) -> list[str]:
        """Every file the job of ``figure`` writes: each panel's PNG and PDF, then the page's."""
        panels = [run.panel(figure, p.name, ext) for p in self.figure_panels[figure] for ext in FIGURE_FORMATS]
        return [str(path) for path in panels + [run.page(figure, ext) for ext in FIGURE_FORMATS]]

    def figure_legend(self, figure: str) -> list[tuple[str, str, str]]:
        """(panel, caption, tables) of every panel of ``figure`` drawn at this scale, for the report's captions
        (reST: the caption escaped, the tables as literals)."""
        return [(p.name, p.report_caption, ", ".join(f"``{path}``" for path in p.inputs.values())
                 or "none (a schematic)") for p in self.figure_panels[figure]]

    # -------------------------------------------------------------- rule all
    def render_targets(self, run: Run) -> list[str]:
        """The clips and the contact sheet of ``run``."""
        return [str(run.clip(name)) for name in self.clip_assays] + [str(run.contact_sheet)]

    def training_targets(self, run: Run) -> list[str]:
        """Every policy the run trains: each seed's final.pt, that of each recipe the scale's assays act with and
        that of each later draw of the homing recipes (in ``rule all``: a sweep's point that copies its training
        gets all of it, as if it had trained; and the draws train beside the seeds, not after the seed selection
        that the top seeds' reruns wait for)."""
        recipes = sorted({p for name in self.assays for p in self.assay_policies[name]} - {SELECTED})
        return [str(run.path(training_file(name, "final.pt")))
                for name in [*map(seed_name, self.seeds), *recipes, *self.draw_trainings]]

    def targets(self, run: Run) -> list[str]:
        """Every final output of the pipeline for ``run``: the default target."""
        scale = self.cfg.scale
        targets = [str(run.path(bench_file(name))) for name in BENCH_TABLES]
        targets += [str(run.bench_figure(name, ext)) for name in BENCH_FIGURES for ext in FIGURE_FORMATS]
        targets += [str(run.path(assay_table(a, t))) for a in self.assays for t in ROLLOUT_TABLES]
        targets += [str(run.path(assay_table(a, "hidden"))) for a in self.hidden_assays]
        if scale.top_seeds:
            targets += [str(run.path(stacked_seeds_table(a))) for a in scale.top_seed_assays]
        targets += [path for a, analyses in self.assay_analyses.items() for analysis in analyses
                    for path in analysis_outputs(analysis, run, a).values()]
        targets += [path for figure in self.figure_panels for path in self.figure_outputs(figure, run)]
        targets += self.render_targets(run)
        targets += [str(run.path(name)) for name in (CLAIMS_TABLE, CLAIM_PARTS, CLAIMS_PAGE)]
        targets += list(power_outputs(run).values())
        if scale.learning:
            targets += list(learning_outputs(run).values())
        return targets
