"""The library installs alone: importing every ``lanevil_core`` module pulls in no package of an extra.

Each check runs in a fresh interpreter, so what the test session already imported (the web app's fixtures,
torch for the learned detectors) does not hide a module-level import.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
WEB_AND_DASK = ("fastapi", "starlette", "uvicorn", "viser", "pydantic_settings", "fastapi_offline", "multipart", "dask",
                "distributed")
LAZY = ("matplotlib", "torch")  # imported inside the functions that need them, never at module level
NEEDS_TORCH = "lanevil_core.learn"  # the training package needs torch by design

_IMPORT_ALL = """
import importlib, json, pkgutil, sys
import lanevil_core

skip = sys.argv[1]
names = sorted(info.name for info in pkgutil.walk_packages(lanevil_core.__path__, "lanevil_core.")
               if not info.name.endswith(".__main__"))  # running a command is not importing it
for name in names:
    if not (skip and (name == skip or name.startswith(skip + "."))):
        importlib.import_module(name)
print(json.dumps({"modules": names, "loaded": sorted(name.split(".")[0] for name in sys.modules)}))
"""


def _import_all(skip: str = "") -> dict[str, list[str]]:
    """Import every ``lanevil_core`` module (but ``skip`` and its submodules) in a new interpreter."""
    result = subprocess.run([sys.executable, "-c", _IMPORT_ALL, skip], capture_output=True, text=True, check=True,
                            cwd=ROOT)
    return json.loads(result.stdout)


def test_every_module_imports_without_web_or_dask() -> None:
    result = _import_all()
    assert "lanevil_core.cli" in result["modules"] and "lanevil_core.render.renderer" in result["modules"]
    assert [name for name in WEB_AND_DASK if name in result["loaded"]] == []


def test_plots_and_torch_load_only_when_used() -> None:
    result = _import_all(skip=NEEDS_TORCH)
    assert [name for name in WEB_AND_DASK + LAZY if name in result["loaded"]] == []


def test_serve_without_the_web_extra_says_what_to_install() -> None:
    code = ("import sys\n"
            "for name in ('fastapi', 'uvicorn', 'viser', 'pydantic_settings'):\n"
            "    sys.modules[name] = None  # as if not installed\n"
            "from app.cli import main\n"
            "sys.exit(main(['serve', '--no-editor']))\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert result.returncode == 2, result.stderr
    assert "needs the web extra" in result.stderr and "pip install 'lanevil[web]'" in result.stderr
