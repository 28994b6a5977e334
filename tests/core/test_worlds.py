"""``--vary-world`` and ``--heldout``: deterministic world draws, held-out ranges disjoint from the train draw's,
the markings' draw (standard, Botts' dots, wear), a tiny varied split whose labels pass the label checks, and flag
combinations refused with one line."""

from __future__ import annotations

import json
import shutil
from dataclasses import fields, replace
from pathlib import Path

import numpy as np
import pytest

from lanevil_core.camera.variation import MountSpans, pick_spans
from lanevil_core.case import GAP_M, Case, Marking, case_json, load_case, parse_case
from lanevil_core.cli import main
from lanevil_core.dataset.plan import (
    CAMERA_PITCH_RANGE_DEG,
    CAMERA_Z_RANGE_M,
    PAINT_WEAR_RANGE,
    PlanError,
    Settings,
    build_plan,
    check_world_flags,
    discover_cases,
    train_variation,
)
from lanevil_core.dataset.worlds import (
    HELDOUT_AXES,
    HELDOUT_WORLD,
    SHARED_AXES,
    TRAIN_WORLD,
    WorldRanges,
    draw_world,
    world_markings,
    world_rng,
)
from lanevil_core.labels.lanes import h_samples_for
from lanevil_core.metrics.formats import read_tusimple
from lanevil_core.typed import MarkingStandardName
from lanevil_core.world.marking_standards import MARKING_STANDARDS

SCENES = Path(__file__).resolve().parents[2] / "scenes"
CLEAN = SCENES / "00_clean"


def _intervals(value: object) -> list[tuple[float, float]]:
    """The (lo, hi) intervals of a spans axis, or of every axis of a ``MountSpans``."""
    if isinstance(value, MountSpans):
        return [span for f in fields(MountSpans) for span in getattr(value, f.name)]
    assert isinstance(value, tuple)
    return [(float(lo), float(hi)) for lo, hi in value]


def _overlaps(a: tuple[float, float], b: tuple[float, float]) -> bool:
    return a[0] <= b[1] and b[0] <= a[1]


def test_every_axis_is_shared_or_held_out() -> None:
    names = {f.name for f in fields(WorldRanges)}
    assert set(SHARED_AXES) | set(HELDOUT_AXES) == names and not set(SHARED_AXES) & set(HELDOUT_AXES)
    assert {"camera", "lane_width_m", "asphalt_albedo", "concrete_albedo", "marking_standards",
            "paint_wear"} <= set(HELDOUT_AXES)


@pytest.mark.parametrize("axis", SHARED_AXES)
def test_shared_axes_take_the_train_ranges(axis: str) -> None:
    assert getattr(HELDOUT_WORLD, axis) == getattr(TRAIN_WORLD, axis) or axis == "draws_camera"


@pytest.mark.parametrize("axis", HELDOUT_AXES)
def test_held_out_ranges_are_disjoint_from_the_train_ranges(axis: str) -> None:
    held, train = getattr(HELDOUT_WORLD, axis), getattr(TRAIN_WORLD, axis)
    if isinstance(held, MountSpans):
        for f in fields(MountSpans):  # field of view against field of view, height against height ...
            for a in getattr(held, f.name):
                assert not any(_overlaps(a, b) for b in getattr(train, f.name)), (f.name, a)
        return
    if all(isinstance(name, str) for name in held):  # named choices (marking standards): no name in both
        assert held and not set(held) & set(train), (axis, set(held) & set(train))
        return
    for a in _intervals(held):
        assert not any(_overlaps(a, b) for b in _intervals(train)), (axis, a)


def test_held_out_cameras_lie_outside_every_train_camera() -> None:
    # the plain train split's mount jitter and the stock cases' cameras lie inside the train camera ranges too
    train = TRAIN_WORLD.camera
    assert all(any(lo <= v <= hi for lo, hi in train.height_m) for v in (*CAMERA_Z_RANGE_M, 3.0))
    assert all(any(lo <= v <= hi for lo, hi in train.pitch_deg) for v in (*CAMERA_PITCH_RANGE_DEG, 0.0))
    assert any(lo <= 90.0 <= hi for lo, hi in train.fov_deg)


