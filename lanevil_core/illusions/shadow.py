"""shadow illusions."""

from __future__ import annotations
