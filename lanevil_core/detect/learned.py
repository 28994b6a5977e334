"""Learned lane detectors at inference: an ONNX model folder run by onnxruntime (no torch needed).

A model folder (written by ``lanevil train``) holds ``config.json`` (a ``ModelSpec``), ``model.onnx`` and
``training.json``. The network takes ``(N, 3, H, W)`` float32 RGB in 0..1 at the spec's input size and returns
probabilities and regressions under fixed names, decoded to lane lines by the family's decoder (``DECODERS``):

- ``ufld``: ``row_probs`` ``(N, slots, anchors, grid + 1)`` (``lane_slots``, row anchors);
- ``seg``, ``scnn``: ``mask_probs`` ``(N, slots + 1, h, w)``, ``exist_probs`` ``(N, slots)`` (``lane_slots``, masks);
- ``laneatt``: ``anchor_scores`` ``(N, A)``, ``anchor_regs`` ``(N, A, 2 + anchors)`` (``line_anchors``);
- ``bezier``: ``curve_exist`` ``(N, Q)``, ``curve_points`` ``(N, Q, 4, 2)`` (``bezier_curves``);
- ``ganet``: ``heat_probs`` ``(N, 1, h, w)``, ``keypoint_offsets`` ``(N, 3, h, w)`` (``lane_keypoints``).

The project ships one small model per family in ``lanevil_core/detect/models/<family>/``; ``--method ufld`` uses
it when no ``--weights`` folder is given. ``BUNDLED_MODELS`` are more model folders shipped there, each a named
detector run as the family its ``config.json`` names.
"""

from __future__ import annotations

import functools
import threading
from collections.abc import Callable, Sequence
from pathlib import Path

import cv2
import numpy as np

from ..typed import Float32Array, FloatArray, UInt8Array
from .bezier_curves import decode_curves
from .lane_keypoints import decode_keypoints
from .lane_slots import LaneLine, anchor_reach, decode_lane_masks, decode_row_anchors, tusimple_lanes
from .line_anchors import decode_anchors, line_anchors
from .model_spec import FAMILIES, ONNX_FILE, ModelSpec, ModelSpecError
from .view import View, ViewError, view_input

SHIPPED_MODELS = Path(__file__).resolve().parent / "models"
# Models shipped beside the six families' own, each a `lanevil train` folder run as the family its config.json names,
# by name; they read other cameras and roads better than the benchmark's six, which keep their models. How each was
# trained and chosen (on synthetic validation splits only: at least 50 % of the ego lines on both car-height preset
# splits, and more accurate than the model it started from) is in docs/learning.md ("Which model to use when");
# `make models-transfer` and then `make models-transfer-world` make them again.
BUNDLED_MODELS: tuple[str, ...] = ("seg-transfer", "scnn-transfer", "laneatt-transfer", "ufld-transfer",
                                   "ganet-transfer")


def shipped_model_dir(name: str) -> Path:
    """The folder of the model shipped for ``name``: one of ``FAMILIES`` or ``BUNDLED_MODELS``."""
    if name not in FAMILIES and name not in BUNDLED_MODELS:
        raise ModelSpecError(f"no shipped model {name!r} (choose from {', '.join((*FAMILIES, *BUNDLED_MODELS))})")
    return SHIPPED_MODELS / name


def network_input(rgb: UInt8Array, input_size: tuple[int, int], view: View | None = None) -> Float32Array:
    """(3, H, W) float32 in 0..1: the frame resized (area filter) to the network's input (width, height), or with a
    ``view`` its window of the frame (``detect.view``)."""
    width, height = input_size
    if view is not None:
        rgb = view_input(rgb, view, input_size)
    elif rgb.shape[1] != width or rgb.shape[0] != height:
        rgb = np.asarray(cv2.resize(rgb, (width, height), interpolation=cv2.INTER_AREA), np.uint8)
    chw = np.ascontiguousarray(rgb.transpose(2, 0, 1), dtype=np.float32)
    return np.multiply(chw, np.float32(1.0 / 255.0), dtype=np.float32)


def providers() -> list[str]:
    """onnxruntime execution providers: CUDA first when this onnxruntime has it, always the CPU."""
    import onnxruntime

    available = onnxruntime.get_available_providers()
    return [p for p in ("CUDAExecutionProvider", "CPUExecutionProvider") if p in available]


Outputs = dict[str, FloatArray]  # one image's network outputs by name (the batch axis removed)
Decoder = Callable[[ModelSpec, Outputs], list[LaneLine | None]]


def _row_anchors(spec: ModelSpec, out: Outputs) -> list[LaneLine | None]:
    return decode_row_anchors(out["row_probs"], spec.anchor_rows)


