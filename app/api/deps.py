"""``Annotated`` dependency aliases of the API routes."""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends, Path

from ..state import AppState, get_state
from ..store import ID_PATTERN, CaseRecord

StateDep = Annotated[AppState, Depends(get_state)]
# The store checks the id (``check_id``: a 422 naming ``case_id``); the description says what it takes.
CaseIdPath = Annotated[str, Path(description="case id: a slug like `fence_shadow-03_level3`",
                                  json_schema_extra={"pattern": ID_PATTERN.pattern},
                                  openapi_examples={"stock": {"value": "fence_shadow-03_level3"}})]
FramePath = Annotated[int, Path(description="frame index, from 0", json_schema_extra={"minimum": 0})]


def get_record(case_id: CaseIdPath, state: StateDep) -> CaseRecord:
    """The stored case named by the ``case_id`` path parameter (422 for a malformed id, 404 for an unknown one)."""
    return state.store.get(case_id)


RecordDep = Annotated[CaseRecord, Depends(get_record)]