def test_held_out_markings_lie_outside_every_train_split() -> None:
    # the held-out manuals' gaps are shorter than any train manual's (custom: the markings' own 9 m gap) ...
    def gap(name: MarkingStandardName) -> float:
        return GAP_M if name == "custom" else MARKING_STANDARDS[name].gap_m

    assert max(gap(name) for name in HELDOUT_WORLD.marking_standards) < min(
        gap(name) for name in TRAIN_WORLD.marking_standards)
    assert Marking().gap == GAP_M
    # ... and the held-out wear lies beyond the world draw's and --vary-camera's (the plain split's paint is fresh)
    worst = max(hi for _, hi in TRAIN_WORLD.paint_wear)
    assert all(lo > max(worst, PAINT_WEAR_RANGE[1]) for lo, _ in HELDOUT_WORLD.paint_wear)


def test_the_markings_draw_comes_last_on_the_world_stream() -> None:
    other = replace(TRAIN_WORLD, marking_standards=("cn_slow",), botts_share=1.0, worn_share=1.0,
                    paint_wear=((0.9, 1.0),))
    for index in range(5):
        first, second = (draw_world(world_rng(2, index), ranges, (640, 360)) for ranges in (TRAIN_WORLD, other))
        assert second["road"].pop("marking_standard") == "cn_slow" and second["markings"]["botts_dots"]
        del first["road"]["marking_standard"], first["markings"], second["markings"]
        assert first == second


def test_pick_spans_covers_every_interval_with_one_draw() -> None:
    spans = ((0.0, 1.0), (10.0, 13.0))
    values = [pick_spans(u, spans) for u in np.linspace(0.0, 1.0, 41)]
    assert all(0.0 <= v <= 1.0 or 10.0 <= v <= 13.0 for v in values)
    assert sum(v >= 10.0 for v in values) > 2 * sum(v <= 1.0 for v in values)  # as likely as its length


@pytest.mark.parametrize("ranges", [TRAIN_WORLD, HELDOUT_WORLD], ids=["train", "heldout"])
def test_the_draw_is_deterministic_per_seed(ranges: WorldRanges) -> None:
    first = draw_world(world_rng(5, 3), ranges, (640, 360))
    assert first == draw_world(world_rng(5, 3), ranges, (640, 360))
    assert first != draw_world(world_rng(6, 3), ranges, (640, 360))
    base = load_case(CLEAN / "00_straight_urban.json")
    one, two = train_variation(base, 5, 3, world=ranges), train_variation(base, 5, 3, world=ranges)
    assert case_json(one[0]) == case_json(two[0]) and one[1] == two[1]


