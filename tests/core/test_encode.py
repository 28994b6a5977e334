"""Image encoders: lossless PNG whose bytes depend on the pixels alone."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from lanevil_core.case import Case
from lanevil_core.export.encode import png_bytes
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.typed import UInt8Array


@pytest.fixture(scope="module")
def rendered() -> UInt8Array:
    """A real frame: road, paint, objects, shadows and sky."""
    return render_frame(compile_scene(Case()), 5, (320, 180)).rgb


def test_png_is_lossless(rendered):
    decoded = np.asarray(Image.open(io.BytesIO(png_bytes(rendered))).convert("RGB"))
    np.testing.assert_array_equal(decoded, rendered)


def test_same_frame_gives_same_bytes(rendered):
    data = png_bytes(rendered)
    assert png_bytes(rendered.copy()) == data
    assert png_bytes(np.asfortranarray(rendered)) == data  # memory layout does not matter
    wider = np.zeros((180, 330, 3), np.uint8)
    wider[:, 5:325] = rendered
    assert png_bytes(wider[:, 5:325]) == data  # nor does a strided view


def test_different_frames_give_different_bytes(rendered):
    changed = rendered.copy()
    changed[90, 160] ^= 1
    assert png_bytes(changed) != png_bytes(rendered)


@pytest.mark.parametrize("shape", [(1, 1, 3), (1, 2, 3), (2, 1, 3), (9, 7, 3)])
def test_png_decodes_the_same_in_two_independent_readers(shape):
    import cv2

    image = np.random.default_rng(sum(shape)).integers(0, 256, shape, dtype=np.uint8)
    data = png_bytes(image)
    np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(data)).convert("RGB")), image)
    np.testing.assert_array_equal(cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)[..., ::-1], image)


def test_png_refuses_other_than_rgb():
    with pytest.raises(ValueError, match="RGB"):
        png_bytes(np.zeros((4, 4, 4), np.uint8))
