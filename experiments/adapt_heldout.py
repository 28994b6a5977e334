"""``lanevil adapt`` under a synthetic domain shift: what chooses its method and settings, before any real frame.

A model trained on the train worlds is adapted on the *unlabelled* images of one held-out split (``--adapt-on``:
``lanevil dataset --vary-world --heldout``, its cameras, roads and materials outside every train range; the split's
labels are never read, ``lanevil adapt`` reads image files only) and scored, before and after, on the labelled
frames of *another* held-out split of other draws (``--score-on``), with the ego line match and TuSimple accuracy.
This is the table that chooses ``lanevil adapt``'s defaults; real footage (``experiments/adapt_real.py``) is read
afterwards, for the report. The dann methods also train on the labelled renders of ``--source`` (the train
worlds' split, never a held-out one).

    .venv/bin/python experiments/adapt_heldout.py --adapt-on out/transfer/val-heldout/train \\
        --score-on out/transfer/val-heldout-2/train [--models seg seg-transfer] \\
        [--adapt adabn self-train adabn+self-train dann adabn+dann] [--rounds 1 2] \\
        [--source out/transfer/train-wc/train] [--epochs 3] [--threads 1]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

from lanevil_core.detect.model_spec import ModelSpec

ROOT = Path(__file__).resolve().parents[1]


def _cli(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "lanevil_core.cli", *args], check=True, cwd=ROOT)


def score(split: Path, method: str, weights: list[str], pred: Path) -> dict[str, float]:
    """Share of ego lines matched and TuSimple accuracy of one model on ``split``."""
    from lanevil_core.metrics.evaluate import evaluate
    from lanevil_core.metrics.pixel import LINE_WIDTH_720

    pred.parent.mkdir(parents=True, exist_ok=True)
    _cli("detect", str(split), "--method", method, *weights, "--out", str(pred))
    ego = evaluate(split, pred, "ego", "ganet", LINE_WIDTH_720)
    tusimple = evaluate(split, pred, "tusimple", "ganet", LINE_WIDTH_720)
    return {"ego": float(ego["match_share"]), "accuracy": float(tusimple["accuracy"])}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--adapt-on", type=Path, required=True, help="held-out split whose images are adapted on")
    parser.add_argument("--score-on", type=Path, required=True, help="labelled held-out split of other draws")
    parser.add_argument("--cache", type=Path, default=ROOT / "out" / "transfer" / "adapt")
    parser.add_argument("--models", nargs="+", default=["seg", "seg-transfer"])
    parser.add_argument("--adapt", nargs="+", default=["adabn", "self-train", "adabn+self-train"])
    parser.add_argument("--rounds", nargs="+", type=int, default=[1])
    parser.add_argument("--source", type=Path, default=None,
                        help="labelled split of the train worlds, for the dann methods")
    parser.add_argument("--epochs", type=int, default=3, help="lanevil adapt --epochs (default 3)")
    parser.add_argument("--domain-weight", type=float, default=1.0,
                        help="lanevil adapt --domain-weight of the dann methods (0: the source-only control)")
    parser.add_argument("--threads", type=int, default=0, help="lanevil adapt --threads (default every core)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    if args.source is None and any("dann" in how for how in args.adapt):
        parser.error("--source: the dann methods need the labelled split of the train worlds")
    rows = []
    for model in args.models:
        rows.append({"model": model, "adapt": "none", "rounds": 0,
                     **score(args.score_on, model, [], args.cache / "pred" / f"{model}.json")})
        for how in args.adapt:
            for rounds in args.rounds if "self-train" in how else [1]:
                weight = f"-w{args.domain_weight:g}" if "dann" in how and args.domain_weight != 1.0 else ""
                name = f"{model}-{how}-r{rounds}{weight}"
                folder = args.cache / "models" / name
                if not (folder / "training.json").is_file():  # reruns resume
                    source = (["--source", str(args.source), "--domain-weight", str(args.domain_weight)]
                              if "dann" in how else [])
                    _cli("adapt", "--weights", model, "--frames", str(args.adapt_on), "--out", str(folder),
                         "--method", how, "--rounds", str(rounds), "--epochs", str(args.epochs),
                         "--threads", str(args.threads), *source, "--quiet")
                training = json.loads((folder / "training.json").read_text())
                family = ModelSpec.load(folder).family  # runs as its family
                rows.append({"model": model, "adapt": how + weight, "rounds": rounds,
                             "pseudo_labelled": training.get("self_training", {}).get("pseudo_labelled"),
                             "domain_accuracy": training.get("dann", {}).get("domain_accuracy"),
                             "seconds": training["seconds"],
                             **score(args.score_on, family, ["--weights", str(folder)],
                                     args.cache / "pred" / f"{name}.json")})
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    print(f"adapted on the images of {args.adapt_on}; scored on {args.score_on}")
    print("| model | adaptation | rounds | ego lines | TuSimple accuracy | domain accuracy per epoch | seconds |")
    print("|---|---|---:|---:|---:|---|---:|")
    for row in rows:
        domain = ", ".join(f"{a:.2f}" for a in row.get("domain_accuracy") or []) or "–"
        print(f"| `{row['model']}` | {row['adapt']} | {row['rounds']} | {100 * row['ego']:.1f} % | "
              f"{100 * row['accuracy']:.1f} % | {domain} | {row.get('seconds', '–')} |")


if __name__ == "__main__":
    main()
