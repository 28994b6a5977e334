"""The ``lanevil`` command line: render frames, export datasets, benchmark the renderer, and more.

Each module of this package may define a module-level ``COMMANDS`` dict (name -> ``Command``); the modules are found
and their dicts merged at start-up, so a new subcommand is a new file here and needs no edit elsewhere. ``base``
holds what the commands share; ``core`` has ``render``, ``export``, ``preview`` and ``bench``.

User errors (a bad case file, a bad flag value, an output path that is a folder) end with exit status 2 and one
line on stderr, never a traceback. Before a command runs, the temporary files that a killed earlier run left in its
output folders (``--out``, ``--labels``) are removed (``files.remove_stale_temps``).
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from collections.abc import Sequence

from .. import __version__
from ..case import CaseError
from .base import PROG, Command, UsageError, _Parser, remove_leftovers

FIRST = "core"  # its commands lead the help

__all__ = ["Command", "UsageError", "all_commands", "build_parser", "main"]


def all_commands() -> dict[str, Command]:
    """The ``COMMANDS`` of every module of this package: ``core`` first, then the others sorted by module name."""
    names = sorted(info.name for info in pkgutil.iter_modules(__path__) if not info.name.startswith("_"))
    commands: dict[str, Command] = {}
    for name in sorted(names, key=lambda name: name != FIRST):
        module = importlib.import_module(f"{__name__}.{name}")
        commands.update(getattr(module, "COMMANDS", {}))
    return commands


def build_parser(commands: dict[str, Command]) -> argparse.ArgumentParser:
    """The top-level parser with one subparser per command."""
    parser = _Parser(prog=PROG, description="LanEvil Studio: lane-detection robustness cases.")
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, command in commands.items():
        command.add_arguments(sub.add_parser(name, help=command.help, description=command.help))
    return parser


def main(argv: Sequence[str] | None = None, extra_commands: dict[str, Command] | None = None) -> int:
    """Run the command line with ``extra_commands`` added; return the exit status (0 ok, 2 user error)."""
    commands = {**all_commands(), **(extra_commands or {})}
    try:
        args = build_parser(commands).parse_args(argv)
        remove_leftovers(args)
        return commands[args.command].run(args)
    except (UsageError, CaseError) as error:
        print(f"{PROG}: error: {error}", file=sys.stderr)
        return 2
    except (IsADirectoryError, NotADirectoryError) as error:  # an output path that names or crosses a folder
        print(f"{PROG}: error: {error.filename or ''}: {error.strerror or error}", file=sys.stderr)
        return 2
    except OSError as error:  # an unwritable output path, a full disk
        print(f"{PROG}: error: {error.filename or ''}: {error.strerror or error}", file=sys.stderr)
        return 1
