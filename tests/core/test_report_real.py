"""The Real -> LanEvil table of ``lanevil report``: real-trained detectors reported apart."""

from __future__ import annotations

import csv
import json

import pytest

from lanevil_core.cli import main
from lanevil_core.detect.registry import ENV_DETECTORS, ENV_DETECTORS_FILE

ROWS = list(range(160, 720, 10))
LANES = [[300] * len(ROWS), [900] * len(ROWS)]
# (type, case, severity): two types of Shadow, one of RoadDamage
IMAGES = [("FenceShadow", "00_original", 0), ("FenceShadow", "05_level5", 5), ("FenceShadow", "02_level2", 2),
          ("RoadCrack", "00_original", 0), ("RoadCrack", "05_level5", 5)]
CATEGORY = {"FenceShadow": "Shadow", "RoadCrack": "RoadDamage"}


def write_files(tmp_path, found_at_level: dict[int, int], pred_name: str = "pred.json"):
    """A split folder whose GT has two lanes per image; a prediction that finds ``found_at_level[severity]`` of
    them. Returns the split folder and the prediction file."""
    split = tmp_path / "test"
    split.mkdir(exist_ok=True)
    gt, pred = split / "test_label.json", tmp_path / pred_name
    gt_lines, pred_lines = [], []
    for type_name, case, severity in IMAGES:
        raw = f"{type_name}/{case}/0.png"
        gt_lines.append(json.dumps({"raw_file": raw, "lanes": LANES, "h_samples": ROWS, "category": CATEGORY[type_name],
                                    "type": type_name, "severity": severity, "case": f"{type_name}/{case}"}))
        pred_lines.append(json.dumps({"raw_file": raw, "lanes": LANES[: found_at_level[severity]], "h_samples": ROWS,
                                      "run_time": 1.0}))
    gt.write_text("\n".join(gt_lines) + "\n")
    pred.write_text("\n".join(pred_lines) + "\n")
    return split, pred


@pytest.fixture(autouse=True)
def no_configured_detectors(monkeypatch) -> None:
    monkeypatch.delenv(ENV_DETECTORS, raising=False)
    monkeypatch.delenv(ENV_DETECTORS_FILE, raising=False)


def test_a_detector_marked_real_trained_gets_the_real_to_lanevil_table(tmp_path, capsys) -> None:
    gt, real = write_files(tmp_path, {0: 2, 2: 2, 5: 1})
    _, synthetic = write_files(tmp_path, {0: 2, 2: 2, 5: 2}, "synthetic.json")
    out = tmp_path / "report"
    assert main(["report", "--gt", str(gt), "--pred", str(real), "--pred", str(synthetic), "--name", "tusimple-model",
                 "--name", "ours", "--real-trained", "tusimple-model", "--out", str(out)]) == 0
    text = (out / "real_to_lanevil.md").read_text()
    assert "## tusimple-model" in text and "## ours" not in text
    # Shadow: originals 100 %; perturbed: level 2 found both lanes (100 %), level 5 one of two (50 %) -> 75 %
    assert "| Shadow | 1/2 | 100.00 | 75.00 | -25.00 [-25.00, -25.00] |" in text
    assert "| RoadDamage | 1/1 | 100.00 | 50.00 | -50.00 [-50.00, -50.00] |" in text
    assert "| **Average** | 2/3 | 100.00 | 66.67 |" in text
    assert "| Shadow | 100.00 | - | 100.00 (+0.00 [+0.00, +0.00]) | - | - | 50.00 (-50.00 [-50.00, -50.00]) |" in text
    rows = list(csv.DictReader((out / "real_to_lanevil.csv").open()))
    level5 = next(r for r in rows if r["category"] == "All" and r["level"] == "5")
    assert level5["detector"] == "tusimple-model" and float(level5["accuracy_gap"]) == pytest.approx(-0.5)
    assert {r["detector"] for r in rows} == {"tusimple-model"}
    assert (out / "compare.md").is_file() and str(out / "real_to_lanevil.md") in capsys.readouterr().out
    assert main(["report", "--gt", str(gt), "--pred", str(real), "--real-trained", "nobody", "--out", str(out)]) == 2
    assert "--real-trained 'nobody': not one of the detector names pred" in capsys.readouterr().err


def test_a_plugin_configured_real_trained_is_marked_without_the_flag(tmp_path, monkeypatch) -> None:
    gt, real = write_files(tmp_path, {0: 2, 2: 1, 5: 0})
    config = tmp_path / "detectors.json"
    config.write_text(json.dumps({"detectors": {"laneatt-tusimple": {"source": "http://127.0.0.1:9/detect",
                                                                     "real_trained": True}}}))
    monkeypatch.setenv(ENV_DETECTORS_FILE, str(config))
    out = tmp_path / "one"
    assert main(["report", "--gt", str(gt), "--pred", str(real), "--name", "laneatt-tusimple", "--out", str(out)]) == 0
    assert (out / "report.md").is_file() and "## laneatt-tusimple" in (out / "real_to_lanevil.md").read_text()
    plain = tmp_path / "plain"
    assert main(["report", "--gt", str(gt), "--pred", str(real), "--name", "other", "--out", str(plain)]) == 0
    assert not (plain / "real_to_lanevil.md").exists()
