"""An editor tab in process (a headless websocket client stands for the browser): panel handles are set from
Python (which fires their callbacks, as a browser would), and the case, the store and the pushed preview image are
checked."""

from __future__ import annotations

import io
import json
import threading
import time
import zipfile
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
import trimesh

from app.editor import EditError, Editor, EditorTab
from app.editor.detection import rate_text
from app.editor.preview import PreviewRequest, PreviewResult, PreviewWorker
from app.editor.session import CaseSession
from app.frames import FrameService
from app.state import AppState
from app.store import CaseRecord
from lanevil_core.case import parse_case
from lanevil_core.detect import catalog as detector_catalog
from lanevil_core.detect.learned import BUNDLED_MODELS
from lanevil_core.detect.split import METHODS
from lanevil_core.illusions.shadow import roadside_t
from lanevil_core.library.benchmark_layout import illusion_folder
from lanevil_core.pipeline.compile import compile_scene

SHADOW = "fence_shadow-00_uphill_rural_noon-03_level3"
WAIT_S = 120.0


def settle(tab: EditorTab) -> np.ndarray:
    """Wait for the preview of the latest state and return the image the panel shows."""
    assert tab.preview.wait_idle(WAIT_S)
    assert tab.push_log and tab.push_log[-1][0] == tab.preview.latest_seq
    return np.asarray(tab.last_result.rgb)


def open_shadow(tab: EditorTab) -> np.ndarray:
    tab.cases.case_id.value = SHADOW
    rgb = settle(tab)
    tab.illusions.selected.value = tab.illusions.selected.options[1]
    return rgb


def test_launch_serves_on_the_real_port_and_shows_a_preview(editor_server: Editor, tab: EditorTab) -> None:
    assert editor_server.port > 0 and editor_server.port == editor_server.server.get_port()
    assert tab.session is not None and tab.session.case_id == tab.cases.case_id.value
    assert settle(tab).shape == (360, 640, 3)
    assert tab.view.surface is not None  # the 3D view has the road


def test_a_case_opens_with_its_first_illusion_selected(tab: EditorTab) -> None:
    tab.cases.case_id.value = SHADOW  # one illusion
    assert tab.selected == 0 and tab.illusions.selected.value == tab.illusions.selected.options[1]
    assert not tab.illusions.severity.disabled and tab.illusions.severity.value == 3
    assert not tab.illusions.delete_button.disabled
    tab.cases.case_id.value = "clean-00_straight_urban"  # none: nothing to select
    assert tab.selected is None and tab.illusions.severity.disabled
    settle(tab)


def test_severity_slider_changes_the_case_and_the_preview(tab: EditorTab) -> None:
    before = open_shadow(tab)
    assert tab.selected == 0 and not tab.illusions.severity.disabled
    tab.illusions.severity.value = 5
    after = settle(tab)
    assert tab.case.illusions[0].severity == 5
    assert tab.session.dirty
    # Levels share one sun, so only the fence and its shadow change: a real but local change of the image.
    assert np.abs(after.astype(int) - before.astype(int)).mean() > 0.2
    assert "version 1" in tab.status.content and "unsaved" in tab.status.content


def test_click_on_the_road_places_the_chosen_type_and_save_stores_it(tab: EditorTab, state: AppState) -> None:
    settle(tab)
    line = tab.view.network.main.line
    p_target = line.to_world(45.0, -1.75)
    tab.illusions.place_type.value = "pedestrian"
    index = tab.illusions.click(p_target + np.array([-20.0, 0.0, 15.0]), np.array([20.0, 0.0, -15.0]))
    settle(tab)
    assert index == len(tab.case.illusions) - 1 and tab.selected == index
    assert tab.case.illusions[index].type == "pedestrian"
    assert tab.case.illusions[index].s == pytest.approx(45.0, abs=0.05)
    assert tab.illusions.place_type.value.startswith("(")  # placing ends after one click
    tab.cases.save_button.value = True  # a click on Save
    stored = state.store.get(tab.session.case_id)
    assert stored.version == 2 and stored.case.illusions[-1].type == "pedestrian"
    assert not tab.session.dirty


