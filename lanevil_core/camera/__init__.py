"""The ego camera: pinhole intrinsics and pose (``pinhole``), lens distortion (``lens``), the bonnet in view
(``bonnet``) and a real sensor's response (``sensor``)."""

from .pinhole import (
    EgoPath,
    Intrinsics,
    PinholeCamera,
    VehiclePose,
    ego_camera,
    ego_path,
    intrinsics_for,
    mounted_camera,
    pose_camera,
    scripted_vehicle_transform,
    vehicle_transform,
)

__all__ = [
    "EgoPath",
    "Intrinsics",
    "PinholeCamera",
    "VehiclePose",
    "ego_camera",
    "ego_path",
    "intrinsics_for",
    "mounted_camera",
    "pose_camera",
    "scripted_vehicle_transform",
    "vehicle_transform",
]
