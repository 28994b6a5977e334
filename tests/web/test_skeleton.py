"""The backend's skeleton: the app builds on a seeded store, the server binds loopback, ``serve`` validates flags."""

from __future__ import annotations

import pytest

from app.cli import main
from app.settings import Settings


def test_store_is_seeded_from_scenes(client, state) -> None:
    assert len(state.store) == 6
    assert state.store.get("fence_shadow-00_uphill_rural_noon-03_level3").severity == 3
    assert client.get("/docs").status_code == 200


def test_default_bind_is_loopback() -> None:
    assert Settings().host == "127.0.0.1"


def test_editor_link_without_editor_is_503(client) -> None:
    response = client.get("/editor", follow_redirects=False)
    assert response.status_code == 503


@pytest.mark.parametrize("argv", [["serve", "--port", "70000"], ["serve", "--editor-port", "x"]])
def test_serve_rejects_bad_flags(argv, capsys) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("lanevil: error:") and "\n" not in err
