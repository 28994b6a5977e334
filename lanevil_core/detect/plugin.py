"""The plug-in detector contract: ``detect(rgb) -> lanes`` with an input-size hint, and the installed plug-ins.

A plug-in is anything with a ``detect`` method (``LaneDetectorPlugin``): it gets an RGB frame and answers polylines
in that frame's pixels (``detect.polylines``). ``input_size`` (width, height), when set, is the size the product
resizes the frame to before calling ``detect`` (the size the model was trained at); the lanes are moved back to the
rendered frame's pixels. ``real_trained`` marks a detector trained on real roads: ``lanevil report`` puts it in the
Real -> LanEvil table.

A Python package adds detectors through the entry-point group ``lanevil.detectors``: each entry point's name is
the detector's name and its object a class (or any callable) that makes the detector with no arguments, e.g. in
``pyproject.toml``::

    [project.entry-points."lanevil.detectors"]
    my-lanes = "my_lanes.detector:MyLaneDetector"

The HTTP and ONNX detectors (``http_detector``, ``onnx_head``) follow the same contract.
"""

from __future__ import annotations

import abc
import functools
import importlib.metadata
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

import cv2
import numpy as np

from ..metrics.formats import LaneFileError
from ..typed import FloatArray, UInt8Array
from .polylines import checked_polylines, polyline_lanes, scaled_polylines

ENTRY_POINT_GROUP = "lanevil.detectors"
Polylines = Sequence[Sequence[Sequence[float]]]  # lanes of [x, y] points, image pixels


@runtime_checkable
class LaneDetectorPlugin(Protocol):
    """What a plug-in detector provides.

    Attributes:
        input_size: (width, height) the frame is resized to before ``detect``, or None for the rendered size.
        real_trained: whether the detector was trained on real roads (reported in the Real -> LanEvil table).
    """

    input_size: tuple[int, int] | None
    real_trained: bool

    def detect(self, rgb: UInt8Array) -> Polylines:
        """Lane polylines ``[[[x, y], ...], ...]`` in ``rgb``'s pixels for one (H, W, 3) uint8 RGB frame."""
        ...


class LaneDetector(abc.ABC):
    """A base class for plug-ins: subclass it, set the class attributes and write ``detect`` (a subclass without it
    cannot be made)."""

    input_size: ClassVar[tuple[int, int] | None] = None
    real_trained: ClassVar[bool] = False

    @abc.abstractmethod
    def detect(self, rgb: UInt8Array) -> Polylines:
        """Lane polylines ``[[[x, y], ...], ...]`` in ``rgb``'s pixels for one (H, W, 3) uint8 RGB frame."""


@dataclass(frozen=True)
class PolylineDetector:
    """A plug-in as the product runs it: ``detector(rgb, h_samples)`` -> TuSimple lanes in the frame's pixels.

    The frame is resized (area filter) to the plug-in's ``input_size`` first, and its lanes moved back.
    """

    name: str
    plugin: Any  # a LaneDetectorPlugin (Protocols with attributes do not check class attributes statically)

    def polylines(self, rgb: UInt8Array) -> list[FloatArray]:
        """The plug-in's lanes on ``rgb``, checked, in ``rgb``'s pixels."""
        height, width = rgb.shape[:2]
        size = getattr(self.plugin, "input_size", None)
        size = (int(size[0]), int(size[1])) if size else (width, height)
        shown = rgb if size == (width, height) else np.asarray(cv2.resize(rgb, size, interpolation=cv2.INTER_AREA))
        try:
            answer = self.plugin.detect(np.ascontiguousarray(shown))
            listed = [[list(point) for point in lane] for lane in answer]
        except LaneFileError:
            raise
        except Exception as error:  # noqa: BLE001 - a failing plug-in is reported in one line, never a crash
            raise LaneFileError(f"detector: {self.name} failed: {type(error).__name__}: {error}") from None
        lanes = checked_polylines({"lanes": listed}, f"detector: {self.name}")
        return scaled_polylines(lanes, size, (width, height))

    def __call__(self, rgb: UInt8Array, h_samples: list[int]) -> list[list[int]]:
        return polyline_lanes(self.polylines(rgb), h_samples, rgb.shape[1])


def _path_state() -> tuple[tuple[str, int], ...]:
    """Each import-path folder with its modification time: installing a package adds a ``*.dist-info`` folder,
    which changes its parent's time."""
    state = []
    for entry in sys.path:
        try:
            state.append((entry, os.stat(entry or ".").st_mtime_ns))
        except OSError:
            continue
    return tuple(state)


@functools.lru_cache(maxsize=4)
def _entry_points(state: tuple[tuple[str, int], ...]) -> dict[str, importlib.metadata.EntryPoint]:
    return {point.name: point for point in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP)}


def entry_points() -> dict[str, importlib.metadata.EntryPoint]:
    """The installed ``lanevil.detectors`` entry points by name. Read again whenever an import-path folder changed
    (a package installed while a server runs is picked up; scanning every distribution takes about 10 ms)."""
    return _entry_points(_path_state())


def entry_point_version(point: importlib.metadata.EntryPoint) -> str:
    """The version of the distribution that installs ``point`` (empty when unknown)."""
    return point.dist.version if point.dist is not None else ""


@functools.lru_cache(maxsize=16)
def _loaded(name: str, value: str, version: str) -> Any:
    point = entry_points().get(name)
    if point is None or point.value != value:
        raise LaneFileError(f"detector: the plug-in {name} is no longer installed")
    try:
        factory = point.load()
        plugin = factory()
    except Exception as error:  # noqa: BLE001 - any failure of third-party code is the plug-in's, said in one line
        raise LaneFileError(f"detector: the plug-in {name} ({value}) cannot be loaded: "
                            f"{type(error).__name__}: {error}") from None
    if not callable(getattr(plugin, "detect", None)):
        raise LaneFileError(f"detector: the plug-in {name} ({value}) has no detect(rgb) method")
    return plugin


def plugin_detector(name: str) -> PolylineDetector:
    """The installed plug-in ``name``, made once per installed version."""
    point = entry_points()[name]
    return PolylineDetector(name, _loaded(name, point.value, entry_point_version(point)))