def _lane_masks(spec: ModelSpec, out: Outputs) -> list[LaneLine | None]:
    rows = np.linspace(spec.anchor_rows[0], spec.anchor_rows[-1], 2 * spec.anchors)
    return decode_lane_masks(out["mask_probs"], out["exist_probs"], rows)


def _line_anchors(spec: ModelSpec, out: Outputs) -> list[LaneLine | None]:
    width, height = spec.input_size
    return decode_anchors(out["anchor_scores"], out["anchor_regs"], line_anchors(), spec.anchor_rows,
                          width / height, spec.slots)


def _curves(spec: ModelSpec, out: Outputs) -> list[LaneLine | None]:
    return decode_curves(out["curve_exist"], out["curve_points"])


def _keypoints(spec: ModelSpec, out: Outputs) -> list[LaneLine | None]:
    return decode_keypoints(out["heat_probs"][0], out["keypoint_offsets"], spec.slots)


DECODERS: dict[str, Decoder] = {"ufld": _row_anchors, "seg": _lane_masks, "scnn": _lane_masks,
                                "laneatt": _line_anchors, "bezier": _curves, "ganet": _keypoints}


def decode_outputs(spec: ModelSpec, outputs: dict[str, FloatArray], index: int = 0) -> list[LaneLine | None]:
    """The lane lines of image ``index`` of a batch of network outputs (slots for ``ufld``/``seg``/``scnn``)."""
    return DECODERS[spec.family](spec, {name: value[index] for name, value in outputs.items()})


def lanes_of(spec: ModelSpec, lines: list[LaneLine | None], h_samples: Sequence[float],
             size: tuple[int, int], view: View | None = None) -> list[list[int]]:
    """TuSimple lanes at ``h_samples`` of an image of ``size`` from decoded lane slots (read through ``view``'s
    window of the image when given)."""
    reach = anchor_reach(spec.anchor_rows)
    if view is not None:
        lines = [None if line is None else view.to_frame(line) for line in lines]
        reach *= view.window[3] - view.window[1]
    return tusimple_lanes(lines, h_samples, size, reach)


def inference_session(onnx_path: Path, threads: int = 0):  # noqa: ANN201 - onnxruntime.InferenceSession
    """An onnxruntime session on ``onnx_path`` (CUDA first when there is one), with ``threads`` intra-op threads
    (0 = onnxruntime's choice) that sleep between runs."""
    import onnxruntime

    options = onnxruntime.SessionOptions()
    options.intra_op_num_threads = threads
    # Pool threads that spin after each run burn the cores the renderer, or the next detector of a several-
    # method run, needs: six families interleaved on one busy 2-core machine took 167 ms of CPU per frame
    # spinning and 43 ms not. Alone on idle cores a network takes about 0.3-0.7 ms longer (ufld 3.5 ms).
    options.add_session_config_entry("session.intra_op.allow_spinning", "0")
    options.log_severity_level = 3
    return onnxruntime.InferenceSession(str(onnx_path), options, providers=providers())


class LearnedDetector:
    """An ONNX lane detector: ``detector(rgb, h_samples)`` -> TuSimple lanes in the frame's own pixels.

    A model folder with a ``view.json`` (``lanevil adapt --method view``) is shown that window of every frame."""

    def __init__(self, model_dir: str | Path, threads: int = 0) -> None:
        self.model_dir = Path(model_dir)
        self.spec = ModelSpec.load(self.model_dir)
        try:
            self.view = View.load(self.model_dir)
        except ViewError as error:
            raise ModelSpecError(str(error)) from None
        onnx_path = self.model_dir / ONNX_FILE
        if not onnx_path.is_file():
            raise ModelSpecError(f"{self.model_dir}: no {ONNX_FILE}")
        self._session = inference_session(onnx_path, threads)
        self._names = [output.name for output in self._session.get_outputs()]
        self._lock = threading.Lock()  # one run at a time per session keeps the thread pool from oversubscribing

    def outputs(self, rgb: UInt8Array) -> dict[str, FloatArray]:
        """The network's named outputs for one frame (batch of one)."""
        batch = network_input(rgb, self.spec.input_size, self.view)[None]
        with self._lock:
            values = self._session.run(self._names, {"image": batch})
        return dict(zip(self._names, values, strict=True))

    def lines(self, rgb: UInt8Array) -> list[LaneLine | None]:
        """The decoded lane slots of one frame (normalised coordinates of the network's input)."""
        return decode_outputs(self.spec, self.outputs(rgb))

    def __call__(self, rgb: UInt8Array, h_samples: list[int]) -> list[list[int]]:
        height, width = rgb.shape[:2]
        return lanes_of(self.spec, self.lines(rgb), h_samples, (width, height), self.view)


@functools.lru_cache(maxsize=8)
def load_detector(model_dir: str) -> LearnedDetector:
    """A cached ``LearnedDetector`` per model folder (sessions are costly to open)."""
    return LearnedDetector(model_dir)
