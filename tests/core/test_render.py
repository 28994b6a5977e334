"""Renderer: determinism, golden images, the id and depth buffers, and every stock case renders."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from lanevil_core.case import Camera, Case, load_case
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.presets import CAMERA_PRESET_NAMES
from lanevil_core.render import Frame, render_frame
from lanevil_core.world.scene import FIRST_OBJECT_ID, ID_ROAD, ID_SKY

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = Path(__file__).parent / "golden"
# Mean absolute difference (0-255) a golden image may drift by across machines and library versions.
GOLDEN_TOLERANCE = 2.0
UPDATE = os.environ.get("LANEVIL_UPDATE_GOLDEN") == "1"  # set to write the actual images as the new goldens
GOLDEN_CASES = ["00_clean/00_straight_urban.json", "00_clean/01_bend_suburban.json",
                "30_shadow/rail_shadow/00_straight_urban_noon/05_level5.json",
                "40_reflection/streetlight_reflection/00_t_junction_suburban_night/05_level5.json"]
# One case through every camera preset: a painted urban street, buildings on both sides, the sun high.
PRESET_GOLDEN_CASE = "00_clean/00_straight_urban.json"
PRESET_GOLDEN_FRAME = 10
PRESET_GOLDEN_WIDTH = 192


def _small(case: Case, size: tuple[int, int] = (320, 180)) -> Case:
    return case.model_copy(update={"camera": case.camera.model_copy(update={"width": size[0], "height": size[1]})})


def test_core_imports_no_web_framework() -> None:
    code = ("import sys, lanevil_core, lanevil_core.cli, lanevil_core.export.case, lanevil_core.render; "
            "bad = [m for m in ('fastapi', 'viser', 'uvicorn', 'starlette') if m in sys.modules]; "
            "print(','.join(bad))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == ""


def test_same_case_gives_identical_bytes(make_case: Callable[..., Case]) -> None:
    case = make_case(road={"type": "bend"}, scene={"kind": "urban", "density": 1.0})
    a = render_frame(compile_scene(case), 7)
    b = render_frame(compile_scene(case), 7)
    assert np.array_equal(a.rgb, b.rgb)
    assert np.array_equal(a.depth, b.depth) and np.array_equal(a.object_id, b.object_id)


def test_buffers_are_consistent(make_case: Callable[..., Case]) -> None:
    case = make_case(scene={"kind": "urban", "density": 1.0})
    frame = render_frame(compile_scene(case), 0)
    h, w = frame.rgb.shape[:2]
    assert frame.rgb.dtype == np.uint8 and frame.depth.shape == (h, w) and frame.object_id.shape == (h, w)
    sky = frame.object_id == ID_SKY
    assert np.isinf(frame.depth[sky]).all() and np.isfinite(frame.depth[~sky]).all()
    assert sky[0].mean() > 0.3 and not sky[-1].any()  # sky at the top, ground at the bottom
    assert (frame.object_id[-1, w // 2 - 20:w // 2 + 20] == ID_ROAD).all()  # the road under the ego
    assert (frame.object_id >= FIRST_OBJECT_ID).any()  # buildings
    # Depth of the road grows towards the horizon.
    column = frame.depth[:, w // 2]
    road_rows = np.flatnonzero(frame.object_id[:, w // 2] == ID_ROAD)
    assert np.all(np.diff(column[road_rows]) < 0)


def test_other_size_keeps_the_field_of_view(make_case: Callable[..., Case]) -> None:
    case = make_case()
    frame = render_frame(compile_scene(case), 0, size=(160, 90))
    assert frame.rgb.shape == (90, 160, 3)
    assert frame.camera.intrinsics.fx == 80.0


def _mean_abs(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a.astype(np.int16) - b.astype(np.int16)).mean())


def _check_golden(rgb: np.ndarray, golden: Path, label: str) -> None:
    """``rgb`` against the golden PNG within ``GOLDEN_TOLERANCE`` (with LANEVIL_UPDATE_GOLDEN=1: written as it)."""
    if UPDATE:
        golden.parent.mkdir(exist_ok=True)
        Image.fromarray(rgb).save(golden)
        pytest.skip(f"wrote {golden.name}")
    assert golden.exists(), f"missing {golden}; LANEVIL_UPDATE_GOLDEN=1 writes it"
    expected = np.asarray(Image.open(golden).convert("RGB"))
    assert rgb.shape == expected.shape, f"{label}: shape {rgb.shape} != the golden's {expected.shape}"
    difference = _mean_abs(rgb, expected)
    if difference > GOLDEN_TOLERANCE:
        actual = golden.parent / "_actual" / golden.name
        actual.parent.mkdir(exist_ok=True)
        Image.fromarray(rgb).save(actual)
        pytest.fail(f"{label}: mean difference {difference:.2f} > {GOLDEN_TOLERANCE} (actual in {actual})")


@pytest.mark.parametrize("relative", GOLDEN_CASES)
def test_golden_images(relative: str) -> None:
    rgb = render_frame(compile_scene(_small(load_case(ROOT / "scenes" / relative))), 0).rgb
    _check_golden(rgb, GOLDEN / (relative.replace("/", "__").removesuffix(".json") + ".png"), relative)


@pytest.mark.parametrize("preset", CAMERA_PRESET_NAMES)
def test_golden_image_per_camera_preset(preset: str) -> None:
    """The golden case seen through each camera preset (lens, bonnet, sensor and its seeded noise), 192 px wide
    with the preset's aspect ratio."""
    case = load_case(ROOT / "scenes" / PRESET_GOLDEN_CASE)
    camera = Camera.model_validate({"preset": preset})
    size = (PRESET_GOLDEN_WIDTH, round(PRESET_GOLDEN_WIDTH * camera.height / camera.width))
    rgb = render_frame(compile_scene(_small(case.model_copy(update={"camera": camera}), size)), PRESET_GOLDEN_FRAME).rgb
    _check_golden(rgb, GOLDEN / f"camera_preset__{preset}.png", f"camera preset {preset}")


