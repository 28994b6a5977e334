"""The work of one render task, run inside a worker (a pool process, a Dask worker or the calling process).

A task's frames are rendered one after another while a background thread encodes (PNG compression or JPEG) and
hashes the previous frame, so the encoder overlaps the next render. Results go back to the caller as bytes; the
caller alone writes files, so workers need no shared file system.
"""

from __future__ import annotations

import functools
import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

from ..case import case_json, parse_case
from ..images import FILE_JPEG_QUALITY
from ..images import encode_image as encode_as
from ..labels.lanes import tusimple_record
from ..library.benchmark_layout import frame_file
from ..pipeline.compile import compile_scene, roadside_key
from ..render import render_frame
from ..typed import BoolArray, UInt8Array
from ..world.scene import CompiledScene
from .plan import FORMATS, RenderTask

SCENE_CACHE_SIZE = 2  # compiled scenes kept per process: consecutive chunks of a case (and of the same case
# without its illusion, which test records are measured against) compile it once


@dataclass(frozen=True)
class FrameResult:
    """One rendered frame: its index, encoded file bytes and their sha256, and its TuSimple record."""

    frame: int
    file_name: str
    data: bytes
    sha256: str
    record: dict[str, Any]


TaskDone = Callable[[RenderTask, list[FrameResult]], None]  # called in the caller's process per finished task


def encode_image(rgb: UInt8Array, image_format: str) -> bytes:
    """PNG or JPEG (``FILE_JPEG_QUALITY``, 4:2:0) bytes with no metadata: same pixels, same bytes."""
    return encode_as(rgb, image_format, FILE_JPEG_QUALITY)


def _encode_and_hash(rgb: UInt8Array, image_format: str) -> tuple[bytes, str]:
    data = encode_image(rgb, image_format)
    return data, hashlib.sha256(data).hexdigest()


_SCENES: OrderedDict[str, CompiledScene] = OrderedDict()
_SCENES_LOCK = threading.Lock()  # a Dask worker may run several tasks on threads of one process


def compiled_scene(case_text: str, case_sha256: str) -> CompiledScene:
    """The compiled scene of a case, from this process's small LRU cache keyed by the case hash; a case compiled
    anew takes the road network and roadside of a cached scene with the same ``roadside_key`` (every level of a
    type folder and its original share them), as the editor does for an edit."""
    with _SCENES_LOCK:
        scene = _SCENES.pop(case_sha256, None)
        cached = list(_SCENES.values())
    if scene is None:
        case = parse_case(case_text)
        key = roadside_key(case)
        scene = compile_scene(case, next((s for s in reversed(cached) if roadside_key(s.case) == key), None))
    with _SCENES_LOCK:
        _SCENES[case_sha256] = scene
        while len(_SCENES) > SCENE_CACHE_SIZE:
            _SCENES.popitem(last=False)
    return scene


def frame_record(scene: CompiledScene, task: RenderTask, frame_index: int, frame: Any) -> dict[str, Any]:
    """The TuSimple record of a rendered frame (``raw_file`` relative to the split folder) plus the task's extras."""
    raw_file = f"{task.folder}/{frame_file(frame_index, FORMATS[task.image_format])}"
    return {**tusimple_record(scene, frame_index, frame, raw_file), **task.extras}


CLEAN_VIEWS_KEPT = 256  # small renders of originals (40 kB each): every level of a type folder is measured
_CLEAN_VIEWS: OrderedDict[tuple[str, int, tuple[int, int]], tuple[UInt8Array, BoolArray]] = OrderedDict()
# against the same original at the same frames, so a worker renders each of those once


def _cached_clean_view(case_sha256: str, scene: CompiledScene, frame_index: int,
                       size: tuple[int, int]) -> tuple[UInt8Array, BoolArray]:
    from ..pipeline.illusion_effect import clean_view

    key = (case_sha256, frame_index, size)
    with _SCENES_LOCK:
        found = _CLEAN_VIEWS.get(key)
        if found is not None:
            _CLEAN_VIEWS.move_to_end(key)
            return found
    view = clean_view(scene, frame_index, size)
    with _SCENES_LOCK:
        _CLEAN_VIEWS[key] = view
        while len(_CLEAN_VIEWS) > CLEAN_VIEWS_KEPT:
            _CLEAN_VIEWS.popitem(last=False)
    return view


def illusion_changes(task: RenderTask, scene: CompiledScene) -> dict[int, dict[str, float]]:
    """Per frame of a case with an illusion (compiled: ``scene``): the share of the lane band it changes and its
    effect there (``illusion_effect``, measured on small renders against the case without its illusions)."""
    from ..pipeline.illusion_effect import SHARE_SIZE, clean_of, scene_changes

    case = parse_case(task.case_text)
    if not case.illusions:
        return {}
    clean_text = case_json(clean_of(case))
    clean_sha256 = hashlib.sha256(clean_text.encode("utf-8")).hexdigest()
    clean = compiled_scene(clean_text, clean_sha256)
    changes = scene_changes(clean, scene, task.frames, SHARE_SIZE, functools.partial(_cached_clean_view, clean_sha256))
    return {frame: {"illusion_share": round(change.share, 4), "illusion_effect": round(change.effect, 3)}
            for frame, change in zip(task.frames, changes, strict=True)}


WARM_UP_SIZE = (32, 18)


def warm_up() -> None:
    """Load the renderer's cached kernels in this process (a tiny frame of the default case), so a worker started
    ahead of its first task is ready when it comes."""
    from ..case import Case

    render_frame(compile_scene(Case()), 0, WARM_UP_SIZE)


def render_chunk(task: RenderTask) -> list[FrameResult]:
    """Render, label and encode the task's frames (encoding of frame k overlaps rendering of frame k + 1)."""
    scene = compiled_scene(task.case_text, task.case_sha256)
    suffix = FORMATS[task.image_format]
    changes = illusion_changes(task, scene) if task.split == "test" else {}
    pending: list[tuple[int, dict[str, Any], Future[tuple[bytes, str]]]] = []
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="lanevil-encode") as encoder:
        for frame_index in task.frames:
            frame = render_frame(scene, frame_index, task.size)
            record = {**frame_record(scene, task, frame_index, frame), **changes.get(frame_index, {})}
            pending.append((frame_index, record, encoder.submit(_encode_and_hash, frame.rgb, task.image_format)))
        results = []
        for frame_index, record, future in pending:
            data, digest = future.result()
            results.append(FrameResult(frame_index, frame_file(frame_index, suffix), data, digest, record))
    return results
