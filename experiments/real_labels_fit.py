"""The semi-automatic fit that made ``experiments/real_labels.json``: the ego lane's two lines of each chosen real
frame.

Per frame and line: a paint mask (bright thin structures by a white top-hat of HLS lightness, plus yellow by hue
and a saturation top-hat), a seed line near the bottom (the strongest paint directions either side of the camera
in a histogram of ``(x - vx) / (y - vy)`` about the camera's vanishing point, or a line through two hand-placed
points where that picks a tar seam or a shadow edge), a tracker that follows the paint up the frame row by row
(the nearest run of paint within a window that widens towards the bottom, predicted from the last 120 rows of
observations), and a robust polynomial ``x(y)`` through what it found (degree 2; observations more than three
median residuals off dropped). Rows are labelled from the highest observation down to the last road row above
the bonnet, through the gaps of dashed lines (below the lowest paint seen, straight on) but never above where the
paint was seen. A few lines are hand-placed
points instead (the tracker lost them), some are cut at a row (a motorbike or a sharp bend above), and frames
whose lines cannot be told in the glare are left out. Every overlay (``--overlays DIR``) was then checked by eye.

    .venv/bin/python experiments/real_footage.py frames --all        # every candidate frame into CACHE/candidates
    .venv/bin/python experiments/real_labels_fit.py [--cache out/real_footage] [--overlays out/real_footage/fit]

It rewrites ``experiments/real_labels.json``; with the same frames it gives the same labels.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from lanevil_core.labels.lanes import h_samples_for

ROOT = Path(__file__).resolve().parents[1]
NO_POINT = -2
SIDES = ("left", "right")
Point = tuple[float, float]  # (x, y) pixels of the frame


@dataclass(frozen=True)
class Camera:
    """Where a clip's road lies: its vanishing point, the last road row above the bonnet, the highest row used."""

    vanishing: Point
    bottom: int
    top: int


# The candidates: frames spread evenly over each clip, and the 1280x720 still images.
CLIPS: dict[str, tuple[str, range, Camera]] = {
    "project_video01": ("highway", range(0, 221, 28), Camera((485, 310), 539, 325)),
    "project_video02": ("highway", range(0, 681, 85), Camera((475, 305), 539, 320)),
    "project_video03": ("highway", range(0, 1260, 78), Camera((643, 425), 660, 445)),
    "challenge01": ("hard", range(0, 251, 12), Camera((650, 440), 660, 460)),
    "challenge03": ("hard", range(0, 1199, 60), Camera((640, 430), 660, 440)),
}
STILLS = ("straight_lines1", "straight_lines2", "test1", "test2", "test3", "test4", "test5", "test6")
STILL_CAMERA = Camera((643, 425), 660, 445)

# Frames left out: the lines cannot be told in the glare or the road bends out of the frame.
LEFT_OUT = {"challenge03_0660", "challenge03_0900", "challenge03_1020", "challenge03_1080"}

