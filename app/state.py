"""What every route and the editor share: settings, the case store, the frame service and the job manager."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from fastapi import Request

from .frames import FrameService
from .jobs import JobManager
from .settings import Settings
from .store import CaseStore

UPLOADS_FOLDER = "uploads"


@dataclass
class AppState:
    """The shared services of one running backend (one per process)."""

    settings: Settings
    store: CaseStore
    frames: FrameService
    jobs: JobManager

    @property
    def meshes_dir(self) -> Path:
        """Where user meshes (a vehicle's ``mesh_file``) are uploaded to and read from: ``<data dir>/uploads``."""
        return uploads_dir(self.settings)

    @classmethod
    def open(cls, settings: Settings) -> AppState:
        """Open (and on first start seed) the store in ``settings.data_dir``."""
        data_dir = Path(settings.data_dir)
        data_dir.mkdir(parents=True, exist_ok=True)
        store = CaseStore(data_dir)
        if len(store) == 0 and Path(settings.scenes_dir).is_dir():
            store.seed_from(Path(settings.scenes_dir))
        uploads_dir(settings).mkdir(exist_ok=True)
        frames = FrameService(settings.frame_cache_bytes, settings.render_threads, meshes_dir=uploads_dir(settings),
                              scene_cache_bytes=settings.scene_cache_bytes, max_renders=settings.max_renders,
                              max_render_queue=settings.max_render_queue)
        return cls(settings=settings, store=store, frames=frames,
                   jobs=JobManager(data_dir, max_unfinished=settings.max_jobs,
                                   max_per_client=settings.max_jobs_per_client))


def uploads_dir(settings: Settings) -> Path:
    return Path(settings.data_dir) / UPLOADS_FOLDER


def get_state(request: Request) -> AppState:
    """FastAPI dependency: the ``AppState`` of the app serving this request."""
    return request.app.state.lanevil
