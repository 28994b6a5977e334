"""The editor's control panel: every input, with short help, laid out in folders (no behaviour here).

``build_panel`` creates the inputs in one browser tab's GUI and returns their handles; ``tab.EditorTab`` wires
their callbacks. Inputs start at sensible defaults and carry hover hints.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import viser

from lanevil_core.illusions import ILLUSION_TYPES
from lanevil_core.presets import CAMERA_PRESET_NAMES, PRESET_NAMES
from lanevil_core.typed import PAVEMENTS, ROAD_TYPES, SCENE_KINDS

from .detection import NO_DETECTOR, detector_choices
from .params import ParamInputs
from .preview import PREVIEW_SIZE, QUALITIES

MESH_TYPES = ".glb,.gltf,.obj"  # what the upload dialog offers
PLACE_OFF = "(pick a type, then click the road)"
NO_SELECTION = "(none)"
CUSTOM_WEATHER = "(as in the case)"
CUSTOM_CAMERA = "(the case's camera)"
HELP = """**LanEvil editor** — build a lane-detection test case in 3D.

1. *Case*: open a stored case or create one from a road template.
2. *Illusions*: pick a type under **Place**, then click the road. Select one to move it with the arrows,
   change its severity (1 subtle – 5 most deceptive) and parameters, or delete it.
