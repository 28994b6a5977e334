"""The viser editor in process: panel handles are set from Python (which fires their callbacks, as a browser
would), and the case, the store and the pushed preview image are checked."""

from __future__ import annotations

import io
import json
import threading
import time
import zipfile
from types import SimpleNamespace

import numpy as np
import pytest
import trimesh

from app.editor import EditError, Editor
from app.editor.detection import rate_text
from app.editor.preview import PreviewRequest, PreviewResult, PreviewWorker
from app.editor.session import CaseSession
from app.frames import FrameService
from app.state import AppState
from lanevil_core.case import parse_case
from lanevil_core.detect import catalog as detector_catalog
from lanevil_core.detect.split import METHODS
from lanevil_core.illusions.shadow import roadside_t
from lanevil_core.library.benchmark_layout import illusion_folder
from lanevil_core.pipeline.compile import compile_scene

SHADOW = "fence_shadow-00_uphill_rural_noon-03_level3"
WAIT_S = 120.0


def settle(editor: Editor) -> np.ndarray:
    """Wait for the preview of the latest state and return the image the panel shows."""
    assert editor.preview.wait_idle(WAIT_S)
    assert editor.push_log and editor.push_log[-1][0] == editor.preview.latest_seq
    return np.asarray(editor.last_result.rgb)


def open_shadow(editor: Editor) -> np.ndarray:
    editor.panel.case_id.value = SHADOW
    rgb = settle(editor)
    editor.panel.selected.value = editor.panel.selected.options[1]
    return rgb


def test_launch_serves_on_the_real_port_and_shows_a_preview(editor: Editor) -> None:
    assert editor.port > 0 and editor.port == editor.server.get_port()
    assert editor.session is not None and editor.session.case_id == editor.panel.case_id.value
    assert settle(editor).shape == (360, 640, 3)
    assert editor.view.surface is not None  # the 3D view has the road


def test_a_case_opens_with_its_first_illusion_selected(editor: Editor) -> None:
    editor.panel.case_id.value = SHADOW  # one illusion
    assert editor.selected == 0 and editor.panel.selected.value == editor.panel.selected.options[1]
    assert not editor.panel.severity.disabled and editor.panel.severity.value == 3
    assert not editor.panel.delete.disabled
    editor.panel.case_id.value = "clean-00_straight_urban"  # none: nothing to select
    assert editor.selected is None and editor.panel.severity.disabled
    settle(editor)


def test_severity_slider_changes_the_case_and_the_preview(editor: Editor) -> None:
    before = open_shadow(editor)
    assert editor.selected == 0 and not editor.panel.severity.disabled
    editor.panel.severity.value = 5
    after = settle(editor)
    assert editor.case.illusions[0].severity == 5
    assert editor.session.dirty
    # Levels share one sun, so only the fence and its shadow change: a real but local change of the image.
    assert np.abs(after.astype(int) - before.astype(int)).mean() > 0.2
    assert "version 1" in editor.panel.status.content and "unsaved" in editor.panel.status.content


def test_click_on_the_road_places_the_chosen_type_and_save_stores_it(editor: Editor, state: AppState) -> None:
    settle(editor)
    line = editor.view.network.main.line
    p_target = line.to_world(45.0, -1.75)
    editor.panel.place.value = "pedestrian"
    index = editor.click(p_target + np.array([-20.0, 0.0, 15.0]), np.array([20.0, 0.0, -15.0]))
    settle(editor)
    assert index == len(editor.case.illusions) - 1 and editor.selected == index
    assert editor.case.illusions[index].type == "pedestrian"
    assert editor.case.illusions[index].s == pytest.approx(45.0, abs=0.05)
    assert editor.panel.place.value.startswith("(")  # placing ends after one click
    editor.panel.save.value = True  # a click on Save
    stored = state.store.get(editor.session.case_id)
    assert stored.version == 2 and stored.case.illusions[-1].type == "pedestrian"
    assert not editor.session.dirty


def test_click_off_the_road_while_placing_is_reported(editor: Editor) -> None:
    settle(editor)
    editor.panel.place.value = "vehicle"
    count = len(editor.case.illusions)
    with pytest.raises(EditError, match="position: click on the road"):
        editor.click(np.array([0.0, 0.0, 5.0]), np.array([1.0, 0.0, 0.5]))  # the sky
    assert len(editor.case.illusions) == count
    browser_click = SimpleNamespace(ray_origin=(0.0, 0.0, 5.0), ray_direction=(1.0, 0.0, 0.5))
    editor.on_scene_click(browser_click)  # as a click in a browser arrives
    assert "click on the road" in editor.panel.status.content and len(editor.case.illusions) == count


