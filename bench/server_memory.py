"""Server memory and frame latency under concurrent clients.

Starts ``python -m app.cli serve --no-editor`` on a free port with a temporary data folder (seeded from
``scenes/``), runs ``--clients`` threads that each fetch distinct frames of distinct cases for ``--seconds``, samples
the server's resident memory (the process and its children) every 0.2 s, and prints the peak RSS and the p50/p95
latency of a frame GET (and how many were answered 503: the render queue was full).

    python bench/server_memory.py [--clients 8] [--seconds 60] [--frame-cache-bytes 0] [--cases road_crack] [--json]

``--cases`` keeps the cases whose id contains that text (``road_crack``: the stock scenes that need the most
memory, 0.2-0.6 GB each once compiled; the worst case for a server).

Extra ``--env NAME=VALUE`` pairs go to the server (e.g. ``--env LANEVIL_MAX_RENDERS=2``).
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def rss_bytes(pid: int) -> int:
    """Resident memory of ``pid`` and its children (psutil if installed, else /proc)."""
    try:
        import psutil

        process = psutil.Process(pid)
        return sum(p.memory_info().rss for p in [process, *process.children(recursive=True)])
    except ImportError:
        total = 0
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                total += int(line.split()[1]) * 1024
        return total


def get(url: str, timeout: float = 120.0) -> tuple[int, bytes]:
    try:
        with urllib.request.urlopen(url, timeout=timeout) as response:
            return response.status, response.read()
    except urllib.error.HTTPError as error:
        return error.code, error.read()


def wait_ready(base: str, process: subprocess.Popen, timeout: float = 180.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if process.poll() is not None:
            raise RuntimeError("the server exited before it was ready")
        try:
            if get(f"{base}/api/cases", timeout=5)[0] == 200:
                return
        except OSError:
            pass
        time.sleep(0.5)
    raise RuntimeError("the server did not answer")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clients", type=int, default=8)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--frame-cache-bytes", type=int, default=0)
    parser.add_argument("--cases", default="", help="only cases whose id contains this text")
    parser.add_argument("--env", action="append", default=[], help="NAME=VALUE for the server")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()

    port = free_port()
    base = f"http://127.0.0.1:{port}"
    with tempfile.TemporaryDirectory(prefix="lanevil-memory-") as data:
        env = {**os.environ, "LANEVIL_FRAME_CACHE_BYTES": str(args.frame_cache_bytes),
               **dict(pair.split("=", 1) for pair in args.env)}
        server = subprocess.Popen([sys.executable, "-m", "app.cli", "serve", "--no-editor", "--port", str(port),
                                   "--data", data, "--scenes", str(REPO / "scenes")], cwd=REPO, env=env,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            wait_ready(base, server)
            idle_rss = rss_bytes(server.pid)
            cases = [row["id"] for row in json.loads(get(f"{base}/api/cases")[1])["data"] if args.cases in row["id"]]
            latencies: list[float] = []
            statuses: dict[int, int] = {}
            peak = [idle_rss]
            stop = threading.Event()
            lock = threading.Lock()

            def sample() -> None:
                while not stop.is_set():
                    peak[0] = max(peak[0], rss_bytes(server.pid))
                    time.sleep(0.2)

            def client(index: int) -> None:
                step = 0
                while not stop.is_set():
                    case_id = cases[(index + step * args.clients) % len(cases)]
                    frame = (step * 7 + index * 3) % 50
                    started = time.perf_counter()
                    status, _ = get(f"{base}/api/cases/{case_id}/frames/{frame}.png")
                    with lock:
                        latencies.append(time.perf_counter() - started)
                        statuses[status] = statuses.get(status, 0) + 1
                    step += 1

            threads = [threading.Thread(target=sample, daemon=True),
                       *(threading.Thread(target=client, args=(i,), daemon=True) for i in range(args.clients))]
            for thread in threads:
                thread.start()
            time.sleep(args.seconds)
            stop.set()
            for thread in threads:
                thread.join(timeout=180)
        finally:
            server.terminate()
            server.wait(timeout=30)
    ok = np.asarray(latencies)
    result = {"clients": args.clients, "seconds": args.seconds, "frame_cache_bytes": args.frame_cache_bytes,
              "env": args.env, "cases": args.cases or "all",
              "idle_rss_mb": round(idle_rss / 1e6), "peak_rss_mb": round(peak[0] / 1e6),
              "requests": len(latencies), "statuses": statuses,
              "p50_s": round(float(np.percentile(ok, 50)), 2) if len(ok) else None,
              "p95_s": round(float(np.percentile(ok, 95)), 2) if len(ok) else None}
    if args.json:
        print(json.dumps(result))
    else:
        for key, value in result.items():
            print(f"{key:18s} {value}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
