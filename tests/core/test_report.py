"""Robustness report: hand-checked grouping on synthetic scores, and a small end-to-end run
(render -> detect -> eval -> report) on tiny frames of stock cases."""

from __future__ import annotations

import csv
import json
import re
import shutil
from pathlib import Path

import pytest

from lanevil_core.case import load_case
from lanevil_core.cli import main
from lanevil_core.illusions import REGISTRY
from lanevil_core.images import png_bytes
from lanevil_core.labels.lanes import tusimple_record
from lanevil_core.library.benchmark_layout import CATEGORY_FOLDERS, TYPE_FOLDERS, frame_file
from lanevil_core.metrics.evaluate import ScoredImage, score_tusimple_files
from lanevil_core.metrics.tusimple import ImageScore, f1_ganet
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render import render_frame
from lanevil_core.report.compare import line_style
from lanevil_core.report.robustness import ALL, build_report, gap_points, markdown, severity_csv

SCENES = Path(__file__).resolve().parents[2] / "scenes"
SIZE = (320, 180)


def scored(category: str, type_name: str, severity: int, accuracy: float, fp: float = 0.0, fn: float = 0.0):
    extra = {"category": category, "type": type_name, "severity": severity, "case": f"0{severity}"}
    return ScoredImage(f"{category}/{type_name}/{severity}.png", ImageScore(accuracy, fp, fn), extra)


def test_groups_original_perturbed_and_gap():
    images = [scored("Shadow", "Fence", 0, 1.0), scored("Shadow", "Fence", 1, 0.8, 0.2, 0.0),
              scored("Shadow", "Fence", 5, 0.4, 0.0, 0.5), scored("Shadow", "Wire", 0, 0.9),
              scored("Shadow", "Wire", 5, 0.9), scored("RoadDamage", "RoadCrack", 0, 0.5),
              scored("RoadDamage", "RoadCrack", 2, 0.7)]
    report = build_report(images + [ScoredImage("x.png", ImageScore(0.0, 0.0, 1.0), {})], "ganet")
    rows = {(row.category, row.type): row for row in report.rows}
    assert [key for key in rows][:3] == [("RoadDamage", "RoadCrack"), ("RoadDamage", ALL), ("Shadow", "Fence")]
    fence = rows[("Shadow", "Fence")]
    assert fence.original.accuracy == 1.0 and fence.perturbed.accuracy == pytest.approx(0.6)
    assert fence.gap("accuracy") == pytest.approx(-0.4)
    assert fence.gap("accuracy", 5) == pytest.approx(-0.6) and fence.levels[3] is None
    assert fence.perturbed.f1 == pytest.approx(f1_ganet(0.1, 0.25))
    shadow = rows[("Shadow", ALL)]
    assert shadow.original.accuracy == pytest.approx(0.95) and shadow.perturbed.images == 3
    assert rows[(ALL, ALL)].original.images == 3 and report.unlabelled == 1
    text = markdown(report)
    assert "| Shadow | Fence | 1/2 | 100.00 | 60.00 | -40.00 [-40.00, -40.00] |" in text  # one case: no spread
    assert "40.00 (-60.00 [-60.00, -60.00])" in text and "1 image(s) without category" in text
    levels = list(csv.DictReader(severity_csv(report).splitlines()))
    assert [r["severity"] for r in levels if r["type"] == "Fence"] == ["0", "1", "5"]


CASES = [("fence_shadow", "00_original", 0), ("fence_shadow", "05_level5", 5), ("road_crack", "00_original", 0),
         ("road_crack", "03_level3", 3)]


def _stock_path(illusion_type: str, name: str) -> Path:
    return min(SCENES.glob(f"*/{illusion_type}/*/{name}.json"))  # on the type's representative original


