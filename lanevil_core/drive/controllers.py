"""Lateral controllers: steering angle (radians, positive turns left) from the estimated centre line.

Both work in the vehicle frame (+X forward, +Y left, origin = vehicle origin) on a ``LanePath``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np

from .lane_estimate import LanePath
from .vehicle import VehicleParams

ControllerName = Literal["pure_pursuit", "stanley"]
CONTROLLERS: tuple[ControllerName, ...] = ("pure_pursuit", "stanley")


class Controller(Protocol):
    def steer(self, path: LanePath, speed: float, params: VehicleParams) -> float: ...


@dataclass(frozen=True)
class PurePursuit:
    """Steer the rear axle along the arc through a look-ahead point of the path: delta = atan(2 L sin(alpha) / l_d),
    look-ahead ``l_d = max(min_lookahead_m, gain_s * speed)`` from the rear axle."""

    gain_s: float = 1.0
    min_lookahead_m: float = 9.0

    def lookahead(self, speed: float) -> float:
        return max(self.min_lookahead_m, self.gain_s * speed)

    def steer(self, path: LanePath, speed: float, params: VehicleParams) -> float:
        l_d = self.lookahead(speed)
        x_vehicle = np.arange(0.0, 3.0 * l_d, 0.05)
        p_rear = path.points(x_vehicle) + np.array([params.rear_axle_m, 0.0])  # rear-axle frame
        distance = np.hypot(p_rear[:, 0], p_rear[:, 1])
        beyond = np.flatnonzero(distance >= l_d)
        x_rear, y_rear = p_rear[beyond[0]] if beyond.size else p_rear[-1]
        alpha = math.atan2(y_rear, x_rear)
        return math.atan(2.0 * params.wheelbase_m * math.sin(alpha) / l_d)


@dataclass(frozen=True)
class Stanley:
    """Stanley's front-axle law: delta = heading error + atan(k e / (k_soft + v)), with e the path's offset from the
    front axle (positive = path to the left)."""

    gain: float = 2.5
    softening_mps: float = 1.0

    def steer(self, path: LanePath, speed: float, params: VehicleParams) -> float:
        x_front = params.wheelbase_m - params.rear_axle_m
        cross_track = float(path.y_at(x_front))
        heading_error = math.atan(path.slope_at(x_front))
        return heading_error + math.atan(self.gain * cross_track / (self.softening_mps + speed))


def controller_for(name: str) -> Controller:
    """The controller called ``name`` with its default gains."""
    if name == "pure_pursuit":
        return PurePursuit()
    if name == "stanley":
        return Stanley()
    raise ValueError(f"controller {name!r}: choose from {', '.join(CONTROLLERS)}")
