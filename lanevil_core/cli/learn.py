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
    if args.aam_keep_paint and args.augment != "aam":
        raise UsageError(f"--aam-keep-paint: only with --augment aam (not {args.augment})")
    if args.min_epochs and args.patience is None:
        raise UsageError("--min-epochs: only with --patience")
    if args.min_epochs > args.epochs:
        raise UsageError(f"--min-epochs {args.min_epochs}: more than --epochs {args.epochs}")
    if not 0.0 <= args.val_fraction < 1.0:
        raise UsageError(f"--val {args.val_fraction}: must lie in [0, 1)")
    try:
        spec = ModelSpec(family=args.model, backbone=args.backbone, width=args.width, input_size=args.size)
        settings = TrainSettings(data=tuple(args.data), out=args.out, spec=spec, epochs=args.epochs, batch=args.batch,
                                 lr=args.lr, augment=args.augment, affine=args.affine, device=args.device,
                                 seed=args.seed,
                                 val_fraction=args.val_fraction, resume=args.resume, init=args.init,
                                 max_steps=args.max_steps, threads=args.threads, patience=args.patience,
                                 min_epochs=args.min_epochs,
                                 aam=AamSettings(keep_paint=args.aam_keep_paint))
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


COMMANDS: dict[str, Command] = {
    "train": Command("train a learned lane detector (ufld, seg, laneatt, bezier, ganet or scnn) on a dataset's "
                     "clean train split",
                     _train_arguments, _run_train),
}
