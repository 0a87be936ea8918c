"""The claims commands of ``efish``: ``claims`` (a run's verdicts, with the other top seeds' and the trends along
training), ``claims-by-stage`` (the claims at the kept training stages), ``compare-claims`` (two runs side by
side) and ``power`` (what a decisive verdict would cost). Their parsers are in :mod:`efish.cli`."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from .cli_support import run_at, run_of, write_metadata
from .layout import (
    CLAIM_PARTS,
    CLAIMS_BY_STAGE,
    CLAIMS_BY_STAGE_FIGURE,
    CLAIMS_PAGE,
    CLAIMS_TABLE,
    CLAIMS_TRENDS,
    CLAIMS_TRENDS_PAGE,
    POWER_CLAIMS,
    POWER_CURVES,
    POWER_FIGURE,
    POWER_PAGE,
    POWER_TABLE,
    RANKING,
    RECIPE_PARTS,
)


def run_claims(args, cfg, started) -> None:
    from . import claims
    from .claims.report import claims_markdown
    from .claims.stages import trend_lines
    from .io import read_parquet, write_parquet_tables, write_text_atomic

    results = args.results or run_of(cfg, args.overrides).results
    if not results.is_dir():
        raise ValueError(f"results folder {results} does not exist")
    out = args.out or (results / CLAIMS_TABLE).parent
    seeds = _seed_claims(args, results)  # read before anything is computed or written
    trends = None if args.trends is None else trend_lines(read_parquet(args.trends, "the claims' trends table"))
    table, parts = claims.claims_and_parts(results, cfg)
    header = (f"Claims of the paper at scale {cfg.scale.name} (run {results.name}), "
              f"{started.strftime('%Y-%m-%d %H:%M UTC')}")
    written = {Path(CLAIM_PARTS).stem: parts}
    if seeds is not None:
        from .claims.recipe import recipe_parts, with_recipe_verdicts
        from .claims.seeds import with_seed_verdicts

        selected, others, other_parts = seeds
        table = with_seed_verdicts(table, others, selected)
        recipe = recipe_parts({selected: parts, **other_parts}, selected, cfg.analysis.claims_alpha)
        table = with_recipe_verdicts(table, recipe, cfg.analysis.claims_alpha)
        written[Path(RECIPE_PARTS).stem] = recipe
        header += f"; selected seed {selected}" + (f", other top seeds {', '.join(map(str, others))}" if others else "")
    table_path, page_path = out / Path(CLAIMS_TABLE).name, out / Path(CLAIMS_PAGE).name
    write_parquet_tables({table_path.stem: table, **written}, out)
    write_text_atomic(page_path, claims_markdown(table, header, trends))
    write_metadata(out, cfg, started, args, results=str(results),
              **({} if seeds is None else {"selected_seed": seeds[0], "other_seeds": list(seeds[1])}),
              **({} if args.trends is None else {"trends": str(args.trends)}))
    shown = ["claim", "panel", *["recipe_verdict"] * ("recipe_verdict" in table.columns), "effect", "ci_low",
             "ci_high", "n", "p", "verdict"]
    print(table[shown + ["seeds_agree"] * ("seeds_agree" in table.columns)].to_string(
        index=False, float_format=lambda v: f"{v:.3g}"))
    print(f"wrote {table_path}, {', '.join(str(out / f'{name}.parquet') for name in written)} and {page_path}")


def run_power(args, cfg, started) -> None:
    """``efish power``: the planner's table, its curves, page and figure for a finished run
    (:mod:`efish.claims.planner`)."""
    import pandas as pd

    from .bench.timing import machine, machine_line
    from .claims.planner import part_models, plan_table, power_curves, read_run, with_stages
    from .claims.power_page import CLAIM_SUMMARY_COLUMNS, claim_summary, headline, power_markdown
    from .claims.report import recorded_alpha, recorded_setting
    from .figures.power import plot_power
    from .io import read_parquet, write_parquet_tables, write_text_atomic
    from .layout import Run

    if args.run is not None and args.results is not None:
        raise ValueError(f"give the run once: {args.run} or --results {args.results}")
    run = run_of(cfg, args.overrides) if args.run is None else run_at(args.run)
    if args.results is not None:
        run = Run(args.results.name, results_root=args.results.parent)
    # the alpha the run's claims were decided at (the config.yaml efish claims wrote beside them), else the config's
    alpha = recorded_alpha(run.path(CLAIMS_TABLE)) or cfg.analysis.claims_alpha
    # the episodes per condition of the selected seed and of the other top seeds' reruns, recorded there too
    episodes, rerun = (recorded_setting(run.path(CLAIMS_TABLE), "scale", key) or getattr(cfg.scale, key)
                       for key in ("max_episodes", "top_seed_episodes"))
    tables, costs = read_run(run, alpha, (episodes, min(rerun, episodes)))  # all read before anything is written
    claims = (read_parquet(run.path(CLAIMS_TABLE), "the run's claims table")
              if run.path(CLAIMS_TABLE).is_file() else None)
    recipe = (read_parquet(run.path(RECIPE_PARTS), "the recipe's parts table")
              if run.path(RECIPE_PARTS).is_file() else None)
    out = args.out or run.path(POWER_TABLE).parent
    figures = args.figures or (run.figures / POWER_FIGURE).parent
    models = part_models(tables, alpha)
    plan = plan_table(models, alpha, costs)
    if run.path(CLAIMS_BY_STAGE).is_file() and run.path(CLAIMS_TRENDS).is_file():  # the run kept stages
        plan = with_stages(plan, read_parquet(run.path(CLAIMS_BY_STAGE), "the claims along training"),
                           read_parquet(run.path(CLAIMS_TRENDS), "the claims' trends"))
    curves = power_curves(models, alpha, costs)
    summary = (claim_summary(plan, claims, recipe, costs) if claims is not None and recipe is not None
               else pd.DataFrame(columns=CLAIM_SUMMARY_COLUMNS))
    seeds = ", ".join(map(str, tables))
    scale = recorded_setting(run.path(CLAIMS_TABLE), "scale", "name", str) or cfg.scale.name  # a run given by folder
    header = (f"Run {run.name} at scale {scale}, seeds {seeds} (the selected seed first), "
              f"{started.strftime('%Y-%m-%d %H:%M UTC')}; {machine_line(machine())}.")
    written = write_parquet_tables({Path(POWER_TABLE).stem: plan, Path(POWER_CURVES).stem: curves,
                                    Path(POWER_CLAIMS).stem: summary}, out)
    page = out / Path(POWER_PAGE).name
    write_text_atomic(page, power_markdown(plan, costs, header, alpha, summary if len(summary) else None))
    drawn = plot_power(curves, plan, figures / Path(POWER_FIGURE).name,
                       f"What a decisive verdict costs: run {run.name}, seeds {seeds}")
    write_metadata(out, cfg, started, args, name="power.provenance.json", results=str(run.results),
                   seeds=list(tables), costs=costs._asdict())
    write_metadata(figures, cfg, started, args, name="power.provenance.json", table=str(written[0]))
    print("\n".join(summary["line"]))
    print(headline(plan, costs))
    print(f"wrote {', '.join(map(str, [*written, page, *drawn]))}")


def _seed_claims(args, results: Path):
    """(selected seed, {other seed: its claims table}, {other seed: its claim_parts table, read beside it}), the
    seeds in ranking order, from --ranking and --seed-claims; None when neither is given (the table keeps the
    columns of ROW_COLUMNS)."""
    from .io import read_parquet

    if args.seed_claims is None and args.ranking is None:
        return None
    ranking_path = args.ranking or results / RANKING
    if not ranking_path.is_file():
        raise ValueError(f"no seed ranking at {ranking_path}: --seed-claims needs --ranking (its first row is the "
                         "selected seed)")
    ranking = [int(s) for s in read_parquet(ranking_path, "the seed ranking")["seed"]]
    if not ranking:
        raise ValueError(f"the seed ranking {ranking_path} has no seed")
    paths = {seed: Path(path) for seed, path in _keyed(
        args.seed_claims, "--seed-claims", "SEED", "PATH", "3=results/laptop/seeds/seed_3/claims/claims.parquet").items()}
    if unknown := sorted(set(paths) - set(ranking)):
        raise ValueError(f"--seed-claims: seeds {unknown} are not in the ranking {ranking_path} "
                         f"(seeds {', '.join(map(str, ranking))})")
    ordered = sorted(paths, key=ranking.index)
    parts = {s: paths[s].with_name(Path(CLAIM_PARTS).name) for s in ordered}
    if lacking := [str(p) for p in parts.values() if not p.is_file()]:
        raise ValueError(f"--seed-claims: {', '.join(lacking)} does not exist (efish claims writes "
                         f"{Path(CLAIM_PARTS).name} beside claims.parquet; rerun it for those seeds)")
    return (ranking[0], {s: read_parquet(paths[s], f"seed {s}'s claims table") for s in ordered},
            {s: read_parquet(parts[s], f"seed {s}'s parts table") for s in ordered})


def _keyed(items: Sequence[str] | None, flag: str, key: str, value: str, example: str) -> dict[int, str]:
    """A flag's ``KEY=VALUE`` entries by integer key (a seed, a stage), in the order given: one line of error for
    an entry without ``=``, a key that is no whole number, or a key given twice."""
    found = {}
    for item in items or []:
        k, sep, v = item.partition("=")
        if not (sep and k.strip().isdigit() and v):
            raise ValueError(f"{flag} {item!r}: write {key}={value}, e.g. {example}")
        if int(k) in found:
            raise ValueError(f"{flag} names {key.lower()} {int(k)} twice")
        found[int(k)] = v
    return found


def _stage_counts(items: Sequence[str] | None, flag: str) -> dict[int, int]:
    """``--env-steps`` / ``--episodes``: ``K=N`` entries, N a whole number."""
    counts = _keyed(items, flag, "K", "N", "1=250000")
    if bad := [f"{k}={v}" for k, v in counts.items() if not v.strip().isdigit()]:
        raise ValueError(f"{flag} {', '.join(bad)}: N must be a whole number, e.g. 1=250000")
    return {k: int(v) for k, v in counts.items()}


def _stage_env_steps(items: Sequence[str]) -> dict[int, int]:
    """``--stage-policies``: the env steps each stage file records (train.keep_stages)."""
    from .rl.policy import read_stage

    return {k: int(read_stage(path)["env_steps"])
            for k, path in _keyed(items, "--stage-policies", "K", "PATH", "1=results/study/train/seed_3/stage_1.pt").items()}


def _read_stage(k: int, where: Path):
    """(path, table) of stage ``k``'s parts table, from its claim_parts.parquet, its claims folder or its results
    folder."""
    from .io import read_parquet

    candidates = [where, where / Path(CLAIM_PARTS).name, where / CLAIM_PARTS]
    path = next((c for c in candidates if c.is_file()), None)
    if path is None:
        raise ValueError(f"--stages {k}: no parts table at {', '.join(map(str, candidates))} (run efish claims "
                         "there first)")
    return path, read_parquet(path, f"stage {k}'s parts table")


def run_claims_by_stage(args, cfg, started) -> None:
    from .claims.report import claims_markdown
    from .claims.stages import claims_by_stage, stage_trends, trend_lines
    from .figures.learning import plot_claims_by_stage
    from .io import read_parquet, write_parquet_tables, write_text_atomic

    run = run_of(cfg, args.overrides)
    out = args.out or run.path(CLAIMS_BY_STAGE).parent
    figures = args.figures or (run.figures / CLAIMS_BY_STAGE_FIGURE).parent
    read = {k: _read_stage(k, Path(p)) for k, p in _keyed(args.stages, "--stages", "K", "PATH",
                                                           "1=results/laptop/learning/stage_1").items()}
    env_steps = (_stage_counts(args.env_steps, "--env-steps") if args.env_steps is not None
                 else _stage_env_steps(args.stage_policies))
    episodes = _stage_counts(args.episodes, "--episodes")
    final = read_parquet(args.claims, "the run's claims table") if args.claims is not None else None
    stacked = claims_by_stage({k: table for k, (_, table) in read.items()}, env_steps, episodes or None)
    trends = stage_trends(stacked, cfg.analysis.claims_trend_alpha, cfg.analysis.claims_alpha)
    drawn = plot_claims_by_stage(stacked, figures / Path(CLAIMS_BY_STAGE_FIGURE).name, trends)
    tables = write_parquet_tables({Path(CLAIMS_BY_STAGE).stem: stacked, Path(CLAIMS_TRENDS).stem: trends}, out)
    if final is not None:
        header = (f"Claims of the paper at scale {cfg.scale.name} (run {run.name}), the selected seed's final policy, "
                  f"with each claim's trend over {len(env_steps)} training stages, {started.strftime('%Y-%m-%d %H:%M UTC')}")
        tables.append(out / Path(CLAIMS_TRENDS_PAGE).name)
        write_text_atomic(tables[-1], claims_markdown(final, header, trend_lines(trends)))
    inputs = {"stages": {str(k): str(path) for k, (path, _) in read.items()},
              "env_steps": {str(k): n for k, n in env_steps.items()},
              "episodes": {str(k): n for k, n in episodes.items()}}
    write_metadata(out, cfg, started, args, name="claims_by_stage.provenance.json", **inputs)
    write_metadata(figures, cfg, started, args, name="claims_by_stage.provenance.json", table=str(tables[0]))
    print("\n".join(trend_lines(trends).values()))
    print(f"wrote {', '.join(map(str, tables + drawn))}")


def run_compare_claims(args, cfg, started) -> None:
    """Two runs side by side as before; with ``--out`` or ``--heatmap`` (or more than two runs) also the claims x
    runs table (:mod:`efish.claims.grid`)."""
    from .claims.grid import TABLE_SUFFIXES, claims_grid, write_table
    from .claims.report import agreement_lines, compare_claims, load_claims
    from .figures.claims_grid import draw_heatmap

    swept = _sweep_points(args) if args.sweep else []
    wanted = [*args.runs, *(run for run, _ in swept)]
    if len(wanted) < 2:
        raise ValueError(f"compare-claims needs two or more runs, got {len(wanted)}: name them or give --sweep")
    if args.out and args.out.suffix not in TABLE_SUFFIXES:
        raise ValueError(f"--out {args.out}: the table is written as {' or '.join(TABLE_SUFFIXES)}")
    loaded = [load_claims(run, args.results) for run in wanted]  # every table read before anything is written
    labels = [name for name, _ in loaded[:len(args.runs)]] + [label for _, label in swept]  # a point by its values
    names = [name if labels.count(name) == 1 else f"{name} ({i + 1})"
             for i, name in enumerate(labels)]  # two folders of one name (two results roots) stay apart
    tables = dict(zip(names, (table for _, table in loaded), strict=True))
    grid = claims_grid(tables) if len(loaded) > 2 or args.out or args.heatmap else None
    if swept:
        print("\n".join(f"{label}: {run}" for run, label in swept))
    if len(loaded) == 2:
        (name_a, name_b), (a, b) = names, tables.values()
        print(compare_claims(a, b, (name_a, name_b)).to_string(index=False))
        print("\n".join(agreement_lines(a, b, (name_a, name_b))))
    else:
        print(grid.to_string(index=False))
    if args.out:
        write_table(grid, args.out)
        print(f"wrote {args.out}")
    if args.heatmap:
        draw_heatmap(grid, list(tables), args.heatmap)
        print(f"wrote {args.heatmap}")


def _sweep_points(args) -> list[tuple[str, str]]:
    """(run folder, label) of each point of ``--sweep`` at ``--scale`` with ``--overrides``, in grid order (as the
    workflow names them; the label is the point's values, :func:`efish.sweep.sweep_points`)."""
    import shlex

    from .run_plan import DEFAULT_SCALE, PlanError
    from .sweep import sweep_points

    try:
        return sweep_points(args.scale or DEFAULT_SCALE, shlex.split(args.overrides), args.sweep)
    except PlanError as exc:
        raise ValueError(str(exc)) from None


def _sweep_runs(args) -> list[str]:
    """The run folders of ``--sweep`` (:func:`_sweep_points` without the labels)."""
    return [run for run, _ in _sweep_points(args)]
