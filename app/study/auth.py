"""The organiser's bearer token (``settings.admin_token``, env ``LANEVIL_ADMIN_TOKEN``) guarding study admin routes."""

from __future__ import annotations

import hmac
from typing import Annotated

from fastapi import Depends
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer

from ..api.deps import StateDep
from ..api.errors import ApiError

# Declared as a security scheme, so /docs has an "Authorize" button; missing or malformed headers are ours to refuse.
bearer = HTTPBearer(auto_error=False, scheme_name="OrganiserToken",
                    description="the organiser token, LANEVIL_ADMIN_TOKEN of the server")


def require_admin(state: StateDep,
                  credentials: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer)] = None) -> None:
    """Pass when ``Authorization: Bearer <token>`` matches the configured token (constant-time compare).

    403 when no token is configured (admin routes are then closed), 401 for a missing or wrong token."""
    token = state.settings.admin_token
    if not token:
        raise ApiError(403, "no organiser token is configured: set LANEVIL_ADMIN_TOKEN (e.g. "
                            "`LANEVIL_ADMIN_TOKEN=$(openssl rand -hex 16) lanevil serve`) and send it as "
                            "`Authorization: Bearer <token>`", "authorization")
    given = credentials.credentials.strip() if credentials else ""
    if not given or not hmac.compare_digest(given.encode(), token.encode()):
        raise ApiError(401, "send the organiser token as `Authorization: Bearer <token>`", "authorization",
                       headers={"WWW-Authenticate": "Bearer"})


AdminDep = Annotated[None, Depends(require_admin)]
