"""The ``efish`` command: compose the config, call one package function, report.

    efish config [overrides]                  print the resolved config
    efish plan [overrides]                    which effects run, and why
    efish train [overrides] [--out D]         train one seed (checkpoint.pt, metrics.parquet, final.pt)
    efish watch RUN [--results D] [--interval S] [--once] [--plot F.png]   every training job of a run in a live
                                              table (update, return, entropy, KL, speed, ETA, state), under
                                              the whole pipeline's jobs done and time left
    efish compare-runs RUN [RUN ...] [--sweep G --scale S --overrides O] [--results D] [--out F] [--plot F.png]
                                              several runs' training curves on shared axes (each seed thin, the
                                              mean over seeds thick) and each metric's final value with a 95% t
                                              interval over seeds -> compare_runs.parquet|.csv, F.png and .pdf
    efish assay [overrides] --policy P...     run an assay into steps/episodes/food(/hidden).parquet
    efish schema steps|episodes|food|hidden|conditions   the columns of a rollout table and what they mean
    efish select --episodes F... --out D      rank seeds, write the ranking and the chosen seed
    efish stack-seeds --tables T... --ranking R --out F   the top seeds' tables as one, with seed and rank
    efish analyze NAME [overrides] --tables D --out D   one analysis of an assay's tables -> <table>.parquet
    efish figure FIG[/PANEL] [overrides]      draw a panel (or a figure's page) from the result tables;
                                              bench/accuracy and bench/scaling redraw a benchmark's figure
    efish render assay=NAME [overrides] [--condition C] [--episode K] [--out F.gif|F.mp4] [--field]
                                              one episode of an assay as a clip, from its rollout tables
    efish contact-sheet [overrides] [--figures D] [--out F.png]   every panel's PNG as a thumbnail with its id
    efish gallery RUN [--figures D] [--results D] [--out D] [--max-width PX]   every panel of a run, web-sized,
                                              with its caption on one page -> figures/<run>/gallery/index.md and img/
    efish claims [overrides] [--results D] [--out D] [--ranking F] [--seed-claims SEED=F ...] [--trends F]
                                              the paper's claims as verdicts -> claims.parquet, claim_parts.parquet
                                              (one row per part), claims.md; with the other top seeds' claims
                                              tables, seed_verdicts and seeds_agree too; with a claims_trends.parquet,
                                              an "Along training" section in claims.md
    efish claims-by-stage [overrides] --stages K=PATH ... (--env-steps K=N ... | --stage-policies K=PATH ...)
                          [--episodes K=N ...] [--claims F] [--out D] [--figures D]
                                              the claims' parts at the kept training stages stacked, each part's
                                              trend -> claims_by_stage.parquet, claims_trends.parquet (--out,
                                              default results/<run>/learning), claims.md with the trend lines
                                              (--claims) and claims_by_stage_<fig>.png|pdf, one per figure
                                              of claims, fig2 .. fig6 (--figures, default figures/<run>/learning)
    efish compare-claims A B                  two runs' claim verdicts, seeds_agree and effects side by side
    efish compare-claims A B C --heatmap H.png  claims x runs: a table (--out) and a heatmap
    efish power [RUN] [overrides] [--results D] [--out D] [--figures D]
                                              what a decisive verdict costs: each part planned over the top seeds,
                                              priced with the run's job times -> power.parquet, power_curves.parquet,
                                              power_claims.parquet, power.md (default results/<run>/claims),
                                              power.png|pdf (--figures)
    efish scene NAME [overrides] --out D      field maps of config/scene/NAME.yaml -> D/NAME.parquet
    efish bench physics [overrides] [--json] [--out D]   sensing throughput, fast vs reference
    efish bench accuracy [overrides] [--out D] [--figures D]   accuracy-vs-time study -> table (--out, default
                                              results/<run>/bench) and figure (--figures, default figures/<run>/bench)
    efish bench scaling [overrides] [--out D] [--figures D]    cost per agent-step vs pellets and agents -> the
                                              same: table and figure
    efish bench multipole [overrides] [--orders P ..] [--width CM]   would cell multipoles make the far field cheaper?
    efish bench env [overrides] [--envs N] [--steps N] [--json]   env-only throughput, fast vs reference physics
    efish bench train [overrides] [--hidden W ..] [--json]   rollout/update speed, model-FLOP utilisation
    efish bench group [overrides] [--sizes K ..] [--json]    grouped rollouts against one by one
    efish bench budget [overrides] [--minutes M] [--hidden W ..] [--seeds N] [--jobs N] [--out D]
                                              fixed training time: wider net, more steps or more seeds?
    efish bench pipeline [--results D]        time per rule family of a pipeline run (Snakemake benchmarks)
    efish plan-cluster [overrides]            every job of a scale (scale=paper) with runtime, memory, cores, vs the
                                              slurm profile (from the laptop run's benchmark files)

Overrides are Hydra's ``key=value`` (``physics.image_order=2``) or group
choices (``arena=patchy70``). ``efish train`` composes ``policy=foraging`` first: the paper's
training arenas, sampled per episode (config/policy/). The benchmarks' sizes are ``bench.*`` fields
(``efish config`` lists them); a bench command's flags override them for one
run. Every error is one line on stderr, exit code 2, and nothing is written.

``efish --version`` prints the installed version (the one provenance.json records). ``--help`` is the user's
documentation, so it is written with :mod:`efish.cli_support`'s helpers: every (sub)command says what it does,
what it writes and which pages of the docs to read (:func:`~efish.cli_support.add_command`, pages by their title
in the site's navigation and their path under docs/), every argument has a help line, and the overrides are
worded once (:func:`~efish.cli_support.add_overrides`). tests/test_cli_help.py holds them to it; the site's
command-line reference (docs/reference/cli.md) is this parser's help, generated when the site is built.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import sys
from datetime import datetime, timezone
from pathlib import Path
from typing import Sequence

from ._version import __version__
from .cli_claims import _sweep_runs, run_claims, run_claims_by_stage, run_compare_claims, run_power
from .cli_support import HelpFormatter, add_command, add_overrides, run_at, run_of, see_docs, write_metadata
from .config import ConfigError, compose, to_yaml
from .figures.gallery import GALLERY, MAX_WIDTH_PX, SITE_GALLERY
from .layout import (
    ANALYSIS_SETTINGS,
    BENCH,
    CLAIMS_BY_STAGE,
    CLAIMS_BY_STAGE_FIGURE,
    CONTACT_SHEET,
    FIGURES_ROOT,
    POWER_FIGURE,
    POWER_TABLE,
    RANKING,
    RESULTS_ROOT,
    SELECTED_SEED,
    Run,
    assay_folder,
    scene_table,
    seed_name,
    training_folder,
)

DESCRIPTION = """\
The command line of efish, a reproduction of a multi-agent RL study of weakly electric fish. Each command composes \
the config (config/ and the overrides), calls one function of the efish package and prints or writes what it made; \
an output folder also gets config.yaml and provenance.json (the resolved config; the command, its start and end, \
the efish and package versions)."""

EPILOG = f"""\
Overrides are Hydra's key=value (physics.image_order=2) or a config group's choice (arena=patchy70); efish config \
prints the resolved config and so lists every key. efish train composes policy=foraging first (the paper's sampled \
training arenas); a bench command's flags override its bench.* sizes for one run. Every error is one line on \
stderr, exit code 2, and nothing is written.

examples:
  efish config scale=smoke              the smoke scale's config
  efish plan arena=patchy70             which effects run in that arena, and why
  efish train scale=smoke train.seed=1  train one seed (results/smoke/train/seed_1)
  efish schema episodes                 the columns of episodes.parquet
  efish COMMAND --help                  what a command does and writes

{see_docs("docs/reference/cli.md", "docs/getting-started.md", "docs/tutorials/override-configs.md")}"""


def _parser() -> argparse.ArgumentParser:
    """The command line; every (sub)command's parser sets ``handler``, the function :func:`main` calls."""
    p = argparse.ArgumentParser(prog="efish", description=DESCRIPTION, epilog=EPILOG, formatter_class=HelpFormatter)
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}",
                   help="print efish's version (the installed package's) and exit")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND",
                           help="what to do (efish COMMAND --help says more)")
    for add in (_config_commands, _training_commands, _assay_commands, _figure_commands, _claims_commands,
                _cluster_commands):
        add(sub)
    _bench_parsers(sub)
    return p


