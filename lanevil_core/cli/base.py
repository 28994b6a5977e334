"""What every ``lanevil`` command shares: the ``Command`` record, ``UsageError``, argument types and output checks."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import NoReturn, TypeVar

import numpy as np

from ..case import Case
from ..files import remove_stale_temps
from ..images import FILE_JPEG_QUALITY, SUFFIX_FORMATS
from ..images import encode_image as encode_as
from ..pipeline.frames import parse_frame_range

PROG = "lanevil"
SCENES_DIR = Path("scenes")
CLEAN_DIR = SCENES_DIR / "00_clean"
OUTPUT_ARGUMENTS = ("out", "labels")  # path arguments whose folders get their leftover temporary files removed


class UsageError(Exception):
    """A user error: printed as ``lanevil: error: <message>`` with exit status 2."""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage dump) so every user error reads the same."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


@dataclass(frozen=True)
class Command:
    """One subcommand: a help line, a function adding its arguments, and a function running it (-> exit code)."""

    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


# ---------------------------------------------------------------------------------------------- argument types

Number = TypeVar("Number", int, float)


def bounded(kind: Callable[[str], Number], noun: str, low: Number, high: Number | None = None,
            note: str = "") -> Callable[[str], Number]:
    """An argparse type: ``kind(text)`` (``int`` or ``float``) no less than ``low`` and, if given, no more than
    ``high``; argparse names the option in the one-line error (``note`` is added to the range)."""

    def parse(text: str) -> Number:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {noun}") from None
        if high is None and value < low:
            raise argparse.ArgumentTypeError(f"must be at least {low}")
        if high is not None and not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text!r}: choose {low}..{high}{note}")
        return value

    return parse


def count(minimum: int) -> Callable[[str], int]:
    """An argparse type: an integer of at least ``minimum``."""
    return bounded(int, "an integer", minimum)


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` -> (width, height), each 64..4096."""
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not WIDTHxHEIGHT (e.g. 1280x720)") from None
    if not (64 <= width <= 4096 and 64 <= height <= 4096):
        raise argparse.ArgumentTypeError(f"{text!r}: width and height must lie in 64..4096")
    return width, height


def parse_formats(text: str) -> frozenset[str]:
    """Comma-separated export formats."""
    from ..export.case import FORMATS

    formats = frozenset(part.strip() for part in text.split(",") if part.strip())
    unknown = sorted(formats - set(FORMATS))
    if unknown or not formats:
        raise argparse.ArgumentTypeError(f"{text!r}: choose from {', '.join(FORMATS)}")
    return formats


def frame_range(text: str, frames: int) -> range:
    """``A:B`` (Python slice, either end optional) -> frames A..B-1 of a case with ``frames`` frames."""
    try:
        return parse_frame_range(text, frames)
    except ValueError as error:
        raise UsageError(f"--frames {error}") from None


def check_frame(case: Case, frame: int) -> None:
    """Raise UsageError naming ``--frame`` unless ``frame`` is one of the case's frames."""
    if not 0 <= frame < case.ego.frames:
        raise UsageError(f"--frame {frame} is outside 0..{case.ego.frames - 1} (the case has {case.ego.frames} frames)")


def output_file(path: Path, flag: str, example: str) -> Path:
    """``path`` if a file can be written there; a ``UsageError`` naming ``flag`` and the path for a folder."""
    if path.is_dir():
        raise UsageError(f"{flag} {path}: is a folder; give a file name, e.g. {path / example}")
    return path


def image_path(path: Path, flag: str = "--out") -> Path:
    """An output image path whose suffix names a format we write (``images.SUFFIX_FORMATS``)."""
    output_file(path, flag, "frame.png")
    if path.suffix.lower() not in SUFFIX_FORMATS:
        raise UsageError(f"{flag} {path}: the suffix picks the format; use one of {', '.join(SUFFIX_FORMATS)}")
    return path


def encode_image(rgb: np.ndarray, path: Path) -> bytes:
    """(H, W, 3) uint8 pixels encoded as ``path``'s suffix says (PNG, or JPEG at ``FILE_JPEG_QUALITY``)."""
    return encode_as(rgb, SUFFIX_FORMATS[path.suffix.lower()], FILE_JPEG_QUALITY)


def remove_leftovers(args: argparse.Namespace) -> None:
    """Remove what killed writes left in the folders this command writes to (files of running processes stay)."""
    for name in OUTPUT_ARGUMENTS:
        value = getattr(args, name, None)
        if isinstance(value, Path):
            remove_stale_temps(value if value.is_dir() else value.parent, recursive=value.is_dir())


def stock_scenes(root: Path = SCENES_DIR) -> list[Path]:
    """Every case file under ``root`` (``**/*.json``), sorted."""
    return sorted(root.glob("**/*.json"))
