"""Several detectors side by side, in the paper's table layout.

For each detector: Perturbed / Original / Gap of TuSimple Accuracy and F1 for each category and their average;
a per-severity table (accuracy drop against the originals at each level), the per-type x per-level breakdown of
the paper's supplementary material, and a plot of the drop against severity, one line per detector. Each detector's
own full report (``report.md`` ...) goes into a sub-folder.

Every gap, drop and gain carries its 95 % bootstrap interval over basic cases (``report_interval``); differences
between two detectors or defences are resampled paired over the cases, and where that interval includes 0 the
two are reported as *not separable*.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import combinations
from pathlib import Path
from typing import Any

from ..files import write_atomic
from .interval import Interval, Term, combination_interval
from .robustness import (
    ALL,
    CATEGORY_ORDER,
    FIELDS,
    INTERVAL_NOTE,
    LEVELS,
    Report,
    Row,
    _csv,
    _number,
    _pct,
    drop_figure_png,
    gap_cell,
    gap_points,
    interval_numbers,
    with_interval,
    write_report,
)

COMPARE_MD, COMPARE_CSV, COMPARE_PNG = "compare.md", "compare.csv", "compare.png"
BREAKDOWN_CSV = "compare_breakdown.csv"
NOT_SEPARABLE = "not separable"


@dataclass(frozen=True)
class Detector:
    """One detector's name (column label) and its report."""

    name: str
    report: Report


def category_rows(report: Report) -> list[Row]:
    """The category rows (in the paper's order) and last the row of all images."""
    rows = {row.category: row for row in report.rows if row.type == ALL}
    ordered = [rows[c] for c in CATEGORY_ORDER if c in rows]
    ordered += [row for c, row in rows.items() if c not in CATEGORY_ORDER and c != ALL]
    return ordered + ([rows[ALL]] if ALL in rows else [])


def _heading(row: Row) -> str:
    return "Average" if row.category == ALL else row.category


def paired_interval(terms: Sequence[tuple[float, Row, int | None]], field: str, f1_variant: str) -> Interval | None:
    """Interval of a combination of rows' figures (coefficient, row, severity key of ``Row.cases``: 0 originals,
    None all perturbed, 1-5 a level), the cases of all the rows resampled paired."""
    chosen: list[Term] = [(coefficient, row.cases[key]) for coefficient, row, key in terms if key in row.cases]
    return combination_interval(chosen, field, f1_variant) if len(chosen) == len(terms) else None


def gap_difference(a: Row, b: Row, field: str, f1_variant: str) -> tuple[float | None, Interval | None]:
    """Gap of ``a`` minus gap of ``b`` and its paired interval."""
    gap_a, gap_b = a.gap(field), b.gap(field)
    if gap_a is None or gap_b is None:
        return None, None
    terms = [(1.0, a, None), (-1.0, a, 0), (-1.0, b, None), (1.0, b, 0)]
    return gap_a - gap_b, paired_interval(terms, field, f1_variant)


def separable_mark(interval: Interval | None) -> str:
    """`` (not separable)`` where a difference's interval includes 0."""
    return f" ({NOT_SEPARABLE})" if interval is not None and not interval.excludes_zero else ""