def _add_out(parser: argparse.ArgumentParser, help_: str, required: bool = False) -> None:
    """``--out``, the folder or file a command writes (``help_``: what goes there, and its default)."""
    parser.add_argument("--out", type=Path, required=required, help=help_)


def _add_json(parser: argparse.ArgumentParser) -> None:
    """``--json``: print the command's result as JSON (records for a table), for a script to read."""
    parser.add_argument("--json", action="store_true", help="print JSON instead of the table")


def _config_commands(sub: argparse._SubParsersAction) -> None:
    """The commands that only print what a config says: config, plan, schema."""
    c = add_command(sub, "config", "print the resolved config",
                    "Print the config the overrides compose to, as YAML: every key a command reads, with its value. "
                    "Writes nothing.", "docs/tutorials/override-configs.md", "docs/reference/config.md")
    add_overrides(c, example="scale=smoke physics.image_order=2")
    c.set_defaults(handler=_config)
    pl = add_command(sub, "plan", "which physical effects the simulator computes, and why",
                     "Print the effect plan of the configured scene: each physical effect (wall images, induction, "
                     "far-field interpolation, ...) on or off, and the setting that decides it. Writes nothing.",
                     "docs/model/effect-plan.md")
    add_overrides(pl, example="arena=patchy70 'env.muted=[0,1,2,3]'")
    pl.set_defaults(handler=_plan)
    sch = add_command(sub, "schema", "print a rollout table's columns and their meaning",
                      "Print the columns of one rollout table with their type, unit and meaning. Writes nothing.",
                      "docs/reference/tables.md", "docs/tutorials/read-the-tables.md")
    sch.add_argument("table", choices=("steps", "episodes", "food", "hidden", "conditions"),
                     help="the table: steps, episodes, food, hidden or conditions")
    add_overrides(sch, note="they do not change the columns")
    sch.set_defaults(handler=_schema)


def _training_commands(sub: argparse._SubParsersAction) -> None:
    """Training a seed, watching the runs train and comparing them, ranking and stacking the seeds: train, watch,
    compare-runs, select, stack-seeds."""
    tr = add_command(sub, "train", "train one seed with recurrent MAPPO",
                     "Train one seed with recurrent MAPPO on the paper's sampled training arenas (policy=foraging is "
                     "composed before the overrides), resuming from a checkpoint in --out. Writes checkpoint.pt, "
                     "metrics.parquet (a row per update), final.pt, config.yaml and provenance.json.",
                     "docs/methods/training.md")
    add_overrides(tr, example="scale=smoke train.seed=3", note="policy= or arena= replaces the training arenas")
    _add_out(tr, "output folder (default results/{run}/train/seed_{seed})")
    tr.add_argument("--restart", action="store_true", help="discard a checkpoint in --out and start afresh")
    tr.set_defaults(handler=_train, recipe=TRAINING_RECIPE)
    wa = add_command(sub, "watch", "a live table of every training job of a run",
                     "Show every training job of a run in a table refreshed in place: update, return, entropy, KL, "
                     "speed, ETA and state, from their metrics.parquet; above it, for a shipped scale's run in this "
                     "workflow's results/, the whole pipeline's jobs done of its total and time left (a Snakemake "
                     "dry run every 10 minutes). Writes nothing but the --plot PNG.",
                     "docs/tutorials/watch-a-run.md", "docs/methods/training.md#live-logs")
    wa.add_argument("run", help="the run's folder name under --results (smoke, laptop-453280a3), or its folder "
                                "(results/laptop)")
    wa.add_argument("--results", type=Path, default=Path("results"), help="the results root (default results)")
    wa.add_argument("--interval", type=float, default=10.0, help="seconds between refreshes (default 10)")
    wa.add_argument("--once", action="store_true", help="print the table once and exit")
    wa.add_argument("--plot", type=Path, metavar="F.png",
                    help="also write every metric of the jobs' metrics against env steps, one panel each and one "
                         "line per job, to this PNG (rewritten at every refresh)")
    wa.set_defaults(handler=_watch)  # no overrides: nothing to compose
    _compare_runs_command(sub)
    sel = add_command(sub, "select", "rank seeds by their selection episodes and choose one",
                      "Rank the trained seeds by their selection episodes and choose the seed the assays act with. "
                      "Writes ranking.parquet, selected_seed.txt, config.yaml and provenance.json to --out.",
                      "docs/methods/training.md#seed-selection")
    add_overrides(sel, example="scale=laptop", note="recorded in config.yaml")
    sel.add_argument("--episodes", nargs="+", type=Path, required=True,
                     help="episodes.parquet files in folders named seed_<n>")
    _add_out(sel, "folder for ranking.parquet and selected_seed.txt", required=True)
    sel.set_defaults(handler=_select)
    st = add_command(sub, "stack-seeds", "stack the top seeds' tables into one",
                     "Stack one table of each top seed (each under seed_<n>/) into one table with seed and rank "
                     "columns, in the order of the seed ranking. Writes the stacked .parquet (--out).",
                     "docs/methods/training.md#seed-selection")
    add_overrides(st, example="scale=laptop")
    st.add_argument("--tables", nargs="+", type=Path, required=True, help="the seeds' tables, each under seed_<n>/")
    st.add_argument("--ranking", type=Path, required=True, help=f"the seed ranking ({RANKING})")
    _add_out(st, "the stacked table (.parquet)", required=True)
    st.set_defaults(handler=_stack_seeds)


