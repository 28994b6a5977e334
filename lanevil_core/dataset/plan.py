"""Which frames of which cases go where: the test split from case files, the train split from clean variations.

A plan is pure data computed in one process from the case files, the settings and a seed; every worker (a local
process or a Dask worker) receives its share as ``RenderTask`` values, so the same plan gives the same files
whatever runs it.

- Test split: every case with an illusion type (its own first illusion's, or for an original with no illusion
  the type named by its folders, ``.../fence_shadow/00_uphill_rural_noon/00_original.json``) lands in
  ``test/<Category>/<Type>/<original>/<case file stem>/`` (``test/<Category>/<Type>/<case file stem>/`` for a
  folder holding one type's cases directly).
- Train split: the clean cases (no illusion, no type folder) are the bases of deterministic variations (weather
  preset, sun angles, seed, ego lane and start, line types), ``TRAIN_FRAMES_PER_VARIANT`` frames each, in
  ``train/<nnnnn>_<base>_<preset>/``.
"""

from __future__ import annotations

import hashlib
import math
import os
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path, PurePosixPath
from typing import Any

import numpy as np

from ..camera.calibration import CalibrationError, camera_choice
from ..camera.variation import random_camera
from ..case import END_MARGIN_M, Case, case_json, load_case, parse_case
from ..illusions import REGISTRY
from ..library.benchmark_layout import (
    case_folder,
    case_illusion_type,
    case_name,
    folder_type,
    frame_file,
)
from ..pipeline.frames import evenly_spaced
from ..presets import PRESET_NAMES, preset_values
from ..typed import LineType
from .worlds import (
    HELDOUT_WORLD,
    TRAIN_WORLD,
    WorldRanges,
    day_label,
    draw_world,
    world_markings,
    world_parameters,
    world_rng,
)

TEST_SPLIT = "test"
TRAIN_SPLIT = "train"
SPLIT_LABELS = {TEST_SPLIT: "test_label.json", TRAIN_SPLIT: "train_label.json"}
CLEAN_CATEGORY = "Clean"
FORMATS: dict[str, str] = {"png": ".png", "jpg": ".jpg"}  # --format -> frame file suffix

TRAIN_FRAMES_PER_VARIANT = 5  # frames of one train variation, evenly spaced over its drive
CHUNK_FRAMES = 10  # frames per render task: one scene compile (~0.25 s) amortised over ~3 s of rendering
SUN_ALTITUDE_JITTER_DEG = 10.0
# The train split must not let a detector place lanes from the road's layout instead of its paint (the
# paint-free control of the test split measures that). So the layout varies: half the variations move the camera
# mount (lateral offset in the lane, height, pitch, yaw), lane count and width vary, and lines go unpainted: an
# edge line, the lane lines of a variation, or (rarely) every line. An unpainted boundary has no label.
CAMERA_JITTER_SHARE = 0.5
VARIED_CAMERA_SHARE = 0.75  # --vary-camera: share of train variations seen through a drawn camera
CONCRETE_SHARE = 0.3  # --vary-camera: share of train variations on a concrete road (drawn after the camera)
WORN_PAINT_SHARE = 0.5  # --vary-camera: share of train variations whose paint is worn, and by how much at most
PAINT_WEAR_RANGE = (0.1, 0.7)
CAMERA_Y_RANGE_M = (-0.7, 0.7)
CAMERA_Z_RANGE_M = (1.4, 3.2)
CAMERA_PITCH_RANGE_DEG = (0.0, 4.0)
CAMERA_YAW_RANGE_DEG = (-3.0, 3.0)
LANES_PER_DIRECTION_CHOICES = (1, 2, 2, 3)
LANE_WIDTH_RANGE_M = (2.9, 4.0)
NO_EDGE_LINE_SHARE = 0.2  # per edge line
NO_LANE_LINES_SHARE = 0.1  # all lane lines of a variation
NO_CENTER_LINE_SHARE = 0.1
NO_PAINT_SHARE = 0.06  # a variation with no paint at all: no lanes to find
LANE_LINE_CHOICES: tuple[LineType, ...] = ("white_dashed", "white_solid", "botts_dots", "white_solid_dashed")
CENTER_LINE_CHOICES: tuple[LineType, ...] = (
    "yellow_double_solid", "yellow_solid", "yellow_dashed", "yellow_solid_dashed", "white_double_solid",
)


