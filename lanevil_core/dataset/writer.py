"""The output folder of a dataset run: frame files, their sidecars, label files and the manifest.

Layout of ``DIR``::

    DIR/test/<Category>/<Type>/<case>/000000.png ...   frames (the case's own frame indices)
    DIR/test/<Category>/<Type>/<case>/labels.json      TuSimple JSON lines, raw_file relative to DIR/test
    DIR/test/<Category>/<Type>/<case>/case.json        the case, canonical JSON
    DIR/test/test_label.json                           every test record, case by case
    DIR/train/<variation>/...                          the same for the train split; DIR/train/train_label.json
    DIR/manifest.json                                  see manifest.py
    DIR/.progress/<split>/<case>/000000.json           per-frame sidecar: key, sha256 and TuSimple record

Every file is written with ``write_atomic`` (temporary file + rename); a frame's sidecar is written after its
image, so a sidecar always describes a complete file.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from ..files import write_atomic
from ..library.benchmark_layout import LABELS_FILE, frame_file
from .manifest import MANIFEST_FILE, manifest_bytes
from .plan import SPLIT_LABELS, PlannedCase
from .worker import FrameResult

PROGRESS_DIR = ".progress"
CASE_FILE = "case.json"


def file_sha256(path: Path) -> str | None:
    """sha256 of a file's bytes, None when it cannot be read."""
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return None


def label_lines(records: list[dict[str, Any]]) -> bytes:
    """TuSimple JSON lines, one record per line."""
    return "".join(json.dumps(record) + "\n" for record in records).encode("utf-8")


class DatasetFolder:
    """Paths and atomic writes under one output folder ``root``."""

    def __init__(self, root: Path, suffix: str) -> None:
        self.root = root
        self.suffix = suffix

    def case_dir(self, case: PlannedCase) -> Path:
        """``root/<split>/<folder>``."""
        return self.root / case.split / case.folder

    def image_path(self, case: PlannedCase, frame_index: int) -> Path:
        """Where a frame's image goes."""
        return self.case_dir(case) / frame_file(frame_index, self.suffix)

    def sidecar_path(self, case: PlannedCase, frame_index: int) -> Path:
        """Where a frame's sidecar goes."""
        return self.root / PROGRESS_DIR / case.split / case.folder / frame_file(frame_index, ".json")

    def verified(self, case: PlannedCase, frame_index: int, key: str) -> dict[str, Any] | None:
        """The sidecar of a frame already on disk with this ``key`` and an intact file, else None."""
        try:
            sidecar = json.loads(self.sidecar_path(case, frame_index).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None
        if not isinstance(sidecar, dict) or sidecar.get("key") != key:
            return None
        if file_sha256(self.image_path(case, frame_index)) != sidecar.get("sha256"):
            return None
        return sidecar

    def remove_partial(self, case: PlannedCase) -> list[Path]:
        """Delete temporary files an interrupted ``write_atomic`` left in the case folder; return them."""
        folder = self.case_dir(case)
        if not folder.is_dir():
            return []
        partial = [path for path in folder.glob(".*") if path.is_file()]
        for path in partial:
            path.unlink(missing_ok=True)
        return partial

    def write_frame(self, case: PlannedCase, result: FrameResult, key: str) -> dict[str, Any]:
        """Write a rendered frame, then its sidecar; return the sidecar."""
        write_atomic(self.image_path(case, result.frame), result.data)
        sidecar = {"key": key, "sha256": result.sha256, "record": result.record}
        write_atomic(self.sidecar_path(case, result.frame), json.dumps(sidecar).encode("utf-8"))
        return sidecar

    def write_case_files(self, case: PlannedCase, records: list[dict[str, Any]]) -> None:
        """The case's ``case.json`` and ``labels.json``."""
        write_atomic(self.case_dir(case) / CASE_FILE, case.case_text.encode("utf-8"))
        write_atomic(self.case_dir(case) / LABELS_FILE, label_lines(records))

    def write_split_labels(self, split: str, records: list[dict[str, Any]]) -> Path:
        """``root/<split>/<split>_label.json`` with every record of the split."""
        path = self.root / split / SPLIT_LABELS[split]
        write_atomic(path, label_lines(records))
        return path

    def write_manifest(self, manifest: dict[str, Any]) -> Path:
        """``root/manifest.json``."""
        path = self.root / MANIFEST_FILE
        write_atomic(path, manifest_bytes(manifest))
        return path
