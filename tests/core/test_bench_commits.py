"""``bench/commits.py``: two revisions' ``lanevil bench`` side by side (the summary, the trees it extracts, and
its one-line errors). The benches themselves take minutes per revision, so they are not run here."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import pytest


@pytest.fixture(scope="module")
def commits(load_script: Callable[[str], ModuleType]) -> ModuleType:
    return load_script("bench/commits.py")


def _bench(case_ms: float, carla_ms: float | None = None) -> dict[str, dict[str, object]]:
    if carla_ms is None:
        return {"1280x720": {"median_ms": case_ms, "stages": {}}}
    return {"1280x720 case": {"median_ms": case_ms, "stages": {}},
            "1280x720 carla": {"median_ms": carla_ms, "stages": {}, "camera": "carla",
                               "ratio": round(carla_ms / case_ms, 2)}}


def test_rows_of_a_camera_bench_line_up_with_an_older_plain_bench(commits: ModuleType) -> None:
    rows = commits.row_medians(_bench(60.0, 96.0))
    assert rows == {"1280x720 case": 60.0, "1280x720 carla": 96.0, "1280x720": 60.0, "1280x720 carla / case": 1.6}
    assert commits.row_medians(_bench(65.0)) == {"1280x720": 65.0}


def test_summary_takes_medians_over_rounds_and_the_ratio_of_the_second_to_the_first(commits: ModuleType) -> None:
    runs = {"old": [commits.row_medians(_bench(v)) for v in (64.0, 70.0, 66.0)],
            "new": [commits.row_medians(_bench(c, k)) for c, k in ((60.0, 96.0), (63.0, 99.0), (61.0, 110.0))]}
    table = commits.summarise(runs, "old", "new")
    assert [row["row"] for row in table] == ["1280x720"]  # the rows both printed
    (row,) = table
    assert row["old median"] == 66.0 and row["new median"] == 61.0 and row["ratio"] == round(61.0 / 66.0, 3)
    assert "ratio 0.924" in commits.format_summary(table, "old", "new")
    same = commits.summarise({"a": runs["new"], "b": runs["new"]}, "a", "b")
    assert {row["row"] for row in same} == {"1280x720 case", "1280x720 carla", "1280x720 carla / case"}
    assert all(row["ratio"] == 1.0 for row in same)


def test_extract_writes_the_revision_s_renderer_and_refuses_an_unknown_one(commits: ModuleType,
                                                                          tmp_path: Path) -> None:
    tree = commits.extract("HEAD", tmp_path / "head")
    assert (tree / "lanevil_core" / "render" / "renderer.py").is_file()
    assert (tree / "app").is_dir() and (tree / "scenes").is_dir()
    with pytest.raises(commits.UsageError, match="revision"):
        commits.extract("no-such-revision-here", tmp_path / "nothing")


def test_bad_input_exits_2_with_one_line(commits: ModuleType, capsys: pytest.CaptureFixture[str]) -> None:
    assert commits.main(["HEAD", "HEAD"]) == 2
    assert commits.main(["HEAD", "--rounds", "0"]) == 2
    assert commits.main(["no-such-revision-here"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 3 and all(line.startswith("commits.py: ") for line in lines)
    assert "revision" in lines[2]


def test_camera_ratios_print_as_ratios(commits: ModuleType) -> None:
    runs = {"a": [commits.row_medians(_bench(62.0, 118.0))], "b": [commits.row_medians(_bench(64.0, 102.0))]}
    text = commits.format_summary(commits.summarise(runs, "a", "b"), "a", "b")
    line = next(line for line in text.splitlines() if "carla / case" in line)
    assert "1.900 | 1.590" in line
