"""A drive's files: ``trace.csv``, ``summary.json``, ``trace.png``, ``path.png`` and ``drive.mp4`` (or ``.gif``)."""

from __future__ import annotations

import csv
import io
import json
import time
from dataclasses import dataclass
from pathlib import Path

from ..case import Case
from ..files import write_atomic
from ..pipeline.compile import compile_scene
from .loop import DriveSettings, DriveTrace, Progress, drive_case
from .plots import path_plot, plots_available, trace_plot
from .summary import DriveSummary, summarize
from .video import DriveVideo

TRACE_FILE = "trace.csv"
SUMMARY_FILE = "summary.json"
TRACE_PLOT_FILE = "trace.png"
PATH_PLOT_FILE = "path.png"
VIDEO_FILE = "drive.mp4"
TRACE_COLUMNS = ("frame", "time", "s", "t", "deviation", "heading_error", "steer", "steer_command",
                 "estimated_offset", "accuracy", "lanes", "source", "x", "y", "yaw")


def trace_csv(trace: DriveTrace) -> str:
    """One row per step (m, s, radians): the columns of ``TRACE_COLUMNS``."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(TRACE_COLUMNS)
    for step in trace.steps:
        writer.writerow([step.frame, f"{step.time:.3f}", f"{step.s_road:.4f}", f"{step.t_road:.5f}",
                         f"{step.deviation:.5f}", f"{step.heading_error:.6f}", f"{step.steer:.6f}",
                         f"{step.steer_command:.6f}", f"{step.estimated_offset:.5f}", f"{step.accuracy:.4f}",
                         step.lanes, step.source, f"{step.x_world:.4f}", f"{step.y_world:.4f}", f"{step.yaw:.6f}"])
    return buffer.getvalue()


def summary_json(summary: DriveSummary) -> str:
    return json.dumps(summary.as_dict(), indent=2) + "\n"


@dataclass(frozen=True)
class DriveOutput:
    """A drive written to ``out_dir``: its summary and the files (by name)."""

    out_dir: Path
    summary: DriveSummary
    files: dict[str, Path]
    trace: DriveTrace


def write_drive(trace: DriveTrace, summary: DriveSummary, out_dir: Path, plots: bool = True) -> dict[str, Path]:
    """Write the trace, the summary and (with ``plots``, when matplotlib is installed) the two plots into
    ``out_dir``."""
    files = {TRACE_FILE: trace_csv(trace).encode("utf-8"), SUMMARY_FILE: summary_json(summary).encode("utf-8")}
    if plots and plots_available():
        files[TRACE_PLOT_FILE] = trace_plot(trace, summary)
        files[PATH_PLOT_FILE] = path_plot(trace, summary)
    for name, data in files.items():
        write_atomic(out_dir / name, data)
    return {name: out_dir / name for name in files}


def drive_to_folder(case: Case, settings: DriveSettings, out_dir: str | Path, video: bool = True,
                    plots: bool = True, progress: Progress | None = None,
                    meshes_dir: Path | None = None) -> DriveOutput:
    """Drive ``case`` and write every output into ``out_dir`` (created); ``mesh_file`` models come from
    ``meshes_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    recorder = DriveVideo(out_dir / VIDEO_FILE, case.ego.fps) if video else None
    started = time.perf_counter()
    scene = compile_scene(case, meshes_dir=meshes_dir)
    trace = drive_case(case, settings, on_step=recorder, progress=progress, scene=scene)
    wall = time.perf_counter() - started
    summary = summarize(trace, wall)
    files = write_drive(trace, summary, out_dir, plots)
    if recorder is not None:
        path = recorder.close()
        files[path.name] = path
    return DriveOutput(out_dir, summary, files, trace)
