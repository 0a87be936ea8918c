"""The contact sheet (``efish contact-sheet``): every panel's id, its thumbnail or the words that it is missing."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from PIL import Image

from efish.cli import main
from efish.figures.contact_sheet import NOT_DRAWN, panel_png, sheet_figure, write_contact_sheet
from efish.figures.panel import Panel
from efish.figures.registry import PANELS

PANELS_HERE = [Panel("fig9", "A", lambda tables, ax: None), Panel("fig9", "B", lambda tables, ax: None),
               Panel("supp", "thing", lambda tables, ax: None)]


def write_png(path, colour) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.new("RGB", (350, 280), colour).save(path)


@pytest.fixture
def figures(tmp_path):
    """A figure folder holding the PNGs of fig9/A (red) and supp/thing (blue), not fig9/B."""
    root = tmp_path / "figures"
    write_png(panel_png(root, PANELS_HERE[0]), (255, 0, 0))
    write_png(panel_png(root, PANELS_HERE[2]), (0, 0, 255))
    return root


def test_every_id_is_written_and_the_missing_panel_says_so(figures):
    fig = sheet_figure(figures, PANELS_HERE)
    try:
        by_id = {}
        for ax in fig.axes:
            texts = [t.get_text() for t in ax.texts]
            ids = [t for t in texts if t in {p.key for p in PANELS_HERE}]
            if ids:
                by_id[ids[0]] = (ax, texts)
        assert list(by_id) == ["fig9/A", "fig9/B", "supp/thing"]  # registry order kept
        for key, (ax, texts) in by_id.items():
            missing = key == "fig9/B"
            assert (NOT_DRAWN in texts) == missing
            assert len(ax.images) == (0 if missing else 1)
        red = by_id["fig9/A"][0].images[0].get_array()
        assert np.asarray(red)[..., :3].reshape(-1, 3).mean(axis=0) == pytest.approx([255, 0, 0], abs=1)
        assert "2 of 3 panels drawn" in fig.get_suptitle()
    finally:
        plt.close(fig)


def test_write_contact_sheet_counts_and_writes_a_png(figures, tmp_path):
    out = tmp_path / "sheet" / "contact_sheet.png"
    assert write_contact_sheet(figures, out, PANELS_HERE) == (2, 1)
    with Image.open(out) as im:
        assert im.format == "PNG" and im.width > 500
    with pytest.raises(ValueError, match="must end in .png"):
        write_contact_sheet(figures, tmp_path / "sheet.pdf", PANELS_HERE)
    with pytest.raises(ValueError, match="no figure folder"):
        write_contact_sheet(tmp_path / "nowhere", out, PANELS_HERE)


def test_efish_contact_sheet_lays_out_every_registered_panel(tmp_path, capsys):
    root = tmp_path / "figures"
    first = next(iter(PANELS.values()))
    write_png(panel_png(root, first), (0, 128, 0))
    out = root / "contact_sheet.png"
    assert main(["contact-sheet", "--figures", str(root), "--out", str(out)]) == 0
    assert out.is_file() and (root / "contact_sheet.provenance.json").is_file()
    assert f"panels drawn: 1; not drawn at this scale: {len(PANELS) - 1}" in capsys.readouterr().out
