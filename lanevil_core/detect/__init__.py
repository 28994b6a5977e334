"""Classical lane-detection baselines (Canny + Hough, bird's-eye sliding windows) that write TuSimple predictions."""

from .birdseye import BirdseyeParams, detect_birdseye
from .common import GroundCamera
from .hough import HoughParams, detect_hough
from .split import DETECTORS, detect_split, detect_split_methods

__all__ = [
    "DETECTORS",
    "BirdseyeParams",
    "GroundCamera",
    "HoughParams",
    "detect_birdseye",
    "detect_hough",
    "detect_split",
    "detect_split_methods",
]