@dataclass(frozen=True)
class Settings:
    """What a dataset run renders: frame size (width, height), image format, frames per test case (None = all),
    total train frames and the seed of the train variations."""

    size: tuple[int, int] = (1280, 720)
    image_format: str = "png"
    frames_per_case: int | None = None
    train_frames: int = 0
    seed: int = 0
    no_paint: bool = False  # also render every original with its lane paint removed (the paint-free control)
    sampling: str = "in_view"  # test frames: "in_view" of each type's level-5 illusion, or "even" over the drive
    camera: str | None = None  # a camera preset or calibration file every case is seen through (None: its own)
    vary_camera: bool = False  # train variations draw their camera and sensor (camera.variation.random_camera)
    vary_world: bool = False  # train variations draw their world (dataset.worlds.draw_world)
    heldout: bool = False  # ... from the held-out ranges (dataset.worlds.HELDOUT_WORLD): a held-out validation split

    @property
    def world(self) -> WorldRanges | None:
        """The ranges train variations draw their world from (None: no world draw)."""
        if not self.vary_world:
            return None
        return HELDOUT_WORLD if self.heldout else TRAIN_WORLD

    @property
    def suffix(self) -> str:
        """Frame file suffix, ``.png`` or ``.jpg``."""
        return FORMATS[self.image_format]


@dataclass(frozen=True)
class SourceCase:
    """A case file found under the cases folder: its path relative to that folder and the parsed case."""

    relative: PurePosixPath
    case: Case

    @property
    def folder_type(self) -> str | None:
        """The illusion type named by the file's folders (``fence_shadow/00_uphill_rural_noon/00_original.json``),
        if any."""
        return folder_type(self.relative)


@dataclass(frozen=True)
class PlannedCase:
    """One case folder of the output: which case, which frames, and the label fields of its records.

    Attributes:
        split: ``test`` or ``train``.
        folder: case folder relative to the split folder, e.g. ``Shadow/Fence/03_level3``.
        case_text: canonical case JSON (``case_json``); its sha256 identifies the case.
        frames: case frame indices rendered, ascending.
        illusion_type: registry type (None for train variations).
        category, type_folder: benchmark folder names (``Clean`` and None for train variations).
        severity: the first illusion's severity, 0 for originals and clean cases.
        source: where the case came from (a case file, or a train variation's base and parameters).
    """

    split: str
    folder: PurePosixPath
    case_text: str
    frames: tuple[int, ...]
    illusion_type: str | None
    category: str
    type_folder: str | None
    severity: int
    source: dict[str, Any] = field(default_factory=dict)
    paint: bool = True

    @property
    def key(self) -> tuple[str, str]:
        """(split, folder): the case folder's identity within a run."""
        return self.split, str(self.folder)

    @property
    def case_sha256(self) -> str:
        """sha256 of the canonical case JSON."""
        return hashlib.sha256(self.case_text.encode("utf-8")).hexdigest()

    @property
    def seed(self) -> int:
        """The case's own seed."""
        return parse_case(self.case_text).seed

    def record_extras(self) -> dict[str, Any]:
        """Fields every TuSimple record of this case carries besides the standard ones."""
        extras = {"category": self.category, "type": self.type_folder, "severity": self.severity,
                  "case": str(self.folder), "illusion": self.illusion_type, "split": self.split}
        if not self.paint:
            extras["paint"] = False
        return extras

    def raw_file(self, frame_index: int, suffix: str) -> str:
        """Frame path relative to the split folder, e.g. ``Shadow/Fence/03_level3/000000.png``."""
        return str(self.folder / frame_file(frame_index, suffix))


@dataclass(frozen=True)
class RenderTask:
    """A chunk of frames of one case, everything a worker needs (plain data, picklable)."""

    split: str
    folder: str
    case_text: str
    case_sha256: str
    frames: tuple[int, ...]
    size: tuple[int, int]
    image_format: str
    extras: dict[str, Any]