def markdown(detectors: list[Detector], f1_variant: str, baseline: str | None = None) -> str:
    first = category_rows(detectors[0].report)
    heads = [_heading(row) for row in first]
    lines = ["# Robustness of several detectors", "",
             f"TuSimple metric, F1 variant `{f1_variant}`, values in %. P = Perturbed, O = Original (the clean "
             "`00_original` cases), G = Gap = P - O. " + INTERVAL_NOTE, ""]
    for field, name in (("accuracy", "Accuracy"), ("f1", "F1")):
        lines += [f"## {name}", "", "| Detector | | " + " | ".join(heads) + " |",
                  "|---|---|" + "---:|" * len(heads)]
        for detector in detectors:
            rows = {_heading(row): row for row in category_rows(detector.report)}
            for label, pick in (("P", "perturbed"), ("O", "original"), ("G", None)):
                cells = []
                for head in heads:
                    row = rows.get(head)
                    if row is None:
                        cells.append("-")
                    elif pick is None:
                        cells.append(gap_cell(row, field))
                    else:
                        cells.append(_pct(getattr(getattr(row, pick), field, None)))
                name_cell = detector.name if label == "P" else ""
                lines.append(f"| {name_cell} | {label} | " + " | ".join(cells) + " |")
        lines.append("")
    if any(category_rows(d.report)[-1].no_paint is not None for d in detectors):
        lines += ["## Paint-free control", "",
                  "Accuracy on the originals and on the same frames with every lane marking removed (labels "
                  "unchanged): low without paint = the detector reads the paint.", "",
                  "| Detector | Original | No paint |", "|---|---:|---:|"]
        for detector in detectors:
            row = category_rows(detector.report)[-1]
            lines.append(f"| {detector.name} | {_pct(getattr(row.original, 'accuracy', None))} | "
                         f"{_pct(getattr(row.no_paint, 'accuracy', None))} |")
        lines.append("")
    lines += separability(detectors, f1_variant)
    if baseline is not None:
        lines += defences(detectors, baseline)
    lines += type_table(detectors)
    lines += ["## Accuracy drop by severity (all categories)", "",
              "| Detector | Original | " + " | ".join(f"Level {level}" for level in LEVELS) + " |",
              "|---|---:|" + "---:|" * len(LEVELS)]
    for detector in detectors:
        row = category_rows(detector.report)[-1]
        cells = [_pct(getattr(row.original, "accuracy", None))]
        cells += [gap_cell(row, "accuracy", level) for level in LEVELS]
        lines.append(f"| {detector.name} | " + " | ".join(cells) + " |")
    lines += ["", *breakdown(detectors)]
    return "\n".join(lines) + "\n"


def separability(detectors: list[Detector], f1_variant: str) -> list[str]:
    """Markdown lines: for every pair of detectors, the difference of their accuracy gaps per category and on
    average with its paired interval, marked where the two are not separable (the interval includes 0)."""
    if len(detectors) < 2:
        return []
    heads = [_heading(row) for row in category_rows(detectors[0].report)]
    lines = ["## Separability", "",
             "Accuracy Gap of the first detector minus the second's (points), cases resampled paired; "
             f"`{NOT_SEPARABLE}` where the interval includes 0.", "",
             "| Detectors | " + " | ".join(heads) + " |", "|---|" + "---:|" * len(heads)]
    inseparable = []
    for first, second in combinations(detectors, 2):
        a_rows = {_heading(row): row for row in category_rows(first.report)}
        b_rows = {_heading(row): row for row in category_rows(second.report)}
        cells = []
        for head in heads:
            if head not in a_rows or head not in b_rows:
                cells.append("-")
                continue
            value, interval = gap_difference(a_rows[head], b_rows[head], "accuracy", f1_variant)
            cells.append(with_interval(value, interval) + separable_mark(interval))
            if head == "Average" and separable_mark(interval):
                inseparable.append(f"{first.name} and {second.name}")
        lines.append(f"| {first.name} - {second.name} | " + " | ".join(cells) + " |")
    if inseparable:
        lines += ["", "Not separable on average (accuracy gap): " + "; ".join(inseparable) + "."]
    return lines + [""]


def breakdown(detectors: list[Detector]) -> list[str]:
    """Markdown lines: the supplementary per-type x per-level table, each detector's accuracy of the originals
    and its gap at every level with the interval."""
    lines = ["## Accuracy by type and level", "",
             "Per type: accuracy of the originals and the gap (points) at each level with its 95 % interval.", "",
             "| Detector | Category | Type | Original | " + " | ".join(f"Level {level}" for level in LEVELS) + " |",
             "|---|---|---|---:|" + "---:|" * len(LEVELS)]
    for detector in detectors:
        for row in detector.report.rows:
            if ALL in (row.category, row.type):
                continue
            cells = [_pct(getattr(row.original, "accuracy", None))]
            cells += [gap_cell(row, "accuracy", level) for level in LEVELS]
            lines.append(f"| {detector.name} | {row.category} | {row.type} | " + " | ".join(cells) + " |")
    return lines + [""]