def test_click_off_the_road_while_placing_is_reported(tab: EditorTab) -> None:
    settle(tab)
    tab.illusions.place_type.value = "vehicle"
    count = len(tab.case.illusions)
    with pytest.raises(EditError, match="position: click on the road"):
        tab.illusions.click(np.array([0.0, 0.0, 5.0]), np.array([1.0, 0.0, 0.5]))  # the sky
    assert len(tab.case.illusions) == count
    browser_click = SimpleNamespace(ray_origin=(0.0, 0.0, 5.0), ray_direction=(1.0, 0.0, 0.5))
    tab.on_scene_click(browser_click)  # as a click in a browser arrives
    assert "click on the road" in tab.status.content and len(tab.case.illusions) == count


def test_undo_and_redo_buttons(tab: EditorTab) -> None:
    open_shadow(tab)
    tab.illusions.severity.value = 1
    tab.illusions.severity.value = 4
    tab.cases.undo_button.value = True
    assert tab.case.illusions[0].severity == 1
    tab.cases.undo_button.value = True
    assert tab.case.illusions[0].severity == 3 and not tab.session.dirty
    tab.cases.redo_button.value = True
    assert tab.case.illusions[0].severity == 1
    assert tab.illusions.severity.value == 1  # the slider follows the case


def test_conflicting_save_is_reported_and_the_edits_kept(tab: EditorTab, state: AppState) -> None:
    open_shadow(tab)
    tab.illusions.severity.value = 5
    theirs = state.store.get(SHADOW).case.model_copy(update={"title": "changed over REST"})
    state.store.update(SHADOW, theirs, expected_version=1)
    assert tab.session.remote_version == 2
    assert tab.cases.save() is None
    assert "Not saved" in tab.status.content
    assert tab.case.illusions[0].severity == 5  # nothing lost
    assert state.store.get(SHADOW).case.title == "changed over REST"
    new_id = tab.cases.save_as_new()
    assert state.store.get(new_id).case.illusions[0].severity == 5


