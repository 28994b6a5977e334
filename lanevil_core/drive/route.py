"""The route of a closed-loop drive: the case's scripted ego path (its lane centre, from its start station).

The vehicle is measured against it in the main road's frame: station ``s``, lateral deviation of the vehicle
origin from the lane centre (m, positive = left of it) and heading error (radians, positive = turned left of the
road).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..camera import VehiclePose
from ..case import Case
from ..world.road_layout import RoadNetwork

END_MARGIN_M = 40.0  # a drive stops this far before the end of the road (the camera needs road ahead)
CAR_WIDTH_M = 1.8


@dataclass(frozen=True)
class RoutePoint:
    """Where the vehicle is relative to its route."""

    s_road: float
    t_road: float
    deviation: float
    heading_error: float


@dataclass(frozen=True)
class Route:
    """The ego lane of the case on the main road, driven from ``start_s`` at ``speed``."""

    network: RoadNetwork
    t_center: float
    start_s: float
    speed: float

    @classmethod
    def of_case(cls, case: Case, network: RoadNetwork) -> Route:
        return cls(network, network.lane_center_t(case.ego.lane), case.ego.start_s, case.ego.speed)

    @property
    def end_s(self) -> float:
        return self.network.main.line.length - END_MARGIN_M

    @property
    def lane_width(self) -> float:
        return self.network.lane_width

    @property
    def carriageway_half_width(self) -> float:
        return self.network.main.half_width

    def start_pose(self, offset_m: float = 0.0) -> VehiclePose:
        """At ``start_s``, ``offset_m`` left of the lane centre, heading along the road."""
        line = self.network.main.line
        p_world = line.to_world(self.start_s, self.t_center + offset_m)
        return VehiclePose(float(p_world[0]), float(p_world[1]), float(line.heading_at(self.start_s)))

    def locate(self, pose: VehiclePose) -> RoutePoint:
        line = self.network.main.line
        s_road, t_road = line.station(np.array([pose.x, pose.y]))
        heading_error = pose.yaw - float(line.heading_at(s_road))
        heading_error = math.atan2(math.sin(heading_error), math.cos(heading_error))
        return RoutePoint(s_road, t_road, t_road - self.t_center, heading_error)

    def departure_threshold(self) -> float:
        """|deviation| (m) at which a 1.8 m wide car's wheel crosses a boundary of its lane."""
        return 0.5 * (self.lane_width - CAR_WIDTH_M)

    def off_road(self, point: RoutePoint) -> bool:
        """The vehicle origin is beyond the carriageway's edge line."""
        return abs(point.t_road) > self.carriageway_half_width
