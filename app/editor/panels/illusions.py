"""The Illusions folder: place a type by clicking the road, select, severity, parameters, mesh upload, delete."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import viser
from viser._gui_handles import GuiModalHandle  # not re-exported by viser 1.x

from lanevil_core.case import Case
from lanevil_core.illusions import ILLUSION_TYPES, REGISTRY, Illusion

from ...meshes import MeshUploadError, store_mesh
from ..params import ParamInputs
from ..placement import anchor_road, placement_fields, ray_surface_hit, road_coordinates
from ..session import CaseSession
from ..text import escape_markdown
from .base import EditError, set_value

if TYPE_CHECKING:
    from ..tab import EditorTab

MESH_TYPES = ".glb,.gltf,.obj"  # what the upload dialog offers
PLACE_OFF = "(pick a type, then click the road)"
NO_SELECTION = "(none)"
SELECT_RADIUS_M = 8.0  # a click this close to an illusion's handle selects it
SELECT_FIRST = "select an illusion first (Illusions → Selected)"


def selection_index(label: str) -> int | None:
    """The illusion index a Selected label names (None for no selection)."""
    return None if label == NO_SELECTION else int(label.split(":", 1)[0])


class IllusionsPanel:
    """The case's illusions: placing, selecting and editing them."""

    def __init__(self, tab: EditorTab, gui: viser.GuiApi) -> None:
        self.tab = tab
        guarded = tab.guarded
        with gui.add_folder("Illusions"):
            self.place_type = gui.add_dropdown("Place", [PLACE_OFF, *ILLUSION_TYPES],
                                               hint="pick a type, then click the road in the 3D view to put it there")
            self.selected = gui.add_dropdown("Selected", [NO_SELECTION], hint="the illusion the sliders below edit")
            self.selected.on_update(guarded(lambda e: self.select(selection_index(str(e.target.value)))))
            self.severity = gui.add_slider("Severity", 1, 5, 1, 3, marks=((1, "subtle"), (3, "3"), (5, "strong")),
                                           hint="1 = subtle … 5 = most deceptive", disabled=True)
            self.severity.on_update(guarded(lambda e: self.set_severity(int(e.target.value))))
            self.delete_button = gui.add_button("Delete illusion", icon=viser.Icon.TRASH, color="red", disabled=True)
            self.delete_button.on_click(guarded(lambda e: self.delete_selected()))
            self.upload_button = gui.add_upload_button(
                "Upload vehicle mesh", icon=viser.Icon.UPLOAD, mime_type=MESH_TYPES,
                hint="a .glb, .gltf or .obj model (at most 60,000 triangles) for the selected vehicle's bodies; "
                     "stored in the server's uploads folder")
            self.upload_button.on_upload(guarded(lambda e: self.upload_mesh(e.target.value.name,
                                                                            e.target.value.content)))
            self.pending_sun: tuple[str, float, float] | None = None  # an illusion waiting for ask_sun's answer
            self._modal: GuiModalHandle | None = None
            self.params = ParamInputs(gui, gui.add_folder("Parameters", expand_by_default=False),
                                      guarded(self.set_field))

    # ------------------------------------------------------------------------------------------ actions

    def _illusion(self, index: int | None) -> Illusion:
        illusions = self.tab.case.illusions
        if index is None or not 0 <= index < len(illusions):
            raise EditError(SELECT_FIRST)
        return illusions[index]

    def _edit_illusion(self, index: int | None, changes: dict[str, Any], label: str) -> None:
        if index is None:
            raise EditError(SELECT_FIRST)
        data = self.tab.data()
        data["illusions"][index] = {**data["illusions"][index], **changes}
        self.tab.edit(data, label)

    def place(self, illusion_type: str, s_road: float, t_road: float, confirmed: bool = False) -> int | None:
        """Add an illusion of ``illusion_type`` at road coordinates (s, t) and select it; returns its index. One
        that sets the sun where another already does is placed only once the user confirms (``ask_sun``; None
        until then)."""
        tab = self.tab
        model = REGISTRY.get(illusion_type)
        if model is None:
            raise EditError(f"type: unknown illusion type {illusion_type!r}")
        rivals = [f"{i}: {other.type}" for i, other in enumerate(tab.case.illusions) if type(other).SETS_SUN]
        if model.SETS_SUN and rivals and not confirmed:
            self.ask_sun(illusion_type, s_road, t_road, rivals)
            return None
        fields = placement_fields(model, tab.network(), s_road, t_road)
        data = tab.data()
        data["illusions"].append({"type": illusion_type, **fields})
        with tab.lock:
            tab.edit(data, f"placed {illusion_type}")
            tab.selected = len(data["illusions"]) - 1
        tab.changed(f"placed {illusion_type} at s = {fields['s']:.1f} m")
        return tab.selected

    def ask_sun(self, illusion_type: str, s_road: float, t_road: float, rivals: list[str]) -> None:
        """Ask before a new illusion's sun overrides the sun of those already in the case."""
        self.pending_sun = (illusion_type, s_road, t_road)
        gui = self.tab.client.gui
        with gui.add_modal("One sun for the whole case") as modal:
            gui.add_markdown(f"**{escape_markdown(illusion_type)}** places the sun itself, and so does "
                             f"{escape_markdown(', '.join(rivals))}. A case has one sun: the illusion placed last "
                             "sets it, and the others' shadows or glare follow it.")
            place = gui.add_button("Place it: its sun wins", color="orange")
            cancel = gui.add_button("Cancel")
        self._modal = modal
        place.on_click(self.tab.guarded(lambda e: self.answer_sun(True)))
        cancel.on_click(self.tab.guarded(lambda e: self.answer_sun(False)))

    def answer_sun(self, place: bool) -> int | None:
        """The answer to ``ask_sun``: place the pending illusion (its index) or drop it."""
        pending, self.pending_sun = self.pending_sun, None
        if self._modal is not None:
            self._modal.close()
            self._modal = None
        if pending is None or not place:
            self.tab.report("not placed: the case keeps its sun")
            return None
        return self.place(*pending, confirmed=True)

    def select(self, index: int | None) -> None:
        if index is not None:
            self._illusion(index)
        self.tab.selected = index
        self.tab.changed(None)

    def move_selected(self, p_world: np.ndarray) -> None:
        """Move the selected illusion to the road point under ``p_world`` (s, and side/offset where it has them)."""
        selected = self.tab.selected
        illusion = self._illusion(selected)
        network = self.tab.network()
        s_road, t_road, _h = road_coordinates(network.main.line, np.asarray(p_world))
        fields = placement_fields(type(illusion), network, float(s_road[0]), float(t_road[0]), illusion)
        self._edit_illusion(selected, fields, f"moved {illusion.type}")

    def set_severity(self, level: int) -> None:
        illusion = self._illusion(self.tab.selected)
        self._edit_illusion(self.tab.selected, {"severity": int(level)}, f"{illusion.type} severity {level}")

    def set_field(self, name: str, value: Any) -> None:
        illusion = self._illusion(self.tab.selected)
        self._edit_illusion(self.tab.selected, {name: value}, f"{illusion.type} {name}")

    def upload_mesh(self, filename: str, data: bytes) -> str:
        """Store a model in the server's uploads folder (as ``POST /api/meshes`` does) and make it the selected
        vehicle's ``mesh_file``; returns the name it is stored under."""
        illusion = self._illusion(self.tab.selected)
        if "mesh_file" not in type(illusion).model_fields:
            raise EditError(f"a {illusion.type} takes no mesh: select a vehicle, then upload its model")
        settings = self.tab.state.settings
        try:
            name = store_mesh(self.tab.state.meshes_dir, filename, data, settings.max_upload_bytes)
        except MeshUploadError as error:
            raise EditError(f"mesh not stored: {error}") from None
        self.set_field("mesh_file", name)
        return name

    def delete_selected(self) -> None:
        tab = self.tab
        illusion = self._illusion(tab.selected)
        data = tab.data()
        del data["illusions"][tab.selected]
        tab.selected = None
        tab.edit(data, f"deleted {illusion.type}")

    def click(self, ray_origin_world: np.ndarray, ray_dir_world: np.ndarray) -> int | None:
        """A click in the 3D view: with a type chosen under Place, put one there; otherwise select the illusion
        nearest to the clicked road point. Returns the index of the placed or selected illusion."""
        surface = self.tab.view.surface
        if surface is None:
            raise EditError("the 3D view is still loading; click again in a moment")
        hit = ray_surface_hit(surface, ray_origin_world, ray_dir_world, self.tab.network().main.line)
        place_type = str(self.place_type.value)
        if hit is None:
            if place_type != PLACE_OFF:
                raise EditError("position: click on the road surface to place the illusion")
            return None
        if place_type == PLACE_OFF:
            return self._select_near(hit.p_world)
        if hit.piece != 0:
            raise EditError("position: place illusions on the main road, not a side road")
        index = self.place(place_type, hit.s_road, hit.t_road)
        with self.tab.syncing():
            set_value(self.place_type, PLACE_OFF)
        return index

    def _select_near(self, p_world: np.ndarray) -> int | None:
        network, case = self.tab.network(), self.tab.case
        best, best_d = None, SELECT_RADIUS_M
        for index, illusion in enumerate(case.illusions):
            s_road, t_road = anchor_road(illusion, case, network)
            distance = float(np.linalg.norm(network.main.line.to_world(s_road, t_road)[:2] - p_world[:2]))
            if distance < best_d:
                best, best_d = index, distance
        if best is not None:
            self.select(best)
        return best

    # ------------------------------------------------------------------------------------------ sync

    def sync(self, case: Case, session: CaseSession) -> None:
        """The illusion list, the selected one's severity and parameters."""
        labels = [NO_SELECTION] + [f"{i}: {illusion.type} (level {illusion.severity})"
                                   for i, illusion in enumerate(case.illusions)]
        selected = self.tab.selected
        self.selected.options = labels
        set_value(self.selected, labels[0 if selected is None else selected + 1])
        illusion = case.illusions[selected] if selected is not None else None
        self.severity.disabled = self.delete_button.disabled = illusion is None
        if illusion is not None:
            set_value(self.severity, illusion.severity)
        self.params.show(illusion)
