"""Worn paint (``Marking.wear``): the line flakes and fades in the image, its label stays, fresh paint is unchanged."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lanevil_core.case import Case
from lanevil_core.dataset.plan import PAINT_WEAR_RANGE, train_variation
from lanevil_core.labels import lanes as L
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.render.surface import paint
from lanevil_core.world.paint import PAINT_WEAR, STRIPE_COLUMNS

ASPHALT = 0.055


def _markings(wear: float) -> list[dict[str, Any]]:
    names = ["white_solid", "white_dashed", "yellow_double_solid", "white_dashed", "white_solid"]
    return [{"type": name, "wear": wear} for name in names]


def _stripe(wear: float) -> np.ndarray:
    """One solid white stripe 0.15 m wide along t = 0."""
    row = np.zeros((1, STRIPE_COLUMNS))
    row[0, :11] = [0, 0.0, 0.075, 0.0, 100.0, 0, 1.0, 1.0, 0.7, 0.7, 0.67]
    row[0, PAINT_WEAR] = wear
    return row


@settings(deadline=None)
@given(chips=st.floats(-1.0, 1.0), t=st.floats(-0.2, 0.2))
def test_fresh_paint_ignores_the_chip_noise(chips: float, t: float) -> None:
    fresh = paint(_stripe(0.0), 0, 1, 5.0, t, 0.01, 0.01, ASPHALT, ASPHALT, ASPHALT, chips, 0.0)
    assert fresh == paint(_stripe(0.0), 0, 1, 5.0, t, 0.01, 0.01, ASPHALT, ASPHALT, ASPHALT, 0.0, 0.0)


@settings(deadline=None)
@given(wear=st.floats(0.05, 1.0), chips=st.floats(-1.0, 1.0))
def test_worn_paint_lies_between_the_asphalt_and_fresh_paint(wear: float, chips: float) -> None:
    fresh = paint(_stripe(0.0), 0, 1, 5.0, 0.0, 0.01, 0.01, ASPHALT, ASPHALT, ASPHALT, chips, 0.0)[0]
    worn = paint(_stripe(wear), 0, 1, 5.0, 0.0, 0.01, 0.01, ASPHALT, ASPHALT, ASPHALT, chips, 0.0)[0]
    assert ASPHALT - 1e-9 <= worn < fresh


def test_far_away_worn_paint_fades_evenly() -> None:
    """Filtered chip noise tends to 0 far away: the line keeps 1 - wear of its paint, a little dirtier."""
    half = paint(_stripe(0.5), 0, 1, 5.0, 0.0, 0.01, 0.01, ASPHALT, ASPHALT, ASPHALT, 0.0, 0.0)[0]
    assert ASPHALT + 0.3 * (0.7 - ASPHALT) < half < ASPHALT + 0.5 * (0.7 - ASPHALT)


def test_worn_lines_are_dimmer_in_the_frame_and_keep_their_labels(make_case: Callable[..., Case]) -> None:
    frames, records = {}, {}
    for wear in (0.0, 0.6):
        scene = compile_scene(make_case(road={"markings": _markings(wear)}))
        frames[wear] = render_frame(scene, 5)
        records[wear] = L.tusimple_record(scene, 5, frames[wear], "a.png")
    assert records[0.6]["lanes"] == records[0.0]["lanes"]
    changed = np.abs(frames[0.6].rgb.astype(int) - frames[0.0].rgb.astype(int)).max(axis=-1) > 10
    assert changed.any()
    assert (frames[0.6].rgb[changed].astype(float).mean() < frames[0.0].rgb[changed].astype(float).mean() - 20)


@pytest.mark.parametrize("vary_camera", [True, False])
def test_the_randomised_split_wears_the_paint_of_some_roads(make_case: Callable[..., Case], vary_camera: bool) -> None:
    base = make_case()
    wears = [train_variation(base, 0, index, vary_camera)[0].road.markings[0].wear for index in range(40)]
    if not vary_camera:
        assert set(wears) == {0.0}
        return
    worn = [wear for wear in wears if wear > 0.0]
    assert 8 <= len(worn) <= 32
    assert all(PAINT_WEAR_RANGE[0] <= wear <= PAINT_WEAR_RANGE[1] for wear in worn)
