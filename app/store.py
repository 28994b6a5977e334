"""The case store: one JSON file per case under ``<data>/cases/``, versioned, written atomically.

A stored file is an envelope ``{"id", "version", "created_at", "updated_at", "origin", "case": {...}}``. Every write
bumps ``version``; a write that names a version other than the current one raises ``VersionConflict`` (HTTP 409),
so concurrent editors never silently overwrite each other. Ids are short slugs checked against ``ID_PATTERN``
before any path is built, so nothing outside the store's folder is ever read or written.

Listeners (``subscribe``) hear every change, whichever front end made it: the REST API and the editor share one
store object.
"""

from __future__ import annotations

import json
import re
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Any, Literal

from lanevil_core.case import Case, CaseError, case_json, load_case, parse_case
from lanevil_core.files import remove_stale_temps, write_atomic
from lanevil_core.library.benchmark_layout import case_illusion_type, case_name, case_types, folder_type, type_category
from lanevil_core.library.stock import CATEGORY_FOLDERS as STOCK_FOLDERS

from .meshes import legacy_mesh_files

ID_PATTERN = re.compile(r"^[a-z0-9][a-z0-9_-]{0,79}$")
CASES_FOLDER = "cases"
ChangeKind = Literal["created", "updated", "deleted"]
Listener = Callable[[ChangeKind, str, "CaseRecord | None"], None]


class StoreError(Exception):
    """Base of the store's errors; ``field`` names what was wrong for the HTTP response."""

    field: str = "case_id"


class InvalidId(StoreError):
    """An id that is not a slug (400/422)."""


class CaseNotFound(StoreError):
    """No case with that id (404)."""


class CaseExists(StoreError):
    """Creating a case under an id that is taken (409)."""


class VersionConflict(StoreError):
    """The writer's version is not the stored one (409)."""

    field = "version"

    def __init__(self, case_id: str, expected: int, current: int) -> None:
        super().__init__(f"case {case_id!r} is at version {current}, not {expected}: reload it and apply your change "
                         "again")
        self.expected = expected
        self.current = current


@dataclass(frozen=True)
class CaseRecord:
    """One stored case and its bookkeeping."""

    id: str
    version: int
    case: Case
    created_at: float
    updated_at: float
    origin: str | None = None  # e.g. "30_shadow/fence_shadow/00_uphill_rural_noon/00_original.json" (stock cases)

    @property
    def illusion_type(self) -> str | None:
        """The case's illusion type (several joined by ``+``: a mixed case), or for a stock original the type its
        folder names."""
        return case_illusion_type(self.case, _origin_type(self.origin))

    @property
    def illusion_types(self) -> tuple[str, ...]:
        """Every illusion type the case holds (its folder's for a stock original)."""
        return case_types(self.case, _origin_type(self.origin))

    @property
    def category(self) -> str:
        """``road_damage`` / ``traffic`` / ``shadow`` / ``reflection``, ``mixed`` (several types), or ``clean``."""
        illusion_type = self.illusion_type
        return type_category(illusion_type) if illusion_type else "clean"

    @property
    def severity(self) -> int:
        """Highest severity among the case's illusions (0 for a case without any)."""
        return max((illusion.severity for illusion in self.case.illusions), default=0)

    def summary(self) -> dict[str, Any]:
        """The listing row: id, title, category, type, severity, version and a few facts for browsing."""
        return {
            "id": self.id,
            "title": self.case.title,
            "category": self.category,
            "type": self.illusion_type,
            "severity": self.severity,
            "version": self.version,
            "road": self.case.road.type,
            "frames": self.case.ego.frames,
            "illusions": len(self.case.illusions),
            "updated_at": self.updated_at,
        }

    def envelope(self) -> dict[str, Any]:
        return {"id": self.id, "version": self.version, "created_at": self.created_at,
                "updated_at": self.updated_at, "origin": self.origin,
                "case": json.loads(case_json(self.case))}


def _origin_type(origin: str | None) -> str | None:
    """The illusion type a stock path files a case under (``30_shadow/fence_shadow/…`` -> ``fence_shadow``)."""
    if not origin:
        return None
    path = PurePosixPath(origin)
    return folder_type(path) if path.parts[0] in STOCK_FOLDERS.values() else None


def check_id(case_id: str) -> str:
    """Return ``case_id`` if it is a valid slug; raise ``InvalidId`` otherwise."""
    if not isinstance(case_id, str) or not ID_PATTERN.fullmatch(case_id):
        raise InvalidId(f"case id {case_id!r} must match {ID_PATTERN.pattern} (lowercase letters, digits, '_', '-')")
    return case_id


def slugify(text: str) -> str:
    """A valid id built from free text (a title, a path)."""
    slug = re.sub(r"[^a-z0-9_-]+", "-", text.lower()).strip("-_")[:64] or "case"
    return slug if slug[0].isalnum() else f"c{slug}"[:64]


def stock_id(relative: PurePosixPath) -> str:
    """Id of a stock case: ``00_clean/00_straight_urban.json`` -> ``clean-00_straight_urban``,
    ``30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json`` -> ``fence_shadow-00_uphill_rural_noon-03_level3``
    (and ``30_shadow/fence_shadow/03_level3.json`` of a folder per type -> ``fence_shadow-03_level3``)."""
    illusion_type = folder_type(relative)
    prefix = illusion_type or ("clean" if relative.parent.name == "00_clean" else relative.parent.name)
    name = case_name(relative).as_posix().replace("/", "-") if illusion_type else relative.stem
    return check_id(slugify(f"{prefix}-{name}"))


