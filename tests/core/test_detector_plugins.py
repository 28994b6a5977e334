"""Plug-in detectors: HTTP servers, installed entry points, the registry and the entry points that use it."""

from __future__ import annotations

import json
import threading

import numpy as np
import pytest

from lanevil_core.cli import main
from lanevil_core.detect.catalog import available_detector, detector_info, detector_infos
from lanevil_core.detect.learned import BUNDLED_MODELS, LearnedDetector, shipped_model_dir
from lanevil_core.detect.model_spec import ModelSpec
from lanevil_core.detect.polylines import checked_polylines, polyline_lanes, scaled_polylines
from lanevil_core.detect.registry import (
    ENV_DETECTORS,
    ENV_DETECTORS_FILE,
    detector_for,
    detector_names,
    ready_detector,
)
from lanevil_core.detect.split import METHODS
from lanevil_core.drive.detectors import drive_detector_names
from lanevil_core.labels.lanes import h_samples_for
from lanevil_core.metrics.formats import LaneFileError

ROWS = h_samples_for(180)


@pytest.fixture(autouse=True)
def no_configured_detectors(monkeypatch) -> None:
    monkeypatch.delenv(ENV_DETECTORS, raising=False)
    monkeypatch.delenv(ENV_DETECTORS_FILE, raising=False)


def test_polylines_become_tusimple_lanes_between_their_ends() -> None:
    line = np.array([[100.0, 179.0], [50.0, 79.0]])  # bottom to top, any order
    assert polyline_lanes([line], [70, 79, 129, 179], 320) == [[-2, 50, 75, 100]]
    assert polyline_lanes([line - [60, 0]], [70, 79, 129, 179], 320) == [[-2, -2, 15, 40]]  # partly left of it
    assert polyline_lanes([line - [90, 0]], [70, 79, 129, 179], 320) == []  # one point inside is no lane
    assert polyline_lanes([np.array([[10.0, 100.0]])], ROWS, 320) == []  # one point is no lane
    moved = scaled_polylines([np.array([[40.0, 0.0]])], (160, 90), (320, 180))[0]
    assert moved.tolist() == [[80.5, 0.5]]  # pixel centres scale about the image corner


@pytest.mark.parametrize(("answer", "message"), [
    ([], "not an object"), ({"lanes": 3}, "\"lanes\" is not a list"),
    ({"lanes": [[[1, 2], [3]]]}, r"lanes\[0\]\[1\] is not a point"),
    ({"lanes": [[[1, float("nan")]]]}, "finite"), ({"lanes": [[[1, 2]]], "scores": [1, 2]}, "scores"),
])
def test_answers_that_are_not_lanes_are_named(answer, message) -> None:
    with pytest.raises(LaneFileError, match=message):
        checked_polylines(answer, "detector: x")


def test_an_http_detector_reads_the_posted_png_and_answers_lanes(lane_server, stripes) -> None:
    detector = detector_for(lane_server.url())
    lanes = detector(stripes([60, 200]), ROWS)
    assert lane_server.content_types == ["image/png"] and lane_server.sizes == [(320, 180)]
    # stripe columns 60..63: centre 61.5 in pixel indices, u_image 62.0, written as floor(u_image)
    assert [set(lane) for lane in lanes] == [{62}, {202}]


def test_an_http_detector_resized_to_its_input_size(monkeypatch, tmp_path, lane_server, stripes) -> None:
    config = tmp_path / "detectors.json"
    config.write_text(json.dumps({"detectors": {"half": {"source": lane_server.url(), "input_size": [160, 90],
                                                         "real_trained": True}}}))
    monkeypatch.setenv(ENV_DETECTORS_FILE, str(config))
    lanes = detector_for("half")(stripes([60, 200]), ROWS)
    assert lane_server.sizes == [(160, 90)]
    # the server sees the stripes at 30..31 and 100..101 (u_image 31, 101) -> frame u_image 62, 202
    assert [set(lane) for lane in lanes] == [{62}, {202}]
    info = detector_info("half")
    assert (info.kind, info.available, info.real_trained, info.source) == ("http", True, True, lane_server.url())
    assert info.version == f"half@{lane_server.url()}"


def test_named_detectors_from_the_environment_join_every_list(monkeypatch, lane_server) -> None:
    monkeypatch.setenv(ENV_DETECTORS, f" mine={lane_server.url()} ; other=onnx:missing.onnx;")
    assert detector_names() == (*METHODS, "mine", "other", *BUNDLED_MODELS)
    assert drive_detector_names() == ("gt", *METHODS, "mine", "other", *BUNDLED_MODELS)
    infos = {info.name: info for info in detector_infos()}
    assert infos["mine"].kind == "http" and infos["mine"].available
    assert infos["other"].kind == "onnx" and not infos["other"].available
    assert "no ONNX model" in (infos["other"].reason or "")
    with pytest.raises(LaneFileError, match="not available"):
        available_detector("other")
    # the web app takes names only: a source is not a name there
    with pytest.raises(LaneFileError, match="unknown detector"):
        available_detector(lane_server.url())


