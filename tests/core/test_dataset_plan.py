"""Dataset plans: frame spacing, folders of the stock library, train variations, the renderer's source set."""

from __future__ import annotations

from pathlib import Path, PurePosixPath

import pytest

from lanevil_core.case import Case, parse_case
from lanevil_core.dataset import PlanError, Settings, build_plan, discover_cases, evenly_spaced
from lanevil_core.dataset.manifest import _PACKAGE, source_files
from lanevil_core.dataset.plan import SourceCase, render_tasks, train_variation
from lanevil_core.library.benchmark_layout import CATEGORY_FOLDERS, TYPE_FOLDERS
from lanevil_core.library.stock import ORIGINALS, original_folder
from lanevil_core.presets import PRESET_NAMES

SCENES = Path(__file__).resolve().parents[2] / "scenes"


@pytest.mark.parametrize(("total", "count", "expected"), [
    (100, 1, (0,)),
    (100, 2, (0, 99)),
    (100, 4, (0, 33, 66, 99)),
    (5, None, (0, 1, 2, 3, 4)),
    (5, 9, (0, 1, 2, 3, 4)),
])
def test_evenly_spaced(total: int, count: int | None, expected: tuple[int, ...]) -> None:
    assert evenly_spaced(total, count) == expected


@pytest.fixture(scope="module")
def stock() -> list[SourceCase]:
    return discover_cases(SCENES)


def test_stock_library_plan(stock: list[SourceCase]) -> None:
    plan = build_plan(stock, Settings(frames_per_case=10, train_frames=160, sampling="even"))
    test = plan.split_cases("test")
    originals = sum(len(originals) for originals in ORIGINALS.values())
    assert len(test) == 6 * originals  # every original and its five levels
    assert len({case.folder for case in test}) == len(test)
    for case in test:
        category, type_folder, original, name = case.folder.parts
        assert category in CATEGORY_FOLDERS.values() and type_folder in TYPE_FOLDERS.values()
        assert case.severity == (0 if name == "00_original" else int(name[-1]))
        assert len(case.frames) == 10
    assert str(test[0].folder) == "RoadDamage/GuardRail/00_bend_highway_noon/00_original"  # sorted by source path
    assert sum(len(case.frames) for case in plan.split_cases("train")) == 160
    assert plan.total_frames == 10 * len(test) + 160


def test_full_test_split_reaches_the_paper_s_scale(stock: list[SourceCase]) -> None:
    """All frames of every case (the default): at least 94 originals, 560 cases and 50,000 test frames."""
    plan = build_plan(stock, Settings())
    test = plan.split_cases("test")
    assert len([case for case in test if case.severity == 0]) >= 94 and len(test) >= 560
    assert sum(len(case.frames) for case in test) >= 50_000
    assert all(case.frames == tuple(range(100)) for case in test)


def test_one_original_s_folder_keeps_its_type() -> None:
    sources = discover_cases(SCENES / "30_shadow" / "fence_shadow" / "00_uphill_rural_noon")
    assert {s.folder_type for s in sources} == {"fence_shadow"} and len(sources) == 6
    plan = build_plan(sources, Settings(frames_per_case=1, sampling="even"))
    assert [str(c.folder) for c in plan.split_cases("test")][:2] == ["Shadow/Fence/00_uphill_rural_noon/00_original",
                                                                      "Shadow/Fence/00_uphill_rural_noon/01_level1"]


def test_train_variations_are_seeded_valid_and_varied(stock: list[SourceCase]) -> None:
    clean = [source for source in stock if source.relative.parts[0] == "00_clean"]
    assert len(clean) == 9
    variations = [train_variation(source.case, 7, index) for index, source in enumerate(clean * 3)]
    again = [train_variation(source.case, 7, index) for index, source in enumerate(clean * 3)]
    assert variations == again
    assert train_variation(clean[0].case, 8, 0) != variations[0]
    for case, parameters in variations:
        assert isinstance(case, Case) and not case.illusions
        assert parameters["preset"] in PRESET_NAMES
        assert 0 <= case.ego.lane < case.road.lanes_per_direction
    assert len({p["preset"] for _, p in variations}) >= 6
    assert len({tuple(p["markings"]) for _, p in variations}) >= 6


def test_clashing_folders_and_missing_cases_are_plan_errors(stock: list[SourceCase]) -> None:
    original = next(source for source in stock if source.relative.name == "01_level1.json")
    twin = SourceCase(PurePosixPath("copy") / original.relative, original.case)
    with pytest.raises(PlanError, match="both map to test/"):
        build_plan([original, twin], Settings())
    with pytest.raises(PlanError, match="no case files"):
        build_plan([], Settings())


