"""Background jobs with progress (long exports), so no request hangs while hundreds of frames render.

``JobManager.submit`` runs ``work(progress)`` on a small worker pool; ``progress(done, total)`` updates the job
that ``GET /api/exports/{job_id}`` and the editor's notifications read. Finished zips live under
``<data>/exports/<job_id>.zip``.

Jobs a client asks for are bounded: a submission with the ``key`` of a queued, running or finished job gets that
job back instead of a new one, and one that would pass ``max_unfinished`` jobs in all or ``max_per_client`` for its
client raises ``JobLimit`` (HTTP 429 with ``Retry-After``). Jobs the server starts itself (a study's renders) pass
no client and are never refused, though they count towards the total.
"""

from __future__ import annotations

import logging
import math
import re
import shutil
import tempfile
import threading
import time
import uuid
import zipfile
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any, Literal

from lanevil_core.case import Case
from lanevil_core.drive.loop import DriveSettings
from lanevil_core.export.case import export_case

JobStatus = Literal["queued", "running", "done", "failed", "cancelled"]
Progress = Callable[[int, int], None]
JOB_ID_PATTERN = re.compile(r"^[0-9a-f]{32}$")
EXPORTS_FOLDER = "exports"
KEEP_FINISHED = 32  # finished jobs (and their zips) kept for polling and download; older ones are dropped
MAX_UNFINISHED = 16  # queued or running jobs in all before clients are told to come back later
MAX_PER_CLIENT = 4  # queued or running jobs of one client
SECONDS_PER_STEP = 0.3  # a frame at 1280x720 before any job has finished (then measured)
RETRY_AFTER_S = (1, 3600)
SCRATCH_PREFIX = "lanevil-export-"
DRIVE_PREFIX = "lanevil-drive-"  # a drive job's output folder: lanevil-drive-<job id>/


class JobNotFound(LookupError):
    """No job with that id (404)."""


class JobLimit(Exception):
    """Too many unfinished jobs, in all or of one client (429); ``retry_after_s`` estimates when one is free."""

    def __init__(self, message: str, retry_after_s: int) -> None:
        super().__init__(message)
        self.retry_after_s = retry_after_s


class JobCancelled(Exception):
    """Raised inside a job's ``progress`` callback once the job was cancelled, to stop its work."""


LOG = logging.getLogger(__name__)


@dataclass
class Job:
    """One background job; fields are read by pollers while the worker updates them."""

    id: str
    kind: str
    total: int
    done: int = 0
    status: JobStatus = "queued"
    error: str | None = None
    result: Path | None = None
    created_at: float = field(default_factory=time.time)
    finished_at: float | None = None
    meta: dict[str, Any] = field(default_factory=dict)  # what the job works on (e.g. case id and frames)
    key: str | None = field(default=None, repr=False)  # equal keys: equal work, so the job is shared
    client: str | None = field(default=None, repr=False)  # who asked for it (limits per client)
    started_at: float | None = None
    finished: threading.Event = field(default_factory=threading.Event, repr=False)
    cancel_requested: threading.Event = field(default_factory=threading.Event, repr=False)

    def to_dict(self) -> dict[str, Any]:
        return {**self.meta, "id": self.id, "kind": self.kind, "status": self.status, "done": self.done,
                "total": self.total, "progress": self.done / self.total if self.total else 1.0, "error": self.error,
                "created_at": self.created_at, "finished_at": self.finished_at}


