"""Road-coordinate placement of the editor: points on the road map to (s, t) and back; clicks land where aimed."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from app.editor.placement import anchor_road, placement_fields, ray_surface_hit, road_coordinates
from lanevil_core.case import parse_case
from lanevil_core.illusions import REGISTRY
from lanevil_core.world.road_layout import build_network
from lanevil_core.world.road_mesh import road_surface

ROADS = {road_type: build_network(parse_case({"road": {"type": road_type, "radius": 60}}).road, "suburban")
         for road_type in ("straight", "bend", "s_curve", "uphill")}
SURFACES = {road_type: road_surface(network) for road_type, network in ROADS.items()}


@settings(max_examples=60, deadline=None)
@given(road_type=st.sampled_from(sorted(ROADS)), s_road=st.floats(1.0, 390.0), t_road=st.floats(-12.0, 12.0),
       h_road=st.floats(-1.0, 3.0))
def test_road_point_maps_to_s_t_and_back(road_type: str, s_road: float, t_road: float, h_road: float) -> None:
    line = ROADS[road_type].main.line
    p_world = line.to_world(s_road, t_road, h_road)
    s_back, t_back, h_back = road_coordinates(line, p_world)
    assert s_back[0] == pytest.approx(s_road, abs=1e-3)
    assert t_back[0] == pytest.approx(t_road, abs=1e-3)
    assert h_back[0] == pytest.approx(h_road, abs=1e-3)
    np.testing.assert_allclose(line.to_world(s_back, t_back, h_back)[0], p_world, atol=1e-3)


@settings(max_examples=40, deadline=None)
@given(road_type=st.sampled_from(sorted(ROADS)), s_road=st.floats(5.0, 380.0), t_road=st.floats(-6.5, 6.5),
       tilt=st.floats(-0.6, 0.6))
def test_click_ray_hits_the_aimed_road_point(road_type: str, s_road: float, t_road: float, tilt: float) -> None:
    line = ROADS[road_type].main.line
    p_target = line.to_world(s_road, t_road)
    direction = np.array([tilt, 0.3 * tilt, -1.0])
    origin = p_target - 40.0 * direction
    hit = ray_surface_hit(SURFACES[road_type], origin, direction, line)
    assert hit is not None and hit.piece == 0
    assert hit.s_road == pytest.approx(s_road, abs=0.05)
    assert hit.t_road == pytest.approx(t_road, abs=0.05)
    np.testing.assert_allclose(hit.p_world, p_target, atol=0.05)


def test_ray_into_the_sky_misses() -> None:
    assert ray_surface_hit(SURFACES["straight"], np.array([0.0, 0.0, 5.0]), np.array([1.0, 0.0, 0.2])) is None


def test_placement_sets_side_and_offset_from_the_lateral_position() -> None:
    network = ROADS["straight"]
    fence = REGISTRY["fence_shadow"]
    left_far = placement_fields(fence, network, 55.5, 12.0)
    assert left_far["s"] == 55.5 and left_far["side"] == "left"
    assert left_far["offset"] == pytest.approx(12.0 - 7.5, abs=0.01)  # beyond the 7 m carriageway + 0.5 m shoulder
    right_near = placement_fields(fence, network, 40.0, -2.0)
    assert right_near == {"s": 40.0, "side": "right"}  # inside the road: the offset is left as it was
    assert placement_fields(REGISTRY["pedestrian"], network, 30.0, 1.0) == {"s": 30.0}


def test_anchor_is_where_placement_put_it() -> None:
    case = parse_case({"illusions": [{"type": "fence_shadow", "s": 80.0, "side": "left", "offset": 3.0}]})
    s_road, t_road = anchor_road(case.illusions[0], case, ROADS["straight"])
    assert (s_road, t_road) == pytest.approx((80.0, 10.5))
    assert placement_fields(REGISTRY["fence_shadow"], ROADS["straight"], s_road, t_road) == {
        "s": 80.0, "side": "left", "offset": 3.0}
