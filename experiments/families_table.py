"""The paper's Table 1 for every shipped learned family: Perturbed / Original / Gap per category and on average, in
Accuracy and F1, with 95 % intervals over basic cases, side by side (``lanevil report``'s ``compare.md``).

Each family's shipped model (``lanevil detect --method FAMILY``) runs over the same test split; a family whose
predictions already exist is not run again, so the script resumes; the others run in one ``lanevil detect`` (each
image read once). Classical baselines can be added with ``--baselines hough,birdseye``.

Usage::

    lanevil dataset --cases scenes --out data/lib4 --frames-per-case 4 --size 640x360 --no-paint
    python experiments/families_table.py --bench data/lib4/test --out out/table1 [--families ufld,seg]
        [--baselines hough]    # (one command)

Writes ``OUT/pred/FAMILY.json`` and ``OUT/report/`` (``compare.md``, ``compare.csv``, ``breakdown.csv``); prints
the detection's seconds and frames per second.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

from lanevil_core.detect.model_spec import FAMILIES


def lanevil(*args: str) -> None:
    """Run one ``lanevil`` command in this interpreter's environment; its output is shown only if it fails."""
    done = subprocess.run([sys.executable, "-m", "app.cli", *args], capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"lanevil {' '.join(args)} failed ({done.returncode}):\n{done.stdout}{done.stderr}")


def frame_count(predictions: Path) -> int:
    """Number of prediction lines (one frame each) in a TuSimple JSON-lines file."""
    with predictions.open(encoding="utf-8") as lines:
        return sum(1 for line in lines if line.strip())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bench", required=True, help="test split folder (or dataset folder)")
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--families", default=",".join(FAMILIES), help="comma-separated learned families")
    parser.add_argument("--baselines", default="", help="comma-separated classical methods (hough, birdseye)")
    args = parser.parse_args()
    methods = [name for name in (*args.families.split(","), *args.baselines.split(",")) if name]
    out = Path(args.out)
    (out / "pred").mkdir(parents=True, exist_ok=True)
    timings = {}
    missing = [method for method in methods if not (out / "pred" / f"{method}.json").exists()]
    if missing:  # one `lanevil detect` for all of them: each image is read once
        started = time.perf_counter()
        # One method writes a predictions file; several write a folder of METHOD.json.
        target = out / "pred" / f"{missing[0]}.json" if len(missing) == 1 else out / "pred"
        method_args = (arg for method in missing for arg in ("--method", method))
        lanevil("detect", args.bench, *method_args, "--out", str(target))
        seconds = time.perf_counter() - started
        frames = frame_count(out / "pred" / f"{missing[0]}.json")
        timings = {"methods": missing, "seconds": round(seconds, 1), "frames": frames}
        print(f"{', '.join(missing)}: {seconds:.0f} s for {frames} frames, {frames / seconds:.1f} frames/s",
              flush=True)
    report_args = ["report", "--gt", args.bench, "--out", str(out / "report"), "--title", "Table 1"]
    for method in methods:
        report_args += ["--pred", str(out / "pred" / f"{method}.json"), "--name", method]
    lanevil(*report_args)
    (out / "timings.json").write_text(json.dumps(timings, indent=2) + "\n", encoding="utf-8")
    print(out / "report" / "compare.md")


if __name__ == "__main__":
    main()