@dataclass(frozen=True)
class DatasetPlan:
    """Every case folder of a run, test split first, in a fixed order."""

    settings: Settings
    cases: tuple[PlannedCase, ...]

    @property
    def total_frames(self) -> int:
        """Frames in the plan."""
        return sum(len(case.frames) for case in self.cases)

    def split_cases(self, split: str) -> list[PlannedCase]:
        """The planned cases of one split, in plan order."""
        return [case for case in self.cases if case.split == split]


class PlanError(ValueError):
    """A run that cannot be planned (no cases, clashing folders, no clean case for the train split)."""


def discover_cases(root: Path) -> list[SourceCase]:
    """Every ``**/*.json`` case under ``root``, sorted by relative path (a bad file raises ``CaseError``)."""
    paths = sorted(root.glob("**/*.json"))
    # A single type's folder (``--cases scenes/30_shadow/fence_shadow``) or one original's folder keeps the type's
    # name in the relative paths, so its original is still known as that type's.
    base = root.parent if root.name in REGISTRY else root.parent.parent if root.parent.name in REGISTRY else root
    return [SourceCase(PurePosixPath(path.relative_to(base).as_posix()), load_case(path)) for path in paths]


SAMPLINGS = ("in_view", "even")


Mapper = Callable[[Callable[[Any], Any], list[Any]], Iterable[Any]]  # like the builtin map, over a list


def threads_map(fn: Callable[[Any], Any], items: list[Any]) -> Iterator[Any]:
    """``map`` on one thread per core: the planner's small renders spend their time in GIL-free kernels. Results
    come in order, each as soon as it and those before it are done."""
    with ThreadPoolExecutor(max_workers=max(min(len(items), os.cpu_count() or 1), 1)) as pool:
        yield from pool.map(fn, items)


def _in_view(job: tuple[Case, int]) -> tuple[int, ...]:
    from ..pipeline.illusion_effect import in_view_frames

    return in_view_frames(*job)


def in_view_by_folder(typed: list[SourceCase], frames_per_case: int | None,
                      mapper: Mapper = threads_map) -> dict[str, tuple[int, ...]]:
    """Test frames per case folder (an original and its levels) where that folder's most severe case shows
    its illusion near the lanes, so Original and every level are scored on the same views. Folders are planned
    with ``mapper`` (a dataset run passes its local workers' when it has them)."""
    if frames_per_case is None:
        return {}
    strongest: dict[str, SourceCase] = {}
    for source in typed:
        if source.case.illusions:
            folder = str(source.relative.parent)
            best = strongest.get(folder)
            if best is None or source.case.illusions[0].severity > best.case.illusions[0].severity:
                strongest[folder] = source
    chosen = mapper(_in_view, [(source.case, frames_per_case) for source in strongest.values()])
    return dict(zip(strongest, chosen, strict=True))


def planned_test_case(source: SourceCase, frames_per_case: int | None,
                      frames: tuple[int, ...] | None = None) -> PlannedCase:
    """The test-split entry of a case with an illusion type (``frames``: chosen frames, else evenly spaced)."""
    case = source.case
    illusion_type = case_illusion_type(case, source.folder_type)
    if illusion_type is None:
        raise PlanError(f"{source.relative}: a clean case has no test folder")
    folder = case_folder(case, case_name(source.relative), source.folder_type)
    category, type_folder = folder.parts[0], folder.parts[1]  # case_filing's folders
    severity = case.illusions[0].severity if case.illusions else 0
    return PlannedCase(
        split=TEST_SPLIT, folder=folder, case_text=case_json(case),
        frames=frames if frames is not None else evenly_spaced(case.ego.frames, frames_per_case),
        illusion_type=illusion_type, category=category, type_folder=type_folder,
        severity=severity, source={"file": str(source.relative)},
    )


NO_PAINT_SUFFIX = "_nopaint"


def seen_through(planned: PlannedCase, camera: dict[str, Any], label: str) -> PlannedCase:
    """The same case and frames seen through the camera fields ``camera`` of ``--camera`` (``label``: the preset's
    or the calibration file's name)."""
    data = parse_case(planned.case_text).model_dump()
    data["camera"] = camera
    return replace(planned, case_text=case_json(parse_case(data)), source={**planned.source, "camera": label})


