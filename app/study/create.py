"""Creating a study: check the spec against the case store and the uploads, render every image once, store rows.

Every stimulus is written once, at creation, to ``<data>/study/<study_id>/items/<position>.png|.jpg`` and served
from there; nothing is rendered per participant. Real uploads are stored byte for byte (unless garbled or given a
trap banner, which re-encodes them as PNG). A study with at most ``SYNC_RENDER_LIMIT`` generated frames renders
inside the request (201, status ``ready``); a larger one renders as a background job (202, status ``rendering``
until the job finishes, then ``ready`` or ``failed``). The rows are written before the job starts, so the study can
be polled at once; participants are turned away (409) until it is ready.
"""

from __future__ import annotations

import secrets
import shutil
import sqlite3
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lanevil_core.case import Case, seen_through
from lanevil_core.files import write_atomic
from lanevil_core.images import png_bytes

from ..frames import FrameService
from ..jobs import Job, JobManager
from ..settings import Settings
from ..store import CaseStore, StoreError
from .db import connect, db_path, transaction
from .images import CheckedUpload, decode_rgb, garble, trap_banner
from .records import FieldError, Study, get_study, set_status
from .spec import ItemSpec, StudySpec

SYNC_RENDER_LIMIT = 8
STUDY_FOLDER = "study"
Progress = Callable[[int, int], None]


class SpecError(FieldError, ValueError):
    """A study spec that names something that does not exist or does not fit; ``field`` says where (422)."""


@dataclass(frozen=True)
class PreparedItem:
    """An item spec resolved against the store and the uploads, with the file it will be written to."""

    position: int
    spec: ItemSpec
    file: str
    media_type: str
    case: Case | None = None
    case_version: int | None = None
    illusion_type: str | None = None
    category: str | None = None
    severity: int | None = None
    upload: CheckedUpload | None = None

    @property
    def re_encoded(self) -> bool:
        """Whether the stored file is derived pixels (PNG) rather than the uploaded bytes."""
        return self.spec.garble or self.spec.role == "trap"


def study_folder(data_dir: Path, study_id: str) -> Path:
    return Path(data_dir) / STUDY_FOLDER / study_id


def items_folder(data_dir: Path, study_id: str) -> Path:
    return study_folder(data_dir, study_id) / "items"


def prepare_items(spec: StudySpec, uploads: Mapping[str, CheckedUpload], store: CaseStore,
                  settings: Settings) -> list[PreparedItem]:
    """Resolve every item of ``spec``; raise ``SpecError`` naming the first field that does not fit."""
    if spec.width > settings.max_width or spec.height > settings.max_height:
        raise SpecError("spec.width", f"render size {spec.width}x{spec.height} exceeds the limit "
                                      f"{settings.max_width}x{settings.max_height}")
    items = spec.all_items(sorted(uploads))
    if not any(item.role == "test" for item in items):
        raise SpecError("spec.items", "a study needs at least one scored (role 'test') item")
    return [_prepare(position, item, uploads, store, spec.camera) for position, item in enumerate(items)]


def _prepare(position: int, item: ItemSpec, uploads: Mapping[str, CheckedUpload], store: CaseStore,
             camera: str | None) -> PreparedItem:
    field = f"spec.items.{position}"
    if item.case_id is not None:
        try:
            record = store.get(item.case_id)
        except StoreError as error:
            raise SpecError(f"{field}.case_id", str(error)) from None
        if item.frame >= record.case.ego.frames:
            raise SpecError(f"{field}.frame", f"frame {item.frame} is outside 0..{record.case.ego.frames - 1} "
                                              f"of case {item.case_id!r}")
        case = record.case if camera is None else seen_through(record.case, camera)
        return PreparedItem(position, item, f"{position:03d}.png", "image/png", case=case,
                            case_version=record.version, illusion_type=record.illusion_type,
                            category=record.category, severity=record.severity)
    upload = uploads.get(item.upload or "")
    if upload is None:
        raise SpecError(f"{field}.upload", f"no uploaded file is named {item.upload!r} "
                                           f"(uploaded: {', '.join(sorted(uploads)) or 'none'})")
    if item.garble or item.role == "trap":
        return PreparedItem(position, item, f"{position:03d}.png", "image/png", upload=upload)
    return PreparedItem(position, item, f"{position:03d}{upload.suffix}", upload.media_type, upload=upload)


