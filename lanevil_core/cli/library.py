"""``lanevil illusions``, ``lanevil sheet`` and ``lanevil library``: the illusion registry and the stock cases."""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path
from typing import Any

from ..case import write_atomic
from ..illusions import REGISTRY, Illusion
from .base import Command, UsageError, parse_size


def illusion_info(cls: type[Illusion]) -> dict[str, Any]:
    """Name, category, tunable parameters (with ranges and defaults) and the severity table of one type."""
    schema = cls.model_json_schema()
    parameters = {}
    for field, spec in schema.get("properties", {}).items():
        if field == "type":
            continue
        keys = ("type", "anyOf", "enum", "default", "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum",
                "description")
        parameters[field] = {key: spec[key] for key in keys if key in spec}
    return {"name": cls.model_fields["type"].default, "category": cls.CATEGORY,
            "description": " ".join((cls.__doc__ or "").strip().split("\n\n")[0].split()), "parameters": parameters,
            "severity": [dataclasses.asdict(row) for row in cls.SEVERITY], "sun": sun_control(cls)}


def sun_control(cls: type[Illusion]) -> str:
    """How a type's sun relates to the case's: ``case`` (it leaves the sun alone), ``overrides`` (it places the
    sun itself, and its ``sun_*`` fields, which sun sliders set, move it) or ``table`` (its severity table places
    the sun; no slider moves it)."""
    if not cls.SETS_SUN:
        return "case"
    return "overrides" if all(f"sun_{name}" in cls.model_fields for name in ("azimuth", "altitude")) else "table"


def _range(spec: dict[str, Any]) -> str:
    for option in spec.get("anyOf", []):  # optional fields: the range of the non-null choice
        if option.get("type") != "null":
            spec = option
    lo = spec.get("minimum", spec.get("exclusiveMinimum"))
    hi = spec.get("maximum", spec.get("exclusiveMaximum"))
    if "enum" in spec:
        return "|".join(map(str, spec["enum"]))
    return f"{lo}..{hi}" if lo is not None or hi is not None else ""


def _format(infos: list[dict[str, Any]]) -> str:
    lines = []
    for info in infos:
        lines.append(f"{info['name']}  [{info['category']}]  {info['description']}")
        params = ", ".join(f"{name}={spec.get('default')!r} ({_range(spec)})".replace(" ()", "")
                           for name, spec in info["parameters"].items())
        lines.append(f"  parameters: {params}")
        for level, row in enumerate(info["severity"], start=1):
            lines.append(f"  level {level}: " + ", ".join(f"{k}={v}" for k, v in row.items()))
    return "\n".join(lines)


def _illusions_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print the registry as JSON")


def _run_illusions(args: argparse.Namespace) -> int:
    infos = [illusion_info(cls) for cls in REGISTRY.values()]
    print(json.dumps(infos, indent=2) if args.json else _format(infos))
    return 0


def _sheet_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, required=True, help="output image (PNG)")
    parser.add_argument("--size", type=parse_size, default=(320, 180), help="cell size WIDTHxHEIGHT (default 320x180)")
    parser.add_argument("--frame", type=int, default=0, help="frame of every case (default 0)")
    parser.add_argument("--types", default=None, help="comma-separated illusion types (default: all 14)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def _run_sheet(args: argparse.Namespace) -> int:
    from ..dataset.progress import progress_bar
    from ..export.encode import png_bytes
    from ..report.sheet import contact_sheet, sheet_frames

    types = None
    if args.types:
        types = [name.strip() for name in args.types.split(",") if name.strip()]
        unknown = [name for name in types if name not in REGISTRY]
        if unknown:
            raise UsageError(f"--types: unknown illusion type {unknown[0]!r}; see 'lanevil illusions'")
    if not 0 <= args.frame < 50:
        raise UsageError("--frame must lie in 0..49 (every stock case has at least 50 frames)")
    with progress_bar(sheet_frames(types), 0, not args.quiet) as bar:
        rgb = contact_sheet(args.size, args.frame, types, on_frame=bar.update)
    write_atomic(args.out, png_bytes(rgb))
    print(args.out)
    return 0


def _library_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, default=Path("scenes"), help="folder to write into (default scenes)")


def _run_library(args: argparse.Namespace) -> int:
    from ..library.stock import write_library

    written = write_library(args.out)
    print(f"{len(written)} cases in {args.out}")
    return 0


def _schema_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, default=None, help="write to this file (default: print)")


def _run_schema(args: argparse.Namespace) -> int:
    from ..case import case_schema

    text = json.dumps(case_schema(), indent=2, sort_keys=True) + "\n"
    if args.out is None:
        print(text, end="")
    else:
        write_atomic(args.out, text.encode("utf-8"))
        print(args.out)
    return 0


COMMANDS: dict[str, Command] = {
    "schema": Command("print the JSON schema of case files (illusions: a discriminated union on type)",
                      _schema_arguments, _run_schema),
    "illusions": Command("list the illusion registry with parameters and severity tables", _illusions_arguments,
                         _run_illusions),
    "sheet": Command("render a contact sheet: one row per illusion, original and levels 1-5", _sheet_arguments,
                     _run_sheet),
    "library": Command("write the stock case library (clean cases and every illusion at levels 1-5)",
                       _library_arguments, _run_library),
}
