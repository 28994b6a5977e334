"""Realism statistics on synthetic images with known properties, and ``lanevil realism`` end to end."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from lanevil_core import cli
from lanevil_core.metrics.realism import (
    STATISTICS,
    RealismError,
    analysis_image,
    edge_density,
    folder_statistics,
    frame_statistics,
    image_files,
    noise_sigma,
    sharpness,
    spectrum_slope,
    summary,
)
from lanevil_core.report.realism import verdict

HEIGHT, WIDTH = 720, 1280  # the analysis size, so no resize blurs the synthetic properties


def gray_rgb(gray: np.ndarray) -> np.ndarray:
    """(H, W) grey -> (H, W, 3) uint8 RGB."""
    return np.repeat(np.clip(np.round(gray), 0, 255).astype(np.uint8)[..., None], 3, axis=2)


def power_law_image(seed: int, exponent: float = 2.0) -> np.ndarray:
    """(720, 1280) uint8 noise whose power spectrum falls as 1 / f**exponent (white noise's spectrum shaped)."""
    rng = np.random.default_rng(seed)
    frequency = np.hypot(*np.meshgrid(np.fft.fftfreq(HEIGHT), np.fft.fftfreq(WIDTH), indexing="ij"))
    frequency[0, 0] = 1.0
    image = np.real(np.fft.ifft2(np.fft.fft2(rng.normal(size=(HEIGHT, WIDTH))) / frequency ** (exponent / 2)))
    image = (image - image.mean()) / image.std() * 40 + 128
    return np.clip(np.round(image), 0, 255).astype(np.uint8)


def checkerboard(square: int = 16) -> np.ndarray:
    """(720, 1280) uint8 black and white squares of ``square`` px."""
    return ((np.indices((HEIGHT, WIDTH)) // square).sum(axis=0) % 2 * 255).astype(np.uint8)


def test_flat_gray_has_no_saturation_edges_contrast_or_noise():
    stats = frame_statistics(np.full((HEIGHT, WIDTH, 3), 128, np.uint8))
    assert stats.saturation == 0.0 and stats.edge_density == 0.0
    assert stats.contrast == pytest.approx(0.0, abs=1e-12) and stats.noise == 0.0 and stats.sharpness == 0.0
    assert stats.brightness == 128.0 and stats.clipped == 0.0


@pytest.mark.parametrize("channel", [0, 1, 2])
def test_a_pure_color_is_fully_saturated(channel):
    rgb = np.zeros((HEIGHT, WIDTH, 3), np.uint8)
    rgb[..., channel] = 200
    assert frame_statistics(rgb).saturation == 255.0


@pytest.mark.parametrize("seed", [0, 1])
def test_noise_estimate_of_gaussian_noise_on_a_flat_image(seed):
    noisy = 128 + np.random.default_rng(seed).normal(0.0, 5.0, (HEIGHT, WIDTH))
    assert noise_sigma(gray_rgb(noisy)[..., 0]) == pytest.approx(5.0, rel=0.15)


def test_noise_estimate_ignores_smooth_shading_and_edges():
    ramp = np.linspace(40, 220, WIDTH)[None, :].repeat(HEIGHT, axis=0)
    ramp[:, WIDTH // 2:] -= 30  # one hard vertical edge
    noisy = ramp + np.random.default_rng(2).normal(0.0, 5.0, (HEIGHT, WIDTH))
    assert noise_sigma(gray_rgb(noisy)[..., 0]) == pytest.approx(5.0, rel=0.15)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_spectrum_slope_of_1_over_f_squared_noise_is_minus_2(seed):
    assert spectrum_slope(power_law_image(seed)) == pytest.approx(-2.0, abs=0.3)


def test_spectrum_slope_of_white_noise_is_flat():
    white = gray_rgb(128 + np.random.default_rng(3).normal(0.0, 20.0, (HEIGHT, WIDTH)))[..., 0]
    assert spectrum_slope(white) == pytest.approx(0.0, abs=0.3)


def test_checkerboard_has_a_high_edge_density():
    assert edge_density(checkerboard()) > 0.05  # two edges per 16 px in both directions: about 1 pixel in 8


def test_blur_lowers_sharpness():
    image = power_law_image(4, exponent=1.0)
    assert sharpness(cv2.GaussianBlur(image, (0, 0), 2.0)) < 0.5 * sharpness(image)


def test_analysis_size_keeps_the_aspect():
    assert analysis_image(np.zeros((360, 640, 3), np.uint8)).shape == (720, 1280, 3)
    assert analysis_image(np.zeros((1080, 1920, 3), np.uint8)).shape == (720, 1280, 3)
    assert analysis_image(np.zeros((1200, 1600, 3), np.uint8)).shape == (960, 1280, 3)


def test_clipped_share_counts_both_ends():
    gray = np.full((HEIGHT, WIDTH), 128.0)
    gray[:180] = 255
    gray[180:270] = 0
    assert frame_statistics(gray_rgb(gray)).clipped == pytest.approx(0.375)


def _write_frames(folder: Path, level: float, sigma: float, count: int, suffix: str = ".png") -> None:
    rng = np.random.default_rng(int(level))
    for index in range(count):
        (folder / f"sub{index % 2}").mkdir(parents=True, exist_ok=True)
        rgb = gray_rgb(level + rng.normal(0.0, sigma, (HEIGHT // 4, WIDTH // 4)))
        cv2.imwrite(str(folder / f"sub{index % 2}" / f"{index:03d}{suffix}"), rgb)


def test_folder_walk_is_recursive_sorted_and_limited(tmp_path):
    _write_frames(tmp_path, 100, 3, 4, ".jpg")
    (tmp_path / "notes.txt").write_text("not an image")
    names = [path.relative_to(tmp_path).as_posix() for path in image_files(tmp_path)]
    assert names == ["sub0/000.jpg", "sub0/002.jpg", "sub1/001.jpg", "sub1/003.jpg"]
    assert len(folder_statistics(tmp_path, limit=3)) == 3
    with pytest.raises(RealismError, match="no such folder"):
        image_files(tmp_path / "sub0" / "none")
    (tmp_path / "empty").mkdir()
    with pytest.raises(RealismError, match="no png/jpg/jpeg images"):
        image_files(tmp_path / "empty")


def test_summary_has_mean_median_std_per_statistic():
    frames = [frame_statistics(np.full((90, 160, 3), level, np.uint8)) for level in (10, 20, 60)]
    brightness = summary(frames)["brightness"]
    assert list(summary(frames)) == list(STATISTICS)
    assert (brightness.mean, brightness.median) == (30.0, 20.0)
    assert brightness.std == pytest.approx(np.std([10, 20, 60]))


def test_verdict_words():
    assert verdict("edge_density", 0.015, 0.039) == "ours is 2.6× smoother"
    assert verdict("noise", 2.0, 1.0) == "ours is 2.0× noisier"
    assert verdict("saturation", 100.0, 95.0) == "similar (within 10 %)"
    assert verdict("spectrum_slope", -2.6, -2.0).startswith("ours is 0.60 steeper")


def test_cli_prints_the_table_and_json(tmp_path, capsys):
    real, ours = tmp_path / "real", tmp_path / "ours"
    _write_frames(real, 120, 6, 3)
    _write_frames(ours, 90, 1, 2)
    report = tmp_path / "report.md"
    assert cli.main(["realism", "--real", str(real), "--ours", str(ours), "--out", str(report)]) == 0
    out = capsys.readouterr().out
    assert "real mean ± std" in out and "ours/real" in out and "ours is" in out
    assert "noise sigma" in out and "| statistic |" in report.read_text()
    assert cli.main(["realism", "--real", str(real), "--ours", str(ours), "--json", "--limit", "1"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["real"]["images"] == 1 and result["ours"]["images"] == 1
    assert set(result["comparison"]) == set(STATISTICS)
    assert result["comparison"]["brightness"]["verdict"].startswith("ours is")


def test_cli_one_folder_prints_one_column(tmp_path, capsys):
    _write_frames(tmp_path, 100, 2, 2)
    assert cli.main(["realism", "--ours", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "ours mean ± std" in out and "real mean" not in out and "verdict" not in out


@pytest.mark.parametrize("problem", ["empty", "missing", "neither"])
def test_cli_folder_errors_exit_2_with_one_line(tmp_path, capsys, problem):
    _write_frames(tmp_path / "ours", 100, 2, 1)
    (tmp_path / "empty").mkdir()
    argv = {"empty": ["--real", str(tmp_path / "empty"), "--ours", str(tmp_path / "ours")],
            "missing": ["--real", str(tmp_path / "missing"), "--ours", str(tmp_path / "ours")],
            "neither": []}[problem]
    assert cli.main(["realism", *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("lanevil: error: ")
    assert {"empty": "no png/jpg/jpeg images", "missing": "no such folder", "neither": "--real"}[problem] in err[0]