class JobManager:
    """Runs jobs on ``workers`` threads and keeps their state (and result files under ``root/exports``)."""

    def __init__(self, root: Path, workers: int = 1, keep_finished: int = KEEP_FINISHED,
                 max_unfinished: int = MAX_UNFINISHED, max_per_client: int = MAX_PER_CLIENT) -> None:
        self.folder = Path(root) / EXPORTS_FOLDER
        self.folder.mkdir(parents=True, exist_ok=True)
        self.keep_finished = keep_finished
        self.workers = workers
        self.max_unfinished = max_unfinished
        self.max_per_client = max_per_client
        self._seconds_per_step = SECONDS_PER_STEP
        self._pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="lanevil-job")
        self._jobs: dict[str, Job] = {}
        self._lock = threading.Lock()
        self._purge_orphans()

    def _purge_orphans(self) -> None:
        """Delete what an earlier process left in the exports folder: its jobs lived in its memory, so nobody can
        poll or download them any more."""
        for path in self.folder.iterdir():
            if path.is_dir() and path.name.startswith((SCRATCH_PREFIX, DRIVE_PREFIX)):
                shutil.rmtree(path, ignore_errors=True)
            elif path.is_file() and (path.suffix == ".zip" or path.name.endswith(".partial")):
                path.unlink(missing_ok=True)

    def _prune(self) -> None:
        """Forget all but the newest ``keep_finished`` finished jobs and delete their zips."""
        with self._lock:
            finished = sorted((job for job in self._jobs.values() if job.finished.is_set()),
                              key=lambda job: job.finished_at or 0.0)
            dropped = finished[:max(len(finished) - self.keep_finished, 0)]
            for job in dropped:
                del self._jobs[job.id]
        for job in dropped:
            if job.result is not None and job.result.parent == self.folder:
                if job.result.is_dir():
                    shutil.rmtree(job.result, ignore_errors=True)
                else:
                    job.result.unlink(missing_ok=True)

    def submit(self, kind: str, total: int, work: Callable[[Job, Progress], Path],
               meta: dict[str, Any] | None = None, key: str | None = None, client: str | None = None) -> Job:
        """Queue ``work(job, progress) -> result path``; return the job at once. ``meta`` is reported with it.

        With ``key``: a queued, running or finished (not failed or cancelled) job of the same key is returned
        instead. With ``client``: ``JobLimit`` if the queue or this client's share of it is full."""
        with self._lock:
            same = self._find(key)
            if same is not None:
                return same
            if client is not None:
                self._check_limits(client)
            job = Job(id=uuid.uuid4().hex, kind=kind, total=total, meta=dict(meta or {}), key=key, client=client)
            self._jobs[job.id] = job
        self._pool.submit(self._run, job, work)
        return job

    def _find(self, key: str | None) -> Job | None:
        if key is None:
            return None
        return next((job for job in self._jobs.values()
                     if job.key == key and job.status in ("queued", "running", "done")
                     and not job.cancel_requested.is_set()), None)

    def _check_limits(self, client: str) -> None:
        unfinished = sorted((job for job in self._jobs.values() if not job.finished.is_set()),
                            key=lambda job: job.created_at)
        if len(unfinished) >= self.max_unfinished:
            wait = self._retry_after(unfinished[:len(unfinished) - self.max_unfinished + 1])
            raise JobLimit(f"the server has {len(unfinished)} jobs queued or running, the most it takes; "
                           f"try again in {wait} s", wait)
        own = [job for job in unfinished if job.client == client]
        if len(own) >= self.max_per_client:
            ahead = unfinished[:unfinished.index(own[0]) + 1]  # this client's oldest job and what runs before it
            wait = self._retry_after(ahead)
            raise JobLimit(f"you have {len(own)} jobs queued or running, the most one client may have; wait for "
                           f"one to finish (about {wait} s) or cancel one", wait)

    def _retry_after(self, ahead: list[Job]) -> int:
        """Seconds until the jobs ``ahead`` are done, from the measured time per step (frame)."""
        steps = sum(max(job.total - job.done, 0) for job in ahead)
        seconds = math.ceil(steps * self._seconds_per_step / max(self.workers, 1))
        return min(max(seconds, RETRY_AFTER_S[0]), RETRY_AFTER_S[1])

    def _run(self, job: Job, work: Callable[[Job, Progress], Path]) -> None:
        if job.cancel_requested.is_set():
            job.status = "cancelled"
            job.finished_at = time.time()
            job.finished.set()
            return
        job.status = "running"
        job.started_at = time.time()

        def progress(done: int, total: int) -> None:
            job.done, job.total = done, total
            if job.cancel_requested.is_set():
                raise JobCancelled(job.id)

        try:
            job.result = work(job, progress)
            job.done = job.total
            job.status = "done"
            if job.total:
                self._seconds_per_step = (time.time() - job.started_at) / job.total
        except JobCancelled:
            job.status = "cancelled"
        except ValueError as error:  # input the job cannot use (a mesh removed since): its message names the field
            job.error = f"{type(error).__name__}: {error}"
            job.status = "failed"
        except Exception as error:  # noqa: BLE001 - a failed job reports its error instead of killing the worker
            LOG.exception("job %s failed", job.id)  # the details (paths, tracebacks) go to the server's log only
            job.error = f"{type(error).__name__}: the job stopped on a server error"
            job.status = "failed"
        job.finished_at = time.time()
        job.finished.set()
        self._prune()

    def get(self, job_id: str) -> Job:
        with self._lock:
            job = self._jobs.get(job_id) if JOB_ID_PATTERN.fullmatch(job_id or "") else None
        if job is None:
            raise JobNotFound(f"no job with id {job_id!r}")
        return job

    def result_path(self, job_id: str) -> Path:
        """Where a job's zip goes (the id is checked, so the path stays in the exports folder)."""
        if not JOB_ID_PATTERN.fullmatch(job_id):
            raise JobNotFound(f"no job with id {job_id!r}")
        return self.folder / f"{job_id}.zip"

    def drive_folder(self, job_id: str) -> Path:
        """Where a drive job writes its files (the id is checked, so the path stays in the exports folder)."""
        if not JOB_ID_PATTERN.fullmatch(job_id):
            raise JobNotFound(f"no job with id {job_id!r}")
        return self.folder / f"{DRIVE_PREFIX}{job_id}"

    def cancel(self, job_id: str) -> Job:
        """Ask a job to stop: a queued job never starts, a running one stops at its next progress report."""
        job = self.get(job_id)
        if job.status in ("queued", "running"):
            job.cancel_requested.set()
        return job

    def shutdown(self, wait: bool = False) -> None:
        """Cancel every unfinished job and stop the workers (a running job stops at its next frame)."""
        with self._lock:
            jobs = list(self._jobs.values())
        for job in jobs:
            job.cancel_requested.set()
        self._pool.shutdown(wait=wait, cancel_futures=True)