def grows_with_level(row: Row) -> bool:
    """Whether the accuracy drop against the originals never shrinks from level 1 to level 5 and is larger at
    level 5 than at level 1 (a flat ladder does not grow)."""
    drops = [row.gap("accuracy", level) for level in LEVELS]
    known = [d for d in drops if d is not None]
    return (len(known) == len(drops) and all(b <= a + 1e-12 for a, b in zip(known, known[1:]))
            and known[-1] < known[0] - 1e-12)


def type_table(detectors: list[Detector]) -> list[str]:
    """Markdown lines: per illusion type, each detector's level-5 accuracy drop, marked ``↑`` where the drop grows
    with the level (never shrinks from level 1 to 5); the last row is the level-5 drop averaged over the types."""
    keyed = [{(row.category, row.type): row for row in d.report.rows if ALL not in (row.category, row.type)}
             for d in detectors]
    types = list(keyed[0]) + [key for rows in keyed[1:] for key in rows if key not in keyed[0]]
    if not types:
        return []
    lines = ["## Level-5 drop by type", "",
             "Accuracy at level 5 minus the originals', per type, with its 95 % interval; `↑` = the drop grows with "
             "the level (levels 1-5). The last row averages the types (each type counts once).", "",
             "| Category | Type | " + " | ".join(d.name for d in detectors) + " |",
             "|---|---|" + "---:|" * len(detectors)]
    for category, type_name in types:
        cells = []
        for rows in keyed:
            row = rows.get((category, type_name))
            cell = "-" if row is None else gap_cell(row, "accuracy", LEVELS[-1])
            cells.append(cell + (" ↑" if row is not None and grows_with_level(row) else ""))
        lines.append(f"| {category} | {type_name} | " + " | ".join(cells) + " |")
    means = []
    for rows in keyed:
        gaps = [g for g in (row.gap("accuracy", LEVELS[-1]) for row in rows.values()) if g is not None]
        growing = sum(grows_with_level(row) for row in rows.values())
        means.append(f"{_pct(sum(gaps) / len(gaps), signed=True)} ({growing}/{len(rows)} ↑)" if gaps else "-")
    lines += ["| **Mean over types** | | " + " | ".join(means) + " |", ""]
    return lines


SEED_MARK = "@"  # a detector named "aam@1" is the run of defence "aam" with seed 1


def defence_and_seed(name: str) -> tuple[str, str | None]:
    """("aam", "1") for "aam@1"; (name, None) for a name without a seed."""
    defence, mark, seed = name.rpartition(SEED_MARK)
    return (defence, seed) if mark and defence and seed else (name, None)


def defences(detectors: list[Detector], baseline: str) -> list[str]:
    """The defence table against ``baseline`` (a detector name, or a defence whose runs are named ``baseline@SEED``:
    then one table per seed, each against that seed's baseline run, and the mean over seeds)."""
    if any(d.name == baseline for d in detectors):
        return defence_table(sorted(detectors, key=lambda d: d.name != baseline))
    seeds = sorted({seed for d in detectors for defence, seed in [defence_and_seed(d.name)]
                    if defence == baseline and seed is not None})
    lines: list[str] = []
    for seed in seeds:
        runs = [d for d in detectors if defence_and_seed(d.name)[1] == seed]
        lines += defence_table(sorted(runs, key=lambda d: d.name != f"{baseline}{SEED_MARK}{seed}"),
                               f"Defences, seed {seed}")
    return lines + seed_mean_table(detectors, baseline, seeds)


def _average(report: Report, field: str) -> float | None:
    row = category_rows(report)[-1]
    return getattr(getattr(row, field), "accuracy", None)


