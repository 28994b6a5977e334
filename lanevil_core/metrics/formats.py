"""Reading and validating lane files: TuSimple JSON lines and CULane ``.lines.txt`` folders.

Every problem raises ``LaneFileError`` whose message names the file and, where there is one, the line, so a
command line can print it as one line. Validation follows what the official TuSimple script needs
(``raw_file``, ``lanes``, ``h_samples`` in ground truth; ``raw_file``, ``lanes``, ``run_time`` in predictions)
and adds the checks it leaves to a crash (types, lane lengths, duplicates).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

Role = Literal["gt", "pred"]
CULANE_SUFFIX = ".lines.txt"


class LaneFileError(ValueError):
    """A lane file that cannot be scored; the message names the file (and line)."""


@dataclass(frozen=True)
class LaneRecord:
    """One image of a TuSimple file.

    Attributes:
        raw_file: image path as written in the file.
        lanes: x per h_sample for each lane (negative = no point), as read.
        h_samples: the rows (GT; a prediction may omit them: then empty).
        run_time: milliseconds (predictions; None in ground truth).
        line: 1-based line number in its file.
        extra: every other field of the record (category, type, severity, case, ...).
    """

    raw_file: str
    lanes: list[list[float]]
    h_samples: list[float]
    run_time: float | None
    line: int
    extra: dict[str, Any]


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _number_list(value: Any, where: str, what: str) -> list[float]:
    if not isinstance(value, list) or not all(_is_number(item) for item in value):
        raise LaneFileError(f"{where}: {what} must be a list of numbers")
    return list(value)


def parse_tusimple_line(text: str, where: str, role: Role, line: int) -> LaneRecord:
    """One JSON line -> ``LaneRecord``; ``where`` (``file:line``) prefixes every error."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as error:
        raise LaneFileError(f"{where}: invalid JSON ({error.msg} at column {error.colno})") from None
    if not isinstance(data, dict):
        raise LaneFileError(f"{where}: expected a JSON object")
    required = ("raw_file", "lanes", "h_samples") if role == "gt" else ("raw_file", "lanes")
    for key in required:
        if key not in data:
            raise LaneFileError(f"{where}: missing {key}")
    if not isinstance(data["raw_file"], str) or not data["raw_file"]:
        raise LaneFileError(f"{where}: raw_file must be a non-empty string")
    if not isinstance(data["lanes"], list):
        raise LaneFileError(f"{where}: lanes must be a list of lanes")
    lanes = [_number_list(lane, where, f"lanes[{i}]") for i, lane in enumerate(data["lanes"])]
    h_samples = _number_list(data.get("h_samples", []), where, "h_samples")
    run_time = data.get("run_time")
    if run_time is not None and not _is_number(run_time):
        raise LaneFileError(f"{where}: run_time must be a number (ms)")
    extra = {key: value for key, value in data.items() if key not in ("raw_file", "lanes", "h_samples", "run_time")}
    return LaneRecord(data["raw_file"], lanes, h_samples, None if run_time is None else float(run_time), line, extra)


