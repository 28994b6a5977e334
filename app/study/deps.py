"""``Annotated`` dependency aliases of the study's routes and pages."""

from __future__ import annotations

import sqlite3
from collections.abc import Iterator
from typing import Annotated

from fastapi import Depends

from ..api.deps import StateDep
from .db import connect, db_path


def get_db(state: StateDep) -> Iterator[sqlite3.Connection]:
    """One SQLite connection for the request, closed after the response."""
    connection = connect(db_path(state.settings.data_dir))
    try:
        yield connection
    finally:
        connection.close()


DbDep = Annotated[sqlite3.Connection, Depends(get_db)]
