"""``lanevil realism``: image statistics of real dash-cam footage and of our renders, side by side."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..files import write_atomic
from ..presets import CAMERA_PRESET_NAMES
from .base import Command, UsageError, count, output_file, parse_size

SHEET_PATH = Path("docs/images/realism-sheet.png")


def _realism_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--real", type=Path, default=None, metavar="DIR",
                        help="folder of real frames (png/jpg/jpeg, searched recursively)")
    parser.add_argument("--ours", type=Path, default=None, metavar="DIR",
                        help="folder of rendered frames (e.g. a lanevil dataset or export folder)")
    parser.add_argument("--limit", type=count(1), default=None, metavar="N",
                        help="analyse the first N images of each folder in sorted path order (default: all)")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    parser.add_argument("--out", type=Path, default=None, metavar="REPORT.md", help="also write a Markdown report")
    parser.add_argument("--sheet", type=Path, nargs="?", const=SHEET_PATH, default=None, metavar="PNG",
                        help="instead of statistics, render a side-by-side sheet (one PNG, default "
                             f"{SHEET_PATH}): one row per scene kind, our clean render left and, with --real DIR, "
                             "the first frame of DIR/<kind>/ right (highway, urban, suburban, rural, "
                             "tunnel_approach, night, wet; a source.txt there captions them)")
    parser.add_argument("--camera", default=None, choices=CAMERA_PRESET_NAMES, metavar="PRESET",
                        help="with --sheet: the camera our side is seen through (default carla, the paper's capture "
                             "camera): " + ", ".join(CAMERA_PRESET_NAMES))
    parser.add_argument("--size", type=parse_size, default=None, metavar="WxH",
                        help="with --sheet: the size of each tile (default 400x225)")
    parser.add_argument("--frame", type=count(0), default=None, metavar="N",
                        help="with --sheet: the frame of every drive (default 30; 0..49)")


def _run_realism(args: argparse.Namespace) -> int:
    from ..metrics.realism import ANALYSIS_WIDTH, RealismError, folder_statistics, summary, summary_dict
    from ..report.realism import comparison_rows, report_markdown, table_text

    if args.sheet is not None:
        return _run_sheet(args)
    for flag in ("camera", "size", "frame"):
        if getattr(args, flag) is not None:
            raise UsageError(f"--{flag} goes with --sheet")
    folders = {side: path for side, path in (("real", args.real), ("ours", args.ours)) if path is not None}
    if not folders:
        raise UsageError("give --real DIR, --ours DIR or both")
    if args.out is not None:
        output_file(args.out, "--out", "realism.md")
    summaries, sources = {}, {}
    for side, folder in folders.items():
        try:
            frames = folder_statistics(folder, args.limit)
        except RealismError as error:
            raise UsageError(f"--{side} {error}") from None
        summaries[side], sources[side] = summary(frames), (str(folder), len(frames))
    rows = comparison_rows(summaries.get("real"), summaries.get("ours"))
    if args.json:
        result = {"analysis_width": ANALYSIS_WIDTH,
                  **{side: {"folder": sources[side][0], "images": sources[side][1],
                            "statistics": summary_dict(summaries[side])} for side in folders},
                  "comparison": {row.name: {"ratio": row.ratio, "verdict": row.verdict} for row in rows
                                 if row.real is not None and row.ours is not None}}
        print(json.dumps(result))
    else:
        print(", ".join(f"{side}: {folder} ({images} images)" for side, (folder, images) in sources.items()))
        print(table_text(rows, "real" in folders, "ours" in folders))
    if args.out is not None:
        write_atomic(args.out, report_markdown(rows, sources).encode("utf-8"))
    return 0


def _run_sheet(args: argparse.Namespace) -> int:
    from ..images import png_bytes
    from ..metrics.realism import RealismError
    from ..report.realism_sheet import SHEET_CAMERA, SHEET_FRAME, SHEET_TILE, realism_sheet

    for flag in ("ours", "limit", "out"):
        if getattr(args, flag) is not None:
            raise UsageError(f"--{flag} does not go with --sheet (the sheet renders our side itself)")
    if args.json:
        raise UsageError("--json does not go with --sheet")
    output_file(args.sheet, "--sheet", "realism-sheet.png")
    if args.sheet.suffix.lower() != ".png":
        raise UsageError(f"--sheet {args.sheet}: the sheet is a PNG; name it *.png")
    frame = SHEET_FRAME if args.frame is None else args.frame
    if frame >= 50:
        raise UsageError("--frame must lie in 0..49 (every stock case has at least 50 frames)")
    try:
        rgb = realism_sheet(args.real, args.camera or SHEET_CAMERA, args.size or SHEET_TILE, frame)
    except RealismError as error:
        raise UsageError(f"--real {error}") from None
    args.sheet.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(args.sheet, png_bytes(rgb))
    print(args.sheet)
    return 0


COMMANDS: dict[str, Command] = {
    "realism": Command("image statistics (saturation, edges, contrast, noise, spectrum, sharpness) of real footage "
                       "and of renders side by side, or (--sheet) a picture of both side by side",
                       _realism_arguments, _run_realism),
}
