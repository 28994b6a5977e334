"""Severity means something: for every illusion type, on every one of its stock originals, the change of what a
lane detector looks at (the local contrast of the lane band, ``illusion_effect``) rises strictly from level 1 to 5,
and level 5 stays in view over the drive.

Rendering every original's ladder takes minutes, so the fast test takes a deterministic sample (one original per
type, the types taking the originals in turn) and the ``slow`` test covers every original."""

from __future__ import annotations

import pytest

from lanevil_core.illusions import REGISTRY
from lanevil_core.library.stock import ORIGINALS, original_case, original_id
from lanevil_core.pipeline.illusion_effect import ladder, lane_band, shown_share, with_illusion

SHOWN_SHARE_MIN = 0.25  # the level-5 illusion is in view on at least this share of its drive's frames
FRAMES = (0, 6, 12)  # the illusions stand about 14-22 m ahead of the ego's start: in view and near
SIZE = (256, 144)
SAMPLE = [(name, position % len(ORIGINALS[name])) for position, name in enumerate(sorted(REGISTRY))]
EVERY = [(name, index) for name in sorted(REGISTRY) for index in range(len(ORIGINALS[name]))]
# Ladders measured flat at one step, each with what was measured; strict, so a fix shows as an unexpected pass.
# (vehicle, 1), 01_bend_highway_cloudy, was 3.30, 3.28, 10.35, 10.87, 11.58; with the saloon's rounded body (drawn-in
# shoulders, a cabin leaning in) 3.37, 3.40, 10.40, 10.90, 11.66: it rises again.
FLAT_STEPS: dict[tuple[str, int], str] = {}


def _ids(pairs: list[tuple[str, int]]) -> list[str]:
    return [f"{name}-{index}" for name, index in pairs]


def test_lane_band_covers_the_lanes_only():
    band = lane_band([[10, 20, 30], [-2, -2, -2]], [50, 60, 70], (64, 80), radius=2)
    assert band[60, 20] and band[60, 22] and not band[60, 25]
    assert not band[10].any()


def _assert_rises(illusion_type: str, index: int) -> None:
    effects = ladder(original_case(illusion_type, index), illusion_type, FRAMES, SIZE)
    assert all(b > a for a, b in zip(effects, effects[1:])), (original_id(illusion_type, index),
                                                              [round(e, 2) for e in effects])


def test_the_sample_covers_every_type_once():
    assert sorted(name for name, _ in SAMPLE) == sorted(REGISTRY)
    assert len({index for _, index in SAMPLE}) == max(len(originals) for originals in ORIGINALS.values())


@pytest.mark.parametrize(("illusion_type", "index"), SAMPLE, ids=_ids(SAMPLE))
def test_lane_band_effect_rises_with_the_level_on_a_sample(illusion_type, index):
    _assert_rises(illusion_type, index)


@pytest.mark.slow
@pytest.mark.parametrize(("illusion_type", "index"), [
    pytest.param(*pair, marks=pytest.mark.xfail(reason=FLAT_STEPS[pair], strict=True)) if pair in FLAT_STEPS
    else pair for pair in EVERY], ids=_ids(EVERY))
def test_lane_band_effect_rises_with_the_level_on_every_original(illusion_type, index):
    _assert_rises(illusion_type, index)


@pytest.mark.parametrize(("illusion_type", "index"), SAMPLE, ids=_ids(SAMPLE))
def test_level5_is_in_view_over_the_drive(illusion_type, index):
    """The full test split scores every frame of a case: crowds, cracks and tire marks run on along the drive
    instead of being passed in its first seconds (experiments/in_view.py measures every original)."""
    case = with_illusion(original_case(illusion_type, index), {"type": illusion_type, "severity": 5})
    assert shown_share(case) >= SHOWN_SHARE_MIN, original_id(illusion_type, index)
