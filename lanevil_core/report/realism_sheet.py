"""The realism sheet (``lanevil realism --sheet``): our clean renders beside real frames of similar scenes, one row
per scene kind, every tile captioned, for anyone to judge by eye.

The left column renders a stock clean case of each kind through a camera preset (the paper's capture camera
``carla`` by default). The right column, when a folder of real frames is given, shows the first image (sorted
path order) of its sub-folder named after the row's kind (``highway/``, ``urban/``, ``night/`` ...), captioned with
its path and, when the sub-folder or the folder holds a ``source.txt``, that file's first line (where the frame
comes from and its licence). A row whose kind has no sub-folder says so in its real tile.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from ..case import Case, seen_through
from ..library.stock import clean_cases, original_case, original_folder
from ..metrics.realism import RealismError, image_files, read_rgb
from ..pipeline.compile import compile_scene
from ..render import render_frame
from ..typed import UInt8Array
from .sheet import label_font

SHEET_CAMERA = "carla"  # the paper's capture camera through CARLA's sensor defaults (docs/cameras.md)
SHEET_FRAME = 30  # 3 s into every stock drive: the ego is under way, the road ahead in view
SHEET_TILE = (400, 225)
SOURCE_FILE = "source.txt"  # first line: where a real folder's frames come from (shown in their captions)
LABEL_W = 120
HEADER_H = 28
CAPTION_H = 36
GAP = 4
BACKGROUND = (24, 24, 28)
EMPTY_TILE = (48, 48, 54)


@dataclass(frozen=True)
class SheetRow:
    """One row: the scene kind (its label, and the real folder's sub-folder that holds its real frames) and the
    stock clean case our side renders."""

    kind: str
    case_name: str  # where the case lives under scenes/
    case: Callable[[], Case]


def _clean(kind: str, name: str) -> SheetRow:
    return SheetRow(kind, f"00_clean/{name}", lambda: clean_cases()[f"00_clean/{name}.json"])


def _original(kind: str, illusion_type: str, index: int) -> SheetRow:
    return SheetRow(kind, original_folder(illusion_type, index), lambda: original_case(illusion_type, index))


SHEET_ROWS: tuple[SheetRow, ...] = (
    _clean("highway", "03_uphill_highway"),  # clear noon, three lanes each way
    _clean("urban", "00_straight_urban"),  # clear noon, office blocks
    _clean("suburban", "01_bend_suburban"),  # cloudy noon, houses and trees
    _original("rural", "fence_shadow", 1),  # clear noon, fields (the clean rural case is a sunset)
    _clean("tunnel_approach", "07_straight_tunnel_approach"),  # cloudy sunset, a portal in a hillside
    _original("night", "streetlight_reflection", 2),  # a highway bend at night, dry
    _original("wet", "vehicle_reflection", 1),  # a wet highway under cloud
)


@dataclass(frozen=True)
class RealFrame:
    """A real frame of one kind and its two caption lines."""

    path: Path
    source: str
    name: str


def _source_line(*folders: Path) -> str:
    for folder in folders:
        path = folder / SOURCE_FILE
        if path.is_file():
            lines = path.read_text(encoding="utf-8", errors="replace").strip().splitlines()
            if lines:
                return lines[0].strip()
    return "real frame"


def scene_words(case: Case) -> str:
    """What a case shows, in words: its description (an original's without the illusion's name before it)."""
    words = case.description.split(": ", 1)[-1] or case.title
    return words[:1].upper() + words[1:]


def real_frames(root: Path, kinds: list[str]) -> dict[str, RealFrame]:
    """Kind -> the first image of ``root/<kind>/`` (searched recursively, sorted path order), for every kind that
    has one. Raises ``RealismError`` when ``root`` is not a folder or no kind's sub-folder holds an image."""
    if not root.is_dir():
        raise RealismError(f"{root}: no such folder")
    frames = {}
    for kind in kinds:
        if (root / kind).is_dir():
            try:
                first = image_files(root / kind, 1)[0]
            except RealismError:
                continue
            frames[kind] = RealFrame(first, _source_line(root / kind, root), first.relative_to(root).as_posix())
    if not frames:
        raise RealismError(f"{root}: no images in sub-folders named after the sheet's rows ({', '.join(kinds)})")
    return frames


def cover(rgb: UInt8Array, size: tuple[int, int]) -> Image.Image:
    """``rgb`` scaled to fill ``size`` (W, H), the overflow cropped evenly from both sides."""
    width, height = size
    image = Image.fromarray(rgb)
    scale = max(width / image.width, height / image.height)
    scaled = image.resize((max(width, round(image.width * scale)), max(height, round(image.height * scale))),
                          Image.Resampling.LANCZOS)
    left, top = (scaled.width - width) // 2, (scaled.height - height) // 2
    return scaled.crop((left, top, left + width, top + height))


def _fit(draw: ImageDraw.ImageDraw, text: str, width: int, font: object) -> str:
    """``text`` cut with an ellipsis to fit ``width`` pixels."""
    if draw.textlength(text, font=font) <= width:  # type: ignore[arg-type]
        return text
    while text and draw.textlength(text + "…", font=font) > width:  # type: ignore[arg-type]
        text = text[:-1]
    return text + "…"


def realism_sheet(real: Path | None = None, camera: str = SHEET_CAMERA, size: tuple[int, int] = SHEET_TILE,
                  frame: int = SHEET_FRAME, rows: tuple[SheetRow, ...] = SHEET_ROWS,
                  on_frame: Callable[[], None] | None = None) -> UInt8Array:
    """(H, W, 3) uint8 sheet: one row per ``rows`` kind, our render of its case through ``camera`` at ``size``
    (frame ``frame``) on the left and, with ``real``, the kind's real frame on the right; every tile captioned.
    Raises ``RealismError`` for a ``real`` folder without a usable frame."""
    width, height = size
    frames = real_frames(real, [row.kind for row in rows]) if real is not None else {}
    columns = [f"ours: {camera} camera, frame {frame}"] + (["real"] if real is not None else [])
    row_h = height + CAPTION_H + GAP
    sheet = Image.new("RGB", (LABEL_W + len(columns) * (width + GAP), HEADER_H + len(rows) * row_h), BACKGROUND)
    draw = ImageDraw.Draw(sheet)
    title, small = label_font(15), label_font(12)
    for j, text in enumerate(columns):
        draw.text((LABEL_W + j * (width + GAP) + 4, 6), _fit(draw, text, width - 8, title), fill=(230, 230, 230),
                  font=title)
    for i, row in enumerate(rows):
        y = HEADER_H + i * row_h
        draw.text((8, y + height // 2 - 8), row.kind.replace("_", " "), fill=(240, 240, 240), font=title)
        case = row.case()
        ours = render_frame(compile_scene(seen_through(case, camera)), frame, size).rgb
        tiles: list[tuple[Image.Image | None, tuple[str, str]]] = [
            (Image.fromarray(ours), (scene_words(case), row.case_name))]
        if real is not None:
            found = frames.get(row.kind)
            tiles.append((cover(read_rgb(found.path), size), (found.source, found.name)) if found is not None else
                         (None, (f"no real frame: add {row.kind}/ to the folder", "")))
        for j, (tile, caption) in enumerate(tiles):
            x = LABEL_W + j * (width + GAP)
            if tile is None:
                draw.rectangle((x, y, x + width - 1, y + height - 1), fill=EMPTY_TILE)
            else:
                sheet.paste(tile, (x, y))
            for k, line in enumerate(caption):
                draw.text((x + 2, y + height + 3 + 15 * k), _fit(draw, line, width - 4, small),
                          fill=(220, 220, 220) if k == 0 else (150, 150, 160), font=small)
        if on_frame is not None:
            on_frame()
    return np.asarray(sheet)
