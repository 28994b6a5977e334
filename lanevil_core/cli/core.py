"""``lanevil render``, ``export``, ``preview`` and ``bench``: frames, datasets and timings of cases."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from ..case import Case, case_meshes_dir, load_case
from ..files import write_atomic
from ..presets import CAMERA_PRESET_NAMES
from .base import (
    CLEAN_DIR,
    SCENES_DIR,
    Command,
    UsageError,
    check_frame,
    encode_image,
    frame_range,
    image_path,
    output_file,
    parse_formats,
    parse_size,
    stock_scenes,
)

# ---------------------------------------------------------------------------------------------- render

def _render_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", type=Path, help="case file (JSON)")
    parser.add_argument("--frame", type=int, default=0, help="frame index (default 0)")
    parser.add_argument("--out", type=Path, required=True, help="output image: .png, or .jpg for JPEG")
    parser.add_argument("--size", type=parse_size, default=None, help="WIDTHxHEIGHT (default: the case camera's)")
    parser.add_argument("--overlay", action="store_true", help="draw the lane labels on the image")
    parser.add_argument("--labels", type=Path, default=None, help="also write the frame's TuSimple record (JSON)")


def render_image(case: Case, frame_index: int, size: tuple[int, int] | None, overlay: bool,
                 meshes_dir: Path | None = None) -> tuple[np.ndarray, dict]:
    """Render one frame; return the (H, W, 3) uint8 image (lanes drawn when ``overlay``) and its TuSimple record.
    A vehicle's ``mesh_file`` is read from ``meshes_dir``."""
    from ..labels.lanes import tusimple_record
    from ..labels.overlay import draw_lanes
    from ..pipeline.compile import compile_scene
    from ..render import render_frame

    scene = compile_scene(case, meshes_dir=meshes_dir)
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
    rgb, record = render_image(case, args.frame, args.size, args.overlay, case_meshes_dir(args.case))
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
    from ..interchange import write_interchange

    for path in write_interchange(case, args.out, opendrive=args.opendrive, openscenario=args.openscenario):
        print(path)


def _run_export(args: argparse.Namespace) -> int:
    from ..export.case import export_case

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

    result = export_case(case, args.out, frames=frames, formats=args.formats, glb=args.glb, progress=progress,
                         meshes_dir=case_meshes_dir(args.case))
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
    from ..images import png_bytes
    from ..labels.overlay import draw_lanes

    paths = args.cases or stock_scenes()
    if not paths:
        raise UsageError(f"no case files given and none under {SCENES_DIR}/")
    cases = [(path, load_case(path)) for path in paths]  # validate every file before rendering any
    for path, case in cases:
        check_frame(case, args.frame)
        rgb, record = render_image(case, args.frame, args.size, overlay=False, meshes_dir=case_meshes_dir(path))
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
    parser.add_argument("--threads", type=int, nargs="+", default=[1], metavar="N",
                        help="threads per frame (default 1); several counts (e.g. --threads 1 2) are timed frame by "
                             "frame side by side, with the speed-up over the first and a byte-identity check")
    parser.add_argument("--camera", nargs="+", default=[], choices=CAMERA_PRESET_NAMES, metavar="PRESET",
                        help="also time every frame through these camera presets (lens, mount and sensor), side by "
                             "side with the case's own camera, with the ratio to it: "
                             + ", ".join(CAMERA_PRESET_NAMES))


def _run_bench(args: argparse.Namespace) -> int:
    from ..pipeline.bench import bench_cases, format_rows, format_table, illusion_benchmark, run_benchmark

    if args.frames_per_case < 1:
        raise UsageError("--frames-per-case must be at least 1")
    if min(args.threads) < 1:
        raise UsageError("--threads must be at least 1")
    if args.illusions:
        rows = illusion_benchmark(frames=args.frames_per_case)
        print(json.dumps(rows) if args.json else format_rows(rows))
        return 0
    result = run_benchmark(bench_cases(stock_scenes() if args.all else stock_scenes(CLEAN_DIR)),
                           frames_per_case=args.frames_per_case, threads=args.threads, cameras=args.camera)
    print(json.dumps(result) if args.json else format_table(result))
    return 0


COMMANDS: dict[str, Command] = {
    "render": Command("render one frame to a PNG or JPEG", _render_arguments, _run_render),
    "export": Command("export frames with TuSimple/CULane labels (and the 3D scene)", _export_arguments, _run_export),
    "preview": Command("render frame 0 of every stock case (and a labelled copy)", _preview_arguments, _run_preview),
    "bench": Command("time the renderer on the stock cases", _bench_arguments, _run_bench),
}
