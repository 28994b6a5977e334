"""The viser editor: place illusions in 3D, scrub severity and sun, live camera preview, export.

``launch_editor(state, host, port)`` starts it beside the FastAPI backend, sharing its ``AppState``; every browser
tab that connects gets its own ``EditorTab`` (panel, 3D view, preview and case session).
"""

from .editor import Editor, launch_editor
from .headless import HeadlessTab
from .panels import EditError
from .tab import EditorTab

__all__ = ["EditError", "Editor", "EditorTab", "HeadlessTab", "launch_editor"]
