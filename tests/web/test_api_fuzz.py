"""Property-based fuzzing of the REST API from its own OpenAPI schema: whatever the input, never a 5xx, and every
answer is one the schema describes (status code, content type, headers and body schema), so a client generated
from ``/openapi.json`` understands it.

Bounded to run in about a minute: few examples per operation, frames rendered at most 160x96, labels and direct
exports capped at a couple of frames (each is a full-size render), study routes left to their own tests.
"""

from __future__ import annotations

import re

import pytest
import schemathesis
from hypothesis import HealthCheck, Phase, given
from hypothesis import settings as hypothesis_settings
from schemathesis.checks import (
    content_type_conformance,
    not_a_server_error,
    response_headers_conformance,
    response_schema_conformance,
    status_code_conformance,
)
from schemathesis.core.result import Ok

import app.api.exports as exports
import app.api.labels as labels
from app.main import create_app
from app.settings import Settings
from app.state import AppState

EXAMPLES_PER_OPERATION = 12
API_PATHS = re.compile(r"^/api/(?!study)")
CHECKS = [not_a_server_error, status_code_conformance, content_type_conformance, response_headers_conformance,
          response_schema_conformance]


@pytest.mark.slow
def test_api_never_answers_5xx_and_answers_what_its_schema_says(settings: Settings,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(labels, "MAX_LABEL_FRAMES", 2)
    monkeypatch.setattr(exports, "SYNC_EXPORT_FRAMES", 1)
    small = settings.model_copy(update={"max_width": 160, "max_height": 96})
    state = AppState.open(small)
    try:
        schema = schemathesis.openapi.from_asgi("/openapi.json", create_app(small, state))
        operations = []
        for result in schema.get_all_operations():
            assert isinstance(result, Ok), result
            if API_PATHS.match(result.ok().path):
                operations.append(result.ok())
        operations.sort(key=lambda operation: operation.method == "delete")  # keep the example case until the end
        assert len(operations) >= 12
        for operation in operations:
            check_operation(operation)
    finally:
        state.jobs.shutdown()


def check_operation(operation) -> None:
    @given(case=operation.as_strategy())
    @hypothesis_settings(max_examples=EXAMPLES_PER_OPERATION, deadline=None, database=None,
                         phases=[Phase.explicit, Phase.generate], suppress_health_check=list(HealthCheck))
    def no_server_error(case) -> None:
        case.call_and_validate(checks=CHECKS)

    no_server_error()