# Hand help per frame and line: "seed" a line through two points (x, y) to start from, "points" the line's own
# hand-placed points (no tracking), "top" the highest row to label.
HELP: dict[str, dict[str, dict[str, Any]]] = {
    "project_video02_0170": {"right": {"seed": [(877.48, 539), (475, 305)]}},
    "project_video03_0702": {"right": {"points": [(1062, 666), (865, 548), (785, 500), (740, 469), (720, 448)]}},
    "project_video03_1014": {"right": {"points": [(1075, 670), (858, 545), (780, 495), (730, 462)]}},
    "test1": {"left": {"seed": [(310, 670), (470, 530)]},
              "right": {"points": [(1050, 655), (763, 488), (727, 466)]}},
    "test4": {"left": {"seed": [(320, 670), (490, 540)]}, "right": {"seed": [(1010, 620), (828, 520)]}},
    "test5": {"left": {"seed": [(230, 670), (400, 560)]}, "right": {"seed": [(912, 578), (750, 480)]}},
    "challenge01_0096": {"left": {"seed": [(331, 672), (650, 440)]}, "right": {"seed": [(1097.76, 672), (650, 440)]}},
    "challenge01_0108": {"left": {"seed": [(311.28, 672), (650, 440)]}, "right": {"seed": [(1102.4, 672), (650, 440)]}},
    "challenge01_0144": {"left": {"seed": [(234.72, 672), (650, 440)]}, "right": {"seed": [(1044.4, 672), (650, 440)]}},
    "challenge01_0156": {"left": {"seed": [(244, 672), (650, 440)]},
                         "right": {"points": [(1030, 660), (1000, 641), (835, 533), (772, 488), (735, 458)]}},
    "challenge01_0120": {"left": {"seed": [(377, 600), (529, 500)]}},
    "challenge01_0192": {"right": {"points": [(735, 462), (790, 500), (878, 548)]}},
    "challenge01_0204": {"right": {"seed": [(971, 600), (794, 500)]}},
    "challenge03_0120": {"right": {"top": 510}},
    "challenge03_0180": {"left": {"seed": [(283, 672), (520, 580)]}},
    "challenge03_0300": {"left": {"seed": [(320, 670), (485, 530)]}, "right": {"seed": [(950, 660), (820, 560)]}},
    "challenge03_0360": {"left": {"seed": [(300, 670), (485, 560)]}, "right": {"seed": [(1045, 665), (940, 540)]}},
    "challenge03_0420": {"left": {"seed": [(255, 670), (390, 560)]}, "right": {"seed": [(1000, 670), (760, 510)]}},
    "challenge03_0600": {"left": {"seed": [(313, 672), (627, 447)]}},
    "challenge03_0720": {"left": {"seed": [(370, 670), (590, 530)]}, "right": {"seed": [(960, 660), (850, 530)]}},
    "challenge03_0840": {"left": {"seed": [(412, 670), (545, 560)]}},
    "challenge03_0960": {"left": {"seed": [(310, 670), (440, 590)], "top": 530},
                         "right": {"seed": [(995, 668), (960, 590)], "top": 545}},
}


def candidates() -> list[tuple[str, str, Camera]]:
    """(stem, source, camera) of every candidate frame: ``project_video03_0078`` / ``test_videos/...mp4#78``."""
    found = [(f"{clip}_{index:04d}", f"test_videos/{clip}.mp4#{index}", camera)
             for clip, (_, indices, camera) in CLIPS.items() for index in indices]
    return found + [(still, f"test_images/{still}.jpg", STILL_CAMERA) for still in STILLS]


def split_of(source: str) -> str:
    return CLIPS[Path(source.split("#")[0]).stem][0] if "#" in source else "highway"


# ---------------------------------------------------------------------------------------------- the fit

def paint_mask(bgr: np.ndarray) -> np.ndarray:
    """(H, W) uint8 1 where (H, W, 3) uint8 BGR shows lane paint: bright thin structures or yellow."""
    kernel = np.ones((1, int(61 * bgr.shape[1] / 1280) | 1), np.uint8)
    lightness = cv2.GaussianBlur(cv2.cvtColor(bgr, cv2.COLOR_BGR2HLS)[..., 1], (3, 3), 0)
    white = cv2.morphologyEx(lightness, cv2.MORPH_TOPHAT, kernel) > 28
    hue, saturation, value = cv2.split(cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV))
    yellow = (hue >= 12) & (hue <= 35) & (saturation > 70) & (value > 90)
    yellow &= cv2.morphologyEx(saturation, cv2.MORPH_TOPHAT, kernel) > 40
    return (white | yellow).astype(np.uint8)


def seed_slopes(mask: np.ndarray, camera: Camera) -> dict[str, float | None]:
    """Per side, ``(x - vx) / (y - vy)`` of the paint direction nearest the camera's own (None when none)."""
    vx, vy = camera.vanishing
    band = int(camera.bottom - 0.6 * (camera.bottom - vy))
    ys, xs = np.nonzero(mask[band:camera.bottom + 1])
    slopes = (xs - vx) / (ys + band - vy)
    hist, edges = np.histogram(slopes, bins=np.linspace(-6, 6, 241))
    hist = np.convolve(hist, [1, 2, 1], "same")
    centers = (edges[:-1] + edges[1:]) / 2
    floor = max(60 * (mask.shape[1] / 1280) ** 2, 0.03 * hist.max())
    peaks = [centers[i] for i in range(1, len(hist) - 1)
             if hist[i] >= hist[i - 1] and hist[i] > hist[i + 1] and hist[i] > floor]
    own = (mask.shape[1] / 2 - vx) / (camera.bottom - vy)
    left, right = [c for c in peaks if c < own], [c for c in peaks if c > own]
    return {"left": max(left) if left else None, "right": min(right) if right else None}


