"""``lanevil realism``: image statistics of real dash-cam footage and of our renders, side by side."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..files import write_atomic
from .base import Command, UsageError, count, output_file


def _realism_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--real", type=Path, default=None, metavar="DIR",
                        help="folder of real frames (png/jpg/jpeg, searched recursively)")
    parser.add_argument("--ours", type=Path, default=None, metavar="DIR",
                        help="folder of rendered frames (e.g. a lanevil dataset or export folder)")
    parser.add_argument("--limit", type=count(1), default=None, metavar="N",
                        help="analyse the first N images of each folder in sorted path order (default: all)")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    parser.add_argument("--out", type=Path, default=None, metavar="REPORT.md", help="also write a Markdown report")


def _run_realism(args: argparse.Namespace) -> int:
    from ..metrics.realism import ANALYSIS_WIDTH, RealismError, folder_statistics, summary, summary_dict
    from ..report.realism import comparison_rows, report_markdown, table_text

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


COMMANDS: dict[str, Command] = {
    "realism": Command("image statistics (saturation, edges, contrast, noise, spectrum, sharpness) of real footage "
                       "and of renders side by side", _realism_arguments, _run_realism),
}
