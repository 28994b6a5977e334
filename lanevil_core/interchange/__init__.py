"""Scenario interchange: a case's road as OpenDRIVE (``road.xodr``) and its drive as OpenSCENARIO
(``scenario.xosc``), for CARLA and other simulators. Both writers need the ``scenariogeneration`` package, imported
only when they run. See docs/interchange.md."""

from __future__ import annotations

from pathlib import Path

from ..case import Case, case_json
from ..files import write_atomic

XODR_FILE = "road.xodr"
XOSC_FILE = "scenario.xosc"
CASE_FILE = "case.json"


def write_interchange(case: Case, out_dir: str | Path, opendrive: bool = True,
                      openscenario: bool = False) -> list[Path]:
    """Write ``road.xodr`` (with ``opendrive`` or ``openscenario``: the scenario refers to it) and, with
    ``openscenario``, ``scenario.xosc`` into ``out_dir``, plus the case itself (``case.json``, whose weather numbers
    ``scripts/carla_run.py`` applies); returns the interchange files written."""
    from ..pipeline.compile import compile_scene
    from .opendrive import write_opendrive
    from .openscenario import write_openscenario

    scene = compile_scene(case)
    written = []
    if opendrive or openscenario:
        written.append(write_opendrive(case, out_dir, scene))
    if openscenario:
        written.append(write_openscenario(case, out_dir, scene))
    write_atomic(Path(out_dir) / CASE_FILE, case_json(case).encode("utf-8"))
    return written


__all__ = ["CASE_FILE", "XODR_FILE", "XOSC_FILE", "write_interchange"]