def zip_folder(source: Path, target: Path, prefix: PurePosixPath) -> None:
    """Zip every file under ``source`` as ``prefix/<relative path>`` (sorted, fixed timestamps), atomically."""
    partial = target.with_name(f".{target.name}.partial")
    with zipfile.ZipFile(partial, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for path in sorted(p for p in source.rglob("*") if p.is_file()):
            info = zipfile.ZipInfo(str(prefix / path.relative_to(source).as_posix()), date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            archive.writestr(info, path.read_bytes())
    partial.replace(target)


def export_zip(case: Case, folder: PurePosixPath, frames: Iterable[int], target: Path,
               progress: Progress | None = None, meshes_dir: Path | None = None) -> Path:
    """Render ``frames`` of ``case`` with TuSimple labels into a zip laid out as the benchmark
    (``folder/000000.png … labels.json case.json``, ``folder`` = ``Category/Type/case``)."""
    with tempfile.TemporaryDirectory(prefix=SCRATCH_PREFIX, dir=target.parent) as scratch:
        export_case(case, scratch, frames=list(frames), formats={"tusimple"}, progress=progress,
                    meshes_dir=meshes_dir)
        zip_folder(Path(scratch), target, folder)
    return target


def drive_job(jobs: JobManager, case: Case, settings: DriveSettings, meta: dict[str, Any] | None = None,
              key: str | None = None, client: str | None = None, meshes_dir: Path | None = None) -> Job:
    """Queue a closed-loop drive of ``case``; the job's result is its folder of files (``lanevil_core.drive``).
    ``key`` and ``client`` as in ``JobManager.submit`` (the same drive shared, a client's share bounded)."""
    from lanevil_core.drive.outputs import drive_to_folder

    steps = max(1, round(settings.duration(case) * case.ego.fps))

    def work(job: Job, progress: Progress) -> Path:
        folder = jobs.drive_folder(job.id)
        drive_to_folder(case, settings, folder, video=True, progress=progress, meshes_dir=meshes_dir)
        return folder

    return jobs.submit("drive", steps, work, meta, key=key, client=client)
