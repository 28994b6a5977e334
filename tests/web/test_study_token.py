"""The organiser token of ``lanevil serve``: generated once into the data folder, reused later, the env var wins."""

from __future__ import annotations

import stat
from pathlib import Path

import pytest

from app.settings import Settings
from app.study.token import TOKEN_FILE, with_organiser_token


def test_first_start_generates_a_private_token_and_later_starts_reuse_it(tmp_path: Path) -> None:
    settings = Settings(data_dir=tmp_path / "data")
    first, created = with_organiser_token(settings)
    stored = tmp_path / "data" / TOKEN_FILE
    assert created and first.admin_token and len(first.admin_token) >= 32
    assert stored.read_text().strip() == first.admin_token
    assert stat.S_IMODE(stored.stat().st_mode) == 0o600
    assert [path.name for path in stored.parent.iterdir()] == [TOKEN_FILE]  # no temporary file left
    again, created_again = with_organiser_token(settings)
    assert not created_again and again.admin_token == first.admin_token
    assert settings.admin_token is None  # the given settings are not changed


def test_an_empty_token_file_is_replaced(tmp_path: Path) -> None:
    (tmp_path / TOKEN_FILE).write_text("\n")
    settings, created = with_organiser_token(Settings(data_dir=tmp_path))
    assert created and (tmp_path / TOKEN_FILE).read_text().strip() == settings.admin_token


def test_the_environment_variable_wins(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / TOKEN_FILE).write_text("stored-token\n")
    monkeypatch.setenv("LANEVIL_ADMIN_TOKEN", "from-env")
    settings, created = with_organiser_token(Settings(data_dir=tmp_path / "fresh"))
    assert settings.admin_token == "from-env" and not created
    assert not (tmp_path / "fresh").exists()  # nothing generated or written
    settings, created = with_organiser_token(Settings(data_dir=tmp_path))
    assert settings.admin_token == "from-env" and not created
