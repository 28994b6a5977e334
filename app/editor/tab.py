"""One browser tab of the editor: its own panels, 3D view, preview and case session, wired to the shared store.

Each viser client (a browser tab) gets an ``EditorTab`` built in its client-scoped GUI and scene: its open case,
unsaved edits and undo history, selection, frame, overlay, detector, quality and camera pose are its own, so what
one tab changes never shows in another tab, nor in one opened later. Tabs meet in the store: a save goes through
its version check, and each tab follows the store's changes of its open case (``CaseStore.subscribe``).

The panels (``panels/``) create their inputs with their callbacks and hold the user actions (``tab.cases.save``,
``tab.illusions.place``, ``tab.sun.set_sun`` …); the tab holds what they share: the session and its edits, the
selection and frame, the status line, the preview worker and the 3D view. Tests and the latency benchmark call the
panels' actions or set their handles directly.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
import viser

from lanevil_core.camera import ego_camera
from lanevil_core.case import Case, CaseError, parse_case
from lanevil_core.metrics.formats import LaneFileError
from lanevil_core.pipeline.compile import roadside_key
from lanevil_core.world.road_layout import RoadNetwork
from lanevil_core.world.scene import CompiledScene

from ..state import AppState
from ..store import StoreError
from .drive_panel import DrivePanel
from .page import BrowserWebGL
from .panels import (
    CameraPanel,
    CasePanel,
    DisplayPanel,
    EditError,
    ExportPanel,
    IllusionsPanel,
    RoadPanel,
    ScenePanel,
    StartScreen,
    SunPanel,
)
from .placement import anchor_road
from .preview import DRAFT_SIZE, PreviewRequest, PreviewResult, PreviewWorker
from .scene_view import SceneView
from .session import CaseSession, SessionRegistry
from .text import escape_markdown

# The 3D view's start pose: behind, beside and above the ego's start, looking down the road.
CAMERA_BACK_M, CAMERA_SIDE_M, CAMERA_UP_M, CAMERA_AHEAD_M = 18.0, 6.0, 14.0, 35.0
HELP = """**LanEvil editor** — build a lane-detection test case in 3D.

1. *Case*: open a stored case or create one from a road template.
2. *Illusions*: pick a type under **Place**, then click the road. Select one to move it with the arrows,
   change its severity (1 subtle – 5 most deceptive) and parameters, or delete it.
