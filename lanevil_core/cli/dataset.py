"""``lanevil dataset``: render the benchmark's test split (and a clean train split) with TuSimple labels."""

from __future__ import annotations

import argparse
import functools
import os
import sys
from pathlib import Path

from ..presets import CAMERA_PRESET_NAMES
from .base import Command, UsageError, count, parse_size


def _dataset_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--cases", type=Path, required=True, help="folder of case files (searched recursively)")
    parser.add_argument("--out", type=Path, required=True, help="output folder (reruns resume into it)")
    parser.add_argument("--train-frames", type=count(0), default=0,
                        help="clean train frames, from variations of the clean cases (default 0)")
    parser.add_argument("--frames-per-case", type=count(1), default=None,
                        help="frames per test case (default: every frame)")
    parser.add_argument("--sampling", choices=("in_view", "even"), default="in_view",
                        help="which test frames with --frames-per-case: in_view (default) = evenly over the frames "
                             "where the type's level-5 illusion changes the lane band, the same frames for its "
                             "original and every level; even = evenly over the whole drive")
    parser.add_argument("--size", type=parse_size, default=(1280, 720), help="WIDTHxHEIGHT (default 1280x720)")
    parser.add_argument("--format", choices=("png", "jpg"), default="png", dest="image_format",
                        help="image format (default png)")
    parser.add_argument("--workers", type=count(1), default=os.cpu_count() or 1,
                        help="local worker processes (default: all cores; ignored with --scheduler)")
    parser.add_argument("--scheduler", default=None,
                        help="run on the Dask cluster of this scheduler, tcp://HOST:PORT")
    parser.add_argument("--scheduler-timeout", type=float, default=10.0,
                        help="seconds to wait for the scheduler (default 10)")
    parser.add_argument("--seed", type=count(0), default=0, help="seed of the train variations")
    parser.add_argument("--no-paint", action="store_true",
                        help="also render every original test case with its lane paint removed "
                             "(<case>_nopaint folders, records with \"paint\": false): the paint-free control")
    parser.add_argument("--camera", default=None, metavar="PRESET|FILE.json",
                        help=f"see every case through this camera: a preset ({', '.join(CAMERA_PRESET_NAMES)}: lens, "
                        "bonnet, sensor) or a calibration file (intrinsics, distortion, mount height, pitch or "
                        "horizon row or vanishing point, bonnet row; docs/cameras.md); default: each case's own "
                        "camera")
    parser.add_argument("--vary-camera", action="store_true",
                        help="train variations draw their camera and sensor: HFOV 45-100, height 1.2-3.5 m, pitch "
                        "-2..6, roll +-2, principal point row, bonnet on/off, lens, exposure, noise, blur, colour, "
                        "compression; and concrete roads (30 %%) and worn paint (half)")
    parser.add_argument("--vary-world", action="store_true",
                        help="train variations draw their world: scene kind and density, sun (day to night), "
                        "clouds, fog, wet or dry, asphalt or concrete in drawn shades, lane width, bends, grades, "
                        "traffic in the lanes (lanevil_core/dataset/worlds.py, docs/learning.md)")
    parser.add_argument("--heldout", action="store_true",
                        help="with --vary-world: draw from the held-out ranges (cameras, lane widths, bends, grades "
                        "and road colours outside the train draw's; the rest alike): a validation split of unseen "
                        "cameras, roads and materials. Not with --vary-camera or --camera")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def _run_dataset(args: argparse.Namespace) -> int:
    from ..dataset import PlanError, Settings, generate_dataset
    from ..dataset.distributed import SchedulerError, check_scheduler_address, run_dask
    from ..dataset.local import LocalPool
    from ..dataset.plan import check_world_flags
    from ..dataset.run import Executor

    if not args.cases.is_dir():
        raise UsageError(f"--cases {args.cases}: no such folder")
    if args.camera is not None:  # checked before a plan is made: a bad file is one line, not a failed run
        from ..camera.calibration import CalibrationError, camera_choice

        try:
            camera_choice(args.camera)
        except CalibrationError as error:
            raise UsageError(str(error)) from None
    settings = Settings(size=args.size, image_format=args.image_format, frames_per_case=args.frames_per_case,
                        train_frames=args.train_frames, seed=args.seed, no_paint=args.no_paint,
                        sampling=args.sampling, camera=args.camera, vary_camera=args.vary_camera,
                        vary_world=args.vary_world, heldout=args.heldout)
    try:  # checked before workers start: a bad combination is one line
        check_world_flags(settings)
    except PlanError as error:
        raise UsageError(str(error)) from None
    if args.scheduler is not None:
        try:
            address = check_scheduler_address(args.scheduler)
        except SchedulerError as error:
            raise UsageError(str(error)) from None
        executor: Executor = functools.partial(run_dask, address=address, timeout_s=args.scheduler_timeout)
    else:
        executor = LocalPool(args.workers)
    try:
        summary = generate_dataset(args.cases, args.out, settings, executor, show_progress=not args.quiet)
    except (PlanError, SchedulerError) as error:
        raise UsageError(str(error)) from None
    except KeyboardInterrupt:
        print(f"interrupted: frames written so far are kept; rerun the same command to resume into {args.out}",
              file=sys.stderr)
        return 130
    print(f"{summary.total} frames in {summary.out_dir} ({summary.rendered} rendered, {summary.kept} kept); "
          f"rendering {summary.render_seconds:.1f} s, {summary.frames_per_second:.2f} frames/s; "
          f"total wall time {summary.seconds:.1f} s (with worker start-up, planning, label files and manifest)")
    return 0


COMMANDS: dict[str, Command] = {
    "dataset": Command("render the test split (and a clean train split) with TuSimple labels and a manifest",
                       _dataset_arguments, _run_dataset),
}
