"""The editor's panels: each creates its inputs with their callbacks, holds the user actions and its ``sync``."""

from .base import EditError
from .camera import CameraPanel
from .case import CasePanel
from .display import DisplayPanel
from .exports import ExportPanel
from .illusions import IllusionsPanel
from .sections import RoadPanel, ScenePanel
from .start import StartScreen
from .sun import SunPanel

__all__ = ["CameraPanel", "CasePanel", "DisplayPanel", "EditError", "ExportPanel", "IllusionsPanel", "RoadPanel",
           "ScenePanel", "StartScreen", "SunPanel"]