def item_pixels(item: PreparedItem, frames: FrameService, size: tuple[int, int]) -> np.ndarray:
    """(H, W, 3) uint8 pixels of a re-encoded or generated item, after garbling and the trap banner."""
    if item.case is not None:
        rgb = frames.frame(item.case, item.spec.frame, size).rgb
    else:
        assert item.upload is not None
        rgb = decode_rgb(item.upload.data)
    if item.spec.garble:
        rgb = garble(rgb, seed=item.position)
    if item.spec.answer is not None:
        rgb = trap_banner(rgb, item.spec.answer)
    return rgb


def write_item(folder: Path, item: PreparedItem, frames: FrameService, size: tuple[int, int]) -> None:
    """Write one item's image file (uploaded bytes as they came, everything else as PNG)."""
    if item.upload is not None and not item.re_encoded:
        write_atomic(folder / item.file, item.upload.data)
    else:
        write_atomic(folder / item.file, png_bytes(item_pixels(item, frames, size)))


def write_items(folder: Path, items: Sequence[PreparedItem], frames: FrameService, size: tuple[int, int],
                progress: Progress | None = None) -> None:
    for done, item in enumerate(items, start=1):
        write_item(folder, item, frames, size)
        if progress:
            progress(done, len(items))


def insert_study(db: sqlite3.Connection, study_id: str, spec: StudySpec, items: Sequence[PreparedItem],
                 status: str) -> None:
    """The study row and its item rows, in one transaction."""
    with transaction(db):
        db.execute("INSERT INTO studies (id, title, question, consent_text, instructions, viewing_ms, width, "
                   "height, camera, status, created_at) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                   (study_id, spec.title, spec.question, spec.consent_text, spec.instructions,
                    round(spec.viewing_seconds * 1000), spec.width, spec.height, spec.camera, status, time.time()))
        db.executemany(
            "INSERT INTO items (study_id, position, role, source, case_id, case_version, frame, upload_name, "
            "illusion_type, category, severity, garbled, gold_min, gold_max, trap_answer, file, media_type) "
            "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            [(study_id, item.position, item.spec.role, item.spec.source, item.spec.case_id, item.case_version,
              item.spec.frame if item.case is not None else None, item.spec.upload, item.illusion_type,
              item.category, item.severity, int(item.spec.garble),
              item.spec.expect[0] if item.spec.expect else None,
              item.spec.expect[1] if item.spec.expect else None, item.spec.answer, item.file, item.media_type)
             for item in items])


def create_study(db: sqlite3.Connection, settings: Settings, store: CaseStore, frames: FrameService,
                 jobs: JobManager, spec: StudySpec, uploads: Mapping[str, CheckedUpload]) -> tuple[Study, Job | None]:
    """Check, render (now or as a job) and store a new study; return it and its render job, if any. A size the
    spec does not give is the default within the server's largest."""
    spec = spec.model_copy(update={name: min(getattr(spec, name), getattr(settings, f"max_{name}"))
                                   for name in ("width", "height") if name not in spec.model_fields_set})
    items = prepare_items(spec, uploads, store, settings)
    study_id = secrets.token_hex(6)
    folder = items_folder(settings.data_dir, study_id)
    folder.mkdir(parents=True, exist_ok=True)
    size = (spec.width, spec.height)
    rendered = [item for item in items if item.case is not None]
    if len(rendered) <= SYNC_RENDER_LIMIT:
        try:
            write_items(folder, items, frames, size)
        except BaseException:
            shutil.rmtree(study_folder(settings.data_dir, study_id), ignore_errors=True)
            raise
        insert_study(db, study_id, spec, items, "ready")
        return get_study(db, study_id), None
    write_items(folder, [item for item in items if item.case is None], frames, size)
    insert_study(db, study_id, spec, items, "rendering")
    job = jobs.submit("study", len(rendered), _render_job(settings, study_id, folder, rendered, frames, size))
    db.execute("UPDATE studies SET job_id = ? WHERE id = ?", (job.id, study_id))
    return get_study(db, study_id), job


def _render_job(settings: Settings, study_id: str, folder: Path, items: Sequence[PreparedItem],
                frames: FrameService, size: tuple[int, int]) -> Callable[[Job, Progress], Path]:
    def work(job: Job, progress: Progress) -> Path:
        db = connect(db_path(settings.data_dir))
        try:
            write_items(folder, items, frames, size, progress)
            set_status(db, study_id, "ready")
        except Exception as error:
            set_status(db, study_id, "failed", f"{type(error).__name__}: {error}")
            raise
        finally:
            db.close()
        return folder

    return work
