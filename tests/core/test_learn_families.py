"""The laneatt, bezier, ganet and scnn families: a known lane set encoded to each family's targets decodes back to
the same TuSimple points, a few training iterations on tiny data write a model folder whose ONNX export matches
torch, and every family is a method of `lanevil detect`, the drive loop and the detector catalog."""

from __future__ import annotations

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from test_learn import TINY_SPEC, _train, tiny_dataset  # noqa: E402, F401 (the fixture is used by name)

from lanevil_core.cli import main  # noqa: E402
from lanevil_core.detect.bezier_curves import encode_curves  # noqa: E402
from lanevil_core.detect.lane_keypoints import decode_keypoints, encode_keypoints, keypoint_map_size  # noqa: E402
from lanevil_core.detect.lane_slots import assign_slots, encode_lane_mask, lane_lines  # noqa: E402
from lanevil_core.detect.learned import LearnedDetector, decode_outputs, lanes_of  # noqa: E402
from lanevil_core.detect.line_anchors import encode_anchors, line_anchors  # noqa: E402
from lanevil_core.detect.model_spec import FAMILIES, ModelSpec  # noqa: E402
from lanevil_core.drive.detectors import drive_detector  # noqa: E402
from lanevil_core.labels.lanes import TUSIMPLE_H_SAMPLES  # noqa: E402

NEW_FAMILIES = ["laneatt", "bezier", "ganet", "scnn"]


def lane_set() -> dict:
    """Four lanes on the 1280x720 grid from row 260 down: straight ones converging to a vanishing point above the
    image's top rows, and one gently curved, plus one leaving through the left border."""
    rows = list(TUSIMPLE_H_SAMPLES)
    lanes = []
    for bottom_x, bend in ((-200, 0.0), (380, 0.0), (900, 60.0), (1500, 0.0)):
        xs = []
        for h in rows:
            s = (h - 200) / (710 - 200)
            x = 640 + (bottom_x - 640) * s + bend * (1 - s) * s * 4
            xs.append(int(x) if h >= 260 and 0 <= x < 1280 else -2)
        lanes.append(xs)
    return {"lanes": lanes, "h_samples": rows}


def encoded_outputs(family: str, spec: ModelSpec, record: dict) -> dict[str, np.ndarray]:
    """The network outputs (batch of one) that say exactly the family's targets for ``record``."""
    placed = assign_slots(lane_lines(record["lanes"], record["h_samples"], (1280, 720)), spec.slots)
    width, height = spec.input_size
    if family == "laneatt":
        targets = encode_anchors(placed, line_anchors(), spec.anchor_rows, width / height)
        return {"anchor_scores": (targets.labels == 1).astype(np.float32)[None],
                "anchor_regs": targets.regression[None]}
    if family == "bezier":
        control, valid = encode_curves(placed)
        return {"curve_exist": valid[None], "curve_points": control[None]}
    if family == "ganet":
        heat, offsets = encode_keypoints(placed, keypoint_map_size(spec.input_size))
        return {"heat_probs": heat[None, None], "keypoint_offsets": offsets[None]}
    mask = encode_lane_mask(placed, spec.mask_size)
    return {"mask_probs": np.eye(spec.slots + 1, dtype=np.float32)[mask].transpose(2, 0, 1)[None],
            "exist_probs": np.array([line is not None for line in placed], np.float32)[None]}


