"""The closed loop: render the ego camera at the vehicle's actual pose -> detector -> ego lane estimate ->
controller -> kinematic bicycle model, once per frame (1 / fps seconds).

The case's scripted ego path becomes the route (start pose, lane, speed); the pose comes from the loop. The same
case and settings always give the same trace.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..camera import mounted_camera, pose_camera
from ..case import Case
from ..labels.lanes import h_samples_for, tusimple_record
from ..pipeline.compile import compile_scene
from ..render import render_view
from ..typed import FloatArray, UInt8Array
from ..world.scene import CompiledScene
from .controllers import ControllerName, controller_for
from .detectors import GROUND_TRUTH, drive_detector, frame_accuracy
from .illusion_view import illusion_span
from .lane_estimate import DEFAULT_LANE_WIDTH_M, LaneEstimate, LanePath, estimate_lane, fit_path
from .route import Route
from .vehicle import VehicleParams, VehicleState, advance

DEFAULT_SIZE = (640, 360)
MEMORY_X_M = np.arange(0.0, 60.0, 1.0)  # the last centre line is remembered at these distances ahead


@dataclass(frozen=True)
class DriveSettings:
    """How to drive a case: detector, controller, duration (None = the case's drive), camera size, vehicle, and
    the start's lateral offset from the lane centre (m, + left)."""

    detector: str = GROUND_TRUTH
    controller: ControllerName = "pure_pursuit"
    seconds: float | None = None
    size: tuple[int, int] = DEFAULT_SIZE
    vehicle: VehicleParams = field(default_factory=VehicleParams)
    weights: str | None = None
    start_offset_m: float = 0.0

    def duration(self, case: Case) -> float:
        return self.seconds if self.seconds is not None else case.ego.frames / case.ego.fps


@dataclass(frozen=True)
class DriveStep:
    """One control step at ``time`` (s): where the vehicle was, what the detector saw and how it steered.

    ``deviation`` (m, + = left of the lane centre) and ``heading_error`` (radians) are true values against the
    route; ``estimated_offset`` is what the lane estimate believed (NaN when nothing was estimated);
    ``steer`` the road-wheel angle at the step and ``steer_command`` the controller's output (radians);
    ``accuracy`` the detector's TuSimple accuracy on the frame; ``source`` ``both``/``left``/``right`` (the
    boundaries seen), ``memory`` (the last centre line carried along) or ``none``.
    """

    frame: int
    time: float
    s_road: float
    t_road: float
    deviation: float
    heading_error: float
    x_world: float
    y_world: float
    yaw: float
    steer: float
    steer_command: float
    estimated_offset: float
    accuracy: float
    lanes: int
    source: str
    render_ms: float
    detect_ms: float


@dataclass(frozen=True)
class StepView:
    """What a step looked like (for a video): the frame, its ground-truth and detected lanes at ``h_samples``."""

    step: DriveStep
    rgb: UInt8Array
    gt_lanes: list[list[int]]
    lanes: list[list[int]]
    h_samples: list[int]


@dataclass(frozen=True)
class DriveTrace:
    """A finished drive: its steps, the route it was measured against, the illusions' stretch of road and why it
    ended (``time``, ``road_end`` or ``off_road``)."""

    case: Case
    settings: DriveSettings
    steps: list[DriveStep]
    route: Route
    illusion_span: tuple[float, float] | None
    ended: str

    @property
    def route_xy(self) -> FloatArray:
        """(n, 2) world points of the route's lane centre over the drive."""
        s_road = np.arange(self.route.start_s, max(step.s_road for step in self.steps) + 1.0, 0.5)
        return self.route.network.main.line.to_world(s_road, self.route.t_center)[:, :2]


StepCallback = Callable[[StepView], None]
Progress = Callable[[int, int], None]


class _Memory:
    """The last estimated centre line, kept in world coordinates so that it can be re-read from a new pose."""

    def __init__(self) -> None:
        self.p_world: FloatArray | None = None
        self.width = DEFAULT_LANE_WIDTH_M

    def remember(self, estimate: LaneEstimate, state: VehicleState) -> None:
        self.width = estimate.width
        self.p_world = _to_world(estimate.center.points(MEMORY_X_M), state)

    def recall(self, state: VehicleState) -> LanePath | None:
        if self.p_world is None:
            return None
        return fit_path(_to_vehicle(self.p_world, state))

    def center_line(self, estimate: LaneEstimate | None, state: VehicleState) -> tuple[LanePath | None, str]:
        """The centre line to steer by and where it came from: ``both``/``left``/``right`` (the boundaries seen this
        frame), ``memory`` (the last one, re-read from the new pose) or ``none``."""
        if estimate is not None:
            self.remember(estimate, state)
            seen = {(True, True): "both", (True, False): "left", (False, True): "right"}
            return estimate.center, seen[(estimate.left_seen, estimate.right_seen)]
        path = self.recall(state)
        return path, "memory" if path is not None else "none"


def _to_world(p_vehicle: FloatArray, state: VehicleState) -> FloatArray:
    c, s = math.cos(state.yaw), math.sin(state.yaw)
    R_world_vehicle = np.array([[c, -s], [s, c]])
    return p_vehicle @ R_world_vehicle.T + np.array([state.x, state.y])


def _to_vehicle(p_world: FloatArray, state: VehicleState) -> FloatArray:
    c, s = math.cos(state.yaw), math.sin(state.yaw)
    R_world_vehicle = np.array([[c, -s], [s, c]])
    return (p_world - np.array([state.x, state.y])) @ R_world_vehicle


def drive_case(case: Case, settings: DriveSettings, on_step: StepCallback | None = None,
               progress: Progress | None = None, scene: CompiledScene | None = None) -> DriveTrace:
    """Drive ``case`` in closed loop for ``settings.duration(case)`` seconds (or until the road ends or the
    vehicle leaves it). ``on_step`` sees every frame; ``progress(done, total)`` counts steps."""
    scene = scene if scene is not None else compile_scene(case)
    detect = drive_detector(settings.detector, settings.weights)
    controller = controller_for(settings.controller)
    route = Route.of_case(case, scene.network)
    params = settings.vehicle
    dt = 1.0 / case.ego.fps
    total = max(1, int(round(settings.duration(case) * case.ego.fps)))
    width, height = settings.size
    h_samples = h_samples_for(height)
    camera_vehicle = mounted_camera(case.camera, np.eye(4), settings.size)
    start = route.start_pose(settings.start_offset_m)
    state = VehicleState(start.x, start.y, start.yaw, 0.0, case.ego.speed)
    memory = _Memory()
    steps: list[DriveStep] = []
    ended = "time"
    for index in range(total):
        point = route.locate(state.pose)
        clock = time.perf_counter()
        frame = render_view(scene, pose_camera(case, scene.network, state.pose, settings.size))
        render_ms = (time.perf_counter() - clock) * 1e3
        gt_lanes = tusimple_record(scene, index, frame, raw_file="", h_samples=h_samples)["lanes"]
        clock = time.perf_counter()
        lanes = detect(frame.rgb, h_samples, gt_lanes)
        detect_ms = (time.perf_counter() - clock) * 1e3
        estimate = estimate_lane(lanes, h_samples, camera_vehicle, memory.width)
        path, source = memory.center_line(estimate, state)
        command = controller.steer(path, state.speed, params) if path is not None else 0.0
        steps.append(DriveStep(
            index, round(index * dt, 6), point.s_road, point.t_road, point.deviation, point.heading_error,
            state.x, state.y, state.yaw, state.steer, command,
            estimate.lateral_offset if estimate is not None else math.nan,
            1.0 if settings.detector == GROUND_TRUTH else frame_accuracy(lanes, gt_lanes, h_samples, (width, height)),
            len(lanes), source, render_ms, detect_ms))
        if on_step is not None:
            on_step(StepView(steps[-1], frame.rgb, gt_lanes, lanes, h_samples))
        if progress is not None:
            progress(index + 1, total)
        if route.off_road(point):
            ended = "off_road"
            break
        if point.s_road >= route.end_s:
            ended = "road_end"
            break
        state = advance(state, command, dt, params)
    return DriveTrace(case, settings, steps, route, illusion_span(scene), ended)
