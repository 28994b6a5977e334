"""road_damage illusions."""

from __future__ import annotations
