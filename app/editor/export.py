"""Downloads from the editor: the case JSON, the current frame (PNG + TuSimple labels), the sequence zip.

The sequence is rendered by the backend's job manager (the same job and zip layout as ``POST /api/exports``);
the editor shows its progress in a notification and sends the zip when it is done.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable
from pathlib import PurePosixPath

from lanevil_core.case import Case, case_json
from lanevil_core.images import png_bytes
from lanevil_core.library.benchmark_layout import case_folder, frame_file

from ..jobs import Job, export_zip
from ..state import AppState

POLL_S = 0.5

Send = Callable[[str, bytes], None]
Notify = Callable[[str, str, bool, str | None], None]  # title, body, loading, colour


def case_download(case_id: str, case: Case) -> tuple[str, bytes]:
    """``<id>.json``: the canonical case JSON."""
    return f"{case_id}.json", case_json(case).encode("utf-8")


def frame_downloads(state: AppState, case_id: str, case: Case, frame: int) -> list[tuple[str, bytes]]:
    """The frame at the case camera's size as PNG and its TuSimple record (``raw_file`` = the PNG's name)."""
    rendered = state.frames.frame(case, frame)
    png_name = f"{case_id}_{frame_file(frame)}"
    record = {**rendered.record, "raw_file": png_name}
    return [(png_name, png_bytes(rendered.rgb)),
            (png_name.removesuffix(".png") + ".json", (json.dumps(record) + "\n").encode("utf-8"))]


def sequence_folder(case: Case, case_id: str, fallback_type: str | None) -> PurePosixPath:
    return case_folder(case, case_id, fallback_type)


def start_sequence_export(state: AppState, case_id: str, case: Case, fallback_type: str | None,
                          frames: range, send: Send, notify: Notify) -> Job:
    """Queue the zip export as a backend job; report progress through ``notify`` and send the zip when done."""
    folder = sequence_folder(case, case_id, fallback_type)
    job = state.jobs.submit("export", len(frames), lambda job, progress: export_zip(
        case, folder, frames, state.jobs.result_path(job.id), progress))
    threading.Thread(target=_follow, args=(job, case_id, send, notify), name="lanevil-editor-export",
                     daemon=True).start()
    return job


def _follow(job: Job, case_id: str, send: Send, notify: Notify) -> None:
    while not job.finished.wait(POLL_S):
        notify("Exporting sequence", f"{case_id}: {job.done} of {job.total} frames rendered", True, None)
    if job.status == "done" and job.result is not None:
        notify("Sequence exported", f"{case_id}: {job.total} frames, sending the zip", False, "green")
        send(f"{case_id}.zip", job.result.read_bytes())
    else:
        notify("Export failed", f"{case_id}: {job.error}", False, "red")
