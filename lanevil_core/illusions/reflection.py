"""reflection illusions."""

from __future__ import annotations
