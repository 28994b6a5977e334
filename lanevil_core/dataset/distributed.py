"""Run render tasks on a Dask distributed cluster (``dask scheduler`` + ``dask worker`` processes).

Each task is one ``client.submit(render_chunk, task)``; results (encoded frames and records) come back to the
calling process, which writes every file, so workers need the package installed but no shared file system.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from .plan import RenderTask
from .worker import TaskDone, render_chunk

SCHEDULER_PATTERN = re.compile(r"^tcp://(?P<host>[A-Za-z0-9.\-]+|\[[0-9A-Fa-f:]+\]):(?P<port>\d{1,5})$")
CONNECT_TIMEOUT_S = 10.0


class SchedulerError(ValueError):
    """A scheduler address that is malformed or cannot be reached (a one-line message)."""


def check_scheduler_address(address: str) -> str:
    """``tcp://HOST:PORT`` with a port in 1..65535, else SchedulerError."""
    match = SCHEDULER_PATTERN.match(address.strip())
    if match is None or not 1 <= int(match.group("port")) <= 65535:
        raise SchedulerError(f"--scheduler {address!r} is not tcp://HOST:PORT (e.g. tcp://127.0.0.1:8786)")
    return address.strip()


def run_dask(tasks: Sequence[RenderTask], on_done: TaskDone, address: str,
             timeout_s: float = CONNECT_TIMEOUT_S) -> None:
    """Render ``tasks`` on the cluster at ``address``, calling ``on_done(task, results)`` as each one finishes."""
    from dask.distributed import Client, as_completed

    check_scheduler_address(address)
    try:
        client = Client(address, timeout=timeout_s, set_as_default=False)
    except (OSError, TimeoutError) as error:
        raise SchedulerError(f"--scheduler {address}: cannot reach the Dask scheduler ({error})") from None
    with client, client.as_current():
        futures = [client.submit(render_chunk, task, pure=False) for task in tasks]
        by_key = {future.key: task for future, task in zip(futures, tasks)}
        try:
            for future in as_completed(futures):
                on_done(by_key[future.key], future.result())
                future.release()
        except BaseException:
            client.cancel(futures)
            raise