@pytest.fixture(scope="module")
def tiny_split(tmp_path_factory) -> Path:
    """A two-type test split (one frame per case at 320x180) in the benchmark layout."""
    split = tmp_path_factory.mktemp("dataset") / "test"
    lines = []
    for illusion_type, name, severity in CASES:
        category = CATEGORY_FOLDERS[REGISTRY[illusion_type].CATEGORY]
        type_folder = TYPE_FOLDERS[illusion_type]
        scene = compile_scene(load_case(_stock_path(illusion_type, name)))
        frame = render_frame(scene, 10, SIZE)
        raw_file = f"{category}/{type_folder}/{name}/{frame_file(0)}"
        (split / raw_file).parent.mkdir(parents=True, exist_ok=True)
        (split / raw_file).write_bytes(png_bytes(frame.rgb))
        record = tusimple_record(scene, 10, frame, raw_file)
        lines.append(json.dumps({**record, "category": category, "type": type_folder, "severity": severity,
                                 "case": name}))
    (split / "test_label.json").write_text("\n".join(lines) + "\n")
    return split


def test_end_to_end_detect_eval_report(tiny_split, tmp_path, capsys):
    preds = tmp_path / "birdseye.json"
    assert main(["detect", str(tiny_split), "--method", "birdseye", "--out", str(preds)]) == 0
    assert main(["eval", "--gt", str(tiny_split), "--pred", str(preds), "--json"]) == 0  # a split folder works
    lines = capsys.readouterr().out.strip().splitlines()
    overall = json.loads(lines[-1])
    out = tmp_path / "report"
    assert main(["report", "--gt", str(tiny_split), "--pred", str(preds), "--out", str(out)]) == 0
    for name in ("report.md", "report.csv", "report_severity.csv", "report.png"):
        assert (out / name).stat().st_size > 0
    assert (out / "report.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = {(r["category"], r["type"]): r for r in csv.DictReader((out / "report.csv").read_text().splitlines())}
    assert set(rows) == {("RoadDamage", "RoadCrack"), ("RoadDamage", ALL), ("Shadow", "Fence"), ("Shadow", ALL),
                         (ALL, ALL)}
    images = score_tusimple_files(tiny_split / "test_label.json", preds)
    everything = rows[(ALL, ALL)]
    # The table agrees with the per-image scores and with eval over the whole split.
    originals = [image.score.accuracy for image in images if image.extra["severity"] == 0]
    assert float(everything["accuracy_original"]) == pytest.approx(sum(originals) / 2, abs=1e-6)
    n_orig, n_pert = int(everything["images_original"]), int(everything["images_perturbed"])
    pooled = (float(everything["accuracy_original"]) * n_orig + float(everything["accuracy_perturbed"]) * n_pert)
    assert pooled / (n_orig + n_pert) == pytest.approx(overall["accuracy"], abs=1e-5)
    for row in rows.values():
        gap = float(row["accuracy_perturbed"]) - float(row["accuracy_original"])
        assert float(row["accuracy_gap"]) == pytest.approx(gap, abs=2e-6)
    text = (out / "report.md").read_text()
    assert "| Shadow | Fence | 1/1 |" in text and "F1 variant `ganet`" in text
    hough = tmp_path / "hough.json"
    assert main(["detect", str(tiny_split), "--method", "hough", "--out", str(hough)]) == 0
    both = tmp_path / "both"
    assert main(["report", "--gt", str(tiny_split), "--pred", str(preds), "--pred", str(hough), "--out", str(both),
                 "--baseline", "hough"]) == 0
    compare = (both / "compare.md").read_text()
    assert "| birdseye | P |" in compare and "| hough | P |" in compare and "gain over `hough`" in compare
    assert (both / "birdseye" / "report.md").is_file() and (both / "compare.png").is_file()
    assert main(["report", "--gt", str(tiny_split), "--pred", str(preds), "--pred", str(hough), "--out", str(both),
                 "--baseline", "nope"]) == 2
    assert main(["report", "--gt", str(tiny_split), "--pred", str(preds), "--pred", str(preds), "--out",
                 str(both)]) == 2  # two detectors of one name


def test_a_dataset_folder_stands_for_its_test_split(tiny_split, tmp_path, capsys):
    dataset = tiny_split.parent  # what `lanevil dataset --out` was given
    preds = tmp_path / "root.json"
    assert main(["detect", str(dataset), "--method", "birdseye", "--out", str(preds), "--fixed-run-time", "1"]) == 0
    split_preds = tmp_path / "split.json"
    assert main(["detect", str(tiny_split), "--method", "birdseye", "--out", str(split_preds),
                 "--fixed-run-time", "1"]) == 0
    assert preds.read_bytes() == split_preds.read_bytes()  # the test split's images, named as its labels name them
    capsys.readouterr()
    assert main(["eval", "--gt", str(dataset), "--pred", str(preds), "--json"]) == 0
    assert main(["eval", "--gt", str(tiny_split), "--pred", str(preds), "--json"]) == 0
    from_root, from_split = capsys.readouterr().out.strip().splitlines()[-2:]
    assert from_root == from_split
    assert main(["report", "--gt", str(dataset), "--pred", str(preds), "--out", str(tmp_path / "report")]) == 0
    assert (tmp_path / "report" / "report.md").is_file()
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["report", "--gt", str(empty), "--pred", str(preds), "--out", str(tmp_path / "r2")]) == 2
    err = capsys.readouterr().err
    assert "found 0" in err and "DATASET/test" in err


