"""The Case and New case folders: open, title, save (version-checked), undo/redo, reload, save a copy, create.

The store is shared by every tab; ``stored`` follows its changes of the open case (``CaseStore.subscribe``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import viser

from lanevil_core.case import Case, parse_case
from lanevil_core.illusions import MeshFileError
from lanevil_core.pipeline.compile import check_mesh_files
from lanevil_core.typed import ROAD_TYPES, SCENE_KINDS

from ...store import CaseRecord, ChangeKind, VersionConflict
from ..session import CaseSession
from .base import EditError, set_value

if TYPE_CHECKING:
    from ..tab import EditorTab

NO_CASES = "(no cases)"


class CasePanel:
    """Open, name, save and create cases."""

    def __init__(self, tab: EditorTab, gui: viser.GuiApi) -> None:
        self.tab = tab
        guarded = tab.guarded
        with gui.add_folder("Case"):
            self.case_id = gui.add_dropdown("Open", tab.case_ids() or [NO_CASES],
                                            hint="stored cases; choosing one opens it")
            self.case_id.on_update(guarded(lambda e: self.open_case(str(e.target.value))))
            self.title = gui.add_text("Title", "", hint="the case's title (saved with it)")
            self.title.on_update(guarded(lambda e: self.set_title(str(e.target.value))))
            self.description = gui.add_text("Description", "", multiline=True,
                                            hint="what the case shows (saved with it)")
            self.description.on_update(guarded(lambda e: self.tab.edit({**self.tab.data(), "description":
                                                                        str(e.target.value)}, "description")))
            self.save_button = gui.add_button("Save", icon=viser.Icon.DEVICE_FLOPPY,
                                              hint="write to the store (version-checked)")
            self.save_button.on_click(guarded(lambda e: self.save()))
            self.undo_button = gui.add_button("Undo", icon=viser.Icon.ARROW_BACK_UP, hint="Ctrl+Z")
            self.undo_button.on_click(guarded(lambda e: self.undo()))
            self.redo_button = gui.add_button("Redo", icon=viser.Icon.ARROW_FORWARD_UP, hint="Ctrl+Shift+Z")
            self.redo_button.on_click(guarded(lambda e: self.redo()))
            self.reload_button = gui.add_button("Reload stored version",
                                                hint="take the stored case (Undo brings your edits back)")
            self.reload_button.on_click(guarded(lambda e: self.reload()))
            self.save_copy_button = gui.add_button("Save as new case", hint="store your edits under a new id")
            self.save_copy_button.on_click(guarded(lambda e: self.save_as_new()))
        with gui.add_folder("New case", expand_by_default=False):
            self.template = gui.add_dropdown("Road template", list(ROAD_TYPES), initial_value="straight",
                                            hint="the road of the new case")
            self.scene_kind = gui.add_dropdown("Roadside", list(SCENE_KINDS), initial_value="suburban")
            self.create_button = gui.add_button("Create and open", icon=viser.Icon.PLUS)
            self.create_button.on_click(guarded(lambda e: self.new_case(str(self.template.value),
                                                                        str(self.scene_kind.value))))
        gui.add_command("Undo", hotkey="Z", modifier="cmd/ctrl",
                        description="undo the last change").on_trigger(guarded(lambda e: self.undo()))
        gui.add_command("Redo", hotkey="Z", modifier="cmd/ctrl+shift",
                        description="redo").on_trigger(guarded(lambda e: self.redo()))

    # ------------------------------------------------------------------------------------------ actions

    def open_case(self, case_id: str) -> None:
        """Show a stored case (its shared session, with any unsaved edits another tab made), its first illusion
        selected so that its severity and parameters show at once."""
        tab = self.tab
        if case_id not in tab.state.store:
            raise EditError(f"case_id: no case {case_id!r} in the store")
        with tab.lock:
            tab.session = tab.sessions.open(case_id)
            tab.selected = 0 if tab.session.case.illusions else None
            tab.frame = min(tab.frame, tab.session.case.ego.frames - 1)
        tab.changed(f"opened {case_id}")

    def new_case(self, road_type: str, scene_kind: str) -> str:
        """Create a case from a road template (no illusions) and open it; returns its id."""
        case = parse_case({"title": f"New {road_type.replace('_', ' ')} road", "road": {"type": road_type},
                           "scene": {"kind": scene_kind}}, source="new case")
        record = self.tab.state.store.create(case)
        self.open_case(record.id)
        return record.id

    def set_title(self, title: str) -> None:
        self.tab.edit({**self.tab.data(), "title": title}, "title")

    def save(self) -> CaseRecord | None:
        """Write the edited case through the store's version check; a conflict is reported and the edits kept."""
        tab = self.tab
        session = tab.current()
        self._check_meshes(session.case)
        try:
            record = session.save(tab.state.store)
        except VersionConflict as error:
            tab.report(f"Not saved: {error}. Your edits are kept: use 'Save as new case', or 'Reload stored "
                       "version' (Undo brings your edits back).", error=True)
            return None
        tab.changed(f"saved version {record.version}")
        return record

    def save_as_new(self) -> str:
        """Store the edited case under a fresh id and continue there."""
        case = self.tab.case
        self._check_meshes(case)
        record = self.tab.state.store.create(case)
        self.open_case(record.id)
        return record.id

    def _check_meshes(self, case: Case) -> None:
        """What the REST API refuses is not stored from here either: a ``mesh_file`` that is not uploaded."""
        try:
            check_mesh_files(case, self.tab.state.meshes_dir)
        except MeshFileError as error:
            raise EditError(f"Not saved: {error} (use Upload vehicle mesh)") from None

    def reload(self) -> None:
        session = self.tab.current()
        session.reload(self.tab.state.store.get(session.case_id))
        self.tab.changed("reloaded the stored version")

    def undo(self) -> None:
        label = self.tab.current().undo()
        self.tab.changed(f"undid {label}" if label else "nothing to undo")

    def redo(self) -> None:
        label = self.tab.current().redo()
        self.tab.changed(f"redid {label}" if label else "nothing to redo")

    def stored(self, kind: ChangeKind, case_id: str, record: CaseRecord | None) -> None:
        """A store change from anywhere: keep the case list current and follow changes of the open case."""
        tab = self.tab
        with tab.syncing():
            options = tab.case_ids() or [NO_CASES]
            self.case_id.options = options
            if tab.session is not None and tab.session.case_id in options:
                set_value(self.case_id, tab.session.case_id)
        session = tab.session
        if session is None or case_id != session.case_id:
            return
        if kind == "deleted":
            tab.sessions.drop(case_id)
            tab.report("This case was deleted from the store; 'Save as new case' keeps your version.", error=True)
        elif record is not None and session.stored_change(record):
            tab.changed(f"version {record.version} arrived from the store")
        elif session.remote_version is not None:
            tab.report(f"Version {session.remote_version} was stored elsewhere; you have unsaved edits "
                       "(Save reports the conflict, Reload takes theirs).", error=True)

    # ------------------------------------------------------------------------------------------ sync

    def field_paths(self) -> set[tuple[str, ...]]:
        return {("title",), ("description",)}

    def sync(self, case: Case, session: CaseSession) -> None:
        """The open case's id, title, description and what Undo / Redo can do."""
        set_value(self.description, case.description)
        if session.case_id not in self.case_id.options:
            self.case_id.options = self.tab.case_ids()
        set_value(self.case_id, session.case_id)
        set_value(self.title, case.title)
        self.undo_button.disabled, self.redo_button.disabled = not session.can_undo, not session.can_redo
