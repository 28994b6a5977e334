"""Rows of the study database as frozen dataclasses, and the queries that read and write them."""

from __future__ import annotations

import re
import sqlite3
import time
from dataclasses import asdict, dataclass
from typing import Any

STUDY_ID_PATTERN = re.compile(r"^[0-9a-f]{12}$")
PARTICIPANT_ID_PATTERN = re.compile(r"^[0-9a-f]{32}$")


class FieldError(Exception):
    """A study error that names the request field it is about (``field``), for the JSON error body."""

    def __init__(self, field: str, message: str) -> None:
        super().__init__(message)
        self.field = field


class NotFound(FieldError, LookupError):
    """An unknown study, item or participant; ``field`` names which (404)."""


@dataclass(frozen=True)
class Study:
    id: str
    title: str
    question: str
    consent_text: str
    instructions: str
    viewing_ms: int
    width: int
    height: int
    camera: str | None  # the camera preset generated items are seen through; None: each case's own
    status: str
    error: str | None
    job_id: str | None
    created_at: float

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class StudyItem:
    id: int
    study_id: str
    position: int
    role: str
    source: str
    case_id: str | None
    case_version: int | None
    frame: int | None
    upload_name: str | None
    illusion_type: str | None
    category: str | None
    severity: int | None
    garbled: int
    gold_min: int | None
    gold_max: int | None
    trap_answer: int | None
    file: str
    media_type: str

    @property
    def scored(self) -> bool:
        """Whether the item's ratings count (training items are practice)."""
        return self.role != "training"

    def to_dict(self) -> dict[str, Any]:
        return asdict(self) | {"image_url": image_url(self.study_id, self.id)}


@dataclass(frozen=True)
class Participant:
    id: str
    study_id: str
    consented_at: float
    completed_at: float | None


@dataclass(frozen=True)
class Rating:
    id: int
    participant_id: str
    item_id: int
    rating: int
    response_ms: int | None
    created_at: float


def image_url(study_id: str, item_id: int) -> str:
    return f"/api/study/studies/{study_id}/items/{item_id}/image"


def get_study(db: sqlite3.Connection, study_id: str) -> Study:
    row = None
    if STUDY_ID_PATTERN.fullmatch(study_id):
        row = db.execute("SELECT * FROM studies WHERE id = ?", (study_id,)).fetchone()
    if row is None:
        raise NotFound("study_id", f"no study with id {study_id!r}")
    return Study(**dict(row))


def list_studies(db: sqlite3.Connection) -> list[Study]:
    return [Study(**dict(row)) for row in db.execute("SELECT * FROM studies ORDER BY created_at, id")]


def study_items(db: sqlite3.Connection, study_id: str) -> list[StudyItem]:
    rows = db.execute("SELECT * FROM items WHERE study_id = ? ORDER BY position", (study_id,))
    return [StudyItem(**dict(row)) for row in rows]


def get_item(db: sqlite3.Connection, study_id: str, item_id: int) -> StudyItem:
    row = db.execute("SELECT * FROM items WHERE study_id = ? AND id = ?", (study_id, item_id)).fetchone()
    if row is None:
        raise NotFound("item_id", f"study {study_id!r} has no item {item_id}")
    return StudyItem(**dict(row))


def get_participant(db: sqlite3.Connection, study_id: str, participant_id: str) -> Participant:
    row = None
    if PARTICIPANT_ID_PATTERN.fullmatch(participant_id):
        row = db.execute("SELECT * FROM participants WHERE id = ? AND study_id = ?",
                         (participant_id, study_id)).fetchone()
    if row is None:
        raise NotFound("participant_id", f"study {study_id!r} has no participant {participant_id!r}")
    return Participant(**dict(row))


def add_participant(db: sqlite3.Connection, study_id: str, participant_id: str) -> Participant:
    now = time.time()
    db.execute("INSERT INTO participants (id, study_id, consented_at) VALUES (?, ?, ?)",
               (participant_id, study_id, now))
    return Participant(participant_id, study_id, now, None)


def complete_participant(db: sqlite3.Connection, participant_id: str) -> None:
    db.execute("UPDATE participants SET completed_at = ? WHERE id = ? AND completed_at IS NULL",
               (time.time(), participant_id))


def study_participants(db: sqlite3.Connection, study_id: str) -> list[Participant]:
    rows = db.execute("SELECT * FROM participants WHERE study_id = ? ORDER BY consented_at, id", (study_id,))
    return [Participant(**dict(row)) for row in rows]


def add_rating(db: sqlite3.Connection, participant_id: str, item_id: int, rating: int,
               response_ms: int | None) -> Rating:
    """Insert one rating; ``sqlite3.IntegrityError`` if this participant already rated this item."""
    now = time.time()
    cursor = db.execute("INSERT INTO ratings (participant_id, item_id, rating, response_ms, created_at) "
                        "VALUES (?, ?, ?, ?, ?)", (participant_id, item_id, rating, response_ms, now))
    return Rating(int(cursor.lastrowid or 0), participant_id, item_id, rating, response_ms, now)


def participant_ratings(db: sqlite3.Connection, participant_id: str) -> list[Rating]:
    rows = db.execute("SELECT * FROM ratings WHERE participant_id = ? ORDER BY id", (participant_id,))
    return [Rating(**dict(row)) for row in rows]


def study_ratings(db: sqlite3.Connection, study_id: str) -> list[Rating]:
    rows = db.execute("SELECT ratings.* FROM ratings JOIN participants ON participants.id = ratings.participant_id "
                      "WHERE participants.study_id = ? ORDER BY ratings.id", (study_id,))
    return [Rating(**dict(row)) for row in rows]


def set_status(db: sqlite3.Connection, study_id: str, status: str, error: str | None = None) -> None:
    db.execute("UPDATE studies SET status = ?, error = ? WHERE id = ?", (status, error, study_id))
