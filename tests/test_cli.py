"""The ``efish`` command's own logic: the training log line; ``efish claims`` with the other top seeds' claims tables
(seed_verdicts, seeds_agree), its parts table and the trends along training; ``efish claims-by-stage``; ``efish
compare-claims`` showing seeds_agree."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from efish.claims.recipe import RECIPE_COLUMNS, RECIPE_PART_COLUMNS
from efish.claims.verdicts import PART_COLUMNS, ROW_COLUMNS
from efish.cli import ReturnLog, _parser, _recipe_override, main

from .claims.test_claims_stages import STEPS, stage_parts


def test_the_training_log_never_prints_nan():
    log = ReturnLog()
    assert log.line({"episode_return": math.nan, "episodes_ended": 0}) == "no episode ended yet"
    assert log.line({"episode_return": 12.5, "episodes_ended": 3}) == "return 12.500 (3 episodes)"
    assert log.line({"episode_return": math.nan, "episodes_ended": 0}) == "no episode ended since the last line"
    assert "nan" not in log.line({"episode_return": -1.0, "episodes_ended": 1})


# ------------------------------------------------- efish claims across seeds
def claims_rows(verdicts: dict[str, str]) -> pd.DataFrame:
    """A claims table (ROW_COLUMNS) with the given verdict per claim."""
    n = len(verdicts)
    return pd.DataFrame({"claim": list(verdicts), "panel": ["3O"] * n, "statistic": ["Spearman rho"] * n,
                         "effect": [0.4] * n, "ci_low": [0.1] * n, "ci_high": [0.7] * n, "n": [8] * n,
                         "p": [0.01] * n, "verdict": list(verdicts.values()),
                         "parts": [f"1 {v}" for v in verdicts.values()], "reason": [""] * n}, columns=ROW_COLUMNS)


@pytest.fixture
def seed_run(tmp_path, monkeypatch):
    """A run folder with a ranking (seed 3 selected, then 1 and 7) and the claims tables of seeds 1 and 7; the
    selected seed's claims are a fixed table and its parts one row per claim (claims_and_parts is replaced: these
    tests are about the CLI)."""
    from efish import claims

    def fixed(results, cfg):
        table = claims_rows({"C1": "holds", "C9": "holds"})
        return table, parts_rows(table)

    monkeypatch.setattr(claims, "claims_and_parts", fixed)
    run = tmp_path / "results" / "myrun"
    (run / "analysis" / "selection").mkdir(parents=True)
    pd.DataFrame({"seed": [3, 1, 7, 2]}).to_parquet(run / "analysis" / "selection" / "ranking.parquet")
    for seed, verdicts, effect in ((1, {"C1": "not run", "C9": "inconclusive"}, 0.2), (7, {"C1": "not run", "C9": "holds"},
                                                                                 0.5)):
        folder = run / "seeds" / f"seed_{seed}" / "claims"
        folder.mkdir(parents=True)
        table = claims_rows(verdicts).assign(effect=effect)
        table.to_parquet(folder / "claims.parquet")
        parts_rows(table).to_parquet(folder / "claim_parts.parquet")
    return run


def parts_rows(table: pd.DataFrame) -> pd.DataFrame:
    """A parts table (PART_COLUMNS) with one part per claim of a claims table (CLI tests), decided against a delta
    of 0.2."""
    parts = table.rename(columns={"panel": "part"}).assign(sign=1.0, decides=True, ci_method="", family=1,
                                                           p_floor=0.0, reference=float("nan"), delta=0.2,
                                                           p_opposite=1.0)
    return parts[PART_COLUMNS]


def seed_table(run, seed: int) -> str:
    return f"{seed}={run / 'seeds' / f'seed_{seed}' / 'claims' / 'claims.parquet'}"


def test_efish_claims_adds_the_verdicts_of_the_other_top_seeds(seed_run, capsys):
    out = seed_run / "claims"
    assert main(["claims", "scale=smoke", "--results", str(seed_run), "--out", str(out),
                 "--ranking", str(seed_run / "analysis/selection/ranking.parquet"),
                 "--seed-claims", seed_table(seed_run, 7), seed_table(seed_run, 1)]) == 0
    table = pd.read_parquet(out / "claims.parquet").set_index("claim")
    assert list(table.reset_index().columns) == [*ROW_COLUMNS[:2], *RECIPE_COLUMNS, *ROW_COLUMNS[2:-1],
                                                 "seed_verdicts", "seeds_agree", "reason"]
    # the recipe: C9's effects 0.4 (seed 3), 0.2 and 0.5 over three seeds (t = 4.2, 2 df, p = 0.053); the 0.9 t
    # interval [0.11, 0.62] straddles delta 0.2
    assert table.loc["C9", "recipe_seeds"] == 3 and table.loc["C9", "recipe_effect"] == pytest.approx(1.1 / 3)
    assert table.loc["C9", "recipe_verdict"] == "inconclusive"
    assert table.loc["C9", "recipe_p"] == pytest.approx(0.053, abs=1e-3)
    assert table.loc["C9", "recipe_ci_low"] == pytest.approx(0.109, abs=1e-3)
    # C1 ran at the selected seed alone (as the homing claims do): one draw, said so
    assert table.loc["C1", "recipe_verdict"] == "holds" and table.loc["C1", "recipe_seeds"] == 1
    assert "one draw" in table.loc["C1", "recipe_reason"]
    recipe = pd.read_parquet(out / "recipe_parts.parquet")
    assert list(recipe.columns) == RECIPE_PART_COLUMNS and recipe["seeds"].tolist() == ["3", "3, 1, 7"]
    assert table.loc["C9", "seed_verdicts"] == "seed 3: holds; seed 1: inconclusive; seed 7: holds"  # ranking order
    assert table.loc["C9", "seeds_agree"] == "2/3 hold, 1/3 inconclusive"
    assert "flips between seeds" in table.loc["C9", "reason"]
    assert table.loc["C1", "seeds_agree"] == "1/1 hold (other seeds: not run)"
    page = (out / "claims.md").read_text()
    assert "| selected seed's verdict | selected seed's parts | seeds_agree | reason | recipe reason |" in page
    assert "| holds | 1 holds | 2/3 hold, 1/3 inconclusive |" in page
    assert "| C9 | 3O | inconclusive | 1 inconclusive | 0.367 [" in page
    assert "The recipe (its top seeds together): 1 holds, 1 inconclusive. The selected seed: 2 holds." in page
    assert "selected seed 3, other top seeds 1, 7" in page.splitlines()[0]
    assert "seeds_agree" in capsys.readouterr().out


def test_efish_claims_reads_the_runs_ranking_by_default_and_alone_gives_the_selected_seed(seed_run):
    assert main(["claims", "scale=smoke", "--results", str(seed_run), "--seed-claims", seed_table(seed_run, 1)]) == 0
    table = pd.read_parquet(seed_run / "claims" / "claims.parquet").set_index("claim")
    assert table.loc["C9", "seed_verdicts"] == "seed 3: holds; seed 1: inconclusive"
    assert main(["claims", "scale=smoke", "--results", str(seed_run), "--seed-claims"]) == 0  # no other seed
    assert pd.read_parquet(seed_run / "claims" / "claims.parquet")["seeds_agree"].tolist() == ["1/1 hold"] * 2


def test_efish_claims_without_seed_tables_keeps_its_columns(seed_run):
    assert main(["claims", "scale=smoke", "--results", str(seed_run)]) == 0
    assert list(pd.read_parquet(seed_run / "claims" / "claims.parquet").columns) == ROW_COLUMNS
    assert "seeds_agree" not in (seed_run / "claims" / "claims.md").read_text()


@pytest.mark.parametrize("seed_args, message", [
    (["9=x.parquet"], "seeds [9] are not in the ranking"),
    (["one=x.parquet"], "write SEED=PATH"),
    (["--ranking", "nowhere.parquet", "--seed-claims", "1=x.parquet"], "no seed ranking at nowhere.parquet"),
    (["3=SELF"], "seed 3 is the selected seed"),
    (["2=NOPARTS"], "claim_parts.parquet does not exist"),
])
def test_efish_claims_refuses_bad_seed_tables_in_one_line_and_writes_nothing(seed_run, capsys, seed_args, message):
    seed_args = [a.replace("SELF", str(seed_run / "seeds/seed_1/claims/claims.parquet")) for a in seed_args]
    if "2=NOPARTS" in seed_args:  # a seed's claims table without its parts table beside it
        (seed_run / "seeds/seed_2/claims").mkdir(parents=True)
        claims_rows({"C1": "holds"}).to_parquet(seed_run / "seeds/seed_2/claims/claims.parquet")
        seed_args = [f"2={seed_run / 'seeds/seed_2/claims/claims.parquet'}"]
    args = seed_args if seed_args[0].startswith("--") else ["--seed-claims", *seed_args]
    assert main(["claims", "scale=smoke", "--results", str(seed_run), *args]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (seed_run / "claims").exists()


def test_efish_claims_writes_the_parts_table_and_the_trends_along_training(seed_run, tmp_path):
    trends = tmp_path / "claims_trends.parquet"
    assert main(["claims-by-stage", "scale=smoke", *stage_args(tmp_path), "--out", str(tmp_path / "learning"),
                 "--figures", str(tmp_path / "figures")]) == 0
    (tmp_path / "learning" / "claims_trends.parquet").rename(trends)
    assert main(["claims", "scale=smoke", "--results", str(seed_run), "--trends", str(trends)]) == 0
    parts = pd.read_parquet(seed_run / "claims" / "claim_parts.parquet")
    assert list(parts.columns) == PART_COLUMNS and parts["claim"].tolist() == ["C1", "C9"]
    page = (seed_run / "claims" / "claims.md").read_text()
    assert "\n## Along training\n" in page and "- C3 (alignment): moving toward the paper's sign (WLS slope" in page
    assert main(["claims", "scale=smoke", "--results", str(seed_run), "--trends", str(tmp_path / "none.parquet")]) == 2


# ------------------------------------------------- efish claims-by-stage
def stage_args(tmp_path, env_steps=STEPS) -> list[str]:
    """--stages and --env-steps of four stages' parts tables: C3 growing in the paper's sign, C9 flat; stage 1 as a
    claims folder, the others as files."""
    tables = stage_parts({("C3", "alignment"): (-1, [-0.1, -0.2, -0.3, -0.4]), ("C9", "bites"): (+1, [0.3] * 4)})
    paths = []
    for k, table in tables.items():
        folder = tmp_path / f"stage_{k}" / "claims"
        folder.mkdir(parents=True)
        table.to_parquet(folder / "claim_parts.parquet")
        paths.append(f"{k}={folder if k == 1 else folder / 'claim_parts.parquet'}")
    return ["--stages", *paths, "--env-steps", *(f"{k}={n}" for k, n in env_steps.items())]


def test_efish_claims_by_stage_writes_the_stacked_table_the_trends_and_the_figure(tmp_path, capsys):
    out, figures = tmp_path / "learning", tmp_path / "figures"
    assert main(["claims-by-stage", "scale=smoke", *stage_args(tmp_path), "--episodes", "1=2", "2=4", "3=4", "4=4",
                 "--out", str(out), "--figures", str(figures)]) == 0
    stacked = pd.read_parquet(out / "claims_by_stage.parquet")
    assert len(stacked) == 8 and stacked["episodes"].tolist()[:4] == [2, 4, 4, 4]
    trends = pd.read_parquet(out / "claims_trends.parquet").set_index("claim")
    assert trends.loc["C3", "trend"] == "moving toward the paper's sign" and trends.loc["C9", "trend"] == "stable"
    assert {"config.yaml", "claims_by_stage.provenance.json"} <= {p.name for p in out.iterdir()}
    for group in ("fig2", "fig3", "fig4", "fig5", "fig6"):  # one figure per figure of the paper's claims
        assert (figures / f"claims_by_stage_{group}.png").is_file() and (figures / f"claims_by_stage_{group}.pdf").is_file()
    text = capsys.readouterr().out
    assert text.startswith("C3 (alignment): moving toward the paper's sign") and "claims_by_stage_fig3.png" in text


def test_efish_claims_by_stage_reads_env_steps_from_the_stage_files_and_writes_the_claims_page(tmp_path):
    """--stage-policies: each stage file's record gives its env steps; --claims: claims.md beside the tables is the
    final policy's claims with one line per claim along training."""
    import torch

    args = stage_args(tmp_path)
    policies = []
    for k, n in STEPS.items():
        torch.save({"stage": {"k": k, "fraction": k / 4, "update": k, "env_steps": n, "total_updates": 4}},
                   tmp_path / f"stage_{k}.pt")
        policies.append(f"{k}={tmp_path / f'stage_{k}.pt'}")
    claims_rows({"C3": "inconclusive", "C9": "holds"}).to_parquet(tmp_path / "claims.parquet")
    out = tmp_path / "learning"
    assert main(["claims-by-stage", "scale=smoke", *args[:args.index("--env-steps")], "--stage-policies", *policies,
                 "--claims", str(tmp_path / "claims.parquet"), "--out", str(out),
                 "--figures", str(tmp_path / "figures")]) == 0
    stacked = pd.read_parquet(out / "claims_by_stage.parquet")
    assert stacked.groupby("stage")["env_steps"].first().to_dict() == STEPS
    page = (out / "claims.md").read_text()
    assert "\n## Along training\n" in page and "- C3 (alignment): moving toward the paper's sign" in page
    with pytest.raises(SystemExit):  # one or the other
        main(["claims-by-stage", "scale=smoke", *args, "--stage-policies", *policies])


