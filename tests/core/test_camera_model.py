"""The camera model: presets, intrinsics from focal length and principal point, roll, lens distortion, the
sensor's determinism and its response to light."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lanevil_core.camera import intrinsics_for, mounted_camera
from lanevil_core.camera.cover import cover_camera
from lanevil_core.camera.lens import distort, undistort
from lanevil_core.camera.sensor import (
    BASE_GAIN,
    KEY,
    LUMA,
    development,
    filmic,
    metered_gain,
    white_balance_gains,
)
from lanevil_core.case import Camera, Case, CaseError, Sensor, parse_case
from lanevil_core.metrics.realism import grey_image, sharpness
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.presets import CAMERA_PRESET_NAMES
from lanevil_core.render import render_frame
from lanevil_core.render.renderer import (
    HEADLIGHT_AHEAD_M,
    HEADLIGHT_HALF_SPAN_M,
    HEADLIGHT_HEIGHT_M,
    headlight_positions,
)
from lanevil_core.world.environment import SKY_AMBIENT_GAIN, SUN_SCALE, clear_sky, daylight


@pytest.mark.parametrize("name", CAMERA_PRESET_NAMES)
def test_every_camera_preset_is_a_valid_camera(name: str) -> None:
    camera = Camera.model_validate({"preset": name})
    assert camera.width >= 640 and 45 <= camera.hfov <= 100


def test_preset_fields_given_beside_it_win() -> None:
    camera = Camera.model_validate({"preset": "dashcam", "fov": 70.0, "bonnet": None})
    assert camera.fov == 70.0 and camera.bonnet is None and camera.lens.k1 == pytest.approx(-0.12)


def test_unknown_camera_preset_names_the_field() -> None:
    with pytest.raises(CaseError, match=r"camera: .*unknown camera preset 'gopro'"):
        parse_case({"camera": {"preset": "gopro"}})


def test_default_camera_keeps_the_papers_intrinsics() -> None:
    k = intrinsics_for(Camera())
    assert (k.fx, k.fy, k.cx, k.cy) == (640.0, 640.0, 640.0, 360.0)


def test_focal_length_and_principal_point_win_over_fov_and_scale_with_size() -> None:
    camera = Camera(focal=1000.0, cx=600.0, cy=400.0)
    k = intrinsics_for(camera)
    assert (k.fx, k.fy, k.cx, k.cy) == (1000.0, 1000.0, 600.0, 400.0)
    half = intrinsics_for(camera, (640, 360))
    assert (half.fx, half.cx, half.cy) == (500.0, 300.0, 200.0)


def test_pitch_up_moves_the_horizon_down_and_roll_tilts_it() -> None:
    far_ahead_world = np.array([[1000.0, -5.0, 0.0], [1000.0, 5.0, 0.0]])
    level = mounted_camera(Camera(z=1.4, x=0.0), np.eye(4))
    up = mounted_camera(Camera(z=1.4, x=0.0, pitch=-3.0), np.eye(4))
    rolled = mounted_camera(Camera(z=1.4, x=0.0, roll=2.0), np.eye(4))
    v_level = level.project(far_ahead_world)[0][:, 1]
    v_up = up.project(far_ahead_world)[0][:, 1]
    assert np.all(v_up > v_level + 25)  # 640 * tan(3 deg) = 33.5 px
    uv_rolled = rolled.project(far_ahead_world)[0]
    assert abs(uv_rolled[0, 1] - uv_rolled[1, 1]) > 0.1  # the horizon is no longer level


@settings(max_examples=60, deadline=None)
@given(x=st.floats(-0.8, 0.8), y=st.floats(-0.45, 0.45), k1=st.floats(-0.2, 0.05), k2=st.floats(-0.02, 0.05),
       p1=st.floats(-0.005, 0.005), p2=st.floats(-0.005, 0.005))
def test_undistort_inverts_distort(x: float, y: float, k1: float, k2: float, p1: float, p2: float) -> None:
    coefficients = (k1, k2, p1, p2, 0.0)
    x_d, y_d = distort(np.array(x), np.array(y), coefficients)
    x_u, y_u = undistort(x_d, y_d, coefficients)
    assert abs(float(x_u) - x) < 1e-6 and abs(float(y_u) - y) < 1e-6


def test_cover_camera_sees_every_ray_of_a_barrel_lens() -> None:
    camera = mounted_camera(Camera(fov=70.0, lens={"k1": -0.2, "k2": 0.05}), np.eye(4))
    cover = cover_camera(camera)
    assert cover.intrinsics.width > camera.intrinsics.width and cover.intrinsics.fx == camera.intrinsics.fx
    corners_world = camera.p_world_camera + np.array([[-1.0, 0.0, 0.0]])  # any point: both see the same pose
    assert np.allclose(cover.T_world_camera, camera.T_world_camera) and corners_world.shape == (1, 3)


def test_metering_brings_the_frame_to_middle_gray_within_limits() -> None:
    flat = np.full((64, 64, 3), 0.05, np.float32)
    assert metered_gain(flat, Sensor()) == pytest.approx(KEY / 0.05, rel=1e-3)
    assert metered_gain(flat * 1e-4, Sensor()) == Sensor().max_gain  # night: the gain limit holds
    assert metered_gain(flat, Sensor(exposure="fixed", gain=2.5)) == 2.5
    dark = development(flat * 0.01, Sensor())
    bright = development(flat, Sensor())
    assert dark.iso_gain > bright.iso_gain and dark.shot > bright.shot  # noise rises with gain in low light


def test_in_the_dark_the_gain_keeps_the_lit_road_below_clip() -> None:
    night = np.full((64, 64, 3), 1e-4, np.float32)
    night[40:] = 0.2  # the road in the headlights' beam under a black sky: the mean alone would ask for max gain
    gain = metered_gain(night, Sensor())
    assert BASE_GAIN <= gain < Sensor().max_gain and gain * 0.2 <= 1.0 + 1e-6
    # by day (a gain below BASE_GAIN) highlights clip as before: the trimmed mean alone decides
    day = np.full((64, 64, 3), 0.2, np.float32)
    day[:16] = 5.0  # a bright sky over a quarter of the frame
    assert metered_gain(day, Sensor()) < BASE_GAIN and metered_gain(day, Sensor()) * 5.0 > 1.0


@pytest.mark.parametrize("height", [1.2, 1.55, 3.0])
@pytest.mark.parametrize("pitch", [-3.0, 0.0, 3.5])
def test_headlights_stand_on_the_car_under_a_camera_of_any_height_and_pitch(height: float, pitch: float) -> None:
    # not a fixed drop below the camera (under a 1.55 m camera that put them under the road: a black night)
    case = Case.model_validate({"camera": {"z": height, "pitch": pitch}, "road": {"type": "straight"}})
    camera = compile_scene(case).ego.camera(0, (160, 90))
    heading, beams_world = headlight_positions(camera, height)
    ground_z = camera.p_world_camera[2] - height
    np.testing.assert_allclose(beams_world[:, 2] - ground_z, HEADLIGHT_HEIGHT_M, atol=1e-9)
    assert heading[2] == 0.0 and np.linalg.norm(heading) == pytest.approx(1.0)
    np.testing.assert_allclose((beams_world - camera.p_world_camera)[:, :2] @ heading[:2], HEADLIGHT_AHEAD_M)
    assert np.linalg.norm(beams_world[0] - beams_world[1]) == pytest.approx(2 * HEADLIGHT_HALF_SPAN_M)


def test_softness_takes_the_finest_detail_as_a_camera_does() -> None:
    def frame(softness: float) -> np.ndarray:
        case = Case.model_validate({"camera": {"width": 640, "height": 360, "sensor": {"softness": softness,
                                                                                       "sharpen": 0.0}}})
        return render_frame(compile_scene(case), 0).rgb

    sharp, soft = frame(0.0), frame(1.6)
    assert sharpness(grey_image(soft)) < 0.5 * sharpness(grey_image(sharp))
    assert abs(soft.mean() - sharp.mean()) < 1.0  # a blur moves no light
    assert np.array_equal(frame(1.6), soft)  # deterministic


def _shadow_share(case: Case) -> float:
    """Light on flat ground in shadow over light in the sun (luminance), as the renderer gets them."""
    env = compile_scene(case).env
    sky = 0.5 * env.sky_zenith.astype(np.float64) + 0.5 * env.sky_horizon.astype(np.float64)
    shade = env.ambient * SKY_AMBIENT_GAIN * float(LUMA @ sky)
    sun = SUN_SCALE * env.sun_intensity * env.sun_dir_world[2] * float(LUMA @ env.sun_color)
    return shade / (shade + sun)


def test_daylight_models_give_the_published_proportions() -> None:
    beam, diffuse = clear_sky(45.0)
    assert 850 < beam < 900 and diffuse / (beam * np.sin(np.radians(45.0)) + diffuse) == pytest.approx(0.12, abs=0.01)
    assert daylight(45.0, 0.0) == pytest.approx(clear_sky(45.0))
    overcast_beam, overcast_diffuse = daylight(45.0, 1.0)
    assert overcast_beam == pytest.approx(0.0, abs=1e-9)  # Kasten & Czeplak: all light diffuse at 8 oktas
    assert overcast_diffuse == pytest.approx(0.25 * (beam * np.sin(np.radians(45.0)) + diffuse))


def test_photographed_shadows_darken_with_a_higher_sun_and_fade_under_clouds() -> None:
    def share(altitude: float, cloudiness: float, camera: dict | None = None) -> float:
        camera = {"preset": "carla"} if camera is None else camera
        return _shadow_share(Case(sun={"altitude": altitude, "azimuth": 0.0, "intensity": 1.0},
                                  weather={"cloudiness": cloudiness}, camera=camera))

    clear = [share(altitude, 0.0) for altitude in (15.0, 20.0, 30.0, 45.0, 60.0)]
    assert all(a > b for a, b in zip(clear, clear[1:]))
    assert 0.03 < clear[-1] < clear[1] < 0.2
    assert share(45.0, 30.0) < share(45.0, 60.0) < share(45.0, 90.0)
    assert share(45.0, 90.0) > 0.6  # overcast: faint shadows
    assert share(45.0, 0.0, {}) == pytest.approx(0.12, abs=0.01)  # the ideal render keeps its own numbers


def test_the_sun_unit_is_the_renderers() -> None:
    from lanevil_core.render.lighting import SUN_SCALE as RENDER_SUN_SCALE

    assert SUN_SCALE == RENDER_SUN_SCALE


def test_filmic_curve_is_monotone_from_black_to_white_and_white_balance_is_neutral_at_daylight() -> None:
    x = np.linspace(0, 1, 1001)
    y = filmic(x, 1.15)
    assert y[0] == 0.0 and y[-1] == pytest.approx(1.0) and np.all(np.diff(y) >= 0)
    assert 0.12 < float(filmic(np.array(KEY), 1.15)) < 0.3
    assert np.allclose(white_balance_gains(Sensor(white_balance=5600.0)), 1.0)
    warm = white_balance_gains(Sensor(white_balance=4000.0))  # balanced for tungsten: daylight turns blue
    assert warm[2] > 1.0 > warm[0]


def _photo_case(make_case: Callable[..., Case], **camera: object) -> Case:
    return make_case(camera={"preset": "dashcam", "width": 320, "height": 180, **camera})


def test_sensor_frames_are_deterministic_per_seed_and_frame(make_case: Callable[..., Case]) -> None:
    case = _photo_case(make_case)
    a = render_frame(compile_scene(case), 5)
    b = render_frame(compile_scene(case), 5)
    assert np.array_equal(a.rgb, b.rgb) and np.array_equal(a.object_id, b.object_id)
    other_frame = render_frame(compile_scene(case), 6)
    other_seed = render_frame(compile_scene(case.model_copy(update={"seed": case.seed + 1})), 5)
    assert not np.array_equal(a.rgb, other_frame.rgb) and not np.array_equal(a.rgb, other_seed.rgb)
    threads = render_frame(compile_scene(case), 5, threads=2)
    assert np.array_equal(a.rgb, threads.rgb)


def test_sensor_noise_is_there_and_scales(make_case: Callable[..., Case]) -> None:
    quiet = render_frame(compile_scene(_photo_case(make_case, sensor={"noise": 0.0, "shutter": 0.0})), 5).rgb
    noisy = render_frame(compile_scene(_photo_case(make_case, sensor={"noise": 3.0, "shutter": 0.0})), 5).rgb
    diff = noisy.astype(np.int16) - quiet.astype(np.int16)
    assert 0.5 < float(diff.std()) < 30.0


def test_sensor_noise_has_the_modelled_sigma_and_independent_channels() -> None:
    """Through a linear tone curve, each channel's noise on a flat grey field has the standard deviation of the
    shot + read model and the three channels draw independently (one hash per pixel picks three table entries)."""
    from lanevil_core.camera.sensor import TONE_LUT_SIZE
    from lanevil_core.render.develop import NOISE_TABLE, develop

    assert abs(float(NOISE_TABLE.mean())) < 0.05 and abs(float(NOISE_TABLE.std()) - 1.0) < 0.03
    level, shot, read = 0.4, 4e-3, 1e-2
    hdr = np.full((240, 320, 3), level, np.float32)
    linear = np.round(np.linspace(0.0, 255.0, TONE_LUT_SIZE)).astype(np.uint8)
    out = np.empty(hdr.shape, np.uint8)
    develop(hdr, 1.0, np.ones(3), 0.0, (160.0, 120.0), shot, read, 1.0, 11, linear, out)
    values = out.reshape(-1, 3).astype(np.float64) / 255.0
    expected = np.sqrt(level * shot + read * read)
    assert np.allclose(values.mean(axis=0), level, atol=0.005)
    assert np.allclose(values.std(axis=0), expected, rtol=0.05)
    correlation = np.asarray(np.corrcoef(values.T))
    assert np.all(np.abs(correlation[np.triu_indices(3, 1)]) < 0.03)
    again = np.empty_like(out)
    develop(hdr, 1.0, np.ones(3), 0.0, (160.0, 120.0), shot, read, 1.0, 11, linear, again, threads=2)
    assert np.array_equal(out, again)


def test_a_sensor_without_noise_develops_a_flat_field_flat_for_any_seed() -> None:
    """With shot and read noise 0 the sensor adds exactly nothing: every pixel of a flat field is the tone curve's
    value of its level, whatever the seed."""
    from lanevil_core.camera.sensor import TONE_LUT_SIZE
    from lanevil_core.render.develop import develop

    level = 0.4
    hdr = np.full((90, 160, 3), level, np.float32)
    linear = np.round(np.linspace(0.0, 255.0, TONE_LUT_SIZE)).astype(np.uint8)
    frames = []
    for seed in (11, 12):
        out = np.empty(hdr.shape, np.uint8)
        develop(hdr, 1.0, np.ones(3), 0.0, (80.0, 45.0), 0.0, 0.0, 1.0, seed, linear, out)
        frames.append(out)
    assert np.all(frames[0] == linear[round(level * (TONE_LUT_SIZE - 1))]) and np.array_equal(frames[0], frames[1])


def test_the_papers_camera_has_no_sensor_noise_and_real_cameras_do() -> None:
    """CARLA's RGB camera has no noise attribute: the ``carla`` preset's sensor adds none; the other presets stand
    for real cameras and keep theirs."""
    for name in CAMERA_PRESET_NAMES:
        sensor = Camera.model_validate({"preset": name}).sensor
        assert sensor is not None and (sensor.noise == 0.0) == (name == "carla"), name


def test_the_papers_camera_adapts_over_two_stops_and_keeps_a_night_dark() -> None:
    """CARLA's histogram auto-exposure adapts between EV 10 and 12 only: the ``carla`` preset's gain window is two
    stops wide, so a night through it is metered no brighter than a dim day, darker than through the same sensor
    with the default window; a clear noon is metered inside the window (unchanged)."""
    from lanevil_core.camera.sensor import metered_gain
    from lanevil_core.library.stock import original_case
    from lanevil_core.pipeline.bench import with_camera

    sensor = Camera.model_validate({"preset": "carla"}).sensor
    assert sensor is not None and sensor.max_gain / sensor.min_gain == pytest.approx(4.0)
    wide = sensor.model_copy(update={"min_gain": Sensor().min_gain, "max_gain": Sensor().max_gain})
    for index, night in ((0, True), (4, False)):  # streetlight_reflection 0: a night; 4: a clear sunset
        case = with_camera(original_case("streetlight_reflection", index), "carla")
        rgb_carla, rgb_wide = (render_frame(compile_scene(case.model_copy(update={"camera": case.camera.model_copy(
            update={"width": 320, "height": 180, "sensor": chosen})})), 30).rgb for chosen in (sensor, wide))
        if night:
            assert rgb_carla.mean() < 0.7 * rgb_wide.mean()
        else:
            assert np.array_equal(rgb_carla, rgb_wide)
    assert metered_gain(np.full((16, 16, 3), 1e-4, np.float32), sensor) == sensor.max_gain


def test_auto_exposure_darkens_shadows_relative_to_the_ideal_render(make_case: Callable[..., Case]) -> None:
    """A metered camera shows sun-lit asphalt bright and its shadow dark: the ratio of the two is lower than the
    ideal render's, as on a photograph."""
    from lanevil_core.world.scene import ID_ROAD

    ratios = []
    for sensor in (None, {"noise": 0.0, "shutter": 0.0, "vignetting": 0.0, "sharpen": 0.0}):
        case = make_case(illusions=[{"type": "fence_shadow", "severity": 5}],
                         camera={"width": 320, "height": 180, "sensor": sensor})
        frame = render_frame(compile_scene(case), 5)
        gray = frame.rgb.mean(axis=-1)[frame.object_id == ID_ROAD]
        ratios.append(np.percentile(gray, 10) / np.percentile(gray, 90))
    assert ratios[1] < ratios[0]


