"""Rendering for the web front ends: one service, content-addressed LRU caches, no duplicate work.

Every image the API, the demo site, the editor and the study serve comes from ``FrameService``. A request is keyed
by the SHA-256 of the canonical case JSON plus frame, size, overlay and detector, so equal requests never render
twice, and an edited case never gets a stale picture. Compiled scenes are cached too (scrubbing frames of one case
compiles once), and so are a detector's lanes on a frame (next to the frame, keyed by its key plus the detector's
version). Concurrent requests for the same key wait for the one render in flight.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Generic, TypeVar

import numpy as np
from pydantic.fields import FieldInfo

from lanevil_core.case import Case, case_json
from lanevil_core.detect.catalog import available_detector
from lanevil_core.detect.frame_detection import FrameDetection, detect_frame
from lanevil_core.illusions import REGISTRY
from lanevil_core.images import ImageFormat, encode_image
from lanevil_core.labels.lanes import CULANE_SIZE, culane_lines, tusimple_record
from lanevil_core.labels.overlay import draw_detections, draw_lanes
from lanevil_core.library.benchmark_layout import frame_file
from lanevil_core.pipeline.compile import compile_scene, roadside_key
from lanevil_core.render import all_cores, render_frame
from lanevil_core.world.scene import CompiledScene

from .memory import release_free_memory
from .settings import FRAME_CACHE_BYTES, MAX_RENDER_QUEUE, MAX_RENDERS, SCENE_CACHE_BYTES

MEDIA_TYPES: dict[str, str] = {"png": "image/png", "jpg": "image/jpeg"}
JPEG_QUALITY = 90  # frames served over HTTP (files on disk: images.FILE_JPEG_QUALITY)
CULANE_CACHE_ENTRIES = 2048  # label texts are small (< 1 kB)
DETECTION_CACHE_ENTRIES = 4096  # a frame's lanes: a few kB

K = TypeVar("K", bound=Hashable)
V = TypeVar("V")


class LRUCache(Generic[K, V]):
    """A thread-safe LRU map bounded by the summed ``weigh(value)`` (bytes, or 1 per entry)."""

    def __init__(self, budget: int, weigh: Callable[[V], int] = lambda value: 1) -> None:
        self.budget = budget
        self._weigh = weigh
        self._items: OrderedDict[K, tuple[V, int]] = OrderedDict()
        self._total = 0
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    def get(self, key: K) -> V | None:
        with self._lock:
            item = self._items.get(key)
            if item is None:
                self.misses += 1
                return None
            self._items.move_to_end(key)
            self.hits += 1
            return item[0]

    def put(self, key: K, value: V) -> None:
        weight = self._weigh(value)
        with self._lock:
            if key in self._items:
                self._total -= self._items.pop(key)[1]
            if weight > self.budget:
                return
            self._items[key] = (value, weight)
            self._total += weight
            while self._total > self.budget:
                self._total -= self._items.popitem(last=False)[1][1]

    def reweigh(self, key: K) -> None:
        """Weigh ``key``'s value again (it grew since ``put``) and evict down to the budget."""
        with self._lock:
            item = self._items.get(key)
            if item is None:
                return
            weight = self._weigh(item[0])
            self._total += weight - item[1]
            self._items[key] = (item[0], weight)
            while self._total > self.budget and self._items:
                self._total -= self._items.popitem(last=False)[1][1]

    def __len__(self) -> int:
        return len(self._items)

    @property
    def total(self) -> int:
        return self._total


class RenderBusy(RuntimeError):
    """Every render slot is taken and ``MAX_RENDER_QUEUE`` requests wait already: come back after ``retry_after_s``."""

    def __init__(self, waiting: int, retry_after_s: int) -> None:
        super().__init__(f"{waiting} frames are waiting to render: try again in {retry_after_s} s")
        self.retry_after_s = retry_after_s