def test_a_dataset_folder_with_only_a_train_split_stands_for_it_and_says_so(tiny_split, tmp_path, capsys):
    dataset = tmp_path / "dataset"  # what `lanevil dataset --train-frames N` alone writes: a train split only
    shutil.copytree(tiny_split, dataset / "train")
    (dataset / "train" / "test_label.json").rename(dataset / "train" / "train_label.json")
    preds = tmp_path / "train.json"
    assert main(["detect", str(dataset), "--method", "birdseye", "--out", str(preds), "--fixed-run-time", "1"]) == 0
    assert "has no test/ split: using its train/ split" in capsys.readouterr().err
    raw_files = [json.loads(line)["raw_file"] for line in preds.read_text().splitlines()]
    assert raw_files and not any(name.startswith("train/") for name in raw_files)  # named as its labels name them
    for gt in (dataset, dataset / "train"):
        assert main(["eval", "--gt", str(gt), "--pred", str(preds), "--json"]) == 0
    scores = [json.loads(line) for line in capsys.readouterr().out.strip().splitlines()[-2:]]
    assert scores[0] == scores[1] and scores[0]["images"] == len(CASES)


def test_the_plot_shows_gaps_with_the_tables_sign():
    images = [scored("Shadow", "Fence", 0, 1.0), scored("Shadow", "Fence", 1, 0.8), scored("Shadow", "Fence", 5, 0.4)]
    row = next(row for row in build_report(images).rows if row.type == ALL and row.category == "Shadow")
    assert gap_points(row) == [(1, pytest.approx(-20.0)), (5, pytest.approx(-60.0))]
    assert f"{100 * row.gap('accuracy', 5):.2f}" in markdown(build_report(images))  # the table's -60.00


def test_paint_free_control_and_several_detectors(tmp_path):
    from lanevil_core.report.compare import Detector, write_comparison
    from lanevil_core.report.compare import markdown as compare_markdown

    def images(clean: float, perturbed: float, no_paint: float) -> list[ScoredImage]:
        control = scored("Shadow", "Fence", 0, no_paint)
        control = ScoredImage("nopaint.png", control.score, {**control.extra, "paint": False})
        return [scored("Shadow", "Fence", 0, clean), scored("Shadow", "Fence", 5, perturbed), control]

    vanilla = build_report(images(0.95, 0.70, 0.02), "ganet")
    total = vanilla.rows[-1]
    assert total.original.accuracy == 0.95 and total.original.images == 1  # the control is not an original
    assert total.no_paint.accuracy == 0.02
    assert "## Paint-free control" in markdown(vanilla) and "| 95.00 | 2.00 |" in markdown(vanilla)
    detectors = [Detector("vanilla", vanilla), Detector("aam", build_report(images(0.94, 0.80, 0.01), "ganet"))]
    assert "## Defences" not in compare_markdown(detectors, "ganet")
    text = compare_markdown(detectors, "ganet", baseline="vanilla")
    gain = "80.00 (+10.00 [+10.00, +10.00])"  # one case: the interval has no width
    assert f"| aam | {gain} | {gain} | 94.00 (-1.00) |" in text
    assert "| vanilla | 95.00 | 2.00 |" in text and "| aam | 94.00 | 1.00 |" in text
    paths = write_comparison(detectors, tmp_path, "ganet", "vanilla")
    assert (tmp_path / "compare.png").read_bytes()[:4] == b"\x89PNG" and (tmp_path / "aam" / "report.md").is_file()
    assert len(paths) == 4 + 2 * 4 and (tmp_path / "compare_breakdown.csv").is_file()


