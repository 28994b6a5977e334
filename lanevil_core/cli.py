"""The ``lanevil`` command line: render frames, export datasets, benchmark the renderer.

Subcommands live in ``COMMANDS`` (name -> ``Command``). Another module adds its own by defining a module-level
``COMMANDS`` dict of the same shape in a file named ``lanevil_core/cli_<anything>.py``; those files are found and
merged at start-up, so a new subcommand needs no edit here.

User errors (a bad case file, a bad flag value, an output path that is a folder) end with exit status 2 and one
line on stderr, never a traceback. Before a command runs, the temporary files that a killed earlier run left in its
output folders (``--out``, ``--labels``) are removed (``files.remove_stale_temps``).
"""

from __future__ import annotations

import argparse
import importlib
import json
import pkgutil
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import NoReturn

import numpy as np

from .case import Case, CaseError, load_case, write_atomic
from .files import remove_stale_temps
from .frame_range import parse_frame_range

PROG = "lanevil"
EXTENSION_PREFIX = "cli_"
SCENES_DIR = Path("scenes")
CLEAN_DIR = SCENES_DIR / "00_clean"
IMAGE_FORMATS = {".png": "png", ".jpg": "jpeg", ".jpeg": "jpeg"}  # --out suffix -> encoding
JPEG_QUALITY = 95
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
    from .export import FORMATS

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
    """An output image path whose suffix names a format we write (``IMAGE_FORMATS``)."""
    output_file(path, flag, "frame.png")
    if path.suffix.lower() not in IMAGE_FORMATS:
        raise UsageError(f"{flag} {path}: the suffix picks the format; use one of {', '.join(IMAGE_FORMATS)}")
    return path


def encode_image(rgb: np.ndarray, path: Path) -> bytes:
    """(H, W, 3) uint8 pixels encoded as ``path``'s suffix says (PNG or JPEG)."""
    from .encode import jpeg_bytes, png_bytes

    return png_bytes(rgb) if IMAGE_FORMATS[path.suffix.lower()] == "png" else jpeg_bytes(rgb, JPEG_QUALITY)


def remove_leftovers(args: argparse.Namespace) -> None:
    """Remove what killed writes left in the folders this command writes to (files of running processes stay)."""
    for name in OUTPUT_ARGUMENTS:
        value = getattr(args, name, None)
        if isinstance(value, Path):
            remove_stale_temps(value if value.is_dir() else value.parent, recursive=value.is_dir())


def stock_scenes(root: Path = SCENES_DIR) -> list[Path]:
    """Every case file under ``root`` (``**/*.json``), sorted."""
    return sorted(root.glob("**/*.json"))


# ---------------------------------------------------------------------------------------------- render

def _render_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", type=Path, help="case file (JSON)")
    parser.add_argument("--frame", type=int, default=0, help="frame index (default 0)")
    parser.add_argument("--out", type=Path, required=True, help="output image: .png, or .jpg for JPEG")
    parser.add_argument("--size", type=parse_size, default=None, help="WIDTHxHEIGHT (default: the case camera's)")
    parser.add_argument("--overlay", action="store_true", help="draw the lane labels on the image")
    parser.add_argument("--labels", type=Path, default=None, help="also write the frame's TuSimple record (JSON)")


def render_image(case: Case, frame_index: int, size: tuple[int, int] | None, overlay: bool) -> tuple[np.ndarray, dict]:
    """Render one frame; return the (H, W, 3) uint8 image (lanes drawn when ``overlay``) and its TuSimple record."""
    from .compile import compile_scene
    from .labels import tusimple_record
    from .overlay import draw_lanes
    from .render import render_frame

    scene = compile_scene(case)
    frame = render_frame(scene, frame_index, size)
    record = tusimple_record(scene, frame_index, frame, raw_file=f"{frame_index:06d}.png")
    rgb = draw_lanes(frame.rgb, record) if overlay else frame.rgb
    return rgb, record


def _run_render(args: argparse.Namespace) -> int:
    image_path(args.out)
    if args.labels is not None:
        output_file(args.labels, "--labels", "labels.json")
    case = load_case(args.case)
    check_frame(case, args.frame)
    rgb, record = render_image(case, args.frame, args.size, args.overlay)
    write_atomic(args.out, encode_image(rgb, args.out))
    if args.labels is not None:
        record["raw_file"] = args.out.name
        write_atomic(args.labels, (json.dumps(record) + "\n").encode("utf-8"))
    print(args.out)
    return 0


# ---------------------------------------------------------------------------------------------- export

def _export_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", type=Path, help="case file (JSON)")
    parser.add_argument("--out", type=Path, required=True, help="output folder")
    parser.add_argument("--frames", default=None, help="START:STOP frame range (default: all)")
    parser.add_argument("--format", type=parse_formats, default=frozenset({"tusimple"}), dest="formats",
                        help="label formats, comma-separated: tusimple,culane (default tusimple)")
    parser.add_argument("--glb", action="store_true", help="also write the 3D scene as scene.glb")
    parser.add_argument("--opendrive", action="store_true",
                        help="write the road as OpenDRIVE 1.6 (road.xodr); frames only with --frames")
    parser.add_argument("--openscenario", action="store_true",
                        help="write the drive as OpenSCENARIO 1.0 (scenario.xosc, with road.xodr); frames only with "
                             "--frames")


def _run_interchange(case: Case, args: argparse.Namespace) -> None:
    from .interchange import write_interchange

    for path in write_interchange(case, args.out, opendrive=args.opendrive, openscenario=args.openscenario):
        print(path)


