"""One browser tab of the editor: its own panel, 3D view, preview and case session, wired to the shared store.

Each viser client (a browser tab) gets an ``EditorTab`` built in its client-scoped GUI and scene: its open case,
unsaved edits and undo history, selection, frame, overlay, detector, quality and camera pose are its own, so what
one tab changes never shows in another tab, nor in one opened later. Tabs meet in the store: a save goes through
its version check, and each tab follows the store's changes of its open case (``CaseStore.subscribe``).

Methods named after user actions (``open_case``, ``place``, ``set_severity`` …) are what the panel's callbacks
call; tests and the latency benchmark call the same methods or set the panel's handles directly.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import viser

from lanevil_core.camera import ego_camera
from lanevil_core.case import Bonnet, Case, CaseError, Sensor, parse_case
from lanevil_core.illusions import REGISTRY, Illusion, MeshFileError
from lanevil_core.metrics.formats import LaneFileError
from lanevil_core.pipeline.compile import check_mesh_files, roadside_key
from lanevil_core.presets import camera_preset_values, preset_values
from lanevil_core.world.road_layout import RoadNetwork
from lanevil_core.world.scene import CompiledScene

from ..meshes import MeshUploadError, store_mesh
from ..state import AppState
from ..store import CaseRecord, ChangeKind, StoreError, VersionConflict
from . import export
from .detection import chosen_detector, detection_text, unavailable_text
from .drive_panel import DrivePanel
from .panel import CUSTOM_CAMERA, CUSTOM_WEATHER, NO_SELECTION, PLACE_OFF, Panel, build_panel
from .placement import anchor_road, field_bounds, placement_fields, ray_surface_hit, road_coordinates
from .preview import DRAFT_SIZE, QUALITIES, PreviewRequest, PreviewResult, PreviewWorker
from .scene_view import SceneView
from .session import CaseSession, SessionRegistry
from .text import escape_markdown

SELECT_RADIUS_M = 8.0  # a click this close to an illusion's handle selects it
SUN_FIELDS = ("azimuth", "altitude", "intensity")
# The 3D view's start pose: behind, beside and above the ego's start, looking down the road.
CAMERA_BACK_M, CAMERA_SIDE_M, CAMERA_UP_M, CAMERA_AHEAD_M = 18.0, 6.0, 14.0, 35.0
SELECT_FIRST = "select an illusion first (Illusions → Selected)"


class EditError(Exception):
    """A user action that cannot be done; the message is shown in the panel as is."""


def _wrap_degrees(angle: float) -> float:
    return float((angle + 180.0) % 360.0 - 180.0)


class EditorTab:
    """The editor as one viser client (browser tab) sees it, over the backend's ``AppState``."""

    def __init__(self, state: AppState, client: viser.ClientHandle, case_id: str | None = None) -> None:
        self.state = state
        self.client = client
        self.sessions = SessionRegistry(state.store)  # this tab's sessions: its unsaved edits are its own
        self.session: CaseSession | None = None
        self.frame = 0
        self.selected: int | None = None
        self.message = ""
        self.push_log: list[tuple[int, float]] = []  # (request seq, perf_counter when the image was pushed)
        self.last_result: PreviewResult | None = None
        self._aimed_key: str | None = None
        self._lock = threading.RLock()
        self._syncing = threading.local()
        self._playing = threading.Event()
        self._stopped = threading.Event()
        self.view = SceneView(client.scene)
        self.panel: Panel = build_panel(client.gui, self._case_ids())
        self.drive = DrivePanel(client.gui, state, lambda: (self._current().case_id, self.case),
                                lambda: chosen_detector(str(self.panel.detector.value)))
        self.panel.params.on_change = self._guarded(self.set_field)
        self.preview = PreviewWorker(self._render, self._publish, self._preview_failed)
        self._wire()
        self._unsubscribe = state.store.subscribe(self._stored)
        self._player = threading.Thread(target=self._play_loop, name="lanevil-editor-play", daemon=True)
        self._player.start()
        ids = self._case_ids()
        if case_id is not None or ids:
            self.open_case(case_id if case_id is not None else ids[0])

    # ------------------------------------------------------------------------------------------ lifecycle

    @property
    def client_id(self) -> int:
        return self.client.client_id

    def stop(self) -> None:
        """Stop the preview worker, the player and the drive playback (the tab closed or the editor stops)."""
        self._stopped.set()
        self._playing.clear()
        self.drive.stop()
        self._unsubscribe()
        self.preview.stop()

    # ------------------------------------------------------------------------------------------ wiring

    def _guarded(self, action: Callable[..., Any]) -> Callable[..., None]:
        """A callback that ignores updates made while the panel is being synced, and reports ``EditError``s."""

        def callback(*args: Any) -> None:
            if getattr(self._syncing, "on", False):
                return
            try:
                action(*args)
            except (EditError, CaseError, StoreError) as error:
                self._report(str(error), error=True)

        return callback

    def _wire(self) -> None:
        p = self.panel
        value = {"frame": lambda e: self.set_frame(int(e.target.value)),
                 "overlay": lambda e: self.set_overlay(bool(e.target.value)),
                 "detector": lambda e: self.set_detector(str(e.target.value)),
                 "quality": lambda e: self.set_quality(str(e.target.value)),
                 "play": lambda e: self.set_playing(bool(e.target.value)),
                 "case_id": lambda e: self.open_case(str(e.target.value)),
                 "title": lambda e: self.set_title(str(e.target.value)),
                 "selected": lambda e: self.select(self._selection_index(str(e.target.value))),
                 "severity": lambda e: self.set_severity(int(e.target.value)),
                 "sun_azimuth": lambda e: self.set_sun(azimuth=float(e.target.value)),
                 "sun_altitude": lambda e: self.set_sun(altitude=float(e.target.value)),
                 "sun_intensity": lambda e: self.set_sun(intensity=float(e.target.value)),
                 "weather": lambda e: self.set_weather_preset(str(e.target.value)),
                 "pavement": lambda e: self.set_pavement(str(e.target.value)),
                 "camera_preset": lambda e: self.set_camera_preset(str(e.target.value)),
                 "camera_fov": lambda e: self.set_camera(fov=float(e.target.value)),
                 "camera_height": lambda e: self.set_camera(z=float(e.target.value)),
                 "camera_pitch": lambda e: self.set_camera(pitch=float(e.target.value)),
                 "camera_roll": lambda e: self.set_camera(roll=float(e.target.value)),
                 "camera_k1": lambda e: self.set_lens(k1=float(e.target.value)),
                 "camera_bonnet": lambda e: self.set_camera_part("bonnet", bool(e.target.value)),
                 "camera_sensor": lambda e: self.set_camera_part("sensor", bool(e.target.value)),
                 "camera_exposure": lambda e: self.set_sensor(bias=float(e.target.value)),
                 "camera_noise": lambda e: self.set_sensor(noise=float(e.target.value))}
        for name, action in value.items():
            getattr(p, name).on_update(self._guarded(action))
        clicks = {"save": lambda e: self.save(), "save_copy": lambda e: self.save_as_new(),
                  "reload": lambda e: self.reload(), "undo": lambda e: self.undo(), "redo": lambda e: self.redo(),
                  "create": lambda e: self.new_case(str(p.template.value), str(p.scene_kind.value)),
                  "delete": lambda e: self.delete_selected(),
                  "export_case": lambda e: self.export_case(),
                  "export_frame": lambda e: self.export_frame(),
                  "export_sequence": lambda e: self.export_sequence()}
        for name, action in clicks.items():
            getattr(p, name).on_click(self._guarded(action))
        p.upload_mesh.on_upload(self._guarded(lambda e: self.upload_mesh(e.target.value.name, e.target.value.content)))
        self.client.gui.add_command("Undo", hotkey="Z", modifier="cmd/ctrl",
                                    description="undo the last change").on_trigger(self._guarded(lambda e: self.undo()))
        self.client.gui.add_command("Redo", hotkey="Z", modifier="cmd/ctrl+shift",
                                    description="redo").on_trigger(self._guarded(lambda e: self.redo()))
        self.on_scene_click = self._guarded(self._clicked)  # what a browser click calls
        self.client.scene.on_click()(self.on_scene_click)

    # ------------------------------------------------------------------------------------------ cases

    def _case_ids(self) -> list[str]:
        return [record.id for record in self.state.store.list()]

    def _current(self) -> CaseSession:
        if self.session is None:
            raise EditError("open a case first (Case → Open)")
        return self.session

    @property
    def case(self) -> Case:
        """The case as currently edited (unsaved changes included)."""
        return self._current().case

    def open_case(self, case_id: str) -> None:
        """Show a stored case (its shared session, with any unsaved edits another tab made), its first illusion
        selected so that its severity and parameters show at once."""
        if case_id not in self.state.store:
            raise EditError(f"case_id: no case {case_id!r} in the store")
        with self._lock:
            self.session = self.sessions.open(case_id)
            self.selected = 0 if self.session.case.illusions else None
            self.frame = min(self.frame, self.session.case.ego.frames - 1)
        self._changed(f"opened {case_id}")

    def new_case(self, road_type: str, scene_kind: str) -> str:
        """Create a case from a road template (no illusions) and open it; returns its id."""
        case = parse_case({"title": f"New {road_type.replace('_', ' ')} road", "road": {"type": road_type},
                           "scene": {"kind": scene_kind}}, source="new case")
        record = self.state.store.create(case)
        self.open_case(record.id)
        return record.id

    def save(self) -> CaseRecord | None:
        """Write the edited case through the store's version check; a conflict is reported and the edits kept."""
        session = self._current()
        self._check_meshes(session.case)
        try:
            record = session.save(self.state.store)
        except VersionConflict as error:
            self._report(f"Not saved: {error}. Your edits are kept: use 'Save as new case', or 'Reload stored "
                         "version' (Undo brings your edits back).", error=True)
            return None
        self._changed(f"saved version {record.version}")
        return record

    def save_as_new(self) -> str:
        """Store the edited case under a fresh id and continue there."""
        case = self.case
        self._check_meshes(case)
        record = self.state.store.create(case)
        self.open_case(record.id)
        return record.id

    def _check_meshes(self, case: Case) -> None:
        """What the REST API refuses is not stored from here either: a ``mesh_file`` that is not uploaded."""
        try:
            check_mesh_files(case, self.state.meshes_dir)
        except MeshFileError as error:
            raise EditError(f"Not saved: {error} (use Upload vehicle mesh)") from None

    def reload(self) -> None:
        session = self._current()
        session.reload(self.state.store.get(session.case_id))
        self._changed("reloaded the stored version")

    def undo(self) -> None:
        label = self._current().undo()
        self._changed(f"undid {label}" if label else "nothing to undo")

    def redo(self) -> None:
        label = self._current().redo()
        self._changed(f"redid {label}" if label else "nothing to redo")

    def _stored(self, kind: ChangeKind, case_id: str, record: CaseRecord | None) -> None:
        """A store change from anywhere: keep the case list current and follow changes of the open case."""
        with self._syncing_panel():
            options = self._case_ids() or ["(no cases)"]
            self.panel.case_id.options = options
            if self.session is not None and self.session.case_id in options:
                self.panel.case_id.value = self.session.case_id
        session = self.session
        if session is None or case_id != session.case_id:
            return
        if kind == "deleted":
            self.sessions.drop(case_id)
            self._report("This case was deleted from the store; 'Save as new case' keeps your version.", error=True)
        elif record is not None and session.stored_change(record):
            self._changed(f"version {record.version} arrived from the store")
        elif session.remote_version is not None:
            self._report(f"Version {session.remote_version} was stored elsewhere; you have unsaved edits "
                         "(Save reports the conflict, Reload takes theirs).", error=True)

    # ------------------------------------------------------------------------------------------ edits

    def _edit(self, data: dict[str, Any], label: str) -> None:
        session = self._current()
        case = parse_case(data, source=session.case_id)
        if session.apply(case, label):
            self._changed(label)

    def _data(self) -> dict[str, Any]:
        return self.case.model_dump(mode="json")

    def set_title(self, title: str) -> None:
        self._edit({**self._data(), "title": title}, "title")

    def _illusion(self, index: int | None) -> Illusion:
        illusions = self.case.illusions
        if index is None or not 0 <= index < len(illusions):
            raise EditError(SELECT_FIRST)
        return illusions[index]

    def _edit_illusion(self, index: int | None, changes: dict[str, Any], label: str) -> None:
        if index is None:
            raise EditError(SELECT_FIRST)
        data = self._data()
        data["illusions"][index] = {**data["illusions"][index], **changes}
        self._edit(data, label)

    def place(self, illusion_type: str, s_road: float, t_road: float) -> int:
        """Add an illusion of ``illusion_type`` at road coordinates (s, t) and select it; returns its index."""
        model = REGISTRY.get(illusion_type)
        if model is None:
            raise EditError(f"type: unknown illusion type {illusion_type!r}")
        fields = placement_fields(model, self._network(), s_road, t_road)
        data = self._data()
        data["illusions"].append({"type": illusion_type, **fields})
        with self._lock:
            self._edit(data, f"placed {illusion_type}")
            self.selected = len(data["illusions"]) - 1
        self._changed(f"placed {illusion_type} at s = {fields['s']:.1f} m")
        return self.selected

    def select(self, index: int | None) -> None:
        if index is not None:
            self._illusion(index)
        self.selected = index
        self._changed(None)

    def move_selected(self, p_world: np.ndarray) -> None:
        """Move the selected illusion to the road point under ``p_world`` (s, and side/offset where it has them)."""
        illusion = self._illusion(self.selected)
        s_road, t_road, _h = road_coordinates(self._network().main.line, np.asarray(p_world))
        fields = placement_fields(type(illusion), self._network(), float(s_road[0]), float(t_road[0]), illusion)
        self._edit_illusion(self.selected, fields, f"moved {illusion.type}")

    def set_severity(self, level: int) -> None:
        illusion = self._illusion(self.selected)
        self._edit_illusion(self.selected, {"severity": int(level)}, f"{illusion.type} severity {level}")

    def set_field(self, name: str, value: Any) -> None:
        illusion = self._illusion(self.selected)
        self._edit_illusion(self.selected, {name: value}, f"{illusion.type} {name}")

    def upload_mesh(self, filename: str, data: bytes) -> str:
        """Store a model in the server's uploads folder (as ``POST /api/meshes`` does) and make it the selected
        vehicle's ``mesh_file``; returns the name it is stored under."""
        illusion = self._illusion(self.selected)
        if "mesh_file" not in type(illusion).model_fields:
            raise EditError(f"a {illusion.type} takes no mesh: select a vehicle, then upload its model")
        try:
            name = store_mesh(self.state.meshes_dir, filename, data, self.state.settings.max_upload_bytes)
        except MeshUploadError as error:
            raise EditError(f"mesh not stored: {error}") from None
        self.set_field("mesh_file", name)
        return name

    def delete_selected(self) -> None:
        illusion = self._illusion(self.selected)
        data = self._data()
        del data["illusions"][self.selected]
        self.selected = None
        self._edit(data, f"deleted {illusion.type}")

    def set_sun(self, azimuth: float | None = None, altitude: float | None = None,
                intensity: float | None = None) -> None:
        """Move the case's sun; illusions that set the sun themselves (shadows) get the same value as override."""
        data = self._data()
        changes = {name: value for name, value in zip(SUN_FIELDS, (azimuth, altitude, intensity)) if value is not None}
        data["sun"].update(changes)
        for illusion, spec in zip(self.case.illusions, data["illusions"]):
            for name, value in changes.items():
                field = f"sun_{name}"
                if field in type(illusion).model_fields:
                    low, high = field_bounds(type(illusion), field)
                    spec[field] = float(np.clip(value, low, high))
        self._edit(data, f"sun {_described(changes)}")

    def set_weather_preset(self, name: str) -> None:
        if name == CUSTOM_WEATHER:
            return
        try:
            values = preset_values(name)
        except KeyError as error:
            raise EditError(f"weather: {error.args[0]}") from None
        data = self._data()
        data["weather"].update(values["weather"])
        data["sun"].update({k: v for k, v in values["sun"].items() if k != "azimuth"})
        self._edit(data, f"weather {name}")

    def set_pavement(self, pavement: str) -> None:
        """Pave the carriageway with ``pavement`` (asphalt or concrete slabs; the case model refuses others)."""
        data = self._data()
        data["road"]["pavement"] = pavement
        self._edit(data, f"pavement {pavement}")

    def set_camera_preset(self, name: str) -> None:
        """See the case through a named camera (its mount, field of view, lens, bonnet and sensor)."""
        if name == CUSTOM_CAMERA:
            return
        try:
            values = camera_preset_values(name)
        except KeyError as error:
            raise EditError(f"camera: {error.args[0]}") from None
        data = self._data()
        data["camera"] = {**data["camera"], "lens": {}, "bonnet": None, "sensor": None, **values}
        self._edit(data, f"camera {name}")

    def set_camera(self, **changes: float) -> None:
        """Change camera fields (``fov``, ``z``, ``pitch``, ``roll`` ...)."""
        self._edit_camera(None, changes)

    def set_lens(self, **changes: float) -> None:
        self._edit_camera("lens", changes)

    def set_camera_part(self, part: str, on: bool) -> None:
        """Put the ``bonnet`` or the ``sensor`` in (with its defaults) or take it out."""
        data = self._data()
        if on == (data["camera"][part] is not None):
            return
        defaults = {"bonnet": Bonnet, "sensor": Sensor}[part]
        data["camera"][part] = defaults().model_dump(mode="json") if on else None
        self._edit(data, f"{part} {'on' if on else 'off'}")

    def set_sensor(self, **changes: float) -> None:
        self._edit_camera("sensor", changes)

    def _edit_camera(self, part: str | None, changes: dict[str, float]) -> None:
        """Update the camera's fields, or those of its ``part`` (``lens``, ``sensor``)."""
        data = self._data()
        fields = data["camera"] if part is None else data["camera"][part]
        if fields is None:
            raise EditError(f"{part}: tick Real sensor first")
        fields.update(changes)
        self._edit(data, f"{part or 'camera'} {_described(changes)}")

    # ------------------------------------------------------------------------------------------ view

    def set_frame(self, frame: int) -> None:
        self.frame = int(np.clip(frame, 0, self.case.ego.frames - 1))
        self._request_preview()

    def set_overlay(self, on: bool) -> None:
        with self._syncing_panel():
            self.panel.overlay.value = on
        self._request_preview()

    def set_detector(self, name: str) -> None:
        """Show ``name``'s lanes and score on the preview (``none``: no detector)."""
        with self._syncing_panel():
            self.panel.detector.value = name
        self._request_preview()

    def set_quality(self, quality: str) -> None:
        """``draft``: quick previews while a slider moves, the exact frame once it rests; ``full``: exact only."""
        if quality not in QUALITIES:
            raise EditError(f"quality: choose one of {', '.join(QUALITIES)}, not {quality!r}")
        with self._syncing_panel():
            self.panel.quality.value = quality
        self._request_preview()

    def set_playing(self, on: bool) -> None:
        (self._playing.set if on else self._playing.clear)()

    def _play_loop(self) -> None:
        while not self._stopped.is_set():
            if not self._playing.wait(0.2) or self.session is None:
                continue
            started = time.monotonic()
            nxt = (self.frame + 1) % self.case.ego.frames
            with self._syncing_panel():
                self.panel.frame.value = nxt
            self.set_frame(nxt)
            self._stopped.wait(max(0.0, 1.0 / self.case.ego.fps - (time.monotonic() - started)))

    def _network(self) -> RoadNetwork:
        return self.state.frames.scene(self.case).network

    def _selection_index(self, label: str) -> int | None:
        return None if label == NO_SELECTION else int(label.split(":", 1)[0])

    def _clicked(self, event: viser.SceneClickEvent) -> None:
        self.click(np.array(event.ray_origin), np.array(event.ray_direction))

    def click(self, ray_origin_world: np.ndarray, ray_dir_world: np.ndarray) -> int | None:
        """A click in the 3D view: with a type chosen under Place, put one there; otherwise select the illusion
        nearest to the clicked road point. Returns the index of the placed or selected illusion."""
        surface = self.view.surface
        if surface is None:
            raise EditError("the 3D view is still loading; click again in a moment")
        hit = ray_surface_hit(surface, ray_origin_world, ray_dir_world, self._network().main.line)
        place_type = str(self.panel.place.value)
        if hit is None:
            if place_type != PLACE_OFF:
                raise EditError("position: click on the road surface to place the illusion")
            return None
        if place_type == PLACE_OFF:
            return self._select_near(hit.p_world)
        if hit.piece != 0:
            raise EditError("position: place illusions on the main road, not a side road")
        index = self.place(place_type, hit.s_road, hit.t_road)
        with self._syncing_panel():
            self.panel.place.value = PLACE_OFF
        return index

    def _select_near(self, p_world: np.ndarray) -> int | None:
        network, case = self._network(), self.case
        best, best_d = None, SELECT_RADIUS_M
        for index, illusion in enumerate(case.illusions):
            s_road, t_road = anchor_road(illusion, case, network)
            distance = float(np.linalg.norm(network.main.line.to_world(s_road, t_road)[:2] - p_world[:2]))
            if distance < best_d:
                best, best_d = index, distance
        if best is not None:
            self.select(best)
        return best

    # ------------------------------------------------------------------------------------------ refresh

    def _syncing_panel(self):
        editor = self

        class _Syncing:
            def __enter__(self) -> None:
                self.previous = getattr(editor._syncing, "on", False)
                editor._syncing.on = True

            def __exit__(self, *exc: object) -> None:
                editor._syncing.on = self.previous

        return _Syncing()

    def _changed(self, message: str | None) -> None:
        """After any change: sync every panel input to the case, ask for a new preview."""
        if message is not None:
            self.message = message
        with self._lock:
            if self.selected is not None and self.selected >= len(self.case.illusions):
                self.selected = None
            self._sync_panel()
        self._request_preview()

    def _status(self, error: bool = False) -> str:
        session = self.session
        if session is None:
            return "No case open."
        facts = [f"**{escape_markdown(session.case_id)}** · version {session.version}"]
        facts.append("unsaved changes" if session.dirty else "saved")
        if session.remote_version is not None:
            facts.append(f"version {session.remote_version} in the store")
        line = f"\n\n{'⚠ ' if error else ''}{escape_markdown(self.message)}" if self.message else ""
        return " · ".join(facts) + line

    def _report(self, message: str, error: bool = False) -> None:
        self.message = message
        self.panel.status.content = self._status(error)
        if error:
            self.client.add_notification("Editor", message, color="red", auto_close_seconds=8.0)

    def _sync_panel(self) -> None:
        p, case, session = self.panel, self.case, self._current()
        with self._syncing_panel():
            if session.case_id not in p.case_id.options:
                p.case_id.options = self._case_ids()
            p.case_id.value = session.case_id
            p.title.value = case.title
            labels = [NO_SELECTION] + [f"{i}: {illusion.type} (level {illusion.severity})"
                                       for i, illusion in enumerate(case.illusions)]
            p.selected.options = labels
            p.selected.value = labels[0 if self.selected is None else self.selected + 1]
            illusion = case.illusions[self.selected] if self.selected is not None else None
            p.severity.disabled = p.delete.disabled = illusion is None
            if illusion is not None:
                p.severity.value = illusion.severity
            p.params.show(illusion)
            p.sun_azimuth.value = _wrap_degrees(case.sun.azimuth)
            p.sun_altitude.value = float(np.clip(case.sun.altitude, p.sun_altitude.min, p.sun_altitude.max))
            p.sun_intensity.value = case.sun.intensity
            p.pavement.value = case.road.pavement
            camera = case.camera
            for handle, value in ((p.camera_fov, camera.hfov), (p.camera_height, camera.z),
                                  (p.camera_pitch, camera.pitch), (p.camera_roll, camera.roll),
                                  (p.camera_k1, camera.lens.k1)):
                handle.value = float(np.clip(value, handle.min, handle.max))
            p.camera_bonnet.value = camera.bonnet is not None
            p.camera_sensor.value = camera.sensor is not None
            p.camera_exposure.disabled = p.camera_noise.disabled = camera.sensor is None
            if camera.sensor is not None:
                p.camera_exposure.value = camera.sensor.bias
                p.camera_noise.value = float(np.clip(camera.sensor.noise, p.camera_noise.min, p.camera_noise.max))
            p.frame.max = case.ego.frames - 1
            p.frame.value = self.frame
            p.undo.disabled, p.redo.disabled = not session.can_undo, not session.can_redo
            p.status.content = self._status()

    def _request_preview(self) -> int:
        detector = chosen_detector(str(self.panel.detector.value))
        quality = next(q for q in QUALITIES if q == self.panel.quality.value)
        return self.preview.request(self.case, self.frame, bool(self.panel.overlay.value), detector=detector,
                                    quality=quality)

    def _render(self, request: PreviewRequest) -> tuple[np.ndarray, CompiledScene]:
        scene = self.state.frames.scene(request.case)
        frames = self.state.frames
        if request.draft:
            return frames.draft(request.case, request.frame, DRAFT_SIZE, request.overlay).rgb, scene
        try:
            rendered = frames.frame(request.case, request.frame, request.size, request.overlay, request.detector)
        except LaneFileError:  # an unavailable detector: the frame without it; _publish says why
            rendered = frames.frame(request.case, request.frame, request.size, request.overlay)
        return rendered.rgb, scene

    def _detection_text(self, request: PreviewRequest) -> str:
        """The score line of the preview's detector (from the frame service's cache: ``_render`` ran it)."""
        if request.detector is None:
            return ""
        try:
            found = self.state.frames.detection(request.case, request.frame, request.size, request.detector)
        except LaneFileError as error:
            return unavailable_text(request.detector, str(error))
        return detection_text(found)

    def _publish(self, result: PreviewResult) -> None:
        """Push the preview image first (latency), then bring the 3D view up to the same state (after the exact
        frame only: a draft's state is about to be replaced by the next one or refined)."""
        self.panel.preview.image = result.rgb
        self.push_log.append((result.request.seq, time.perf_counter()))
        self.last_result = result
        case, scene = result.request.case, result.scene
        timing = f"rendered in {result.render_ms:.0f} ms" if result.render_ms >= 1.0 else "from the frame cache"
        kind = "draft " if result.request.draft else ""
        self.panel.preview_info.content = (f"Frame {result.request.frame} · {kind}{result.rgb.shape[1]}×"
                                           f"{result.rgb.shape[0]} · {timing}")
        if result.request.draft:  # no detector, no 3D view: both wait for the exact frame
            return
        self.panel.detection.content = self._detection_text(result.request)
        selected = self.selected if self.selected is not None and self.selected < len(case.illusions) else None
        road_key = roadside_key(case)
        # An illusion's meshes may depend on those placed before it (traffic keeps clear of earlier footprints).
        specs = [illusion.model_dump_json() for illusion in case.illusions]
        keys = [f"{road_key}:{':'.join(specs[:i + 1])}" for i in range(len(specs))]
        if road_key != self._aimed_key:
            self._aim_cameras(case, scene.network)
            self._aimed_key = road_key
        self.view.show(scene, road_key, keys, selected)
        self.view.show_camera(ego_camera(case, scene.network, result.request.frame))
        anchor = anchor_road(case.illusions[selected], case, scene.network) if selected is not None else None
        self.view.show_gizmo(anchor, self._guarded(self.move_selected))

    def _aim_cameras(self, case: Case, network: RoadNetwork) -> None:
        """Look down the road from behind and above the ego's start (a new tab, and a tab on a new road)."""
        line = network.main.line
        s_start = case.ego.start_s
        t_lane = network.lane_center_t(case.ego.lane)
        position = line.to_world(max(s_start - CAMERA_BACK_M, 0.0), t_lane - CAMERA_SIDE_M, CAMERA_UP_M)
        look_at = line.to_world(min(s_start + CAMERA_AHEAD_M, line.length), t_lane, 0.0)
        self.client.camera.position, self.client.camera.look_at = position, look_at

    def _preview_failed(self, request: PreviewRequest, error: Exception) -> None:
        self._report(f"Preview failed: {type(error).__name__}: {error}", error=True)

    # ------------------------------------------------------------------------------------------ export

    def _send(self, name: str, data: bytes) -> None:
        self.client.send_file_download(name, data, save_immediately=True)

    def export_case(self) -> tuple[str, bytes]:
        """Download the edited case's JSON in this tab."""
        name, data = export.case_download(self._current().case_id, self.case)
        self._send(name, data)
        return name, data

    def export_frame(self) -> list[tuple[str, bytes]]:
        """Download the current frame (PNG) and its labels in this tab."""
        files = export.frame_downloads(self.state, self._current().case_id, self.case, self.frame)
        for name, data in files:
            self._send(name, data)
        return files

    def export_sequence(self, frames: range | None = None):
        """Start the sequence zip as a backend job; progress shows as a notification, the zip downloads at the end."""
        session = self._current()
        fallback = self.state.store.get(session.case_id).illusion_type
        notes: list[viser.NotificationHandle] = []

        def notify(title: str, body: str, loading: bool, color: str | None) -> None:
            if not notes:
                notes.append(self.client.add_notification(title, body, loading=loading, with_close_button=True))
                return
            note = notes[0]
            note.title, note.body, note.loading = title, body, loading
            if color is not None:
                note.color = color  # type: ignore[assignment]  # one of viser's colour names

        frames = frames if frames is not None else range(self.case.ego.frames)
        job = export.start_sequence_export(self.state, session.case_id, self.case, fallback, frames, self._send,
                                           notify)
        self._report(f"exporting {len(frames)} frames (job {job.id[:8]})")
        return job


def _described(changes: dict[str, float]) -> str:
    """``name value, ...`` of an edit's changes, for its undo label."""
    return ", ".join(f"{k} {v:g}" for k, v in changes.items())
