"""Scrubbing overrides: severity and sun reach the illusions that own them, within their ranges. Render slots and
the byte-bounded scene cache bound the server's memory."""

from __future__ import annotations

import threading
import time
from pathlib import Path
from typing import Any

import pytest
from pydantic import ValidationError

from app.frames import FrameService, RenderBusy, RenderSlots, apply_overrides, case_hash
from lanevil_core.case import load_case
from lanevil_core.illusions import REGISTRY
from lanevil_core.pipeline.compile import roadside_key

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def test_sun_override_moves_a_shadow_illusions_own_sun() -> None:
    case = load_case(SCENES / "30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json")
    moved = apply_overrides(case, severity=5, sun_azimuth=120.0, sun_altitude=0.0)
    illusion: Any = moved.illusions[0]  # a fence shadow
    assert illusion.severity == 5 and illusion.sun_azimuth == 120.0
    assert illusion.sun_altitude == REGISTRY["fence_shadow"].model_fields["sun_altitude"].metadata[0].ge
    assert moved.sun.azimuth == 120.0 and moved.sun.altitude == 0.0
    stored: Any = case.illusions[0]
    assert stored.sun_azimuth is None  # the stored case is untouched


def test_sun_override_leaves_illusions_without_sun_fields_alone() -> None:
    case = load_case(SCENES / "40_reflection/sunlight_reflection/00_straight_suburban_noon/03_level3.json")
    moved = apply_overrides(case, sun_azimuth=100.0)
    assert moved.illusions[0] == case.illusions[0] and moved.sun.azimuth == 100.0


def test_out_of_range_override_is_a_validation_error() -> None:
    case = load_case(SCENES / "30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json")
    with pytest.raises(ValidationError):
        apply_overrides(case, severity=9)


def test_render_slots_bound_renders_in_flight_and_refuse_a_long_queue() -> None:
    slots = RenderSlots(slots=1, max_waiting=1)
    inside, release = threading.Event(), threading.Event()
    peak = [0]

    def render() -> None:
        with slots.hold():
            with slots.hold():  # re-entering (a render compiling its scene) takes no second slot
                inside.set()
                release.wait(10)

    first = threading.Thread(target=render)
    first.start()
    assert inside.wait(10)
    second = threading.Thread(target=lambda: slots.hold().__enter__())
    second.start()
    deadline = time.monotonic() + 10
    while slots.waiting < 1 and time.monotonic() < deadline:
        time.sleep(0.01)
    peak[0] = slots.waiting
    with pytest.raises(RenderBusy) as busy:
        with slots.hold():
            pass
    assert busy.value.retry_after_s >= 1 and peak[0] == 1
    release.set()
    first.join(10)
    second.join(10)


def test_a_busy_renderer_answers_503_with_retry_after(client, state, monkeypatch) -> None:
    def busy(*args, **kwargs):
        raise RenderBusy(32, retry_after_s=16)

    monkeypatch.setattr(state.frames, "frame", busy)
    response = client.get("/api/cases/clean-00_straight_urban/frames/0.png?width=160&height=90")
    assert response.status_code == 503 and response.headers["Retry-After"] == "16"
    assert "waiting to render" in response.json()["detail"]


def test_the_scene_cache_is_bounded_by_bytes() -> None:
    case = load_case(SCENES / "00_clean" / "00_straight_urban.json")
    other = case.model_copy(update={"seed": 7})
    sizes = []
    for each in (case, other):  # each scene's weight, with its packed arrays, in a cache with room for both
        roomy = FrameService(cache_bytes=0, threads=1)
        roomy.frame(each, 0, (160, 90))
        scene = roomy.scenes.get(case_hash(each))
        assert scene is not None and roomy.scenes.total == scene.nbytes() > 1_000_000
        sizes.append(scene.nbytes())
    budget = max(sizes) + min(sizes) // 2  # room for either scene, never both
    service = FrameService(cache_bytes=0, threads=1, scene_cache_bytes=budget)
    service.frame(case, 0, (160, 90))
    assert service.scenes.total == sizes[0] and len(service.scenes) == 1
    service.frame(other, 0, (160, 90))
    assert service.scenes.total == sizes[1] <= budget and len(service.scenes) == 1  # the first made room


def test_the_roadside_cache_keeps_no_render_caches() -> None:
    case = load_case(SCENES / "00_clean" / "00_straight_urban.json")
    service = FrameService(cache_bytes=0, threads=1)
    for frame in (0, 9):
        service.frame(case, frame, (160, 90))
    roadside = service.roadsides.get(roadside_key(case))
    assert roadside is not None and roadside.cache == {}
    assert service.roadsides.total == roadside.nbytes() < service.scenes.total


def test_openapi_documents_the_503_of_rendering_routes(client) -> None:
    paths = client.get("/openapi.json").json()["paths"]
    for path in ("/api/cases/{case_id}/frames/{frame}.{fmt}", "/api/render", "/api/cases/{case_id}/labels"):
        operation = next(iter(paths[path].values()))
        assert "Retry-After" in operation["responses"]["503"]["headers"], path
