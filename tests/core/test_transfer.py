"""Training that transfers: the domain randomiser is deterministic per seed and keeps the paint, ImageNet
checkpoints in torchvision's layout load into the backbone (and wrong ones are refused in one line), and
``lanevil adapt`` writes a usable model from unlabelled frames (with ``--method dann``, from labelled renders too)."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

torch = pytest.importorskip("torch")

from test_learn import TINY_SPEC, _train, straight_record, tiny_dataset  # noqa: E402, F401 (the fixture by name)

from lanevil_core.cli import main  # noqa: E402
from lanevil_core.detect.lane_slots import LaneLine, lane_lines  # noqa: E402
from lanevil_core.detect.learned import BUNDLED_MODELS, LearnedDetector, shipped_model_dir  # noqa: E402
from lanevil_core.detect.model_spec import FAMILIES, ModelSpec  # noqa: E402
from lanevil_core.images import frame_files  # noqa: E402
from lanevil_core.learn.adapt import adapt_batch_norm, agreeing_lanes  # noqa: E402
from lanevil_core.learn.backbone import BackboneWeightsError, ResNet, load_backbone_weights  # noqa: E402
from lanevil_core.learn.dann import reversal_weight, reverse_gradient, target_batches  # noqa: E402
from lanevil_core.learn.data import LabelledFrames, read_splits  # noqa: E402
from lanevil_core.learn.models import build_model, pooled_features  # noqa: E402
from lanevil_core.learn.randomise import paint_mask, photometric, randomise, recolour  # noqa: E402

SIZE = (320, 180)


def _scene() -> tuple[np.ndarray, np.ndarray, list[LaneLine]]:
    """A grey road with white lines where ``straight_record`` puts them, and the lines."""
    record = straight_record()
    lines = lane_lines(record["lanes"], record["h_samples"], (1280, 720))
    image = np.full((SIZE[1], SIZE[0], 3), 90, np.uint8)
    for line in lines:
        points = np.round(line.points * SIZE).astype(np.int32)
        cv2.polylines(image, [points], False, (235, 235, 235), 2)
    return image, paint_mask(lines, SIZE), lines


def test_randomiser_is_deterministic_per_seed_and_differs_between_seeds():
    image, keep, _ = _scene()
    a = randomise(image, keep, np.random.default_rng(5))
    b = randomise(image, keep, np.random.default_rng(5))
    c = randomise(image, keep, np.random.default_rng(6))
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    p = photometric(image, np.random.default_rng(5))
    assert np.array_equal(p, photometric(image, np.random.default_rng(5)))
    assert p.shape == image.shape and p.dtype == np.uint8


def test_paint_mask_covers_the_painted_lines_and_little_else():
    image, keep, lines = _scene()
    painted = image[..., 0] > 200
    painted[: int(SIZE[1] * 0.6)] = False  # near the vanishing point a 2-pixel stroke is wider than paint would be
    assert keep[painted].mean() > 0.95  # the lines' pixels are kept
    assert keep.mean() < 0.15  # the rest of the road is free to change
    assert not paint_mask([], SIZE).any()


def test_recoloring_changes_the_road_and_keeps_the_paint_brighter_than_its_road():
    image, keep, _ = _scene()
    painted = (image[..., 0] > 200) & keep
    painted[: int(SIZE[1] * 0.6)] = False
    beside = cv2.dilate(keep.astype(np.uint8), np.ones((5, 5), np.uint8)).astype(bool) & ~keep
    beside[: int(SIZE[1] * 0.6)] = False
    changed_road = []
    for seed in range(12):
        out = recolour(image, keep, np.random.default_rng(seed)) * 255.0
        assert out[painted].mean() > out[beside].mean() + 40.0, seed
        changed_road.append(np.abs(out[~keep] - image[~keep]).mean())
    assert np.median(changed_road) > 15.0


def test_training_samples_with_randomisation_are_reproducible(tiny_dataset):  # noqa: F811
    spec = ModelSpec(family="ufld", width=TINY_SPEC["width"], input_size=tuple(TINY_SPEC["input_size"]))
    split = read_splits([tiny_dataset])[0]
    plain = LabelledFrames(split, spec, seed=3)
    a = LabelledFrames(split, spec, seed=3, randomised=True, photometric=True)
    b = LabelledFrames(split, spec, seed=3, randomised=True, photometric=True)
    for index in range(len(plain)):
        sample_a, sample_b, sample_p = a[index], b[index], plain[index]
        assert torch.equal(sample_a["image"], sample_b["image"])
        assert not torch.equal(sample_a["image"], sample_p["image"])
        assert torch.equal(sample_a["rows"], sample_p["rows"])  # labels (and the flip) are those of a plain run


def test_randomised_training_records_its_ingredients(tiny_dataset, tmp_path):  # noqa: F811
    assert _train(tiny_dataset, tmp_path, "ufld", "--randomise", "--photometric") == 0
    summary = json.loads((tmp_path / "training.json").read_text())
    assert summary["randomise"] is True and summary["photometric"] is True


def _torchvision_state(depth: str) -> dict:
    """A state dict in torchvision's ResNet layout: the backbone's names, random values, and its classifier."""
    generator = torch.Generator().manual_seed(0)
    state = {name: torch.randn(tensor.shape, generator=generator) if tensor.is_floating_point() else tensor
             for name, tensor in ResNet(depth, 1.0).state_dict().items()}
    state["fc.weight"] = torch.randn(1000, 512, generator=generator)
    state["fc.bias"] = torch.randn(1000, generator=generator)
    return state


def test_backbone_weights_in_torchvision_layout_load_every_tensor(tmp_path):
    state = _torchvision_state("resnet18")
    path = tmp_path / "resnet18-imagenet.pth"
    torch.save(state, path)
    model = build_model(ModelSpec(family="seg", width=1.0, input_size=(128, 72)))
    assert load_backbone_weights(model.backbone, path) == len(model.backbone.state_dict())
    for name, tensor in model.backbone.state_dict().items():
        assert torch.equal(tensor, state[name].to(tensor.dtype)), name
    torch.save({"state_dict": {"module." + k: v for k, v in state.items()}}, path)  # a wrapped checkpoint
    assert load_backbone_weights(build_model(ModelSpec(family="ufld", width=1.0)).backbone, path) > 0


def test_backbone_weights_of_another_depth_or_width_are_refused(tmp_path):
    path = tmp_path / "resnet34.pth"
    torch.save(_torchvision_state("resnet34"), path)
    with pytest.raises(BackboneWeightsError, match="layer1.2|not a tensor"):
        load_backbone_weights(ResNet("resnet18", 1.0), path)
    torch.save(_torchvision_state("resnet18"), path)
    with pytest.raises(BackboneWeightsError, match="--width 1.0"):
        load_backbone_weights(ResNet("resnet18", 0.5), path)
    (tmp_path / "junk.pth").write_bytes(b"not a checkpoint")
    with pytest.raises(BackboneWeightsError, match="not a PyTorch state dict"):
        load_backbone_weights(ResNet("resnet18", 1.0), tmp_path / "junk.pth")


def test_backbone_weights_cli_errors_exit_2(tiny_dataset, tmp_path, capsys):  # noqa: F811
    path = tmp_path / "resnet18.pth"
    torch.save(_torchvision_state("resnet18"), path)
    assert _train(tiny_dataset, tmp_path / "m", "ufld", "--backbone-weights", str(path)) == 2  # width 0.125
    assert "--width 1.0" in capsys.readouterr().err
    assert _train(tiny_dataset, tmp_path / "m", "ufld", "--backbone-weights", str(tmp_path / "none.pth")) == 2
    assert "no such file" in capsys.readouterr().err


def test_mirror_agreement_keeps_lanes_read_alike_and_drops_the_rest():
    rows = np.linspace(0.5, 1.0, 11)
    left = LaneLine(np.stack([0.45 - 0.6 * (rows - 0.5), rows], axis=1))
    right = LaneLine(np.stack([0.55 + 0.6 * (rows - 0.5), rows], axis=1))
    mirrored_left = LaneLine(np.stack([0.55 + 0.6 * (rows - 0.5), rows], axis=1))  # the left line in the mirror
    mirrored_right_off = LaneLine(np.stack([np.full(11, 0.5), rows], axis=1))  # the right line read elsewhere
    direct = [None, None, left, right, None, None]
    flipped = [None, None, mirrored_right_off, mirrored_left, None, None]
    kept = agreeing_lanes(direct, flipped, 0.015)
    assert len(kept) == 1 and kept[0] is left


def test_mirror_agreement_matches_lanes_by_position_when_the_counts_differ():
    """Anchor and curve families read however many lanes they find, in score order: a frame and its mirror may
    give different counts, and the lanes are matched by where they lie."""
    rows = np.linspace(0.5, 1.0, 11)
    left = LaneLine(np.stack([0.45 - 0.6 * (rows - 0.5), rows], axis=1))
    right = LaneLine(np.stack([0.55 + 0.6 * (rows - 0.5), rows], axis=1))
    mirrored_left = LaneLine(np.stack([0.55 + 0.6 * (rows - 0.5), rows], axis=1))
    stray = LaneLine(np.stack([np.full(11, 0.1), rows], axis=1))
    assert agreeing_lanes([right, left], [mirrored_left], 0.015) == [left]
    assert agreeing_lanes([left], [stray, mirrored_left, None], 0.015) == [left]
    assert agreeing_lanes([left, right], [], 0.015) == []


def test_adabn_re_estimates_the_normalization_statistics_only():
    model = build_model(ModelSpec(family="seg", width=0.125, input_size=(128, 72)))
    statistics = ("running", "num_batches")
    weights_before = {k: v.clone() for k, v in model.state_dict().items() if not any(s in k for s in statistics)}
    images = np.random.default_rng(0).integers(0, 255, (6, 72, 128, 3), dtype=np.uint8)
    layers = adapt_batch_norm(model, images, torch.device("cpu"), batch=3)
    assert layers > 0 and not model.training
    state = model.state_dict()
    assert all(torch.equal(state[k], v) for k, v in weights_before.items())
    assert float(model.backbone.bn1.running_mean.abs().sum()) > 0.0  # reset from zero, then estimated


def test_adapt_writes_a_model_usable_as_weights(tiny_dataset, tmp_path, capsys):  # noqa: F811
    assert _train(tiny_dataset, tmp_path / "model", "ufld") == 0
    frames = _my_frames(tiny_dataset, tmp_path / "my_frames")
    assert frame_files((frames,), 2) == [frames / "0.png", frames / "3.png"]
    out = tmp_path / "adapted"
    code = main(["adapt", "--weights", str(tmp_path / "model"), "--frames", str(frames), "--out", str(out),
                 "--epochs", "1", "--quiet"])
    assert code == 0, capsys.readouterr().err
    summary = json.loads((out / "training.json").read_text())
    assert summary["frames"] == 4 and summary["adabn_layers"] > 0 and "self_training" in summary
    detector = LearnedDetector(out)
    rgb = cv2.imread(str(frames / "0.png"))[..., ::-1]
    assert isinstance(detector(np.ascontiguousarray(rgb), list(range(100, 144, 4))), list)
    assert main(["detect", str(tiny_dataset / "train"), "--method", "ufld", "--weights", str(out),
                 "--out", str(tmp_path / "pred.json")]) == 0
    again = tmp_path / "two_rounds"
    code = main(["adapt", "--weights", str(tmp_path / "model"), "--frames", str(frames), "--out", str(again),
                 "--method", "self-train", "--rounds", "2", "--epochs", "1", "--quiet"])
    assert code == 0, capsys.readouterr().err
    rounds = json.loads((again / "training.json").read_text())["self_training"]
    assert "adabn_layers" not in json.loads((again / "training.json").read_text())
    assert "rounds" in rounds and len(rounds["rounds"]) == 2


def _my_frames(dataset: Path, folder: Path, count: int = 4) -> Path:
    """``count`` frames of a dataset copied, unlabelled, into ``folder``."""
    folder.mkdir()
    for index, path in enumerate(sorted((dataset / "train").rglob("*.png"))[:count]):
        (folder / f"{index}.png").write_bytes(path.read_bytes())
    return folder


def test_gradient_reversal_flips_the_sign_of_gradients_and_nothing_else():
    features = torch.randn(3, 5, generator=torch.Generator().manual_seed(0), requires_grad=True)
    weights = torch.randn(5, generator=torch.Generator().manual_seed(1))
    reversed_out = reverse_gradient(features, 0.7)
    assert torch.equal(reversed_out, features)
    (reversed_out * weights).sum().backward()
    assert torch.allclose(features.grad, -0.7 * weights.expand(3, 5))
    plain = features.detach().clone().requires_grad_(True)
    (plain * weights).sum().backward()
    assert torch.allclose(features.grad, -0.7 * plain.grad)
    ramp = [reversal_weight(p) for p in np.linspace(0.0, 1.0, 11)]
    assert ramp[0] == 0.0 and abs(ramp[-1] - 0.99991) < 1e-5 and abs(ramp[1] - 0.4621) < 1e-4 and all(np.diff(ramp) > 0)


@pytest.mark.parametrize("family", FAMILIES)
def test_pooled_features_reach_the_backbone_of_every_family(family):
    model = build_model(ModelSpec(family=family, **TINY_SPEC)).train()
    images = torch.rand(2, 3, TINY_SPEC["input_size"][1], TINY_SPEC["input_size"][0])
    with pooled_features(model) as features:
        model(images)
    model(images)  # outside the block: nothing more is kept
    assert len(features) == 1 and features[0].shape == (2, model.backbone.channels[-1])
    features[0].sum().backward()
    assert float(model.backbone.conv1.weight.grad.abs().sum()) > 0.0


def test_target_batches_cover_every_frame_before_repeating_one():
    batches = target_batches(5, 3, 4, np.random.default_rng(0))
    assert [len(b) for b in batches] == [3, 3, 3, 3]
    assert sorted(np.concatenate(batches)[:5].tolist()) == [0, 1, 2, 3, 4]


@pytest.mark.parametrize(("family", "method"), [("ufld", "adabn+dann"), ("seg", "dann")])
def test_dann_adapts_on_labelled_renders_and_writes_a_loadable_model(tiny_dataset, tmp_path, capsys,  # noqa: F811
                                                                      family, method):
    assert _train(tiny_dataset, tmp_path / "model", family) == 0
    frames = _my_frames(tiny_dataset, tmp_path / "my_frames")
    runs = []
    for name in ("a", "b"):  # the same seed twice: the same weights
        out = tmp_path / name
        code = main(["adapt", "--weights", str(tmp_path / "model"), "--frames", str(frames), "--out", str(out),
                     "--method", method, "--source", str(tiny_dataset / "train"), "--epochs", "2", "--seed", "3",
                     "--quiet"])
        assert code == 0, capsys.readouterr().err
        runs.append(torch.load(out / "weights.pt", weights_only=True))
    assert all(torch.equal(runs[0][k], runs[1][k]) for k in runs[0])
    before = torch.load(tmp_path / "model" / "weights.pt", weights_only=True)
    assert any(not torch.equal(before[k], runs[0][k]) for k in before if "backbone.layer1" in k)
    summary = json.loads((tmp_path / "a" / "training.json").read_text())
    dann = summary["dann"]
    assert summary["source"] == ["train"] and dann["source_frames"] == 10 and dann["target_frames"] == 4
    assert len(dann["domain_accuracy"]) == 2 and all(0.0 <= a <= 1.0 for a in dann["domain_accuracy"])
    assert ("adabn_layers" in summary) == ("adabn" in method) and "self_training" not in summary
    detector = LearnedDetector(tmp_path / "a")
    rgb = cv2.imread(str(frames / "0.png"))[..., ::-1]
    assert isinstance(detector(np.ascontiguousarray(rgb), list(range(100, 144, 4))), list)


def test_dann_without_source_or_source_without_dann_exits_2(tiny_dataset, tmp_path, capsys):  # noqa: F811
    frames = _my_frames(tiny_dataset, tmp_path / "my_frames", 1)
    base = ["adapt", "--weights", "seg", "--frames", str(frames), "--out", str(tmp_path / "o")]
    for method in ("dann", "adabn+dann", "dann+self-train"):
        assert main([*base, "--method", method]) == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and "--source" in err, err
    assert main([*base, "--source", str(tiny_dataset / "train")]) == 2
    assert "--source: only with a dann method" in capsys.readouterr().err
    assert main([*base, "--method", "dann", "--source", str(tmp_path / "nowhere")]) == 2
    assert "--source" in capsys.readouterr().err and not (tmp_path / "o").exists()
    assert main([*base, "--method", "dann", "--source", str(tiny_dataset / "train"), "--domain-weight", "-1"]) == 2
    assert "--domain-weight -1: must be at least 0" in capsys.readouterr().err


def test_a_model_folder_is_a_named_detector_everywhere(tiny_dataset, tmp_path, monkeypatch, capsys):  # noqa: F811
    from lanevil_core.detect.catalog import detector_info

    assert _train(tiny_dataset, tmp_path / "model", "seg") == 0
    monkeypatch.setenv("LANEVIL_DETECTORS", f"mine=onnx:{tmp_path / 'model'};gone=onnx:{tmp_path / 'nowhere'}")
    info = detector_info("mine")
    assert info.kind == "onnx" and info.available, info.reason
    assert main(["detect", str(tiny_dataset / "train"), "--method", "mine", "--out", str(tmp_path / "p.json")]) == 0
    assert len((tmp_path / "p.json").read_text().splitlines()) == 10
    assert not detector_info("gone").available
    assert main(["detect", str(tiny_dataset / "train"), "--method", "gone", "--out", str(tmp_path / "q.json")]) == 2
    assert "gone" in capsys.readouterr().err


@pytest.mark.parametrize("name", BUNDLED_MODELS)
def test_adapt_takes_a_bundled_model_by_name_and_keeps_its_family(tiny_dataset, tmp_path, capsys, name):  # noqa: F811
    frames = _my_frames(tiny_dataset, tmp_path / "my_frames", 2)
    out = tmp_path / "adapted"
    code = main(["adapt", "--weights", name, "--frames", str(frames), "--out", str(out), "--method", "adabn",
                 "--quiet"])
    assert code == 0, capsys.readouterr().err
    family = ModelSpec.load(shipped_model_dir(name)).family
    assert ModelSpec.load(out).family == family
    assert json.loads((out / "training.json").read_text())["adapted_from"] == name
    assert main(["detect", str(tiny_dataset / "train"), "--method", family, "--weights", str(out),
                 "--out", str(tmp_path / "pred.json")]) == 0


def test_adapt_errors_exit_2(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    for shipped in ("ufld", *BUNDLED_MODELS):  # a family's and a bundled model's name both name a shipped folder
        assert main(["adapt", "--weights", shipped, "--frames", str(tmp_path / "empty"),
                     "--out", str(tmp_path / "o")]) == 2
        assert "no png or jpg" in capsys.readouterr().err
    assert main(["adapt", "--weights", "ufld", "--frames", str(tmp_path), "--out", str(tmp_path / "o"),
                 "--rounds", "0"]) == 2
    assert "--rounds" in capsys.readouterr().err
    assert main(["adapt", "--weights", str(tmp_path / "nowhere"), "--frames", str(tmp_path),
                 "--out", str(tmp_path / "o")]) == 2
    assert "no such model folder" in capsys.readouterr().err


@pytest.mark.parametrize(("changes", "message"), [
    ({"min_epochs": 2}, "--min-epochs: only with --patience"),
    ({"min_epochs": 5, "patience": 2, "epochs": 3}, "more than --epochs 3"),
    ({"val_fraction": 1.0}, r"--val 1.0: must lie in \[0, 1\)"),
    ({"backbone_weights": Path("r18.pth")}, "need --width 1.0"),
    ({"time_limit": 0.0}, "--time-limit 0: must be positive"),
    ({"augment": "blur"}, "--augment blur: choose from"),
])
def test_train_settings_hold_their_own_rules(tmp_path, changes, message):
    from lanevil_core.learn.train import TrainError, TrainSettings

    with pytest.raises(TrainError, match=message):
        TrainSettings(data=(tmp_path,), out=tmp_path / "m", **changes)
    TrainSettings(data=(tmp_path,), out=tmp_path / "m")  # the defaults hold every rule


def test_a_run_ships_only_with_half_the_ego_lines_on_both_car_height_splits_and_more_accuracy(load_script):
    choose = load_script("experiments/transfer_choice.py").choose

    def table(**models: tuple[float, float]) -> dict:
        return {name: {"frame": {"ego": ego, "accuracy": accuracy}} for name, (ego, accuracy) in models.items()}

    tusimple = table(start=(60, 70), a=(70, 75), b=(40, 90), c=(55, 69))
    dashcam = table(start=(60, 70), a=(55, 75), b=(80, 90), c=(55, 69))
    heldout = table(start=(20, 50), a=(10, 52), b=(30, 60), c=(30, 55))
    chosen, mean = choose([tusimple, dashcam, heldout], "start")
    assert chosen == "a"  # b is more accurate but misses half the ego lines on tusimple
    assert mean["start"] == pytest.approx(190 / 3) and mean["c"] == pytest.approx(193 / 3)
    assert choose([tusimple, dashcam, heldout], "start", ego=80)[0] == "start"  # none qualifies
