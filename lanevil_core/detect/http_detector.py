"""A detector served over HTTP: the frame POSTed as PNG, the lanes read back as JSON.

The product sends ``POST URL`` with the frame as a PNG body (``Content-Type: image/png``; resized first to the
detector's ``input_size`` when one is configured) and expects ``200`` with a JSON object
``{"lanes": [[[x, y], ...], ...], "scores": [...]}`` (``scores`` optional) in the posted image's pixels
(``detect.polylines``). So a detector runs in its own environment (its framework, its CUDA) and the product needs
none of it.

A connection failure, a timeout or a 5xx answer is tried again ``retries`` times (after 0.2 s, 0.4 s, ...); a 4xx
answer or a body that is not such JSON fails at once. Every failure is a ``LaneFileError`` whose one line names the
detector, its URL and what went wrong. At most ``concurrency`` requests run at once per detector; a caller waits
for a free place at most the time one request may take.
"""

from __future__ import annotations

import json
import threading
import time
import urllib.error
import urllib.request
from dataclasses import dataclass, field
from typing import Any

import cv2
import numpy as np

from ..metrics.formats import LaneFileError
from ..typed import FloatArray, UInt8Array
from .polylines import checked_polylines

RETRY_PAUSE_S = 0.2
MAX_ANSWER_BYTES = 16 * 1024 * 1024  # a lane answer is a few kB; a larger body is not one


def png_body(rgb: UInt8Array) -> bytes:
    """PNG bytes of an (H, W, 3) uint8 RGB frame."""
    ok, encoded = cv2.imencode(".png", np.ascontiguousarray(rgb[..., ::-1]))
    if not ok:
        raise LaneFileError("detector: the frame cannot be encoded as PNG")
    return bytes(encoded)


class _Retry(Exception):
    """A failure worth another try (the server is down, slow or failing)."""


@dataclass
class HttpLaneDetector:
    """A lane detector behind ``url`` (a ``LaneDetectorPlugin``: ``detect(rgb)`` -> polylines).

    Attributes:
        name: the detector's name, used in error messages.
        url: ``http://HOST:PORT/PATH`` (or https) the frames are POSTed to.
        input_size: (width, height) frames are resized to before posting, or None.
        real_trained: whether the detector was trained on real roads.
        timeout_s: seconds one request may take (connect and answer).
        retries: further tries after a connection failure, a timeout or a 5xx answer.
        concurrency: requests at most in flight at once to this detector.
    """

    name: str
    url: str
    input_size: tuple[int, int] | None = None
    real_trained: bool = False
    timeout_s: float = 10.0
    retries: int = 1
    concurrency: int = 1
    _slots: threading.BoundedSemaphore = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._slots = threading.BoundedSemaphore(self.concurrency)

    @property
    def where(self) -> str:
        """How errors name the detector: its name and URL (the URL once when it is its own name)."""
        return f"detector: {self.name}" if self.name == self.url else f"detector: {self.name} ({self.url})"

    def detect(self, rgb: UInt8Array) -> list[FloatArray]:
        """The server's lanes on ``rgb`` (the image it was sent), checked; raises ``LaneFileError`` on failure."""
        body = png_body(rgb)
        if not self._slots.acquire(timeout=self.timeout_s * (self.retries + 1)):
            raise LaneFileError(f"{self.where}: busy ({self.concurrency} requests in flight did not end in time)")
        try:
            return checked_polylines(self._answer(body), self.where)
        finally:
            self._slots.release()

    def _answer(self, body: bytes) -> Any:
        failure = ""
        for attempt in range(self.retries + 1):
            if attempt:
                time.sleep(RETRY_PAUSE_S * attempt)
            try:
                return self._post(body)
            except _Retry as error:
                failure = str(error)
        tries = self.retries + 1
        raise LaneFileError(f"{self.where}: {failure} (after {tries} {'try' if tries == 1 else 'tries'})")

    def _post(self, body: bytes) -> Any:
        request = urllib.request.Request(self.url, data=body, method="POST",
                                         headers={"Content-Type": "image/png", "Accept": "application/json"})
        try:
            with urllib.request.urlopen(request, timeout=self.timeout_s) as response:  # noqa: S310 - configured URL
                data = response.read(MAX_ANSWER_BYTES + 1)
        except urllib.error.HTTPError as error:
            detail = error.read(300).decode("utf-8", "replace").strip().replace("\n", " ")
            message = f"answered HTTP {error.code}" + (f": {detail}" if detail else "")
            if error.code >= 500:
                raise _Retry(message) from None
            raise LaneFileError(f"{self.where}: {message}") from None
        except TimeoutError:
            raise _Retry(f"no answer within {self.timeout_s:g} s") from None
        except urllib.error.URLError as error:
            reason = error.reason
            if isinstance(reason, TimeoutError):
                raise _Retry(f"no answer within {self.timeout_s:g} s") from None
            raise _Retry(f"cannot connect ({reason})") from None
        except OSError as error:  # a connection reset or refused while reading
            raise _Retry(f"connection failed ({error})") from None
        if len(data) > MAX_ANSWER_BYTES:
            raise LaneFileError(f"{self.where}: the answer is over {MAX_ANSWER_BYTES // (1024 * 1024)} MiB")
        try:
            return json.loads(data)
        except (UnicodeDecodeError, json.JSONDecodeError):
            start = data[:60].decode("utf-8", "replace").replace("\n", " ")
            raise LaneFileError(f"{self.where}: the answer is not JSON ({start!r})") from None
