"""Pixels in and out (lanevil_core.images): lossless PNG whose bytes depend on the pixels alone, encoders by
format, image files read back, the sRGB transfer curve."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from lanevil_core.case import Case
from lanevil_core.images import (
    FILE_JPEG_QUALITY,
    encode_image,
    jpeg_bytes,
    linear_to_srgb,
    png_bytes,
    read_rgb,
    srgb_to_linear,
)
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


def test_encode_image_picks_the_encoder_by_format_with_the_given_quality(rendered):
    assert encode_image(rendered, "png", FILE_JPEG_QUALITY) == png_bytes(rendered)
    assert encode_image(rendered, "jpg", 90) == jpeg_bytes(rendered, 90) != jpeg_bytes(rendered, FILE_JPEG_QUALITY)
    with pytest.raises(ValueError, match="unknown image format 'bmp' \\(choose from png, jpg\\)"):
        encode_image(rendered, "bmp", FILE_JPEG_QUALITY)


def test_read_rgb_reads_what_was_written_and_names_an_unreadable_file(rendered, tmp_path):
    path = tmp_path / "frame.png"
    path.write_bytes(png_bytes(rendered))
    np.testing.assert_array_equal(read_rgb(path), rendered)
    (tmp_path / "broken.png").write_bytes(b"not an image")
    with pytest.raises(KeyError, match="broken.png: cannot read the image"):
        read_rgb(tmp_path / "broken.png", error=KeyError)


def test_srgb_transfer_round_trips_and_meets_its_reference_points():
    encoded = np.linspace(0.0, 1.0, 1001)
    np.testing.assert_allclose(linear_to_srgb(srgb_to_linear(encoded)), encoded, atol=1e-12)
    assert srgb_to_linear(0.5) == pytest.approx(0.21404, abs=1e-5)  # mid-grey byte 128 is 21 % of white's light
    assert linear_to_srgb(1.5) == pytest.approx(1.0) and linear_to_srgb(-0.5) == 0.0  # clipped to [0, 1] first