def test_points_beyond_the_lens_models_reach_are_not_projected_into_the_image() -> None:
    """A strong barrel polynomial turns back far off axis; points there must not fold back into the image."""
    camera = mounted_camera(Camera(fov=70.0, x=0.0, z=1.5, lens={"k1": -0.15, "k2": 0.0}), np.eye(4))
    angles = np.radians(np.arange(-89.0, 90.0, 1.0))
    p_world = np.stack([np.cos(angles) * 10.0, np.sin(angles) * 10.0, np.full_like(angles, 1.5)], axis=1)
    uv, _ = camera.project(p_world)
    inside = np.isfinite(uv[:, 0]) & (uv[:, 0] >= 0) & (uv[:, 0] < camera.intrinsics.width)
    assert np.all(np.abs(np.degrees(angles[inside])) < 45.0)  # half the 70-degree view, plus the margin
    u = uv[np.isfinite(uv[:, 0]), 0]
    assert np.all(np.diff(u) < 0)  # left to right in the world is right to left in y: monotone, no fold


def test_vary_camera_draws_cameras_within_the_ranges_and_keeps_the_rest_of_the_variation() -> None:
    from lanevil_core.dataset.plan import train_variation

    base = Case()
    drawn = 0
    for index in range(24):
        plain, plain_parameters = train_variation(base, 3, index)
        varied, parameters = train_variation(base, 3, index, vary_camera=True)
        # The same road but for what the randomised split draws after the camera: its pavement and paint wear.
        road = varied.road.model_copy(update={"pavement": plain.road.pavement, "markings": [
            marking.model_copy(update={"wear": 0.0}) for marking in varied.road.markings]})
        assert varied.sun == plain.sun and road == plain.road and varied.seed == plain.seed
        camera = varied.camera
        if camera.sensor is None:  # one of the variations kept on the base's camera
            assert camera == plain.camera
            continue
        drawn += 1
        assert 45.0 <= camera.fov <= 100.0 and 1.2 <= camera.z <= 3.5 and -2.0 <= camera.pitch <= 6.0
        assert -2.0 <= camera.roll <= 2.0 and parameters["camera"]["fov"] == camera.fov
    assert 12 <= drawn < 24


