"""The study database: SQLite in WAL mode at ``<data>/study.sqlite3``, one short-lived connection per request.

WAL lets participants' rating inserts and the organiser's reads run side by side; ``busy_timeout`` makes a writer
wait for the write lock instead of failing. Every write is a single autocommitted statement or an explicit
``BEGIN IMMEDIATE`` transaction (a deferred transaction that upgrades to a write can fail with SQLITE_BUSY without
waiting). ``UNIQUE(participant_id, item_id)`` makes a second rating of the same item impossible, whatever the
concurrency: the insert raises ``sqlite3.IntegrityError`` and the API answers 409.
"""

from __future__ import annotations

import sqlite3
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

DB_FILE = "study.sqlite3"
BUSY_TIMEOUT_MS = 15_000

SCHEMA = """
CREATE TABLE IF NOT EXISTS studies (
    id TEXT PRIMARY KEY,
    title TEXT NOT NULL,
    question TEXT NOT NULL,
    consent_text TEXT NOT NULL,
    instructions TEXT NOT NULL,
    viewing_ms INTEGER NOT NULL,
    width INTEGER NOT NULL,
    height INTEGER NOT NULL,
    camera TEXT,
    status TEXT NOT NULL CHECK (status IN ('rendering', 'ready', 'failed')),
    error TEXT,
    job_id TEXT,
    created_at REAL NOT NULL
);
CREATE TABLE IF NOT EXISTS items (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    study_id TEXT NOT NULL REFERENCES studies(id) ON DELETE CASCADE,
    position INTEGER NOT NULL,
    role TEXT NOT NULL CHECK (role IN ('test', 'training', 'gold', 'trap')),
    source TEXT NOT NULL CHECK (source IN ('synthetic', 'real')),
    case_id TEXT,
    case_version INTEGER,
    frame INTEGER,
    upload_name TEXT,
    illusion_type TEXT,
    category TEXT,
    severity INTEGER,
    garbled INTEGER NOT NULL DEFAULT 0,
    gold_min INTEGER,
    gold_max INTEGER,
    trap_answer INTEGER,
    file TEXT NOT NULL,
    media_type TEXT NOT NULL,
    UNIQUE (study_id, position)
);
CREATE TABLE IF NOT EXISTS participants (
    id TEXT PRIMARY KEY,
    study_id TEXT NOT NULL REFERENCES studies(id) ON DELETE CASCADE,
    consented_at REAL NOT NULL,
    completed_at REAL
);
CREATE TABLE IF NOT EXISTS ratings (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    participant_id TEXT NOT NULL REFERENCES participants(id) ON DELETE CASCADE,
    item_id INTEGER NOT NULL REFERENCES items(id) ON DELETE CASCADE,
    rating INTEGER NOT NULL CHECK (rating BETWEEN 1 AND 5),
    response_ms INTEGER,
    created_at REAL NOT NULL,
    UNIQUE (participant_id, item_id)
);
CREATE INDEX IF NOT EXISTS items_by_study ON items (study_id, position);
CREATE INDEX IF NOT EXISTS participants_by_study ON participants (study_id);
CREATE INDEX IF NOT EXISTS ratings_by_item ON ratings (item_id);
"""

_ready: set[Path] = set()
_ready_lock = threading.Lock()


def db_path(data_dir: Path) -> Path:
    """Where a data folder keeps its study database."""
    return Path(data_dir) / DB_FILE


def connect(path: Path) -> sqlite3.Connection:
    """A new autocommit connection with rows as ``sqlite3.Row``; the schema exists once this returns."""
    _ensure_schema(path)
    return _open(path)


def _open(path: Path) -> sqlite3.Connection:
    # check_same_thread=False: FastAPI may open a request's connection on one worker thread and use it on another;
    # the connection is still used by one request at a time.
    connection = sqlite3.connect(path, timeout=BUSY_TIMEOUT_MS / 1000, isolation_level=None,
                                 check_same_thread=False)
    connection.row_factory = sqlite3.Row
    connection.execute(f"PRAGMA busy_timeout = {BUSY_TIMEOUT_MS}")
    connection.execute("PRAGMA foreign_keys = ON")
    connection.execute("PRAGMA synchronous = NORMAL")
    return connection


def _ensure_schema(path: Path) -> None:
    """Create the tables (and switch the file to WAL) the first time this process opens ``path``."""
    key = Path(path).resolve()
    if key in _ready:
        return
    with _ready_lock:
        if key in _ready:
            return
        key.parent.mkdir(parents=True, exist_ok=True)
        connection = _open(key)
        try:
            connection.execute("PRAGMA journal_mode = WAL")
            connection.executescript(SCHEMA)
            _add_missing_columns(connection)
        finally:
            connection.close()
        _ready.add(key)


ADDED_COLUMNS = {"studies": {"camera": "TEXT"}}  # columns added since a table was first made: (table, name, type)


def _add_missing_columns(connection: sqlite3.Connection) -> None:
    """Bring a file made by an earlier version up to ``SCHEMA``: add the columns it lacks (null in old rows)."""
    for table, columns in ADDED_COLUMNS.items():
        present = {row[1] for row in connection.execute(f"PRAGMA table_info({table})")}
        for name, kind in columns.items():
            if name not in present:
                connection.execute(f"ALTER TABLE {table} ADD COLUMN {name} {kind}")


@contextmanager
def transaction(connection: sqlite3.Connection) -> Iterator[sqlite3.Connection]:
    """``BEGIN IMMEDIATE`` … ``COMMIT`` (``ROLLBACK`` on error): several writes as one."""
    connection.execute("BEGIN IMMEDIATE")
    try:
        yield connection
    except BaseException:
        connection.execute("ROLLBACK")
        raise
    connection.execute("COMMIT")