@pytest.mark.parametrize(("value", "message"), [
    ("mine", "is not NAME=SOURCE"), ("mine=ftp://x", "is not http"), ("ufld=http://x:1/d", "is taken"),
    ("a b=http://x:1/d", "must be 1-40"), ("a=http://x:1/d;a=http://y:1/d", "configured twice"),
])
def test_a_malformed_environment_is_one_clear_error(monkeypatch, value, message) -> None:
    monkeypatch.setenv(ENV_DETECTORS, value)
    with pytest.raises(LaneFileError, match=message):
        detector_names()


def test_the_bundled_models_are_listed_after_the_methods() -> None:
    assert detector_names() == (*METHODS, *BUNDLED_MODELS)
    assert {"seg-transfer", "scnn-transfer", "laneatt-transfer"} <= set(BUNDLED_MODELS)


@pytest.mark.parametrize("name", BUNDLED_MODELS)
def test_a_bundled_model_is_a_named_detector_a_configured_one_may_take_over(monkeypatch, stripes, name) -> None:
    info = detector_info(name)
    assert info.available and info.kind == "onnx" and not info.real_trained
    assert info.source == f"onnx:detect/models/{name}"  # not the path of the installation's disk
    assert info.model is not None and info.model["input_size"] == [320, 180]
    folder = shipped_model_dir(name)
    family = ModelSpec.load(folder).family
    assert name == f"{family}-transfer"  # named after the family it runs as
    detector = detector_for(name)
    assert isinstance(detector, LearnedDetector) and detector.spec.family == family
    rgb = stripes([60, 100])
    assert detector(rgb, ROWS) == detector_for(family, folder)(rgb, ROWS)  # as `--method FAMILY --weights FOLDER`
    monkeypatch.setenv(ENV_DETECTORS, f"{name}=onnx:missing.onnx")
    assert detector_names().count(name) == 1 and not detector_info(name).available


def test_a_malformed_config_file_names_the_field(monkeypatch, tmp_path) -> None:
    config = tmp_path / "detectors.json"
    monkeypatch.setenv(ENV_DETECTORS_FILE, str(config))
    for data, message in (({"detectors": {"a": {"source": "http://x:1/d", "retries": -1}}}, "retries must be"),
                          ({"detectors": {"a": {"source": "http://x:1/d", "colour": 1}}}, "unknown option 'colour'"),
                          ({"a": 1}, "expected"), ({"detectors": {"a": {"src": "x"}}}, "\"source\" string")):
        config.write_text(json.dumps(data))
        with pytest.raises(LaneFileError, match=message):
            detector_names()


def test_failures_are_one_line_naming_the_detector(lane_server, stripes, down_url) -> None:
    rgb = stripes([60])
    for path, message in (("/nonsense", "not JSON"), ("/bad", r"lanes\[0\] is not a list|lanes\[0\]\[0\]"),
                          ("/reject", "answered HTTP 400: .*image too small")):
        with pytest.raises(LaneFileError, match=message) as caught:
            detector_for(lane_server.url(path))(rgb, ROWS)
        assert str(caught.value).startswith(f"detector: {lane_server.url(path)}") and "\n" not in str(caught.value)
        assert lane_server.calls[path] == 1  # no retry of an answer that is wrong
    with pytest.raises(LaneFileError, match=r"answered HTTP 500.*\(after 2 tries\)"):
        detector_for(lane_server.url("/fail"))(rgb, ROWS)
    assert lane_server.calls["/fail"] == 2  # retried once (the default)
    with pytest.raises(LaneFileError, match=r"cannot connect .*\(after 2 tries\)"):
        detector_for(down_url)(rgb, ROWS)


def test_a_slow_server_times_out(monkeypatch, tmp_path, lane_server, stripes) -> None:
    config = tmp_path / "detectors.json"
    config.write_text(json.dumps({"detectors": {"slow": {"source": lane_server.url("/slow"), "timeout_s": 0.2,
                                                         "retries": 0}}}))
    monkeypatch.setenv(ENV_DETECTORS_FILE, str(config))
    lane_server.slow_s = 1.0
    with pytest.raises(LaneFileError, match=r"no answer within 0.2 s \(after 1 try\)"):
        detector_for("slow")(stripes([60]), ROWS)