def test_defences_over_seeds_compare_each_run_with_its_own_seed_s_baseline():
    from lanevil_core.report.compare import Detector, defence_and_seed
    from lanevil_core.report.compare import markdown as compare_markdown

    def report(clean: float, perturbed: float):
        return build_report([scored("Shadow", "Fence", 0, clean), scored("Shadow", "Fence", 5, perturbed)], "ganet")

    runs = {"none@0": (0.90, 0.60), "aam@0": (0.90, 0.70), "cutout@0": (0.88, 0.75),
            "none@1": (0.90, 0.80), "aam@1": (0.89, 0.86), "cutout@1": (0.90, 0.79)}
    detectors = [Detector(name, report(*scores)) for name, scores in runs.items()]
    text = compare_markdown(detectors, "ganet", baseline="none")
    assert "## Defences, seed 0" in text and "## Defences, seed 1" in text
    gain = "86.00 (+6.00 [+6.00, +6.00])"
    assert f"| aam@1 | {gain} | {gain} | 89.00 (-1.00) |" in text  # against none@1, not none@0
    mean = text.split("## Defences, mean over seeds")[1]
    # aam: +10 and +6 -> +8; cutout: +15 and -1 -> +7; best first
    assert mean.index("| aam | +10.00 | +6.00 | **+8.00 [+8.00, +8.00]** | -0.50 | 2 |") < mean.index(
        "| cutout | +15.00 | -1.00 | **+7.00 [+7.00, +7.00]** | -1.00 | 2 |")
    assert defence_and_seed("aam@1") == ("aam", "1") and defence_and_seed("aam") == ("aam", None)
    assert defence_and_seed("@1") == ("@1", None)


def test_level5_drop_by_type_marks_drops_that_grow_with_the_level():
    from lanevil_core.report.compare import Detector, grows_with_level, type_table

    def ladder(type_name: str, accuracies: list[float]) -> list[ScoredImage]:
        return [scored("Shadow", type_name, level, acc) for level, acc in enumerate(accuracies)]

    report = build_report(ladder("Fence", [0.9, 0.9, 0.85, 0.85, 0.7, 0.5])
                          + ladder("Wire", [0.9, 0.8, 0.85, 0.8, 0.8, 0.8])
                          + ladder("Rail", [0.9, 0.85, 0.85, 0.85, 0.85, 0.85]), "ganet")
    rows = {row.type: row for row in report.rows}
    assert grows_with_level(rows["Fence"]) and not grows_with_level(rows["Wire"])
    assert not grows_with_level(rows["Rail"])  # the same drop at every level: flat, not growing
    lines = type_table([Detector("a", report)])
    assert "| Shadow | Fence | -40.00 [-40.00, -40.00] ↑ |" in lines
    assert "| Shadow | Wire | -10.00 [-10.00, -10.00] |" in lines
    assert "| **Mean over types** | | -18.33 (1/3 ↑) |" in lines


# ------------------------------------------------------------------------------------ intervals (bootstrap over cases)

def _cases(count: int, original: float, perturbed: float, spread: float, seed: int = 0,
           type_name: str = "Fence") -> list[ScoredImage]:
    """``count`` basic cases of three frames per level: accuracies around ``original`` / ``perturbed`` with a
    per-case offset of up to ``spread`` (frames of one case alike, as in a drive)."""
    import numpy as np

    rng = np.random.default_rng(seed)
    images = []
    for index in range(count):
        offset = float(rng.uniform(-spread, spread))
        for level in range(6):
            accuracy = min(max((original if level == 0 else perturbed) + offset, 0.0), 1.0)
            for frame in range(3):
                extra = {"category": "Shadow", "type": type_name, "severity": level,
                         "case": f"Shadow/{type_name}/{index:02d}_case/{level:02d}"}
                images.append(ScoredImage(f"{index}/{level}/{frame}.png", ImageScore(accuracy, 0.0, 0.0), extra))
    return images