def _run_export(args: argparse.Namespace) -> int:
    from .export import export_case

    if args.out.exists() and not args.out.is_dir():
        raise UsageError(f"--out {args.out}: is a file; give a folder to export into")
    case = load_case(args.case)
    if args.opendrive or args.openscenario:
        _run_interchange(case, args)
        if args.frames is None and not args.glb:
            return 0
    frames = frame_range(args.frames if args.frames is not None else ":", case.ego.frames)

    def progress(done: int, total: int) -> None:
        print(f"\rframe {done}/{total}", end="" if done < total else "\n", file=sys.stderr, flush=True)

    result = export_case(case, args.out, frames=frames, formats=args.formats, glb=args.glb, progress=progress)
    print(f"{len(result.files)} files in {result.out_dir}")
    return 0


# ---------------------------------------------------------------------------------------------- preview

def _preview_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("cases", type=Path, nargs="*", help=f"case files (default: {SCENES_DIR}/**/*.json)")
    parser.add_argument("--out", type=Path, default=Path("out"), help="output folder (default out)")
    parser.add_argument("--frame", type=int, default=0, help="frame index (default 0)")
    parser.add_argument("--size", type=parse_size, default=None, help="WIDTHxHEIGHT (default: the case camera's)")


def preview_path(case_path: Path, out_dir: Path, root: Path = SCENES_DIR) -> Path:
    """``out_dir/<path relative to root>.png`` (just the file name for cases outside ``root``)."""
    try:
        relative = case_path.resolve().relative_to(root.resolve())
    except ValueError:
        relative = Path(case_path.name)
    return out_dir / relative.with_suffix(".png")


def _run_preview(args: argparse.Namespace) -> int:
    from .encode import png_bytes
    from .overlay import draw_lanes

    paths = args.cases or stock_scenes()
    if not paths:
        raise UsageError(f"no case files given and none under {SCENES_DIR}/")
    cases = [(path, load_case(path)) for path in paths]  # validate every file before rendering any
    for path, case in cases:
        check_frame(case, args.frame)
        rgb, record = render_image(case, args.frame, args.size, overlay=False)
        target = preview_path(path, args.out)
        write_atomic(target, png_bytes(rgb))
        write_atomic(target.with_suffix(".overlay.png"), png_bytes(draw_lanes(rgb, record)))
        print(f"{target}  {target.with_suffix('.overlay.png')}")
    return 0


# ---------------------------------------------------------------------------------------------- bench

def _bench_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    parser.add_argument("--frames-per-case", type=int, default=2, help="frames timed per stock case (default 2)")
    parser.add_argument("--all", action="store_true",
                        help=f"time every stock case (default: the clean cases in {CLEAN_DIR})")
    parser.add_argument("--illusions", action="store_true",
                        help="instead: per illusion type, its original and level-5 case at 1280x720")


def _run_bench(args: argparse.Namespace) -> int:
    from .bench import bench_cases, format_rows, format_table, illusion_benchmark, run_benchmark

    if args.frames_per_case < 1:
        raise UsageError("--frames-per-case must be at least 1")
    if args.illusions:
        rows = illusion_benchmark(frames=args.frames_per_case)
        print(json.dumps(rows) if args.json else format_rows(rows))
        return 0
    result = run_benchmark(bench_cases(stock_scenes() if args.all else stock_scenes(CLEAN_DIR)),
                           frames_per_case=args.frames_per_case)
    print(json.dumps(result) if args.json else format_table(result))
    return 0


COMMANDS: dict[str, Command] = {
    "render": Command("render one frame to a PNG or JPEG", _render_arguments, _run_render),
    "export": Command("export frames with TuSimple/CULane labels (and the 3D scene)", _export_arguments, _run_export),
    "preview": Command("render frame 0 of every stock case (and a labelled copy)", _preview_arguments, _run_preview),
    "bench": Command("time the renderer on the stock cases", _bench_arguments, _run_bench),
}


def all_commands() -> dict[str, Command]:
    """``COMMANDS`` plus those of every ``lanevil_core/cli_*.py`` module (sorted by module name)."""
    commands = dict(COMMANDS)
    package = importlib.import_module(__package__ or "lanevil_core")
    for info in sorted(pkgutil.iter_modules(package.__path__), key=lambda info: info.name):
        if info.name.startswith(EXTENSION_PREFIX):
            module = importlib.import_module(f"{package.__name__}.{info.name}")
            commands.update(getattr(module, "COMMANDS", {}))
    return commands


def build_parser(commands: dict[str, Command]) -> argparse.ArgumentParser:
    """The top-level parser with one subparser per command."""
    parser = _Parser(prog=PROG, description="LanEvil Studio: lane-detection robustness cases.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, command in commands.items():
        command.add_arguments(sub.add_parser(name, help=command.help, description=command.help))
    return parser


def main(argv: Sequence[str] | None = None, extra_commands: dict[str, Command] | None = None) -> int:
    """Run the command line with ``extra_commands`` added; return the exit status (0 ok, 2 user error)."""
    commands = {**all_commands(), **(extra_commands or {})}
    try:
        args = build_parser(commands).parse_args(argv)
        remove_leftovers(args)
        return commands[args.command].run(args)
    except (UsageError, CaseError) as error:
        print(f"{PROG}: error: {error}", file=sys.stderr)
        return 2
    except (IsADirectoryError, NotADirectoryError) as error:  # an output path that names or crosses a folder
        print(f"{PROG}: error: {error.filename or ''}: {error.strerror or error}", file=sys.stderr)
        return 2
    except OSError as error:  # an unwritable output path, a full disk
        print(f"{PROG}: error: {error.filename or ''}: {error.strerror or error}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
