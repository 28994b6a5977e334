"""Contact sheet: one row per illusion type, columns = original and severity levels 1-5 of the same frame."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from ..illusions import REGISTRY
from ..library.stock import LEVELS, original_case, perturbed_case
from ..pipeline.compile import compile_scene
from ..render import render_frame
from ..typed import UInt8Array

LABEL_W = 170
HEADER_H = 26
GAP = 2


def label_font(size: int) -> ImageFont.ImageFont | ImageFont.FreeTypeFont:
    """Pillow's default font at ``size`` px (its fixed small font on Pillow < 10.1)."""
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1 has no sized default font
        return ImageFont.load_default()


def sheet_types(types: list[str] | None = None) -> list[str]:
    """The rows of a sheet: ``types`` or every registered illusion type."""
    return types if types is not None else list(REGISTRY)


def sheet_frames(types: list[str] | None = None) -> int:
    """How many frames a sheet of ``types`` renders (one per cell)."""
    return len(sheet_types(types)) * (1 + len(LEVELS))


def contact_sheet(size: tuple[int, int] = (320, 180), frame: int = 0, types: list[str] | None = None,
                  on_frame: Callable[[], None] | None = None) -> UInt8Array:
    """(H, W, 3) uint8 grid of renders (``size`` per cell) with row and column labels; ``on_frame`` is called
    after each cell's render (a progress bar)."""
    names = sheet_types(types)
    width, height = size
    columns = ["original", *[f"level {level}" for level in LEVELS]]
    sheet = Image.new("RGB", (LABEL_W + len(columns) * (width + GAP), HEADER_H + len(names) * (height + GAP)),
                      (24, 24, 28))
    draw = ImageDraw.Draw(sheet)
    font = label_font(15)
    for j, title in enumerate(columns):
        draw.text((LABEL_W + j * (width + GAP) + 6, 5), title, fill=(230, 230, 230), font=font)
    for i, name in enumerate(names):
        y = HEADER_H + i * (height + GAP)
        draw.text((8, y + height // 2 - 18), name, fill=(240, 240, 240), font=font)
        draw.text((8, y + height // 2 + 2), REGISTRY[name].CATEGORY, fill=(150, 150, 160), font=font)
        cases = [original_case(name), *[perturbed_case(name, level) for level in LEVELS]]
        for j, case in enumerate(cases):
            rgb = render_frame(compile_scene(case), frame, size).rgb
            sheet.paste(Image.fromarray(rgb), (LABEL_W + j * (width + GAP), y))
            if on_frame is not None:
                on_frame()
    return np.asarray(sheet)