def test_drawn_mount_heights_favour_car_cameras_and_still_span_the_whole_range() -> None:
    from lanevil_core.camera.variation import CAR_HEIGHT_M, CAR_HEIGHT_SHARE, HEIGHT_M, random_camera

    heights = np.array([random_camera(np.random.default_rng([11, index]))["z"] for index in range(400)])
    assert heights.min() >= HEIGHT_M[0] and heights.max() <= HEIGHT_M[1]
    car = np.mean(heights <= CAR_HEIGHT_M[1])
    assert abs(car - CAR_HEIGHT_SHARE) < 0.08  # a uniform draw over HEIGHT_M would put 17 % there
    assert heights.max() > 3.2 and heights.min() < 1.3


def test_a_lens_that_turns_back_inside_the_image_is_refused_and_drawn_lenses_cover_their_view() -> None:
    from lanevil_core.camera.cover import cover_camera
    from lanevil_core.camera.variation import random_camera

    with pytest.raises(CaseError, match=r"camera: lens: .*turns back inside the image"):
        parse_case({"camera": {"fov": 100.0, "lens": {"k1": -0.3}}})
    for index in range(40):
        camera = Camera.model_validate(random_camera(np.random.default_rng([7, index])))
        cover = cover_camera(mounted_camera(camera, np.eye(4), (320, 180))).intrinsics
        assert cover.width * cover.height < 4 * 320 * 180