def _compare_runs_command(sub: argparse._SubParsersAction) -> None:
    """``efish compare-runs``: several runs' training curves on shared axes, and their final values."""
    cr = add_command(sub, "compare-runs", "several runs' training curves on shared axes, with their final values",
                     "Read the foraging seeds' metrics.parquet of each run (with --sweep, a sweep's runs), smooth each "
                     "seed's curve of every metric over its last 10 finite values (as efish watch smooths the return) "
                     "and print, per run and metric, the seeds' final values: their mean with a 95% t interval over "
                     "the seeds (none with one seed). Policy recipes (train/homing) are left out. Writes the table "
                     "(--out) and the curves against env steps, one panel per metric, each seed thin and the mean "
                     "over seeds thick, one colour per run (--plot) when asked.",
                     "docs/tutorials/watch-a-run.md#compare-runs", "docs/tutorials/sweep-a-parameter.md")
    cr.add_argument("runs", nargs="*", metavar="RUN",
                    help="a run name under --results (smoke, laptop-453280a3) or a run's folder (one holding train/); "
                         "one or more in all, with --sweep's")
    _add_sweep(cr)
    _add_out(cr, "write the table (run, metric, seeds, final_mean, ci_low, ci_high, env_steps) as .parquet or .csv; "
                 "a folder gets compare_runs.parquet")
    cr.add_argument("--plot", type=Path, metavar="F.png", help="draw the curves to this PNG, and the same as .pdf "
                                                                "beside it")
    cr.set_defaults(handler=_compare_runs)  # no Hydra overrides: nothing to compose


def _assay_commands(sub: argparse._SubParsersAction) -> None:
    """Running the trained policies and analysing what they did: assay, analyze, scene."""
    asy = add_command(sub, "assay", "run an assay with trained policies into rollout tables",
                      "Run the configured assay (assay=NAME) with the policies of --policy: each condition's "
                      "episodes, recorded as steps, episodes, food and conditions tables (and hidden where the assay "
                      "records hidden states). Writes <table>.parquet, config.yaml and provenance.json to --out.",
                      "docs/methods/assays.md", "docs/reference/tables.md")
    add_overrides(asy, example="assay=patchy4 scale=smoke")
    asy.add_argument("--policy", nargs="+", default=[], metavar="[NAME=]PATH",
                     help="training folder, final.pt or checkpoint.pt of each policy the conditions act with "
                          "(NAME: selected, homing, homing_raycast, ...; a bare PATH is the assay's own policy)")
    asy.add_argument("--group", nargs="+", metavar="MEMBER=PATH",
                     help="several policies that each act as the assay's own policy (e.g. the top seeds, MEMBER their "
                          "seed numbers), all in one env on the same episodes: each member's tables equal its run "
                          "alone, and go to --out with {member} replaced by its name")
    _add_out(asy, "output folder (default results/{run}/assays/{assay}); with --group a template holding {member}")
    asy.set_defaults(handler=_assay)
    an = add_command(sub, "analyze", "run one analysis of an assay's rollout tables",
                     "Run one analysis (efish.analysis.registry) of an assay's rollout tables under the config's "
                     "analysis settings. Writes its <table>.parquet files, analysis_settings.parquet, config.yaml and "
                     "provenance.json to --out.", "docs/methods/analyses.md", "docs/tutorials/add-an-analysis.md")
    an.add_argument("name", help="an analysis of efish.analysis.registry, e.g. behaviour (a wrong name lists them)")
    add_overrides(an, example="assay=patchy4 analysis.rate_bins=10")
    an.add_argument("--tables", type=Path, required=True,
                    help="folder of the assay's tables (steps.parquet, ..., conditions.parquet: what it simulated)")
    _add_out(an, "folder for <table>.parquet, analysis_settings.parquet (the analysis settings it ran with), "
                 "config.yaml, provenance.json", required=True)
    an.set_defaults(handler=_analyze)
    sc = add_command(sub, "scene", "compute a scene's field maps into a table",
                     "Compute the field maps of a scene (config/scene/NAME.yaml) on its grid with the physics, for "
                     "Fig 1 and the sensing-range panels. Writes NAME.parquet, config.yaml and NAME.provenance.json "
                     "to --out.", "docs/methods/figures.md#panels")
    sc.add_argument("name", help="a scene of config/scene/, e.g. eod_walls")
    add_overrides(sc, example="scene.resolution_cm=1")
    _add_out(sc, "folder for <name>.parquet (default results/{run}/scenes)")
    sc.set_defaults(handler=_scene)


def _figure_commands(sub: argparse._SubParsersAction) -> None:
    """Drawing from the result tables: figure, render, contact-sheet."""
    fg = add_command(sub, "figure", "draw a panel or a figure's page from the result tables",
                     "Draw one panel (fig3/M), or each panel of a figure and its page (fig3), from a run's result "
                     "tables; bench/accuracy and bench/scaling redraw a benchmark's figure. Writes PNG and PDF files, "
                     "each with its provenance, and config.yaml to --out.", "docs/methods/figures.md")
    fg.add_argument("key", help="panel id like fig3/M, a figure id like fig3 for its page, or bench/accuracy, "
                                "bench/scaling (a benchmark's figure, from results/{run}/bench/bench_<name>.parquet)")
    add_overrides(fg, example="scale=smoke")
    fg.add_argument("--results", type=Path, help="folder of the result tables (default results/{run})")
    _add_out(fg, "folder for the figures (default figures/{run}; a benchmark's figure goes to its bench/)")
    fg.set_defaults(handler=_figure)
    rd = add_command(sub, "render", "draw one episode of an assay as a clip",
                     "Draw one episode of an assay (assay=NAME) from its rollout tables as a clip, .gif or (with "
                     "ffmpeg) .mp4, optionally over the field of the discharges. Writes the clip, config.yaml and "
                     "<clip>.provenance.json.", "docs/tutorials/render-an-episode.md",
                     "docs/methods/figures.md#episode-clips")
    add_overrides(rd, example="assay=homing scale=smoke", note="assay=NAME names the assay")
    rd.add_argument("--condition", help="condition to draw (default: the assay's first)")
    rd.add_argument("--episode", type=int, help="episode to draw (default: the condition's first)")
    rd.add_argument("--tables", type=Path, help="folder of the assay's tables (default results/{run}/assays/{assay})")
    _add_out(rd, "the clip, .gif or .mp4 (default figures/{run}/clips/{assay}.gif)")
    rd.add_argument("--every", type=int, help="draw every N-th step (default: the smallest N that plays in real "
                                              "time and keeps the clip a few MB)")
    rd.add_argument("--fps", type=float, help="frames per second (default env.fps / N: real time)")
    rd.add_argument("--field", action="store_true", help="overlay |E| of the EODs discharged at each step "
                                                         "(computed by the physics on a coarse grid)")
    rd.set_defaults(handler=_render)
    cs = add_command(sub, "contact-sheet", "every registered panel's PNG as a thumbnail with its id",
                     "Lay out each registered panel's PNG of a run as a thumbnail with its id, marking the panels not "
                     "drawn at this scale. Writes one PNG with its config.yaml and provenance.",
                     "docs/methods/figures.md#contact-sheet")
    add_overrides(cs, example="scale=smoke")
    cs.add_argument("--figures", type=Path, help="figure folder of the run (default figures/{run})")
    _add_out(cs, f"the sheet, a .png (default <figures>/{CONTACT_SHEET})")
    cs.set_defaults(handler=_contact_sheet)
    ga = add_command(sub, "gallery", "every registered panel of a run on one Markdown page (the site's gallery)",
                     "Copy every registered panel of a run, web-sized, onto one Markdown page grouped by figure, each "
                     "with its caption, a panel the run did not draw saying why, and the commits, CPU and torch CPU "
                     "capability the run recorded. Writes <out>/index.md and <out>/img/.", "docs/methods/figures.md#gallery")
    ga.add_argument("run", help="the run's name (laptop, smoke, laptop-453280a3): the page's title and its folders' "
                                "default names")
    ga.add_argument("--figures", type=Path, help="the run's figure folder, whose <figure>/<panel>.png it copies "
                                                 "(default figures/<run>)")
    ga.add_argument("--results", type=Path, help="the run's results folder: the commits of its tables' provenance "
                                                 "and the CPU of bench/bench_physics.json (default results/<run>)")
    ga.add_argument("--out", type=Path, help=f"folder for index.md and the images under img/ (default "
                                             f"<figures>/{GALLERY}; the site's own page: --out {SITE_GALLERY})")
    ga.add_argument("--max-width", type=int, default=MAX_WIDTH_PX,
                    help=f"widest image in pixels: wider PNGs are scaled down (default {MAX_WIDTH_PX})")
    ga.set_defaults(handler=_gallery)  # no overrides: nothing to compose