def test_tasks_cover_the_pending_frames_in_chunks(stock: list[SourceCase]) -> None:
    plan = build_plan(stock[:12], Settings(frames_per_case=10, sampling="even"))
    pending = {case.key: list(case.frames) for case in plan.cases}
    tasks = render_tasks(plan, pending, chunk_frames=4)
    assert sum(len(task.frames) for task in tasks) == plan.total_frames
    assert max(len(task.frames) for task in tasks) == 4


def test_renderer_sources_reach_the_render_path_only() -> None:
    names = {path.relative_to(_PACKAGE).as_posix() for path in source_files()}
    assert {"dataset/worker.py", "render/renderer.py", "labels/lanes.py", "pipeline/compile.py",
            "images.py"} <= names
    assert not any(name.startswith(("cli", "dataset/local", "dataset/run")) for name in names)


def test_in_view_sampling_picks_frames_that_show_the_illusion(stock: list[SourceCase]) -> None:
    from lanevil_core.pipeline.illusion_effect import IN_VIEW_SHARE, SHARE_SIZE, clean_of, frame_changes

    fence = [source for source in stock if str(source.relative.parent) == original_folder("fence_shadow")]
    plan = build_plan(fence, Settings(frames_per_case=4))
    frames = {case.frames for case in plan.split_cases("test")}
    assert len(frames) == 1  # the original and every level share the views
    strongest = max(fence, key=lambda s: s.case.illusions[0].severity if s.case.illusions else 0).case
    changes = frame_changes(clean_of(strongest), strongest, next(iter(frames)), SHARE_SIZE)
    assert all(change.share >= IN_VIEW_SHARE for change in changes)


def test_in_view_planning_on_worker_processes_picks_the_same_frames(stock: list[SourceCase]) -> None:
    from lanevil_core.dataset.local import LocalPool

    folders = (original_folder("fence_shadow"), original_folder("vehicle"))
    sources = [source for source in stock if str(source.relative.parent) in folders]
    on_threads = build_plan(sources, Settings(frames_per_case=3))
    pool = LocalPool(2)
    pool.start()
    try:
        on_workers = build_plan(sources, Settings(frames_per_case=3), pool.map)
    finally:
        pool.close()
    assert [case.frames for case in on_workers.cases] == [case.frames for case in on_threads.cases]


def test_a_single_type_folder_keeps_its_original_as_that_type() -> None:
    sources = discover_cases(SCENES / "30_shadow" / "fence_shadow")
    assert [str(s.relative) for s in sources][:2] == ["fence_shadow/00_uphill_rural_noon/00_original.json",
                                                      "fence_shadow/00_uphill_rural_noon/01_level1.json"]
    assert {s.folder_type for s in sources} == {"fence_shadow"}
    plan = build_plan(sources, Settings(frames_per_case=2, sampling="even"))
    levels = sorted(c.severity for c in plan.split_cases("test"))
    assert levels == sorted([0, 1, 2, 3, 4, 5] * len(ORIGINALS["fence_shadow"]))


def test_the_local_pool_lets_go_of_each_task_s_frames_once_they_are_written():
    """A finished future holds its frames' encoded bytes: the pool must drop it once ``on_done`` has them, or a
    58,800-frame run keeps every PNG in memory (about 0.4 MB each) to the end."""
    import gc
    import weakref
    from concurrent.futures import ThreadPoolExecutor

    from lanevil_core.dataset.local import _run_on

    class Frames:  # stands for a task's encoded frames
        pass

    handed: list[weakref.ref] = []
    alive_at_each_call: list[int] = []

    def on_done(task, frames):
        gc.collect()
        alive_at_each_call.append(sum(ref() is not None for ref in handed))
        handed.append(weakref.ref(frames))

    _run_on(ThreadPoolExecutor(max_workers=1), list(range(6)), on_done, work=lambda task: Frames())
    assert len(handed) == 6
    # At each call only the frames handed over now are alive (this call's argument), none of the earlier tasks'.
    assert alive_at_each_call == [0] * 6


def test_a_case_of_two_illusion_types_is_planned_under_mixed(stock: list[SourceCase]) -> None:
    source = next(source for source in stock if source.relative.name == "03_level3.json"
                  and source.case.illusions[0].type == "fence_shadow")
    data = source.case.model_dump()
    data["illusions"].append({"type": "road_crack", "severity": 2, "s": 60.0})
    mixed = SourceCase(source.relative, parse_case(data))
    planned = build_plan([mixed], Settings(frames_per_case=2, sampling="even")).cases[0]
    assert str(planned.folder) == "Mixed/RoadDamageRoadCrack+ShadowFence/00_uphill_rural_noon/03_level3"
    assert (planned.category, planned.type_folder, planned.illusion_type) == (
        "Mixed", "RoadDamageRoadCrack+ShadowFence", "road_crack+fence_shadow")
