"""Plots of a drive (PNG bytes, matplotlib's Agg backend): deviation over time, and the path from above.

matplotlib comes with the ``report`` extra; without it a drive writes no plots (``plots_available``).
"""

from __future__ import annotations

import importlib.util

import numpy as np

from ..export.encode import figure_png
from .illusion_view import VIEW_RANGE_M
from .loop import DriveTrace
from .summary import DEVIATION_THRESHOLD_M, SUCCESS_WINDOW_S, DriveSummary

ILLUSION_COLOR = "#f4a261"


def _pyplot():  # noqa: ANN202 - matplotlib's module
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plots_available() -> bool:
    """Whether matplotlib is installed (``pip install 'lanevil[report]'``)."""
    return importlib.util.find_spec("matplotlib") is not None


def _title(summary: DriveSummary) -> str:
    return f"{summary.title or 'case'}: {summary.detector} + {summary.controller} ({summary.verdict})"


def trace_plot(trace: DriveTrace, summary: DriveSummary) -> bytes:
    """PNG: lateral deviation (with the +-0.285 m threshold and the 2.5 s window after the illusion comes into
    view), steering angle, and the detector's per-frame accuracy, against time."""
    plt = _pyplot()
    time = np.array([step.time for step in trace.steps])
    fig, (ax_dev, ax_steer, ax_acc) = plt.subplots(3, 1, figsize=(8.0, 6.4), dpi=110, sharex=True,
                                                    gridspec_kw={"height_ratios": [3, 1.3, 1.3]})
    if summary.t_view is not None:
        label = "illusion in view + 2.5 s" if trace.illusion_span is not None else "window (from the start)"
        ax_dev.axvspan(summary.t_view, summary.t_view + SUCCESS_WINDOW_S, color=ILLUSION_COLOR, alpha=0.25,
                       label=label)
    ax_dev.plot(time, [step.deviation for step in trace.steps], color="#1d3557", lw=1.6, label="true deviation")
    estimated = np.array([step.estimated_offset for step in trace.steps])
    ax_dev.plot(time, estimated, color="#8d99ae", lw=1.0, ls="--", label="estimated offset")
    for sign in (-1, 1):
        ax_dev.axhline(sign * DEVIATION_THRESHOLD_M, color="#e63946", lw=1.0, ls=":")
    ax_dev.axhline(0.0, color="black", lw=0.5)
    if summary.t_exceed is not None:
        ax_dev.axvline(summary.t_exceed, color="#e63946", lw=1.0, label=f"|dev| > {DEVIATION_THRESHOLD_M} m")
    limit = max(0.4, 1.1 * summary.max_abs_deviation)
    ax_dev.set_ylim(-limit, limit)
    ax_dev.set_ylabel("deviation (m, + left)")
    ax_dev.legend(loc="upper left", fontsize=7, ncol=2)
    ax_dev.set_title(_title(summary), fontsize=10)
    ax_steer.plot(time, np.degrees([step.steer for step in trace.steps]), color="#2a9d8f", lw=1.2)
    ax_steer.set_ylabel("steering (deg)")
    ax_acc.plot(time, [step.accuracy for step in trace.steps], color="#6a4c93", lw=1.2)
    ax_acc.set_ylim(-0.05, 1.05)
    ax_acc.set_ylabel("accuracy")
    ax_acc.set_xlabel("time (s)")
    for ax in (ax_dev, ax_steer, ax_acc):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return figure_png(fig)


def path_plot(trace: DriveTrace, summary: DriveSummary) -> bytes:
    """PNG: the drive from above (world x, y) and unrolled along the road (s against t, lateral axis stretched),
    with the lane boundaries, the route, the driven path and the illusion's stretch."""
    plt = _pyplot()
    line = trace.route.network.main.line
    s_path = np.array([step.s_road for step in trace.steps])
    s_road = np.arange(max(0.0, s_path.min() - 5.0), min(line.length, s_path.max() + 10.0), 0.5)
    boundaries = trace.route.network.main.boundaries_t
    fig, (ax_top, ax_unrolled) = plt.subplots(1, 2, figsize=(11.0, 4.6), dpi=110,
                                              gridspec_kw={"width_ratios": [1, 1.4]})
    for k, t_road in enumerate(boundaries):
        p_world = line.to_world(s_road, float(t_road))
        style = {"color": "#444444", "lw": 0.8 if 0 < k < len(boundaries) - 1 else 1.4}
        ax_top.plot(p_world[:, 0], p_world[:, 1], **style)
        ax_unrolled.plot(s_road, np.full_like(s_road, t_road), **style)
    ax_top.plot(trace.route_xy[:, 0], trace.route_xy[:, 1], color="#2a9d8f", lw=1.0, ls="--", label="route")
    ax_top.plot([step.x_world for step in trace.steps], [step.y_world for step in trace.steps], color="#e63946",
                lw=1.6, label="driven")
    ax_top.set_aspect("equal")
    ax_top.set_xlabel("x (m, east)")
    ax_top.set_ylabel("y (m, north)")
    ax_top.legend(fontsize=7)
    route_t = trace.route.t_center
    if trace.illusion_span is not None:
        ax_unrolled.axvspan(*trace.illusion_span, color=ILLUSION_COLOR, alpha=0.25, label="illusion")
        s_view = trace.illusion_span[0] - VIEW_RANGE_M
        if s_view > s_road[0]:  # stock illusions are in view from the start
            ax_unrolled.axvline(s_view, color=ILLUSION_COLOR, lw=1.0, ls=":", label="comes into view (camera)")
    ax_unrolled.axhspan(route_t - DEVIATION_THRESHOLD_M, route_t + DEVIATION_THRESHOLD_M, color="#2a9d8f",
                        alpha=0.12, label=f"route +- {DEVIATION_THRESHOLD_M} m")
    ax_unrolled.plot(s_path, [step.t_road for step in trace.steps], color="#e63946", lw=1.6, label="driven")
    ax_unrolled.set_xlim(s_road[0], s_road[-1])
    ax_unrolled.set_ylim(boundaries[-1] - 1.0, boundaries[0] + 1.0)
    ax_unrolled.set_xlabel("s along the road (m)")
    ax_unrolled.set_ylabel("t (m, + left)")
    ax_unrolled.legend(fontsize=7, loc="upper left")
    ax_unrolled.set_title(f"max |deviation| {summary.max_abs_deviation:.3f} m", fontsize=10)
    for ax in (ax_top, ax_unrolled):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return figure_png(fig)
