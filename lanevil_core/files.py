"""Atomic file writes, and the removal of what a killed write leaves behind.

``write_atomic`` writes to a temporary file beside the target and renames it into place, so a reader never sees
half a file. The temporary file is named ``.<target name>.<pid>.<random>.tmp``: if the process is killed between
the two steps the file stays, and ``remove_stale_temps`` (run when a command or the server starts) removes those
whose process is gone. Files of a process that still runs are never touched, so two writers may share a folder.
"""

from __future__ import annotations

import errno
import json
import os
import re
import tempfile
from pathlib import Path
from typing import Any

TEMP_SUFFIX = ".tmp"
# .<target name>.<pid>.<mkstemp's random part>.tmp
TEMP_NAME = re.compile(r"^\.(?P<target>.+)\.(?P<pid>\d+)\.[A-Za-z0-9_]+\.tmp$")
SKIPPED_FOLDERS = frozenset({".git", ".venv", "node_modules", "__pycache__"})


def write_atomic(path: Path, data: bytes, mode: int | None = None, replace: bool = True) -> None:
    """Write bytes to ``path`` via a temporary file in the same folder and an atomic rename.

    ``mode``: the file's permissions (default: 0666 less the umask, as ``open`` gives). ``replace=False`` links the
    file into place instead, so an existing ``path`` stays as it is and ``FileExistsError`` is raised (of two
    processes creating the same file, one wins and the other reads what it wrote).
    An ``OSError`` names ``path`` (what the caller asked for), never the temporary file."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}.", suffix=TEMP_SUFFIX, dir=path.parent)
    except FileExistsError:  # a part of the folder path is a file
        raise NotADirectoryError(errno.ENOTDIR, os.strerror(errno.ENOTDIR), str(path)) from None
    except OSError as error:
        raise OSError(error.errno, error.strerror, str(path)) from None
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, 0o666 & ~_umask() if mode is None else mode)  # mkstemp creates 0600
        if replace:
            os.replace(tmp, path)
        else:
            os.link(tmp, path)
            os.unlink(tmp)
    except BaseException as error:
        Path(tmp).unlink(missing_ok=True)
        if isinstance(error, FileExistsError):
            raise FileExistsError(error.errno, error.strerror, str(path)) from None
        if isinstance(error, OSError):
            raise OSError(error.errno, error.strerror, str(path)) from None
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def process_alive(pid: int) -> bool:
    """Whether a process with this id runs on this machine (one of another user counts as running)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except OSError:  # e.g. a pid too large for the platform
        return False
    return True


def stale_temp(path: Path) -> bool:
    """Whether ``path`` is a temporary file of ``write_atomic`` whose writing process is gone."""
    match = TEMP_NAME.match(path.name)
    return match is not None and not process_alive(int(match["pid"]))


def remove_stale_temps(folder: Path, recursive: bool = False) -> list[Path]:
    """Delete the temporary files that killed ``write_atomic`` calls left in ``folder`` (and its subfolders, but
    not hidden or tool folders such as ``.git``); return what was deleted. A missing folder has none."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    removed = []
    for root, folders, names in os.walk(folder):
        folders[:] = [] if not recursive else [name for name in folders if name not in SKIPPED_FOLDERS
                                               and not name.startswith(".")]
        for name in names:
            path = Path(root) / name
            if stale_temp(path):
                path.unlink(missing_ok=True)
                removed.append(path)
    return removed


def read_json(path: Path, where: str, error: type[Exception] = ValueError) -> Any:
    """The JSON value of the file ``path``; ``error`` says in one line, after ``where``, why it cannot be read."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except OSError as failure:
        raise error(f"{where}: cannot read it ({failure.strerror})") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as failure:
        raise error(f"{where}: not JSON ({failure})") from None