@pytest.mark.parametrize("change, message", [
    (lambda a: ["1=x" if x == "1=25000" else x for x in a], "--env-steps 1=x: N must be a whole number"),
    (lambda a: [x for x in a if x != "4=100000"], "no env steps for stages [4]"),
    (lambda a: [x.replace("stage_2", "stage_9") for x in a], "--stages 2: no parts table at"),
    (lambda a: [*a[:2], a[1], *a[2:]], "--stages names k 1 twice"),
    (lambda a: [*a[:a.index("--env-steps")], "--stage-policies", "1=nowhere.pt"], "no stage file at nowhere.pt"),
    (lambda a: [*a, "--claims", "nowhere.parquet"], "nowhere.parquet"),
])
def test_efish_claims_by_stage_refuses_bad_stages_in_one_line_and_writes_nothing(tmp_path, capsys, change, message):
    args = stage_args(tmp_path)
    assert main(["claims-by-stage", "scale=smoke", *change(args), "--out", str(tmp_path / "out"),
                 "--figures", str(tmp_path / "fig")]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists() and not (tmp_path / "fig").exists()


def test_compare_claims_shows_each_runs_seeds_agree_and_a_dash_without(tmp_path, capsys):
    from efish.claims.seeds import with_seed_verdicts

    with_seeds = with_seed_verdicts(claims_rows({"C9": "holds"}), {1: claims_rows({"C9": "holds"})}, 3)
    (tmp_path / "new").mkdir()
    (tmp_path / "old").mkdir()
    with_seeds.to_parquet(tmp_path / "new" / "claims.parquet")
    claims_rows({"C9": "inconclusive"}).to_parquet(tmp_path / "old" / "claims.parquet")
    assert main(["compare-claims", str(tmp_path / "new"), str(tmp_path / "old")]) == 0
    header, row, agreement = capsys.readouterr().out.splitlines()
    assert "new seeds_agree" in header and "old seeds_agree" in header
    assert "2/2 hold" in row and " - " in row and row.rstrip().endswith("*")
    assert agreement.startswith("selected seeds' verdicts: the same for 0 of 1 claims")


def test_compare_claims_counts_the_recipe_verdicts_that_agree_between_two_runs(tmp_path, capsys):
    """The stability run's numbers: with the recipe's verdict in both tables, moved marks the recipe's and two
    lines count the agreement of the recipe's and of the selected seeds' verdicts, naming holds-opposite flips."""
    rows = claims_rows({"C1": "holds", "C2": "inconclusive", "C3": "opposite"})
    a = rows.assign(recipe_verdict=["holds", "inconclusive", "holds"])
    b = rows.assign(recipe_verdict=["holds", "opposite", "opposite"], verdict=["holds", "inconclusive", "holds"])
    for name, t in (("a", a), ("b", b)):
        (tmp_path / name).mkdir()
        t.to_parquet(tmp_path / name / "claims.parquet")
    assert main(["compare-claims", str(tmp_path / "a"), str(tmp_path / "b")]) == 0
    *table, recipe, selected = capsys.readouterr().out.splitlines()
    assert "a recipe" in table[0] and [line.rstrip().endswith("*") for line in table[1:]] == [False, True, True]
    assert recipe == "recipe verdicts: the same for 1 of 3 claims; holds in one and opposite in the other: C3 (a vs b)"
    assert selected == ("selected seeds' verdicts: the same for 2 of 3 claims; holds in one and opposite in the other: "
                        "C3 (a vs b)")


# ------------------------------------------------- dispatch: every (sub)command has a handler
def _commands(parser) -> dict:
    """{command: its parser} of every (sub)command, ``bench physics`` style for the nested ones."""
    import argparse

    found = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                nested = _commands(sub)
                found.update({f"{name} {k}": v for k, v in nested.items()} if nested else {name: sub})
    return found


def test_every_command_has_a_handler_and_the_docstring_lists_it():
    import efish.cli as cli

    commands = _commands(cli._parser())
    assert len(commands) == 29 and "bench group" in commands and "bench scaling" in commands and "claims-by-stage" in commands and "compare-claims" in commands
    assert "watch" in commands and "compare-runs" in commands
    for name, parser in commands.items():
        assert callable(parser.get_default("handler")), name
    usage = {" ".join(line.split()[1:3]) if line.split()[1] == "bench" else line.split()[1]
             for line in cli.__doc__.splitlines() if line.strip().startswith("efish ")}
    assert usage == set(commands)


@pytest.mark.parametrize("argv, listed", [
    (["--help"], ["config", "train", "assay", "figure", "claims", "compare-claims", "plan-cluster", "bench"]),
    (["bench", "--help"], ["physics", "env", "train", "budget", "pipeline", "accuracy", "scaling", "multipole"]),
])
def test_help_lists_every_subcommand(argv, listed, capsys):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 0
    out = capsys.readouterr().out
    assert all(name in out for name in listed)


@pytest.mark.parametrize("argv", [
    ["config", "bench.nope=1"],
    ["train", "train.lr=-1"],
    ["figure", "fig3/M", "scale=nope"],
    ["bench", "accuracy", "bench.repeats=0"],
    ["bench", "scaling", "bench.nope=1"],
    ["bench", "train", "bench.train_skip_below=2"],
])
def test_a_bad_override_is_one_line_exit_2_and_nothing_written(argv, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("efish: error:") and len(err.splitlines()) == 1, err
    assert list(tmp_path.iterdir()) == []


def test_config_lists_the_bench_sizes(capsys):
    assert main(["config", "bench.train_skip_below=0.5"]) == 0
    out = capsys.readouterr().out
    for key in ("env_envs: 16", "train_skip_below: 0.5", "budget_minutes:", "multipole_width_cm: 560.0"):
        assert key in out


@pytest.mark.parametrize("argv, layout", [
    (["train"], "training"), (["bench", "train"], "training"), (["bench", "budget"], "training"),
    (["train", "policy=homing"], "training"), (["train", "arena=patchy70"], "patchy"),
    (["bench", "physics"], "patchy"), (["assay"], "patchy")])
def test_training_commands_sample_the_papers_arenas(argv, layout):
    """efish train and the benches that time it compose policy=foraging before the user's overrides, so they
    train on sampled arenas unless told otherwise; the other commands keep the default assay's arena."""
    from efish.config import compose

    args = _parser().parse_args([*argv, *(["--policy", "p"] if argv == ["assay"] else [])])
    cfg = compose([*_recipe_override(args), *args.overrides])
    assert cfg.arena.layout == layout
    assert (cfg.env.task == "homing") == ("policy=homing" in argv)


def test_default_folders_are_the_runs(tmp_path, monkeypatch, capsys):
    """A command without --results reads the run its scale and overrides name (efish.layout)."""
    from efish.config import run_name

    monkeypatch.chdir(tmp_path)
    assert main(["bench", "pipeline", "scale=smoke"]) == 2
    assert "results/smoke/benchmarks" in capsys.readouterr().err
    assert main(["claims", "scale=smoke", "analysis.claims_resamples=20"]) == 2
    run = run_name("smoke", ["analysis.claims_resamples=20"])
    assert f"results folder results/{run} does not exist" in capsys.readouterr().err