def _claims_commands(sub: argparse._SubParsersAction) -> None:
    """The paper's claims as verdicts, along training and across runs: claims, claims-by-stage, compare-claims."""
    cl = add_command(sub, "claims", "the paper's claims as verdicts from a run's tables",
                     "Test the paper's claims on a run's result tables under the ten rules and give each a verdict. "
                     "Writes claims.parquet, claim_parts.parquet (a row per part) and claims.md to --out; with the "
                     "other top seeds' claims also seed_verdicts and seeds_agree.", "docs/claims/index.md",
                     "docs/claims/results.md")
    add_overrides(cl, example="scale=smoke analysis.claims_resamples=200")
    cl.add_argument("--results", type=Path, help="the run's results folder (default results/{run})")
    _add_out(cl, "folder for claims.parquet and claims.md (default <results>/claims)")
    cl.add_argument("--seed-claims", nargs="*", metavar="SEED=PATH",
                    help="the claims.parquet of each other top seed (results/{run}/seeds/seed_<n>/claims/): adds "
                         "seed_verdicts and seeds_agree; given with no value, the selected seed's "
                         "alone ('1/1 hold')")
    cl.add_argument("--ranking", type=Path,
                    help=f"the seed ranking, whose first row is the selected seed (default with --seed-claims: "
                         f"<results>/{RANKING}); alone it adds the seed columns too")
    cl.add_argument("--trends", type=Path, help="a claims_trends.parquet (efish claims-by-stage): claims.md gains an "
                                                "'Along training' section, one line per claim")
    cl.set_defaults(handler=run_claims)
    _claims_by_stage_command(sub)
    _compare_claims_command(sub)
    _power_command(sub)


def _power_command(sub: argparse._SubParsersAction) -> None:
    """``efish power``: what a decisive verdict costs, from a finished run."""
    pw = add_command(sub, "power", "what a decisive verdict would cost: seeds and CPU-hours per claim part",
                     "Plan each claim part over the run's top seeds: split its effect's spread into between seeds and "
                     "within a seed, give the chance that the recipe's verdict settles (holds if the effect is twice "
                     "delta, absent if there is none) now and the seeds, priced in CPU-hours with the run's own job "
                     "times, that reach 80%; the same for the selected seed's own verdict over its episodes; per "
                     "claim the recipe left inconclusive, what would settle it. Writes "
                     "power.parquet, power_curves.parquet, power_claims.parquet and power.md (--out) and power.png "
                     "and .pdf (--figures). Nothing here changes a verdict.", "docs/claims/power.md")
    add_overrides(pw, example="scale=laptop", note="the run itself may stand among them, as its folder "
                  "(results/laptop) or its name under results/; else they name it", run=True)
    pw.add_argument("--results", type=Path, help="the run's results folder (default: the run given, else "
                                                 "results/{run} of the overrides)")
    _add_out(pw, f"folder for power.parquet, power_curves.parquet, power_claims.parquet and power.md (default "
                 f"results/{{run}}/{Path(POWER_TABLE).parent})")
    pw.add_argument("--figures", type=Path, help=f"folder for power.png and .pdf (default "
                                                 f"figures/{{run}}/{Path(POWER_FIGURE).parent})")
    pw.set_defaults(handler=run_power)


def _claims_by_stage_command(sub: argparse._SubParsersAction) -> None:
    """``efish claims-by-stage``: the claims' parts at the kept training stages."""
    cbs = add_command(sub, "claims-by-stage", "the claims' parts at the kept training stages, and their trends",
                      "Stack the claims' parts at the kept training stages and test whether each is still moving. "
                      "Writes claims_by_stage.parquet and claims_trends.parquet (--out), claims.md with a line per "
                      "claim along training (--claims) and claims_by_stage.png and .pdf (--figures).",
                      "docs/claims/along-training.md")
    add_overrides(cbs, example="scale=laptop analysis.claims_trend_alpha=0.01", note="they name the run")
    cbs.add_argument("--stages", nargs="+", required=True, metavar="K=PATH",
                     help="each stage's claim_parts.parquet, its claims folder, or its results folder "
                          "(results/{run}/learning/stage_<k>)")
    trained = cbs.add_mutually_exclusive_group(required=True)
    trained.add_argument("--env-steps", nargs="+", metavar="K=N",
                         help="the env steps trained at each stage (one per --stages entry)")
    trained.add_argument("--stage-policies", nargs="+", metavar="K=PATH",
                         help="the stage file (train/seed_N/stage_<k>.pt) each stage's assays acted with: its "
                              "record gives the env steps trained")
    cbs.add_argument("--claims", type=Path, help="the run's claims.parquet (its final policy's verdicts): writes "
                                                 "claims.md beside the tables with one line per claim along training")
    cbs.add_argument("--episodes", nargs="+", metavar="K=N",
                     help="episodes per condition the stage's assays ran (adds an episodes column)")
    _add_out(cbs, "folder for claims_by_stage.parquet and claims_trends.parquet "
                  f"(default results/{{run}}/{Path(CLAIMS_BY_STAGE).parent})")
    cbs.add_argument("--figures", type=Path, help="folder for claims_by_stage_<fig>.png and .pdf, one per figure "
                                                  "of the paper's claims (fig2 .. fig6) (default "
                                                  f"figures/{{run}}/{Path(CLAIMS_BY_STAGE_FIGURE).parent})")
    cbs.set_defaults(handler=run_claims_by_stage)


def _add_sweep(parser: argparse.ArgumentParser) -> None:
    """What a command over several runs takes beside their names: a sweep's runs (``--sweep`` with ``--scale`` and
    ``--overrides``, as the workflow's ``--config`` names them) and the results root the names are under."""
    parser.add_argument("--sweep", help="also every run of this sweep, in grid order: the grid given to the "
                                        "workflow's --config sweep= (inline or a YAML file), with --scale and --overrides")
    parser.add_argument("--scale", help="the sweep's scale (--config scale=; default: the workflow's)")
    parser.add_argument("--overrides", default="", help="the sweep's run overrides (--config overrides=)")
    parser.add_argument("--results", type=Path, default=RESULTS_ROOT, help="where a run name's folder is (default "
                                                                           "results/)")