def _scene_files() -> list[Path]:
    return sorted((ROOT / "scenes").glob("**/*.json"))


def test_every_stock_case_loads_with_a_title() -> None:
    files = _scene_files()
    assert len(files) >= 60
    for path in files:
        case = load_case(path)
        assert case.title and case.description, path


def test_stock_library_matches_its_source() -> None:
    from lanevil_core.case import case_json
    from lanevil_core.library.stock import library

    lib = library()
    on_disk = {str(p.relative_to(ROOT / "scenes")): p.read_text() for p in _scene_files()}
    assert set(on_disk) == set(lib), "run `lanevil library --out scenes` after changing lanevil_core/library/stock.py"
    for relative, case in lib.items():
        assert on_disk[relative] == case_json(case), relative


def test_clean_cases_cover_every_road_line_and_scene_kind() -> None:
    from lanevil_core.typed import LINE_TYPES, ROAD_TYPES, SCENE_KINDS

    cases = [load_case(p) for p in sorted((ROOT / "scenes" / "00_clean").glob("*.json"))]
    assert {c.road.type for c in cases} == set(ROAD_TYPES)
    # Every paint type; "none" (an unpainted boundary) belongs to the train variations, not the stock drives.
    assert {m.type for c in cases for m in c.road.markings} == set(LINE_TYPES) - {"none"}
    assert {c.scene.kind for c in cases} == set(SCENE_KINDS)


@pytest.mark.slow
@pytest.mark.parametrize("path", _scene_files(), ids=lambda p: str(p.relative_to(ROOT / "scenes")))
def test_every_stock_case_renders(path: Path) -> None:
    case = load_case(path)
    frame = render_frame(compile_scene(_small(case, (160, 90))), case.ego.frames - 1)
    assert frame.rgb.std() > 5.0  # not a blank image


# vehicles, sun shadows, a wet road and a puddle
THREADED_CASE = "40_reflection/vehicle_reflection/00_downhill_suburban_noon/05_level5.json"


def _buffers_equal(a: Frame, b: Frame) -> bool:
    return (np.array_equal(a.rgb, b.rgb) and np.array_equal(a.depth, b.depth)
            and np.array_equal(a.object_id, b.object_id))


def test_threads_give_the_bytes_of_one_thread() -> None:
    scene = compile_scene(_small(load_case(ROOT / "scenes" / THREADED_CASE)))
    assert scene.env.sun_intensity > 0 and scene.env.wetness > 0 and scene.meshes
    one = render_frame(scene, 4, threads=1)
    assert _buffers_equal(one, render_frame(scene, 4, threads=2))
    assert _buffers_equal(one, render_frame(scene, 4, threads=3))


def test_a_frame_after_other_frames_equals_it_rendered_cold() -> None:
    case = _small(load_case(ROOT / "scenes" / THREADED_CASE))
    cold = render_frame(compile_scene(case), 6)
    warm_scene = compile_scene(case)
    for index in (0, 5, 6, 7, 6):  # shadow cascades that did not move are reused
        warm = render_frame(warm_scene, index, threads=2)
    assert warm_scene.cache["shadow_cascades"].hits > 0
    assert _buffers_equal(cold, warm)
