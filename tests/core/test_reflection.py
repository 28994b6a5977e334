"""The sunlight reflection's glare sun: it sinks with the level, never above a day case's own sun."""

from __future__ import annotations

import numpy as np
import pytest

from lanevil_core.case import Case
from lanevil_core.illusions.reflection import SunlightReflection
from lanevil_core.library.stock import LEVELS
from lanevil_core.pipeline.compile import compile_scene

TABLE = [level.sun_altitude for level in SunlightReflection.SEVERITY]  # 24, 17, 12, 10, 8


def glare_altitudes(case_sun: float, before: list[dict] | None = None) -> list[float]:
    """The compiled sun's altitude (degrees) of levels 1-5 on a case whose sun stands at ``case_sun``."""
    altitudes = []
    for level in LEVELS:
        case = Case(scene={"density": 0.0}, sun={"altitude": case_sun},
                    illusions=[*(before or []), {"type": "sunlight_reflection", "severity": level}])
        altitudes.append(float(np.degrees(np.arcsin(compile_scene(case).env.sun_dir_world[2]))))
    return altitudes


@pytest.mark.parametrize(("case_sun", "expected"), [
    (45.0, TABLE),  # a noon case: the table's sun
    (15.0, [15.0, 15.0, 12.0, 10.0, 8.0]),  # a sunset: levels 1 and 2 keep its sun, no level lifts it
    (5.0, [8.0] * 5),  # lower than level 5's: every level at level 5's
    (-20.0, TABLE),  # a night case takes the table's sun
])
def test_glare_sun_never_stands_above_a_day_case_sun(case_sun: float, expected: list[float]) -> None:
    assert glare_altitudes(case_sun) == pytest.approx(expected, abs=1e-6)


def test_glare_sun_follows_the_case_sun_not_an_earlier_illusion() -> None:
    fence_first = glare_altitudes(45.0, [{"type": "fence_shadow", "sun_altitude": 12.0}])
    assert fence_first == pytest.approx(TABLE, abs=1e-6)