class RenderSlots:
    """At most ``slots`` renders at once; a thread already holding a slot re-enters freely (a frame's render may
    compile its scene); more than ``max_waiting`` threads waiting -> ``RenderBusy``."""

    def __init__(self, slots: int = MAX_RENDERS, max_waiting: int = MAX_RENDER_QUEUE) -> None:
        self.slots = slots
        self.max_waiting = max_waiting
        self._semaphore = threading.BoundedSemaphore(slots)
        self._lock = threading.Lock()
        self._held = threading.local()
        self.waiting = 0

    @contextmanager
    def hold(self) -> Iterator[None]:
        if getattr(self._held, "depth", 0):
            self._held.depth += 1
            try:
                yield
            finally:
                self._held.depth -= 1
            return
        with self._lock:
            if self.waiting >= self.max_waiting:
                raise RenderBusy(self.waiting, retry_after_s=max(1, self.waiting // self.slots))
            self.waiting += 1
        try:
            self._semaphore.acquire()
        finally:
            with self._lock:
                self.waiting -= 1
        self._held.depth = 1
        try:
            yield
        finally:
            self._held.depth = 0
            self._semaphore.release()
            release_free_memory()  # what the compile and render freed goes back to the system (memory.py)


def case_hash(case: Case) -> str:
    """SHA-256 (hex) of the canonical case JSON: the identity of everything rendered from it."""
    return hashlib.sha256(case_json(case).encode("utf-8")).hexdigest()


def camera_size(case: Case) -> tuple[int, int]:
    """(width, height) of the case camera: the size a frame renders at unless asked otherwise."""
    return case.camera.width, case.camera.height


def apply_overrides(case: Case, severity: int | None = None, sun_azimuth: float | None = None,
                    sun_altitude: float | None = None, sun_intensity: float | None = None) -> Case:
    """A copy of ``case`` with every illusion at ``severity`` and/or the sun moved (for scrubbing without saving).

    Values are validated by the case model: an out-of-range override raises ``pydantic.ValidationError``.
    Illusions that place the sun themselves (the shadow types' ``sun_*`` fields) get the sun override too, clamped
    to their own ranges, so a sun slider moves their shadows; the others keep the sun their severity table sets.
    """
    data: dict[str, Any] = case.model_dump(mode="json")
    sun = {"azimuth": sun_azimuth, "altitude": sun_altitude, "intensity": sun_intensity}
    for illusion in data["illusions"]:
        if severity is not None:
            illusion["severity"] = severity
        fields = REGISTRY[illusion["type"]].model_fields
        for name, value in sun.items():
            field = fields.get(f"sun_{name}")
            if value is not None and field is not None:
                illusion[f"sun_{name}"] = _clamp_to_field(value, field)
    for name, value in sun.items():
        if value is not None:
            data["sun"][name] = value
    return Case.model_validate(data)


def _clamp_to_field(value: float, field: FieldInfo) -> float:
    """``value`` clamped to a pydantic field's ``ge``/``le`` bounds."""
    for bound in field.metadata:
        if getattr(bound, "ge", None) is not None:
            value = max(value, bound.ge)
        if getattr(bound, "le", None) is not None:
            value = min(value, bound.le)
    return value


def encode(rgb: np.ndarray, fmt: ImageFormat) -> bytes:
    """PNG (no metadata, deterministic) or baseline JPEG bytes of an (H, W, 3) uint8 image."""
    return encode_image(rgb, fmt, JPEG_QUALITY)


@dataclass(frozen=True)
class RenderedFrame:
    """A rendered frame (overlay applied if asked) and its TuSimple record, at the size it was rendered."""

    rgb: np.ndarray
    record: dict[str, Any]
    key: str


@dataclass(frozen=True)
class EncodedImage:
    """Image bytes for an HTTP response; ``etag`` is the content key."""

    data: bytes
    media_type: str
    etag: str


class FrameService:
    """Renders frames of cases through ``lanevil_core``, caching compiled scenes, frames and encodings."""

    def __init__(self, cache_bytes: int = FRAME_CACHE_BYTES, threads: int = 0, meshes_dir: Path | None = None,
                 scene_cache_bytes: int = SCENE_CACHE_BYTES, max_renders: int = MAX_RENDERS,
                 max_render_queue: int = MAX_RENDER_QUEUE) -> None:
        self.meshes_dir = meshes_dir  # where a vehicle's ``mesh_file`` is read from
        self.threads = threads or all_cores()  # one frame's row bands on every core (0): a request waits on one frame
        self.slots = RenderSlots(max_renders, max_render_queue)
        # Scenes and the roadsides reused from them are bounded by their arrays' bytes.
        self.scenes: LRUCache[str, CompiledScene] = LRUCache(scene_cache_bytes, CompiledScene.nbytes)
        self.roadsides: LRUCache[str, CompiledScene] = LRUCache(scene_cache_bytes // 2, CompiledScene.nbytes)
        self.frames: LRUCache[str, RenderedFrame] = LRUCache(cache_bytes // 2, lambda item: item.rgb.nbytes)
        self.images: LRUCache[str, EncodedImage] = LRUCache(cache_bytes // 2, lambda item: len(item.data))
        self.culane: LRUCache[str, str] = LRUCache(CULANE_CACHE_ENTRIES)
        self.detections: LRUCache[str, FrameDetection] = LRUCache(DETECTION_CACHE_ENTRIES)
        self._inflight: dict[str, threading.Lock] = {}
        self._inflight_lock = threading.Lock()
        self.renders = 0  # frames actually rendered (not served from a cache)
        self.full_compiles = 0  # scenes compiled from scratch
        self.partial_compiles = 0  # scenes that reused a recent scene's road and roadside
        self.detector_runs = 0  # detections actually run (not served from the cache)

    def _single_flight(self, key: str) -> threading.Lock:
        with self._inflight_lock:
            return self._inflight.setdefault(key, threading.Lock())

    def _release(self, key: str) -> None:
        with self._inflight_lock:
            self._inflight.pop(key, None)

    def scene(self, case: Case) -> CompiledScene:
        """The compiled scene of ``case`` (cached by content hash); a case that differs from a recent one only in
        sun, weather or illusions reuses that one's road and roadside (``compile_scene(case, reuse=...)``)."""
        key = case_hash(case)
        scene = self.scenes.get(key)
        if scene is None:
            side_key = roadside_key(case)
            reuse = self.roadsides.get(side_key)
            with self.slots.hold():
                scene = compile_scene(case, reuse=reuse, meshes_dir=self.meshes_dir)
            if reuse is None:
                self.full_compiles += 1
            else:
                self.partial_compiles += 1
            self.scenes.put(key, scene)
            # Without the renderer's cache (packed arrays, shadow cascades: tens of MB once frames are drawn), which
            # a reuse never reads: what the roadside cache keeps is what it weighed.
            self.roadsides.put(side_key, replace(scene, cache={}))
        return scene

    @staticmethod
    def frame_key(case: Case, index: int, size: tuple[int, int] | None = None, overlay: bool = False,
                  detector: str | None = None) -> str:
        """Cache key of a rendered frame: case content hash, frame, size (default: the camera's), overlay, and the
        version of the detector whose lanes are drawn (``detector_catalog.detector_version``), if any."""
        width, height = size or camera_size(case)
        key = f"{case_hash(case)}:{index}:{width}x{height}:{int(overlay)}"
        return f"{key}:{available_detector(detector).version}" if detector else key

    def image_etag(self, case: Case, index: int, size: tuple[int, int] | None = None, overlay: bool = False,
                   fmt: ImageFormat = "png", detector: str | None = None) -> str:
        """The ETag ``image(...)`` will carry, known without rendering (so a 304 costs no render)."""
        key = f"{self.frame_key(case, index, size, overlay, detector)}:{fmt}"
        return hashlib.sha256(key.encode("ascii")).hexdigest()[:32]

    def frame(self, case: Case, index: int, size: tuple[int, int] | None = None,
              overlay: bool = False, detector: str | None = None) -> RenderedFrame:
        """Frame ``index`` of ``case`` at ``size`` (default: the case camera's), lane overlay drawn if asked, and
        the lanes of ``detector`` (a name of ``detect.registry.detector_names()``) drawn in the detection colour if
        given.

        Raises ``LaneFileError`` (message starting ``detector:``) for an unknown or unavailable detector."""
        if not 0 <= index < case.ego.frames:
            raise IndexError(f"frame {index} is outside 0..{case.ego.frames - 1}")
        key = self.frame_key(case, index, size, overlay, detector)
        cached = self.frames.get(key)
        if cached is not None:
            return cached
        lock = self._single_flight(key)
        with lock:
            cached = self.frames.get(key)
            if cached is None:
                cached = self._render(case, index, size or camera_size(case), overlay, detector, key)
                self.frames.put(key, cached)
        self._release(key)
        return cached

    def detection(self, case: Case, index: int, size: tuple[int, int] | None = None,
                  detector: str = "ufld") -> FrameDetection:
        """``detector``'s lanes on the plain frame (no overlay) and their TuSimple score against its labels
        (cached next to the frame). Raises ``LaneFileError`` for an unknown or unavailable detector."""
        key = f"{self.frame_key(case, index, size, False, detector)}:lanes"
        cached = self.detections.get(key)
        if cached is not None:
            return cached
        plain = self.frame(case, index, size)
        lock = self._single_flight(key)
        with lock:
            cached = self.detections.get(key)
            if cached is None:
                with self.slots.hold():
                    cached = detect_frame(detector, np.asarray(plain.rgb), plain.record)
                self.detector_runs += 1
                self.detections.put(key, cached)
        self._release(key)
        return cached

    def draft(self, case: Case, index: int, size: tuple[int, int], overlay: bool = False) -> RenderedFrame:
        """A quick look at frame ``index`` of ``case`` at ``size``: the same compiled scene, lens and bonnet, but
        without the camera's sensor stage (auto-exposure, motion blur, noise, sharpening), so colours differ from
        ``frame``'s where the case has a sensor. For the editor's draft quality while a slider moves; cached apart
        from exact frames (its key ends in ``:draft``)."""
        key = f"{self.frame_key(case, index, size, overlay)}:draft"
        cached = self.frames.get(key)
        if cached is not None:
            return cached
        with self.slots.hold():
            scene = self.scene(case)
            # The same scene (and its renderer cache: packed triangles, shadow maps) seen by a camera without sensor.
            ego = replace(scene.ego, mount=scene.ego.mount.model_copy(update={"sensor": None}))
            frame = render_frame(replace(scene, ego=ego), index, size, threads=self.threads)
            self.renders += 1
            record = tusimple_record(scene, index, frame, raw_file=frame_file(index))
        rgb = draw_lanes(frame.rgb, record) if overlay else np.ascontiguousarray(frame.rgb)
        rgb.setflags(write=False)
        drafted = RenderedFrame(rgb, record, key)
        self.frames.put(key, drafted)
        return drafted

    def _render(self, case: Case, index: int, size: tuple[int, int], overlay: bool, detector: str | None,
                key: str) -> RenderedFrame:
        if detector:  # detected lanes as bands on the plain frame, the labels' dots (if asked) on top of them
            plain = self.frame(case, index, size)
            found = self.detection(case, index, size, detector)
            rgb = draw_detections(plain.rgb, found.lanes, found.h_samples)
            return RenderedFrame(draw_lanes(rgb, plain.record) if overlay else rgb, plain.record, key)
        if overlay:  # the overlay is drawn on the plain frame, which is then cached too
            plain = self.frame(case, index, size, overlay=False)
            return RenderedFrame(draw_lanes(plain.rgb, plain.record), plain.record, key)
        with self.slots.hold():
            scene = self.scene(case)
            frame = render_frame(scene, index, size, threads=self.threads)
            self.renders += 1
            record = tusimple_record(scene, index, frame, raw_file=frame_file(index))
        self.scenes.reweigh(case_hash(case))  # the first render packed the scene's arrays into its cache
        rgb = np.ascontiguousarray(frame.rgb)
        rgb.setflags(write=False)
        return RenderedFrame(rgb, record, key)

    def image(self, case: Case, index: int, size: tuple[int, int] | None = None, overlay: bool = False,
              fmt: ImageFormat = "png", detector: str | None = None) -> EncodedImage:
        """Encoded bytes of ``frame(...)``, cached by the same key plus the format."""
        key = f"{self.frame_key(case, index, size, overlay, detector)}:{fmt}"
        cached = self.images.get(key)
        if cached is None:
            rendered = self.frame(case, index, size, overlay, detector)
            etag = self.image_etag(case, index, size, overlay, fmt, detector)
            cached = EncodedImage(encode(rendered.rgb, fmt), MEDIA_TYPES[fmt], etag)
            self.images.put(key, cached)
        return cached

    def culane_lines(self, case: Case, index: int) -> str:
        """CULane ``.lines.txt`` text of frame ``index``, from a render at ``CULANE_SIZE`` (cached)."""
        if not 0 <= index < case.ego.frames:
            raise IndexError(f"frame {index} is outside 0..{case.ego.frames - 1}")
        key = f"{case_hash(case)}:{index}:culane"
        lines = self.culane.get(key)
        if lines is None:
            with self.slots.hold():
                scene = self.scene(case)
                lines = culane_lines(scene, render_frame(scene, index, CULANE_SIZE, threads=self.threads))
                self.renders += 1
            self.culane.put(key, lines)
        return lines