def _ramp_scene(height: int = 120, width: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """Radiance with sharp vertical stripes and a road-like depth that falls towards the bottom rows (sky above)."""
    rng = np.random.default_rng(3)
    hdr = np.repeat(rng.uniform(0.05, 0.6, (1, width, 3)), height, axis=0).astype(np.float32)
    rows = np.arange(height)[:, None] + 0.5 - height / 2
    depth = np.where(rows > 2, 1.5 * (width / 2) / np.maximum(rows, 1e-3), np.inf) * np.ones((1, width))
    return hdr, depth.astype(np.float32)


def test_motion_blur_streaks_grow_towards_the_frame_edges_and_leave_the_sky_sharp() -> None:
    from lanevil_core.render.develop import motion_blur

    hdr, depth = _ramp_scene()
    center = (100.0, 60.0)
    blurred = motion_blur(hdr, depth, center, travel=0.05)
    changed = np.abs(blurred - hdr).max(axis=-1) > 1e-6
    assert not changed[:60].any()  # the sky and the rows near the horizon stay sharp
    assert changed[-1].sum() > changed[100].sum() > 0  # nearer (lower) rows streak more
    # The streaks point away from the principal point: near its column, vertical stripes blur less.
    assert changed[-1, :40].mean() > changed[-1, 95:105].mean()
    assert np.array_equal(motion_blur(hdr, depth, center, travel=0.0), hdr)
    longer = motion_blur(hdr, depth, center, travel=0.1)
    assert (np.abs(longer - hdr).max(axis=-1) > 1e-6).sum() > changed.sum()


def test_developing_with_streaks_is_blurring_then_developing() -> None:
    """The one-pass path (blur as the sensor reads a pixel) gives the bytes of the two-pass one, and object ids
    that never change leave the frame as it was (no edge to blend); any thread count, same bytes."""
    from lanevil_core.camera.sensor import tone_lut
    from lanevil_core.render.develop import Streaks, develop, motion_blur

    hdr, depth = _ramp_scene()
    center, travel = (100.0, 60.0), 0.05
    lut = tone_lut(1.0)
    args = (1.5, np.array([1.1, 1.0, 0.9]), 0.3, center, 2e-3, 5e-3, 1.2, 17, lut)
    two_pass = np.empty(hdr.shape, np.uint8)
    develop(motion_blur(hdr, depth, center, travel), *args, two_pass)
    one_pass = np.empty_like(two_pass)
    develop(hdr, *args, one_pass, 2, np.zeros(depth.shape, np.int32), Streaks(depth, *center, travel))
    assert np.array_equal(one_pass, two_pass)
    plain = np.empty_like(two_pass)
    develop(hdr, *args, plain)
    assert not np.array_equal(plain, two_pass)


def test_developing_blends_object_edges_only() -> None:
    from lanevil_core.camera.sensor import tone_lut
    from lanevil_core.render.develop import develop

    hdr = np.full((40, 60, 3), 0.05, np.float32)
    hdr[:, 30:] = 0.6
    ids = np.zeros((40, 60), np.int32)
    ids[:, 30:] = 7
    args = (1.0, np.ones(3), 0.0, (30.0, 20.0), 0.0, 0.0, 1.0, 5, tone_lut(1.0))
    sharp, soft = np.empty(hdr.shape, np.uint8), np.empty(hdr.shape, np.uint8)
    develop(hdr, *args, sharp)
    develop(hdr, *args, soft, 1, ids)
    differs = np.any(sharp != soft, axis=-1)
    assert differs[:, 29].all() and differs[:, 30].all()  # the two columns on the edge
    assert not differs[:, :29].any() and not differs[:, 31:].any()
    assert sharp[0, 29, 0] < soft[0, 29, 0] and soft[0, 30, 0] < sharp[0, 30, 0]
