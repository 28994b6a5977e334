"""The viser editor: place illusions in 3D, scrub severity and sun, live camera preview, export.

``launch_editor(state, host, port)`` starts it beside the FastAPI backend, sharing its ``AppState``.
"""

from .editor import EditError, Editor, launch_editor

__all__ = ["EditError", "Editor", "launch_editor"]
