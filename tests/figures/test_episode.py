"""Episode clips (``efish render``): frames drawn from synthetic rollout tables and the conditions the run recorded,
checked artist by artist."""

from __future__ import annotations

import math
import shutil
import subprocess

import numpy as np
import pandas as pd
import pytest
from PIL import Image, ImageSequence
from tests.helpers import rollout_tables

from efish.cli import main
from efish.config import compose
from efish.figures import clip_file as clip_file_module
from efish.figures import episode as episode_module
from efish.figures.clip_file import BlitFrames, clip_encoder
from efish.figures.episode import FieldOverlay, draw_frame, frame_rows, load_episode, render_clip, spans
from efish.figures.style import panel_style
from efish.rollout.tables import write_tables

OVERRIDES = ["scale=smoke", "assay=patchy4"]  # one condition, "control", in a 70 x 70 arena
STEPS = 30
EATEN_AT, SPAWNED_AT = 10, 5


@pytest.fixture(scope="module")
def cfg():
    return compose(OVERRIDES)


@pytest.fixture(scope="module")
def tables(tmp_path_factory, recorded):
    """steps/food.parquet of two episodes of "control" (3 agents, 30 steps) and patchy4's conditions.parquet; in
    episode 0 pellet 0 is eaten by agent 1 at step 10, pellet 1 spawns at step 5, and agent 0 bites agent 2 at
    step 12."""
    t = rollout_tables(seed=3, conditions=("control",), episodes=2, n_agents=3, steps=STEPS)
    steps, food = t["steps"], t["food"]
    first = (food["episode"] == 0)
    food.loc[first & (food["pellet"] == 0), ["t_eaten", "eaten_by"]] = [EATEN_AT, 1]
    food.loc[first & (food["pellet"] == 1), "t_spawned"] = SPAWNED_AT
    ep0 = steps["episode"] == 0
    steps.loc[ep0, ["bit", "bite_target"]] = [False, -1]
    biter = ep0 & (steps["t"] == 12) & (steps["agent"] == 0)
    steps.loc[biter, ["bit", "bite_target"]] = [True, 2]
    folder = tmp_path_factory.mktemp("assay")
    steps.to_parquet(folder / "steps.parquet", index=False)
    food.to_parquet(folder / "food.parquet", index=False)
    write_tables({"conditions": recorded("patchy4")["conditions/patchy4"]}, folder)
    return folder


def copy_tables(tables, folder, names=("steps", "food", "conditions")):
    for name in names:
        (folder / f"{name}.parquet").write_bytes((tables / f"{name}.parquet").read_bytes())
    return folder


@pytest.fixture(scope="module")
def ep(tables, cfg):
    return load_episode(tables, OVERRIDES, cfg, "control", 0)


def row_of(ep, t: int) -> int:
    return int(np.flatnonzero(ep.t == t)[0])


def drawn(ep, t: int, overlay=None) -> dict:
    """The artists of the frame of step ``t``, drawn on a fresh axes."""
    with panel_style() as plt:
        fig, ax = plt.subplots()
        artists = draw_frame(ax, ep, row_of(ep, t), overlay)
        plt.close(fig)
    return artists


def pellet_xy(artists) -> set:
    (scatter,) = artists["pellets"]
    return {tuple(np.round(p, 6)) for p in scatter.get_offsets()}


def test_the_episode_holds_the_tables_rows(ep, tables):
    steps = pd.read_parquet(tables / "steps.parquet")
    rows = steps[(steps["condition"] == "control") & (steps["episode"] == 0)]
    assert ep.xy.shape == (STEPS, 3, 2) and list(ep.t) == list(range(STEPS))
    row = rows[(rows["t"] == 7) & (rows["agent"] == 2)].iloc[0]
    assert ep.xy[7, 2].tolist() == pytest.approx([row["x_cm"], row["y_cm"]])
    assert ep.heading[7, 2] == pytest.approx(row["heading_rad"])
    assert ep.bite_target[12, 0] == 2 and ep.bit.sum() == 1


def test_a_pellet_is_drawn_until_the_step_it_is_eaten_and_after_it_spawns(ep):
    eaten = tuple(np.round(ep.food.loc[ep.food["pellet"] == 0, ["x_cm", "y_cm"]].to_numpy()[0], 6))
    spawned = tuple(np.round(ep.food.loc[ep.food["pellet"] == 1, ["x_cm", "y_cm"]].to_numpy()[0], 6))
    assert eaten in pellet_xy(drawn(ep, EATEN_AT - 1))
    at = drawn(ep, EATEN_AT)
    assert eaten not in pellet_xy(at) and len(at["eaten"]) == 1  # marked once, in the eater's colour
    assert eaten not in pellet_xy(drawn(ep, EATEN_AT + 1)) and not drawn(ep, EATEN_AT + 1)["eaten"]
    assert spawned not in pellet_xy(drawn(ep, SPAWNED_AT - 1))
    assert spawned in pellet_xy(drawn(ep, SPAWNED_AT))
    assert len(pellet_xy(drawn(ep, 0))) == len(ep.food) - 1  # every pellet but the late one