def seed_mean_table(detectors: list[Detector], baseline: str, seeds: list[str]) -> list[str]:
    """Markdown lines: per defence, its average perturbed gain over the baseline run of the same seed, each seed's
    and their mean with its interval (cases resampled paired across all runs; ranked by the mean), and the mean
    change of clean accuracy."""
    by_name = {d.name: d for d in detectors}
    rows: list[tuple[float, str]] = []
    for defence in dict.fromkeys(defence_and_seed(d.name)[0] for d in detectors):
        if defence == baseline:
            continue
        gains, clean, pairs = [], [], []
        for seed in seeds:
            run, base = by_name.get(f"{defence}{SEED_MARK}{seed}"), by_name[f"{baseline}{SEED_MARK}{seed}"]
            mine, theirs = (None, None) if run is None else (_average(run.report, "perturbed"),
                                                              _average(base.report, "perturbed"))
            gains.append(None if mine is None or theirs is None else mine - theirs)
            if gains[-1] is not None and run is not None:
                pairs.append((category_rows(run.report)[-1], category_rows(base.report)[-1]))
            o_mine, o_theirs = (None, None) if run is None else (_average(run.report, "original"),
                                                                  _average(base.report, "original"))
            clean.append(None if o_mine is None or o_theirs is None else o_mine - o_theirs)
        found = [g for g in gains if g is not None]
        if not found:
            continue
        mean = sum(found) / len(found)
        terms = [term for mine_row, base_row in pairs
                 for term in ((1.0 / len(pairs), mine_row, None), (-1.0 / len(pairs), base_row, None))]
        interval = paired_interval(terms, "accuracy", detectors[0].report.f1_variant)
        found_clean = [c for c in clean if c is not None]
        mean_clean = sum(found_clean) / len(found_clean) if found_clean else None
        cells = [_pct(g, signed=True) for g in gains]
        rows.append((mean, f"| {defence} | " + " | ".join(cells) + f" | **{with_interval(mean, interval)}**"
                           f"{separable_mark(interval)} | {_pct(mean_clean, signed=True)} | {len(found)} |"))
    if not rows:
        return []
    lines = ["## Defences, mean over seeds", "",
             f"Average perturbed accuracy gain (points) over `{baseline}` trained with the same seed, per seed and "
             "their mean with its 95 % interval (best first; `not separable` where it includes 0), and the mean "
             "change of clean accuracy.", "",
             "| Defence | " + " | ".join(f"seed {seed}" for seed in seeds) + " | Mean gain | Clean change | Seeds |",
             "|---|" + "---:|" * (len(seeds) + 3)]
    lines += [line for _, line in sorted(rows, key=lambda r: -r[0])]
    return lines + [""]


def defence_table(detectors: list[Detector], title: str = "Defences") -> list[str]:
    """Markdown lines: each detector's Perturbed accuracy per category and average, its gain over the first
    detector (the baseline: the vanilla model when comparing training defences) with the paired interval, and its
    clean (Original) accuracy and change."""
    if len(detectors) < 2:
        return []
    base = {_heading(row): row for row in category_rows(detectors[0].report)}
    heads = list(base)
    f1_variant = detectors[0].report.f1_variant
    lines = [f"## {title}", "",
             f"Perturbed accuracy (%) per category and its gain over `{detectors[0].name}` in parentheses with its "
             f"95 % interval, cases resampled paired (`{NOT_SEPARABLE}` where it includes 0); Clean = accuracy on "
             "the originals (a defence should not cost more than 1 point there).", "",
             "| Detector | " + " | ".join(heads) + " | Clean |", "|---|" + "---:|" * (len(heads) + 1)]
    for detector in detectors:
        rows = {_heading(row): row for row in category_rows(detector.report)}
        cells = []
        for head in heads:
            mine = getattr(rows[head].perturbed, "accuracy", None) if head in rows else None
            theirs = getattr(base[head].perturbed, "accuracy", None)
            gain = None if mine is None or theirs is None else mine - theirs
            if detector is detectors[0] or gain is None:
                cells.append(_pct(mine))
                continue
            interval = paired_interval([(1.0, rows[head], None), (-1.0, base[head], None)], "accuracy", f1_variant)
            cells.append(f"{_pct(mine)} ({with_interval(gain, interval)}){separable_mark(interval)}")
        clean = getattr(rows.get("Average") and rows["Average"].original, "accuracy", None)
        base_clean = getattr(base["Average"].original, "accuracy", None) if "Average" in base else None
        clean_cell = _pct(clean)
        if detector is not detectors[0] and clean is not None and base_clean is not None:
            clean_cell += f" ({_pct(clean - base_clean, signed=True)})"
        lines.append(f"| {detector.name} | " + " | ".join(cells) + f" | {clean_cell} |")
    return lines + [""]


