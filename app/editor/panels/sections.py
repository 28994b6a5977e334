"""The case's sections as folders of inputs generated from the case model (``params.ModelInputs``): Road (with
its markings per boundary), Ego and Scene; the sun and camera panels hold the weather numbers and the camera's
other fields the same way. A change the case model refuses is shown in place, under the folder's title, and the
inputs go back to the case's values.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import viser

from lanevil_core.case import Case, CaseError, Marking, resize_markings
from lanevil_core.typed import LINE_TYPES

from ..params import ModelInputs
from ..session import CaseSession
from ..text import escape_markdown
from .base import set_value

if TYPE_CHECKING:
    from ..tab import EditorTab

FieldPath = tuple[str, ...]
LAST = 1e9  # viser order: after every input of the folder
FieldSetter = Callable[[FieldPath, Any], None]


class SectionInputs:
    """One section of the case (``road``, ``ego`` …) as inputs in a folder, with its last refusal in place."""

    def __init__(self, tab: EditorTab, gui: viser.GuiApi, section: str, folder: viser.GuiFolderHandle,
                 skip: tuple[str, ...] = (), setter: FieldSetter | None = None) -> None:
        self.tab = tab
        self.section = section
        with folder:
            self.error = gui.add_markdown("", visible=False)
        self.inputs = ModelInputs(gui, folder, tab.guarded(setter or self.set_field), skip)

    def set_field(self, path: FieldPath, value: Any) -> None:
        """Set the section's field at ``path`` (nested: ``("lens", "k1")``) to ``value``."""
        data = self.tab.data()
        target = data[self.section]
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value
        self.apply(data, f"{self.section}.{'.'.join(path)} {value}")

    def apply(self, data: dict[str, Any], label: str) -> None:
        """Edit the case; a refusal shows under the folder's title (and in the status line), and the inputs go
        back to the case's values."""
        try:
            self.tab.edit(data, label)
        except CaseError as error:
            self.error.content = f"⚠ {escape_markdown(str(error).split(': ', 1)[-1])}"
            self.error.visible = True
            self.tab.changed(None)
            raise
        self.error.visible = False

    def field_paths(self) -> set[FieldPath]:
        """The case paths these inputs edit."""
        return {(self.section, *path) for path in self.inputs.paths()}

    def sync(self, case: Case, session: CaseSession) -> None:
        self.inputs.show(getattr(case, self.section))


def boundary_label(index: int, lanes_per_direction: int) -> str:
    """``Line 0 (left edge)`` … ``Line 2 (centre)`` … of the boundary ``index``, left to right."""
    last = 2 * lanes_per_direction
    where = {0: "left edge", lanes_per_direction: "centre", last: "right edge"}.get(index, "lane line")
    return f"Line {index} ({where})"


class RoadPanel:
    """The Road folder: layout, paving and paint; a new lane count keeps the markings' styles."""

    def __init__(self, tab: EditorTab, gui: viser.GuiApi) -> None:
        self.tab = tab
        self.gui = gui
        self.section = SectionInputs(tab, gui, "road", gui.add_folder("Road", expand_by_default=False),
                                     skip=("markings",), setter=self.set_field)
        with self.section.inputs.folder:
            self.markings = gui.add_folder("Markings", expand_by_default=False, order=LAST)
        with self.markings:
            self.lines_folder = gui.add_folder("All lines", expand_by_default=False)
        self.lines = ModelInputs(gui, self.lines_folder, tab.guarded(self.set_lines), skip=("type",))
        self.line_types: list[viser.GuiDropdownHandle] = []

    def set_field(self, path: FieldPath, value: Any) -> None:
        """Set a road field; a new lane count resizes the markings (``resize_markings``) and keeps the ego on the
        road."""
        data = self.tab.data()
        data["road"][path[0]] = value
        if path == ("lanes_per_direction",) and isinstance(value, int) and value > 0:
            markings = [Marking.model_validate(m) for m in data["road"]["markings"]]
            data["road"]["markings"] = [m.model_dump(mode="json") for m in resize_markings(markings, value)]
            data["ego"]["lane"] = min(data["ego"]["lane"], value - 1)
        self.section.apply(data, f"road.{path[0]} {value}")

    def set_line_type(self, index: int, line_type: str) -> None:
        """Paint boundary ``index`` (left to right) with ``line_type``."""
        data = self.tab.data()
        data["road"]["markings"][index]["type"] = line_type
        self.section.apply(data, f"{boundary_label(index, self.tab.case.road.lanes_per_direction)} {line_type}")

    def set_lines(self, path: FieldPath, value: Any) -> None:
        """Set a paint field (width, dash, gap, wear) on every line."""
        data = self.tab.data()
        for marking in data["road"]["markings"]:
            marking[path[0]] = value
        self.section.apply(data, f"lines {path[0]} {value}")

    def field_paths(self) -> set[FieldPath]:
        marking_fields = {("road", "markings", *path) for path in self.lines.paths()}
        return self.section.field_paths() | marking_fields | ({("road", "markings", "type")} if self.line_types
                                                              else set())

    def sync(self, case: Case, session: CaseSession) -> None:
        self.section.sync(case, session)
        markings = case.road.markings
        if len(self.line_types) != len(markings):
            for handle in self.line_types:
                handle.remove()
            with self.markings:
                self.line_types = [self._line_type(index, case.road.lanes_per_direction)
                                   for index in range(len(markings))]
        for handle, marking in zip(self.line_types, markings, strict=True):
            set_value(handle, str(marking.type))
        self.lines.show(markings[0])

    def _line_type(self, index: int, lanes_per_direction: int) -> viser.GuiDropdownHandle:
        handle = self.gui.add_dropdown(boundary_label(index, lanes_per_direction), list(LINE_TYPES),
                                       hint="the paint of this lane boundary, left to right as the ego sees them")
        handle.on_update(self.tab.guarded(lambda e: self.set_line_type(index, str(e.target.value))))
        return handle


class ScenePanel:
    """The Ego and Scene folders (the case's seed with the scene)."""

    def __init__(self, tab: EditorTab, gui: viser.GuiApi) -> None:
        self.tab = tab
        self.ego = SectionInputs(tab, gui, "ego", gui.add_folder("Ego", expand_by_default=False))
        scene_folder = gui.add_folder("Scene", expand_by_default=False)
        self.scene = SectionInputs(tab, gui, "scene", scene_folder)
        with scene_folder:
            self.seed = gui.add_number("seed", 0, min=0, max=2**32 - 1, step=1,
                                       hint="the case's random seed: roadside props, illusion details, noise")
        self.seed.on_update(tab.guarded(lambda e: self.scene.apply({**tab.data(), "seed": int(e.target.value)},
                                                                   f"seed {e.target.value}")))

    def field_paths(self) -> set[FieldPath]:
        return self.ego.field_paths() | self.scene.field_paths() | {("seed",)}

    def sync(self, case: Case, session: CaseSession) -> None:
        self.ego.sync(case, session)
        self.scene.sync(case, session)
        set_value(self.seed, case.seed)
