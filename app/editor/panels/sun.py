"""The Sun & weather folder: the sun's direction and strength, weather presets and the weather's numbers."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import viser

from lanevil_core.case import Case
from lanevil_core.illusions import Illusion
from lanevil_core.presets import PRESET_NAMES, preset_values

from ..placement import field_bounds
from ..session import CaseSession
from ..text import escape_markdown
from .base import EditError, described, set_clipped, set_value, wrap_degrees
from .sections import SectionInputs

if TYPE_CHECKING:
    from ..tab import EditorTab

SUN_FIELDS = ("azimuth", "altitude", "intensity")
CUSTOM_WEATHER = "(as in the case)"


def has_sun_fields(illusion: Illusion) -> bool:
    """Whether the sun sliders reach an illusion's sun (its ``sun_*`` overrides)."""
    return all(f"sun_{name}" in type(illusion).model_fields for name in SUN_FIELDS)


def sun_owner_text(case: Case, sun_set_by: tuple[int, ...]) -> str:
    """Who sets the sun the preview shows, and which illusions' own suns it overrides (markdown)."""
    if not sun_set_by:
        return "☀ The sun is the case's: these sliders set it."
    owner = sun_set_by[-1]
    illusion = case.illusions[owner]
    how = ("the sliders set its sun" if has_sun_fields(illusion)
           else "its severity table places it, so the sliders are off while it is in the case")
    text = f"☀ Sun set by illusion **{owner}: {escape_markdown(illusion.type)}** ({how})."
    others = [f"{i}: {escape_markdown(other.type)}" for i, other in enumerate(case.illusions)
              if i != owner and type(other).SETS_SUN]
    if others:
        text += (f" ⚠ It overrides the sun of {', '.join(others)}: their shadows or glare follow this sun, "
                 "not their own.")
    return text


class SunPanel:
    """The sun and the weather."""

    def __init__(self, tab: EditorTab, gui: viser.GuiApi) -> None:
        self.tab = tab
        guarded = tab.guarded
        with gui.add_folder("Sun & weather"):
            self.owner = gui.add_markdown("")
            self.azimuth = gui.add_slider("Sun azimuth", -180.0, 180.0, 1.0, 30.0,
                                          hint="degrees counter-clockwise from the road's start heading (90 = left)")
            self.azimuth.on_update(guarded(lambda e: self.set_sun(azimuth=float(e.target.value))))
            self.altitude = gui.add_slider("Sun altitude", -10.0, 90.0, 1.0, 45.0, hint="degrees above the horizon")
            self.altitude.on_update(guarded(lambda e: self.set_sun(altitude=float(e.target.value))))
            self.intensity = gui.add_slider("Sun intensity", 0.0, 3.0, 0.05, 1.0, hint="1 = clear noon")
            self.intensity.on_update(guarded(lambda e: self.set_sun(intensity=float(e.target.value))))
            self.weather = gui.add_dropdown("Weather preset", [CUSTOM_WEATHER, *PRESET_NAMES],
                                            hint="fills cloud, rain, puddles, fog and the sun's height")
            self.weather.on_update(guarded(lambda e: self.set_weather_preset(str(e.target.value))))
            self.weather_numbers = SectionInputs(tab, gui, "weather", gui.add_folder("Weather numbers"))

    def set_sun(self, azimuth: float | None = None, altitude: float | None = None,
                intensity: float | None = None) -> None:
        """Move the case's sun; illusions that set the sun themselves (shadows) get the same value as override."""
        tab = self.tab
        data = tab.data()
        changes = {name: value for name, value in zip(SUN_FIELDS, (azimuth, altitude, intensity)) if value is not None}
        data["sun"].update(changes)
        for illusion, spec in zip(tab.case.illusions, data["illusions"]):
            for name, value in changes.items():
                field = f"sun_{name}"
                if field in type(illusion).model_fields:
                    low, high = field_bounds(type(illusion), field)
                    spec[field] = float(np.clip(value, low, high))
        tab.edit(data, f"sun {described(changes)}")

    def set_weather_preset(self, name: str) -> None:
        if name == CUSTOM_WEATHER:
            return
        try:
            values = preset_values(name)
        except KeyError as error:
            raise EditError(f"weather: {error.args[0]}") from None
        data = self.tab.data()
        data["weather"].update(values["weather"])
        data["sun"].update({k: v for k, v in values["sun"].items() if k != "azimuth"})
        self.tab.edit(data, f"weather {name}")

    def show_owner(self, case: Case, sun_set_by: tuple[int, ...]) -> None:
        """Say who sets the rendered sun (from the compiled scene); where an illusion's severity table places it,
        the sliders would not move it and are disabled."""
        self.owner.content = sun_owner_text(case, sun_set_by)
        fixed = bool(sun_set_by) and not has_sun_fields(case.illusions[sun_set_by[-1]])
        self.azimuth.disabled = self.altitude.disabled = self.intensity.disabled = fixed

    def field_paths(self) -> set[tuple[str, ...]]:
        return {("sun", name) for name in SUN_FIELDS} | self.weather_numbers.field_paths()

    def sync(self, case: Case, session: CaseSession) -> None:
        """The case's sun and weather."""
        set_value(self.azimuth, wrap_degrees(case.sun.azimuth))
        set_clipped(self.altitude, case.sun.altitude)
        set_value(self.intensity, case.sun.intensity)
        self.weather_numbers.sync(case, session)
