"""``/editor?case=ID``: the demo's "Open the editor" link opens that case in the running editor, then redirects."""

from __future__ import annotations

import pytest


@pytest.fixture
def opened(app) -> list[str]:
    """As when ``lanevil serve`` runs the editor: a port and the editor's ``open_case``."""
    calls: list[str] = []
    app.state.editor_port = 8765
    app.state.open_in_editor = calls.append
    return calls


def test_a_case_link_opens_the_case_and_redirects(client, opened: list[str]) -> None:
    response = client.get("/editor?case=fence_shadow-00_uphill_rural_noon-03_level3", follow_redirects=False)
    assert response.status_code == 307 and response.headers["location"] == "http://testserver:8765/"
    assert opened == ["fence_shadow-00_uphill_rural_noon-03_level3"]
    assert client.get("/editor", follow_redirects=False).status_code == 307 and len(opened) == 1


@pytest.mark.parametrize(("case", "status"), [("no-such-case", 404), ("..%2Fx", 422), ("Not A Slug", 422)])
def test_a_bad_case_is_refused_naming_it(client, opened: list[str], case: str, status: int) -> None:
    response = client.get(f"/editor?case={case}", follow_redirects=False)
    assert response.status_code == status and response.json()["field"] == "case"
    assert response.json()["detail"].startswith("case: ") and opened == []


def test_without_the_editor_a_case_link_is_503(client) -> None:
    response = client.get("/editor?case=fence_shadow-00_uphill_rural_noon-03_level3", follow_redirects=False)
    assert response.status_code == 503
