"""The one frame-range parser of the CLI and the API."""

from __future__ import annotations

import pytest

from lanevil_core.pipeline.frames import parse_frame_range


@pytest.mark.parametrize(("text", "expected"), [(":", range(50)), ("10:", range(10, 50)), (":3", range(3)),
                                                ("4:9", range(4, 9))])
def test_slices(text: str, expected: range) -> None:
    assert parse_frame_range(text, 50) == expected


def test_single_frame_only_where_allowed() -> None:
    assert parse_frame_range("7", 50, single=True) == range(7, 8)
    with pytest.raises(ValueError, match=r"is not START:STOP \("):
        parse_frame_range("7", 50)


@pytest.mark.parametrize("text", ["0:51", "5:5", "-1:3", "a:b", "1:2:3", "50"])
def test_bad_ranges_name_the_text(text: str) -> None:
    with pytest.raises(ValueError, match=repr(text).replace("[", r"\[")):
        parse_frame_range(text, 50, single=True)
