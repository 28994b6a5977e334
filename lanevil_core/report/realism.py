"""Real footage vs our renders side by side: one row per ``realism`` statistic with a plain-words verdict.

A ratio ours/real within ``SIMILAR_RATIO`` of 1 reads "similar"; otherwise the verdict names the larger side's
word ("ours is 2.1x smoother" for an edge density of 0.48 times the real one). The power-spectrum slope is a
negative exponent, so it is compared by difference (``SIMILAR_SLOPE``) rather than by ratio.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..metrics.realism import ANALYSIS_WIDTH, STATISTICS, StatisticSummary

SIMILAR_RATIO = 1.1  # ours/real within [1/1.1, 1.1] is "similar"
SIMILAR_SLOPE = 0.1  # slopes closer than this are "similar"
SLOPE = "spectrum_slope"


@dataclass(frozen=True)
class StatisticLabel:
    """How a statistic reads in a table: its title, number format, and the words for more / less of it."""

    title: str
    spec: str
    more: str
    less: str


LABELS: dict[str, StatisticLabel] = {
    "saturation": StatisticLabel("colour saturation (HSV S, 0-255)", ".1f", "more saturated", "less saturated"),
    "edge_density": StatisticLabel("edge density (Canny share)", ".4f", "busier (more edges)", "smoother"),
    "contrast": StatisticLabel("RMS contrast (grey std, 0-1)", ".3f", "more contrasted", "flatter in contrast"),
    "noise": StatisticLabel("noise sigma (Immerkær, grey levels)", ".2f", "noisier", "cleaner"),
    SLOPE: StatisticLabel("power-spectrum slope (natural ≈ -2)", ".2f", "flatter", "steeper"),
    "sharpness": StatisticLabel("sharpness (Laplacian variance)", ".1f", "sharper", "softer"),
    "brightness": StatisticLabel("mean brightness (grey, 0-255)", ".1f", "brighter", "darker"),
    "clipped": StatisticLabel("clipped pixels (grey <= 5 or >= 250)", ".4f", "more clipped", "less clipped"),
}


@dataclass(frozen=True)
class ComparisonRow:
    """One statistic of the two folders; ``real`` or ``ours`` is None when that folder was not given."""

    name: str
    real: StatisticSummary | None
    ours: StatisticSummary | None
    ratio: float | None
    verdict: str


def ratio(ours: float, real: float) -> float | None:
    """ours / real; None when real is 0 (and ours is not)."""
    if real == 0:
        return 1.0 if ours == 0 else None
    return ours / real


def verdict(name: str, ours: float, real: float) -> str:
    """Plain words comparing the means of statistic ``name``: "ours is 2.1x smoother", "similar (within 10 %)"."""
    label = LABELS[name]
    if name == SLOPE:
        difference = ours - real
        if abs(difference) < SIMILAR_SLOPE:
            return f"similar (within {SIMILAR_SLOPE})"
        detail = "more fine detail or noise" if difference > 0 else "less fine detail"
        return f"ours is {abs(difference):.2f} {label.more if difference > 0 else label.less} ({detail})"
    value = ratio(ours, real)
    if value is None:
        return f"real is 0, ours {format(ours, label.spec)}"
    if value == 0:
        return f"ours is 0, real {format(real, label.spec)}"
    if 1 / SIMILAR_RATIO <= value <= SIMILAR_RATIO:
        return f"similar (within {round(100 * (SIMILAR_RATIO - 1))} %)"
    return f"ours is {value:.1f}× {label.more}" if value > 1 else f"ours is {1 / value:.1f}× {label.less}"


def comparison_rows(real: dict[str, StatisticSummary] | None,
                    ours: dict[str, StatisticSummary] | None) -> list[ComparisonRow]:
    """One row per statistic (``STATISTICS`` order); ratio and verdict only when both sides are given."""
    rows = []
    for name in STATISTICS:
        real_value = real[name] if real is not None else None
        ours_value = ours[name] if ours is not None else None
        if real_value is None or ours_value is None:
            rows.append(ComparisonRow(name, real_value, ours_value, None, ""))
            continue
        rows.append(ComparisonRow(name, real_value, ours_value, ratio(ours_value.mean, real_value.mean),
                                  verdict(name, ours_value.mean, real_value.mean)))
    return rows


def _mean_std(value: StatisticSummary | None, spec: str) -> str:
    return "" if value is None else f"{format(value.mean, spec)} ± {format(value.std, spec)}"


def _cells(row: ComparisonRow, real: bool, ours: bool) -> list[str]:
    spec = LABELS[row.name].spec
    cells = [LABELS[row.name].title]
    cells += [_mean_std(row.real, spec)] if real else []
    cells += [_mean_std(row.ours, spec)] if ours else []
    if real and ours:
        cells += ["n/a" if row.ratio is None or not math.isfinite(row.ratio) else f"{row.ratio:.2f}", row.verdict]
    return cells


def _header(real: bool, ours: bool) -> list[str]:
    header = ["statistic"] + (["real mean ± std"] if real else []) + (["ours mean ± std"] if ours else [])
    return header + (["ours/real", "verdict"] if real and ours else [])


def table_text(rows: list[ComparisonRow], real: bool, ours: bool) -> str:
    """The rows as an aligned plain-text table (only the columns of the folders given)."""
    lines = [_header(real, ours)] + [_cells(row, real, ours) for row in rows]
    widths = [max(len(line[column]) for line in lines) for column in range(len(lines[0]))]
    return "\n".join("  ".join(cell.ljust(width) for cell, width in zip(line, widths, strict=True)).rstrip()
                     for line in lines)


def table_markdown(rows: list[ComparisonRow], real: bool, ours: bool) -> str:
    """The rows as a Markdown table."""
    header = _header(real, ours)
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(_cells(row, real, ours)) + " |" for row in rows]
    return "\n".join(lines)


def report_markdown(rows: list[ComparisonRow], sources: dict[str, tuple[str, int]]) -> str:
    """A Markdown report: which folders (``sources``: side -> (folder, images)), the analysis size, the table."""
    lines = ["# Realism statistics", ""]
    lines += [f"- {side}: `{folder}` ({images} images)" for side, (folder, images) in sources.items()]
    lines += [f"- every image analysed at {ANALYSIS_WIDTH} px width, aspect kept (1280x720 for 16:9)", ""]
    lines.append(table_markdown(rows, "real" in sources, "ours" in sources))
    return "\n".join(lines) + "\n"
