"""Lane detectors: classical baselines (Canny + Hough, bird's-eye sliding windows), the learned families, and
plug-ins (HTTP servers, ONNX models with a sidecar, ``lanevil.detectors`` entry points) resolved by name through
``registry``; all write TuSimple predictions."""

from .birdseye import BirdseyeParams, detect_birdseye
from .common import GroundCamera
from .hough import HoughParams, detect_hough
from .plugin import LaneDetector, LaneDetectorPlugin
from .registry import detector_for, detector_names
from .split import DETECTORS, detect_split, detect_split_methods

__all__ = [
    "DETECTORS",
    "BirdseyeParams",
    "GroundCamera",
    "HoughParams",
    "LaneDetector",
    "LaneDetectorPlugin",
    "detect_birdseye",
    "detect_hough",
    "detect_split",
    "detect_split_methods",
    "detector_for",
    "detector_names",
]
