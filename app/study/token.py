"""The organiser token of ``lanevil serve``: ``LANEVIL_ADMIN_TOKEN`` when set; otherwise one generated on the first
start and kept in the data folder (``DATA/admin_token``, mode 0600), so that later starts reuse it and
``/study/admin`` works without a restart."""

from __future__ import annotations

import secrets
from pathlib import Path

from lanevil_core.files import write_atomic

from ..settings import Settings

TOKEN_FILE = "admin_token"
TOKEN_BYTES = 24  # 32 URL-safe characters


def stored_token(data_dir: Path) -> tuple[str, bool]:
    """The token kept in ``data_dir`` and False, or a new one written there (atomically, 0600) and True."""
    path = data_dir / TOKEN_FILE
    if path.is_file() and (token := path.read_text(encoding="utf-8").strip()):
        return token, False
    token = secrets.token_urlsafe(TOKEN_BYTES)
    try:
        write_atomic(path, f"{token}\n".encode(), mode=0o600, replace=path.exists())  # an empty file is replaced
    except FileExistsError:  # another server on this data folder wrote it first: use that one
        return stored_token(data_dir)
    return token, True


def with_organiser_token(settings: Settings) -> tuple[Settings, bool]:
    """``settings`` with an organiser token (the configured one wins, else the stored one), and whether the token
    was generated now (so the caller prints it once)."""
    if settings.admin_token:
        return settings, False
    token, created = stored_token(settings.data_dir)
    return settings.model_copy(update={"admin_token": token}), created
