"""Robustness report: Original / Perturbed / Gap of TuSimple Accuracy and F1 per category, type and severity.

Images are grouped by the extra fields of the split's labels (``category``, ``type``, ``severity``): severity 0
marks the clean original cases, 1-5 the perturbed ones. Every figure of a group is the official per-image mean
over its images (F1 from the group's mean FP and FN), so a category pools the images of its types. Gap =
Perturbed - Original (negative = the detector lost accuracy under the illusion).

Every Gap carries a 95 % interval from a bootstrap over basic cases (``report_interval``: frames within a case
are not independent, so whole cases are resampled), printed ``-7.40 [-9.10, -5.80]`` and written as ``_lo`` /
``_hi`` columns.

Records with ``"paint": false`` (``lanevil dataset --no-paint``) are the originals rendered with their lane paint
removed: they form the *paint-free control*, reported beside the originals and never mixed into them. A detector
that reads the paint scores low there; one that scores high places lanes from the road's layout.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable
from dataclasses import dataclass
from dataclasses import field as default_field
from pathlib import Path
from typing import Any

from ..export.encode import figure_png
from ..files import write_atomic
from ..metrics.evaluate import ScoredImage
from ..metrics.tusimple import summarize
from .interval import CaseSums, Interval, gap_interval

LEVELS = (1, 2, 3, 4, 5)
ALL = "All"
CATEGORY_ORDER = ("RoadDamage", "TrafficObstruction", "Shadow", "Reflection")
REPORT_MD, REPORT_CSV, SEVERITY_CSV, REPORT_PNG = "report.md", "report.csv", "report_severity.csv", "report.png"
FIELDS = ("accuracy", "f1")


@dataclass(frozen=True)
class Stats:
    """TuSimple figures of one group of images (accuracy, FP, FN, F1 as fractions)."""

    images: int
    accuracy: float
    fp: float
    fn: float
    f1: float


@dataclass(frozen=True)
class Row:
    """One table row: a category (type ``All``), a type, or everything (category and type ``All``).

    ``cases`` holds the per-case totals the intervals are resampled from: key 0 the originals, 1-5 each level,
    None every perturbed image; ``intervals`` the 95 % interval of each gap by (field, level or None)."""

    category: str
    type: str
    original: Stats | None
    perturbed: Stats | None
    levels: dict[int, Stats | None]
    no_paint: Stats | None = None
    cases: dict[int | None, CaseSums] = default_field(default_factory=dict)
    intervals: dict[tuple[str, int | None], Interval | None] = default_field(default_factory=dict)

    def gap(self, field: str, level: int | None = None) -> float | None:
        """Perturbed (or one level) minus Original of ``field`` ('accuracy' or 'f1'); None if either is missing."""
        other = self.perturbed if level is None else self.levels.get(level)
        if self.original is None or other is None:
            return None
        return getattr(other, field) - getattr(self.original, field)

    def gap_interval(self, field: str, level: int | None = None) -> Interval | None:
        """The 95 % interval of ``gap(field, level)`` (None where the gap is missing)."""
        return self.intervals.get((field, level))


@dataclass(frozen=True)
class Report:
    """All rows (types, then their category, then everything), the F1 variant and unlabelled image count."""

    rows: list[Row]
    f1_variant: str
    title: str
    unlabelled: int


def _stats(images: list[ScoredImage], f1_variant: str) -> Stats | None:
    if not images:
        return None
    summary = summarize([image.score for image in images], f1_variant)
    return Stats(summary.images, summary.accuracy, summary.fp, summary.fn, summary.f1)


def _severity(image: ScoredImage) -> int:
    return int(image.extra["severity"])


def paint_free(image: ScoredImage) -> bool:
    """An image of the paint-free control (its record says ``"paint": false``)."""
    return image.extra.get("paint") is False


def _row(category: str, type_name: str, images: list[ScoredImage], f1_variant: str) -> Row:
    control = [image for image in images if paint_free(image)]
    images = [image for image in images if not paint_free(image)]
    originals = [image for image in images if _severity(image) == 0]
    perturbed = [image for image in images if _severity(image) > 0]
    by_level = {level: [image for image in images if _severity(image) == level] for level in LEVELS}
    levels = {level: _stats(chosen, f1_variant) for level, chosen in by_level.items()}
    cases: dict[int | None, CaseSums] = {0: CaseSums.of(originals), None: CaseSums.of(perturbed),
                                         **{level: CaseSums.of(chosen) for level, chosen in by_level.items()}}
    intervals = {(name, level): gap_interval(cases[0], cases[level], name, f1_variant)
                 for name in FIELDS for level in (None, *LEVELS) if originals and cases[level].keys}
    return Row(category, type_name, _stats(originals, f1_variant), _stats(perturbed, f1_variant), levels,
               _stats(control, f1_variant), cases, intervals)


def _labelled(image: ScoredImage) -> bool:
    extra = image.extra
    return all(key in extra for key in ("category", "type", "severity")) and isinstance(extra["severity"], int)


def _category_key(category: str) -> tuple[int, str]:
    return (CATEGORY_ORDER.index(category) if category in CATEGORY_ORDER else len(CATEGORY_ORDER), category)


def build_report(images: Iterable[ScoredImage], f1_variant: str = "ganet", title: str = "") -> Report:
    """Rows for every (category, type) found, each category, and all images together."""
    chosen = list(images)
    labelled = [image for image in chosen if _labelled(image)]
    rows = []
    for category in sorted({image.extra["category"] for image in labelled}, key=_category_key):
        in_category = [image for image in labelled if image.extra["category"] == category]
        for type_name in sorted({image.extra["type"] for image in in_category}):
            in_type = [image for image in in_category if image.extra["type"] == type_name]
            rows.append(_row(category, type_name, in_type, f1_variant))
        rows.append(_row(category, ALL, in_category, f1_variant))
    rows.append(_row(ALL, ALL, labelled, f1_variant))
    return Report(rows, f1_variant, title, len(chosen) - len(labelled))


# ---------------------------------------------------------------------------------------------- formatting

def _pct(value: float | None, signed: bool = False) -> str:
    if value is None:
        return "-"
    percent = round(100 * value, 2) or 0.0  # no "-0.00" from float noise
    return f"{percent:+.2f}" if signed else f"{percent:.2f}"


def with_interval(value: float | None, interval: Interval | None) -> str:
    """``-7.40 [-9.10, -5.80]``: a signed percentage and its interval (just the value where there is none)."""
    text = _pct(value, signed=True)
    if value is None or interval is None:
        return text
    return f"{text} [{_pct(interval.lo, signed=True)}, {_pct(interval.hi, signed=True)}]"


def gap_cell(row: Row, field: str, level: int | None = None) -> str:
    """A gap of a row with its 95 % interval."""
    return with_interval(row.gap(field, level), row.gap_interval(field, level))


def _label(row: Row) -> tuple[str, str]:
    if row.category == ALL:
        return "**All**", ""
    if row.type == ALL:
        return f"**{row.category}**", "**all types**"
    return row.category, row.type


def _images(stats: Stats | None) -> int:
    return stats.images if stats is not None else 0


def markdown(report: Report) -> str:
    """report.md: the main Original/Perturbed/Gap table and per-severity tables (values in %)."""
    lines = [f"# {report.title or 'Robustness report'}", "",
             f"TuSimple metric; F1 variant `{report.f1_variant}`. Values in %. Gap = Perturbed - Original "
             "(negative = drop). Original = the clean `00_original` cases of each type. " + INTERVAL_NOTE, ""]
    if report.unlabelled:
        lines += [f"{report.unlabelled} image(s) without category/type/severity are not in the tables.", ""]
    lines += ["| Category | Type | Images orig/pert | Acc Original | Acc Perturbed | Acc Gap | F1 Original "
              "| F1 Perturbed | F1 Gap |", "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for row in report.rows:
        category, type_name = _label(row)
        cells = [category, type_name, f"{_images(row.original)}/{_images(row.perturbed)}"]
        for field in ("accuracy", "f1"):
            cells += [_pct(getattr(row.original, field, None)), _pct(getattr(row.perturbed, field, None)),
                      gap_cell(row, field)]
        lines.append("| " + " | ".join(cells) + " |")
    total = report.rows[-1] if report.rows else None
    if total is not None and total.no_paint is not None:
        lines += ["", "## Paint-free control", "",
                  "Accuracy on the originals rendered with every lane marking removed (labels unchanged). A detector "
                  "that reads the paint scores low here; a high score means it places lanes from the road's layout.",
                  "", "| Category | Type | Images | Acc Original | Acc no paint |", "|---|---|---:|---:|---:|"]
        for row in report.rows:
            if row.no_paint is None:
                continue
            category, type_name = _label(row)
            lines.append(f"| {category} | {type_name} | {row.no_paint.images} | "
                         f"{_pct(getattr(row.original, 'accuracy', None))} | {_pct(row.no_paint.accuracy)} |")
    for field, name in (("accuracy", "Accuracy"), ("f1", "F1")):
        lines += ["", f"## {name} by type and severity", "",
                  f"{name} of the originals (level 0) and of each level, per type (the supplementary breakdown); in "
                  "parentheses the gap to the originals with its 95 % interval.", "",
                  "| Category | Type | Original | " + " | ".join(f"Level {level}" for level in LEVELS) + " |",
                  "|---|---|" + "---:|" * (len(LEVELS) + 1)]
        for row in report.rows:
            category, type_name = _label(row)
            cells = [category, type_name, _pct(getattr(row.original, field, None))]
            for level in LEVELS:
                stats = row.levels[level]
                value = _pct(getattr(stats, field, None))
                gap = row.gap(field, level)
                cells.append(value if gap is None else f"{value} ({gap_cell(row, field, level)})")
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _number(value: float | None) -> str:
    return "" if value is None else f"{value:.6f}"


def interval_numbers(interval: Interval | None) -> list[str | int]:
    """The ``_lo`` and ``_hi`` CSV cells of an interval (empty where there is none)."""
    return ["", ""] if interval is None else [_number(interval.lo), _number(interval.hi)]


INTERVAL_NOTE = ("Intervals in brackets: 95 % bootstrap over basic cases (an original with its levels; "
                 "2,000 resamples, seed 0).")


def _csv(rows: list[list[str | int]]) -> str:
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerows(rows)
    return buffer.getvalue()


def report_csv(report: Report) -> str:
    """report.csv: one line per row with original/perturbed/gap accuracy and F1 (fractions)."""
    header = ["category", "type", "images_original", "images_perturbed", "cases"]
    for name in FIELDS:
        header += [f"{name}_original", f"{name}_perturbed", f"{name}_gap", f"{name}_gap_lo", f"{name}_gap_hi"]
    rows: list[list[str | int]] = [[*header, "f1_variant"]]
    for row in report.rows:
        cells: list[str | int] = [row.category, row.type, _images(row.original), _images(row.perturbed),
                                  len(row.cases[0].keys) if row.cases else 0]
        for name in FIELDS:
            cells += [_number(getattr(row.original, name, None)), _number(getattr(row.perturbed, name, None)),
                      _number(row.gap(name)), *interval_numbers(row.gap_interval(name))]
        rows.append([*cells, report.f1_variant])
    return _csv(rows)


def severity_csv(report: Report) -> str:
    """report_severity.csv: one line per row and level 0-5 (0 = originals) with accuracy, FP, FN, F1, gaps."""
    header = ["category", "type", "severity", "images", "accuracy", "fp", "fn", "f1", "accuracy_gap",
              "accuracy_gap_lo", "accuracy_gap_hi", "f1_gap", "f1_gap_lo", "f1_gap_hi", "f1_variant"]
    rows: list[list[str | int]] = [list(header)]
    for row in report.rows:
        for level in (0, *LEVELS):
            stats = row.original if level == 0 else row.levels[level]
            if stats is None:
                continue
            gaps: list[str | int] = []
            for name in FIELDS:
                if level == 0:
                    gaps += [_number(0.0), "", ""]
                else:
                    gaps += [_number(row.gap(name, level)), *interval_numbers(row.gap_interval(name, level))]
            rows.append([row.category, row.type, level, stats.images, _number(stats.accuracy), _number(stats.fp),
                         _number(stats.fn), _number(stats.f1), *gaps, report.f1_variant])
    return _csv(rows)


def gap_points(row: Row) -> list[tuple[int, float]]:
    """(level, accuracy gap in percentage points) of every level a row has: level - Original, negative for a drop,
    the sign of the tables."""
    return [(level, 100 * gap) for level in LEVELS if (gap := row.gap("accuracy", level)) is not None]


def severity_plot(report: Report) -> bytes:
    """PNG: accuracy gap (level - Original, percentage points, negative = drop) against severity, one line per
    category."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.2), dpi=120)
    for row in report.rows:
        if row.type != ALL:
            continue
        points = gap_points(row)
        if not points:
            continue
        style = {"color": "black", "linestyle": "--", "linewidth": 2.2} if row.category == ALL else {"linewidth": 1.6}
        ax.plot([p[0] for p in points], [p[1] for p in points], marker="o", label=row.category, **style)
    return drop_figure_png(fig, ax, report.title or "Accuracy drop by severity")


def drop_figure_png(fig: Any, ax: Any, title: str, legend_beside: bool = False, legend_columns: int = 1) -> bytes:
    """Finish an accuracy-gap-by-severity plot (zero line, level ticks, labels, grid, legend) and encode it;
    ``legend_beside`` puts the legend right of the axes, off the lines, for plots with many of them."""
    ax.axhline(0.0, color="grey", linewidth=0.8)
    ax.set_xticks(list(LEVELS))
    ax.set_xlabel("severity level")
    ax.set_ylabel("accuracy gap vs original (points, negative = drop)")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    if legend_beside:
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), ncol=legend_columns)
    else:
        ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
    return figure_png(fig)


def write_report(report: Report, out_dir: str | Path) -> list[Path]:
    """Write report.md, report.csv, report_severity.csv and report.png into ``out_dir``; return their paths."""
    out_dir = Path(out_dir)
    files = {REPORT_MD: markdown(report).encode("utf-8"), REPORT_CSV: report_csv(report).encode("utf-8"),
             SEVERITY_CSV: severity_csv(report).encode("utf-8"), REPORT_PNG: severity_plot(report)}
    for name, data in files.items():
        write_atomic(out_dir / name, data)
    return [out_dir / name for name in files]
