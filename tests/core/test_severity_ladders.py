"""Severity means something: for every illusion type, added to clean stock cases, the change of what a lane
detector looks at (the local contrast of the lane band, ``illusion_effect``) rises strictly from level 1 to 5 on at
least three different clean stock cases."""

from __future__ import annotations

from pathlib import Path

import pytest

from lanevil_core.case import load_case
from lanevil_core.illusion_effect import ladder, lane_band
from lanevil_core.illusions import REGISTRY

CLEAN = Path(__file__).resolve().parents[2] / "scenes" / "00_clean"
# Tried in this order until three rise strictly. The urban street canyon comes last on purpose: its buildings
# shade the whole road under a low sun, so sun-shadow illusions rightly change little there.
CASES = ("01_bend_suburban", "02_s_curve_rural", "03_uphill_highway", "04_downhill_suburban",
         "08_bend_highway_botts", "06_crossroad_suburban", "05_t_junction_urban", "07_straight_tunnel_approach",
         "00_straight_urban")
FRAMES = (0, 6, 12)  # the illusions stand about 14-22 m ahead of the ego's start: in view and near
SIZE = (256, 144)
NEEDED = 3


def test_lane_band_covers_the_lanes_only():
    band = lane_band([[10, 20, 30], [-2, -2, -2]], [50, 60, 70], (64, 80), radius=2)
    assert band[60, 20] and band[60, 22] and not band[60, 25]
    assert not band[10].any()


@pytest.mark.slow
@pytest.mark.parametrize("illusion_type", sorted(REGISTRY))
def test_lane_band_effect_rises_with_the_level(illusion_type):
    rising, seen = [], {}
    for name in CASES:
        effects = ladder(load_case(CLEAN / f"{name}.json"), illusion_type, FRAMES, SIZE)
        seen[name] = [round(e, 2) for e in effects]
        if all(b > a for a, b in zip(effects, effects[1:])):
            rising.append(name)
            if len(rising) == NEEDED:
                break
    assert len(rising) >= NEEDED, seen
