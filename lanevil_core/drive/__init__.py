"""Closed-loop lane keeping: the paper's driving-system test on the CPU, with the renderer in the loop.

``drive_case`` renders the ego camera at the vehicle's actual pose, runs a lane detector, estimates the ego lane's
centre line on the road plane, steers with a lateral controller and moves a kinematic bicycle model; ``summarize``
applies the attack-success criterion (|deviation| > 0.285 m within 2.5 s); ``drive_to_folder`` writes the trace,
summary, plots and video; ``run_suite`` drives a whole case library. See docs/drive.md.
"""

from .controllers import CONTROLLERS, PurePursuit, Stanley, controller_for
from .detectors import DRIVE_DETECTORS, GROUND_TRUTH, drive_detector
from .lane_estimate import LaneEstimate, LanePath, estimate_lane
from .loop import DEFAULT_SIZE, DriveSettings, DriveStep, DriveTrace, StepView, drive_case
from .outputs import DriveOutput, drive_to_folder
from .route import Route, RoutePoint
from .suite import SuiteEntry, run_suite, write_suite
from .summary import DEVIATION_THRESHOLD_M, SUCCESS_WINDOW_S, DriveSummary, summarize
from .vehicle import VehicleParams, VehicleState, advance

__all__ = [
    "CONTROLLERS",
    "DEFAULT_SIZE",
    "DEVIATION_THRESHOLD_M",
    "DRIVE_DETECTORS",
    "GROUND_TRUTH",
    "SUCCESS_WINDOW_S",
    "DriveOutput",
    "DriveSettings",
    "DriveStep",
    "DriveSummary",
    "DriveTrace",
    "LaneEstimate",
    "LanePath",
    "PurePursuit",
    "Route",
    "RoutePoint",
    "Stanley",
    "StepView",
    "SuiteEntry",
    "VehicleParams",
    "VehicleState",
    "advance",
    "controller_for",
    "drive_case",
    "drive_detector",
    "drive_to_folder",
    "estimate_lane",
    "run_suite",
    "summarize",
    "write_suite",
]
