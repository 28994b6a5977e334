"""``lanevil drive``: closed-loop lane keeping of one case, or of every case of a folder (``--suite``)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .base import Command, UsageError, bounded, parse_size


def _drive_arguments(parser: argparse.ArgumentParser) -> None:
    from ..drive.controllers import CONTROLLERS
    from ..drive.detectors import GROUND_TRUTH
    from ..drive.loop import DEFAULT_SIZE

    parser.add_argument("case", type=Path, nargs="?", help="case file (JSON); leave out with --suite")
    parser.add_argument("--suite", type=Path, default=None, metavar="DIR",
                        help="drive every case under DIR (e.g. scenes/) and tabulate ASR per type and level")
    parser.add_argument("--detector", required=True, metavar="DETECTOR",
                        help=f"{GROUND_TRUTH} = the projected ground truth (the reference), a method of `lanevil "
                             "detect` (built-in or plug-in name), or a source http://HOST:PORT/PATH or onnx:PATH")
    parser.add_argument("--weights", type=Path, default=None, help="model folder of a learned detector")
    parser.add_argument("--controller", choices=CONTROLLERS, default="pure_pursuit",
                        help="lateral controller (default pure_pursuit)")
    parser.add_argument("--seconds", type=bounded(float, "a number of seconds", 0.1, 600, " seconds"), default=None,
                        help="how long to drive (default: the case's drive, frames / fps)")
    parser.add_argument("--size", type=parse_size, default=DEFAULT_SIZE,
                        help=f"camera WIDTHxHEIGHT (default {DEFAULT_SIZE[0]}x{DEFAULT_SIZE[1]})")
    parser.add_argument("--out", type=Path, required=True, help="output folder")
    parser.add_argument("--video", action=argparse.BooleanOptionalAction, default=None,
                        help="write drive.mp4 (default: yes for one case, no with --suite)")
    parser.add_argument("--json", action="store_true", help="print the summary (or suite) as JSON")


def _settings(args: argparse.Namespace):  # noqa: ANN202 - DriveSettings, imported lazily
    from ..drive.loop import DriveSettings

    return DriveSettings(detector=args.detector, controller=args.controller, seconds=args.seconds, size=args.size,
                         weights=str(args.weights) if args.weights is not None else None)


def _check_detector(args: argparse.Namespace) -> None:
    """The detector can run (an HTTP one answers) before the first frame renders; exit 2 with one line if not."""
    from ..detect.registry import ready_detector
    from ..drive.detectors import GROUND_TRUTH
    from ..metrics.formats import LaneFileError

    if args.detector == GROUND_TRUTH:
        return
    try:
        ready_detector(args.detector, args.weights)
    except LaneFileError as error:
        raise UsageError(str(error)) from None


def _run_suite(args: argparse.Namespace) -> int:
    from ..drive.suite import markdown, run_suite, suite_cases, suite_json, write_suite

    if not args.suite.is_dir():
        raise UsageError(f"--suite {args.suite}: no such folder")
    if not suite_cases(args.suite):
        raise UsageError(f"--suite {args.suite}: no case files (*.json) in it")
    settings = _settings(args)

    def progress(done: int, total: int, name: str) -> None:
        print(f"\r[{done}/{total}] {name:60s}", end="" if done < total else "\n", file=sys.stderr, flush=True)

    entries = run_suite(args.suite, settings, args.out, video=bool(args.video), progress=progress)
    write_suite(entries, settings, args.out)
    print(suite_json(entries, settings) if args.json else markdown(entries, settings))
    return 0


def _run_drive(args: argparse.Namespace) -> int:
    from ..metrics.formats import LaneFileError

    try:
        return _drive(args)
    except LaneFileError as error:  # a plug-in detector that fails mid-drive (its server went down)
        raise UsageError(str(error)) from None


def _drive(args: argparse.Namespace) -> int:
    from ..case import case_meshes_dir, load_case
    from ..drive.outputs import drive_to_folder, summary_json
    from ..drive.plots import plots_available

    if (args.case is None) == (args.suite is None):
        raise UsageError("give one case file or --suite DIR")
    _check_detector(args)
    if args.suite is not None:
        return _run_suite(args)
    case = load_case(args.case)

    def progress(done: int, total: int) -> None:
        print(f"\rstep {done}/{total}", end="" if done < total else "\n", file=sys.stderr, flush=True)

    output = drive_to_folder(case, _settings(args), args.out, video=args.video is not False, progress=progress,
                             meshes_dir=case_meshes_dir(args.case))
    if not plots_available():
        print("note: matplotlib is not installed (pip install 'lanevil[report]'): no plots written", file=sys.stderr)
    summary = output.summary
    if args.json:
        print(summary_json(summary), end="")
    else:
        exceed = f"{summary.t_exceed:.1f} s" if summary.t_exceed is not None else "never"
        print(f"{summary.verdict}: max |deviation| {summary.max_abs_deviation:.3f} m, > 0.285 m at {exceed}, "
              f"lane departure {'yes' if summary.lane_departure else 'no'}, "
              f"off road {'yes' if summary.off_road else 'no'}; {summary.steps} steps "
              f"({summary.steps_per_second:.1f}/s)")
        print(" ".join(str(path) for path in output.files.values()))
    return 0


COMMANDS: dict[str, Command] = {
    "drive": Command("closed-loop lane keeping with a detector in the loop (the paper's driving test)",
                     _drive_arguments, _run_drive),
}
