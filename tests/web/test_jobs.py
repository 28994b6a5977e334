"""Background jobs keep a bounded number of finished results, clear what an earlier process left behind, share
identical work and refuse clients past the queue's limits."""

from __future__ import annotations

import threading
from collections.abc import Callable
from pathlib import Path

import pytest

from app.jobs import EXPORTS_FOLDER, SCRATCH_PREFIX, Job, JobLimit, JobManager, Progress


def _write_zip(folder: Path, name: str) -> Path:
    path = folder / f"{name}.zip"
    path.write_bytes(b"PK")
    return path


def test_only_the_newest_finished_jobs_and_zips_are_kept(tmp_path: Path) -> None:
    manager = JobManager(tmp_path, keep_finished=2)
    jobs = []
    for _ in range(4):
        job = manager.submit("export", 1, lambda job, progress: _write_zip(manager.folder, job.id))
        assert job.finished.wait(10)
        jobs.append(job)
    manager.shutdown(wait=True)
    assert sorted(path.name for path in manager.folder.glob("*.zip")) == sorted(f"{job.id}.zip" for job in jobs[2:])
    assert manager.get(jobs[-1].id).status == "done"
    assert all(job.id not in manager._jobs for job in jobs[:2])


def test_a_new_manager_clears_orphaned_results(tmp_path: Path) -> None:
    folder = tmp_path / EXPORTS_FOLDER
    (folder / f"{SCRATCH_PREFIX}abc").mkdir(parents=True)
    stray = [_write_zip(folder, "0" * 32), folder / ".x.zip.partial"]
    stray[1].write_bytes(b"")
    keep = folder / "notes.txt"
    keep.write_text("not ours")
    JobManager(tmp_path).shutdown()
    assert sorted(path.name for path in folder.iterdir()) == ["notes.txt"]


def _blocked(release: threading.Event) -> Callable[[Job, Progress], Path]:
    def work(job: Job, progress: Progress) -> Path:
        release.wait(30)
        return Path("unused")

    return work


def test_an_identical_job_is_shared_and_failed_ones_are_not(tmp_path: Path) -> None:
    manager = JobManager(tmp_path)
    release = threading.Event()
    try:
        first = manager.submit("export", 3, _blocked(release), key="same", client="a")
        assert manager.submit("export", 3, _blocked(release), key="same", client="b") is first
        release.set()
        assert first.finished.wait(10) and first.status == "done"
        assert manager.submit("export", 3, _blocked(release), key="same", client="a") is first  # finished: reused
        failing = manager.submit("export", 1, lambda job, progress: Path(str(1 / 0)), key="broken")
        assert failing.finished.wait(10) and failing.status == "failed"
        assert manager.submit("export", 1, _blocked(release), key="broken") is not failing
    finally:
        release.set()
        manager.shutdown(wait=True)


def test_full_queue_and_per_client_share_raise_job_limit(tmp_path: Path) -> None:
    manager = JobManager(tmp_path, max_unfinished=3, max_per_client=2)
    release = threading.Event()
    try:
        own_jobs = [manager.submit("export", 10, _blocked(release), key=f"a{index}", client="a") for index in range(2)]
        with pytest.raises(JobLimit, match="you have 2 jobs") as own:
            manager.submit("export", 10, _blocked(release), key="a2", client="a")
        assert 1 <= own.value.retry_after_s <= 3600
        manager.submit("export", 10, _blocked(release), key="b0", client="b")
        with pytest.raises(JobLimit, match="3 jobs queued or running"):
            manager.submit("export", 10, _blocked(release), key="c0", client="c")
        assert manager.submit("export", 10, _blocked(release), key="a0", client="a") is own_jobs[0]  # shared, not new
        study = manager.submit("study", 10, _blocked(release))  # the server's own jobs are never refused
        assert study.status in ("queued", "running")
    finally:
        release.set()
        manager.shutdown(wait=True)
