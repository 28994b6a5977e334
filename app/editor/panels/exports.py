"""The Export folder: the case's JSON, the current frame with its labels, the whole sequence as a zip."""

from __future__ import annotations

from typing import TYPE_CHECKING

import viser

from ...jobs import Job
from .. import export

if TYPE_CHECKING:
    from ..tab import EditorTab


class ExportPanel:
    """Downloads of the edited case, in this tab."""

    def __init__(self, tab: EditorTab, gui: viser.GuiApi) -> None:
        self.tab = tab
        guarded = tab.guarded
        with gui.add_folder("Export", expand_by_default=False):
            self.case_button = gui.add_button("Case JSON", icon=viser.Icon.FILE_DOWNLOAD)
            self.case_button.on_click(guarded(lambda e: self.export_case()))
            self.frame_button = gui.add_button("Current frame (PNG + labels)", icon=viser.Icon.PHOTO)
            self.frame_button.on_click(guarded(lambda e: self.export_frame()))
            self.sequence_button = gui.add_button("Whole sequence (zip)", icon=viser.Icon.FILE_ZIP,
                                                  hint="renders every frame with TuSimple labels in the background")
            self.sequence_button.on_click(guarded(lambda e: self.export_sequence()))

    def _send(self, name: str, data: bytes) -> None:
        self.tab.client.send_file_download(name, data, save_immediately=True)
        self.tab.client.flush()  # viser windows outgoing messages: without this the file waited for the next one

    def export_case(self) -> tuple[str, bytes]:
        """Download the edited case's JSON in this tab."""
        name, data = export.case_download(self.tab.current().case_id, self.tab.case)
        self._send(name, data)
        return name, data

    def export_frame(self) -> list[tuple[str, bytes]]:
        """Download the current frame (PNG) and its labels in this tab."""
        tab = self.tab
        files = export.frame_downloads(tab.state, tab.current().case_id, tab.case, tab.frame)
        for name, data in files:
            self._send(name, data)
        return files

    def export_sequence(self, frames: range | None = None) -> Job:
        """Start the sequence zip as a backend job; progress shows as a notification, the zip downloads at the end."""
        tab = self.tab
        session = tab.current()
        fallback = tab.state.store.get(session.case_id).illusion_type
        notes: list[viser.NotificationHandle] = []

        def notify(title: str, body: str, loading: bool, color: str | None) -> None:
            if not notes:
                notes.append(tab.client.add_notification(title, body, loading=loading, with_close_button=True))
                return
            note = notes[0]
            note.title, note.body, note.loading = title, body, loading
            if color is not None:
                note.color = color  # type: ignore[assignment]  # one of viser's colour names

        frames = frames if frames is not None else range(tab.case.ego.frames)
        job = export.start_sequence_export(tab.state, session.case_id, tab.case, fallback, frames, self._send, notify)
        tab.report(f"exporting {len(frames)} frames (job {job.id[:8]})")
        return job
