"""What a drive amounts to: the attack-success criterion of the paper's driving test, lane departure, off-road.

An illusion succeeds (Sato et al.'s criterion, used by LanEvil against OpenPilot) when the vehicle's lateral
deviation from its lane centre exceeds ``DEVIATION_THRESHOLD_M`` within ``SUCCESS_WINDOW_S`` of the illusion
coming into view (``illusion_view``). A case without illusions is scored from the drive's start, so a clean
original's "success" is a detector's own failure: the baseline.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from .illusion_view import VIEW_RANGE_M, in_view
from .loop import DriveTrace

DEVIATION_THRESHOLD_M = 0.285  # the margin between a 3.6 m lane and a 1.8 m wide car (AASHTO)
SUCCESS_WINDOW_S = 2.5


def verdict(success: bool, illusion: bool, max_abs_deviation: float) -> str:
    """One phrase for a drive: whether the illusion succeeded, or the car kept its lane (a clean case's "success"
    is the detector's own failure, named so)."""
    if success:
        return "ATTACK SUCCEEDED" if illusion else "LANE LOST (no illusion: the detector's own failure)"
    if max_abs_deviation <= DEVIATION_THRESHOLD_M:
        return "LANE KEPT (attack failed)" if illusion else "LANE KEPT"
    window = f"over {DEVIATION_THRESHOLD_M} m only outside the {SUCCESS_WINDOW_S} s window"
    return f"ATTACK FAILED (deviation {window})" if illusion else f"LANE KEPT at first (deviation {window})"


@dataclass(frozen=True)
class DriveSummary:
    """One drive in numbers (m, s, radians; None where a moment never came)."""

    title: str
    detector: str
    controller: str
    size: tuple[int, int]
    steps: int
    seconds: float
    ended: str
    max_abs_deviation: float
    mean_abs_deviation: float
    max_abs_heading_error: float
    mean_accuracy: float
    illusion_span: tuple[float, float] | None
    t_view: float | None
    t_exceed: float | None
    success: bool
    lane_departure: bool
    t_departure: float | None
    off_road: bool
    t_off_road: float | None
    steps_per_second: float | None

    @property
    def verdict(self) -> str:
        """The drive in one phrase (``verdict``)."""
        return verdict(self.success, self.illusion_span is not None, self.max_abs_deviation)

    def as_dict(self) -> dict[str, Any]:
        data = asdict(self)
        data.update(deviation_threshold_m=DEVIATION_THRESHOLD_M, success_window_s=SUCCESS_WINDOW_S,
                    view_range_m=VIEW_RANGE_M)
        return data


def _first(times: np.ndarray, hits: np.ndarray) -> float | None:
    index = np.flatnonzero(hits)
    return float(times[index[0]]) if index.size else None


def view_time(trace: DriveTrace) -> float | None:
    """When the illusion first comes into view (0 for a case without illusions; None if it never does)."""
    if trace.illusion_span is None:
        return 0.0
    for step in trace.steps:
        if in_view(trace.illusion_span, step.s_road + trace.case.camera.x):
            return step.time
    return None


def summarize(trace: DriveTrace, wall_seconds: float | None = None) -> DriveSummary:
    """The summary of a drive; ``wall_seconds`` (the loop's wall-clock time) gives ``steps_per_second``."""
    times = np.array([step.time for step in trace.steps])
    deviation = np.abs([step.deviation for step in trace.steps])
    t_view = view_time(trace)
    t_exceed = None if t_view is None else _first(times, (times >= t_view) & (deviation > DEVIATION_THRESHOLD_M))
    success = t_exceed is not None and t_view is not None and t_exceed - t_view <= SUCCESS_WINDOW_S + 1e-9
    t_departure = _first(times, deviation > trace.route.departure_threshold())
    t_off_road = _first(times, np.abs([step.t_road for step in trace.steps]) > trace.route.carriageway_half_width)
    dt = 1.0 / trace.case.ego.fps
    return DriveSummary(
        title=trace.case.title, detector=trace.settings.detector, controller=trace.settings.controller,
        size=trace.settings.size, steps=len(trace.steps), seconds=round(len(trace.steps) * dt, 6), ended=trace.ended,
        max_abs_deviation=float(deviation.max()), mean_abs_deviation=float(deviation.mean()),
        max_abs_heading_error=float(np.abs([step.heading_error for step in trace.steps]).max()),
        mean_accuracy=float(np.mean([step.accuracy for step in trace.steps])),
        illusion_span=trace.illusion_span, t_view=t_view, t_exceed=t_exceed, success=bool(success),
        lane_departure=t_departure is not None, t_departure=t_departure,
        off_road=t_off_road is not None, t_off_road=t_off_road,
        steps_per_second=(len(trace.steps) / wall_seconds) if wall_seconds and wall_seconds > 0 else None)
