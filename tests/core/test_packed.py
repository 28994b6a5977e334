"""The packed scene of an edited case (its roadside packed once per road and reused) equals packing it afresh."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from lanevil_core.case import load_case
from lanevil_core.pipeline.compile import compile_scene
from lanevil_core.render.packed import PackedScene, pack_scene

SCENES = Path(__file__).resolve().parents[2] / "scenes"
CASE = SCENES / "20_traffic/vehicle/00_straight_highway_noon/03_level3.json"


def assert_same(a: PackedScene, b: PackedScene) -> None:
    for field in dataclasses.fields(a):
        x, y = getattr(a, field.name), getattr(b, field.name)
        pairs = ([(getattr(x, g.name), getattr(y, g.name)) for g in dataclasses.fields(x)]
                 if dataclasses.is_dataclass(x) else [(x, y)])
        for left, right in pairs:
            assert left.dtype == right.dtype and left.shape == right.shape, field.name
            assert np.array_equal(left, right, equal_nan=True), field.name


def test_an_edit_packs_as_a_fresh_compile_does() -> None:
    case = load_case(CASE)
    first = compile_scene(case)
    pack_scene(first)
    edits = [case.model_copy(update={"sun": case.sun.model_copy(update={"altitude": 20.0})}),
             case.model_copy(update={"illusions": [case.illusions[0].model_copy(update={"severity": 5})]}),
             case.model_copy(update={"illusions": []})]
    for edited in edits:
        reused = compile_scene(edited, reuse=first)
        assert reused.network is first.network  # the roadside is reused, so its packing is too
        assert_same(pack_scene(reused), pack_scene(compile_scene(edited)))


def test_scenes_share_no_packed_array() -> None:
    """A render may write into a scene's packed arrays; an edited scene's never alias the first's."""
    case = load_case(CASE)
    first = compile_scene(case)
    again = compile_scene(case.model_copy(update={"title": "edited"}), reuse=first)
    a, b = pack_scene(first), pack_scene(again)
    for field in ("vertices", "faces", "face_color", "face_normal", "face_grad_st", "face_object"):
        assert not np.shares_memory(getattr(a, field), getattr(b, field)), field