def _paint_runs(row: np.ndarray, merge: float) -> list[tuple[int, int]]:
    """[start, end) of the runs of 1 in a mask row, runs closer than ``merge`` px joined (double lines)."""
    steps = np.diff(np.concatenate([[0], row, [0]]))
    runs: list[tuple[int, int]] = []
    for start, end in zip(np.flatnonzero(steps == 1), np.flatnonzero(steps == -1)):
        if runs and start - runs[-1][1] <= merge:
            runs[-1] = (runs[-1][0], int(end))
        else:
            runs.append((int(start), int(end)))
    return runs


def track(mask: np.ndarray, seed: Point, seed_slope: float, camera: Camera) -> list[Point]:
    """(x, y) observations of one line followed up from the bottom row; ``seed``/``seed_slope`` (dx/dy) the line
    it starts from."""
    vy = camera.vanishing[1]
    observations: list[Point] = []
    last_seen: int | None = None
    for y in range(camera.bottom, camera.top - 1, -2):
        recent = [(ox, oy) for ox, oy in observations if oy - y <= 120]
        if len(recent) >= 6 and recent[0][1] - recent[-1][1] >= 40:
            k, b = np.polyfit([oy for _, oy in recent], [ox for ox, _ in recent], 1)
            predicted = k * y + b
        elif observations:
            predicted = observations[-1][0] + seed_slope * (y - observations[-1][1])
        else:
            predicted = seed[0] + seed_slope * (y - seed[1])
        distance = y - vy
        window = max(6.0, 0.16 * distance)
        low, high = int(max(0, predicted - window)), int(min(mask.shape[1], predicted + window + 1))
        runs = _paint_runs(mask[y, low:high], max(3.0, 0.12 * distance)) if high > low else []
        centers = [low + (start + end - 1) / 2 for start, end in runs if end - start <= max(4.0, 0.5 * distance)]
        if centers:
            observations.append((min(centers, key=lambda x: abs(x - predicted)), float(y)))
            last_seen = y
        if last_seen is not None and last_seen - y > max(25.0, 0.9 * distance):
            break
        if last_seen is None and camera.bottom - y > 0.75 * (camera.bottom - vy):
            break
    return observations


def fitted_lane(observations: list[Point], rows: list[int], width: int, camera: Camera, top: int | None,
                hand_placed: bool) -> list[int]:
    """x per row of the polynomial through ``observations`` (-2 above the highest, below the bottom road row and
    outside the frame); tracked observations are fitted robustly, hand-placed points as they are."""
    if len(observations) < (3 if hand_placed else 8):
        return [NO_POINT] * len(rows)
    xs, ys = np.array([x for x, _ in observations]), np.array([y for _, y in observations])
    degree = min(2 if ys.max() - ys.min() > 60 else 1, len(ys) - 2)
    keep = np.ones(len(ys), bool)
    for _ in range(3):
        poly = np.polyfit(ys[keep], xs[keep], degree)
        if hand_placed:
            break
        residual = np.abs(np.polyval(poly, ys) - xs)
        keep = residual <= max(3.0, 3 * np.median(residual[keep]) + 1.5)
    highest = ys[keep].min() if top is None else top
    lowest = camera.bottom if camera.bottom - ys[keep].max() <= max(25.0, 0.9 * (camera.bottom - camera.vanishing[1])) \
        else ys[keep].max()
    # Below the lowest observation the line is carried on straight (its slope over the lowest 100 rows seen, or the
    # curve's tangent): a parabola through far dashes alone bends away over the gap to the bottom.
    seen = ys[keep].max()
    near = keep & (ys >= seen - 100 * camera.bottom / 720)
    slope = np.polyfit(ys[near], xs[near], 1)[0] if np.ptp(ys[near]) >= 30 else np.polyval(np.polyder(poly), seen)
    lane = []
    for row in rows:
        x = float(np.polyval(poly, min(row, seen)) + (slope * (row - seen) if row > seen else 0.0))
        lane.append(int(round(x)) if highest - 1 <= row <= lowest and 0 <= x < width else NO_POINT)
    return lane