def _level_rows(detectors: list[Detector], rows_of: Callable[[Report], list[Row]]) -> list[list[str | int]]:
    header: list[str | int] = ["detector", "category", "type", "severity", "images", "accuracy", "f1"]
    for name in FIELDS:
        header += [f"{name}_gap", f"{name}_gap_lo", f"{name}_gap_hi"]
    rows: list[list[str | int]] = [header]
    for detector in detectors:
        for row in rows_of(detector.report):
            for level in (0, *LEVELS):
                stats = row.original if level == 0 else row.levels[level]
                if stats is None:
                    continue
                cells: list[str | int] = [detector.name, row.category, row.type, level, stats.images,
                                          _number(stats.accuracy), _number(stats.f1)]
                for name in FIELDS:
                    cells += ([_number(0.0), "", ""] if level == 0 else
                              [_number(row.gap(name, level)), *interval_numbers(row.gap_interval(name, level))])
                rows.append(cells)
    return rows


def comparison_csv(detectors: list[Detector]) -> str:
    """compare.csv: per detector, category (and all) and level 0-5: images, accuracy, F1, gaps and intervals."""
    return _csv(_level_rows(detectors, category_rows))


def breakdown_csv(detectors: list[Detector]) -> str:
    """compare_breakdown.csv: the same per detector, illusion type and level (the supplementary breakdown)."""
    return _csv(_level_rows(detectors, lambda report: [row for row in report.rows
                                                          if ALL not in (row.category, row.type)]))


PLOT_LEGEND_INSIDE_MAX = 6  # more detectors than this: the legend goes beside the axes, off the lines
PLOT_COLORS = 10  # matplotlib's default colour cycle
PLOT_MARKERS = ("o", "s", "^", "D", "v", "P")


def line_style(index: int) -> dict[str, Any]:
    """Colour, marker and dash of the ``index``-th detector's line: one colour each for the first ten, then the
    colours again with another marker and dash, so no two of up to 60 lines look alike."""
    turn = index // PLOT_COLORS
    return {"color": f"C{index % PLOT_COLORS}", "marker": PLOT_MARKERS[turn % len(PLOT_MARKERS)],
            "linestyle": "-" if turn % 2 == 0 else "--"}


def comparison_plot(detectors: list[Detector]) -> bytes:
    """PNG: accuracy drop (percentage points) against severity over all categories, one line per detector."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    many = len(detectors) > PLOT_LEGEND_INSIDE_MAX
    fig, ax = plt.subplots(figsize=(9.0 if many else 7.0, 4.2), dpi=120)
    for index, detector in enumerate(detectors):
        row = category_rows(detector.report)[-1]
        points = gap_points(row)
        if points:
            ax.plot([p[0] for p in points], [p[1] for p in points], linewidth=1.8, label=detector.name,
                    **line_style(index))
    return drop_figure_png(fig, ax, "Accuracy drop by severity, per detector", legend_beside=many,
                           legend_columns=1 + len(detectors) // 16)


def write_comparison(detectors: list[Detector], out_dir: str | Path, f1_variant: str,
                     baseline: str | None = None) -> list[Path]:
    """compare.md, compare.csv, compare_breakdown.csv and compare.png in ``out_dir`` and each detector's report in
    ``out_dir/<name>/``."""
    out_dir = Path(out_dir)
    written = []
    for detector in detectors:
        written += write_report(detector.report, out_dir / detector.name)
    files = {COMPARE_MD: markdown(detectors, f1_variant, baseline).encode("utf-8"),
             COMPARE_CSV: comparison_csv(detectors).encode("utf-8"),
             BREAKDOWN_CSV: breakdown_csv(detectors).encode("utf-8"), COMPARE_PNG: comparison_plot(detectors)}
    for name, data in files.items():
        write_atomic(out_dir / name, data)
    return [out_dir / name for name in files] + written
