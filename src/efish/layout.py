"""Where every file of a run lives: the one home of the results layout.

A run named ``<run>`` (the scale, or the scale and a hash of its overrides) keeps
its tables under ``results/<run>/`` and its drawings under ``figures/<run>/``::

    results/<run>/
      train/<seed_N | policy>/        final.pt, metrics.parquet, stage_K.pt (training); metrics.csv, tensorboard/
                                      (its live logs, efish.rl.loggers)
      train/<policy>_draw_K/          the same for the K-th draw of a policy recipe (K >= 2, scale.homing_seeds)
      selection/seed_N/               episodes, steps, food (held-out patchy episodes)
      analysis/selection/             ranking.parquet, selected_seed.txt
      assays/<assay>/                 steps, episodes, food, conditions (, hidden) .parquet
      analysis/<analysis>/<assay>/    the tables of efish.analysis.registry, analysis_settings.parquet
      seeds/<assay>/episodes.parquet  the top seeds' episodes stacked (supplement)
      seeds/seed_N/                   another top seed's assays, analyses and claims, same layout (the K-th
                                      top seed's homing with the K-th draw of the homing recipes)
      seeds/groups/<assay>/seed_N/    while a run lasts: the top seeds' reruns of an assay, rolled out in one job
      learning/stage_K/               the same for the selected seed's K-th kept training stage
      learning/                       claims_by_stage, claims_trends .parquet, claims.md (claims along training)
      scenes/<scene>.parquet          field maps
      claims/                         claims, claim_parts, recipe_parts .parquet, claims.md; power, power_curves,
                                      power_claims .parquet, power.md (what a decisive verdict costs)
      bench/                          benchmark tables
      logs/, benchmarks/              one .log and one Snakemake .tsv per job
    figures/<run>/
      <figure>/<panel>.png|pdf, <figure>.png|pdf, clips/<assay>.gif, contact_sheet.png, bench/,
      learning/claims_by_stage_<figure>.png|pdf (the claims along training, one per figure of claims),
      claims/power.png|pdf (what a decisive verdict costs)

Panels and claims name a table by its path relative to ``results/<run>/`` (``assays/patchy4/steps.parquet``);
the functions below build those names and :func:`parse_table` reads them back. :class:`Run` anchors them in a
run's folders; the Snakemake rules pass wildcard names (``Run("{run}")``, ``assay="{assay}"``), so the rules,
the CLI, the panels and the claims all share this one layout. Nothing here imports beyond the standard library.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

RESULTS_ROOT = Path("results")
FIGURES_ROOT = Path("figures")

# The tables an assay writes (hidden only where the assay records the GRU state) and their order.
ROLLOUT_TABLES = ("steps", "episodes", "food", "conditions")
RANKING = "analysis/selection/ranking.parquet"
SELECTED_SEED = "analysis/selection/selected_seed.txt"
CLAIMS_TABLE = "claims/claims.parquet"
CLAIMS_PAGE = "claims/claims.md"
FIGURE_FORMATS = ("png", "pdf")
BENCH = "bench"  # the benchmarks' folder: tables under results/<run>/, figures under figures/<run>/
BENCHMARKS = "benchmarks"  # Snakemake's per-job .tsv timings under results/<run>/
CONTACT_SHEET = "contact_sheet.png"  # under figures/<run>/
LEARNING = "learning"  # the claims along training: the stages' copies of the layout and the stacked tables
FINAL_POLICY = "final.pt"  # train/<name>/: the finished training's policy, written last (efish.rl.train)
TRAINING_METRICS = "metrics.parquet"  # train/<name>/: one row per update, rewritten after each


def seed_name(seed: int | str) -> str:
    """A trained seed's folder name: ``seed_3`` (``seed_{seed}`` in a rule)."""
    return f"seed_{seed}"


def assay_folder(assay: str) -> str:
    return f"assays/{assay}"


def assay_table(assay: str, table: str) -> str:
    """``assays/<assay>/<table>.parquet``: a rollout table (steps, episodes, food, conditions, hidden)."""
    return f"{assay_folder(assay)}/{table}.parquet"


def analysis_folder(analysis: str, assay: str) -> str:
    return f"analysis/{analysis}/{assay}"


def analysis_table(analysis: str, assay: str, table: str) -> str:
    """``analysis/<analysis>/<assay>/<table>.parquet``: a table of an analysis of one assay."""
    return f"{analysis_folder(analysis, assay)}/{table}.parquet"


#: The table an analysis job writes beside its own: the analysis settings it ran with
#: (:func:`efish.config.recorded.settings_table`); no analysis names an output so.
ANALYSIS_SETTINGS = "analysis_settings"


def analysis_settings(analysis: str, assay: str) -> str:
    """``analysis/<analysis>/<assay>/analysis_settings.parquet``: the settings that analysis job ran with."""
    return analysis_table(analysis, assay, ANALYSIS_SETTINGS)