def test_bodies_flashes_and_bites_follow_the_steps_table(ep):
    for t in (0, 12, 20):
        artists = drawn(ep, t)
        i = row_of(ep, t)
        assert len(artists["bodies"]) == 3
        assert len(artists["flashes"]) == int(ep.eod[i].sum())
        assert len(artists["bites"]) == (2 if t == 12 else 0)  # the line and the mark on the victim
        body = artists["bodies"][0]
        assert (body.get_xdata()[0], body.get_ydata()[0]) == pytest.approx(tuple(ep.xy[i, 0]))
    line = drawn(ep, 12)["bites"][0]
    assert np.column_stack([line.get_xdata(), line.get_ydata()]) == pytest.approx(ep.xy[12, [0, 2]])


def test_the_gif_has_one_frame_per_drawn_step(ep, tmp_path):
    out = tmp_path / "clip.gif"
    frames = math.ceil(STEPS / 4) + 1  # steps 0, 4, ..., 28 and the last, 29
    assert render_clip(ep, out, every=4) == frames
    with Image.open(out) as im:
        assert sum(1 for _ in ImageSequence.Iterator(im)) == frames
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # written atomically, no leftovers


@pytest.mark.parametrize("t", [0, 12, 20])
def test_a_blitted_frame_is_the_full_draw_of_the_same_frame(ep, t):
    """The background saved without the walls and the clock, the frame's artists and those drawn over it in
    z-order: the same pixels as matplotlib's full draw (with the field overlay, which sits under the walls)."""
    from efish.drawing import FRAME_DPI, frame_size

    overlay = FieldOverlay(ep)
    with panel_style() as plt:
        fig = plt.figure(figsize=frame_size(70.0, 70.0, True), dpi=FRAME_DPI, layout="constrained")
        ax = fig.add_subplot()
        clock = episode_module.draw_arena(fig, ax, ep, overlay)
        fig.canvas.draw()
        fig.set_layout_engine("none")
        frames = BlitFrames(fig, ax, moving=[clock])
        artists = [a for group in draw_frame(ax, ep, row_of(ep, t), overlay).values() for a in group]
        clock.set_text(f"frame of step {t}")
        blitted = frames.grab(artists)
        fig.canvas.draw()
        full = np.asarray(fig.canvas.buffer_rgba()).copy()
        plt.close(fig)
    assert blitted.shape == full.shape
    differ = (blitted != full).any(axis=2)
    assert not differ.any(), f"{differ.sum()} of {differ.size} pixels differ"


@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="needs ffmpeg on PATH (.ci/run installs it)")
def test_the_mp4_has_one_frame_per_drawn_step(ep, tmp_path):
    out = tmp_path / "clip.mp4"
    assert render_clip(ep, out, every=3) == 11  # steps 0, 3, ..., 27 and the last, 29
    probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                            "stream=nb_read_frames,width,height", "-of", "csv=p=0", str(out)],
                           capture_output=True, text=True, check=True)
    width, height, frames = (int(v) for v in probe.stdout.strip().split(","))
    assert frames == 11 and width % 2 == 0 and height % 2 == 0
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_the_default_stride_keeps_a_gif_in_real_time_and_short(ep, monkeypatch):
    assert ep.fps / 2 <= episode_module.GIF_MAX_FPS < ep.fps  # 83 fps: every second step
    assert list(frame_rows(ep, None, ".gif")) == [*range(0, STEPS, 2), STEPS - 1]
    assert list(frame_rows(ep, None, ".mp4")) == list(range(STEPS))  # a video plays 83 fps
    monkeypatch.setattr(episode_module, "MAX_FRAMES", 5)
    assert list(frame_rows(ep, None, ".gif")) == [*range(0, STEPS, 6), STEPS - 1]
    with pytest.raises(ValueError, match="--every must be at least 1"):
        frame_rows(ep, 0, ".gif")


