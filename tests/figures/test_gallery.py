"""The gallery (``efish gallery``): every registered panel on the page, web-sized, with its caption; a missing one
says why; the header reads the run's provenance; the committed gallery lists the current registry."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from matplotlib.figure import Figure
from PIL import Image

from efish.cli import main
from efish.figures.gallery import NOT_DRAWN, OTHERS, markdown_text
from efish.figures.registry import PANELS

REPO = Path(__file__).resolve().parents[2]
COMMITTED = REPO / "docs/gallery"
DRAWN_PX = 1600  # the fake panels' width: the gallery must scale them down
ENTRY = re.compile(r'^<figure markdown id="([\w-]+)">\n\n(.*?)\n\n<figcaption markdown>\n\n\*\*(\S+)\*\*: (.*?)\n\n'
                   r"</figcaption>", re.M | re.S)


def draw_png(path: Path, colour: str) -> None:
    """A panel-like PNG, DRAWN_PX wide, drawn with matplotlib as the figure jobs draw theirs."""
    fig = Figure(figsize=(8, 4), dpi=DRAWN_PX / 8)
    ax = fig.subplots()
    ax.plot([0, 1, 2], [0, 1, 0], colour)
    ax.set_title(path.stem)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)


def provenance(commit: str, command: list[str] | None = None) -> str:
    return json.dumps({"efish_version": "0.0.9", "git_commit": commit, "python": "3.11.0", "platform": "TestOS",
                       "packages": {"torch": "2.0.0+cpu"}, "command": command or ["efish", "figure"],
                       "started": "2030-01-02T03:04:05+00:00", "finished": "2030-01-02T03:05:06+00:00"})


@pytest.fixture
def run(tmp_path):
    """A run ``fake`` of two drawn registry panels (one schematic, one reading an assay), a benchmark figure and a
    stale gallery image; its scale runs only the drawn panel's assays and no top seeds."""
    schematic = next(p for p in PANELS.values() if not p.inputs)
    reader = next(p for p in PANELS.values() if p.assays() and not p.top_seed_assays())
    figures, results = tmp_path / "figures/fake", tmp_path / "results/fake"
    for panel, colour in ((schematic, "r"), (reader, "b")):
        draw_png(figures / panel.figure / f"{panel.name}.png", colour)
        (figures / panel.figure / f"{panel.name}.provenance.json").write_text(provenance("a" * 40))
    draw_png(figures / "bench/bench_speed.png", "g")
    (figures / "bench/bench_speed.provenance.json").write_text(
        provenance("b" * 40, ["/usr/bin/efish", "bench", "speed", "scale=fake"]))
    (figures / "config.yaml").write_text(
        "scale:\n  name: fake\n  assays: [" + ", ".join(sorted(reader.assays())) + "]\n  top_seeds: 0\n"
        "  top_seed_assays: []\n")
    (results / "bench").mkdir(parents=True)
    (results / "bench/bench_physics.json").write_text(json.dumps({"cpu": "Test CPU 9000", "cpu_capability": "AVX2"}))
    (results / "bench/provenance.json").write_text(provenance("c" * 40))
    stale = tmp_path / "gallery/img/fig9/Z.png"
    stale.parent.mkdir(parents=True)
    Image.new("RGB", (10, 10)).save(stale)
    return {"figures": figures, "results": results, "out": tmp_path / "gallery", "drawn": {schematic.key, reader.key},
            "stale": stale}


def entries(page: str) -> dict[str, tuple[str, str, str]]:
    """Every entry of a gallery page: key -> (anchor, image or reason, caption)."""
    return {key: (anchor, picture, caption) for anchor, picture, key, caption in ENTRY.findall(page)}


