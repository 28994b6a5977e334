"""Shared fixtures: small, fast cases."""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from lanevil_core.case import Case

SMALL_SIZE = (320, 180)
ROOT = Path(__file__).resolve().parents[1]


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


@pytest.fixture(scope="session")
def load_script() -> Callable[[str], ModuleType]:
    """Importer of a script of the repository that is not a package module (``bench/defences.py``,
    ``scripts/carla_run.py``), by its path from the repository root; registered under its file name."""

    def load(relative: str) -> ModuleType:
        path = ROOT / relative
        spec = importlib.util.spec_from_file_location(path.stem, path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[path.stem] = module  # dataclasses defined in the script look their module up
        spec.loader.exec_module(module)
        return module

    return load
