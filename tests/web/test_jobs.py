"""Background jobs keep a bounded number of finished results and clear what an earlier process left behind."""

from __future__ import annotations

from pathlib import Path

from app.jobs import EXPORTS_FOLDER, SCRATCH_PREFIX, JobManager


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
