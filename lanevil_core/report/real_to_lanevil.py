"""The Real -> LanEvil table: detectors trained on real roads, tested on LanEvil's renders (the paper's second
experiment: do models that never saw a render fall for the illusions?).

A detector is marked real-trained on the command line (``lanevil report --real-trained NAME``) or by its plug-in
(``real_trained`` in the detector configuration, an ONNX sidecar or a Python plug-in; docs/detectors.md). Such
detectors are reported apart, in ``real_to_lanevil.md`` and ``real_to_lanevil.csv``: per category and on
average, Original / Perturbed / Gap of TuSimple Accuracy and F1, then each severity level against the originals,
with the same 95 % bootstrap intervals as every other table. A real-trained model's Original figure also says how
well our renders pass for its training roads (a low one means the camera does not match: docs/cameras.md).
"""

from __future__ import annotations

from pathlib import Path

from ..case import write_atomic
from .compare import Detector, category_rows
from .robustness import ALL, FIELDS, INTERVAL_NOTE, LEVELS, Row, _csv, _number, _pct, gap_cell, interval_numbers

REAL_MD, REAL_CSV = "real_to_lanevil.md", "real_to_lanevil.csv"
FIELD_NAMES = {"accuracy": "Accuracy", "f1": "F1"}


def _heading(row: Row) -> str:
    return "**Average**" if row.category == ALL else row.category


def markdown(detectors: list[Detector], f1_variant: str) -> str:
    """real_to_lanevil.md: per real-trained detector, the category table and the per-level table of each field."""
    lines = ["# Real → LanEvil", "",
             "Detectors trained on real roads, tested on LanEvil. TuSimple metric, F1 variant "
             f"`{f1_variant}`, values in %. Gap = Perturbed - Original (negative = drop); Original = the clean "
             "`00_original` cases. " + INTERVAL_NOTE, ""]
    for detector in detectors:
        rows = category_rows(detector.report)
        lines += [f"## {detector.name}", "",
                  "| Category | Images orig/pert | Acc Original | Acc Perturbed | Acc Gap | F1 Original | F1 Perturbed "
                  "| F1 Gap |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
        for row in rows:
            cells = [_heading(row), f"{getattr(row.original, 'images', 0)}/{getattr(row.perturbed, 'images', 0)}"]
            for field in FIELDS:
                cells += [_pct(getattr(row.original, field, None)), _pct(getattr(row.perturbed, field, None)),
                          gap_cell(row, field)]
            lines.append("| " + " | ".join(cells) + " |")
        for field in FIELDS:
            lines += ["", f"### {detector.name}: {FIELD_NAMES[field]} by level", "",
                      "In parentheses the gap to the originals with its 95 % interval.", "",
                      "| Category | Original | " + " | ".join(f"Level {level}" for level in LEVELS) + " |",
                      "|---|---:|" + "---:|" * len(LEVELS)]
            for row in rows:
                cells = [_heading(row), _pct(getattr(row.original, field, None))]
                for level in LEVELS:
                    value = _pct(getattr(row.levels[level], field, None))
                    cells.append(value if row.gap(field, level) is None else f"{value} ({gap_cell(row, field, level)})")
                lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    return "\n".join(lines)


def table_csv(detectors: list[Detector], f1_variant: str) -> str:
    """real_to_lanevil.csv: one line per detector, category and level (``all`` = every perturbed image)."""
    header = ["detector", "category", "level", "images_original", "images_perturbed"]
    for field in FIELDS:
        header += [f"{field}_original", f"{field}_perturbed", f"{field}_gap", f"{field}_gap_lo", f"{field}_gap_hi"]
    lines: list[list[str | int]] = [[*header, "f1_variant"]]
    for detector in detectors:
        for row in category_rows(detector.report):
            for level in ("all", *LEVELS):
                key = None if level == "all" else int(level)
                other = row.perturbed if key is None else row.levels[key]
                cells: list[str | int] = [detector.name, row.category, level,
                                          getattr(row.original, "images", 0), getattr(other, "images", 0)]
                for field in FIELDS:
                    cells += [_number(getattr(row.original, field, None)), _number(getattr(other, field, None)),
                              _number(row.gap(field, key)), *interval_numbers(row.gap_interval(field, key))]
                lines.append([*cells, f1_variant])
    return _csv(lines)


def write_real_table(detectors: list[Detector], out_dir: str | Path, f1_variant: str) -> list[Path]:
    """real_to_lanevil.md and .csv of the real-trained ``detectors`` in ``out_dir``; their paths."""
    out_dir = Path(out_dir)
    files = {REAL_MD: markdown(detectors, f1_variant).encode("utf-8"),
             REAL_CSV: table_csv(detectors, f1_variant).encode("utf-8")}
    for name, data in files.items():
        write_atomic(out_dir / name, data)
    return [out_dir / name for name in files]