def test_the_gallery_lists_every_registered_panel_and_says_why_one_is_missing(run, capsys):
    out = run["out"]
    assert main(["gallery", "fake", "--figures", str(run["figures"]), "--results", str(run["results"]),
                 "--out", str(out), "--max-width", "700"]) == 0
    assert "panels drawn: 2; not drawn in this run: " + str(len(PANELS) - 2) in capsys.readouterr().out
    page = (out / "index.md").read_text()
    found = entries(page)
    assert set(PANELS) <= set(found)
    for key, panel in PANELS.items():
        anchor, picture, caption = found[key]
        assert anchor == key.replace("/", "-") and caption == markdown_text(panel.caption, links=True)
        if key in run["drawn"]:
            assert picture == f"[![{key}](img/{key}.png){{ loading=lazy }}](img/{key}.png)"
        else:
            assert NOT_DRAWN + ": " in picture, key
    missing = {key: found[key][1] for key in PANELS if key not in run["drawn"]}
    reader = next(PANELS[k] for k in run["drawn"] if PANELS[k].assays())
    other = next(p for p in PANELS.values() if p.assays() - reader.assays())
    assert f"scale fake runs no {sorted(other.assays() - reader.assays())[0]}" in missing[other.key]
    drawable_absent = next(p for p in PANELS.values() if p.key not in run["drawn"] and not p.inputs)
    assert "its figure job has not run" in missing[drawable_absent.key]
    # the other drawings of the run follow, with the command that drew each
    assert "**bench/bench_speed**: drawn by `efish bench speed scale=fake`" in page
    # the header: the command that regenerates it, and what the run recorded
    assert f"efish gallery fake --figures {run['figures']} --results {run['results']} --out {out} --max-width 700" in page
    assert "`aaaaaaa` (2 panels)" in page and "`ccccccc` (1 output)" in page
    assert "Test CPU 9000; torch CPU capability AVX2" in page and "efish 0.0.9, Python 3.11.0, torch 2.0.0+cpu" in page


def test_the_gallerys_images_are_scaled_down_and_stale_ones_removed(run):
    assert main(["gallery", "fake", "--figures", str(run["figures"]), "--results", str(run["results"]),
                 "--out", str(run["out"]), "--max-width", "500"]) == 0
    images = sorted((run["out"] / "img").rglob("*.png"))
    assert {str(p.relative_to(run["out"] / "img").with_suffix("")) for p in images} == run["drawn"] | {
        "bench/bench_speed"}
    for image in images:
        source = run["figures"] / image.relative_to(run["out"] / "img")
        with Image.open(image) as small, Image.open(source) as big:
            assert big.width == DRAWN_PX and small.width == 500 and small.mode == "P"
            assert abs(small.height / small.width - big.height / big.width) < 0.01
        assert image.stat().st_size < source.stat().st_size
    assert not run["stale"].exists()


def test_a_run_that_recorded_no_cpu_says_so(run):
    (run["results"] / "bench/bench_physics.json").unlink()
    assert main(["gallery", "fake", "--figures", str(run["figures"]), "--results", str(run["results"]),
                 "--out", str(run["out"])]) == 0
    assert "**CPU**: not recorded" in (run["out"] / "index.md").read_text()


def test_a_missing_figure_folder_is_one_line(tmp_path, capsys):
    assert main(["gallery", "nope", "--figures", str(tmp_path / "nope"), "--out", str(tmp_path / "g")]) == 2
    assert capsys.readouterr().err.startswith("efish: error: no figure folder")
    assert not (tmp_path / "g").exists()


def test_by_default_a_runs_gallery_goes_under_its_figures_not_onto_the_sites_page(run, capsys):
    assert main(["gallery", "fake", "--figures", str(run["figures"]), "--results", str(run["results"])]) == 0
    page = run["figures"] / "gallery" / "index.md"
    assert page.is_file() and str(page) in capsys.readouterr().out
    assert f"efish gallery fake --figures {run['figures']} --results {run['results']}\n" in page.read_text()


def test_the_committed_gallery_lists_every_panel_of_the_registry():
    """Adding a panel without regenerating the gallery (efish gallery laptop --out docs/gallery) fails here."""
    page = (COMMITTED / "index.md").read_text()
    listed = set(entries(page.split(OTHERS, 1)[0]))
    assert listed == set(PANELS), ("regenerate docs/gallery (efish gallery laptop --out docs/gallery): "
                                   f"missing {sorted(set(PANELS) - listed)}, no longer registered {sorted(listed - set(PANELS))}")
    linked = set(re.findall(r"\]\((img/[^)]+\.png)\)", page))
    on_disk = {str(p.relative_to(COMMITTED)) for p in (COMMITTED / "img").rglob("*.png")}
    assert linked == on_disk
    assert sum(p.stat().st_size for p in COMMITTED.rglob("*")) < 4e6