def _compare_claims_command(sub: argparse._SubParsersAction) -> None:
    """``efish compare-claims``: runs' verdicts side by side."""
    cc = add_command(sub, "compare-claims", "two or more runs' claim verdicts and effect sizes side by side",
                     "Print two or more runs' claim verdicts, seeds_agree and effect sizes side by side (with --sweep, "
                     "a sweep's runs). Writes a claims x runs table (--out) and heatmap (--heatmap) when asked.",
                     "docs/tutorials/compare-claims.md", "docs/tutorials/sweep-a-parameter.md")
    cc.add_argument("runs", nargs="*", metavar="RUN",
                    help="claims.parquet, a claims folder, or a run name (results/<name>/claims/claims.parquet); two "
                         "or more in all, with --sweep's")
    _add_sweep(cc)
    _add_out(cc, "write the claims x runs table (each run's recipe verdict and effect where it has them, its verdict "
                 "and effect) as .parquet or .csv")
    cc.add_argument("--heatmap", type=Path, help="draw the claims x runs heatmap as a PNG (cell colour: each run's "
                                                 "recipe verdict, else its verdict; text: that effect)")
    cc.set_defaults(handler=run_compare_claims)  # no overrides: nothing to compose


def _cluster_commands(sub: argparse._SubParsersAction) -> None:
    """Planning a run on a SLURM cluster from a measured one: plan-cluster."""
    pc = add_command(sub, "plan-cluster", "every job of a scale with runtime, memory and cores, against a profile",
                     "Scale the benchmark files of a measured run (--from) to every job of another scale "
                     "(scale=paper): the expected runtime, memory and cores of each, checked against a SLURM "
                     "profile. Writes nothing; --suggest prints set-resources for the profile.",
                     "docs/getting-started.md#slurm", "docs/benchmarks.md#pipeline")
    add_overrides(pc, example="scale=paper", note="the scale to plan")
    pc.add_argument("--from", dest="source", default="laptop", help="scale whose run was measured (default laptop)")
    pc.add_argument("--results", type=Path, help="results folder of that run (default results/<--from>)")
    pc.add_argument("--profile", type=Path, default=Path("workflow/profiles/slurm"),
                    help="the Snakemake profile whose resources are checked (default workflow/profiles/slurm)")
    pc.add_argument("--dry-run", type=Path, metavar="FILE",
                    help="a saved `snakemake -n --forceall` output to read instead of running the dry run")
    _add_json(pc)
    pc.add_argument("--suggest", action="store_true", help="also print set-resources covering the headroom")
    pc.set_defaults(handler=_plan_cluster)


# efish bench <study>: (summary, description) of each study; each cites its section of docs/benchmarks.md
BENCH_STUDIES = {
    "physics": ("sensing throughput: fast path vs reference, one thread",
                "Time the sensing of a step, the fast path against the reference, on one thread. Prints a table "
                "(or JSON); --out also writes bench_physics.json with config.yaml and provenance.json."),
    "env": ("env-only throughput with random actions: fast path vs reference",
            "Time stepping the environment with random actions, fast physics against the reference. Prints a "
            "table (or JSON); writes nothing."),
    "train": ("rollout/update speed and model-FLOP utilisation",
              "Time the rollout and the update of training at each network width, and their model-FLOP "
              "utilisation, on the paper's training arenas. Prints a table (or JSON); writes nothing."),
    "budget": ("at fixed training time: a wider network, more env steps or more seeds",
               "Train runs of a fixed wall time: is a wider network, more env steps or more seeds worth it? Prints a "
               "table; --out also writes bench_budget.parquet with config.yaml and its provenance."),
    "pipeline": ("time per rule family of a finished pipeline run",
                 "Sum the time of each rule family of a finished pipeline run, from Snakemake's benchmark files. "
                 "Prints a table (or JSON); writes nothing."),
    "accuracy": ("accuracy-vs-time sweep: table and figure",
                 "Sweep the physics' accuracy settings and measure the error each gives against its time. Writes "
                 "bench_accuracy.parquet (--out) and its figure as PNG and PDF (--figures), each with config.yaml "
                 "and provenance."),
    "scaling": ("cost per agent-step against pellets and agents: table and figure",
                "Measure the cost of an agent-step as pellets and agents are added. Writes bench_scaling.parquet "
                "(--out) and its figure as PNG and PDF (--figures), each with config.yaml and provenance."),
    "group": ("grouped rollouts: K policies on the same episodes in one env against one by one",
              "Time K untrained policies running the same assay episodes one by one and grouped in one env "
              "(efish assay --group), for each group size. Prints a table (or JSON); writes nothing."),
    "multipole": ("cell multipoles against direct far-field reads at the plan's accuracy",
                  "Would cell multipoles make the far field cheaper? Compares them with direct far-field reads at "
                  "the plan's accuracy, for each expansion order. Prints a table (or JSON); writes nothing."),
}


def _bench_command(bsub: argparse._SubParsersAction, name: str, *docs: str, sized: bool = True
                   ) -> argparse.ArgumentParser:
    """``efish bench <name>`` with its help (:data:`BENCH_STUDIES`) and overrides, citing its Benchmarks section;
    ``sized``: the study runs work of the bench.* sizes (a finished run's timing does not: its overrides name the
    run)."""
    summary, description = BENCH_STUDIES[name]
    parser = add_command(bsub, name, summary, description, f"docs/benchmarks.md#{name}", *docs)
    if sized:
        add_overrides(parser, example="scale=smoke bench.repeats=3", note="the bench.* fields are the study's sizes")
    else:
        add_overrides(parser, example="scale=laptop", note="they name the run")
    return parser