def test_a_save_is_never_reported_as_a_version_stored_elsewhere(tab: EditorTab, state: AppState,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    open_shadow(tab)
    errors: list[str] = []
    report = tab.report

    def recording_report(message: str, error: bool = False) -> None:
        if error:
            errors.append(message)
        report(message, error)

    monkeypatch.setattr(tab, "report", recording_report)
    tab.illusions.severity.value = 5
    tab.cases.save_button.value = True  # a click on Save
    assert state.store.get(SHADOW).version == 2 and tab.session.version == 2
    assert errors == [] and tab.session.remote_version is None
    assert "saved version 2" in tab.status.content
    # a write made elsewhere while this session has unsaved edits is still reported
    tab.illusions.severity.value = 4
    theirs = state.store.get(SHADOW).case.model_copy(update={"title": "changed over REST"})
    state.store.update(SHADOW, theirs, expected_version=2)
    assert tab.session.remote_version == 3
    assert len(errors) == 1 and "Version 3 was stored elsewhere" in errors[0]


def test_a_session_takes_its_new_version_before_store_listeners_hear_of_it(state: AppState) -> None:
    session = CaseSession(state.store.get(SHADOW))
    heard: list[tuple[int, bool, int | None]] = []

    def hear(kind: str, case_id: str, record: CaseRecord | None) -> None:
        assert record is not None  # a save
        heard.append((session.version, session.stored_change(record), session.remote_version))

    state.store.subscribe(hear)
    edited = session.case.model_copy(update={"title": "edited"})
    session.apply(edited, "title")
    assert session.save(state.store).version == 2
    assert heard == [(2, False, None)] and not session.dirty


def test_a_rest_change_shows_up_in_the_open_editor(tab: EditorTab, state: AppState) -> None:
    open_shadow(tab)
    settle(tab)
    record = state.store.get(SHADOW)
    changed = parse_case({**record.case.model_dump(mode="json"), "title": "from the API",
                          "illusions": [{"type": "fence_shadow", "severity": 1}]})
    state.store.update(SHADOW, changed, expected_version=record.version)
    settle(tab)
    assert tab.case.title == "from the API" and tab.cases.title.value == "from the API"
    assert tab.case.illusions[0].severity == 1 and tab.session.version == 2
    assert "new-id" not in tab.cases.case_id.options
    state.store.create(changed, case_id="new-id")
    assert "new-id" in tab.cases.case_id.options


def test_sun_sliders_and_weather_preset(tab: EditorTab) -> None:
    before = settle(tab)
    tab.sun.altitude.value = 8.0
    tab.sun.azimuth.value = -120.0
    after = settle(tab)
    assert (tab.case.sun.altitude, tab.case.sun.azimuth) == (8.0, -120.0)
    assert np.abs(after.astype(int) - before.astype(int)).mean() > 1.0
    tab.sun.weather.value = "HardRainNoon"
    settle(tab)
    assert tab.case.weather.precipitation == 100 and tab.case.sun.azimuth == -120.0
    tab.sun.intensity.value = 0.5
    assert tab.case.sun.intensity == 0.5


def test_road_pavement_input_paves_the_road_with_concrete_and_undo_takes_it_back(tab: EditorTab) -> None:
    before = settle(tab)
    assert tab.road.section.inputs.handles["pavement"].value == tab.case.road.pavement == "asphalt"
    tab.road.section.inputs.handles["pavement"].value = "concrete"
    after = settle(tab)
    assert tab.case.road.pavement == "concrete"
    assert after.astype(float).mean() > before.astype(float).mean() + 5  # pale slabs fill the lower frame
    tab.cases.undo()
    settle(tab)
    assert tab.case.road.pavement == "asphalt" and tab.road.section.inputs.handles["pavement"].value == "asphalt"


def test_sun_sliders_override_a_shadow_illusions_own_sun(tab: EditorTab) -> None:
    open_shadow(tab)
    tab.sun.altitude.value = 20.0
    shadow: Any = tab.case.illusions[0]
    assert shadow.sun_altitude == 20.0


def test_frame_slider_and_overlay_toggle(tab: EditorTab) -> None:
    first = settle(tab)
    tab.display.frame.value = 40
    moved = settle(tab)
    assert tab.last_result.request.frame == 40
    assert np.abs(moved.astype(int) - first.astype(int)).mean() > 0.5
    tab.display.overlay.value = False
    plain = settle(tab)
    assert not tab.last_result.request.overlay
    assert not np.array_equal(plain, moved)


def test_detector_dropdown_draws_its_lanes_and_scores_the_frame(tab: EditorTab, state: AppState, monkeypatch,
                                                                 tmp_path) -> None:
    assert list(tab.display.detector.options) == ["none", *METHODS, *BUNDLED_MODELS]
    assert tab.display.detector.value == "none"
    plain = settle(tab)
    assert tab.display.detection.content == "" and tab.last_result.request.detector is None
    shown: dict[str, np.ndarray] = {}
    for name in ("hough", "ufld"):
        tab.display.detector.value = name
        shown[name] = settle(tab)
        request = tab.last_result.request
        assert request.detector == name and request.overlay
        found = state.frames.detection(request.case, request.frame, request.size, name)
        text = tab.display.detection.content
        assert f"**{name}**" in text and f"accuracy **{100 * found.accuracy:.1f}%**" in text
        assert f"FP {rate_text(found.fp)} · FN {rate_text(found.fn)}" in text
        assert ("fooled**" in text) == (found.fp > 0 or found.fn > 0)
        assert 0.002 < np.any(shown[name] != plain, axis=2).mean() < 0.5  # magenta bands under the labels
    assert not np.array_equal(shown["hough"], shown["ufld"])

    monkeypatch.setattr(detector_catalog, "SHIPPED_MODELS", tmp_path)  # as without the ufld model
    tab.display.frame.value = 1
    missing = settle(tab)
    assert "not available" in tab.display.detection.content and "⚠" not in tab.status.content
    overlaid = state.frames.frame(tab.case, 1, missing.shape[1::-1], overlay=True).rgb
    np.testing.assert_array_equal(missing, overlaid)  # the preview without the detector, not an error
    tab.display.detector.value = "none"
    settle(tab)
    assert tab.display.detection.content == "" and tab.last_result.request.detector is None


@pytest.fixture
def served_detector(monkeypatch, lane_server):
    """``mine``: a detector server named in ``LANEVIL_DETECTORS`` before the editor's tab is made."""
    monkeypatch.setenv("LANEVIL_DETECTORS", f"mine={lane_server.url()}")
    return lane_server


def test_a_plugin_detector_is_a_choice_and_a_server_down_is_said(served_detector, tab: EditorTab, monkeypatch,
                                                                  down_url: str) -> None:
    assert list(tab.display.detector.options) == ["none", *METHODS, "mine", *BUNDLED_MODELS]
    tab.display.detector.value = "mine"
    settle(tab)
    assert "**mine**" in tab.display.detection.content and served_detector.sizes
    monkeypatch.setenv("LANEVIL_DETECTORS", f"mine={down_url}")
    tab.display.frame.value = 1
    settle(tab)
    assert "⚠ **mine**" in tab.display.detection.content and "cannot connect" in tab.display.detection.content


def test_gizmo_move_and_parameter_inputs(tab: EditorTab) -> None:
    open_shadow(tab)
    settle(tab)
    line = tab.view.network.main.line
    tab.illusions.move_selected(line.to_world(70.0, 11.0, 0.3))  # where a drag of the handle ends
    fence: Any = tab.case.illusions[0]
    assert fence.s == pytest.approx(70.0, abs=0.01) and fence.side == "left"
    assert fence.offset == pytest.approx(11.0 - roadside_t(tab.view.network.main, 0.0, 1.0), abs=0.01)
    tab.illusions.params.handles["offset"].value = 2.0
    fence = tab.case.illusions[0]
    assert fence.offset == 2.0
    tab.illusions.params.handles["length"].value = "abc"  # not a number: reported with the field name
    fence = tab.case.illusions[0]
    assert "length" in tab.message and fence.length is None
    tab.illusions.delete_button.value = True
    assert tab.case.illusions == [] and tab.selected is None and tab.illusions.delete_button.disabled


def test_new_case_from_a_road_template(tab: EditorTab, state: AppState) -> None:
    tab.cases.template.value = "bend"
    tab.cases.scene_kind.value = "highway"
    tab.cases.create_button.value = True
    settle(tab)
    record = state.store.get(tab.session.case_id)
    assert record.case.road.type == "bend" and record.case.scene.kind == "highway"
    assert tab.cases.case_id.value == record.id


def test_exports(tab: EditorTab) -> None:
    open_shadow(tab)
    name, data = tab.exports.export_case()
    assert name == f"{SHADOW}.json" and json.loads(data)["illusions"][0]["type"] == "fence_shadow"
    tab.display.frame.value = 3
    (png_name, png), (labels_name, labels) = tab.exports.export_frame()
    assert png_name == f"{SHADOW}_000003.png" and png.startswith(b"\x89PNG")
    assert json.loads(labels)["raw_file"] == png_name and labels_name.endswith(".json")
    job = tab.exports.export_sequence(frames=range(2))
    assert job.finished.wait(WAIT_S) and job.status == "done"
    names = set(zipfile.ZipFile(io.BytesIO(job.result.read_bytes())).namelist())
    folder = f"{illusion_folder('fence_shadow')}/{SHADOW}"
    assert {f"{folder}/{name}" for name in ("000000.png", "000001.png", "labels.json", "case.json")} <= names


def test_preview_worker_coalesces_and_ends_on_the_latest_state() -> None:
    case = parse_case({})
    rendered: list[int] = []
    published: list[PreviewResult] = []
    gate = threading.Event()

    def render(request: PreviewRequest):
        gate.wait(5)
        rendered.append(request.seq)
        time.sleep(0.02)
        return np.zeros((2, 2, 3), np.uint8), None

    worker = PreviewWorker(render, published.append, lambda request, error: None)
    seqs = [worker.request(case, frame, False) for frame in range(20)]
    gate.set()
    assert worker.wait_idle(10)
    worker.stop()
    assert published[-1].request.seq == seqs[-1] and published[-1].request.frame == 19
    assert len(rendered) <= 3 and worker.dropped >= 17


@pytest.mark.parametrize("illusion", [{"type": "fence_shadow", "severity": 5}, {"type": "vehicle", "severity": 4},
                                      {"type": "road_crack", "severity": 2}])
def test_partial_recompile_equals_a_full_compile(illusion: dict) -> None:
    compiler = FrameService(0)
    compiler.scene(parse_case({"scene": {"kind": "urban"}, "illusions": [{"type": "fence_shadow"}]}))
    case = parse_case({"scene": {"kind": "urban"}, "sun": {"azimuth": 100}, "illusions": [illusion]})
    partial, full = compiler.scene(case), compile_scene(case)
    assert compiler.partial_compiles == 1
    assert len(partial.meshes) == len(full.meshes) and len(partial.layers) == len(full.layers)
    for a, b in zip(partial.meshes, full.meshes):
        np.testing.assert_array_equal(a.vertices, b.vertices)
        np.testing.assert_array_equal(a.colors, b.colors)
    for layer_a, layer_b in zip(partial.layers, full.layers):
        np.testing.assert_array_equal(layer_a.rgba, layer_b.rgba)
    np.testing.assert_allclose(partial.env.sun_dir_world, full.env.sun_dir_world)
    assert partial.env.sun_intensity == full.env.sun_intensity and len(partial.lights) == len(full.lights)


def test_camera_controls_change_the_case_camera_and_the_preview(tab: EditorTab) -> None:
    before = settle(tab)
    tab.camera.preset.value = "dashcam"
    after = settle(tab)
    camera = tab.case.camera
    assert camera.fov == 58.0 and camera.bonnet is not None and camera.sensor is not None and camera.lens.k1 < 0
    assert tab.camera.bonnet.value and tab.camera.sensor.value
    assert np.abs(after.astype(int) - before.astype(int)).mean() > 5.0
    tab.camera.fov.value = 70.0
    tab.camera.roll.value = 1.5
    tab.camera.exposure.value = 1.0
    assert (tab.case.camera.fov, tab.case.camera.roll, tab.case.camera.sensor.bias) == (70.0, 1.5, 1.0)
    tab.camera.bonnet.value = False
    tab.camera.sensor.value = False
    settle(tab)
    assert tab.case.camera.bonnet is None and tab.case.camera.sensor is None
    assert tab.camera.exposure.disabled


INJECTION = '<iframe srcdoc="<script>alert(1)</script>"> <script>alert(2)</script> [x](javascript:alert(3))'


def markdown_texts(tab: EditorTab) -> list[str]:
    return [tab.status.content, tab.display.info.content, tab.display.detection.content,
            tab.drive.status.content]


def test_case_text_and_errors_are_escaped_in_the_markdown(tab: EditorTab, state: AppState, monkeypatch) -> None:
    case = parse_case({"title": INJECTION, "description": INJECTION})
    record = state.store.create(case, case_id="injected")
    tab.cases.case_id.value = record.id
    settle(tab)
    assert tab.cases.title.value == INJECTION  # a text input shows the title as typed

    def fail(*args, **kwargs):
        raise FileNotFoundError(f"obstacle model not found: {INJECTION}")

    monkeypatch.setattr(state.frames, "frame", fail)
    tab.display.frame.value = 3
    assert tab.preview.wait_idle(WAIT_S)
    status = tab.status.content
    assert "Preview failed" in status and "obstacle model not found" in status
    assert "&lt;iframe srcdoc\\=&quot;&lt;script&gt;" in status
    tab.drive.status.content = ""
    monkeypatch.setattr(tab.drive, "current", fail)
    tab.drive.start()
    for text in markdown_texts(tab):
        assert "<" not in text and "](" not in text and '"' not in text, text


def test_upload_mesh_stores_the_model_and_sets_the_vehicles_mesh_file(tab: EditorTab, state: AppState) -> None:


    case = parse_case({"title": "vans", "illusions": [{"type": "vehicle", "severity": 1, "kind": "van"}]})
    tab.cases.case_id.value = state.store.create(case, case_id="vans").id
    settle(tab)
    tab.illusions.selected.value = tab.illusions.selected.options[1]
    glb = trimesh.Scene(trimesh.creation.box((4.0, 2.0, 1.5))).export(file_type="glb")
    assert tab.illusions.upload_mesh("../My Van.glb", glb) == "My_Van.glb"
    settle(tab)
    obstacle: Any = tab.case.illusions[0]
    assert obstacle.mesh_file == "My_Van.glb"
    assert (state.meshes_dir / "My_Van.glb").read_bytes() == glb
    assert "⚠" not in tab.status.content
    with pytest.raises(EditError, match="mesh not stored"):
        tab.illusions.upload_mesh("notes.txt", b"hello")
    open_shadow(tab)
    with pytest.raises(EditError, match="takes no mesh"):
        tab.illusions.upload_mesh("van.glb", glb)


def test_a_mesh_file_that_is_not_uploaded_is_not_saved(tab: EditorTab, state: AppState) -> None:
    case = parse_case({"title": "vans", "illusions": [{"type": "vehicle", "severity": 1}]})
    tab.cases.case_id.value = state.store.create(case, case_id="vans").id
    settle(tab)
    tab.illusions.selected.value = tab.illusions.selected.options[1]
    tab.illusions.set_field("mesh_file", "nowhere.glb")
    assert tab.preview.wait_idle(WAIT_S)
    with pytest.raises(EditError, match="nowhere.glb"):
        tab.cases.save()
    with pytest.raises(EditError, match="Not saved"):
        tab.cases.save_as_new()
    assert state.store.get("vans").version == 1
