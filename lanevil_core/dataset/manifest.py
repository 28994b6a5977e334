"""``manifest.json``: what was rendered, from what, with which software, and the hash of every written frame.

The manifest holds no timestamps or run settings that do not change the files (workers, scheduler), so two runs
of the same plan write the same bytes. ``frame_key`` is the identity of one frame's output: a frame on disk is
kept on a rerun only when its sidecar carries the same key and the file still has the recorded sha256.
"""

from __future__ import annotations

import ast
import hashlib
import importlib.metadata
import json
import platform
import zlib
from pathlib import Path
from typing import Any

import numba
import numpy as np
import PIL

from ..library.benchmark_layout import frame_file
from .plan import SPLIT_LABELS, DatasetPlan, PlannedCase, Settings

MANIFEST_FILE = "manifest.json"
MANIFEST_VERSION = 1
_PACKAGE = Path(__file__).resolve().parents[1]
_WORKER = Path(__file__).resolve().with_name("worker.py")


def _module_file(package_dir: Path, dotted: str) -> Path | None:
    """The file of a module named relative to the package root (``render.packed``), or None."""
    base = package_dir.joinpath(*dotted.split(".")) if dotted else package_dir
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _relative_imports(path: Path, package_dir: Path) -> set[Path]:
    """Files of the package imported by ``path`` through relative imports (``from .x import y``)."""
    here = path.parent.relative_to(package_dir).parts  # modules and packages both resolve against their folder
    found: set[Path] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not isinstance(node, ast.ImportFrom) or node.level == 0:
            continue
        parts = list(here[: len(here) - (node.level - 1)]) + (node.module.split(".") if node.module else [])
        names = [".".join(parts)] + [".".join(parts + [alias.name]) for alias in node.names]
        found.update(file for name in names if (file := _module_file(package_dir, name)) is not None)
    return found


def source_files(start: Path = _WORKER, package_dir: Path = _PACKAGE) -> list[Path]:
    """Every module of ``lanevil_core`` that ``start`` reaches through relative imports (itself included)."""
    seen: set[Path] = set()
    todo = [start]
    while todo:
        path = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        todo.extend(_relative_imports(path, package_dir) - seen)
    return sorted(seen)


def source_digest(package_dir: Path = _PACKAGE) -> str:
    """sha256 over the names and bytes of the modules that render, label and encode a frame."""
    digest = hashlib.sha256()
    for path in source_files(package_dir=package_dir):
        digest.update(path.relative_to(package_dir).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _lanevil_version() -> str:
    try:
        return importlib.metadata.version("lanevil")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


def software_versions() -> dict[str, str]:
    """Versions that decide the bytes of a frame: the package and the digest of its render-path sources (an
    edit that does not bump the version still changes the frames), the array and JIT libraries, the image
    encoder and zlib."""
    return {"lanevil": _lanevil_version(), "renderer_source_sha256": source_digest(),
            "python": platform.python_version(), "numpy": np.__version__, "numba": numba.__version__,
            "pillow": PIL.__version__, "zlib": zlib.ZLIB_RUNTIME_VERSION}


def frame_key(case: PlannedCase, frame_index: int, plan: DatasetPlan, versions: dict[str, str]) -> str:
    """sha256 of everything one frame's file and record depend on (case, frame, size, format, folder, versions)."""
    settings = plan.settings
    identity = {"case_sha256": case.case_sha256, "frame": frame_index, "size": list(settings.size),
                "format": settings.image_format, "folder": f"{case.split}/{case.folder}",
                "extras": case.record_extras(), "versions": versions}
    return hashlib.sha256(json.dumps(identity, sort_keys=True).encode("utf-8")).hexdigest()


def case_entry(case: PlannedCase, plan: DatasetPlan, frame_hashes: dict[int, str]) -> dict[str, Any]:
    """The manifest entry of one case folder."""
    settings = plan.settings
    folder = f"{case.split}/{case.folder}"
    return {
        "split": case.split,
        "case": str(case.folder),
        "folder": folder,
        "case_file": f"{folder}/case.json",
        "labels": f"{folder}/labels.json",
        "case_sha256": case.case_sha256,
        "seed": case.seed,
        "illusion_type": case.illusion_type,
        "category": case.category,
        "type": case.type_folder,
        "severity": case.severity,
        "source": case.source,
        "size": list(settings.size),
        "format": settings.image_format,
        "frames": [
            {"frame": index, "file": f"{folder}/{frame_file(index, settings.suffix)}",
             "sha256": frame_hashes[index]}
            for index in case.frames
        ],
    }


def world_setting(settings: Settings) -> dict[str, str]:
    """``{"world": "train" | "heldout"}`` for a run with ``--vary-world``, else nothing (manifests of runs without
    it stay as they were)."""
    if not settings.vary_world:
        return {}
    return {"world": "heldout" if settings.heldout else "train"}


def build_manifest(plan: DatasetPlan, versions: dict[str, str],
                   frame_hashes: dict[tuple[str, str], dict[int, str]]) -> dict[str, Any]:
    """The whole manifest; ``frame_hashes`` maps (split, folder) -> frame -> sha256 of the written file."""
    settings = plan.settings
    splits = {}
    for split, labels in SPLIT_LABELS.items():
        cases = plan.split_cases(split)
        if cases:
            splits[split] = {"labels": f"{split}/{labels}", "cases": len(cases),
                             "frames": sum(len(case.frames) for case in cases)}
    return {
        "manifest_version": MANIFEST_VERSION,
        "versions": versions,
        "settings": {"size": list(settings.size), "format": settings.image_format,
                     "frames_per_case": settings.frames_per_case, "train_frames": settings.train_frames,
                     "seed": settings.seed, "no_paint": settings.no_paint,
                     "sampling": settings.sampling, **world_setting(settings)},
        "splits": splits,
        "cases": [case_entry(case, plan, frame_hashes[case.key]) for case in plan.cases],
    }


def manifest_bytes(manifest: dict[str, Any]) -> bytes:
    """The manifest as indented JSON text with a trailing newline."""
    return (json.dumps(manifest, indent=2) + "\n").encode("utf-8")