def _bench_parsers(sub: argparse._SubParsersAction) -> None:
    """``efish bench <study>``: a flag left out means the config's ``bench.*`` value (one copy: the schema)."""
    b = add_command(sub, "bench", "speed and accuracy studies (sizes: the bench.* config fields)",
                    "Speed and accuracy studies of the simulator, the environment and training. Their sizes are the "
                    "bench.* config fields (efish config lists them); a study's flags override them for one run.",
                    "docs/benchmarks.md")
    bsub = b.add_subparsers(dest="bench", required=True, metavar="STUDY",
                            help="the study to run (efish bench STUDY --help says more)")
    bp = _bench_command(bsub, "physics")
    _add_json(bp)
    _add_out(bp, "also write bench_physics.json (+ config, provenance) here")
    bp.set_defaults(handler=_bench_physics)
    be = _bench_command(bsub, "env")
    _add_json(be)
    be.add_argument("--envs", type=int, help="arenas stepped together (default bench.env_envs)")
    be.add_argument("--steps", type=int, help="timed steps (default bench.env_steps)")
    be.set_defaults(handler=_bench_env)
    bt = _bench_command(bsub, "train", "docs/methods/training.md")
    _add_json(bt)
    bt.add_argument("--hidden", type=int, nargs="+", help="widths to time (default bench.train_hidden)")
    bt.add_argument("--device", choices=("cpu", "cuda", "auto"),
                    help="where the GEMMs, the update and the rollout's networks run (default train.device; auto: "
                         "cuda where torch sees a GPU)")
    bt.set_defaults(handler=_bench_train, recipe=TRAINING_RECIPE)
    bb = _bench_command(bsub, "budget")
    bb.add_argument("--minutes", type=float, help="wall time of each run (default bench.budget_minutes)")
    bb.add_argument("--hidden", type=int, nargs="+", help="widths to train (default bench.budget_hidden)")
    bb.add_argument("--seeds", type=int, help="seeds per width (default bench.budget_seeds)")
    bb.add_argument("--jobs", type=int, help="runs at a time, one thread each (default bench.budget_jobs)")
    _add_out(bb, "also write bench_budget.parquet (+ config, provenance) here")
    bb.set_defaults(handler=_bench_budget, recipe=TRAINING_RECIPE)
    bg = _bench_command(bsub, "group", "docs/methods/assays.md#grouped-rollouts")
    _add_json(bg)
    bg.add_argument("--sizes", type=int, nargs="+", help="policies per group (default bench.group_sizes)")
    bg.add_argument("--episodes", type=int, help="episodes per policy (default bench.group_episodes)")
    bg.add_argument("--steps", type=int, help="steps per episode (default bench.group_steps)")
    bg.set_defaults(handler=_bench_group)
    bpl = _bench_command(bsub, "pipeline", sized=False)
    bpl.add_argument("--results", type=Path, help="results folder of the run (default results/{run})")
    _add_json(bpl)
    bpl.set_defaults(handler=_bench_pipeline)
    for name, handler, docs in (("accuracy", _bench_accuracy, ("docs/model/accuracy.md",)),
                                ("scaling", _bench_scaling, ())):
        bf = _bench_command(bsub, name, *docs)
        _add_out(bf, f"folder for bench_{name}.parquet, config.yaml and provenance (default results/{{run}}/bench)")
        bf.add_argument("--figures", type=Path, help=f"folder for bench_{name}.png and .pdf (default "
                                                     "figures/{run}/bench)")
        _add_json(bf)
        bf.set_defaults(handler=handler)
    bm = _bench_command(bsub, "multipole")
    bm.add_argument("--orders", type=int, nargs="+", help="expansion orders (default bench.multipole_orders)")
    bm.add_argument("--width", type=float, help="square arena side of the scene, cm (default bench.multipole_width_cm)")
    _add_json(bm)
    bm.set_defaults(handler=_bench_multipole)


def _progress(items: list, label: str, unit: str = "setting", every: int = 1):
    """tqdm bar on a terminal, otherwise a plain line per ``every`` items (and after the last)."""
    if sys.stderr.isatty():
        from tqdm import tqdm

        return tqdm(items, desc=label, unit=unit)

    def lines():
        for i, item in enumerate(items, 1):
            if i % every == 0 or i == len(items):
                print(f"{label}: {i}/{len(items)} {item}", file=sys.stderr, flush=True)
            yield item
    return lines()


class ReturnLog:
    """The return part of a training log line: the mean return of the episodes that ended since the last line."""

    def __init__(self):
        self.ended = 0

    def line(self, row: dict) -> str:
        k = int(row.get("episodes_ended", 0))
        self.ended += k
        if k:
            return f"return {row['episode_return']:.3f} ({k} episodes)"
        return "no episode ended yet" if self.ended == 0 else "no episode ended since the last line"


def _train(args, cfg, started) -> None:
    from .rl.train import train

    out = args.out or run_of(cfg, args.overrides).path(training_folder(seed_name(cfg.train.seed)))
    bar = None
    if sys.stderr.isatty():
        from tqdm import tqdm

        bar = tqdm(unit="update", desc=f"seed {cfg.train.seed}")

    log = ReturnLog()

    def report(row: dict, total: int) -> None:
        line = (f"update {row['update']}/{total}  env-steps {row['env_steps']:,}  {log.line(row)}  "
                f"{row['env_steps_per_s']:,.0f} env-steps/s")
        if bar is not None:
            bar.total = total
            bar.set_postfix_str(line.split("  ", 1)[1])
            bar.update(1)
        else:
            print(line, file=sys.stderr, flush=True)

    df = train(cfg, out, progress=report, restart=args.restart)
    if bar is not None:
        bar.close()
    write_metadata(out, cfg, started, args, compute=df.attrs["compute"])  # device, precision and how it was chosen
    print(f"trained {len(df)} updates into {out}")


def _watch(args, cfg, started) -> None:
    from .watch import watch

    try:
        watch(run_at(args.run, args.results), args.interval, args.once, args.plot)
    except KeyboardInterrupt:  # Ctrl-C is how a live table is left: not an error
        pass


def _compare_runs(args, cfg, started) -> None:
    from .compare_runs import compare_runs

    compare_runs([*args.runs, *(_sweep_runs(args) if args.sweep else [])], args.results, args.out, args.plot)


def _assay(args, cfg, started) -> None:
    from .rl.policy import load_policy
    from .rollout.assay import run_assay_group
    from .rollout.tables import write_tables

    if not args.policy and not args.group:
        raise ValueError("efish assay needs --policy (or --group): the trained policies the conditions act with")
    paths = policy_paths(args.policy, cfg.assay.policy)
    group = policy_paths(args.group, None, "--group") if args.group else {}
    if group and "{member}" not in str(args.out or ""):
        raise ValueError("--group needs an --out template holding {member}, e.g. "
                         "results/laptop/seeds/seed_{member}/assays/patchy4")
    if not group and "{member}" in str(args.out or ""):
        raise ValueError("--out holds {member}, which only --group fills")
    policies = {name: load_policy(path) for name, path in paths.items()}
    members = [{cfg.assay.policy: load_policy(path)} for path in group.values()] or [{}]
    outs = ([Path(str(args.out).replace("{member}", name)) for name in group] if group
            else [args.out or run_of(cfg, args.overrides).path(assay_folder(cfg.assay.name))])
    shared = {k: v for k, v in policies.items() if not (group and k == cfg.assay.policy)}
    all_tables, stats = run_assay_group(args.overrides, shared, members,
                                        progress=lambda c: print(f"condition {c} done", file=sys.stderr, flush=True))
    for out, tables, member_path in zip(outs, all_tables, [*group.values()] or [None], strict=True):
        write_tables(tables, out)
        used = {**paths, **({cfg.assay.policy: member_path} if member_path else {})}
        write_metadata(out, cfg, started, args, policies={k: str(v) for k, v in used.items()}, **stats)
        print(f"wrote {', '.join(f'{k}.parquet ({len(v)} rows)' for k, v in tables.items())} to {out} "
              f"({stats['env_steps_per_s']:,.0f} env-steps/s)")


def policy_paths(entries: list[str], default: str | None, flag: str = "--policy") -> dict[str, Path]:
    """``--policy`` entries ``NAME=PATH`` (or a bare ``PATH`` for the assay's own policy, ``default``; with
    ``default`` None every entry must name itself, as ``--group``'s do)."""
    paths = {}
    for entry in entries:
        name, sep, path = entry.partition("=")
        if not sep and default is None:
            raise ValueError(f"{flag} entry {entry!r} must be MEMBER=PATH")
        name, path = (name, path) if sep else (default, entry)
        if name in paths:
            raise ValueError(f"{flag} names {name!r} twice")
        paths[name] = Path(path)
    return paths


