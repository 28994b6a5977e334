"""``lanevil train``: fit a learned lane detector (one of ``detect.model_spec.FAMILIES``) on a dataset's clean
train split."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .base import Command, UsageError, count, parse_size


def _train_arguments(parser: argparse.ArgumentParser) -> None:
    from ..detect.model_spec import BACKBONES, FAMILIES

    parser.add_argument("--data", type=Path, required=True, action="append",
                        help="dataset folder written by `lanevil dataset` (its train/ split and train_label.json); "
                             "repeat to train on several splits together (each case folder is held out whole)")
    parser.add_argument("--out", type=Path, required=True, help="model folder to write")
    parser.add_argument("--model", choices=FAMILIES, default="ufld",
                        help="detector family: ufld (row anchors), seg (segmentation), laneatt (line anchors + "
                             "attention), bezier (Bézier curves), ganet (keypoints), scnn (message-passing "
                             "segmentation) (default ufld)")
    parser.add_argument("--backbone", choices=BACKBONES, default="resnet18", help="default resnet18")
    parser.add_argument("--width", type=float, default=0.25,
                        help="backbone channel multiplier (1.0 = published ResNet widths; default 0.25)")
    parser.add_argument("--size", type=parse_size, default=(320, 180), help="network input WxH (default 320x180)")
    parser.add_argument("--epochs", type=count(1), default=12, help="default 12 (the most, with --patience)")
    parser.add_argument("--batch", type=count(1), default=16, help="default 16")
    parser.add_argument("--lr", type=float, default=2e-3, help="peak learning rate of AdamW (default 2e-3)")
    parser.add_argument("--augment", choices=("none", "cutout", "mixup", "hsv", "copy_paste", "aam", "pgd"),
                        default="none",
                        help="training augmentation / defence: the paper's baselines, aam (Attention Area Mixing "
                             "with hard examples rendered from training variations) or pgd (adversarial training) "
                             "(default none)")
    parser.add_argument("--aam-keep-paint", action="store_true",
                        help="with --augment aam: leave each image's own lane markings unmixed, so an illusion lies "
                             "around the lines the labels describe but never erases them")
    parser.add_argument("--affine", action="store_true",
                        help="UFLD's geometric augmentation: every training sample rotated by up to 6 degrees and "
                             "shifted by up to 14 %% of the height and 16 %% of the width, labels with it")
    parser.add_argument("--device", choices=("auto", "cpu", "cuda"), default="auto", help="default auto")
    parser.add_argument("--seed", type=count(0), default=0, help="default 0")
    parser.add_argument("--val", type=float, default=0.1, dest="val_fraction",
                        help="share of the train split's case folders held out for validation (default 0.1)")
    parser.add_argument("--init", type=Path, default=None,
                        help="state dict to initialise from: a trained model's weights.pt (fine-tuning, heads "
                             "included) or a backbone's (e.g. ImageNet ResNet weights)")
    parser.add_argument("--randomise", action="store_true",
                        help="domain randomisation: everything but the lane paint re-coloured and re-textured, random "
                             "shadows, lights, occluders and distractors (learn/randomise.py)")
    parser.add_argument("--photometric", action="store_true",
                        help="strong photometric augmentation: colour, exposure, gamma, blur, noise, JPEG, erasing")
    parser.add_argument("--backbone-weights", type=Path, default=None,
                        help="start the backbone from an ImageNet checkpoint you supply, in torchvision's ResNet key "
                             "layout (resnet18/resnet34 state dict; needs --width 1.0; nothing is downloaded)")
    parser.add_argument("--val-data", type=Path, action="append", default=[],
                        help="validate (and with --patience choose the epoch) on these held-out synthetic splits "
                             "instead of held-out case folders of --data; repeatable")
    parser.add_argument("--loader-workers", type=count(0), default=0,
                        help="data-loading processes (default 0; on a GPU, several keep it fed)")
    parser.add_argument("--time-limit", type=float, default=None,
                        help="seconds of training after which no new epoch starts (the model is then exported as "
                             "after the last epoch)")
    parser.add_argument("--threads", type=count(0), default=0,
                        help="CPU threads (default 0 = every core; use 1 when other work shares the cores: "
                             "oversubscribed threads make training many times slower)")
    parser.add_argument("--resume", action="store_true", help="continue from MODEL_DIR/checkpoint.pt")
    parser.add_argument("--max-steps", type=count(1), default=None, help="batches per epoch at most (smoke runs)")
    parser.add_argument("--patience", type=count(1), default=None,
                        help="stop when validation accuracy has not improved for this many epochs and keep the best "
                             "epoch's weights (full-length training; --epochs is then the most)")
    parser.add_argument("--min-epochs", type=count(0), default=0,
                        help="with --patience: train at least this many epochs before it may stop (default 0)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def _run_train(args: argparse.Namespace) -> int:
    try:
        import torch  # noqa: F401
    except ImportError:
        raise UsageError("lanevil train needs PyTorch: pip install -e '.[learn]'") from None
    from ..detect.model_spec import ModelSpec, ModelSpecError
    from ..learn.aam import AamSettings
    from ..learn.train import TrainError, TrainSettings, train

    for data in args.data:
        if not data.is_dir():
            raise UsageError(f"--data {data}: no such folder")
    if len(set(args.data)) < len(args.data):
        raise UsageError("--data: the same folder given twice")
    if args.init is not None and not args.init.is_file():
        raise UsageError(f"--init {args.init}: no such file")
    if args.backbone_weights is not None and not args.backbone_weights.is_file():
        raise UsageError(f"--backbone-weights {args.backbone_weights}: no such file")
    for data in args.val_data:
        if not data.is_dir():
            raise UsageError(f"--val-data {data}: no such folder")
    try:
        spec = ModelSpec(family=args.model, backbone=args.backbone, width=args.width, input_size=args.size)
        settings = TrainSettings(data=tuple(args.data), out=args.out, spec=spec, epochs=args.epochs, batch=args.batch,
                                 lr=args.lr, augment=args.augment, affine=args.affine, device=args.device,
                                 seed=args.seed,
                                 val_fraction=args.val_fraction, resume=args.resume, init=args.init,
                                 max_steps=args.max_steps, threads=args.threads, patience=args.patience,
                                 min_epochs=args.min_epochs,
                                 aam=AamSettings(keep_paint=args.aam_keep_paint), randomise=args.randomise,
                                 photometric=args.photometric, backbone_weights=args.backbone_weights,
                                 val_data=tuple(args.val_data), loader_workers=args.loader_workers,
                                 time_limit=args.time_limit)
        summary = train(settings, show_progress=not args.quiet)
    except (ModelSpecError, TrainError) as error:
        raise UsageError(str(error)) from None
    except KeyboardInterrupt:
        print(f"interrupted: the last finished epoch is in {args.out}; add --resume to continue", file=sys.stderr)
        return 130
    accuracy = summary["val_accuracy"]
    shown = "n/a" if accuracy is None else f"{100 * accuracy:.2f} %"
    kept = f" (kept epoch {summary['kept_epoch']})" if summary["patience"] is not None else ""
    print(f"{args.out}: {summary['epochs_run']} epochs in {summary['seconds']:.0f} s, "
          f"validation accuracy {shown}{kept}")
    return 0


def _adapt_arguments(parser: argparse.ArgumentParser) -> None:
    from ..detect.learned import BUNDLED_MODELS
    from ..detect.model_spec import FAMILIES
    from ..learn import ADAPT_METHODS

    parser.add_argument("--weights", required=True,
                        help=f"the model to adapt: a model folder of `lanevil train`, a shipped family "
                             f"({', '.join(FAMILIES)}) or a shipped model ({', '.join(BUNDLED_MODELS)})")
    parser.add_argument("--frames", type=Path, required=True, action="append",
                        help="folder of your own unlabelled frames (png/jpg, searched recursively); repeatable")
    parser.add_argument("--out", type=Path, required=True, help="model folder to write")
    parser.add_argument("--method", choices=ADAPT_METHODS, default="adabn+self-train",
                        help="AdaBN (normalisation statistics re-estimated), self-training on confident "
                             "pseudo-labels, both in that order (default), or domain-adversarial training on "
                             "--source renders and your frames (dann; adabn+dann estimates the statistics after it, "
                             "dann+self-train self-trains the model it leaves), or view: the window of your camera "
                             "that shows the model the view it was trained on (no training; see --camera-height)")
    parser.add_argument("--camera-height", type=float, default=None,
                        help="with --method view: your camera's height over the road in metres, which with "
                             "--lane-width sets how wide the window is (without it the window keeps the frame's "
                             "proportions)")
    parser.add_argument("--lane-width", type=float, default=None,
                        help="with --method view and --camera-height: the width of your roads' lanes in metres "
                             "(default 3.5)")
    parser.add_argument("--source", type=Path, action="append", default=[],
                        help="with a dann method: a labelled split folder of renders (`lanevil dataset`, TuSimple "
                             "labels, as `lanevil train --data` reads) to keep the lanes learned on; repeatable")
    parser.add_argument("--epochs", type=count(1), default=3,
                        help="self-training epochs, and passes over the --source frames with dann (default 3)")
    parser.add_argument("--domain-weight", type=float, default=1.0,
                        help="with a dann method: scale of the reversed domain gradient (default 1; 0 fine-tunes on "
                             "--source alone, the control that says what the alignment adds)")
    parser.add_argument("--rounds", type=count(1), default=1,
                        help="self-training rounds, each on the last round's model's readings (default 1)")
    parser.add_argument("--lr", type=float, default=2e-4,
                        help="self-training and adversarial learning rate (default 2e-4)")
    parser.add_argument("--max-frames", type=count(1), default=2000,
                        help="frames read at most, of --frames and of --source each (default 2000)")
    parser.add_argument("--device", choices=("auto", "cpu", "cuda"), default="auto", help="default auto")
    parser.add_argument("--seed", type=count(0), default=0, help="default 0")
    parser.add_argument("--threads", type=count(0), default=0, help="CPU threads (default every core)")
    parser.add_argument("--quiet", action="store_true", help="no progress lines")


def _adapted_model(weights: str) -> Path:
    """The model folder ``--weights`` names: a shipped family or model, or a folder (which must exist)."""
    from ..detect.learned import BUNDLED_MODELS, shipped_model_dir
    from ..detect.model_spec import FAMILIES

    model = shipped_model_dir(weights) if weights in FAMILIES or weights in BUNDLED_MODELS else Path(weights)
    if not model.is_dir():
        raise UsageError(f"--weights {weights}: no such model folder")
    return model


def _check_folders(flags: tuple[tuple[str, list[Path]], ...]) -> None:
    """Every folder given with each flag exists, else a usage error naming the flag and the folder."""
    for flag, folders in flags:
        for folder in folders:
            if not folder.is_dir():
                raise UsageError(f"{flag} {folder}: no such folder")


def _run_adapt_view(args: argparse.Namespace) -> int:
    from ..detect.view import ViewError
    from ..learn.view import DEFAULT_LANE_M, adapt_view

    if args.source:
        raise UsageError("--source: only with a dann method (not view)")
    if args.camera_height is not None and not 0.3 <= args.camera_height <= 10.0:
        raise UsageError(f"--camera-height {args.camera_height}: give the height in metres, 0.3 to 10")
    if args.lane_width is not None and args.camera_height is None:
        raise UsageError("--lane-width: only with --camera-height")
    lane_width = DEFAULT_LANE_M if args.lane_width is None else args.lane_width
    if not 2.0 <= lane_width <= 6.0:
        raise UsageError(f"--lane-width {lane_width}: give the width in metres, 2 to 6")
    model = _adapted_model(args.weights)
    _check_folders((("--frames", args.frames),))
    try:
        summary = adapt_view(model, tuple(args.frames), args.out, args.camera_height, lane_width, args.max_frames)
    except ViewError as error:
        raise UsageError(str(error)) from None
    window = ", ".join(f"{value:.2f}" for value in summary["view"]["window"])
    print(f"{args.out}: view of {summary['frames']} frames (vanishing point measured on {summary['view']['frames']}), "
          f"window [{window}] in {summary['seconds']:.0f} s")
    return 0


def _run_adapt(args: argparse.Namespace) -> int:
    if args.method == "view":
        return _run_adapt_view(args)
    for flag, value in (("--camera-height", args.camera_height), ("--lane-width", args.lane_width)):
        if value is not None:
            raise UsageError(f"{flag}: only with --method view")
    try:
        import torch  # noqa: F401
    except ImportError:
        raise UsageError("lanevil adapt needs PyTorch: pip install -e '.[learn]'") from None
    from ..detect.model_spec import ModelSpecError
    from ..learn.adapt import AdaptError, AdaptSettings, adapt

    model = _adapted_model(args.weights)
    _check_folders((("--frames", args.frames), ("--source", args.source)))
    try:
        settings = AdaptSettings(model=model, frames=tuple(args.frames), out=args.out, method=args.method,
                                 source=tuple(args.source), epochs=args.epochs,
                                 domain_weight=args.domain_weight, rounds=args.rounds, lr=args.lr,
                                 max_frames=args.max_frames, device=args.device, seed=args.seed,
                                 threads=args.threads)
        summary = adapt(settings, show_progress=not args.quiet)
    except (AdaptError, ModelSpecError) as error:
        raise UsageError(str(error)) from None
    kept = summary.get("self_training", {}).get("pseudo_labelled")
    extra = "" if kept is None else f", {kept} frames pseudo-labelled"
    if "dann" in summary:
        extra += (f", {summary['dann']['source_frames']} source frames, domain accuracy "
                  f"{summary['dann']['domain_accuracy'][-1]:.2f}")
    print(f"{args.out}: adapted on {summary['frames']} frames ({args.method}{extra}) in {summary['seconds']:.0f} s")
    return 0


COMMANDS: dict[str, Command] = {
    "adapt": Command("adapt a learned detector to your own unlabelled frames (AdaBN, self-training, DANN, view)",
                     _adapt_arguments, _run_adapt),
    "train": Command("train a learned lane detector (ufld, seg, laneatt, bezier, ganet or scnn) on a dataset's "
                     "clean train split",
                     _train_arguments, _run_train),
}
