"""Night and sky light: lamp beams, the lens's glare, the cloud deck, and the lamps of a night street."""

from __future__ import annotations

import numpy as np

from lanevil_core.case import parse_case
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.render.lighting import LOW_ABOVE, beam_weight, cloud_cover, light_row
from lanevil_core.render.post import GLARE_THRESHOLD, glare
from lanevil_core.render.textures import noise_textures
from lanevil_core.world.scene import FIRST_OBJECT_ID, ID_ROAD


def _unit(x: float, y: float, z: float) -> tuple[float, float, float]:
    n = float(np.linalg.norm([x, y, z]))
    return x / n, y / n, z / n


def test_a_low_beam_lights_the_road_ahead_and_not_what_stands_above_the_horizon() -> None:
    lights = np.array([light_row((0.0, 0.0, 0.7), (1.0, 1.0, 1.0), 100.0, (1.0, 0.0, 0.0), "low")])
    road_30m = beam_weight(lights, 0, *_unit(30.0, 0.0, -0.7))
    wall_top = beam_weight(lights, 0, *_unit(20.0, 0.0, 3.0))
    beside = beam_weight(lights, 0, *_unit(10.0, 12.0, -0.7))
    behind = beam_weight(lights, 0, *_unit(-10.0, 0.0, -0.7))
    assert road_30m > 0.9
    assert wall_top <= LOW_ABOVE + 1e-9 and beside < 0.05 and behind == 0.0


def test_a_street_lamp_lights_below_it_and_nothing_near_the_horizontal() -> None:
    lights = np.array([light_row((0.0, 0.0, 8.0), (1.0, 0.8, 0.5), 30.0, (0.0, 0.0, -1.0), "street")])
    assert beam_weight(lights, 0, 0.0, 0.0, -1.0) == 1.0
    assert beam_weight(lights, 0, *_unit(1.0, 0.0, -0.05)) == 0.0
    omni = np.array([light_row((0.0, 0.0, 8.0), (1.0, 1.0, 1.0), 30.0, (0.0, 0.0, -1.0), "omni")])
    assert beam_weight(omni, 0, *_unit(1.0, 0.0, 0.5)) == 1.0


def test_glare_spreads_only_what_is_far_brighter_than_white() -> None:
    hdr = np.full((72, 128, 3), 0.5, np.float32)
    before = hdr.copy()
    glare(hdr, 1.0)
    assert np.array_equal(hdr, before)  # nothing that bright: no change
    hdr[36, 64] = 50.0 * GLARE_THRESHOLD
    glare(hdr, 1.0)
    assert hdr[36, 70, 0] > 0.5 and hdr[36, 64, 0] >= 50.0 * GLARE_THRESHOLD
    assert hdr[36, 70, 0] > hdr[36, 100, 0] >= 0.5  # it falls off away from the source


def test_the_cloud_deck_covers_more_of_the_sky_with_more_cloudiness() -> None:
    _, coarse = noise_textures()
    rng = np.random.default_rng(0)
    directions = [_unit(float(rng.normal()), float(rng.normal()), abs(float(rng.normal())) + 0.2) for _ in range(400)]

    def cover(cloudiness: float) -> float:
        return float(np.mean([cloud_cover(*d, coarse, cloudiness) for d in directions]))

    shares = [cover(c) for c in (0.0, 0.1, 0.5, 0.9)]
    assert shares[0] == 0.0 and shares[0] < shares[1] < shares[2] < shares[3]
    assert shares[1] < 0.15 and 0.25 < shares[2] < 0.6 and shares[3] > 0.65  # about the cloudiness, thinner low down


def test_a_night_street_is_lit_by_its_lamps_and_the_road_outshines_the_houses() -> None:
    night = {"road": {"type": "straight"}, "scene": {"kind": "suburban"}, "sun": {"altitude": -30.0},
             "camera": {"width": 256, "height": 144}}
    scene = compile_scene(parse_case(night))
    day = compile_scene(parse_case({**night, "sun": {"altitude": 40.0}}))
    assert len(scene.lights) > 4 and all(light.beam == "street" for light in scene.lights) and not day.lights
    frame = render_frame(scene, 20)
    luma = frame.rgb.astype(np.float64) @ (0.299, 0.587, 0.114)
    road = luma[frame.object_id == ID_ROAD].mean()
    objects = luma[frame.object_id >= FIRST_OBJECT_ID].mean()
    assert road > 1.5 * objects
