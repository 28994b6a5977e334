"""`lanevil bench` of two commits side by side: is a change faster or slower than the code before it?

Each revision (a commit, a branch, or `worktree` for the files as they are now) is extracted into its own folder
(`lanevil_core`, `app`, `scenes`) with its own numba cache, and `python -m app.cli bench --json` runs in each, the
revisions alternated round after round, so load on the machine hits both alike. Printed: every round's median
ms/frame per row of the bench (a size, and a camera with `--camera`), the medians over rounds and the ratio of the
second revision to the first; with `--camera`, also each revision's own ratio of a camera's frame to the case
camera's (rows `WxH <camera> / case`, whose "ms" are that ratio). Each bench warms numba up before it times, so
compiles are not timed; the first round of a revision compiles its kernels into its cache (minutes) before the
bench starts.

    .venv/bin/python bench/commits.py HEAD~1 worktree --rounds 3 --camera carla

Rows a revision's bench does not print (an older `lanevil bench` without `--camera`) are left out of the ratio;
with `--camera`, an older revision's plain rows are compared with the newer one's case-camera rows by size.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from lanevil_core.cli.base import UsageError

ROOT = Path(__file__).resolve().parent.parent
WORKTREE = "worktree"
TREE_PARTS = ("lanevil_core", "app", "scenes")


def extract(revision: str, into: Path) -> Path:
    """The files of ``revision`` (``worktree``: as they are now) that the bench imports, under ``into``."""
    into.mkdir(parents=True, exist_ok=True)
    if revision == WORKTREE:
        for part in TREE_PARTS:
            shutil.copytree(ROOT / part, into / part, ignore=shutil.ignore_patterns("__pycache__"))
        return into
    check = subprocess.run(["git", "rev-parse", "--verify", "--quiet", f"{revision}^{{commit}}"], cwd=ROOT,
                           capture_output=True, text=True)
    if check.returncode != 0:
        raise UsageError(f"revision: {revision!r} is not a commit of this repository")
    archive = subprocess.run(["git", "archive", revision, *TREE_PARTS], cwd=ROOT, capture_output=True, check=True)
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive.stdout, check=True)
    return into


def bench_once(tree: Path, bench_args: list[str]) -> dict[str, Any]:
    """One ``lanevil bench --json`` of the code under ``tree`` (its own numba cache)."""
    env = dict(os.environ, PYTHONPATH=str(tree), NUMBA_CACHE_DIR=str(tree / ".numba"))
    done = subprocess.run([sys.executable, "-m", "app.cli", "bench", "--json", *bench_args], cwd=tree, env=env,
                          capture_output=True, text=True)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["no output"])[-1]
        raise UsageError(f"bench of {tree.name} failed: {last}")
    result: dict[str, Any] = json.loads(done.stdout)
    return result


def row_medians(result: dict[str, Any], case_camera: str = "case") -> dict[str, float]:
    """``{row: median ms}`` of one bench; a ``"WxH case"`` row is also filed under ``"WxH"`` (what a bench
    without cameras calls it), unless that name is taken, and a camera row's ratio to the case camera under
    ``"WxH <camera> / case"``."""
    rows = {key: float(row["median_ms"]) for key, row in result.items()}
    rows.update({f"{key} / {case_camera}": float(row["ratio"]) for key, row in result.items() if "ratio" in row})
    for key in list(rows):
        size, _, camera = key.partition(" ")
        if camera == case_camera and size not in rows:
            rows[size] = rows[key]
    return rows


def summarise(runs: dict[str, list[dict[str, float]]], first: str, second: str) -> list[dict[str, Any]]:
    """Per bench row both revisions printed: every round's median ms of each, the median over rounds and the
    ratio second / first of those medians."""
    rows = [key for key in runs[second][0] if all(key in r for r in runs[first] + runs[second])]
    rows = [key for key in rows if f"{key} case" not in rows]  # a size's alias, when both have its case row
    table = []
    for key in rows:
        a = [r[key] for r in runs[first]]
        b = [r[key] for r in runs[second]]
        table.append({"row": key, first: a, second: b, f"{first} median": statistics.median(a),
                      f"{second} median": statistics.median(b),
                      "ratio": round(statistics.median(b) / statistics.median(a), 3)})
    return table


def format_summary(table: list[dict[str, Any]], first: str, second: str) -> str:
    lines = [f"median ms/frame per round ({first} | {second}), medians over rounds, ratio {second} / {first}"]
    for row in table:
        digits = 3 if row["row"].endswith(" / case") else 1  # a camera-to-case ratio, not milliseconds
        a = ", ".join(f"{v:.{digits}f}" for v in row[first])
        b = ", ".join(f"{v:.{digits}f}" for v in row[second])
        lines.append(f"{row['row']:>22}  {a} | {b}  ->  {row[f'{first} median']:.{digits}f} | "
                     f"{row[f'{second} median']:.{digits}f}  ratio {row['ratio']:.3f}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("first", help="the revision to compare with (a commit, a branch, or 'worktree')")
    parser.add_argument("second", nargs="?", default=WORKTREE, help="the revision timed against it (default: "
                        "the working tree)")
    parser.add_argument("--rounds", type=int, default=3, help="benches of each revision, alternated (default 3)")
    parser.add_argument("--camera", nargs="+", default=[], metavar="PRESET",
                        help="also time these camera presets (lanevil bench --camera)")
    parser.add_argument("--frames-per-case", type=int, default=2, help="lanevil bench --frames-per-case")
    parser.add_argument("--json", action="store_true", help="print the table as JSON")
    args = parser.parse_args(argv)
    try:
        if args.rounds < 1:
            raise UsageError("--rounds must be at least 1")
        if args.first == args.second:
            raise UsageError("first and second: give two different revisions")
        with tempfile.TemporaryDirectory(prefix="lanevil-commits-") as tmp:
            trees = {rev: extract(rev, Path(tmp) / f"rev{i}") for i, rev in enumerate((args.first, args.second))}
            runs: dict[str, list[dict[str, float]]] = {rev: [] for rev in trees}
            for round_index in range(args.rounds):
                for rev, tree in trees.items():
                    bench_args = ["--frames-per-case", str(args.frames_per_case)]
                    try:
                        result = bench_once(tree, bench_args + (["--camera", *args.camera] if args.camera else []))
                    except UsageError as error:
                        if not args.camera or "--camera" not in str(error):
                            raise
                        result = bench_once(tree, bench_args)  # an older bench without --camera: timed plain
                    runs[rev].append(row_medians(result))
                    print(f"round {round_index + 1}: {rev} done", file=sys.stderr)
        table = summarise(runs, args.first, args.second)
    except UsageError as error:
        print(f"commits.py: {error}", file=sys.stderr)
        return 2
    print(json.dumps(table) if args.json else format_summary(table, args.first, args.second))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
