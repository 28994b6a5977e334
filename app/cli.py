"""The ``lanevil`` command: every ``lanevil_core`` subcommand plus ``serve`` (the web backend and editor)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from lanevil_core import cli as core_cli
from lanevil_core.cli import Command, UsageError
from lanevil_core.cli.base import bounded

# 0 = any free port
_port = bounded(int, "a port number", 0, 65535, " (0 = any free port)")


def _serve_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--host", default=None, help="address to bind (default 127.0.0.1)")
    parser.add_argument("--port", type=_port, default=None, help="port of the website and API (default 8000)")
    parser.add_argument("--editor-port", type=_port, default=None, help="port of the viser editor (default 8080)")
    parser.add_argument("--data", type=Path, default=None, help="data folder: cases, exports, study (default ./data)")
    parser.add_argument("--scenes", type=Path, default=None, help="cases that seed an empty store (default scenes/)")
    parser.add_argument("--no-editor", action="store_true", help="serve the API and website only")


def _run_serve(args: argparse.Namespace) -> int:
    from pydantic import ValidationError

    try:
        from .server import ListenError, serve
        from .settings import Settings
    except ImportError as error:  # the library installed without the web extra
        raise UsageError(f"serve needs the web extra ({error.name} is missing): pip install 'lanevil[web]'") from None

    given = {"host": args.host, "port": args.port, "editor_port": args.editor_port, "data_dir": args.data,
             "scenes_dir": args.scenes}
    overrides = {name: value for name, value in given.items() if value is not None}
    if args.no_editor:
        overrides["editor"] = False
    try:
        settings = Settings(**overrides)
    except ValidationError as error:
        first = error.errors()[0]
        raise UsageError(f"{'.'.join(str(part) for part in first['loc'])}: {first['msg']}") from None
    if settings.data_dir.exists() and not settings.data_dir.is_dir():
        raise UsageError(f"--data {settings.data_dir}: not a folder")
    try:
        return serve(settings)
    except ListenError as error:
        raise UsageError(str(error)) from None


COMMANDS: dict[str, Command] = {
    "serve": Command("start the web backend, demo website, study and the viser editor", _serve_arguments,
                     _run_serve),
}


def main(argv: Sequence[str] | None = None) -> int:
    """``lanevil`` with the web commands added."""
    return core_cli.main(argv, extra_commands=COMMANDS)


if __name__ == "__main__":
    sys.exit(main())