3. *Sun & weather*, *Frame*: scrub and watch the camera preview.
4. **Save** writes the case (Ctrl+Z / Ctrl+Shift+Z undo and redo); *Export* downloads it.
"""


class EditorTab:
    """The editor as one viser client (browser tab) sees it, over the backend's ``AppState``."""

    def __init__(self, state: AppState, client: viser.ClientHandle, case_id: str | None = None,
                 webgl: BrowserWebGL | None = None) -> None:
        self.state = state
        self.client = client
        self.sessions = SessionRegistry(state.store)  # this tab's sessions: its unsaved edits are its own
        self.session: CaseSession | None = None
        self.frame = 0
        self.selected: int | None = None
        self.message = ""
        self.push_log: list[tuple[int, float]] = []  # (request seq, perf_counter when the image was pushed)
        self.last_result: PreviewResult | None = None
        self.lock = threading.RLock()
        self._aimed_key: str | None = None
        self._syncing = threading.local()
        self.view = SceneView(client.scene)
        self.preview = PreviewWorker(self._render, self._publish, self._preview_failed)
        gui = client.gui
        gui.configure_theme(control_width="large", show_share_button=False, brand_color=(214, 98, 32))
        gui.set_panel_label("LanEvil editor")
        with gui.add_folder("Help", expand_by_default=False):
            gui.add_markdown(HELP)
        self.status = gui.add_markdown("Opening…")
        self.display = DisplayPanel(self, gui, webgl or BrowserWebGL())
        self.cases = CasePanel(self, gui)
        self.illusions = IllusionsPanel(self, gui)
        self.road = RoadPanel(self, gui)
        self.scene = ScenePanel(self, gui)
        self.sun = SunPanel(self, gui)
        self.camera = CameraPanel(self, gui)
        self.exports = ExportPanel(self, gui)
        self.panels = (self.display, self.cases, self.illusions, self.road, self.scene, self.sun, self.camera)
        self.drive = DrivePanel(gui, state, lambda: (self.current().case_id, self.case),
                                self.display.chosen_detector)
        self._unsubscribe = state.store.subscribe(self.cases.stored)
        self.on_scene_click = self.guarded(self._clicked)  # what a browser click calls
        client.scene.on_click()(self.on_scene_click)
        ids = self.case_ids()
        if case_id is not None or ids:
            self.cases.open_case(case_id if case_id is not None else ids[0])
        # A tab opened on no particular case starts on the start screen (the first case open behind it).
        self.start = StartScreen(self, gui) if case_id is None else None

    @property
    def client_id(self) -> int:
        return self.client.client_id

    def stop(self) -> None:
        """Stop the preview worker, the player and the drive playback (the tab closed or the editor stops)."""
        self.display.stop()
        self.drive.stop()
        self._unsubscribe()
        self.preview.stop()

    # ------------------------------------------------------------------------------------------ what panels share

    def guarded(self, action: Callable[..., Any]) -> Callable[..., None]:
        """A callback that ignores updates made while the panel is being synced, and reports ``EditError``s."""

        def callback(*args: Any) -> None:
            if getattr(self._syncing, "on", False):
                return
            try:
                action(*args)
            except (EditError, CaseError, StoreError) as error:
                self.report(str(error), error=True)

        return callback

    @contextmanager
    def syncing(self) -> Iterator[None]:
        """Within it, setting an input's value does not run its callback (the panel follows the case)."""
        previous = getattr(self._syncing, "on", False)
        self._syncing.on = True
        try:
            yield
        finally:
            self._syncing.on = previous

    def case_ids(self) -> list[str]:
        return [record.id for record in self.state.store.list()]

    def current(self) -> CaseSession:
        if self.session is None:
            raise EditError("open a case first (Case → Open)")
        return self.session

    @property
    def case(self) -> Case:
        """The case as currently edited (unsaved changes included)."""
        return self.current().case

    def data(self) -> dict[str, Any]:
        """The edited case as JSON data, for an edit to change and hand to ``edit``."""
        return self.case.model_dump(mode="json")

    def edit(self, data: dict[str, Any], label: str) -> None:
        """Make ``data`` the edited case (an undo step named ``label``) if the case model takes it."""
        session = self.current()
        case = parse_case(data, source=session.case_id)
        if session.apply(case, label):
            self.changed(label)

    def network(self) -> RoadNetwork:
        return self.state.frames.scene(self.case).network

    def changed(self, message: str | None) -> None:
        """After any change: sync every panel to the case, ask for a new preview."""
        if message is not None:
            self.message = message
        with self.lock:
            case, session = self.case, self.current()
            if self.selected is not None and self.selected >= len(case.illusions):
                self.selected = None
            with self.syncing():
                for panel in self.panels:
                    panel.sync(case, session)
                self.status.content = self._status()
        self.request_preview()

    def request_preview(self) -> int:
        return self.display.request_preview()

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

    def report(self, message: str, error: bool = False) -> None:
        """Show ``message`` on the status line (an error also as a notification)."""
        self.message = message
        self.status.content = self._status(error)
        if error:
            self.client.add_notification("Editor", message, color="red", auto_close_seconds=8.0)

    def _clicked(self, event: viser.SceneClickEvent) -> None:
        self.illusions.click(np.array(event.ray_origin), np.array(event.ray_direction))

    # ------------------------------------------------------------------------------------------ preview

    def _render(self, request: PreviewRequest) -> tuple[np.ndarray, CompiledScene]:
        scene = self.state.frames.scene(request.case)
        frames = self.state.frames
        if request.draft:
            return frames.draft(request.case, request.frame, DRAFT_SIZE, request.overlay).rgb, scene
        try:
            rendered = frames.frame(request.case, request.frame, request.size, request.overlay, request.detector)
        except LaneFileError:  # an unavailable detector: the frame without it; the score line says why
            rendered = frames.frame(request.case, request.frame, request.size, request.overlay)
        return rendered.rgb, scene

    def _publish(self, result: PreviewResult) -> None:
        """Push the preview image first (latency), then bring the 3D view up to the same state (after the exact
        frame only: a draft's state is about to be replaced by the next one or refined)."""
        self.display.image.image = result.rgb
        self.push_log.append((result.request.seq, time.perf_counter()))
        self.display.publish(result)
        if self.view.mode == "off":  # the camera preview is the main view
            self.view.show_backdrop(result.rgb)
        self.last_result = result
        if result.request.draft:  # a draft's state is about to be replaced or refined
            return
        self.sun.show_owner(result.request.case, result.scene.env.sun_set_by)
        if self.view.mode != "off":
            self.show_3d(result)

    def show_3d(self, result: PreviewResult) -> None:
        """Bring the 3D view up to the state of an exact preview."""
        case, scene = result.request.case, result.scene
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
        self.view.show_gizmo(anchor, self.guarded(self.illusions.move_selected))

    def _aim_cameras(self, case: Case, network: RoadNetwork) -> None:
        """Look down the road from behind and above the ego's start (a new tab, and a tab on a new road)."""
        line = network.main.line
        s_start = case.ego.start_s
        t_lane = network.lane_center_t(case.ego.lane)
        position = line.to_world(max(s_start - CAMERA_BACK_M, 0.0), t_lane - CAMERA_SIDE_M, CAMERA_UP_M)
        look_at = line.to_world(min(s_start + CAMERA_AHEAD_M, line.length), t_lane, 0.0)
        self.client.camera.position, self.client.camera.look_at = position, look_at

    def _preview_failed(self, request: PreviewRequest, error: Exception) -> None:
        self.report(f"Preview failed: {type(error).__name__}: {error}", error=True)