def training_folder(name: str) -> str:
    """``train/<name>``: ``name`` is a seed's folder (:func:`seed_name`) or a policy recipe."""
    return f"train/{name}"


def training_file(name: str, file: str) -> str:
    """``train/<name>/<file>``: ``name`` is a seed's folder (:func:`seed_name`) or a policy recipe."""
    return f"{training_folder(name)}/{file}"


#: Between a policy recipe's name and the number of its draw in the draw's training folder (:func:`recipe_draw`).
DRAW = "_draw_"


def recipe_draw(recipe: str, k: int | str) -> str:
    """The training folder's name of the k-th independent draw of policy recipe ``recipe`` (``train.seed =
    scale.seed_offset + k``): draw 1 is the recipe's own folder, a later one ``homing_draw_2`` (``{policy}_draw_{draw}``
    in a rule).

    >>> recipe_draw("homing", 1), recipe_draw("homing_raycast", 3)
    ('homing', 'homing_raycast_draw_3')
    """
    return recipe if str(k) == "1" else f"{recipe}{DRAW}{k}"


def parse_recipe_draw(name: str) -> tuple[str, int]:
    """The recipe and the draw of a recipe's training folder: the inverse of :func:`recipe_draw`.

    >>> parse_recipe_draw("homing_raycast_draw_3"), parse_recipe_draw("homing")
    (('homing_raycast', 3), ('homing', 1))
    """
    recipe, _, k = name.rpartition(DRAW)
    return (recipe, int(k)) if recipe and k.isdigit() and int(k) >= 2 else (name, 1)


def stage_name(k: int | str) -> str:
    """``stage_3``: the k-th kept training stage (k = 1..K in the order of ``train.keep_stages``)."""
    return f"stage_{k}"


def stage_file(k: int | str) -> str:
    """``stage_3.pt``: the policy training kept at its k-th stage, beside final.pt (``stage_{k}.pt`` in a rule)."""
    return f"{stage_name(k)}.pt"


def selection_table(seed: int | str, table: str) -> str:
    """``selection/seed_N/<table>.parquet``: a seed's held-out episodes for the selection."""
    return f"selection/{seed_name(seed)}/{table}.parquet"


def stacked_seeds_table(assay: str) -> str:
    """``seeds/<assay>/episodes.parquet``: the top seeds' episodes of an assay, with seed and rank columns."""
    return f"seeds/{assay}/episodes.parquet"


def scene_table(scene: str) -> str:
    return f"scenes/{scene}.parquet"


def bench_file(name: str) -> str:
    """``bench/<name>``: a benchmark's table, JSON or figure."""
    return f"{BENCH}/{name}"


class TableId(NamedTuple):
    """What a table path relative to ``results/<run>/`` names: ``kind`` is ``assays``, ``analysis`` or
    ``seeds`` (the stacked top-seed tables); ``analysis`` is empty but for analysis tables."""

    kind: str
    assay: str
    analysis: str
    table: str


def parse_table(path: str) -> TableId | None:
    """The assay (and analysis) a relative table path names, or None for any other file (training, ranking,
    scenes): the inverse of :func:`assay_table`, :func:`analysis_table` and :func:`stacked_seeds_table`."""
    parts = path.split("/")
    stem = parts[-1].removesuffix(".parquet")
    if parts[0] == "assays" and len(parts) == 3:
        return TableId("assays", parts[1], "", stem)
    if parts[0] == "analysis" and len(parts) == 4:
        return TableId("analysis", parts[2], parts[1], stem)
    if parts[0] == "seeds" and len(parts) == 3 and not parts[1].startswith("seed_"):
        return TableId("seeds", parts[1], "", stem)
    return None


def top_seed_copy(seed: int | str) -> str:
    """``seeds/seed_N``: another top seed's copy of the layout (its assays, analyses and claims)."""
    return f"seeds/{seed_name(seed)}"


def top_seed_group(assay: str) -> str:
    """``seeds/groups/<assay>``: where one job rolls out every top seed that reruns ``assay`` (``efish assay
    --group``), one :func:`seed_name` folder each, before each seed's tables are handed to its copy of the layout.
    The workflow removes it once every seed has its tables (a Snakemake ``temp`` output)."""
    return f"seeds/groups/{assay}"


def stage_copy(k: int | str) -> str:
    """``learning/stage_K``: the copy of the layout where the selected seed's K-th kept training stage acts."""
    return f"{LEARNING}/{stage_name(k)}"