def test_undo_and_redo_buttons(editor: Editor) -> None:
    open_shadow(editor)
    editor.panel.severity.value = 1
    editor.panel.severity.value = 4
    editor.panel.undo.value = True
    assert editor.case.illusions[0].severity == 1
    editor.panel.undo.value = True
    assert editor.case.illusions[0].severity == 3 and not editor.session.dirty
    editor.panel.redo.value = True
    assert editor.case.illusions[0].severity == 1
    assert editor.panel.severity.value == 1  # the slider follows the case


def test_conflicting_save_is_reported_and_the_edits_kept(editor: Editor, state: AppState) -> None:
    open_shadow(editor)
    editor.panel.severity.value = 5
    theirs = state.store.get(SHADOW).case.model_copy(update={"title": "changed over REST"})
    state.store.update(SHADOW, theirs, expected_version=1)
    assert editor.session.remote_version == 2
    assert editor.save() is None
    assert "Not saved" in editor.panel.status.content
    assert editor.case.illusions[0].severity == 5  # nothing lost
    assert state.store.get(SHADOW).case.title == "changed over REST"
    new_id = editor.save_as_new()
    assert state.store.get(new_id).case.illusions[0].severity == 5


def test_a_save_is_never_reported_as_a_version_stored_elsewhere(editor: Editor, state: AppState,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    open_shadow(editor)
    errors: list[str] = []
    report = editor._report

    def recording_report(message: str, error: bool = False) -> None:
        if error:
            errors.append(message)
        report(message, error)

    monkeypatch.setattr(editor, "_report", recording_report)
    editor.panel.severity.value = 5
    editor.panel.save.value = True  # a click on Save
    assert state.store.get(SHADOW).version == 2 and editor.session.version == 2
    assert errors == [] and editor.session.remote_version is None
    assert "saved version 2" in editor.panel.status.content
    # a write made elsewhere while this session has unsaved edits is still reported
    editor.panel.severity.value = 4
    theirs = state.store.get(SHADOW).case.model_copy(update={"title": "changed over REST"})
    state.store.update(SHADOW, theirs, expected_version=2)
    assert editor.session.remote_version == 3
    assert len(errors) == 1 and "Version 3 was stored elsewhere" in errors[0]


def test_a_session_takes_its_new_version_before_store_listeners_hear_of_it(state: AppState) -> None:
    session = CaseSession(state.store.get(SHADOW))
    heard: list[tuple[int, bool, int | None]] = []
    state.store.subscribe(lambda kind, case_id, record: heard.append(
        (session.version, session.stored_change(record), session.remote_version)))
    edited = session.case.model_copy(update={"title": "edited"})
    session.apply(edited, "title")
    assert session.save(state.store).version == 2
    assert heard == [(2, False, None)] and not session.dirty


def test_a_rest_change_shows_up_in_the_open_editor(editor: Editor, state: AppState) -> None:
    open_shadow(editor)
    settle(editor)
    record = state.store.get(SHADOW)
    changed = parse_case({**record.case.model_dump(mode="json"), "title": "from the API",
                          "illusions": [{"type": "fence_shadow", "severity": 1}]})
    state.store.update(SHADOW, changed, expected_version=record.version)
    settle(editor)
    assert editor.case.title == "from the API" and editor.panel.title.value == "from the API"
    assert editor.case.illusions[0].severity == 1 and editor.session.version == 2
    assert "new-id" not in editor.panel.case_id.options
    state.store.create(changed, case_id="new-id")
    assert "new-id" in editor.panel.case_id.options


def test_sun_sliders_and_weather_preset(editor: Editor) -> None:
    before = settle(editor)
    editor.panel.sun_altitude.value = 8.0
    editor.panel.sun_azimuth.value = -120.0
    after = settle(editor)
    assert (editor.case.sun.altitude, editor.case.sun.azimuth) == (8.0, -120.0)
    assert np.abs(after.astype(int) - before.astype(int)).mean() > 1.0
    editor.panel.weather.value = "HardRainNoon"
    settle(editor)
    assert editor.case.weather.precipitation == 100 and editor.case.sun.azimuth == -120.0
    editor.panel.sun_intensity.value = 0.5
    assert editor.case.sun.intensity == 0.5


def test_sun_sliders_override_a_shadow_illusions_own_sun(editor: Editor) -> None:
    open_shadow(editor)
    editor.panel.sun_altitude.value = 20.0
    assert editor.case.illusions[0].sun_altitude == 20.0


def test_frame_slider_and_overlay_toggle(editor: Editor) -> None:
    first = settle(editor)
    editor.panel.frame.value = 40
    moved = settle(editor)
    assert editor.last_result.request.frame == 40
    assert np.abs(moved.astype(int) - first.astype(int)).mean() > 0.5
    editor.panel.overlay.value = False
    plain = settle(editor)
    assert not editor.last_result.request.overlay
    assert not np.array_equal(plain, moved)


def test_detector_dropdown_draws_its_lanes_and_scores_the_frame(editor: Editor, state: AppState, monkeypatch,
                                                                 tmp_path) -> None:
    assert list(editor.panel.detector.options) == ["none", *METHODS] and editor.panel.detector.value == "none"
    plain = settle(editor)
    assert editor.panel.detection.content == "" and editor.last_result.request.detector is None
    shown: dict[str, np.ndarray] = {}
    for name in ("hough", "ufld"):
        editor.panel.detector.value = name
        shown[name] = settle(editor)
        request = editor.last_result.request
        assert request.detector == name and request.overlay
        found = state.frames.detection(request.case, request.frame, request.size, name)
        text = editor.panel.detection.content
        assert f"**{name}**" in text and f"accuracy **{100 * found.accuracy:.1f}%**" in text
        assert f"FP {rate_text(found.fp)} · FN {rate_text(found.fn)}" in text
        assert ("fooled**" in text) == (found.fp > 0 or found.fn > 0)
        assert 0.002 < np.any(shown[name] != plain, axis=2).mean() < 0.5  # magenta bands under the labels
    assert not np.array_equal(shown["hough"], shown["ufld"])

    monkeypatch.setattr(detector_catalog, "SHIPPED_MODELS", tmp_path)  # as without the ufld model
    editor.panel.frame.value = 1
    missing = settle(editor)
    assert "not available" in editor.panel.detection.content and "⚠" not in editor.panel.status.content
    overlaid = state.frames.frame(editor.case, 1, missing.shape[1::-1], overlay=True).rgb
    np.testing.assert_array_equal(missing, overlaid)  # the preview without the detector, not an error
    editor.panel.detector.value = "none"
    settle(editor)
    assert editor.panel.detection.content == "" and editor.last_result.request.detector is None


def test_gizmo_move_and_parameter_inputs(editor: Editor) -> None:
    open_shadow(editor)
    settle(editor)
    line = editor.view.network.main.line
    editor.move_selected(line.to_world(70.0, 11.0, 0.3))  # where a drag of the handle ends
    fence = editor.case.illusions[0]
    assert fence.s == pytest.approx(70.0, abs=0.01) and fence.side == "left"
    assert fence.offset == pytest.approx(11.0 - roadside_t(editor.view.network.main, 0.0, 1.0), abs=0.01)
    editor.panel.params.handles["offset"].value = 2.0
    assert editor.case.illusions[0].offset == 2.0
    editor.panel.params.handles["length"].value = "abc"  # not a number: reported with the field name
    assert "length" in editor.message and editor.case.illusions[0].length is None
    editor.panel.delete.value = True
    assert editor.case.illusions == [] and editor.selected is None and editor.panel.delete.disabled


def test_new_case_from_a_road_template(editor: Editor, state: AppState) -> None:
    editor.panel.template.value = "bend"
    editor.panel.scene_kind.value = "highway"
    editor.panel.create.value = True
    settle(editor)
    record = state.store.get(editor.session.case_id)
    assert record.case.road.type == "bend" and record.case.scene.kind == "highway"
    assert editor.panel.case_id.value == record.id


def test_exports(editor: Editor) -> None:
    open_shadow(editor)
    name, data = editor.export_case(None)
    assert name == f"{SHADOW}.json" and json.loads(data)["illusions"][0]["type"] == "fence_shadow"
    editor.panel.frame.value = 3
    (png_name, png), (labels_name, labels) = editor.export_frame(None)
    assert png_name == f"{SHADOW}_000003.png" and png.startswith(b"\x89PNG")
    assert json.loads(labels)["raw_file"] == png_name and labels_name.endswith(".json")
    job = editor.export_sequence(None, frames=range(2))
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
    for a, b in zip(partial.layers, full.layers):
        np.testing.assert_array_equal(a.rgba, b.rgba)
    np.testing.assert_allclose(partial.env.sun_dir_world, full.env.sun_dir_world)
    assert partial.env.sun_intensity == full.env.sun_intensity and len(partial.lights) == len(full.lights)


def test_camera_controls_change_the_case_camera_and_the_preview(editor: Editor) -> None:
    before = settle(editor)
    editor.panel.camera_preset.value = "dashcam"
    after = settle(editor)
    camera = editor.case.camera
    assert camera.fov == 58.0 and camera.bonnet is not None and camera.sensor is not None and camera.lens.k1 < 0
    assert editor.panel.camera_bonnet.value and editor.panel.camera_sensor.value
    assert np.abs(after.astype(int) - before.astype(int)).mean() > 5.0
    editor.panel.camera_fov.value = 70.0
    editor.panel.camera_roll.value = 1.5
    editor.panel.camera_exposure.value = 1.0
    assert (editor.case.camera.fov, editor.case.camera.roll, editor.case.camera.sensor.bias) == (70.0, 1.5, 1.0)
    editor.panel.camera_bonnet.value = False
    editor.panel.camera_sensor.value = False
    settle(editor)
    assert editor.case.camera.bonnet is None and editor.case.camera.sensor is None
    assert editor.panel.camera_exposure.disabled


INJECTION = '<iframe srcdoc="<script>alert(1)</script>"> <script>alert(2)</script> [x](javascript:alert(3))'


def markdown_texts(editor: Editor) -> list[str]:
    return [editor.panel.status.content, editor.panel.preview_info.content, editor.panel.detection.content,
            editor.drive.status.content]


def test_case_text_and_errors_are_escaped_in_the_markdown(editor: Editor, state: AppState, monkeypatch) -> None:
    case = parse_case({"title": INJECTION, "description": INJECTION})
    record = state.store.create(case, case_id="injected")
    editor.panel.case_id.value = record.id
    settle(editor)
    assert editor.panel.title.value == INJECTION  # a text input shows the title as typed

    def fail(*args, **kwargs):
        raise FileNotFoundError(f"obstacle model not found: {INJECTION}")

    monkeypatch.setattr(state.frames, "frame", fail)
    editor.panel.frame.value = 3
    assert editor.preview.wait_idle(WAIT_S)
    status = editor.panel.status.content
    assert "Preview failed" in status and "obstacle model not found" in status
    assert "&lt;iframe srcdoc\\=&quot;&lt;script&gt;" in status
    editor.drive.status.content = ""
    monkeypatch.setattr(editor.drive, "current", fail)
    editor.drive.start()
    for text in markdown_texts(editor):
        assert "<" not in text and "](" not in text and '"' not in text, text


def test_upload_mesh_stores_the_model_and_sets_the_vehicles_mesh_file(editor: Editor, state: AppState) -> None:


    case = parse_case({"title": "vans", "illusions": [{"type": "vehicle", "severity": 1, "kind": "van"}]})
    editor.panel.case_id.value = state.store.create(case, case_id="vans").id
    settle(editor)
    editor.panel.selected.value = editor.panel.selected.options[1]
    glb = trimesh.Scene(trimesh.creation.box((4.0, 2.0, 1.5))).export(file_type="glb")
    assert editor.upload_mesh("../My Van.glb", glb) == "My_Van.glb"
    settle(editor)
    assert editor.case.illusions[0].mesh_file == "My_Van.glb"
    assert (state.meshes_dir / "My_Van.glb").read_bytes() == glb
    assert "⚠" not in editor.panel.status.content
    with pytest.raises(EditError, match="mesh not stored"):
        editor.upload_mesh("notes.txt", b"hello")
    open_shadow(editor)
    with pytest.raises(EditError, match="takes no mesh"):
        editor.upload_mesh("van.glb", glb)


def test_a_mesh_file_that_is_not_uploaded_is_not_saved(editor: Editor, state: AppState) -> None:
    case = parse_case({"title": "vans", "illusions": [{"type": "vehicle", "severity": 1}]})
    editor.panel.case_id.value = state.store.create(case, case_id="vans").id
    settle(editor)
    editor.panel.selected.value = editor.panel.selected.options[1]
    editor.set_field("mesh_file", "nowhere.glb")
    assert editor.preview.wait_idle(WAIT_S)
    with pytest.raises(EditError, match="nowhere.glb"):
        editor.save()
    with pytest.raises(EditError, match="Not saved"):
        editor.save_as_new()
    assert state.store.get("vans").version == 1