def fit_frame(bgr: np.ndarray, camera: Camera, hand: dict[str, dict[str, Any]]) -> tuple[list[int], list[list[int]]]:
    """(h_samples, [left lane, right lane]) of one frame."""
    rows = h_samples_for(bgr.shape[0])
    mask = paint_mask(bgr)
    slopes = seed_slopes(mask, camera)
    vx, vy = camera.vanishing
    lanes = []
    for side in SIDES:
        help_ = hand.get(side, {})
        if "points" in help_:
            observations = [(float(x), float(y)) for x, y in help_["points"]]
        elif "seed" in help_:
            (x1, y1), (x2, y2) = help_["seed"]
            observations = track(mask, (x1, y1), (x2 - x1) / (y2 - y1), camera)
        elif slopes[side] is not None:
            observations = track(mask, (vx, vy), float(slopes[side]), camera)  # type: ignore[arg-type]
        else:
            observations = []
        lanes.append(fitted_lane(observations, rows, bgr.shape[1], camera, help_.get("top"), "points" in help_))
    return rows, lanes


def how(hand: dict[str, dict[str, Any]]) -> str:
    """In words, the hand help a frame's labels had ("tracked" when none)."""
    words = []
    for side, help_ in hand.items():
        if "points" in help_:
            words.append(f"{side}: hand-placed points")
        if "seed" in help_:
            words.append(f"{side}: tracked from a hand-placed seed")
        if "top" in help_:
            words.append(f"{side}: cut at row {help_['top']}")
    return "; ".join(words) or "tracked"


def draw(bgr: np.ndarray, rows: list[int], lanes: list[list[int]], title: str) -> np.ndarray:
    """The labels over the frame: left red, right magenta."""
    image = bgr.copy()
    for lane, color in zip(lanes, ((0, 0, 255), (255, 0, 255))):
        points = [(x, y) for x, y in zip(lane, rows) if x >= 0]
        for a, b in zip(points, points[1:]):
            cv2.line(image, a, b, color, 1)
        for point in points:
            cv2.circle(image, point, 2, color, -1)
    cv2.putText(image, title, (10, 30), cv2.FONT_HERSHEY_SIMPLEX, 0.9, (0, 0, 255), 2)
    return image


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cache", type=Path, default=ROOT / "out" / "real_footage")
    parser.add_argument("--overlays", type=Path, default=None)
    parser.add_argument("--labels", type=Path, default=ROOT / "experiments" / "real_labels.json")
    args = parser.parse_args()
    header = {key: value for key, value in json.loads(args.labels.read_text()).items() if key != "frames"}
    frames = []
    for stem, source, camera in candidates():
        if stem in LEFT_OUT:
            continue
        bgr = cv2.imread(str(args.cache / "candidates" / f"{stem}.png"))
        if bgr is None:
            raise SystemExit(f"{args.cache / 'candidates'}: no {stem}.png; "
                             "run experiments/real_footage.py frames --all")
        hand = HELP.get(stem, {})
        rows, lanes = fit_frame(bgr, camera, hand)
        frames.append({"split": split_of(source), "source": source, "image_size": [bgr.shape[1], bgr.shape[0]],
                       "how": how(hand), "h_samples": rows, "lanes": lanes})
        if args.overlays is not None:
            args.overlays.mkdir(parents=True, exist_ok=True)
            cv2.imwrite(str(args.overlays / f"{stem}.png"), draw(bgr, rows, lanes, stem))
    lines = ["{"] + [f"  {json.dumps(key)}: {json.dumps(value)}," for key, value in header.items()]
    lines += ['  "frames": [', ",\n".join("    " + json.dumps(frame) for frame in frames), "  ]", "}"]
    args.labels.write_text("\n".join(lines) + "\n")
    print(f"{args.labels}: {len(frames)} frames")


if __name__ == "__main__":
    main()