@pytest.mark.parametrize("family", NEW_FAMILIES)
def test_known_targets_decode_to_the_same_tusimple_points(family):
    record = lane_set()
    spec = ModelSpec(family=family)
    decoded = lanes_of(spec, decode_outputs(spec, encoded_outputs(family, spec, record)), record["h_samples"],
                       (1280, 720))
    assert len(decoded) == len(record["lanes"])
    truth = sorted(record["lanes"], key=lambda lane: next(x for x in lane[::-1] if x >= 0))
    found = sorted(decoded, key=lambda lane: next(x for x in lane[::-1] if x >= 0))
    both = [(t, f) for want, got in zip(truth, found, strict=True) for t, f in zip(want, got, strict=True)
            if t >= 0 and f >= 0]
    labelled = sum(x >= 0 for lane in truth for x in lane)
    errors = np.abs(np.array(both, float)[:, 0] - np.array(both, float)[:, 1])
    # laneatt's offsets live on 28 row anchors, so a lane ending between two of them loses the TuSimple rows past
    # 0.6 anchor spacings (as ufld). scnn's masks (as seg's) hold one class per map pixel (8 px of the 1280 grid)
    # and lose a few rows where lanes come close near the top: its ceiling is one map pixel, not 1 px.
    coverage = {"scnn": 0.9, "laneatt": 0.98}.get(family, 1.0)
    assert len(both) >= coverage * labelled
    assert np.all(errors <= (8.0 if family == "scnn" else 1.0))


def test_keypoints_group_by_start_point_not_by_order():
    spec = ModelSpec(family="ganet")
    record = lane_set()
    placed = assign_slots(lane_lines(record["lanes"], record["h_samples"], (1280, 720)), spec.slots)
    heat, offsets = encode_keypoints(placed, keypoint_map_size(spec.input_size))
    lines = decode_keypoints(heat, offsets, spec.slots)
    starts = sorted(round(float(line.points[-1, 1]), 2) for line in lines)
    assert len(lines) == 4 and starts[0] < 0.9  # the lane leaving through the left border starts higher up


def test_laneatt_anchors_leave_every_border():
    anchors = line_anchors()
    assert {0.0, 1.0} <= set(anchors[:, 0]) and np.any(anchors[:, 1] == 1.0)
    assert len(anchors) == 420


def test_every_family_is_a_detect_drive_and_catalog_method():
    from lanevil_core.detect.catalog import detector_infos
    from lanevil_core.detect.split import METHODS
    from lanevil_core.drive.detectors import DRIVE_DETECTORS

    assert set(FAMILIES) <= set(METHODS) and set(FAMILIES) <= set(DRIVE_DETECTORS)
    assert {info.name for info in detector_infos() if info.kind == "learned"} == set(FAMILIES)


@pytest.mark.parametrize("family", NEW_FAMILIES)
def test_training_writes_a_model_whose_onnx_matches_torch(tiny_dataset, tmp_path, family):  # noqa: F811
    from lanevil_core.learn.models import Deployed, build_model

    assert _train(tiny_dataset, tmp_path, family) == 0
    spec = ModelSpec.load(tmp_path)
    assert spec.family == family and spec.width == TINY_SPEC["width"]
    model = build_model(spec)
    model.load_state_dict(torch.load(tmp_path / "checkpoint.pt", weights_only=False)["model"])
    image = np.random.default_rng(1).random((2, 3, spec.input_size[1], spec.input_size[0]), dtype=np.float32)
    with torch.no_grad():
        expected = [t.numpy() for t in Deployed(model)(torch.from_numpy(image))]
    detector = LearnedDetector(tmp_path)
    got = detector._session.run(None, {"image": image})
    assert [o.name for o in detector._session.get_outputs()] == list(model.OUTPUTS)
    for want, have in zip(expected, got, strict=True):
        assert want.shape == have.shape and np.max(np.abs(want - have)) < 1e-4
    lanes = detector((image[0].transpose(1, 2, 0) * 255).astype(np.uint8), list(range(20, 72, 4)))
    assert all(len(lane) == 13 for lane in lanes)

    pred = tmp_path / "pred.json"
    assert main(["detect", str(tiny_dataset / "train"), "--method", family, "--weights", str(tmp_path),
                 "--out", str(pred)]) == 0
    assert len(pred.read_text().splitlines()) == 10
    drive = drive_detector(family, tmp_path)
    assert isinstance(drive(np.zeros((72, 128, 3), np.uint8), list(range(20, 72, 4)), []), list)
