"""The defence comparison: one detector family trained with every ``--augment`` over several seeds, scored on the
benchmark's test split, and ``lanevil report``'s defence table (gain over vanilla per seed and averaged).

Every run uses the same train split, family, size and epochs; only ``--augment`` and ``--seed`` change (the seed
also picks the held-out folders and the initialisation). Runs train with one thread each, ``--jobs`` of them at a
time; a run whose model (or predictions) already exist is not repeated, so the script resumes.

Usage::

    lanevil dataset --cases scenes/00_clean --out data/train2k --train-frames 2000 --size 640x360
    lanevil dataset --cases scenes --out data/bench --frames-per-case 10 --train-frames 0 --no-paint
    python experiments/defences.py --data data/train2k --bench data/bench/test --out out/defences \\
        [--family seg] [--epochs 6] [--augments none,aam,cutout,copy_paste,hsv,mixup,pgd,aam_keep_paint] \\
        [--seeds 0,1,2] [--jobs 2] \\
        [--init lanevil_core/detect/models/ufld/weights.pt --lr 1e-3] [--patience 4 [--min-epochs 15]] [--train-only]

``aam_keep_paint`` is AAM with ``lanevil train --aam-keep-paint`` (each image's own lane markings left unmixed).

``--patience`` trains each run until its validation accuracy stops improving (``--epochs`` is then the most) and
keeps the best epoch. ``--train-only`` stops after training: run the same command without it (on another machine,
say, with the model folders copied over) to detect and report.

Writes ``OUT/models/AUGMENT@SEED/``, ``OUT/pred/AUGMENT@SEED.json`` and ``OUT/report/`` (``compare.md`` holds the
defence tables); prints each run's seconds and the report's path.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from lanevil_core.detect.model_spec import FAMILIES

AUGMENTS = ("none", "aam", "cutout", "copy_paste", "hsv", "mixup", "pgd")
# runs of one augment with other settings: name -> (--augment, extra lanevil train arguments)
VARIANTS = {"aam_keep_paint": ("aam", ("--aam-keep-paint",))}


def lanevil(*args: str) -> None:
    """Run one ``lanevil`` command in this interpreter's environment; its output is shown only if it fails."""
    done = subprocess.run([sys.executable, "-m", "app.cli", *args], capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"lanevil {' '.join(args)} failed ({done.returncode}):\n{done.stdout}{done.stderr}")


def run_one(args: argparse.Namespace, name: str) -> tuple[str, float]:
    """Train (unless done) and detect (unless done) one ``AUGMENT@SEED`` run; (name, seconds)."""
    augment, seed = name.split("@")
    model_dir = args.out / "models" / name
    pred = args.out / "pred" / f"{name}.json"
    started = time.perf_counter()
    if not (model_dir / "model.onnx").is_file():
        extra = ["--max-steps", str(args.max_steps)] if args.max_steps else []
        extra += ["--init", str(args.init)] if args.init else []
        extra += ["--lr", str(args.lr)] if args.lr else []
        extra += ["--patience", str(args.patience)] if args.patience else []
        extra += ["--min-epochs", str(args.min_epochs)] if args.min_epochs else []
        augment, settings = VARIANTS.get(augment, (augment, ()))
        lanevil("train", "--data", str(args.data), "--out", str(model_dir), "--model", args.family,
                "--epochs", str(args.epochs), "--augment", augment, "--seed", seed, "--threads", "1", "--quiet",
                *settings, *extra)
    if not pred.is_file() and not args.train_only:
        pred.parent.mkdir(parents=True, exist_ok=True)
        lanevil("detect", str(args.bench), "--method", args.family, "--weights", str(model_dir), "--out", str(pred))
    return name, time.perf_counter() - started


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, required=True, help="a dataset folder with a clean train split")
    parser.add_argument("--bench", type=Path, default=None,
                        help="the benchmark's test split folder (needed unless --train-only)")
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--family", choices=FAMILIES, default="seg")
    parser.add_argument("--epochs", type=int, default=6)
    parser.add_argument("--augments", default=",".join(AUGMENTS))
    parser.add_argument("--seeds", default="0,1,2")
    parser.add_argument("--jobs", type=int, default=2, help="runs at a time (each trains with one thread)")
    parser.add_argument("--max-steps", type=int, default=None, help="optimiser steps per epoch at most (smoke runs)")
    parser.add_argument("--init", type=Path, default=None,
                        help="every run fine-tunes from these weights (e.g. the shipped model's weights.pt) instead "
                             "of training from scratch")
    parser.add_argument("--lr", type=float, default=None, help="peak learning rate (default: lanevil train's)")
    parser.add_argument("--patience", type=int, default=None,
                        help="train each run until validation accuracy has not improved for this many epochs")
    parser.add_argument("--min-epochs", type=int, default=0,
                        help="with --patience: no run stops before this many epochs")
    parser.add_argument("--train-only", action="store_true", help="train every run, then stop (no detection)")
    args = parser.parse_args(argv)
    if args.bench is None and not args.train_only:
        parser.error("--bench: the test split to score on is needed (or --train-only)")
    augments = [a for a in args.augments.split(",") if a]
    unknown = sorted(set(augments) - set(AUGMENTS) - set(VARIANTS))
    if unknown or "none" not in augments:
        parser.error(f"--augments: {', '.join(unknown) or 'none'} {'unknown' if unknown else 'is needed'}"
                     f" (choose from {', '.join(AUGMENTS + tuple(VARIANTS))}; 'none' is the baseline)")
    names = [f"{augment}@{seed}" for seed in args.seeds.split(",") for augment in augments]
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for name, seconds in pool.map(lambda n: run_one(args, n), names):
            print(f"{name}: {seconds:.0f} s", flush=True)
    if args.train_only:
        print(f"models: {args.out / 'models'}")
        return 0
    report = args.out / "report"
    pairs = [part for name in names for part in ("--pred", str(args.out / "pred" / f"{name}.json"), "--name", name)]
    lanevil("report", "--gt", str(args.bench), *pairs, "--baseline", "none", "--out", str(report))
    print(f"defence tables: {report / 'compare.md'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