def _select(args, cfg, started) -> None:
    from .analysis.selection import select_seed
    from .io import atomic_path, write_text_atomic

    table, chosen = select_seed(args.episodes)
    if table["fallback"].any():
        print("efish: warning: no seed has a positive median intercept; ranked all seeds (fallback)", file=sys.stderr)
    with atomic_path(args.out / Path(RANKING).name) as tmp:
        table.to_parquet(tmp, index=False)
    write_text_atomic(args.out / Path(SELECTED_SEED).name, f"{chosen}\n")
    write_metadata(args.out, cfg, started, args, episodes=[str(p) for p in args.episodes])
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    print(f"selected seed {chosen}")


def _stack_seeds(args, cfg, started) -> None:
    from .analysis.selection import stack_top_seeds
    from .io import atomic_path, read_parquet

    table = stack_top_seeds(args.tables, read_parquet(args.ranking, "the seed ranking"))
    with atomic_path(args.out) as tmp:
        table.to_parquet(tmp, index=False)
    print(f"wrote {args.out} ({len(table)} rows, seeds {sorted(table['seed'].unique().tolist())})")


def _analyze(args, cfg, started) -> None:
    """One analysis of an assay's record (its rollout tables and recorded conditions) under the analysis settings
    of ``cfg``, which it writes beside the tables (``analysis_settings.parquet``) for the panels and claims."""
    from .analysis.registry import read_tables, run
    from .config.recorded import settings_table
    from .io import write_parquet_tables

    # everything is read before anything is written
    result = run(args.name, read_tables(args.name, args.tables), cfg.analysis)
    write_parquet_tables({**result, ANALYSIS_SETTINGS: settings_table(cfg.analysis)}, args.out)
    write_metadata(args.out, cfg, started, args, analysis=args.name, tables=str(args.tables))
    print(f"wrote {', '.join(f'{k}.parquet ({len(v)} rows)' for k, v in result.items())} and "
          f"{ANALYSIS_SETTINGS}.parquet to {args.out}")


def _scene(args, cfg, started) -> None:
    from .io import write_parquet_tables
    from .rollout.scenes import build_scene, compose_scene, to_arrow

    scene_cfg = compose_scene(args.name, args.overrides)
    if scene_cfg.scene.name != args.name:
        raise ValueError(f"config/scene/{args.name}.yaml names its scene {scene_cfg.scene.name!r}: they must agree")
    table = build_scene(scene_cfg, args.overrides)
    out = args.out or run_of(cfg, args.overrides).path(scene_table(args.name)).parent
    write_parquet_tables({args.name: to_arrow(table)}, out)
    # the folder holds every scene: one config (the run's) and one provenance per scene, with the scene resolved
    write_metadata(out, cfg, started, args, name=f"{args.name}.provenance.json", scene=args.name,
              scene_config=dataclasses.asdict(scene_cfg.scene))
    print(f"wrote {out / f'{args.name}.parquet'} ({len(table)} rows)")


def _figure(args, cfg, started) -> None:
    from .bench.figures import NAMES as BENCH_FIGURES
    from .bench.figures import redraw_bench_figure
    from .figures.registry import drawable, figures
    from .figures.render import render_figure, render_panel

    run = run_of(cfg, args.overrides)
    results = args.results or run.results
    out = args.out or run.figures
    if args.key.startswith(f"{BENCH}/"):
        drawn = {args.key: redraw_bench_figure(args.key.split("/", 1)[1], results, out / BENCH)}
    elif "/" in args.key:
        drawn = {args.key: render_panel(args.key, results, out, cfg.scale.seed_numbers())}
    else:  # a figure: each of its panels and its page, from one reading of the tables
        if args.key not in figures():
            raise ValueError(f"unknown figure {args.key!r}: choose one of {', '.join(figures())}, "
                             f"{', '.join(f'{BENCH}/{n}' for n in BENCH_FIGURES)}")
        panels = [p for p in drawable(cfg.scale) if p.figure == args.key]
        drawn = render_figure(args.key, panels, results, out, cfg.scale.seed_numbers())
    # one provenance per drawn output (a figure folder holds many panels), one config per folder
    for key, files in drawn.items():
        write_metadata(files[0].parent, cfg, started, args, name=f"{files[0].stem}.provenance.json", figure=key,
                  results=str(results))
    written = [path for files in drawn.values() for path in files]
    print("wrote " + ", ".join(map(str, written)))


