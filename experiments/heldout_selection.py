"""Selection on held-out synthetic worlds: every detector on validation splits of one seed that differ only in what
``lanevil dataset``'s world flags change, the held-out split (``--vary-world --heldout``) last. This table, not real
frames, chooses among runs.

Renders the splits under ``--out`` (once; reruns resume), runs the shipped detectors and the model folders given
with ``--model NAME=MODEL_DIR`` over each split, and prints a Markdown table: share of the ego lane's lines matched /
TuSimple accuracy, per split. ``--val DIR`` adds an existing split folder (e.g. a ``--vary-camera`` split) as the
first column.

    .venv/bin/python experiments/heldout_selection.py --out out/transfer \\
        --model seg-both=out/transfer/models/seg-both --val out/transfer/val/train
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ("ufld", "seg", "laneatt", "bezier", "ganet", "scnn", "hough", "birdseye")
SPLITS: dict[str, tuple[str, ...]] = {  # folder under --out -> the world flags it is rendered with
    "val-world": ("--vary-world",),
    "val-world-camera": ("--vary-world", "--vary-camera"),
    "val-heldout": ("--vary-world", "--heldout"),
}


def _cli(*args: str, env: dict[str, str] | None = None) -> None:
    subprocess.run([sys.executable, "-m", "lanevil_core.cli", *args], check=True, cwd=ROOT, env=env)


def render(out: Path, flags: tuple[str, ...], args: argparse.Namespace) -> Path:
    """The split folder of one world setting (rendered unless complete)."""
    _cli("dataset", "--cases", str(ROOT / "scenes" / "00_clean"), "--out", str(out), "--train-frames",
         str(args.frames), "--seed", str(args.seed), "--size", args.size, "--format", "jpg", "--workers",
         str(args.workers), "--quiet", *flags)
    return out / "train"


def scores(split: Path, predictions: Path, methods: list[str], env: dict[str, str]) -> dict[str, tuple[float, float]]:
    """Method -> (share of ego lines matched, TuSimple accuracy) on one split."""
    from lanevil_core.cli.evaluate import file_stem
    from lanevil_core.metrics.evaluate import evaluate
    from lanevil_core.metrics.pixel import LINE_WIDTH_720

    predictions.mkdir(parents=True, exist_ok=True)
    _cli("detect", str(split), *[part for method in methods for part in ("--method", method)],
         "--out", str(predictions), env=env)
    result = {}
    for method in methods:
        pred = predictions / f"{file_stem(method)}.json"
        ego = evaluate(split, pred, "ego", "ganet", LINE_WIDTH_720)
        tusimple = evaluate(split, pred, "tusimple", "ganet", LINE_WIDTH_720)
        result[method] = (float(ego["match_share"]), float(tusimple["accuracy"]))
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "transfer")
    parser.add_argument("--model", action="append", default=[], metavar="NAME=MODEL_DIR")
    parser.add_argument("--val", type=Path, action="append", default=[], metavar="SPLIT_DIR")
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--seed", type=int, default=1042)
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()

    named = [entry.split("=", 1) for entry in args.model]
    env = {**os.environ, "LANEVIL_DETECTORS": ";".join(f"{name}=onnx:{path}" for name, path in named)}
    methods = [*SHIPPED, *(name for name, _ in named)]
    splits = {path.parent.name if path.name == "train" else path.name: path for path in args.val}
    splits.update({name: render(args.out / name, flags, args) for name, flags in SPLITS.items()})
    table = {name: scores(path, args.out / "predictions" / name, methods, env) for name, path in splits.items()}
    if args.json:
        print(json.dumps(table, indent=2))
        return
    print("| detector | " + " | ".join(f"`{name}`" for name in table) + " |")
    print("|---|" + "---:|" * len(table))
    held_out = table["val-heldout"]
    for method in sorted(methods, key=lambda m: -held_out[m][0]):
        cells = " | ".join(f"{100 * t[method][0]:.1f} / {100 * t[method][1]:.1f}" for t in table.values())
        print(f"| `{method}` | {cells} |")


if __name__ == "__main__":
    main()
