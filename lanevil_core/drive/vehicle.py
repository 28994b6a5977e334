"""Kinematic bicycle model of the ego vehicle.

The rear axle moves along circular arcs of curvature ``tan(delta) / L`` (L = wheelbase): x' = v cos(psi),
y' = v sin(psi), psi' = v tan(delta) / L. The steering angle ``delta`` follows the controller's command at a limited
rate and within a limited angle. The pose reported is that of the vehicle origin (where the case camera is
mounted from), ``rear_axle_m`` ahead of the rear axle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..camera import VehiclePose

SUBSTEPS = 10  # integration steps per control step (the steering ramps within a step)


@dataclass(frozen=True)
class VehicleParams:
    """A sedan: wheelbase (m), steering limit (radians), steering rate limit (radians/s at the road wheels),
    and where the vehicle origin sits ahead of the rear axle (m)."""

    wheelbase_m: float = 2.8
    max_steer: float = math.radians(35.0)
    max_steer_rate: float = math.radians(30.0)
    rear_axle_m: float = 1.4


@dataclass(frozen=True)
class VehicleState:
    """Pose of the vehicle origin (world x, y in m; yaw in radians), road-wheel steering angle (radians, positive
    turns left) and speed (m/s, horizontal)."""

    x: float
    y: float
    yaw: float
    steer: float
    speed: float

    @property
    def pose(self) -> VehiclePose:
        return VehiclePose(self.x, self.y, self.yaw)


def _arc(x: float, y: float, yaw: float, curvature: float, distance: float) -> tuple[float, float, float]:
    """Rear-axle pose after ``distance`` metres on an arc of ``curvature`` (exact, straight when ~0)."""
    if abs(curvature) < 1e-9:
        return x + distance * math.cos(yaw), y + distance * math.sin(yaw), yaw
    yaw_end = yaw + curvature * distance
    x_end = x + (math.sin(yaw_end) - math.sin(yaw)) / curvature
    y_end = y - (math.cos(yaw_end) - math.cos(yaw)) / curvature
    return x_end, y_end, yaw_end


def advance(state: VehicleState, steer_command: float, dt: float, params: VehicleParams) -> VehicleState:
    """The state ``dt`` seconds later, steering towards ``steer_command`` (clamped to the limits)."""
    target = min(max(steer_command, -params.max_steer), params.max_steer)
    h = dt / SUBSTEPS
    max_change = params.max_steer_rate * h
    b = params.rear_axle_m
    x_rear = state.x - b * math.cos(state.yaw)
    y_rear = state.y - b * math.sin(state.yaw)
    yaw, steer = state.yaw, state.steer
    for _ in range(SUBSTEPS):
        steer += min(max(target - steer, -max_change), max_change)
        curvature = math.tan(steer) / params.wheelbase_m
        x_rear, y_rear, yaw = _arc(x_rear, y_rear, yaw, curvature, state.speed * h)
    yaw = math.atan2(math.sin(yaw), math.cos(yaw))
    return replace(state, x=x_rear + b * math.cos(yaw), y=y_rear + b * math.sin(yaw), yaw=yaw, steer=steer)