class CaseStore:
    """Thread-safe, versioned case files in ``root/cases``."""

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        self.folder = self.root / CASES_FOLDER
        self.folder.mkdir(parents=True, exist_ok=True)
        remove_stale_temps(self.folder)  # what a killed write of an earlier process left
        self._lock = threading.RLock()
        self._records: dict[str, CaseRecord] = {}
        self._listeners: list[Listener] = []
        for path in sorted(self.folder.glob("*.json")):
            record = self._read(path)
            self._records[record.id] = record

    # ------------------------------------------------------------------------------------------ files

    def _path(self, case_id: str) -> Path:
        return self.folder / f"{check_id(case_id)}.json"

    def _read(self, path: Path) -> CaseRecord:
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
            case = parse_case(legacy_mesh_files(data["case"]), source=str(path.name))
            return CaseRecord(id=check_id(data["id"]), version=int(data["version"]), case=case,
                              created_at=float(data["created_at"]), updated_at=float(data["updated_at"]),
                              origin=data.get("origin"))
        except (OSError, ValueError, KeyError, TypeError) as error:
            raise CaseError(f"{path}: not a stored case: {error}") from None

    def _write(self, record: CaseRecord) -> None:
        data = json.dumps(record.envelope(), indent=2, ensure_ascii=False) + "\n"
        write_atomic(self._path(record.id), data.encode("utf-8"))

    # ------------------------------------------------------------------------------------------ seeding

    def seed_from(self, scenes_dir: Path) -> int:
        """Copy every case under ``scenes_dir`` into an empty store; return how many were added."""
        with self._lock:
            if self._records:
                return 0
            added = 0
            for path in sorted(Path(scenes_dir).glob("**/*.json")):
                relative = PurePosixPath(path.relative_to(scenes_dir).as_posix())
                self.create(load_case(path), case_id=stock_id(relative), origin=relative.as_posix())
                added += 1
            return added

    # ------------------------------------------------------------------------------------------ queries

    def list(self, category: str | None = None, illusion_type: str | None = None) -> list[CaseRecord]:
        """Every record (sorted by id), optionally only one category and/or illusion type."""
        with self._lock:
            records = sorted(self._records.values(), key=lambda record: record.id)
        if category is not None:
            records = [record for record in records if record.category == category]
        if illusion_type is not None:
            records = [record for record in records if illusion_type in (record.illusion_type, *record.illusion_types)]
        return records

    def get(self, case_id: str) -> CaseRecord:
        check_id(case_id)
        with self._lock:
            record = self._records.get(case_id)
        if record is None:
            raise CaseNotFound(f"no case with id {case_id!r}")
        return record

    def __contains__(self, case_id: object) -> bool:
        return isinstance(case_id, str) and case_id in self._records

    def __len__(self) -> int:
        return len(self._records)

    # ------------------------------------------------------------------------------------------ changes

    def new_id(self, case: Case) -> str:
        """A free id derived from the case title."""
        base = slugify(case.title or "case")[:56]
        with self._lock:
            candidate, number = base, 1
            while candidate in self._records:
                number += 1
                candidate = f"{base}-{number}"
            return candidate

    def create(self, case: Case, case_id: str | None = None, origin: str | None = None) -> CaseRecord:
        """Store a new case (version 1) under ``case_id`` or a fresh id from its title."""
        with self._lock:
            case_id = check_id(case_id) if case_id is not None else self.new_id(case)
            if case_id in self._records:
                raise CaseExists(f"a case with id {case_id!r} exists already")
            now = time.time()
            record = CaseRecord(id=case_id, version=1, case=case, created_at=now, updated_at=now, origin=origin)
            self._write(record)
            self._records[case_id] = record
        self._notify("created", case_id, record)
        return record

    def update(self, case_id: str, case: Case, expected_version: int | None = None,
               on_stored: Callable[[CaseRecord], None] | None = None) -> CaseRecord:
        """Replace a case; with ``expected_version`` set, only if it is still the stored version.

        ``on_stored(record)`` runs once the file is written and before any listener hears of it, so a writer that
        listens too (an editor session) can take its new version first and not mistake its own write for
        someone else's."""
        with self._lock:
            current = self.get(case_id)
            if expected_version is not None and expected_version != current.version:
                raise VersionConflict(case_id, expected_version, current.version)
            record = CaseRecord(id=case_id, version=current.version + 1, case=case, created_at=current.created_at,
                                updated_at=max(time.time(), current.updated_at), origin=current.origin)
            self._write(record)
            self._records[case_id] = record
            if on_stored is not None:
                on_stored(record)
        self._notify("updated", case_id, record)
        return record

    def delete(self, case_id: str, expected_version: int | None = None) -> None:
        """Remove a case; with ``expected_version`` set, only if it is still the stored version."""
        with self._lock:
            current = self.get(case_id)
            if expected_version is not None and expected_version != current.version:
                raise VersionConflict(case_id, expected_version, current.version)
            self._path(case_id).unlink(missing_ok=True)
            del self._records[case_id]
        self._notify("deleted", case_id, None)

    # ------------------------------------------------------------------------------------------ listeners

    def subscribe(self, listener: Listener) -> Callable[[], None]:
        """Call ``listener(kind, case_id, record)`` after every change; returns a function that unsubscribes."""
        with self._lock:
            self._listeners.append(listener)

        def unsubscribe() -> None:
            with self._lock:
                if listener in self._listeners:
                    self._listeners.remove(listener)

        return unsubscribe

    def _notify(self, kind: ChangeKind, case_id: str, record: CaseRecord | None) -> None:
        with self._lock:
            listeners = list(self._listeners)
        for listener in listeners:
            listener(kind, case_id, record)


__all__ = ["CaseExists", "CaseNotFound", "CaseRecord", "CaseStore", "InvalidId", "StoreError",
           "VersionConflict", "check_id", "slugify", "stock_id"]
