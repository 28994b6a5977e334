"""Drive every case of a folder with one detector and tabulate the paper's driving test per type and level.

ASR (attack success rate) of a group of cases = the share of its drives where the illusion pushed the vehicle
more than 0.285 m off its lane centre within 2.5 s of coming into view (``summary``). Originals (level 0) and the
clean road-type cases are scored the same way from the drive's start: their rate is the detector's own failure,
the baseline the perturbed levels compare with.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from ..case import Case, load_case
from ..files import write_atomic
from ..illusions import CATEGORIES, REGISTRY
from ..library.benchmark_layout import MIXED_CATEGORY, case_illusion_type, folder_type, type_category
from .loop import DriveSettings
from .outputs import drive_to_folder
from .summary import DriveSummary

LEVELS = (0, 1, 2, 3, 4, 5)  # 0 = the original (no illusion)
CLEAN = "clean"
# The paper's closed-loop figures (CARLA + OpenPilot / Apollo): per category where published.
PAPER_ASR = {"road_damage": "OpenPilot 92.31 %"}
PAPER_NOTE = ("Paper: OpenPilot in CARLA, 8 cases (two types per category), 5 repeats; Road Damage reached "
              "92.31 % ASR; Apollo stopped in 6 of 8 cases.")


@dataclass(frozen=True)
class SuiteEntry:
    """One case of the suite and its drive."""

    path: str  # relative to the suite folder
    category: str  # an illusion category, or ``clean``
    type: str  # the illusion type, or the clean case's road type
    level: int  # severity, 0 for an original or a clean case
    summary: DriveSummary


def case_group(case: Case, path: Path) -> tuple[str, str, int]:
    """(category, type, level) of a case: its illusion type (or its folders', for an original)."""
    illusion_type = case_illusion_type(case, folder_type(PurePosixPath(path.as_posix())))
    if illusion_type is None:
        return CLEAN, case.road.type, 0
    level = max((illusion.severity for illusion in case.illusions), default=0)
    return type_category(illusion_type), illusion_type, level


def suite_cases(root: Path) -> list[Path]:
    return sorted(root.glob("**/*.json"))


Progress = Callable[[int, int, str], None]


def run_suite(root: str | Path, settings: DriveSettings, out_dir: str | Path, video: bool = False,
              progress: Progress | None = None) -> list[SuiteEntry]:
    """Drive every case under ``root`` into ``out_dir/<case path>/``; returns the entries in path order."""
    root, out_dir = Path(root), Path(out_dir)
    paths = suite_cases(root)
    cases = [(path, load_case(path)) for path in paths]  # every file validated before the first drive
    entries = []
    for done, (path, case) in enumerate(cases, start=1):
        relative = path.relative_to(root).with_suffix("")
        output = drive_to_folder(case, settings, out_dir / relative, video=video)
        category, type_name, level = case_group(case, path)
        entries.append(SuiteEntry(relative.as_posix(), category, type_name, level, output.summary))
        if progress is not None:
            progress(done, len(cases), relative.as_posix())
    return entries


# ---------------------------------------------------------------------------------------------- tables

def _rate(entries: list[SuiteEntry]) -> float | None:
    return sum(entry.summary.success for entry in entries) / len(entries) if entries else None


def _pct(value: float | None) -> str:
    return "" if value is None else f"{100 * value:.0f} %"


def _cell(entries: list[SuiteEntry]) -> str:
    if not entries:
        return ""
    summary = entries[0].summary
    mark = "**hit**" if summary.success else "-"
    flags = ("D" if summary.lane_departure else "") + ("X" if summary.off_road else "")
    return f"{mark} {summary.max_abs_deviation:.2f}{' ' + flags if flags else ''}"


def asr_by_category(entries: list[SuiteEntry]) -> dict[str, dict[int, float | None]]:
    """category (and ``all``) -> level -> ASR over that level's cases."""
    table = {}
    illusion_entries = [entry for entry in entries if entry.category != CLEAN]
    for category in (*CATEGORIES, "all"):
        group = [entry for entry in illusion_entries if category in ("all", entry.category)]
        if group:
            table[category] = {level: _rate([e for e in group if e.level == level]) for level in LEVELS}
    return table


def markdown(entries: list[SuiteEntry], settings: DriveSettings) -> str:
    """The suite's tables: ASR per category and level, every type's drives, the clean road types."""
    width, height = settings.size
    lines = [f"# Closed-loop suite: {settings.detector} + {settings.controller}, {width}x{height}", "",
             "ASR = share of drives whose |lateral deviation| exceeded 0.285 m within 2.5 s of the illusion "
             "coming into view (originals: from the start). " + PAPER_NOTE, "",
             "## ASR per category and level", "",
             "| category | original | L1 | L2 | L3 | L4 | L5 | L1-5 | paper |",
             "|---|---|---|---|---|---|---|---|---|"]
    illusion_entries = [entry for entry in entries if entry.category != CLEAN]
    for category, rates in asr_by_category(entries).items():
        group = [e for e in illusion_entries if category in ("all", e.category) and e.level > 0]
        cells = [_pct(rates[level]) for level in LEVELS]
        lines.append(f"| {category} | {' | '.join(cells)} | {_pct(_rate(group))} | {PAPER_ASR.get(category, '')} |")
    lines += ["", "## Every drive: success and max |deviation| (m); D = lane departure, X = off the road", "",
              "| category | type | original | L1 | L2 | L3 | L4 | L5 | ASR L1-5 |",
              "|---|---|---|---|---|---|---|---|---|"]
    order = [*CATEGORIES, MIXED_CATEGORY]  # mixed cases after every category, their types by name
    types = sorted({(e.category, e.type) for e in illusion_entries},
                   key=lambda key: (order.index(key[0]), list(REGISTRY).index(key[1]) if key[1] in REGISTRY else 0,
                                    key[1]))
    for category, type_name in types:
        group = [e for e in illusion_entries if e.type == type_name]
        cells = [_cell([e for e in group if e.level == level]) for level in LEVELS]
        lines.append(f"| {category} | {type_name} | {' | '.join(cells)} | "
                     f"{_pct(_rate([e for e in group if e.level > 0]))} |")
    clean = [entry for entry in entries if entry.category == CLEAN]
    if clean:
        lines += ["", "## Clean road types", "", "| case | road | max dev (m) | departure | off road | accuracy |",
                  "|---|---|---|---|---|---|"]
        for entry in clean:
            s = entry.summary
            departed, left_road = "yes" if s.lane_departure else "", "yes" if s.off_road else ""
            lines.append(f"| {entry.path} | {entry.type} | {s.max_abs_deviation:.3f} | {departed} | {left_road} | "
                         f"{s.mean_accuracy:.2f} |")
    departures = sum(entry.summary.lane_departure for entry in entries)
    off_road = sum(entry.summary.off_road for entry in entries)
    speeds = [entry.summary.steps_per_second for entry in entries if entry.summary.steps_per_second]
    speed = f", {sum(speeds) / len(speeds):.1f} steps/s" if speeds else ""
    lines += ["", f"{len(entries)} drives, {departures} lane departures, {off_road} off the road{speed}.", ""]
    return "\n".join(lines)


def suite_csv(entries: list[SuiteEntry]) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["path", "category", "type", "level", "success", "t_view", "t_exceed", "max_abs_deviation",
                     "lane_departure", "off_road", "mean_accuracy", "ended"])
    for entry in entries:
        s = entry.summary
        writer.writerow([entry.path, entry.category, entry.type, entry.level, int(s.success), s.t_view, s.t_exceed,
                         f"{s.max_abs_deviation:.4f}", int(s.lane_departure), int(s.off_road),
                         f"{s.mean_accuracy:.4f}", s.ended])
    return buffer.getvalue()


def suite_json(entries: list[SuiteEntry], settings: DriveSettings) -> str:
    data = {"detector": settings.detector, "controller": settings.controller, "size": list(settings.size),
            "asr": {category: {str(level): rate for level, rate in rates.items()}
                    for category, rates in asr_by_category(entries).items()},
            "drives": [{"path": e.path, "category": e.category, "type": e.type, "level": e.level,
                        **e.summary.as_dict()} for e in entries]}
    return json.dumps(data, indent=2) + "\n"


def write_suite(entries: list[SuiteEntry], settings: DriveSettings, out_dir: str | Path) -> list[Path]:
    """``suite.md``, ``suite.csv`` and ``suite.json`` in ``out_dir``."""
    out_dir = Path(out_dir)
    files = {"suite.md": markdown(entries, settings), "suite.csv": suite_csv(entries),
             "suite.json": suite_json(entries, settings)}
    for name, text in files.items():
        write_atomic(out_dir / name, text.encode("utf-8"))
    return [out_dir / name for name in files]
