"""``lanevil realism --sheet``: our clean renders beside real frames of the same scene kinds, tiny tiles."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from lanevil_core import cli
from lanevil_core.metrics.realism import RealismError
from lanevil_core.report.realism_sheet import (
    CAPTION_H,
    EMPTY_TILE,
    GAP,
    HEADER_H,
    LABEL_W,
    SHEET_ROWS,
    cover,
    real_frames,
)

TILE = (64, 64)
REAL_RGB = (200, 30, 30)


def _real_folder(root: Path) -> Path:
    """A real folder with one frame for the highway row (a flat colour, 160x90) and its source line."""
    (root / "highway" / "clip").mkdir(parents=True)
    Image.new("RGB", (160, 90), REAL_RGB).save(root / "highway" / "clip" / "b.png")
    Image.new("RGB", (160, 90), (0, 0, 0)).save(root / "highway" / "clip" / "c.jpg")
    (root / "highway" / "source.txt").write_text("Some dash cam (CC BY 4.0)\nmore\n")
    (root / "not_a_kind").mkdir()
    Image.new("RGB", (16, 16)).save(root / "not_a_kind" / "a.png")
    return root


def _tile(sheet: np.ndarray, row: int, column: int) -> np.ndarray:
    y = HEADER_H + row * (TILE[1] + CAPTION_H + GAP)
    x = LABEL_W + column * (TILE[0] + GAP)
    return sheet[y:y + TILE[1], x:x + TILE[0]]


def test_real_frames_take_the_first_image_of_each_kind_and_its_source(tmp_path):
    frames = real_frames(_real_folder(tmp_path), [row.kind for row in SHEET_ROWS])
    assert list(frames) == ["highway"]
    assert frames["highway"].name == "highway/clip/b.png"
    assert frames["highway"].source == "Some dash cam (CC BY 4.0)"


def test_real_frames_need_a_kind_folder_with_images(tmp_path):
    (tmp_path / "highway").mkdir()
    Image.new("RGB", (16, 16)).save(tmp_path / "frame.png")  # images beside the kind folders do not count
    with pytest.raises(RealismError, match="no images in sub-folders named after the sheet's rows"):
        real_frames(tmp_path, ["highway", "urban"])


def test_cover_fills_the_tile_and_crops_the_overflow_evenly():
    rgb = np.zeros((100, 200, 3), np.uint8)
    rgb[:, 100:] = 255  # left half black, right half white
    tile = np.asarray(cover(rgb, (50, 50)))
    assert tile.shape == (50, 50, 3)
    assert tile[:, :20].max() < 10 and tile[:, 30:].min() > 245  # the middle of the wide image, both halves


def test_cli_sheet_puts_ours_beside_the_real_frames(tmp_path, capsys):
    out = tmp_path / "docs" / "sheet.png"
    argv = ["realism", "--sheet", str(out), "--real", str(_real_folder(tmp_path / "real")), "--size", "64x64",
            "--frame", "0"]
    assert cli.main(argv) == 0
    assert capsys.readouterr().out.strip() == str(out)
    sheet = np.asarray(Image.open(out).convert("RGB"))
    rows = len(SHEET_ROWS)
    assert sheet.shape == (HEADER_H + rows * (TILE[1] + CAPTION_H + GAP), LABEL_W + 2 * (TILE[0] + GAP), 3)
    assert (_tile(sheet, 0, 1) == REAL_RGB).all()  # the highway row: its real frame, scaled to cover the tile
    assert all((_tile(sheet, row, 1) == EMPTY_TILE).all() for row in range(1, rows))  # no real frame of its kind
    assert all(_tile(sheet, row, 0).std() > 5 for row in range(rows))  # our renders: a scene, not a flat tile


@pytest.mark.parametrize("problem", ["missing", "no_kinds", "with_ours", "jpeg", "camera_alone"])
def test_cli_sheet_errors_exit_2_with_one_line(tmp_path, capsys, problem):
    (tmp_path / "flat").mkdir()
    Image.new("RGB", (16, 16)).save(tmp_path / "flat" / "a.png")
    sheet = str(tmp_path / "sheet.png")
    argv, words = {
        "missing": (["--sheet", sheet, "--real", str(tmp_path / "missing")], "no such folder"),
        "no_kinds": (["--sheet", sheet, "--real", str(tmp_path / "flat")], "no images in sub-folders"),
        "with_ours": (["--sheet", sheet, "--ours", str(tmp_path / "flat")], "--ours does not go with --sheet"),
        "jpeg": (["--sheet", str(tmp_path / "sheet.jpg")], "name it *.png"),
        "camera_alone": (["--ours", str(tmp_path / "flat"), "--camera", "carla"], "--camera goes with --sheet"),
    }[problem]
    assert cli.main(["realism", *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("lanevil: error: ") and words in err[0]
    assert not (tmp_path / "sheet.png").exists()
