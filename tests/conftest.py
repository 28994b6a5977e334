"""Shared fixtures: small, fast cases."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from lanevil_core.case import Case

SMALL_SIZE = (320, 180)


def _merge(base: dict[str, Any], extra: dict[str, Any]) -> dict[str, Any]:
    out = dict(base)
    for key, value in extra.items():
        out[key] = _merge(out[key], value) if isinstance(value, dict) and isinstance(out.get(key), dict) else value
    return out


@pytest.fixture
def make_case() -> Callable[..., Case]:
    """Factory of valid cases: a 320x180 camera, 50 frames, no roadside props; keyword sections override."""

    def factory(**sections: Any) -> Case:
        base = {
            "camera": {"width": SMALL_SIZE[0], "height": SMALL_SIZE[1]},
            "ego": {"frames": 50},
            "scene": {"density": 0.0},
        }
        return Case.model_validate(_merge(base, sections))

    return factory