def test_the_field_overlay_appears_only_when_someone_discharges(ep):
    overlay = FieldOverlay(ep)
    anyone = ep.eod.any(axis=1)
    assert anyone.any() and not anyone.all()  # the fixed seed gives both kinds of step
    assert not drawn(ep, int(ep.t[np.flatnonzero(~anyone)[0]]), overlay)["field"]
    loud = int(ep.t[np.flatnonzero(anyone)[0]])
    assert len(drawn(ep, loud, overlay)["field"]) == 1
    i = row_of(ep, loud)
    field = overlay.log_magnitude(ep, i)
    assert field.shape == (len(overlay.ys), len(overlay.xs))
    # the strongest field sits next to an emitter
    peak = np.unravel_index(np.nanargmax(field), field.shape)
    peak_xy = np.array([overlay.xs[peak[1]], overlay.ys[peak[0]]])
    emitters = ep.xy[i][ep.eod[i]]
    assert np.min(np.linalg.norm(emitters - peak_xy, axis=1)) < 2 * (overlay.xs[1] - overlay.xs[0])


def test_unknown_condition_episode_and_missing_tables_are_one_clear_error(tables, cfg, tmp_path):
    with pytest.raises(ValueError, match=r"unknown condition 'treated'.*hold control"):
        load_episode(tables, OVERRIDES, cfg, "treated", 0)
    with pytest.raises(ValueError, match=r"no episode 9: it has episodes 0-1"):
        load_episode(tables, OVERRIDES, cfg, "control", 9)
    with pytest.raises(ValueError, match="missing rollout table"):
        load_episode(tmp_path, OVERRIDES, cfg, "control", 0)
    (tmp_path / "config.yaml").write_text("assay:\n  name: wide2\n")
    copy_tables(tables, tmp_path)
    with pytest.raises(ValueError, match="are assay wide2's.*pass assay=wide2"):
        load_episode(tmp_path, OVERRIDES, cfg, "control", 0)


def test_the_clip_draws_the_condition_as_the_run_recorded_it(tables, cfg, recorded, tmp_path):
    """fps, arena and physics are the recorded condition's (the run's overrides), whatever ``overrides`` says."""
    copy_tables(tables, tmp_path, ("steps", "food"))
    conditions = recorded("patchy4", overrides=("env.fps=25", "arena.width_cm=90"))["conditions/patchy4"]
    write_tables({"conditions": conditions}, tmp_path)
    ep = load_episode(tmp_path, OVERRIDES, cfg, "control", 0)
    assert (ep.fps, ep.cfg.arena.width_cm) == (25.0, 90.0)
    assert list(frame_rows(ep, None, ".mp4")) == list(range(STEPS))  # 25 fps plays every step in real time
    assert list(frame_rows(ep, None, ".gif")) == list(range(STEPS))


def test_tables_without_recorded_conditions_or_of_another_assay_are_one_clear_error(tables, cfg, recorded, tmp_path):
    copy_tables(tables, tmp_path, ("steps", "food"))
    with pytest.raises(ValueError, match=r"missing .*conditions\.parquet.*rerun the assay"):
        load_episode(tmp_path, OVERRIDES, cfg, "control", 0)
    write_tables({"conditions": recorded("wide2")["conditions/wide2"]}, tmp_path)  # no config.yaml to check
    with pytest.raises(ValueError, match=r"are assay wide2's \(its conditions\.parquet\).*pass assay=wide2"):
        load_episode(tmp_path, OVERRIDES, cfg, "control", 0)


def test_the_defaults_are_the_first_condition_and_episode(tables, cfg):
    ep = load_episode(tables, OVERRIDES, cfg)
    assert (ep.condition, ep.episode) == ("control", 0)


def test_clip_files_are_gif_or_mp4_with_ffmpeg(monkeypatch, tmp_path):
    assert clip_encoder(tmp_path / "a.GIF") == "pillow"
    with pytest.raises(ValueError, match="must end in .gif or .mp4"):
        clip_encoder(tmp_path / "a.avi")
    monkeypatch.setattr(clip_file_module.shutil, "which", lambda name: None)
    with pytest.raises(ValueError, match="needs ffmpeg on PATH"):
        clip_encoder(tmp_path / "a.mp4")


def test_spans_compacts_episode_lists():
    assert spans([5, 0, 1, 2, 7, 8]) == "0-2, 5, 7-8" and spans([]) == ""


def test_efish_render_writes_the_clip_and_its_provenance(tables, tmp_path, capsys):
    out = tmp_path / "clips" / "patchy4.gif"
    assert main(["render", *OVERRIDES, "--tables", str(tables), "--out", str(out), "--every", "10"]) == 0
    assert out.is_file() and (out.parent / "patchy4.provenance.json").is_file()
    assert "4 frames" in capsys.readouterr().out  # steps 0, 10, 20 and the last
    assert main(["render", *OVERRIDES, "--tables", str(tables), "--out", str(out), "--condition", "x"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("efish: error: unknown condition 'x'") and "\n" not in err
