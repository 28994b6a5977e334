"""The live preview: one background thread that always renders the newest requested state.

GUI callbacks call ``request`` (cheap, never blocks on rendering). The worker takes the newest request, renders
it, publishes the image, and repeats while newer requests exist; requests that arrive while a render is running
replace each other, so a dragged slider costs at most one render behind the user and the last image shown is
always that of the latest state.

Quality ``draft`` (the panel's Quality, per tab) renders each request at ``DRAFT_SIZE`` without the camera's sensor
stage first, then, once no newer request has come for ``REFINE_AFTER_S``, the exact frame of the same state: a
dragged slider shows quick drafts and comes to rest on the exact frame. ``full`` renders only exact frames.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from lanevil_core.case import Case
from lanevil_core.world.scene import CompiledScene

PREVIEW_SIZE = (640, 360)
DRAFT_SIZE = (320, 180)  # half the preview's width and height: a quarter of its pixels
REFINE_AFTER_S = 0.25  # a draft is followed by the exact frame once its state has rested this long
Quality = Literal["draft", "full"]
QUALITIES: tuple[Quality, ...] = ("draft", "full")


@dataclass(frozen=True)
class PreviewRequest:
    """What to show: a case at a frame, with or without the lane overlay and a detector's lanes; ``draft``: the
    quick look (``DRAFT_SIZE``, no sensor stage, no detector) rather than the exact frame."""

    case: Case
    frame: int
    overlay: bool
    size: tuple[int, int] = PREVIEW_SIZE
    seq: int = 0
    requested_at: float = field(default_factory=time.perf_counter)
    detector: str | None = None
    draft: bool = False


@dataclass(frozen=True)
class PreviewResult:
    """A rendered preview and how long it took from the request to the push."""

    request: PreviewRequest
    rgb: np.ndarray
    scene: CompiledScene
    render_ms: float
    latency_ms: float


Renderer = Callable[[PreviewRequest], tuple[np.ndarray, CompiledScene]]
Publisher = Callable[[PreviewResult], None]
ErrorHandler = Callable[[PreviewRequest, Exception], None]


class PreviewWorker:
    """A single thread rendering the newest ``PreviewRequest`` and handing it to ``publish``."""

    def __init__(self, render: Renderer, publish: Publisher, on_error: ErrorHandler) -> None:
        self._render = render
        self._publish = publish
        self._on_error = on_error
        self._cond = threading.Condition()
        self._pending: PreviewRequest | None = None
        self._refine: PreviewRequest | None = None  # the exact frame owed after the last draft
        self._refine_at = 0.0  # perf_counter time from which it may start
        self._seq = 0
        self._done_seq = 0
        self._busy = False
        self._stopped = False
        self.dropped = 0  # requests replaced by a newer one before they were rendered
        self._thread = threading.Thread(target=self._run, name="lanevil-editor-preview", daemon=True)
        self._thread.start()

    def request(self, case: Case, frame: int, overlay: bool, size: tuple[int, int] = PREVIEW_SIZE,
                detector: str | None = None, quality: Quality = "full") -> int:
        """Ask for a preview of this state (``draft``: a draft first, the exact frame once it rests); returns its
        sequence number."""
        if quality not in QUALITIES:
            raise ValueError(f"quality: {quality!r} is not one of {', '.join(QUALITIES)}")
        with self._cond:
            self._seq += 1
            if self._pending is not None:
                self.dropped += 1
            self._pending = PreviewRequest(case, frame, overlay, size, self._seq, detector=detector,
                                           draft=quality == "draft")
            self._refine = None
            self._cond.notify_all()
            return self._seq

    @property
    def latest_seq(self) -> int:
        return self._seq

    def wait_idle(self, timeout: float = 30.0) -> bool:
        """Block until every request so far has been rendered and published (or failed); False on timeout."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while self._pending is not None or self._refine is not None or self._busy:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._cond.wait(remaining)
            return True

    def stop(self) -> None:
        with self._cond:
            self._stopped = True
            self._cond.notify_all()
        self._thread.join(timeout=10)

    def _next(self) -> PreviewRequest | None:
        """The newest request, else the exact frame owed after a draft once it is due; None once stopped."""
        with self._cond:
            while not self._stopped:
                if self._pending is not None:
                    request, self._pending = self._pending, None
                    break
                if self._refine is not None and time.perf_counter() >= self._refine_at:
                    request, self._refine = self._refine, None
                    break
                self._cond.wait(None if self._refine is None else max(self._refine_at - time.perf_counter(), 0.0))
            else:
                return None
            self._busy = True
            return request

    def _run(self) -> None:
        while (request := self._next()) is not None:
            shown = False
            try:
                started = time.perf_counter()
                rgb, scene = self._render(request)
                render_ms = (time.perf_counter() - started) * 1000.0
                latency_ms = (time.perf_counter() - request.requested_at) * 1000.0
                self._publish(PreviewResult(request, rgb, scene, render_ms, latency_ms))
                shown = True
            except Exception as error:  # noqa: BLE001 - a bad state is reported in the panel, the worker lives on
                self._on_error(request, error)
            with self._cond:
                self._busy = False
                self._done_seq = request.seq
                if shown and request.draft and self._pending is None:
                    self._refine = replace(request, draft=False)
                    self._refine_at = time.perf_counter() + REFINE_AFTER_S
                self._cond.notify_all()
