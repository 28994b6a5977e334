"""The Camera folder: a camera preset, the mount, the lens's k1, the bonnet and the sensor."""

from __future__ import annotations

from typing import TYPE_CHECKING

import viser

from lanevil_core.case import Bonnet, Case, Sensor
from lanevil_core.presets import CAMERA_PRESET_NAMES, camera_preset_values

from ..session import CaseSession
from .base import EditError, described, set_clipped, set_value
from .sections import SectionInputs

if TYPE_CHECKING:
    from ..tab import EditorTab

CUSTOM_CAMERA = "(the case's camera)"
SLIDER_FIELDS = ("fov", "z", "pitch", "roll")  # the camera's fields with a slider of their own


class CameraPanel:
    """The case's camera."""

    def __init__(self, tab: EditorTab, gui: viser.GuiApi) -> None:
        self.tab = tab
        guarded = tab.guarded
        with gui.add_folder("Camera", expand_by_default=False):
            self.preset = gui.add_dropdown("Camera preset", [CUSTOM_CAMERA, *CAMERA_PRESET_NAMES],
                                           hint="the paper's CARLA camera, a TuSimple- or CULane-like front camera "
                                                "or a dash cam: field of view, mount, lens, bonnet and sensor")
            self.preset.on_update(guarded(lambda e: self.set_preset(str(e.target.value))))
            self.fov = gui.add_slider("Field of view", 30.0, 120.0, 0.5, 90.0, hint="horizontal, degrees")
            self.fov.on_update(guarded(lambda e: self.set_camera(fov=float(e.target.value))))
            self.height = gui.add_slider("Mount height", 0.5, 6.0, 0.05, 3.0, hint="above the road (m)")
            self.height.on_update(guarded(lambda e: self.set_camera(z=float(e.target.value))))
            self.pitch = gui.add_slider("Pitch", -10.0, 15.0, 0.1, 0.0, hint="degrees, positive looks down")
            self.pitch.on_update(guarded(lambda e: self.set_camera(pitch=float(e.target.value))))
            self.roll = gui.add_slider("Roll", -10.0, 10.0, 0.1, 0.0, hint="degrees about the optical axis")
            self.roll.on_update(guarded(lambda e: self.set_camera(roll=float(e.target.value))))
            self.k1 = gui.add_slider("Lens k1", -0.3, 0.1, 0.005, 0.0,
                                     hint="radial distortion (negative: a wide lens's barrel); labels follow it")
            self.k1.on_update(guarded(lambda e: self.set_lens(k1=float(e.target.value))))
            self.bonnet = gui.add_checkbox("Bonnet in view", False, hint="the ego's hood; labels stop at its edge")
            self.bonnet.on_update(guarded(lambda e: self.set_part("bonnet", bool(e.target.value))))
            self.sensor = gui.add_checkbox("Real sensor", False,
                                           hint="auto-exposure, filmic response, noise, motion blur, texture")
            self.sensor.on_update(guarded(lambda e: self.set_part("sensor", bool(e.target.value))))
            self.exposure = gui.add_slider("Exposure bias", -3.0, 3.0, 0.1, 0.0, hint="EV (real sensor)")
            self.exposure.on_update(guarded(lambda e: self.set_sensor(bias=float(e.target.value))))
            self.noise = gui.add_slider("Sensor noise", 0.0, 4.0, 0.1, 1.0, hint="1 = a typical small sensor")
            self.noise.on_update(guarded(lambda e: self.set_sensor(noise=float(e.target.value))))
            self.more = SectionInputs(tab, gui, "camera", gui.add_folder("More camera fields", expand_by_default=False),
                                      skip=SLIDER_FIELDS)

    def set_preset(self, name: str) -> None:
        """See the case through a named camera (its mount, field of view, lens, bonnet and sensor)."""
        if name == CUSTOM_CAMERA:
            return
        try:
            values = camera_preset_values(name)
        except KeyError as error:
            raise EditError(f"camera: {error.args[0]}") from None
        data = self.tab.data()
        data["camera"] = {**data["camera"], "lens": {}, "bonnet": None, "sensor": None, **values}
        self.tab.edit(data, f"camera {name}")

    def set_camera(self, **changes: float) -> None:
        """Change camera fields (``fov``, ``z``, ``pitch``, ``roll`` ...)."""
        self._edit(None, changes)

    def set_lens(self, **changes: float) -> None:
        self._edit("lens", changes)

    def set_sensor(self, **changes: float) -> None:
        self._edit("sensor", changes)

    def set_part(self, part: str, on: bool) -> None:
        """Put the ``bonnet`` or the ``sensor`` in (with its defaults) or take it out."""
        data = self.tab.data()
        if on == (data["camera"][part] is not None):
            return
        defaults = {"bonnet": Bonnet, "sensor": Sensor}[part]
        data["camera"][part] = defaults().model_dump(mode="json") if on else None
        self.tab.edit(data, f"{part} {'on' if on else 'off'}")

    def _edit(self, part: str | None, changes: dict[str, float]) -> None:
        """Update the camera's fields, or those of its ``part`` (``lens``, ``sensor``)."""
        data = self.tab.data()
        fields = data["camera"] if part is None else data["camera"][part]
        if fields is None:
            raise EditError(f"{part}: tick Real sensor first")
        fields.update(changes)
        self.tab.edit(data, f"{part or 'camera'} {described(changes)}")

    def field_paths(self) -> set[tuple[str, ...]]:
        return {("camera", name) for name in SLIDER_FIELDS} | self.more.field_paths()

    def sync(self, case: Case, session: CaseSession) -> None:
        """The case's camera on the sliders (clipped to their ranges) and in its other fields."""
        self.more.sync(case, session)
        camera = case.camera
        for handle, value in ((self.fov, camera.hfov), (self.height, camera.z), (self.pitch, camera.pitch),
                              (self.roll, camera.roll), (self.k1, camera.lens.k1)):
            set_clipped(handle, value)
        set_value(self.bonnet, camera.bonnet is not None)
        set_value(self.sensor, camera.sensor is not None)
        self.exposure.disabled = self.noise.disabled = camera.sensor is None
        if camera.sensor is not None:
            set_value(self.exposure, camera.sensor.bias)
            set_clipped(self.noise, camera.sensor.noise)
