"""The start screen a new tab opens with: a new case, the recent cases, and the library as a tree (category,
type, original) with a search box. Choosing closes it; *Close* keeps the case the tab opened behind it."""

from __future__ import annotations

import threading
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import PurePosixPath
from typing import TYPE_CHECKING

import numpy as np
import viser
from viser._gui_handles import GuiModalHandle  # not re-exported by viser 1.x

from lanevil_core.library.benchmark_layout import folder_type
from lanevil_core.typed import ROAD_TYPES

from ...store import CaseRecord
from .base import set_value

if TYPE_CHECKING:
    from ..tab import EditorTab

ANY = "(any)"
NONE_FOUND = "(no case matches)"
RECENT_COUNT = 8
THUMBNAIL_SIZE = (320, 180)


@dataclass(frozen=True)
class LibraryRow:
    """One stored case as the library tree files it."""

    category: str
    type: str
    original: str
    case_id: str
    title: str

    @property
    def label(self) -> str:
        return f"{self.case_id} — {self.title}" if self.title else self.case_id


def library_row(record: CaseRecord) -> LibraryRow:
    """Where a case sits in the tree: its category and type, and for a stock case its original's folder."""
    origin = PurePosixPath(record.origin) if record.origin else None
    typed = origin is not None and folder_type(origin) not in (None, origin.parent.name)
    original = origin.parent.name if origin is not None and typed else "-"
    return LibraryRow(record.category, record.illusion_type or "clean", original, record.id, record.case.title)


def matching(rows: Iterable[LibraryRow], category: str, type_name: str, query: str) -> list[LibraryRow]:
    """The rows under ``category`` and ``type_name`` (``ANY``: all) whose id, title or original holds every word of
    ``query`` (case-insensitive)."""
    words = query.lower().split()
    return [row for row in rows
            if category in (ANY, row.category) and type_name in (ANY, row.type)
            and all(word in f"{row.case_id} {row.title} {row.original}".lower() for word in words)]


def recent(records: Iterable[CaseRecord], count: int = RECENT_COUNT) -> list[CaseRecord]:
    """The most recently changed cases, newest first."""
    return sorted(records, key=lambda record: (-record.updated_at, record.id))[:count]


class StartScreen:
    """A modal over the editor until the user picks a case (or closes it)."""

    def __init__(self, tab: EditorTab, gui: viser.GuiApi) -> None:
        self.tab = tab
        records = tab.state.store.list()
        self.rows = [library_row(record) for record in records]
        guarded = tab.guarded
        self.modal: GuiModalHandle | None = gui.add_modal("LanEvil editor: what to open")
        with self.modal:
            gui.add_markdown("**New case** — a road to author from scratch:")
            self.road = gui.add_dropdown("Road template", list(ROAD_TYPES), initial_value="straight")
            self.new_button = gui.add_button("Create a new case", icon=viser.Icon.PLUS)
            self.new_button.on_click(guarded(lambda e: self.new_case()))
            gui.add_markdown("**Recent cases**")
            recent_ids = [record.id for record in recent(records)] or [NONE_FOUND]
            self.recent = gui.add_dropdown("Recent", recent_ids)
            gui.add_button("Open recent").on_click(guarded(lambda e: self.open(str(self.recent.value))))
            gui.add_markdown("**Library** — category, type and original, or search:")
            self.search = gui.add_text("Search", "", hint="words of the id, the title or the original")
            self.category = gui.add_dropdown("Category", [ANY, *sorted({row.category for row in self.rows})])
            self.type = gui.add_dropdown("Type", [ANY])
            self.case = gui.add_dropdown("Case", [NONE_FOUND])
            self.found = gui.add_markdown("")
            self.thumbnail = gui.add_image(np.full((THUMBNAIL_SIZE[1], THUMBNAIL_SIZE[0], 3), 200, np.uint8),
                                           label="First frame", format="jpeg", jpeg_quality=80)
            self.case.on_update(guarded(lambda e: self.show_thumbnail()))
            for handle in (self.search, self.category, self.type):
                handle.on_update(guarded(lambda e: self.filter()))
            gui.add_button("Open from the library").on_click(guarded(lambda e: self.open(self._chosen())))
            gui.add_button("Close").on_click(guarded(lambda e: self.close()))
        self.filter()

    def filter(self) -> list[LibraryRow]:
        """Narrow the tree to the chosen category and type and the search words; returns the matching rows."""
        category = str(self.category.value)
        types = sorted({row.type for row in self.rows if category in (ANY, row.category)})
        with self.tab.syncing():
            self.type.options = [ANY, *types]
            if self.type.value not in self.type.options:
                set_value(self.type, ANY)
        rows = matching(self.rows, category, str(self.type.value), str(self.search.value))
        with self.tab.syncing():
            self.case.options = [row.label for row in rows] or [NONE_FOUND]
        self.found.content = f"{len(rows)} of {len(self.rows)} cases"
        self.show_thumbnail()
        return rows

    def show_thumbnail(self) -> threading.Thread | None:
        """Show the first frame of the chosen case, small (a draft render, cached by the frame service), once a
        background thread has rendered it; returns that thread."""
        case_id = self._chosen()
        if case_id == NONE_FOUND or case_id not in self.tab.state.store:
            return None
        case = self.tab.state.store.get(case_id).case

        def render() -> None:
            rgb = self.tab.state.frames.draft(case, 0, THUMBNAIL_SIZE).rgb
            if self._chosen() == case_id:  # still the chosen case
                self.thumbnail.image = rgb

        thread = threading.Thread(target=render, name="lanevil-editor-thumbnail", daemon=True)
        thread.start()
        return thread

    def _chosen(self) -> str:
        return str(self.case.value).split(" — ", 1)[0]

    def open(self, case_id: str) -> None:
        """Open ``case_id`` and close the screen (the placeholder of an empty list does nothing)."""
        if case_id == NONE_FOUND:
            return
        self.tab.cases.open_case(case_id)
        self.close()

    def new_case(self) -> str:
        """Create a new case from the chosen road template, open it, close the screen."""
        case_id = self.tab.cases.new_case(str(self.road.value), "suburban")
        self.close()
        return case_id

    def close(self) -> None:
        if self.modal is not None:
            self.modal.close()
            self.modal = None
