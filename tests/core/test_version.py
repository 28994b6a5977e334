"""One version: ``pyproject.toml`` -> the installed package's metadata -> ``lanevil_core.__version__``, which
``lanevil --version`` prints and the web app's OpenAPI document carries."""

from __future__ import annotations

import importlib.metadata
import tomllib
from pathlib import Path

import pytest

import lanevil_core
from lanevil_core.cli import main

PYPROJECT = Path(__file__).resolve().parents[2] / "pyproject.toml"


def test_the_version_comes_from_the_package_metadata() -> None:
    declared = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["project"]["version"]
    assert importlib.metadata.version("lanevil") == declared, "reinstall the package: its metadata is stale"
    assert lanevil_core.__version__ == declared


def test_lanevil_version_prints_it(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out == f"lanevil {lanevil_core.__version__}\n"


def test_no_second_version_literal_in_the_sources() -> None:
    """The version is written once, in pyproject.toml; the code reads it from the package metadata."""
    literal = f'"{lanevil_core.__version__}"'
    root = PYPROJECT.parent
    holders = [path.relative_to(root).as_posix() for folder in ("lanevil_core", "app")
               for path in sorted((root / folder).rglob("*.py")) if literal in path.read_text(encoding="utf-8")]
    assert holders == []


def test_the_web_app_reports_it(tmp_path: Path) -> None:
    pytest.importorskip("fastapi")
    from app.main import create_app
    from app.settings import Settings

    app = create_app(Settings(data_dir=tmp_path / "data", scenes_dir=tmp_path / "no-scenes", editor=False))
    assert app.version == lanevil_core.__version__
