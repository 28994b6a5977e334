"""Scrubbing overrides: severity and sun reach the illusions that own them, within their ranges."""

from __future__ import annotations

from pathlib import Path

import pytest
from pydantic import ValidationError

from app.frames import apply_overrides
from lanevil_core.case import load_case
from lanevil_core.illusions import REGISTRY

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def test_sun_override_moves_a_shadow_illusions_own_sun() -> None:
    case = load_case(SCENES / "30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json")
    moved = apply_overrides(case, severity=5, sun_azimuth=120.0, sun_altitude=0.0)
    illusion = moved.illusions[0]
    assert illusion.severity == 5 and illusion.sun_azimuth == 120.0
    assert illusion.sun_altitude == REGISTRY["fence_shadow"].model_fields["sun_altitude"].metadata[0].ge
    assert moved.sun.azimuth == 120.0 and moved.sun.altitude == 0.0
    assert case.illusions[0].sun_azimuth is None  # the stored case is untouched


def test_sun_override_leaves_illusions_without_sun_fields_alone() -> None:
    case = load_case(SCENES / "40_reflection/sunlight_reflection/00_straight_suburban_noon/03_level3.json")
    moved = apply_overrides(case, sun_azimuth=100.0)
    assert moved.illusions[0] == case.illusions[0] and moved.sun.azimuth == 100.0


def test_out_of_range_override_is_a_validation_error() -> None:
    case = load_case(SCENES / "30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json")
    with pytest.raises(ValidationError):
        apply_overrides(case, severity=9)