def _render(args, cfg, started) -> None:
    from .figures.clip_file import clip_encoder
    from .figures.episode import load_episode, render_clip

    # assay= picks the tables, not the run: the default folders are the run's (results/smoke for scale=smoke)
    run = run_of(cfg, [o for o in args.overrides if not o.startswith("assay=")])
    tables = args.tables or run.path(assay_folder(cfg.assay.name))
    out = args.out or run.clip(cfg.assay.name)
    clip_encoder(out)  # a wrong suffix, or .mp4 without ffmpeg, fails before any table is read
    episode = load_episode(tables, args.overrides, cfg, args.condition, args.episode)
    frames = render_clip(episode, out, every=args.every, fps=args.fps, field=args.field,
                         progress=lambda rows: _progress(rows, "frames", unit="frame", every=max(1, len(rows) // 10)))
    write_metadata(out.parent, cfg, started, args, name=f"{out.stem}.provenance.json", tables=str(tables),
              condition=episode.condition, episode=episode.episode)
    print(f"wrote {out} ({frames} frames of {episode.assay}, condition {episode.condition}, "
          f"episode {episode.episode})")


def _contact_sheet(args, cfg, started) -> None:
    from .figures.contact_sheet import write_contact_sheet

    figures = args.figures or run_of(cfg, args.overrides).figures
    out = args.out or figures / CONTACT_SHEET
    drawn, absent = write_contact_sheet(figures, out)
    write_metadata(out.parent, cfg, started, args, name=f"{out.stem}.provenance.json", figures=str(figures))
    print(f"wrote {out} (panels drawn: {drawn}; not drawn at this scale: {absent})")


def _gallery(args, cfg, started) -> None:
    from .figures.gallery import gallery_folder, write_gallery

    # the page names the command that regenerates it: the run and the options that differ from their defaults
    given = {"--figures": (args.figures, FIGURES_ROOT / args.run), "--results": (args.results, RESULTS_ROOT / args.run),
             "--out": (args.out, None), "--max-width": (args.max_width, MAX_WIDTH_PX)}
    command = " ".join(["efish gallery", args.run, *(f"{flag} {value}" for flag, (value, default) in given.items()
                                                     if value is not None and value != default)])
    out = gallery_folder(args.run, args.figures, args.out)
    drawn, absent = write_gallery(args.run, args.figures, args.results, out, args.max_width, command)
    print(f"wrote {out / 'index.md'} and its images (panels drawn: {drawn}; not drawn in this run: {absent})")


def _plan_cluster(args, cfg, started) -> None:
    from .bench.cluster import format_plan, plan_cluster, suggested_resources

    text = args.dry_run.read_text() if args.dry_run else None
    checked = plan_cluster(args.overrides, args.source, args.results or Run(args.source).results, args.profile, text)
    print(checked.to_json(orient="records", indent=1) if args.json else format_plan(checked))
    if args.suggest:
        import yaml

        print(yaml.safe_dump({"set-resources": suggested_resources(checked)}, sort_keys=True), end="")


def _config(args, cfg, started) -> None:
    print(to_yaml(cfg), end="")


def _schema(args, cfg, started) -> None:
    from .rollout.schema import describe

    print(describe(args.table))


def _plan(args, cfg, started) -> None:
    from .env.vec_env import scene_of
    from .physics.plan import build_plan

    print(build_plan(cfg, scene_of(cfg)).explain())


def _stderr(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def _with_bench(cfg, **flags):
    """``cfg`` with the ``bench.*`` fields a bench command's flags set (a flag left out, None, keeps the config's),
    so the config.yaml written beside an output records what ran."""
    changes = {k: v for k, v in flags.items() if v is not None}
    return dataclasses.replace(cfg, bench=dataclasses.replace(cfg.bench, **changes)) if changes else cfg


def _bench_physics(args, cfg, started) -> None:
    from .bench.physics import bench_physics, format_physics
    from .io import write_text_atomic

    result = bench_physics(cfg)
    print(json.dumps(result, indent=2) if args.json else format_physics(result))
    if args.out:
        write_text_atomic(args.out / "bench_physics.json", json.dumps(result, indent=2) + "\n")
        write_metadata(args.out, cfg, started, args)


def _bench_env(args, cfg, started) -> None:
    from .bench.env import bench_env, format_env

    rows = bench_env(_with_bench(cfg, env_envs=args.envs, env_steps=args.steps))
    print(json.dumps(rows, indent=2) if args.json else format_env(rows))


def _bench_train(args, cfg, started) -> None:
    from .bench.train import bench_train, format_train
    from .rl.compute import pick_device

    if args.device:
        cfg = dataclasses.replace(cfg, train=dataclasses.replace(cfg.train, device=pick_device(args.device)))
    rows = bench_train(_with_bench(cfg, train_hidden=args.hidden), progress=lambda line: _stderr(f"bench train: {line}"))
    print(json.dumps(rows, indent=2) if args.json else format_train(rows))


def _bench_group(args, cfg, started) -> None:
    from .bench.group import bench_group, format_group

    rows = bench_group(_with_bench(cfg, group_sizes=args.sizes, group_episodes=args.episodes,
                                   group_steps=args.steps), args.overrides)
    print(json.dumps(rows, indent=2) if args.json else format_group(rows))


def _bench_budget(args, cfg, started) -> None:
    from .bench.budget import bench_budget, budget_sizes, format_budget
    from .io import atomic_path

    cfg = _with_bench(cfg, budget_minutes=args.minutes, budget_hidden=args.hidden, budget_seeds=args.seeds,
                      budget_jobs=args.jobs)
    hiddens, seeds, minutes, jobs = budget_sizes(cfg)  # checked before announcing the runs
    runs = len(hiddens) * seeds
    _stderr(f"bench budget: {runs} runs of {minutes:g} min, {jobs} at a time: about "
            f"{minutes * -(-runs // jobs):.0f} min")
    table = bench_budget(cfg, progress=lambda run: _stderr(f"budget: {run} done"))
    if args.out:
        with atomic_path(args.out / "bench_budget.parquet") as tmp:
            table.to_parquet(tmp, index=False)
        write_metadata(args.out, cfg, started, args, name="bench_budget.provenance.json")
    print(format_budget(table))


def _bench_pipeline(args, cfg, started) -> None:
    from .bench.pipeline import format_timings, pipeline_timings

    table = pipeline_timings(args.results or run_of(cfg, args.overrides).results)
    print(table.to_json(orient="records", indent=1) if args.json else format_timings(table))


def _bench_multipole(args, cfg, started) -> None:
    from .bench.multipole import bench_multipole, format_multipole

    table = bench_multipole(_with_bench(cfg, multipole_orders=args.orders, multipole_width_cm=args.width))
    print(table.to_json(orient="records", indent=1) if args.json else format_multipole(table))


def _bench_with_figure(name: str, df, args, cfg, started) -> tuple[Path, list[Path]]:
    """Write a benchmark's table (+ config, provenance) to ``--out`` and its figure (PNG, PDF, each with config and
    provenance) to ``--figures``, by default the run's ``results/<run>/bench`` and ``figures/<run>/bench``."""
    from .bench.figures import draw_bench_figure, stem
    from .io import atomic_path

    run = run_of(cfg, args.overrides)
    out, figures = args.out or run.bench, args.figures or run.bench_figures
    table = out / f"{stem(name)}.parquet"
    with atomic_path(table) as tmp:
        df.to_parquet(tmp, index=False)
    write_metadata(out, cfg, started, args, name=f"{stem(name)}.provenance.json")
    written = draw_bench_figure(name, df, figures)
    write_metadata(figures, cfg, started, args, name=f"{stem(name)}.provenance.json", table=str(table))
    return table, written


def _bench_accuracy(args, cfg, started) -> None:
    from .bench.accuracy import bench_accuracy

    df = bench_accuracy(cfg, progress=lambda s: _progress(s, "accuracy"))
    table, figures = _bench_with_figure("accuracy", df, args, cfg, started)
    if args.json:
        print(df.to_json(orient="records", indent=1))
    else:
        cols = ["tolerance", "image_order", "dtype", "softening_m", "us_per_agent_step", "max_abs_error",
                "threshold_cross_fraction"]
        print(df[cols].to_string(index=False, float_format=lambda v: f"{v:.3g}"))
        print(f"wrote {table} and {', '.join(map(str, figures))}")


def _bench_scaling(args, cfg, started) -> None:
    from .bench.scaling import bench_scaling, format_scaling

    df = bench_scaling(cfg, progress=lambda c: _progress(c, "scaling", unit="case"))
    table, figures = _bench_with_figure("scaling", df, args, cfg, started)
    print(df.to_json(orient="records", indent=1) if args.json else format_scaling(df))
    if not args.json:
        print(f"wrote {table} and {', '.join(map(str, figures))}")


# The recipe (config/policy/) that ``efish train`` and the benches timing training compose before the user's
# overrides: the paper's sampled training arenas, which the default assay's fixed arena would otherwise replace.
TRAINING_RECIPE = "foraging"


def _recipe_override(args: argparse.Namespace) -> list[str]:
    """``policy=<recipe>`` for the commands that train (a ``policy=`` or ``arena=`` of the user's still wins)."""
    return [f"policy={args.recipe}"] if getattr(args, "recipe", None) else []


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``efish`` console script: parse, compose the overrides (commands that take them), call the
    command's handler; an error is one line on stderr and exit code 2."""
    args = _parser().parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="efish: %(message)s", stream=sys.stderr)
    started = datetime.now(timezone.utc)
    try:
        # a command's Hydra overrides are a list; compare-claims' and compare-runs' --overrides is a sweep's string
        composes = isinstance(getattr(args, "overrides", None), list)
        cfg = compose([*_recipe_override(args), *args.overrides]) if composes else None
        args.handler(args, cfg, started)
    except (ConfigError, ValueError, OSError) as exc:
        print(f"efish: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
