"""``lanevil dataset``: layout and labels, manifest, determinism, resume, CLI errors (tiny frames, few cases)."""

from __future__ import annotations

import functools
import hashlib
import json
import multiprocessing
import shutil
import socket
from collections.abc import Sequence
from pathlib import Path

import pytest
from PIL import Image

from lanevil_core.case import case_json, load_case
from lanevil_core.cli import main
from lanevil_core.dataset import Settings, generate_dataset
from lanevil_core.dataset.local import LocalPool, run_local
from lanevil_core.dataset.plan import PlanError, RenderTask
from lanevil_core.dataset.worker import FrameResult, TaskDone
from lanevil_core.labels.lanes import h_samples_for

SCENES = Path(__file__).resolve().parents[2] / "scenes"
SIZE = "160x90"
CASE_FILES = (
    "30_shadow/fence_shadow/00_uphill_rural_noon/00_original.json",
    "30_shadow/fence_shadow/00_uphill_rural_noon/01_level1.json",
    "10_road_damage/road_crack/00_straight_suburban_cloudy/03_level3.json",
    "00_clean/00_straight_urban.json",
)
EXPECTED_TEST = {  # case folder -> (category, type, severity, source file)
    "Shadow/Fence/00_uphill_rural_noon/00_original": ("Shadow", "Fence", 0, CASE_FILES[0]),
    "Shadow/Fence/00_uphill_rural_noon/01_level1": ("Shadow", "Fence", 1, CASE_FILES[1]),
    "RoadDamage/RoadCrack/00_straight_suburban_cloudy/03_level3": ("RoadDamage", "RoadCrack", 3, CASE_FILES[2]),
}
ARGS = ["--size", SIZE, "--frames-per-case", "2", "--sampling", "even", "--train-frames", "3", "--quiet"]
SETTINGS = Settings(size=(160, 90), frames_per_case=2, train_frames=3, sampling="even")  # ARGS in the API


def copy_cases(root: Path, files: tuple[str, ...] = CASE_FILES) -> Path:
    """A cases folder holding copies of some stock cases under their stock relative paths."""
    for relative in files:
        target = root / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(SCENES / relative, target)
    return root


def run_cli(*argv: str) -> int:
    return main(["dataset", *argv])


def tree(root: Path) -> dict[str, str]:
    """Relative path -> sha256 of every file under ``root``."""
    return {path.relative_to(root).as_posix(): hashlib.sha256(path.read_bytes()).hexdigest()
            for path in sorted(root.rglob("*")) if path.is_file()}


def read_lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


@pytest.fixture(scope="module")
def cases_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return copy_cases(tmp_path_factory.mktemp("cases"))


