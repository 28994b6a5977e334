"""Learned lane detectors: training seconds per epoch and ONNX inference milliseconds per frame.

Training: for each family (ufld, seg) and input size, a few timed optimiser steps on random images with real
targets shapes (batch 16, all cores), scaled to an epoch of ``--epoch-frames`` frames (the shipped models trained
on 3,600 frames). Inference: the shipped ONNX models through onnxruntime on a 1280x720 frame (resize + network +
decoding, as ``lanevil detect`` runs them), median of ``--repeats`` runs, with 1 thread and with all cores.

Usage: ``python bench/learned_detectors.py [--sizes 320x180,480x270] [--steps 6] [--repeats 30] [--json]``
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time

import numpy as np

from lanevil_core.detect.learned import LearnedDetector, shipped_model_dir
from lanevil_core.detect.model_spec import ModelSpec
from lanevil_core.labels.lanes import TUSIMPLE_H_SAMPLES


def train_seconds_per_epoch(family: str, size: tuple[int, int], steps: int, epoch_frames: int,
                            batch: int = 16) -> float:
    import torch

    from lanevil_core.learn.losses import detector_loss
    from lanevil_core.learn.models import build_model

    torch.manual_seed(0)
    torch.set_num_threads(os.cpu_count() or 1)
    spec = ModelSpec(family=family, input_size=size)
    model = build_model(spec).train()
    optimizer = torch.optim.AdamW(model.parameters(), lr=1e-3)
    mask_w, mask_h = spec.mask_size
    batch_data = {"image": torch.rand(batch, 3, size[1], size[0]),
                  "rows": torch.randint(0, spec.grid + 1, (batch, spec.slots, spec.anchors)),
                  "mask": torch.randint(0, spec.slots + 1, (batch, mask_h, mask_w)),
                  "exist": torch.randint(0, 2, (batch, spec.slots)).float()}
    times = []
    for step in range(steps + 1):
        start = time.perf_counter()
        loss, _ = detector_loss(family, model(batch_data["image"]), batch_data)
        optimizer.zero_grad()
        loss.backward()
        optimizer.step()
        if step:  # the first step pays for allocation
            times.append(time.perf_counter() - start)
    return statistics.median(times) * epoch_frames / batch


def inference_ms(family: str, threads: int, repeats: int) -> float | None:
    model_dir = shipped_model_dir(family)
    if not (model_dir / "model.onnx").is_file():
        return None
    detector = LearnedDetector(model_dir, threads=threads)
    rgb = np.random.default_rng(0).integers(0, 256, (720, 1280, 3), dtype=np.uint8)
    rows = list(TUSIMPLE_H_SAMPLES)
    detector(rgb, rows)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        detector(rgb, rows)
        times.append(1000 * (time.perf_counter() - start))
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="320x180,480x270")
    parser.add_argument("--steps", type=int, default=6)
    parser.add_argument("--epoch-frames", type=int, default=3600)
    parser.add_argument("--repeats", type=int, default=30)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    sizes = [tuple(int(v) for v in s.split("x")) for s in args.sizes.split(",")]
    result: dict = {"train_s_per_epoch": {}, "inference_ms": {}, "cores": os.cpu_count()}
    for family in ("ufld", "seg"):
        for size in sizes:
            key = f"{family} {size[0]}x{size[1]}"
            result["train_s_per_epoch"][key] = round(
                train_seconds_per_epoch(family, size, args.steps, args.epoch_frames), 1)
        for threads in (1, 0):
            value = inference_ms(family, threads, args.repeats)
            label = f"{family} {'1 thread' if threads == 1 else 'all cores'}"
            result["inference_ms"][label] = None if value is None else round(value, 2)
    if args.json:
        print(json.dumps(result, indent=2))
        return
    print(f"training, seconds per epoch of {args.epoch_frames} frames (batch 16, {os.cpu_count()} cores):")
    for key, value in result["train_s_per_epoch"].items():
        print(f"  {key:14s} {value:8.1f} s")
    print("ONNX inference on a 1280x720 frame (resize + network + decode), median ms:")
    for key, value in result["inference_ms"].items():
        print(f"  {key:18s} {'-' if value is None else f'{value:8.2f}'}")


if __name__ == "__main__":
    main()
