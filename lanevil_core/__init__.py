"""lanevil_core: editable 3D lane-detection robustness cases, a CPU renderer and exact lane ground truth."""

from importlib.metadata import PackageNotFoundError, version

from .camera import EgoPath, Intrinsics, PinholeCamera, VehiclePose, ego_camera, pose_camera
from .case import (
    Camera,
    Case,
    CaseError,
    Ego,
    Marking,
    Road,
    Scene,
    Sun,
    Weather,
    case_json,
    case_schema,
    load_case,
    parse_case,
    save_case,
)
from .export.case import export_case
from .illusions import CATEGORIES, ILLUSION_TYPES, REGISTRY, Illusion
from .images import jpeg_bytes, png_bytes
from .labels.lanes import culane_lines, tusimple_record
from .labels.overlay import draw_lanes
from .pipeline.compile import compile_scene
from .render import Frame, render_frame, render_view
from .world.paint import RoadPaint
from .world.road_layout import RoadNetwork, build_network
from .world.scene import CompiledScene

try:  # one source for the version: the installed package's metadata (pyproject.toml's `version`)
    __version__ = version("lanevil")
except PackageNotFoundError:  # a source tree on sys.path that was never installed
    __version__ = "0+unknown"

__all__ = [
    "CATEGORIES",
    "ILLUSION_TYPES",
    "REGISTRY",
    "Camera",
    "Case",
    "CaseError",
    "CompiledScene",
    "Ego",
    "EgoPath",
    "Frame",
    "Illusion",
    "Intrinsics",
    "Marking",
    "PinholeCamera",
    "Road",
    "RoadPaint",
    "RoadNetwork",
    "Scene",
    "Sun",
    "VehiclePose",
    "Weather",
    "build_network",
    "case_json",
    "case_schema",
    "compile_scene",
    "culane_lines",
    "draw_lanes",
    "ego_camera",
    "export_case",
    "jpeg_bytes",
    "load_case",
    "parse_case",
    "png_bytes",
    "pose_camera",
    "render_frame",
    "render_view",
    "save_case",
    "tusimple_record",
    "__version__",
]
