"""The editor's Quality setting: ``draft`` shows a half-size preview without the sensor stage while a slider moves,
then the exact frame of the same state once it rests; ``full`` shows exact frames only."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from app.editor import EditError, EditorTab
from app.editor.preview import DRAFT_SIZE, PREVIEW_SIZE, QUALITIES, PreviewRequest, PreviewResult, PreviewWorker
from app.frames import FrameService
from app.state import AppState
from lanevil_core.case import parse_case

WAIT_S = 120.0


def watched(tab: EditorTab) -> list[PreviewResult]:
    """Every result the tab's preview worker publishes from now on (the tab still shows them)."""
    published: list[PreviewResult] = []
    show = tab.preview._publish

    def publish(result: PreviewResult) -> None:
        published.append(result)
        show(result)

    tab.preview._publish = publish
    return published


def test_the_worker_follows_a_draft_with_the_exact_frame_once_it_rests() -> None:
    case = parse_case({})
    rendered: list[tuple[int, bool]] = []
    gate = threading.Event()

    def render(request: PreviewRequest):
        gate.wait(5)
        rendered.append((request.seq, request.draft))
        return np.zeros((2, 2, 3), np.uint8), None

    worker = PreviewWorker(render, lambda result: None, lambda request, error: None)
    seqs = [worker.request(case, frame, False, quality="draft") for frame in range(5)]
    gate.set()
    assert worker.wait_idle(10)  # idle only once the exact frame is shown
    worker.stop()
    assert rendered[-1] == (seqs[-1], False) and rendered[-2] == (seqs[-1], True)
    assert [seq for seq, draft in rendered if not draft] == [seqs[-1]]  # no exact frame of a passed state
    with pytest.raises(ValueError, match="quality"):
        worker.request(case, 0, False, quality="fast")  # type: ignore[arg-type]


def test_draft_quality_shows_a_draft_then_the_exact_frame(tab: EditorTab, state: AppState) -> None:
    assert tuple(tab.display.quality.options) == QUALITIES and tab.display.quality.value == "draft"
    assert tab.preview.wait_idle(WAIT_S)
    published = watched(tab)
    tab.sun.altitude.value = 15.0
    assert tab.preview.wait_idle(WAIT_S)
    draft, exact = published[-2:]
    assert draft.request.draft and draft.rgb.shape == (DRAFT_SIZE[1], DRAFT_SIZE[0], 3)
    assert not exact.request.draft and exact.rgb.shape == (PREVIEW_SIZE[1], PREVIEW_SIZE[0], 3)
    assert draft.request.seq == exact.request.seq == tab.preview.latest_seq
    expected = state.frames.frame(tab.case, tab.frame, PREVIEW_SIZE, overlay=True).rgb
    np.testing.assert_array_equal(tab.last_result.rgb, expected)  # it rests on the exact frame
    assert "draft" not in tab.display.info.content


def test_full_quality_shows_exact_frames_only(tab: EditorTab) -> None:
    tab.display.quality.value = "full"
    assert tab.preview.wait_idle(WAIT_S)
    published = watched(tab)
    for altitude in (20.0, 25.0):
        tab.sun.altitude.value = altitude
        assert tab.preview.wait_idle(WAIT_S)
    assert published and not any(result.request.draft for result in published)
    assert {result.rgb.shape for result in published} == {(PREVIEW_SIZE[1], PREVIEW_SIZE[0], 3)}
    with pytest.raises(EditError, match="quality"):
        tab.display.set_quality("fast")


def mean_difference(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a.astype(np.int16) - b.astype(np.int16)).mean())


def test_a_draft_is_the_frame_without_the_sensor_stage(make_case) -> None:
    frames = FrameService(cache_bytes=32_000_000, threads=1)
    case = make_case(camera={"preset": "dashcam", "width": 320, "height": 180})
    ideal = case.model_copy(update={"camera": case.camera.model_copy(update={"sensor": None})})
    draft = frames.draft(case, 2, (160, 90))
    assert draft.rgb.shape == (90, 160, 3) and draft.key.endswith(":draft")
    assert frames.draft(case, 2, (160, 90)) is draft  # cached
    without_sensor = FrameService(threads=1).frame(ideal, 2, (160, 90)).rgb
    photographed = frames.frame(case, 2, (160, 90)).rgb
    # Close to the case rendered without a sensor (the sensor's surface texture detail is compiled into the scene;
    # its daylight in proportion darkens the shaded road a little), far from the photographed frame (auto-exposure,
    # filmic curve, noise, sharpening).
    to_ideal, to_photograph = mean_difference(draft.rgb, without_sensor), mean_difference(draft.rgb, photographed)
    assert to_ideal < 5.0 and to_photograph > 10.0 and to_photograph > 3 * to_ideal
    overlaid = frames.draft(case, 2, (160, 90), overlay=True)
    assert overlaid.rgb.shape == (90, 160, 3) and not np.array_equal(overlaid.rgb, draft.rgb)
