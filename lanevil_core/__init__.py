"""lanevil_core: editable 3D lane-detection robustness cases, a CPU renderer and exact lane ground truth."""

from .camera import Intrinsics, PinholeCamera, ego_camera
from .case import Camera, Case, CaseError, Ego, Marking, Road, Scene, Sun, Weather, load_case, parse_case, save_case
from .illusions import ILLUSION_TYPES, REGISTRY, Illusion
from .road_layout import RoadNetwork, build_network

__all__ = [
    "ILLUSION_TYPES",
    "REGISTRY",
    "Camera",
    "Case",
    "CaseError",
    "Ego",
    "Illusion",
    "Intrinsics",
    "Marking",
    "PinholeCamera",
    "Road",
    "RoadNetwork",
    "Scene",
    "Sun",
    "Weather",
    "build_network",
    "ego_camera",
    "load_case",
    "parse_case",
    "save_case",
]