@dataclass(frozen=True)
class Run:
    """The folders of one run. ``name`` may be a Snakemake wildcard (``{run}``); ``copy`` set means a copy of the
    layout inside the run: another top seed's (:func:`top_seed_copy`, ``results/<run>/seeds/seed_N/``) or a
    training stage's (:func:`stage_copy`, ``results/<run>/learning/stage_K/``). A copy's logs and benchmark files
    stay under the run's own ``logs/<copy>/`` and ``benchmarks/<copy>/`` so one folder times the whole run."""

    name: str
    copy: str = ""
    results_root: Path = RESULTS_ROOT
    figures_root: Path = FIGURES_ROOT

    @property
    def results(self) -> Path:
        """Where this run's (or this copy's) tables live."""
        root = Path(self.results_root) / self.name
        return root / self.copy if self.copy else root

    @property
    def figures(self) -> Path:
        return Path(self.figures_root) / self.name

    def within(self, copy: str | None) -> Run:
        """The copy of the layout at ``copy`` (a :func:`top_seed_copy` or :func:`stage_copy`; None: the run)."""
        return Run(self.name, copy or "", self.results_root, self.figures_root)

    def top_seed(self, seed: int | str) -> Run:
        """Another top seed's copy of the layout."""
        return self.within(top_seed_copy(seed))

    def stage(self, k: int | str) -> Run:
        """The copy of the layout of the selected seed's k-th kept training stage."""
        return self.within(stage_copy(k))

    def path(self, relative: str) -> Path:
        """A file under the results folder, from a relative name of this module (e.g. :func:`assay_table`)."""
        return self.results / relative

    def _job_file(self, kind: str, job: str, suffix: str) -> Path:
        copy = f"{self.copy}/" if self.copy else ""
        return Path(self.results_root) / self.name / kind / f"{copy}{job}{suffix}"

    def log(self, job: str) -> Path:
        """``results/<run>/logs/<job>.log`` (``job`` may hold folders: ``assays/patchy4``)."""
        return self._job_file("logs", job, ".log")

    def benchmark(self, job: str) -> Path:
        """``results/<run>/benchmarks/<job>.tsv``: Snakemake's timing of one job (``efish bench pipeline``)."""
        return self._job_file(BENCHMARKS, job, ".tsv")

    @property
    def benchmarks(self) -> Path:
        return Path(self.results_root) / self.name / BENCHMARKS

    @property
    def bench(self) -> Path:
        """``results/<run>/bench/``: the benchmarks' tables (``efish bench ... --out``)."""
        return self.results / BENCH

    @property
    def bench_figures(self) -> Path:
        """``figures/<run>/bench/``: the benchmarks' figures (``efish bench accuracy|scaling --figures``)."""
        return self.figures / BENCH

    def panel(self, figure: str, panel: str, ext: str) -> Path:
        """``figures/<run>/<figure>/<panel>.<ext>``."""
        return self.figures / figure / f"{panel}.{ext}"

    def page(self, figure: str, ext: str) -> Path:
        """``figures/<run>/<figure>.<ext>``: a figure's page of every panel drawn at its scale."""
        return self.figures / f"{figure}.{ext}"

    def bench_figure(self, name: str, ext: str) -> Path:
        """``figures/<run>/bench/<name>.<ext>``: a benchmark's figure."""
        return self.bench_figures / f"{name}.{ext}"

    def clip(self, assay: str, ext: str = "gif") -> Path:
        return self.figures / "clips" / f"{assay}.{ext}"

    @property
    def contact_sheet(self) -> Path:
        return self.figures / CONTACT_SHEET


# ------------------------------------------------ claims per part and along training (efish claims, claims-by-stage)
CLAIM_PARTS = "claims/claim_parts.parquet"  # one row per part of each claim, beside claims.parquet
RECIPE_PARTS = "claims/recipe_parts.parquet"  # each part decided over the top seeds (efish.claims.recipe)
#: What a decisive verdict costs (``efish power``): the plan per part, the chance per part and design, the page,
#: and the figure's stem under ``figures/<run>/``.
POWER_TABLE = "claims/power.parquet"
POWER_CURVES = "claims/power_curves.parquet"
POWER_CLAIMS = "claims/power_claims.parquet"  # one line per claim: what would decide it
POWER_PAGE = "claims/power.md"
POWER_FIGURE = "claims/power"
#: The claims along training (``efish claims-by-stage``): the stages' parts stacked and each part's trend, under
#: ``results/<run>/``, and their figures (``.png``, ``.pdf``) under ``figures/<run>/``.
CLAIMS_BY_STAGE = f"{LEARNING}/claims_by_stage.parquet"
CLAIMS_TRENDS = f"{LEARNING}/claims_trends.parquet"
#: The selected seed's claims page with one line per claim along training (its trend over the stages).
CLAIMS_TRENDS_PAGE = f"{LEARNING}/claims.md"
#: The claims along training's figures are one per figure of the paper's claims, ``claims_by_stage_<group>``
#: (:func:`claims_by_stage_stem`; the groups: ``efish.claims.registry.CLAIM_FIGURES``).
CLAIMS_BY_STAGE_FIGURE = f"{LEARNING}/claims_by_stage"


def claims_by_stage_stem(group: str) -> str:
    """The stem, under ``figures/<run>/``, of the claims along training's figure of ``group`` (``fig3``); it is
    written as ``.png`` and ``.pdf``.

    >>> claims_by_stage_stem("fig3")
    'learning/claims_by_stage_fig3'
    """
    return f"{CLAIMS_BY_STAGE_FIGURE}_{group}"
