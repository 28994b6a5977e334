"""Editing state of one stored case in one browser tab: undo/redo, dirty, version.

The session holds the case being edited and the store version it is based on. ``save`` goes through the same
version check as the REST API, so a save over someone else's newer version raises ``VersionConflict`` and the
edits stay in the session (nothing is lost). Changes that arrive from the store (another tab's save, a REST
``PUT``) replace a clean session at once; a session with unsaved edits keeps them and remembers the newer version.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

from lanevil_core.case import Case, case_json

from ..store import CaseRecord, CaseStore

UNDO_LIMIT = 200


@dataclass(frozen=True)
class Step:
    """One undoable change: the case before it, and what it was (for the status line)."""

    case: Case
    label: str


class CaseSession:
    """The case being edited, its undo/redo stacks and the store version it is based on (thread-safe)."""

    def __init__(self, record: CaseRecord) -> None:
        self.case_id = record.id
        self._lock = threading.RLock()
        self._case = record.case
        self._saved_json = case_json(record.case)
        self.version = record.version
        self.remote_version: int | None = None  # a newer stored version this session has not taken
        self._undo: list[Step] = []
        self._redo: list[Step] = []

    @property
    def case(self) -> Case:
        return self._case

    @property
    def dirty(self) -> bool:
        """True while the case differs from the stored version it is based on."""
        return case_json(self._case) != self._saved_json

    @property
    def can_undo(self) -> bool:
        return bool(self._undo)

    @property
    def can_redo(self) -> bool:
        return bool(self._redo)

    def apply(self, case: Case, label: str) -> bool:
        """Make ``case`` the current case (undoable); False when nothing changed."""
        with self._lock:
            if case_json(case) == case_json(self._case):
                return False
            self._undo.append(Step(self._case, label))
            del self._undo[:-UNDO_LIMIT]
            self._redo.clear()
            self._case = case
            return True

    def undo(self) -> str | None:
        """Step back; returns the label of the undone change, or None if there was nothing to undo."""
        with self._lock:
            if not self._undo:
                return None
            step = self._undo.pop()
            self._redo.append(Step(self._case, step.label))
            self._case = step.case
            return step.label

    def redo(self) -> str | None:
        """Step forward again; returns the label of the redone change, or None."""
        with self._lock:
            if not self._redo:
                return None
            step = self._redo.pop()
            self._undo.append(Step(self._case, step.label))
            self._case = step.case
            return step.label

    def save(self, store: CaseStore) -> CaseRecord:
        """Write the case if the stored version is still the one it is based on; raises ``VersionConflict``."""
        with self._lock:
            # take the new version inside the store's update, before its listeners (this session's editor among
            # them) hear of it: our own write is then never mistaken for a newer version stored elsewhere
            return store.update(self.case_id, self._case, expected_version=self.version,
                                on_stored=lambda record: self._taken(record, keep_case=True))

    def reload(self, record: CaseRecord) -> None:
        """Take the stored ``record``, undoably (Undo brings the local edits back)."""
        with self._lock:
            if case_json(record.case) != case_json(self._case):
                self._undo.append(Step(self._case, "reload"))
                self._redo.clear()
            self._taken(record, keep_case=False)

    def stored_change(self, record: CaseRecord) -> bool:
        """A newer version arrived from the store: take it if there are no unsaved edits (returns True), else
        keep the edits and remember the version (returns False)."""
        with self._lock:
            if record.version <= self.version:
                return False
            if self.dirty:
                self.remote_version = record.version
                return False
            self.reload(record)
            return True

    def _taken(self, record: CaseRecord, keep_case: bool) -> None:
        if not keep_case:
            self._case = record.case
        self._saved_json = case_json(record.case)
        self.version = record.version
        self.remote_version = None


class SessionRegistry:
    """A tab's ``CaseSession``s, one per case id it opened (switching back to a case finds its unsaved edits)."""

    def __init__(self, store: CaseStore) -> None:
        self.store = store
        self._sessions: dict[str, CaseSession] = {}
        self._lock = threading.Lock()

    def open(self, case_id: str) -> CaseSession:
        """The session of ``case_id`` (opened from the store on first use; raises ``CaseNotFound``)."""
        with self._lock:
            session = self._sessions.get(case_id)
            if session is None:
                session = CaseSession(self.store.get(case_id))
                self._sessions[case_id] = session
            return session

    def get(self, case_id: str) -> CaseSession | None:
        with self._lock:
            return self._sessions.get(case_id)

    def drop(self, case_id: str) -> None:
        with self._lock:
            self._sessions.pop(case_id, None)