@pytest.fixture(scope="module")
def dataset(cases_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One generated dataset (one worker), shared by the read-only tests."""
    out = tmp_path_factory.mktemp("dataset")
    assert run_cli("--cases", str(cases_dir), "--out", str(out), "--workers", "1", *ARGS) == 0
    return out


def test_test_split_layout_and_labels(dataset: Path) -> None:
    split = dataset / "test"
    folders = sorted(p.parent.relative_to(split).as_posix() for p in split.rglob("labels.json"))
    assert folders == sorted(EXPECTED_TEST)
    all_records = []
    for folder, (category, type_folder, severity, _) in EXPECTED_TEST.items():
        records = read_lines(split / folder / "labels.json")
        assert [r["frame"] for r in records] == [0, 99]  # two frames spread over the 100-frame drive
        for record in records:
            assert record["raw_file"] == f"{folder}/{record['frame']:06d}.png"
            with Image.open(split / record["raw_file"]) as image:
                assert image.size == (160, 90) and image.format == "PNG"
            assert record["h_samples"] == h_samples_for(90)
            assert 2 <= len(record["lanes"]) <= 5
            assert all(len(lane) == len(record["h_samples"]) for lane in record["lanes"])
            assert all(x == -2 or 0 <= x < 160 for lane in record["lanes"] for x in lane)
            assert (record["category"], record["type"], record["severity"], record["case"]) == (
                category, type_folder, severity, folder)
            assert {"visibility", "line_types"} <= record.keys()
            if severity:  # where the illusion shows, measured against the case without it
                assert 0.0 <= record["illusion_share"] <= 1.0 and record["illusion_effect"] >= 0.0
            else:
                assert "illusion_share" not in record
        all_records += records
    # The split file holds the same lines as the case files (case folders sorted by source path).
    split_records = read_lines(split / "test_label.json")
    assert sorted(map(json.dumps, split_records)) == sorted(map(json.dumps, all_records))
    assert (split / "Shadow/Fence/00_uphill_rural_noon/01_level1/case.json").is_file()


def test_train_split_from_clean_variations(dataset: Path) -> None:
    records = read_lines(dataset / "train" / "train_label.json")
    assert len(records) == 3
    for record in records:
        assert (dataset / "train" / record["raw_file"]).is_file()
        assert record["category"] == "Clean" and record["severity"] == 0 and record["split"] == "train"
        case = load_case(dataset / "train" / record["case"] / "case.json")
        assert not case.illusions
        assert record["raw_file"].startswith("00000_00_straight_urban_")


def test_manifest_pins_inputs_and_hashes(dataset: Path, cases_dir: Path) -> None:
    manifest = json.loads((dataset / "manifest.json").read_text())
    assert {"lanevil", "numpy", "numba", "python", "pillow", "renderer_source_sha256"} <= manifest["versions"].keys()
    assert manifest["settings"]["size"] == [160, 90] and manifest["settings"]["format"] == "png"
    assert manifest["splits"]["test"] == {"labels": "test/test_label.json", "cases": 3, "frames": 6}
    by_case = {entry["case"]: entry for entry in manifest["cases"] if entry["split"] == "test"}
    assert by_case.keys() == EXPECTED_TEST.keys()
    for folder, (_, _, severity, source) in EXPECTED_TEST.items():
        entry = by_case[folder]
        case = load_case(cases_dir / source)
        assert entry["case_sha256"] == hashlib.sha256(case_json(case).encode()).hexdigest()
        assert entry["seed"] == case.seed and entry["severity"] == severity
        assert entry["illusion_type"] == ("road_crack" if "Crack" in folder else "fence_shadow")
        assert entry["source"] == {"file": source}
        assert [f["frame"] for f in entry["frames"]] == [0, 99]
        for frame in entry["frames"]:
            assert hashlib.sha256((dataset / frame["file"]).read_bytes()).hexdigest() == frame["sha256"]
    train = [entry for entry in manifest["cases"] if entry["split"] == "train"]
    assert train[0]["source"]["base"] == CASE_FILES[3] and train[0]["source"]["preset"]


def test_lanevil_render_regenerates_a_frame_byte_identically(dataset: Path, tmp_path: Path) -> None:
    manifest = json.loads((dataset / "manifest.json").read_text())
    entry = next(entry for entry in manifest["cases"] if entry["split"] == "train")
    frame = entry["frames"][-1]
    target = tmp_path / "again.png"
    assert main(["render", str(dataset / entry["case_file"]), "--frame", str(frame["frame"]), "--size", SIZE,
                 "--out", str(target)]) == 0
    assert hashlib.sha256(target.read_bytes()).hexdigest() == frame["sha256"]


def test_rerun_keeps_every_verified_frame(dataset: Path, cases_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    before = tree(dataset)
    assert run_cli("--cases", str(cases_dir), "--out", str(dataset), "--workers", "1", *ARGS) == 0
    assert "(0 rendered, 9 kept)" in capsys.readouterr().out
    assert tree(dataset) == before


def test_process_pool_writes_the_same_bytes_as_one_process(dataset: Path, cases_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "two_workers"
    assert run_cli("--cases", str(cases_dir), "--out", str(out), "--workers", "2", *ARGS) == 0
    assert tree(out) == tree(dataset)


def test_resume_repairs_exactly_the_damaged_frames(
    dataset: Path, cases_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    out = tmp_path / "damaged"
    shutil.copytree(dataset, out)
    expected = tree(dataset)
    case_dir = out / "test/Shadow/Fence/00_uphill_rural_noon/01_level1"
    missing, truncated = case_dir / "000000.png", case_dir / "000099.png"
    flipped = out / "test/RoadDamage/RoadCrack/00_straight_suburban_cloudy/03_level3/000000.png"
    missing.unlink()
    truncated.write_bytes(truncated.read_bytes()[:100])
    data = bytearray(flipped.read_bytes())
    data[len(data) // 2] ^= 0xFF
    flipped.write_bytes(bytes(data))
    partial = case_dir / ".000000.png.tmp123"  # what an interrupted atomic write leaves behind
    partial.write_bytes(b"\x89PNG partial")
    untouched = {path: path.stat().st_mtime_ns for path in out.rglob("*.png") if path not in (truncated, flipped)}
    assert run_cli("--cases", str(cases_dir), "--out", str(out), "--workers", "1", *ARGS) == 0
    assert "(3 rendered, 6 kept)" in capsys.readouterr().out
    assert not partial.exists()
    assert tree(out) == expected
    assert all(path.stat().st_mtime_ns == mtime for path, mtime in untouched.items())


def test_interrupted_run_resumes_to_the_same_bytes(dataset: Path, cases_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "interrupted"

    def interrupt_after_two_tasks(tasks: Sequence[RenderTask], on_done: TaskDone) -> None:
        done = []

        def counting(task: RenderTask, results: list[FrameResult]) -> None:
            on_done(task, results)
            done.append(task)
            if len(done) == 2:
                raise KeyboardInterrupt

        run_local(tasks, counting, workers=1)

    with pytest.raises(KeyboardInterrupt):
        generate_dataset(cases_dir, out, SETTINGS, interrupt_after_two_tasks, show_progress=False)
    assert not (out / "manifest.json").exists()
    written = sorted(out.rglob("*.png"))
    assert 0 < len(written) < 9
    summary = generate_dataset(cases_dir, out, SETTINGS, functools.partial(run_local, workers=1),
                               show_progress=False)
    assert (summary.kept, summary.rendered) == (len(written), 9 - len(written))
    assert 0 < summary.render_seconds < summary.seconds  # planning, resume check and manifest are not rendering
    assert summary.frames_per_second == pytest.approx(summary.rendered / summary.render_seconds)
    assert tree(out) == tree(dataset)


def test_frames_from_other_settings_are_not_reused(dataset: Path, cases_dir: Path, tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "resized"
    shutil.copytree(dataset, out)
    assert run_cli("--cases", str(cases_dir), "--out", str(out), "--workers", "1", "--size", "128x72",
                   "--frames-per-case", "1", "--sampling", "even", "--quiet") == 0
    line = capsys.readouterr().out
    assert "(3 rendered, 0 kept); rendering " in line and " frames/s; total wall time " in line
    labels = json.loads((out / "test/Shadow/Fence/00_uphill_rural_noon/00_original/labels.json").read_text())
    (record,) = labels if isinstance(labels, list) else [labels]
    with Image.open(out / "test" / record["raw_file"]) as image:  # the one frame this run wrote for the case
        assert image.size == (128, 72)
    manifest = json.loads((out / "manifest.json").read_text())
    assert [entry["split"] for entry in manifest["cases"]] == ["test"] * 3


def test_frames_from_other_code_are_not_reused(dataset: Path, cases_dir: Path, tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    # an illusion's code can change its frames while the case files stay the same: the render-path digest is part
    # of every frame's key, so a rerun after such a change renders every frame again
    out = tmp_path / "other_code"
    shutil.copytree(dataset, out)
    monkeypatch.setattr("lanevil_core.dataset.manifest.source_digest", lambda: "0" * 64)
    summary = generate_dataset(cases_dir, out, SETTINGS, functools.partial(run_local, workers=1),
                               show_progress=False)
    assert (summary.kept, summary.rendered) == (0, 9)
    assert json.loads((out / "manifest.json").read_text())["versions"]["renderer_source_sha256"] == "0" * 64
    assert {path: data for path, data in tree(out).items() if path.endswith(".png")} == \
        {path: data for path, data in tree(dataset).items() if path.endswith(".png")}


def test_jpg_format(cases_dir: Path, tmp_path: Path) -> None:
    cases = copy_cases(tmp_path / "cases", CASE_FILES[:1])
    out = tmp_path / "jpg"
    assert run_cli("--cases", str(cases), "--out", str(out), "--size", SIZE, "--frames-per-case", "1",
                   "--format", "jpg", "--workers", "1", "--quiet") == 0
    record = read_lines(out / "test" / "test_label.json")[0]
    assert record["raw_file"] == "Shadow/Fence/00_uphill_rural_noon/00_original/000000.jpg"
    assert (out / "test" / record["raw_file"]).read_bytes()[:3] == b"\xff\xd8\xff"


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


@pytest.mark.parametrize(("argv", "message"), [
    (["--cases", "{tmp}/nowhere"], "no such folder"),
    (["--cases", "{tmp}/empty"], "no case files"),
    (["--cases", "{cases}", "--size", "160by90"], "is not WIDTHxHEIGHT"),
    (["--cases", "{cases}", "--size", "10x10"], "must lie in 64..4096"),
    (["--cases", "{cases}", "--format", "gif"], "invalid choice"),
    (["--cases", "{cases}", "--frames-per-case", "0"], "argument --frames-per-case: must be at least 1"),
    (["--cases", "{cases}", "--scheduler", "localhost:8786"], "is not tcp://HOST:PORT"),
    (["--cases", "{cases}", "--scheduler", "tcp://127.0.0.1:{port}", "--scheduler-timeout", "1"],
     "cannot reach the Dask scheduler"),
    (["--cases", "{typed}", "--train-frames", "5"], "--train-frames needs clean cases"),
    (["--cases", "{clean}", "--frames-per-case", "3"], "--frames-per-case 3: no test case under --cases"),
    (["--cases", "{clean}", "--frames-per-case", "3", "--train-frames", "5"], "only seed the train split"),
    (["--cases", "{clean}"], "no test cases (cases with an illusion type) found and --train-frames is 0"),
])
def test_cli_errors_exit_2_with_one_line(argv: list[str], message: str, tmp_path: Path, cases_dir: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "empty").mkdir()
    typed = copy_cases(tmp_path / "typed", CASE_FILES[:1])
    clean = copy_cases(tmp_path / "clean", CASE_FILES[3:]) / "00_clean"
    values = {"tmp": tmp_path, "cases": cases_dir, "typed": typed, "clean": clean, "port": _free_port()}
    argv = [part.format(**values) for part in argv]
    assert run_cli(*argv, "--out", str(tmp_path / "out"), "--quiet") == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err, err
    assert not (tmp_path / "out" / "manifest.json").exists()


def test_levels_of_a_folder_share_the_worker_s_original_renders() -> None:
    from lanevil_core.dataset import worker
    from lanevil_core.pipeline.compile import compile_scene
    from lanevil_core.pipeline.illusion_effect import SHARE_SIZE, clean_of, scene_changes

    folder = SCENES / "30_shadow" / "fence_shadow" / "00_uphill_rural_noon"
    frames = (0, 30)
    worker._CLEAN_VIEWS.clear()
    for level in (2, 4):
        case = load_case(folder / f"0{level}_level{level}.json")
        text = case_json(case)
        task = RenderTask("test", f"level{level}", text, hashlib.sha256(text.encode()).hexdigest(), frames,
                          (320, 180), "png", {})
        scene = worker.compiled_scene(task.case_text, task.case_sha256)
        measured = worker.illusion_changes(task, scene)
        fresh = scene_changes(compile_scene(clean_of(case)), scene, frames, SHARE_SIZE)  # nothing cached
        assert [measured[f] for f in frames] == [
            {"illusion_share": round(c.share, 4), "illusion_effect": round(c.effect, 3)} for c in fresh]
        assert len(worker._CLEAN_VIEWS) == len(frames)  # the second level found the original's renders


def test_workers_started_before_planning_stop_when_planning_fails(tmp_path: Path) -> None:
    pool = LocalPool(2)
    (tmp_path / "empty").mkdir()
    with pytest.raises(PlanError, match="no case files"):
        generate_dataset(tmp_path / "empty", tmp_path / "out", Settings(size=(64, 36)), pool, show_progress=False)
    assert multiprocessing.active_children() == []


def test_dask_cluster_writes_the_same_bytes_as_the_local_run(dataset: Path, cases_dir: Path, tmp_path: Path) -> None:
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        out = tmp_path / "dask"
        assert run_cli("--cases", str(cases_dir), "--out", str(out), "--scheduler", cluster.scheduler_address,
                       *ARGS) == 0
    assert tree(out) == tree(dataset)


def test_planning_shows_a_bar_over_the_case_folders(cases_dir: Path, tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """The in-view search renders a few small frames per case folder (minutes for the whole library) before the
    first frame is rendered: a bar counts the folders, so a long planning does not look like a hang."""
    settings = Settings(size=(160, 90), frames_per_case=1, train_frames=0)
    generate_dataset(cases_dir, tmp_path / "out", settings, functools.partial(run_local, workers=1))
    err = capsys.readouterr().err
    assert "planning: 100%" in err
    assert "2/2 [" in err  # the fence shadow's folder and the road crack's
    generate_dataset(cases_dir, tmp_path / "quiet", settings, functools.partial(run_local, workers=1),
                     show_progress=False)
    assert "planning" not in capsys.readouterr().err