def paint_free(planned: PlannedCase) -> PlannedCase:
    """The same case and frames with every lane marking removed from the world, in ``<folder>_nopaint``."""
    data = parse_case(planned.case_text).model_dump()
    data["road"]["paint"] = False
    case = parse_case(data)
    folder = planned.folder.with_name(planned.folder.name + NO_PAINT_SUFFIX)
    return replace(planned, folder=folder, case_text=case_json(case), paint=False,
                   source={**planned.source, "paint": False})


def _markings(lanes_per_direction: int, rng: np.random.Generator) -> list[dict[str, Any]]:
    """Paint of every boundary, left to right: one lane-line type for all lane lines and one centre line,
    white solid edges, each of them possibly left unpainted (``none``); always ten draws."""
    draws = rng.uniform(0.0, 1.0, 6)
    lane_line = LANE_LINE_CHOICES[int(draws[0] * len(LANE_LINE_CHOICES))]
    center_line = CENTER_LINE_CHOICES[int(draws[1] * len(CENTER_LINE_CHOICES))]
    if draws[2] < NO_LANE_LINES_SHARE:
        lane_line = "none"
    if draws[3] < NO_CENTER_LINE_SHARE:
        center_line = "none"
    edges = ["none" if u < NO_EDGE_LINE_SHARE else "white_solid" for u in draws[4:6]]
    n = lanes_per_direction
    names = [edges[0]] + [lane_line] * (n - 1) + [center_line] + [lane_line] * (n - 1) + [edges[1]]
    if rng.uniform() < NO_PAINT_SHARE:
        names = ["none"] * len(names)
    return [{"type": name} for name in names]


def _camera_mount(base: Case, rng: np.random.Generator) -> dict[str, Any]:
    """The base's camera, or (``CAMERA_JITTER_SHARE`` of the time) one moved within the mount ranges."""
    camera = base.camera.model_dump()
    draws = rng.uniform(0.0, 1.0, 5)  # always five draws, so what is drawn after this does not shift
    ranges = (CAMERA_Y_RANGE_M, CAMERA_Z_RANGE_M, CAMERA_PITCH_RANGE_DEG, CAMERA_YAW_RANGE_DEG)
    if draws[0] < CAMERA_JITTER_SHARE:
        for key, (lo, hi), u in zip(("y", "z", "pitch", "yaw"), ranges, draws[1:], strict=True):
            camera[key] = round(lo + (hi - lo) * float(u), 2)
    return camera


