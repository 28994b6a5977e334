"""Property-based fuzzing of the REST API from its own OpenAPI schema: whatever the input, never a 5xx; every
answer is one the schema describes (status code, content type, headers and body schema), so a client generated
from ``/openapi.json`` understands it; and the schema is as strict as the server: schema-valid requests to every
operation (study routes included, with the organiser's token) are not refused (schemathesis'
``positive_data_acceptance``: no 400, 413, 415 or 422 for a request the schema allows).

What JSON Schema cannot state is excused by name, each a rule the server documents (``RELATIONAL_RULES``): rules
across fields of one body (a case's drive must end 60 m before its road, a study item is a frame or an upload),
and rules against what is stored (a case's frame count, an uploaded file's content). Any other refusal fails.

Bounded (the conformance test about a minute, the acceptance test about 15 s): few examples per operation, frames
rendered at most 160x96, labels and direct exports capped at a couple of frames (each is a full-size render).
"""

from __future__ import annotations

import re
from collections.abc import Iterator

import pytest
import schemathesis
from hypothesis import HealthCheck, Phase, given
from hypothesis import settings as hypothesis_settings
from schemathesis.checks import (
    content_type_conformance,
    not_a_server_error,
    positive_data_acceptance,
    response_headers_conformance,
    response_schema_conformance,
    status_code_conformance,
)
from schemathesis.core.failures import FailureGroup
from schemathesis.core.result import Ok
from schemathesis.generation import GenerationMode

import app.api.routes.exports as exports
import app.api.routes.labels as labels
from app.main import create_app
from app.settings import Settings
from app.state import AppState

EXAMPLES_PER_OPERATION = 12
ACCEPTANCE_EXAMPLES_PER_OPERATION = 25
API_PATHS = re.compile(r"^/api/(?!study)")
ADMIN = {"Authorization": "Bearer test-admin"}
CHECKS = [not_a_server_error, status_code_conformance, content_type_conformance, response_headers_conformance,
          response_schema_conformance]
# Refusals of schema-valid requests that depend on other fields or on stored data (message fragments, by rule).
RELATIONAL_RULES: dict[str, tuple[str, ...]] = {
    "a case's fields together (the Case validators)": (
        "does not exist: road has", "ego drives to s=", "markings needs", "junction_s must lie",
        "this distortion turns back"),
    "a mesh_file names an uploaded model": ("upload it first",),
    "an uploaded file is a model that loads, or an image that decodes": (
        "is not a usable model", "is not usable glTF JSON", "is not a binary glTF", "refers to other files",
        "upload PNG or JPEG images", "does not decode as a PNG or JPEG image"),
    "an envelope's version agrees with If-Match": ("If-Match says version",),
    "frame ranges lie in the case, in order, at most a request's worth": ("must satisfy 0 <= START < STOP",
                                                                          "frames per request"),
    "a study's uploads each have a name of their own": ("give each file its own name",),
    "a study item is a frame or an upload, with its role's answer": (
        "give exactly one of case_id", "a gold item needs", "expect must be", "expect is only",
        "a trap item needs", "needs at least one scored", "no uploaded file is named", "no case with id",
        "is outside 0.."),
}
EXCUSED = tuple(fragment for fragments in RELATIONAL_RULES.values() for fragment in fragments)


@pytest.fixture
def operations(settings: Settings, monkeypatch: pytest.MonkeyPatch) -> Iterator[list]:
    """Every ``/api`` operation of an app on the small store, rendering at most 160x96 (deletes last, so the
    example case stays until the end)."""
    monkeypatch.setattr(labels, "MAX_LABEL_FRAMES", 2)
    monkeypatch.setattr(exports, "SYNC_EXPORT_FRAMES", 1)
    small = settings.model_copy(update={"max_width": 160, "max_height": 96})
    state = AppState.open(small)
    try:
        schema = schemathesis.openapi.from_asgi("/openapi.json", create_app(small, state))
        found = []
        for result in schema.get_all_operations():
            assert isinstance(result, Ok), result
            if result.ok().path.startswith("/api/"):
                found.append(result.ok())
        yield sorted(found, key=lambda operation: operation.method == "delete")
    finally:
        state.jobs.shutdown()


@pytest.mark.slow
def test_api_never_answers_5xx_and_answers_what_its_schema_says(operations: list) -> None:
    operations = [operation for operation in operations if API_PATHS.match(operation.path)]
    assert len(operations) >= 12
    for operation in operations:
        check_operation(operation)


def check_operation(operation) -> None:
    @given(case=operation.as_strategy())
    @hypothesis_settings(max_examples=EXAMPLES_PER_OPERATION, deadline=None, database=None,
                         phases=[Phase.explicit, Phase.generate], suppress_health_check=list(HealthCheck))
    def no_server_error(case) -> None:
        case.call_and_validate(checks=CHECKS)

    no_server_error()


def test_every_schema_valid_request_is_accepted_and_none_fails(operations: list) -> None:
    assert len(operations) == 36
    refused = [refusal for operation in operations for refusal in refusals(operation)]
    assert not refused, "\n".join(refused)


def excused(response) -> bool:
    """Whether a 422 names one of ``RELATIONAL_RULES``."""
    return response.status_code == 422 and any(fragment in response.json().get("detail", "") for fragment in EXCUSED)


def refusals(operation) -> list[str]:
    """The schema-valid requests of ``operation`` the server refused for no documented rule (a 5xx raises).
    Generated only: the documented examples use the default server's sizes (1280x720, over this app's 160x96)."""
    refused: list[str] = []

    @given(case=operation.as_strategy(GenerationMode.POSITIVE))
    @hypothesis_settings(max_examples=ACCEPTANCE_EXAMPLES_PER_OPERATION, deadline=None, database=None,
                         phases=[Phase.generate], suppress_health_check=list(HealthCheck))
    def schema_valid(case) -> None:
        response = case.call(headers=ADMIN)
        try:
            case.validate_response(response, checks=[not_a_server_error, positive_data_acceptance])
        except FailureGroup:
            if not excused(response):
                refused.append(f"{case.method} {case.formatted_path} {case.query} {str(case.body)[:200]!r} -> "
                               f"{response.status_code} {response.text[:300]}")

    schema_valid()
    return refused