@pytest.mark.parametrize("ranges", [TRAIN_WORLD, HELDOUT_WORLD], ids=["train", "heldout"])
def test_drawn_worlds_lie_in_their_ranges(ranges: WorldRanges) -> None:
    base = load_case(CLEAN / "01_bend_suburban.json")
    cases = [train_variation(base, 0, index, world=ranges)[0] for index in range(60)]

    def inside(value: float, spans: tuple[tuple[float, float], ...]) -> bool:
        return any(lo - 1e-9 <= value <= hi + 1e-9 for lo, hi in spans)

    for case in cases:
        assert inside(case.road.lane_width, ranges.lane_width_m) and inside(case.road.radius, ranges.bend_radius_m)
        assert case.road.surface_color is not None
        grey = case.road.surface_color[1]
        assert inside(grey, ranges.concrete_albedo if case.road.pavement == "concrete" else ranges.asphalt_albedo)
        assert case.scene.kind in ranges.scene_kinds
    own = [train_variation(base, 0, index)[0].road.markings for index in range(60)]
    for case, markings in zip(cases, own, strict=True):
        assert case.road.marking_standard in ranges.marking_standards
        wear = {marking.wear for marking in case.road.markings}  # one wear on every line
        assert len(wear) == 1 and (wear == {0.0} or inside(min(wear), ranges.paint_wear))
        last = len(markings) - 1
        for index, (marking, before) in enumerate(zip(case.road.markings, markings, strict=True)):
            if marking.type != before.type:  # only broken lane lines change; edges, centre, solid lines stay
                assert {before.type, marking.type} == {"white_dashed", "botts_dots"}
                assert index not in (0, last // 2, last)
    assert len({case.road.marking_standard for case in cases}) == len(ranges.marking_standards)
    assert any(marking.wear > 0 for case in cases for marking in case.road.markings)
    assert any(case.road.markings[0].wear == 0 for case in cases)
    assert any([m.type for m in case.road.markings] != [m.type for m in markings]
               for case, markings in zip(cases, own, strict=True))  # some dashes became dots, or dots dashes
    camera_heights = {case.camera.z for case in cases}
    if ranges.draws_camera:
        assert all(inside(case.camera.fov, ranges.camera.fov_deg) and inside(case.camera.z, ranges.camera.height_m)
                   and inside(case.camera.pitch, ranges.camera.pitch_deg) for case in cases)
    else:  # the train world leaves the camera to the variation (and to --vary-camera)
        plain = {train_variation(base, 0, index)[0].camera.z for index in range(60)}
        assert camera_heights == plain
    kinds = {case.scene.kind for case in cases}
    assert len(kinds) >= 4
    assert any(case.sun.altitude <= -2 for case in cases) and any(case.sun.altitude > 20 for case in cases)
    assert any(case.weather.wetness > 0 for case in cases) and any(case.weather.wetness == 0 for case in cases)
    assert any(case.illusions for case in cases) and any(not case.illusions for case in cases)
    assert {case.road.pavement for case in cases} == {"asphalt", "concrete"}


def test_without_world_flags_variations_and_case_files_are_unchanged() -> None:
    base = load_case(CLEAN / "00_straight_urban.json")
    case, parameters = train_variation(base, 2, 1)
    assert case.road.surface_color is None and "surface_color" not in case_json(case)
    assert "world" not in parameters and not case.illusions
    assert case_json(base) == (CLEAN / "00_straight_urban.json").read_text()
    assert case.road.marking_standard == "custom"
    # the world's own stream: the variation's other draws (markings, ego lane and start) stay; the world draws
    # only the standard, the wear and whether broken lane lines are dots
    for index in range(8):
        case, _ = train_variation(base, 2, index)
        varied, _ = train_variation(base, 2, index, world=TRAIN_WORLD)
        drawn = draw_world(world_rng(2, index), TRAIN_WORLD, (base.camera.width, base.camera.height))["markings"]
        plain = [marking.model_dump() for marking in case.road.markings]
        assert [Marking(**m) for m in world_markings(plain, drawn)] == varied.road.markings
        assert (varied.ego, varied.seed) == (case.ego, case.seed)


def test_botts_dots_keep_the_labels_of_the_broken_lines() -> None:
    from lanevil_core.camera.pinhole import ego_camera
    from lanevil_core.labels.lanes import lane_labels
    from lanevil_core.pipeline.compile import compile_scene

    base = load_case(CLEAN / "03_uphill_highway.json")
    dashed = [marking.model_dump() for marking in base.road.markings]
    assert sum(m["type"] == "white_dashed" for m in dashed) >= 2
    dotted = world_markings(dashed, {"botts_dots": True, "wear": 0.5})
    assert sum(m["type"] == "botts_dots" for m in dotted) == sum(m["type"] == "white_dashed" for m in dashed)
    assert world_markings(dotted, {"botts_dots": False, "wear": 0.0}) == dashed
    lanes = []
    for markings in (dashed, dotted):
        data = base.model_dump()
        data["road"].update(markings=markings, marking_standard="us_mutcd")
        scene = compile_scene(parse_case(data))
        camera = ego_camera(scene.case, scene.network, 30, (320, 180))
        labels = lane_labels(scene, camera, np.arange(90.0, 180.0, 10.0))
        lanes.append([(label.boundary.index, np.nan_to_num(label.x_image, nan=-1.0).tolist()) for label in labels])
    assert len(lanes[0]) >= 3 and lanes[0] == lanes[1]


def test_surface_color_round_trips_and_changes_the_road() -> None:
    data = Case().model_dump()
    data["road"]["surface_color"] = (0.12, 0.1, 0.09)
    case = parse_case(data)
    assert parse_case(case_json(case)).road.surface_color == (0.12, 0.1, 0.09)
    with pytest.raises(Exception, match="surface_color"):
        data["road"]["surface_color"] = (2.0, 0.1, 0.1)
        parse_case(data)


def test_surface_color_lightens_the_rendered_road_and_its_gltf() -> None:
    from lanevil_core.export.case import scene_glb
    from lanevil_core.pipeline.compile import compile_scene
    from lanevil_core.render import render_frame
    from lanevil_core.world.scene import ID_ROAD, ID_SKY

    data = load_case(CLEAN / "00_straight_urban.json").model_dump()
    plain = compile_scene(parse_case(data))
    data["road"]["surface_color"] = (0.3, 0.3, 0.3)
    grey = compile_scene(parse_case(data))
    dark, light = render_frame(plain, 0, (160, 90)), render_frame(grey, 0, (160, 90))
    road, sky = dark.object_id == ID_ROAD, dark.object_id == ID_SKY
    assert np.array_equal(road, light.object_id == ID_ROAD)
    assert light.rgb[road].mean() > dark.rgb[road].mean() + 30
    assert abs(float(light.rgb[sky].mean()) - float(dark.rgb[sky].mean())) < 2.0  # the sky stays
    assert scene_glb(plain) != scene_glb(grey)


def test_plan_names_world_folders_and_records_the_draw() -> None:
    sources = discover_cases(CLEAN)
    plan = build_plan(sources, Settings(train_frames=10, seed=1, vary_world=True, heldout=True),
                      mapper=lambda fn, items: map(fn, items))
    assert all(case.folder.name.split("_")[-1].startswith("Heldout") for case in plan.cases)
    assert all(case.source["world"]["scene"] == parse_case(case.case_text).scene.kind for case in plan.cases)


@pytest.mark.parametrize(("settings", "message"), [
    (Settings(train_frames=5, heldout=True), "--heldout: only with --vary-world"),
    (Settings(train_frames=5, vary_world=True, heldout=True, vary_camera=True), "not with --vary-camera"),
    (Settings(train_frames=5, vary_world=True, heldout=True, camera="dashcam"), "not with --camera"),
    (Settings(vary_world=True), "--vary-world: needs --train-frames"),
])
def test_flag_combinations_that_cannot_be_honoured(settings: Settings, message: str) -> None:
    with pytest.raises(PlanError, match=message):
        check_world_flags(settings)


@pytest.mark.parametrize(("flags", "message"), [
    (["--heldout", "--train-frames", "3"], "--heldout: only with --vary-world"),
    (["--vary-world", "--heldout", "--vary-camera", "--train-frames", "3"], "not with --vary-camera"),
    (["--vary-world", "--heldout", "--camera", "dashcam", "--train-frames", "3"], "not with --camera"),
    (["--vary-world", "--cases", "{typed}"], "--vary-world: needs --train-frames"),
])
def test_cli_refuses_bad_combinations_with_one_line(flags: list[str], message: str, tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    typed = tmp_path / "typed"
    shutil.copytree(SCENES / "30_shadow" / "fence_shadow" / "00_uphill_rural_noon", typed)
    argv = ["dataset", "--cases", str(CLEAN), *[flag.format(typed=typed) for flag in flags],
            "--out", str(tmp_path / "out"), "--quiet"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err, err
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
@pytest.mark.parametrize("flags", [["--vary-world"], ["--vary-world", "--heldout"]], ids=["train", "heldout"])
def test_a_tiny_varied_split_writes_labels_that_pass_the_checks(flags: list[str], tmp_path: Path) -> None:
    cases = tmp_path / "cases"
    cases.mkdir()
    shutil.copyfile(CLEAN / "03_uphill_highway.json", cases / "03_uphill_highway.json")
    out = tmp_path / "out"
    assert main(["dataset", "--cases", str(cases), "--out", str(out), "--train-frames", "2", "--size", "160x90",
                 "--workers", "1", "--seed", "3", *flags, "--quiet"]) == 0
    records = read_tusimple(out / "train" / "train_label.json", "gt")  # the scorers' checks of a GT file
    assert len(records) == 2
    for record in records:
        assert record.h_samples == h_samples_for(90)
        assert all(x == -2 or 0 <= x < 160 for lane in record.lanes for x in lane)
        assert (out / "train" / record.raw_file).is_file()
        case = load_case(out / "train" / record.extra["case"] / "case.json")
        assert case.road.surface_color is not None
        world = HELDOUT_WORLD if "--heldout" in flags else TRAIN_WORLD
        assert case.road.marking_standard in world.marking_standards
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["settings"]["world"] == ("heldout" if "--heldout" in flags else "train")