def train_variation(base: Case, seed: int, index: int, vary_camera: bool = False,
                    world: WorldRanges | None = None) -> tuple[Case, dict[str, Any]]:
    """Variation ``index`` of a clean case and its parameters, drawn from ``default_rng([seed, index])``; with
    ``vary_camera`` its camera and sensor are drawn too (after every other draw, so the rest stays the same), and
    used for ``VARIED_CAMERA_SHARE`` of the variations (the rest keep the base's camera, the paper's), and last
    its pavement (concrete slabs for ``CONCRETE_SHARE`` of them) and its paint's wear (``WORN_PAINT_SHARE``).
    With ``world`` (``dataset.worlds``), a world drawn from those ranges on its own stream replaces the scene,
    weather, sun, pavement, lane width, bends and grades, the marking standard and the paint's wear, turns the
    broken lane lines into Botts' dots (some variations), adds traffic, and (a held-out world) the camera."""
    rng = np.random.default_rng([seed, index])
    preset = PRESET_NAMES[int(rng.integers(len(PRESET_NAMES)))]
    values = preset_values(preset)
    altitude = values["sun"]["altitude"]
    if altitude > 0:
        altitude = float(np.clip(altitude + rng.uniform(-1, 1) * SUN_ALTITUDE_JITTER_DEG, 5.0, 85.0))
    azimuth = round(float(rng.uniform(0.0, 360.0)), 1)
    lanes_per_direction = int(LANES_PER_DIRECTION_CHOICES[int(rng.integers(len(LANES_PER_DIRECTION_CHOICES)))])
    lane_width = round(float(rng.uniform(*LANE_WIDTH_RANGE_M)), 2)
    lane = int(rng.integers(lanes_per_direction))
    drive_m = base.ego.speed * (base.ego.frames - 1) / base.ego.fps
    latest_start = max(0.0, base.road.length - END_MARGIN_M - drive_m - 1.0)
    start_s = round(float(rng.uniform(0.0, latest_start)), 1)
    case_seed = int(rng.integers(0, 2**32))
    camera = _camera_mount(base, rng)
    markings = _markings(lanes_per_direction, rng)
    drawn = random_camera(rng, (base.camera.width, base.camera.height)) if vary_camera else None
    if drawn is not None and rng.uniform() < VARIED_CAMERA_SHARE:
        camera = drawn
    pavement = "concrete" if vary_camera and rng.uniform() < CONCRETE_SHARE else base.road.pavement
    wear = 0.0
    if vary_camera:  # always two draws
        worn, amount = rng.uniform(0.0, 1.0, 2)
        if worn < WORN_PAINT_SHARE:
            wear = round(PAINT_WEAR_RANGE[0] + (PAINT_WEAR_RANGE[1] - PAINT_WEAR_RANGE[0]) * float(amount), 2)
    for marking in markings:
        marking["wear"] = wear
    data = base.model_dump()
    data["camera"] = camera
    data["weather"] = values["weather"]
    data["sun"] = {**values["sun"], "azimuth": azimuth, "altitude": round(altitude, 1)}
    data["road"].update(lanes_per_direction=lanes_per_direction, lane_width=lane_width,
                        markings=markings, pavement=pavement)
    data["ego"].update(lane=lane, start_s=start_s)
    data["seed"] = case_seed
    parameters: dict[str, Any] = {}
    if world is not None:
        drawn_world = draw_world(world_rng(seed, index), world, (base.camera.width, base.camera.height))
        data["road"].update(drawn_world["road"], markings=world_markings(markings, drawn_world["markings"]))
        wear = drawn_world["markings"]["wear"]
        data.update({key: drawn_world[key] for key in ("scene", "weather", "sun", "illusions", "camera")
                     if key in drawn_world})
        camera = data["camera"]
        preset = ("Heldout" if world.draws_camera else "World") + day_label(drawn_world["sun"]["altitude"])
        parameters["world"] = world_parameters(drawn_world)
    data["title"] = f"{base.title} ({preset}, variation {index})"
    road = data["road"]
    parameters = {"preset": preset, "sun_azimuth": data["sun"]["azimuth"], "sun_altitude": data["sun"]["altitude"],
                  "seed": case_seed, "lane": lane, "start_s": start_s, "lanes_per_direction": lanes_per_direction,
                  "lane_width": road["lane_width"], "pavement": road["pavement"], "paint_wear": wear,
                  "camera": {k: camera[k] for k in ("fov", "x", "y", "z", "pitch", "yaw", "roll") if k in camera},
                  "markings": [m["type"] for m in road["markings"]], **parameters}
    return parse_case(data, source=f"train variation {index}"), parameters


def train_cases(clean: list[SourceCase], train_frames: int, seed: int,
                vary_camera: bool = False, world: WorldRanges | None = None) -> list[PlannedCase]:
    """``train_frames`` frames over variations of the clean cases (bases taken in turn, so every road type,
    scene and line type of the clean library recurs)."""
    if train_frames <= 0:
        return []
    if not clean:
        raise PlanError("--train-frames needs clean cases (cases with no illusion) under --cases")
    planned = []
    for index in range(math.ceil(train_frames / TRAIN_FRAMES_PER_VARIANT)):
        base = clean[index % len(clean)]
        case, parameters = train_variation(base.case, seed, index, vary_camera, world)
        count = min(TRAIN_FRAMES_PER_VARIANT, train_frames - index * TRAIN_FRAMES_PER_VARIANT)
        folder = PurePosixPath(f"{index:05d}_{base.relative.stem}_{parameters['preset']}")
        planned.append(PlannedCase(
            split=TRAIN_SPLIT, folder=folder, case_text=case_json(case),
            frames=evenly_spaced(case.ego.frames, count), illusion_type=None, category=CLEAN_CATEGORY,
            type_folder=None, severity=0,
            source={"base": str(base.relative), "seed": seed, "variation": index, **parameters},
        ))
    return planned


def _check_unique(cases: list[PlannedCase]) -> None:
    seen: dict[tuple[str, str], str] = {}
    for case in cases:
        key = case.key
        where = str(case.source.get("file", case.source))
        if key in seen:
            raise PlanError(f"{seen[key]} and {where} both map to {case.split}/{case.folder}")
        seen[key] = where


