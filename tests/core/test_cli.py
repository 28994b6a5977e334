"""The ``lanevil`` command line: subcommands, one-line user errors with exit status 2, extension commands."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import types
from functools import partial
from pathlib import Path

import pytest
from PIL import Image

from lanevil_core import cli, files
from lanevil_core.case import save_case
from lanevil_core.cli import base as cli_base
from lanevil_core.cli import core as cli_core
from lanevil_core.pipeline import bench


@pytest.fixture
def case_file(tmp_path, make_case) -> Path:
    path = tmp_path / "case.json"
    save_case(make_case(), path)
    return path


def _error_line(capsys) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_render_writes_image_overlay_and_labels(case_file, tmp_path, capsys):
    out, labels = tmp_path / "f.png", tmp_path / "f.json"
    assert cli.main(["render", str(case_file), "--frame", "4", "--out", str(out), "--overlay",
                     "--labels", str(labels)]) == 0
    assert Image.open(out).size == (320, 180)
    record = json.loads(labels.read_text())
    assert record["raw_file"] == "f.png" and record["frame"] == 4
    assert record["h_samples"] == sorted({round(y / 4) for y in range(160, 720, 10)})
    assert capsys.readouterr().out.strip() == str(out)


def test_render_size_flag(case_file, tmp_path):
    out = tmp_path / "small.png"
    assert cli.main(["render", str(case_file), "--out", str(out), "--size", "160x90"]) == 0
    assert Image.open(out).size == (160, 90)


def test_invalid_case_names_the_field(tmp_path, capsys):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"road": {"lane_width": 1.0}}))
    assert cli.main(["render", str(path), "--out", str(tmp_path / "x.png")]) == 2
    assert _error_line(capsys) == (
        f"lanevil: error: {path}: road.lane_width: Input should be greater than or equal to 2.5")
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["render", "{case}", "--frame", "50", "--out", "{tmp}/x.png"], "--frame 50 is outside 0..49"),
        (["render", "{case}", "--frame", "-1", "--out", "{tmp}/x.png"], "--frame -1"),
        (["render", "{case}", "--size", "12x", "--out", "{tmp}/x.png"], "argument --size"),
        (["render", "{case}", "--size", "10x10", "--out", "{tmp}/x.png"], "64..4096"),
        (["render", "{case}"], "--out"),
        (["render", "{tmp}/missing.json", "--out", "{tmp}/x.png"], "missing.json: cannot read"),
        (["export", "{case}", "--out", "{tmp}/e", "--frames", "5:2"], "--frames '5:2'"),
        (["export", "{case}", "--out", "{tmp}/e", "--frames", "x"], "START:STOP"),
        (["export", "{case}", "--out", "{tmp}/e", "--format", "kitti"], "argument --format"),
        (["bench", "--frames-per-case", "0"], "--frames-per-case"),
        (["bench", "--camera", "fisheye"], "argument --camera: invalid choice: 'fisheye'"),
        (["paint"], "invalid choice"),
        ([], "required"),
    ],
)
def test_user_errors_exit_2_with_one_line(case_file, tmp_path, capsys, argv, needle):
    argv = [arg.format(case=case_file, tmp=tmp_path) for arg in argv]
    assert cli.main(argv) == 2
    line = _error_line(capsys)
    assert line.startswith("lanevil: error: ") and needle in line


@pytest.mark.parametrize(("name", "image_format"), [("f.jpg", "JPEG"), ("f.JPEG", "JPEG"), ("f.png", "PNG")])
def test_render_writes_the_format_the_suffix_names(case_file, tmp_path, name, image_format):
    out = tmp_path / name
    assert cli.main(["render", str(case_file), "--out", str(out), "--size", "160x90"]) == 0
    with Image.open(out) as image:
        assert image.format == image_format and image.size == (160, 90)


@pytest.mark.parametrize(("argv", "needle"), [
    (["render", "{case}", "--out", "{tmp}/x.bmp"], "--out {tmp}/x.bmp: the suffix picks the format; use one of "
                                                   ".png, .jpg, .jpeg"),
    (["render", "{case}", "--out", "{tmp}/frame"], "--out {tmp}/frame: the suffix picks the format"),
    (["render", "{case}", "--out", "{tmp}"], "--out {tmp}: is a folder; give a file name, e.g. {tmp}/frame.png"),
    (["render", "{case}", "--out", "{tmp}/ok.png", "--labels", "{tmp}"], "--labels {tmp}: is a folder"),
    (["export", "{case}", "--out", "{case}"], "--out {case}: is a file; give a folder"),
])
def test_output_paths_are_checked_before_rendering(case_file, tmp_path, capsys, argv, needle):
    argv = [arg.format(case=case_file, tmp=tmp_path) for arg in argv]
    assert cli.main(argv) == 2
    line = _error_line(capsys)
    assert line.startswith(f"lanevil: error: {needle.format(case=case_file, tmp=tmp_path)}")
    assert ".tmp" not in line


def test_an_output_below_a_file_exits_2_naming_the_users_path(case_file, tmp_path, capsys):
    out = case_file / "frame.png"  # the case file is not a folder
    assert cli.main(["render", str(case_file), "--out", str(out), "--size", "64x64"]) == 2
    line = _error_line(capsys)
    assert line.startswith(f"lanevil: error: {out}: ") and ".tmp" not in line


def test_leftovers_of_a_killed_write_are_removed_at_start(case_file, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead_pid = int(dead.stdout)
    stale = out / f".frame.png.{dead_pid}.abcd1234.tmp"
    live = out / f".frame.png.{os.getpid()}.efgh5678.tmp"  # a write of a running process: kept
    other = out / ".notes.tmp"
    for path in (stale, live, other):
        path.write_bytes(b"partial")
    assert cli.main(["render", str(case_file), "--out", str(out / "frame.png"), "--size", "64x64"]) == 0
    assert sorted(path.name for path in out.iterdir()) == sorted(["frame.png", live.name, other.name])


def test_write_atomic_leaves_nothing_and_names_the_target(tmp_path):
    target = tmp_path / "a" / "b.bin"
    files.write_atomic(target, b"data")
    assert target.read_bytes() == b"data" and [path.name for path in target.parent.iterdir()] == ["b.bin"]
    with pytest.raises(IsADirectoryError) as error:
        files.write_atomic(tmp_path / "a", b"data")
    assert error.value.filename == str(tmp_path / "a")
    assert [path.name for path in target.parent.iterdir()] == ["b.bin"]


def test_stale_temps_are_found_below_a_folder_but_not_in_hidden_ones(tmp_path):
    nested, hidden = tmp_path / "x" / "y", tmp_path / ".git"
    nested.mkdir(parents=True)
    hidden.mkdir()
    names = [nested / ".f.png.999999999.abc.tmp", hidden / ".f.png.999999999.abc.tmp"]
    for path in names:
        path.write_bytes(b"")
    assert files.remove_stale_temps(tmp_path) == []  # not recursive by default
    assert files.remove_stale_temps(tmp_path, recursive=True) == [names[0]]
    assert names[1].exists()


def test_not_json_is_a_user_error(tmp_path, capsys):
    path = tmp_path / "broken.json"
    path.write_text("{road: ")
    assert cli.main(["export", str(path), "--out", str(tmp_path / "e")]) == 2
    assert "not valid JSON" in _error_line(capsys)


def test_export_frames_and_formats(case_file, tmp_path):
    out = tmp_path / "e"
    assert cli.main(["export", str(case_file), "--out", str(out), "--frames", "48:", "--format", "tusimple"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["000048.png", "000049.png", "case.json", "labels.json"]
    assert [json.loads(line)["frame"] for line in (out / "labels.json").read_text().splitlines()] == [48, 49]


def test_frame_range_parsing():
    assert cli_base.frame_range(":", 50) == range(50)
    assert cli_base.frame_range("10:", 50) == range(10, 50)
    assert cli_base.frame_range(":3", 50) == range(3)
    with pytest.raises(cli.UsageError):
        cli_base.frame_range("0:51", 50)


def test_preview_writes_image_and_overlay(case_file, tmp_path, capsys):
    out = tmp_path / "out"
    assert cli.main(["preview", str(case_file), "--out", str(out), "--size", "160x90"]) == 0
    plain, overlay = out / "case.png", out / "case.overlay.png"
    assert Image.open(plain).size == Image.open(overlay).size == (160, 90)
    assert plain.read_bytes() != overlay.read_bytes()
    assert str(plain) in capsys.readouterr().out


def test_preview_path_keeps_the_folder_below_scenes(tmp_path):
    root = tmp_path / "scenes"
    assert cli_core.preview_path(root / "01_shadow" / "a.json", Path("out"), root) == Path("out/01_shadow/a.png")
    assert cli_core.preview_path(tmp_path / "b.json", Path("out"), root) == Path("out/b.png")


def test_bench_json_is_one_object(monkeypatch, capsys, make_case):
    monkeypatch.setattr(bench, "run_benchmark", partial(bench.run_benchmark, sizes=((160, 90), (96, 64))))
    monkeypatch.setattr(bench, "bench_cases", lambda paths: [make_case()])
    assert cli.main(["bench", "--json", "--frames-per-case", "2"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert list(result) == ["160x90", "96x64"]
    for row in result.values():
        assert row["median_ms"] > 0 and {"raster", "shade"} <= set(row["stages"])
    table = bench.format_table(result)
    assert table.splitlines()[0].split()[:2] == ["size", "ms/frame"] and len(table.splitlines()) == 3


def test_bench_times_camera_presets_beside_the_case_camera(monkeypatch, capsys, make_case):
    monkeypatch.setattr(bench, "run_benchmark", partial(bench.run_benchmark, sizes=((160, 90),)))
    monkeypatch.setattr(bench, "bench_cases", lambda paths: [make_case()])
    assert cli.main(["bench", "--json", "--frames-per-case", "1", "--camera", "carla", "dashcam"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert list(result) == ["160x90 case", "160x90 carla", "160x90 dashcam"]
    case_ms = result["160x90 case"]["median_ms"]
    for name in ("carla", "dashcam"):
        row = result[f"160x90 {name}"]
        assert row["camera"] == name and row["ratio"] == round(row["median_ms"] / case_ms, 2)
        assert "lens" in row["stages"]  # the photographed path ran
    assert "ratio" not in result["160x90 case"] and "lens" not in result["160x90 case"]["stages"]
    assert bench.format_table(result).splitlines()[0].split()[-1] == "ratio"


def test_frames_to_time_spreads_over_the_drive(make_case):
    case = make_case()
    assert bench.frames_to_time(case, 3) == [0, 24, 49]
    assert bench.frames_to_time(case, 1) == [0]


def test_extension_modules_add_commands(monkeypatch):
    module = types.ModuleType("lanevil_core.cli.fake")
    module.COMMANDS = {"fake": cli.Command("a test command", lambda parser: parser.add_argument("--n", type=int),
                                           lambda args: args.n)}
    monkeypatch.setitem(sys.modules, "lanevil_core.cli.fake", module)
    real = cli.pkgutil.iter_modules
    fake = types.SimpleNamespace(name="fake", ispkg=False)
    monkeypatch.setattr(cli.pkgutil, "iter_modules", lambda path: [*real(path), fake])
    assert {"render", "export", "preview", "bench", "fake"} <= set(cli.all_commands())
    assert cli.main(["fake", "--n", "7"]) == 7


@pytest.mark.slow
def test_bench_on_the_stock_cases(capsys):
    assert cli.main(["bench", "--json", "--frames-per-case", "1"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert list(result) == ["1280x720", "640x360"]
    assert result["1280x720"]["median_ms"] > result["640x360"]["median_ms"] > 0


def test_bounded_argument_types_name_the_range():
    import argparse

    from lanevil_core.cli.base import bounded, count

    port = bounded(int, "a port number", 0, 65535)
    assert port("8080") == 8080 and count(1)("3") == 3
    for parse, text, message in ((port, "x", "'x' is not a port number"), (port, "70000", "choose 0..65535"),
                                 (count(1), "0", "must be at least 1")):
        with pytest.raises(argparse.ArgumentTypeError, match=message):
            parse(text)


def test_sheet_shows_progress_per_rendered_frame(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "sheet.png"
    assert cli.main(["sheet", "--out", str(out), "--size", "64x64", "--types", "fence_shadow"]) == 0
    captured = capsys.readouterr()
    assert out.read_bytes()[:4] == b"\x89PNG" and captured.out.strip() == str(out)
    assert "6/6" in captured.err and "frame" in captured.err  # one bar step per cell: the original and 5 levels
    assert cli.main(["sheet", "--out", str(out), "--size", "64x64", "--types", "fence_shadow", "--quiet"]) == 0
    assert capsys.readouterr().err == ""
