"""``Annotated`` dependency aliases of the API routes."""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends, Path

from ..state import AppState, get_state
from ..store import CaseRecord

StateDep = Annotated[AppState, Depends(get_state)]
CaseIdPath = Annotated[str, Path(description="case id: a slug like `fence_shadow-03_level3`", max_length=200,
                                  openapi_examples={"stock": {"value": "fence_shadow-03_level3"}})]


def get_record(case_id: CaseIdPath, state: StateDep) -> CaseRecord:
    """The stored case named by the ``case_id`` path parameter (422 for a malformed id, 404 for an unknown one)."""
    return state.store.get(case_id)


RecordDep = Annotated[CaseRecord, Depends(get_record)]