@pytest.mark.parametrize("concurrency", [1, 2])
def test_requests_in_flight_stay_within_the_concurrency_limit(monkeypatch, tmp_path, lane_server, stripes,
                                                              concurrency) -> None:
    config = tmp_path / "detectors.json"
    config.write_text(json.dumps({"detectors": {"lim": {"source": lane_server.url(), "concurrency": concurrency}}}))
    monkeypatch.setenv(ENV_DETECTORS_FILE, str(config))
    lane_server.hold_s = 0.15
    detector = detector_for("lim")
    threads = [threading.Thread(target=detector, args=(stripes([60]), ROWS)) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert lane_server.calls["/detect"] == 4 and lane_server.peak == concurrency


def test_ready_detector_asks_an_http_detector_once(lane_server, down_url) -> None:
    ready_detector(lane_server.url())
    assert lane_server.calls == {"/detect": 1}
    with pytest.raises(LaneFileError, match="cannot connect"):
        ready_detector(down_url)


def _write_split(split, frames) -> None:
    import cv2

    lines = []
    for index, rgb in enumerate(frames):
        name = f"{index:06d}.png"
        cv2.imwrite(str(split / name), rgb[..., ::-1])
        lines.append(json.dumps({"raw_file": name, "lanes": [], "h_samples": ROWS}))
    (split / "test_label.json").write_text("\n".join(lines) + "\n")


def test_lanevil_detect_with_an_http_method_and_with_the_server_down(tmp_path, lane_server, stripes, capsys,
                                                                  down_url) -> None:
    split = tmp_path / "test"
    split.mkdir()
    _write_split(split, [stripes([60, 200]), stripes([100])])
    out = tmp_path / "pred.json"
    assert main(["detect", str(split), "--method", lane_server.url(), "--out", str(out)]) == 0
    records = [json.loads(line) for line in out.read_text().splitlines()]
    assert [[set(lane) for lane in record["lanes"]] for record in records] == [[{62}, {202}], [{102}]]
    both = tmp_path / "both"
    assert main(["detect", str(split), "--method", lane_server.url(), "--method", "hough", "--out", str(both)]) == 0
    assert sorted(path.name for path in both.iterdir()) == ["hough.json", "http_127.0.0.1_"
                                                            f"{lane_server.httpd.server_address[1]}_detect.json"]
    capsys.readouterr()
    assert main(["detect", str(split), "--method", lane_server.url(), "--method", lane_server.url() + "?",
                 "--out", str(both)]) == 2
    assert "would write the same file" in capsys.readouterr().err
    assert main(["detect", str(split), "--method", down_url, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("lanevil: error: detector: http://127.0.0.1:") and "cannot connect" in err
    assert len(err.splitlines()) == 1
    assert main(["detect", str(split), "--method", "yolo", "--out", str(out)]) == 2
    assert "unknown detector 'yolo'" in capsys.readouterr().err


def test_lanevil_drive_refuses_a_server_that_is_down(tmp_path, capsys, down_url) -> None:
    case = tmp_path / "case.json"
    case.write_text("{}")
    assert main(["drive", str(case), "--detector", down_url, "--out", str(tmp_path / "out")]) == 2
    assert "cannot connect" in capsys.readouterr().err


def test_an_installed_entry_point_is_a_detector(installed_plugin, stripes) -> None:
    names = detector_names()
    assert names[: len(METHODS)] == METHODS and {"bright", "broken"} <= set(names)
    assert names.count("ufld") == 1  # a plug-in cannot take a built-in's name
    lanes = detector_for("bright")(stripes([200]), ROWS)
    assert [set(lane) for lane in lanes] == [{201}]  # the brightest column 100 of 160: u_image 100.5, 201 of 320
    info = detector_info("bright")
    assert (info.kind, info.available, info.real_trained) == ("plugin", True, True)
    assert info.version == "bright@1.2.0" and info.source == "bright_lanes:BrightColumn"
    broken = detector_info("broken")
    assert not broken.available and "RuntimeError: no weights file" in (broken.reason or "")


def test_lanevil_drive_with_an_http_detector_in_the_loop(tmp_path, make_case, lane_server) -> None:
    case = tmp_path / "case.json"
    case.write_text(make_case().model_dump_json())
    out = tmp_path / "drive"
    assert main(["drive", str(case), "--detector", lane_server.url(), "--seconds", "0.3", "--size", "160x90",
                 "--out", str(out), "--no-video", "--json"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    # one black probe frame before the drive, then every step's frame
    assert summary["steps"] >= 3 and lane_server.sizes == [(640, 360)] + [(160, 90)] * summary["steps"]


def test_lanevil_detectors_lists_built_ins_and_plugins(monkeypatch, lane_server, capsys) -> None:
    monkeypatch.setenv(ENV_DETECTORS, f"mine={lane_server.url()};gone=onnx:missing.onnx")
    assert main(["detectors"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == [*METHODS, "mine", "gone", *BUNDLED_MODELS]
    mine, gone = len(METHODS), len(METHODS) + 1
    assert lines[mine].split()[1:3] == ["http", "available"] and lane_server.url() in lines[mine]
    assert "not available: gone: no ONNX model at missing.onnx" in lines[gone]
    assert main(["detectors", "--json"]) == 0
    entries = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert entries[mine] == {"name": "mine", "kind": "http", "available": True, "reason": None, "model": None,
                           "source": lane_server.url(), "real_trained": False}
    monkeypatch.setenv(ENV_DETECTORS, "mine")
    assert main(["detectors"]) == 2
    assert "is not NAME=SOURCE" in capsys.readouterr().err