def split_sources(sources: list[SourceCase], settings: Settings) -> tuple[list[SourceCase], list[SourceCase]]:
    """(typed, clean): the cases of the test split and the bases of the train split; raises ``PlanError`` for a
    run that would write nothing or ignore a setting (``--frames-per-case`` with no test case). Cheap: a run
    checks this before it starts its workers."""
    if not sources:
        raise PlanError("no case files (*.json) found")
    typed = [s for s in sources if case_illusion_type(s.case, s.folder_type) is not None]
    clean = [s for s in sources if case_illusion_type(s.case, s.folder_type) is None]
    if settings.sampling not in SAMPLINGS:
        raise PlanError(f"sampling: {settings.sampling!r} is not one of {', '.join(SAMPLINGS)}")
    if not typed and settings.frames_per_case is not None:
        raise PlanError(f"--frames-per-case {settings.frames_per_case}: no test case under --cases (a test case has "
                        f"an illusion, or sits in an illusion type's folder); the {len(clean)} clean case(s) only "
                        "seed the train split, sized by --train-frames")
    if not typed and settings.train_frames <= 0:
        raise PlanError("no test cases (cases with an illusion type) found and --train-frames is 0")
    check_world_flags(settings)
    return typed, clean


def check_world_flags(settings: Settings) -> None:
    """Raise ``PlanError`` for world flags that cannot be honoured: ``--heldout`` without ``--vary-world``, a
    held-out split with train cameras (``--vary-camera``) or one fixed camera (``--camera``), a world draw with no
    train frames."""
    if settings.heldout and not settings.vary_world:
        raise PlanError("--heldout: only with --vary-world (it picks the held-out ranges of the world draw)")
    if settings.heldout and settings.vary_camera:
        raise PlanError("--heldout: not with --vary-camera (a held-out split draws its cameras outside the "
                        "--vary-camera ranges)")
    if settings.heldout and settings.camera is not None:
        raise PlanError("--heldout: not with --camera (a held-out split draws its own cameras)")
    if settings.vary_world and settings.train_frames <= 0:
        raise PlanError("--vary-world: needs --train-frames (it varies the train variations)")


def build_plan(sources: list[SourceCase], settings: Settings, mapper: Mapper = threads_map) -> DatasetPlan:
    """The test split from the typed cases, the train split from variations of the clean ones (in-view frames
    found with ``mapper``)."""
    typed, clean = split_sources(sources, settings)
    chosen = in_view_by_folder(typed, settings.frames_per_case, mapper) if settings.sampling == "in_view" else {}
    planned = [planned_test_case(source, settings.frames_per_case,
                                 chosen.get(str(source.relative.parent))) for source in typed]
    if settings.no_paint:
        planned += [paint_free(case) for case in planned if case.severity == 0]
    planned += train_cases(clean, settings.train_frames, settings.seed, settings.vary_camera, settings.world)
    if settings.camera is not None:  # every case through one camera; drawn train cameras stay drawn
        try:  # a preset, or a calibration file read once (``camera.calibration``)
            camera, label = camera_choice(settings.camera)
        except CalibrationError as error:
            raise PlanError(str(error)) from None
        drawn = settings.vary_camera or settings.heldout
        planned = [case if drawn and case.split == TRAIN_SPLIT else seen_through(case, camera, label)
                   for case in planned]
    _check_unique(planned)
    return DatasetPlan(settings, tuple(planned))


def render_tasks(plan: DatasetPlan, pending: dict[tuple[str, str], list[int]],
                 chunk_frames: int = CHUNK_FRAMES) -> list[RenderTask]:
    """Tasks of at most ``chunk_frames`` frames covering the ``pending`` frames ((split, folder) -> frames)."""
    tasks = []
    settings = plan.settings
    for case in plan.cases:
        frames = pending.get(case.key, [])
        for start in range(0, len(frames), chunk_frames):
            tasks.append(RenderTask(case.split, str(case.folder), case.case_text, case.case_sha256,
                                    tuple(frames[start:start + chunk_frames]), settings.size,
                                    settings.image_format, case.record_extras()))
    return tasks
