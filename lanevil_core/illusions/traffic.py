"""traffic illusions."""

from __future__ import annotations
