"""Marking standards: dash and gap lengths and line widths of lane markings per country and road class, from the
national marking manuals (sources in ``docs/realism.md#markings-as-on-real-roads``).

A road that names a standard (``Road.marking_standard``) has the dashes, gaps and widths of its markings from this
table, whatever its markings say; ``custom`` (the default) keeps each marking's own numbers. The line types (solid,
dashed, double, Botts' dots) and colours stay the case's: a standard sets how long and wide, not where.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..typed import MarkingStandardName

if TYPE_CHECKING:  # the case model builds on the world, not the other way round
    from ..case import Marking

FOOT_M = 0.3048
INCH_M = 0.0254


@dataclass(frozen=True)
class MarkingStandard:
    """One country's and road class's broken-line pattern and line widths (m)."""

    country: str
    road_class: str
    dash_m: float  # painted segment of a broken (dashed) line
    gap_m: float  # unpainted gap between two segments
    line_width_m: float | None  # lane lines and the centre line (None: each marking's own width)
    edge_width_m: float | None  # the carriageway's edge lines (None: as line_width_m)
    source: str  # manual, part and section


MARKING_STANDARDS: dict[MarkingStandardName, MarkingStandard] = {
    "us_mutcd": MarkingStandard(
        "United States", "all roads", 10 * FOOT_M, 30 * FOOT_M, 6 * INCH_M, None,
        "MUTCD (FHWA), Section 3A.06: broken lines of 10 ft segments and 30 ft gaps; normal lines 4 to 6 in wide"),
    "de_autobahn": MarkingStandard(
        "Germany", "Autobahn", 6.0, 12.0, 0.15, 0.30,
        "RMS (FGSV), Teil A: Markierung von Autobahnen: Leitlinie 6 m / 12 m (1:2), Schmalstrich 0.15 m; "
        "Fahrbahnbegrenzung as Breitstrich 0.30 m"),
    "de_urban": MarkingStandard(
        "Germany", "urban roads (innerorts)", 3.0, 6.0, 0.12, None,
        "RMS (FGSV), Teil 1: Leitlinie 3 m / 6 m (1:2) inside built-up areas; Schmalstrich 0.12 m off the Autobahn"),
    "cn_fast": MarkingStandard(
        "China", "design speed 60 km/h and above", 6.0, 9.0, 0.15, None,
        "GB 51038-2015, 12.3.2 (after GB 5768.3-2009): lane line 6 m / 9 m, 15 cm wide"),
    "cn_slow": MarkingStandard(
        "China", "design speed under 60 km/h", 2.0, 4.0, 0.10, None,
        "GB 51038-2015, 12.3.2 (after GB 5768.3-2009): lane line 2 m / 4 m, 10 cm wide"),
    "jp_expressway": MarkingStandard(
        "Japan", "motorway, design speed 80 km/h and above", 8.0, 12.0, None, None,
        "MLIT notice 区画線の設置様式について (1974), after the 標識令 (道路標識、区画線及び道路標示に関する命令): "
        "車線境界線 broken 8 m / 12 m"),
    "jp_general": MarkingStandard(
        "Japan", "ordinary roads", 5.0, 5.0, None, None,
        "MLIT notice 区画線の設置様式について (1974), after the 標識令: 車線境界線 broken 5 m / 5 m"),
}


def standard_markings(markings: Sequence[Marking], standard: MarkingStandardName) -> tuple[Marking, ...]:
    """``markings`` (left to right, the first and last are the edges) with the dash, gap and widths of
    ``standard``; ``custom`` returns them as they are."""
    if standard == "custom":
        return tuple(markings)
    table = MARKING_STANDARDS[standard]
    last = len(markings) - 1

    def width(index: int, marking: Marking) -> float:
        edge = table.edge_width_m if index in (0, last) else None
        return edge or table.line_width_m or marking.width

    return tuple(marking.model_copy(update={"dash": table.dash_m, "gap": table.gap_m, "width": width(index, marking)})
                 for index, marking in enumerate(markings))