3. *Sun & weather*, *Frame*: scrub and watch the camera preview.
4. **Save** writes the case (Ctrl+Z / Ctrl+Shift+Z undo and redo); *Export* downloads it.
"""


@dataclass
class Panel:
    """Handles of every panel input."""

    status: viser.GuiMarkdownHandle
    case_id: viser.GuiDropdownHandle
    title: viser.GuiTextHandle
    save: viser.GuiButtonHandle
    save_copy: viser.GuiButtonHandle
    reload: viser.GuiButtonHandle
    undo: viser.GuiButtonHandle
    redo: viser.GuiButtonHandle
    template: viser.GuiDropdownHandle
    scene_kind: viser.GuiDropdownHandle
    create: viser.GuiButtonHandle
    place: viser.GuiDropdownHandle
    selected: viser.GuiDropdownHandle
    severity: viser.GuiSliderHandle
    delete: viser.GuiButtonHandle
    upload_mesh: viser.GuiUploadButtonHandle
    params: ParamInputs
    sun_azimuth: viser.GuiSliderHandle
    sun_altitude: viser.GuiSliderHandle
    sun_intensity: viser.GuiSliderHandle
    weather: viser.GuiDropdownHandle
    pavement: viser.GuiDropdownHandle
    camera_preset: viser.GuiDropdownHandle
    camera_fov: viser.GuiSliderHandle
    camera_height: viser.GuiSliderHandle
    camera_pitch: viser.GuiSliderHandle
    camera_roll: viser.GuiSliderHandle
    camera_k1: viser.GuiSliderHandle
    camera_bonnet: viser.GuiCheckboxHandle
    camera_sensor: viser.GuiCheckboxHandle
    camera_exposure: viser.GuiSliderHandle
    camera_noise: viser.GuiSliderHandle
    frame: viser.GuiSliderHandle
    play: viser.GuiCheckboxHandle
    overlay: viser.GuiCheckboxHandle
    detector: viser.GuiDropdownHandle
    quality: viser.GuiDropdownHandle
    preview: viser.GuiImageHandle
    preview_info: viser.GuiMarkdownHandle
    detection: viser.GuiMarkdownHandle
    export_case: viser.GuiButtonHandle
    export_frame: viser.GuiButtonHandle
    export_sequence: viser.GuiButtonHandle


def build_panel(gui: viser.GuiApi, case_ids: list[str]) -> Panel:
    """Create the panel's inputs (in display order) and return their handles."""
    gui.configure_theme(control_width="large", show_share_button=False, brand_color=(214, 98, 32))
    gui.set_panel_label("LanEvil editor")
    with gui.add_folder("Help", expand_by_default=False):
        gui.add_markdown(HELP)
    status = gui.add_markdown("Opening…")
    preview = gui.add_image(np.full((PREVIEW_SIZE[1], PREVIEW_SIZE[0], 3), 200, np.uint8), label="Camera preview",
                            format="jpeg", jpeg_quality=90)
    preview_info = gui.add_markdown("")
    detection = gui.add_markdown("")
    with gui.add_folder("Frame"):
        frame = gui.add_slider("Frame", 0, 99, 1, 0, hint="frame of the ego drive shown in the preview")
        play = gui.add_checkbox("Play", False, hint="step through the frames (loops)")
        overlay = gui.add_checkbox("Lane overlay", True, hint="draw the ground-truth lanes on the preview")
        detector = gui.add_dropdown("Detector", list(detector_choices()), initial_value=NO_DETECTOR,
                                    hint="run a lane detector on the preview: its lanes in magenta, its TuSimple "
                                         "accuracy / FP / FN under the picture")
        quality = gui.add_dropdown("Quality", list(QUALITIES), initial_value="draft",
                                   hint="draft: while a slider moves, a quick half-size preview without the camera's "
                                        "sensor stage, then the exact frame once it rests; full: only exact frames")
    with gui.add_folder("Case"):
        case_id = gui.add_dropdown("Open", case_ids or ["(no cases)"], hint="stored cases; choosing one opens it")
        title = gui.add_text("Title", "", hint="the case's title (saved with it)")
        save = gui.add_button("Save", icon=viser.Icon.DEVICE_FLOPPY, hint="write to the store (version-checked)")
        undo, redo = gui.add_button("Undo", icon=viser.Icon.ARROW_BACK_UP, hint="Ctrl+Z"), \
            gui.add_button("Redo", icon=viser.Icon.ARROW_FORWARD_UP, hint="Ctrl+Shift+Z")
        reload = gui.add_button("Reload stored version", hint="take the stored case (Undo brings your edits back)")
        save_copy = gui.add_button("Save as new case", hint="store your edits under a new id")
    with gui.add_folder("New case", expand_by_default=False):
        template = gui.add_dropdown("Road", list(ROAD_TYPES), initial_value="straight", hint="road template")
        scene_kind = gui.add_dropdown("Roadside", list(SCENE_KINDS), initial_value="suburban")
        create = gui.add_button("Create and open", icon=viser.Icon.PLUS)
    with gui.add_folder("Illusions"):
        place = gui.add_dropdown("Place", [PLACE_OFF, *ILLUSION_TYPES],
                                 hint="pick a type, then click the road in the 3D view to put it there")
        selected = gui.add_dropdown("Selected", [NO_SELECTION], hint="the illusion the sliders below edit")
        severity = gui.add_slider("Severity", 1, 5, 1, 3, marks=((1, "subtle"), (3, "3"), (5, "strong")),
                                  hint="1 = subtle … 5 = most deceptive", disabled=True)
        delete = gui.add_button("Delete illusion", icon=viser.Icon.TRASH, color="red", disabled=True)
        upload_mesh = gui.add_upload_button("Upload vehicle mesh", icon=viser.Icon.UPLOAD, mime_type=MESH_TYPES,
                                            hint="a .glb, .gltf or .obj model (at most 60,000 triangles) for the "
                                                 "selected vehicle's bodies; stored in the server's uploads folder")
        params_folder = gui.add_folder("Parameters", expand_by_default=False)
    with gui.add_folder("Sun & weather"):
        sun_azimuth = gui.add_slider("Sun azimuth", -180.0, 180.0, 1.0, 30.0,
                                     hint="degrees counter-clockwise from the road's start heading (90 = left)")
        sun_altitude = gui.add_slider("Sun altitude", -10.0, 90.0, 1.0, 45.0, hint="degrees above the horizon")
        sun_intensity = gui.add_slider("Sun intensity", 0.0, 3.0, 0.05, 1.0, hint="1 = clear noon")
        weather = gui.add_dropdown("Weather preset", [CUSTOM_WEATHER, *PRESET_NAMES],
                                   hint="fills cloud, rain, puddles, fog and the sun's height")
        pavement = gui.add_dropdown("Pavement", list(PAVEMENTS), initial_value="asphalt",
                                    hint="asphalt, or jointed concrete slabs with sealed joints")
    with gui.add_folder("Camera", expand_by_default=False):
        camera_preset = gui.add_dropdown("Camera preset", [CUSTOM_CAMERA, *CAMERA_PRESET_NAMES],
                                         hint="the paper's CARLA camera, a TuSimple- or CULane-like front camera or "
                                              "a dash cam: field of view, mount, lens, bonnet and sensor")
        camera_fov = gui.add_slider("Field of view", 30.0, 120.0, 0.5, 90.0, hint="horizontal, degrees")
        camera_height = gui.add_slider("Mount height", 0.5, 6.0, 0.05, 3.0, hint="above the road (m)")
        camera_pitch = gui.add_slider("Pitch", -10.0, 15.0, 0.1, 0.0, hint="degrees, positive looks down")
        camera_roll = gui.add_slider("Roll", -10.0, 10.0, 0.1, 0.0, hint="degrees about the optical axis")
        camera_k1 = gui.add_slider("Lens k1", -0.3, 0.1, 0.005, 0.0,
                                   hint="radial distortion (negative: a wide lens's barrel); labels follow it")
        camera_bonnet = gui.add_checkbox("Bonnet in view", False, hint="the ego's hood; labels stop at its edge")
        camera_sensor = gui.add_checkbox("Real sensor", False,
                                         hint="auto-exposure, filmic response, noise, motion blur, texture")
        camera_exposure = gui.add_slider("Exposure bias", -3.0, 3.0, 0.1, 0.0, hint="EV (real sensor)")
        camera_noise = gui.add_slider("Sensor noise", 0.0, 4.0, 0.1, 1.0, hint="1 = a typical small sensor")
    with gui.add_folder("Export", expand_by_default=False):
        export_case = gui.add_button("Case JSON", icon=viser.Icon.FILE_DOWNLOAD)
        export_frame = gui.add_button("Current frame (PNG + labels)", icon=viser.Icon.PHOTO)
        export_sequence = gui.add_button("Whole sequence (zip)", icon=viser.Icon.FILE_ZIP,
                                         hint="renders every frame with TuSimple labels in the background")
    return Panel(status=status, case_id=case_id, title=title, save=save, save_copy=save_copy, reload=reload,
                 undo=undo, redo=redo, template=template, scene_kind=scene_kind, create=create, place=place,
                 selected=selected, severity=severity, delete=delete, upload_mesh=upload_mesh,
                 params=ParamInputs(gui, params_folder, lambda name, value: None),
                 sun_azimuth=sun_azimuth, sun_altitude=sun_altitude, sun_intensity=sun_intensity, weather=weather,
                 pavement=pavement,
                 camera_preset=camera_preset, camera_fov=camera_fov, camera_height=camera_height,
                 camera_pitch=camera_pitch, camera_roll=camera_roll, camera_k1=camera_k1, camera_bonnet=camera_bonnet,
                 camera_sensor=camera_sensor, camera_exposure=camera_exposure, camera_noise=camera_noise, frame=frame,
                 play=play, overlay=overlay, detector=detector, quality=quality, preview=preview,
                 preview_info=preview_info, detection=detection,
                 export_case=export_case, export_frame=export_frame, export_sequence=export_sequence)