def test_gap_interval_contains_the_gap_and_narrows_with_more_cases():
    widths = []
    for count in (8, 64):
        row = build_report(_cases(count, 0.9, 0.8, 0.15), "ganet").rows[0]
        for level in (None, 5):
            interval = row.gap_interval("accuracy", level)
            assert interval is not None and interval.contains(row.gap("accuracy", level))
            assert interval.excludes_zero  # a 10-point drop on every case
        f1 = row.gap_interval("f1")
        assert f1 is not None and f1.contains(row.gap("f1"))
        interval = row.gap_interval("accuracy")
        widths.append(interval.hi - interval.lo)
    assert widths[1] < 0.6 * widths[0]


def test_cases_not_frames_are_resampled():
    from lanevil_core.report.interval import CaseSums, case_unit

    images = _cases(4, 0.9, 0.8, 0.1)
    assert case_unit(images[0]) == "Shadow/Fence/00_case"
    sums = CaseSums.of(images)
    assert len(sums.keys) == 4 and sums.n.tolist() == [18.0] * 4


def test_report_prints_and_writes_intervals(tmp_path):
    from lanevil_core.report.robustness import report_csv, write_report

    report = build_report(_cases(12, 0.9, 0.8, 0.1), "ganet")
    assert re.search(r"\| Shadow \| Fence \| 36/180 \| [\d.]+ \| [\d.]+ \| -10\.00 \[-\d+\.\d\d, -\d+\.\d\d\] \|",
                     markdown(report))
    row = next(csv.DictReader(report_csv(report).splitlines()))
    assert float(row["accuracy_gap_lo"]) <= float(row["accuracy_gap"]) <= float(row["accuracy_gap_hi"])
    assert row["cases"] == "12" and "f1_gap_lo" in row and "f1_gap_hi" in row
    levels = [r for r in csv.DictReader(severity_csv(report).splitlines()) if r["type"] == "Fence"]
    assert [r["accuracy_gap_lo"] != "" for r in levels] == [False, True, True, True, True, True]
    write_report(report, tmp_path)


def test_compare_says_which_detectors_are_separable():
    from lanevil_core.report.compare import NOT_SEPARABLE, Detector, gap_difference
    from lanevil_core.report.compare import markdown as compare_markdown

    strong = build_report(_cases(30, 0.9, 0.88, 0.1, seed=1), "ganet")  # drops 2 points
    weak = build_report(_cases(30, 0.9, 0.70, 0.1, seed=1), "ganet")  # drops 20 points on the same cases
    twin = build_report(_cases(30, 0.9, 0.88, 0.1, seed=1)[:-1], "ganet")  # the strong one, one frame fewer
    value, interval = gap_difference(strong.rows[-1], weak.rows[-1], "accuracy", "ganet")
    assert value == pytest.approx(0.18) and interval.excludes_zero
    value, interval = gap_difference(strong.rows[-1], twin.rows[-1], "accuracy", "ganet")
    assert abs(value) < 0.01 and not interval.excludes_zero
    text = compare_markdown([Detector("strong", strong), Detector("weak", weak), Detector("twin", twin)], "ganet",
                            baseline="weak")
    separability = text.split("## Separability")[1].split("##")[0]
    assert "| strong - twin |" in separability and NOT_SEPARABLE in separability.split("| strong - twin |")[1]
    assert NOT_SEPARABLE not in separability.split("| strong - weak |")[1].split("\n")[0]
    assert "Not separable on average (accuracy gap): strong and twin." in separability
    defences = text.split("## Defences")[1].split("##")[0]
    assert re.search(r"\| strong \| [\d.]+ \(\+18\.00 \[\+\d", defences) and "## Accuracy by type and level" in text


def test_comparison_lines_stay_distinguishable() -> None:
    """A defence study compares 18+ runs: no two of the first 60 lines share colour, marker and dash."""
    styles = {tuple(sorted(line_style(index).items())) for index in range(60)}
    assert len(styles) == 60