def read_tusimple(path: str | Path, role: Role) -> list[LaneRecord]:
    """Every record of a TuSimple JSON-lines file (blank lines skipped); duplicate ``raw_file`` is an error."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise LaneFileError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as error:
        raise LaneFileError(f"{path}: cannot read ({error})") from None
    records: list[LaneRecord] = []
    first_line: dict[str, int] = {}
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        record = parse_tusimple_line(line, f"{path}:{number}", role, number)
        if record.raw_file in first_line:
            raise LaneFileError(f"{path}:{number}: duplicate raw_file {record.raw_file!r} "
                                f"(first at line {first_line[record.raw_file]})")
        first_line[record.raw_file] = number
        if role == "gt":
            _check_gt_lanes(record, f"{path}:{number}")
        records.append(record)
    if not records:
        raise LaneFileError(f"{path}: no records")
    return records


def _check_gt_lanes(record: LaneRecord, where: str) -> None:
    for i, lane in enumerate(record.lanes):
        if len(lane) != len(record.h_samples):
            raise LaneFileError(f"{where}: lanes[{i}] has {len(lane)} points but h_samples has "
                                f"{len(record.h_samples)}")


def pair_records(gt: list[LaneRecord], pred: list[LaneRecord], gt_name: str, pred_name: str,
                 require_run_time: bool = True) -> list[tuple[LaneRecord, LaneRecord]]:
    """(gt, pred) per GT image, in GT order, after the official script's checks.

    Raises ``LaneFileError`` for a prediction without ``run_time`` (when ``require_run_time``: the TuSimple
    metric needs it), a prediction of an image not in the ground truth, a GT image without a prediction (the
    official script refuses a submission that does not cover every test image), h_samples that differ from the
    GT's, and a lane whose length differs from the GT's h_samples.
    """
    by_file = {record.raw_file: record for record in gt}
    for record in pred:
        where = f"{pred_name}:{record.line}"
        if require_run_time and record.run_time is None:
            raise LaneFileError(f"{where}: missing run_time")
        target = by_file.get(record.raw_file)
        if target is None:
            raise LaneFileError(f"{where}: raw_file {record.raw_file!r} is not in the ground truth {gt_name}")
        if record.h_samples and record.h_samples != target.h_samples:
            raise LaneFileError(f"{where}: h_samples mismatch with {gt_name}:{target.line}")
        for i, lane in enumerate(record.lanes):
            if len(lane) != len(target.h_samples):
                raise LaneFileError(f"{where}: lanes[{i}] has {len(lane)} points but the ground truth has "
                                    f"{len(target.h_samples)} h_samples")
    predicted = {record.raw_file: record for record in pred}
    missing = [record for record in gt if record.raw_file not in predicted]
    if missing:
        raise LaneFileError(f"{gt_name}:{missing[0].line}: no prediction for raw_file {missing[0].raw_file!r} "
                            f"in {pred_name} ({len(missing)} image(s) without prediction)")
    return [(record, predicted[record.raw_file]) for record in gt]


# ---------------------------------------------------------------------------------------------- CULane

Points = list[tuple[float, float]]


def parse_culane_text(text: str, where: str) -> list[Points]:
    """``x1 y1 x2 y2 ...`` per line -> lanes of (x, y); lanes with fewer than two points are dropped (official)."""
    lanes: list[Points] = []
    for number, line in enumerate(text.splitlines(), start=1):
        fields = line.split()
        if not fields:
            continue
        try:
            values = [float(field) for field in fields]
        except ValueError:
            raise LaneFileError(f"{where}:{number}: not a list of numbers") from None
        if len(values) % 2 or not all(math.isfinite(value) for value in values):
            raise LaneFileError(f"{where}:{number}: expected finite x y pairs, got {len(values)} numbers")
        points = [(values[i], values[i + 1]) for i in range(0, len(values), 2)]
        if len(points) >= 2:
            lanes.append(points)
    return lanes


def culane_files(root: str | Path) -> list[str]:
    """Relative POSIX paths of every ``*.lines.txt`` under ``root``, sorted."""
    root = Path(root)
    if not root.is_dir():
        raise LaneFileError(f"{root}: not a folder of {CULANE_SUFFIX} files")
    return sorted(path.relative_to(root).as_posix() for path in root.rglob(f"*{CULANE_SUFFIX}"))


def read_culane_file(path: Path) -> list[Points]:
    """Lanes of one ``.lines.txt`` file."""
    try:
        return parse_culane_text(path.read_text(encoding="utf-8"), str(path))
    except (OSError, UnicodeDecodeError) as error:
        raise LaneFileError(f"{path}: cannot read ({error})") from None


def tusimple_points(lane: list[float], h_samples: list[float]) -> Points:
    """A TuSimple lane as (x, y) points, top to bottom as written, skipping missing (negative) x."""
    return [(float(x), float(y)) for x, y in zip(lane, h_samples) if x >= 0]


LABEL_SUFFIX = "_label.json"
DATASET_SPLIT = "test"  # the split a dataset folder (written by ``lanevil dataset``) stands for


def resolve_split(path: str | Path) -> tuple[Path, str | None]:
    """(split folder, note): ``path``, or its ``test`` split when ``path`` is a dataset folder (no label file of
    its own, a ``test/``); a dataset folder with no ``test/`` but one other split (``lanevil dataset`` with only
    ``--train-frames``) falls back to that split, and the note says so (None when nothing was substituted)."""
    path = Path(path)
    if not path.is_dir() or any(path.glob(f"*{LABEL_SUFFIX}")):
        return path, None
    if (path / DATASET_SPLIT).is_dir():
        return path / DATASET_SPLIT, None
    splits = sorted(child for child in path.iterdir() if child.is_dir() and any(child.glob(f"*{LABEL_SUFFIX}")))
    if len(splits) == 1:
        return splits[0], f"{path} has no {DATASET_SPLIT}/ split: using its {splits[0].name}/ split"
    return path, None


def split_folder(path: str | Path) -> Path:
    """``path``, or the split a dataset folder stands for (``resolve_split``)."""
    return resolve_split(path)[0]


def split_note(path: str | Path) -> str | None:
    """What ``resolve_split`` substituted for ``path``, if anything (printed by the commands before they run)."""
    return resolve_split(path)[1]


def split_labels(split_dir: str | Path) -> Path:
    """The TuSimple label file of a split folder: ``<split>/<split name>_label.json`` or its only ``*_label.json``;
    a dataset folder stands for its ``test`` split."""
    split_dir = split_folder(split_dir)
    if not split_dir.is_dir():
        raise LaneFileError(f"{split_dir}: not a split folder")
    named = split_dir / f"{split_dir.name}{LABEL_SUFFIX}"
    if named.is_file():
        return named
    found = sorted(split_dir.glob(f"*{LABEL_SUFFIX}"))
    if len(found) != 1:
        raise LaneFileError(f"{split_dir}: expected one *{LABEL_SUFFIX} file, found {len(found)}; give a split "
                            f"folder (e.g. DATASET/{DATASET_SPLIT}) or a dataset folder with a {DATASET_SPLIT}/ split")
    return found[0]
