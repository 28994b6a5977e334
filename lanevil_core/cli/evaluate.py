"""``lanevil eval``, ``lanevil detect``, ``lanevil detectors`` and ``lanevil report``: metrics, detectors,
robustness tables."""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

from ..files import write_atomic
from ..metrics.formats import LaneFileError, split_note
from ..metrics.tusimple import F1_VARIANTS
from .base import Command, UsageError

METRIC_CHOICES = ("tusimple", "culane", "ego", "pixel")


def _note_split(path: Path) -> None:
    """Say on stderr when a dataset folder stands for a split other than its test split."""
    note = split_note(path)
    if note is not None:
        print(f"note: {note}", file=sys.stderr)


def _eval_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--gt", type=Path, required=True,
                        help="ground truth: TuSimple JSON lines (or a split folder with its *_label.json, or a "
                             "dataset folder: its test split), or a folder of CULane .lines.txt files")
    parser.add_argument("--pred", type=Path, required=True, help="predictions in the same format as --gt")
    parser.add_argument("--metric", choices=METRIC_CHOICES, default="tusimple",
                        help="default tusimple; ego: share of the ego lane's two lines matched (>= 85 %% of their "
                             "labelled rows within 20 px) and their mean point accuracy; pixel: IoU and F1 of the "
                             "lane-line pixels, both sides' lanes drawn --line-width wide (--pred may also be a "
                             "folder of mask PNGs named like the GT images)")
    parser.add_argument("--line-width", type=float, default=None, metavar="PX",
                        help="pixel metric: lane-line width in pixels at 720 image rows, scaled with the height "
                             "(default 8)")
    parser.add_argument("--f1", choices=tuple(F1_VARIANTS), default="ganet",
                        help="TuSimple F1 variant: ganet (P = 1-FP, R = 1-FN) or clrnet (default ganet)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def _format_eval(result: dict) -> str:
    if result["metric"] == "tusimple":
        return (f"TuSimple  images {result['images']}  Accuracy {100 * result['accuracy']:.2f} %  "
                f"FP {result['fp']:.4f}  FN {result['fn']:.4f}  F1({result['f1_variant']}) {100 * result['f1']:.2f} %")
    if result["metric"] == "pixel":
        return (f"Pixel lane lines ({result['line_width']:g} px at 720 rows)  images {result['images']}  "
                f"IoU {100 * result['iou']:.2f} %  F1 {100 * result['f1']:.2f} %  P {100 * result['precision']:.2f} %  "
                f"R {100 * result['recall']:.2f} %")
    if result["metric"] == "ego":
        return (f"Ego lines  images {result['images']}  lines {result['ego_lines']}  matched {result['matched']} "
                f"({100 * result['match_share']:.2f} %)  point accuracy {100 * result['point_accuracy']:.2f} %")
    return (f"CULane IoU>{result['iou_threshold']}  images {result['images']}  TP {result['tp']}  FP {result['fp']}  "
            f"FN {result['fn']}  P {100 * result['precision']:.2f} %  R {100 * result['recall']:.2f} %  "
            f"F1 {100 * result['f1']:.2f} %")


def _run_eval(args: argparse.Namespace) -> int:
    from ..metrics.evaluate import evaluate
    from ..metrics.pixel import LINE_WIDTH_720

    if args.line_width is not None and args.metric != "pixel":
        raise UsageError("--line-width: only with --metric pixel")
    _note_split(args.gt)
    try:
        result = evaluate(args.gt, args.pred, args.metric, args.f1,
                          args.line_width if args.line_width is not None else LINE_WIDTH_720)
    except LaneFileError as error:
        raise UsageError(str(error)) from None
    print(json.dumps(result) if args.json else _format_eval(result))
    return 0


def _detect_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("split", type=Path, help="split folder (e.g. DATASET/test) with its *_label.json or "
                                                 "images; a dataset folder stands for its test split (for its only "
                                                 "split, with a note, when it has no test split)")
    from ..detect.learned import BUNDLED_MODELS
    from ..detect.split import METHODS

    parser.add_argument("--method", required=True, action="append", metavar="METHOD",
                        help=f"built-in: {', '.join(METHODS)} (learned ufld: row anchors, seg: segmentation, laneatt: "
                             "line anchors, bezier: Bézier curves, ganet: keypoints, scnn: message-passing "
                             "segmentation; ONNX; hough, birdseye: classical); a shipped named model, run as its "
                             f"family, for other cameras and roads: {', '.join(BUNDLED_MODELS)}; a plug-in's name "
                             "(LANEVIL_DETECTORS, LANEVIL_DETECTORS_FILE, installed lanevil.detectors); or a "
                             "source: http://HOST:PORT/PATH (a detector server) or onnx:PATH (a model with a sidecar "
                             "JSON); repeat to run several over one reading of the images")
    parser.add_argument("--weights", type=Path, default=None,
                        help="model folder of a learned method (default: the model shipped with lanevil); "
                             "only with a single --method")
    parser.add_argument("--out", type=Path, required=True,
                        help="predictions file (TuSimple JSON lines); with several --method a folder that gets "
                             "one METHOD.json each")
    parser.add_argument("--masks", type=Path, default=None, metavar="DIR",
                        help="also write each image's lane-line mask as DIR/<image>.png (an ONNX model with a mask "
                             "head, one --method) for lanevil eval --metric pixel --pred DIR")
    parser.add_argument("--fixed-run-time", type=float, default=None, metavar="MS",
                        help="write this run_time instead of the measured one (byte-reproducible output)")


def file_stem(method: str) -> str:
    """A file name for a method: its name, or a source (``http://...``, ``onnx:PATH``) with every character that is
    not a letter, digit, ``_``, ``.`` or ``-`` made one ``_`` per run."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", method).strip("._") or "detector"


def _run_detect(args: argparse.Namespace) -> int:
    from ..detect import detect_split_methods

    def progress(done: int, total: int) -> None:
        if done % 50 == 0 or done == total:
            print(f"\rimage {done}/{total}", end="" if done < total else "\n", file=sys.stderr, flush=True)

    several = len(args.method) > 1
    # Checked before the images are read: a full split takes most of an hour.
    if several and args.out.exists() and not args.out.is_dir():
        raise UsageError(f"--out {args.out}: with several --method, a folder (it is a file)")
    if not several and args.out.is_dir():
        raise UsageError(f"--out {args.out}: with one --method, a predictions file (it is a folder)")
    masks_by = None
    if args.masks is not None:  # checked before the images are read, like --out
        from ..detect.mask_split import mask_detector

        if several:
            raise UsageError("--masks: only with a single --method")
        try:
            masks_by = mask_detector(args.method[0])
        except LaneFileError as error:
            raise UsageError(str(error)) from None
    stems = [file_stem(method) for method in args.method]
    if several and len(set(stems)) < len(stems) == len(set(args.method)):  # (a method named twice: said below)
        raise UsageError(f"--method: two methods would write the same file in --out ({', '.join(args.method)}); "
                         "name them in LANEVIL_DETECTORS")
    _note_split(args.split)
    try:
        by_method = detect_split_methods(args.split, args.method, progress, args.fixed_run_time, args.weights)
    except LaneFileError as error:
        raise UsageError(str(error)) from None
    for method, records in by_method.items():
        path = args.out / f"{file_stem(method)}.json" if several else args.out
        write_atomic(path, "".join(json.dumps(record) + "\n" for record in records).encode("utf-8"))
        print(f"{len(records)} predictions in {path}")
    if masks_by is not None:
        from ..detect.mask_split import write_split_masks

        try:
            count = write_split_masks(args.split, masks_by, args.masks, progress)
        except LaneFileError as error:
            raise UsageError(str(error)) from None
        print(f"{count} lane-line masks in {args.masks}")
    return 0


def _report_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--gt", type=Path, required=True,
                        help="dataset folder (its test split) or split folder (e.g. DATASET/test)")
    parser.add_argument("--pred", type=Path, required=True, action="append",
                        help="predictions (TuSimple JSON lines); repeat for several detectors side by side")
    parser.add_argument("--name", action="append", default=None,
                        help="detector name for each --pred, in order (default: the file names)")
    parser.add_argument("--baseline", default=None, metavar="NAME",
                        help="with several --pred: add the defence table, each detector's perturbed accuracy and its "
                             "gain over this one (e.g. the model trained with --augment none); with runs named "
                             "DEFENCE@SEED (e.g. --name none@0 --name aam@0 --name none@1 --name aam@1 --baseline "
                             "none), one table per seed and the mean gain over seeds")
    parser.add_argument("--real-trained", action="append", default=[], metavar="NAME",
                        help="a detector (its --name) trained on real roads: reported apart in the Real -> LanEvil "
                             "table (real_to_lanevil.md); repeatable. Plug-ins marked real_trained are included "
                             "without it")
    parser.add_argument("--out", type=Path, required=True, help="report folder")
    parser.add_argument("--f1", choices=tuple(F1_VARIANTS), default="ganet", help="F1 variant (default ganet)")
    parser.add_argument("--title", default=None, help="report title (default: from the prediction file name)")


def real_trained(names: list[str], marked: list[str]) -> list[str]:
    """The detectors of ``names`` reported in the Real -> LanEvil table: those ``--real-trained`` names, and the
    plug-ins whose configuration or metadata says so (a malformed plug-in configuration marks none)."""
    from ..detect.catalog import detector_info
    from ..detect.registry import plugin_specs

    unknown = sorted(set(marked) - set(names))
    if unknown:
        raise UsageError(f"--real-trained {unknown[0]!r}: not one of the detector names {', '.join(names)}")
    try:
        plugins = set(plugin_specs())
        by_plugin = {name for name in names if name in plugins and detector_info(name).real_trained}
    except LaneFileError:
        by_plugin = set()
    return [name for name in names if name in marked or name in by_plugin]


def _run_report(args: argparse.Namespace) -> int:
    from ..metrics.evaluate import score_tusimple_files
    from ..metrics.formats import split_labels
    from ..report.compare import SEED_MARK, Detector, defence_and_seed, write_comparison
    from ..report.robustness import build_report, write_report

    names = args.name or [path.stem for path in args.pred]
    if len(names) != len(args.pred):
        raise UsageError(f"--name: {len(names)} names for {len(args.pred)} --pred files")
    if len(set(names)) != len(names):
        raise UsageError("--pred: two detectors have the same name; give each a --name")
    detectors = []
    _note_split(args.gt)
    try:
        gt = split_labels(args.gt)
        for name, pred in zip(names, args.pred, strict=True):
            title = args.title or f"Robustness report: {name}"
            detectors.append(Detector(name, build_report(score_tusimple_files(gt, pred), args.f1, title)))
    except LaneFileError as error:
        raise UsageError(str(error)) from None
    for detector in detectors:
        total = detector.report.rows[-1]
        figures = [f"{label} {100 * stats.accuracy:.2f} %" for label, stats in
                   (("original", total.original), ("perturbed", total.perturbed), ("paint-free", total.no_paint))
                   if stats is not None]
        print(f"{detector.name}: accuracy " + ", ".join(figures))
    real = real_trained(names, args.real_trained)
    if len(detectors) == 1:
        paths = write_report(detectors[0].report, args.out)
    else:
        seeded = {f"{args.baseline}{SEED_MARK}{defence_and_seed(name)[1]}" for name in names}
        if args.baseline is not None and args.baseline not in names and not seeded & set(names):
            raise UsageError(f"--baseline {args.baseline!r}: not one of the detector names {', '.join(names)} "
                             f"(nor a defence whose runs are named {args.baseline}{SEED_MARK}SEED)")
        paths = write_comparison(detectors, args.out, args.f1, args.baseline)
    if real:
        from ..report.real_to_lanevil import write_real_table

        paths += write_real_table([d for d in detectors if d.name in real], args.out, args.f1)
    for path in paths:
        print(path)
    return 0


def _detectors_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print one JSON object per detector")


def _run_detectors(args: argparse.Namespace) -> int:
    from ..detect.catalog import detector_infos

    try:
        infos = detector_infos()
    except LaneFileError as error:
        raise UsageError(str(error)) from None
    for info in infos:
        if args.json:
            print(json.dumps(info.as_dict()))
            continue
        state = "available" if info.available else f"not available: {info.reason}"
        extra = "".join(part for part in (f"  {info.source}" if info.source else "",
                                          "  real-trained" if info.real_trained else ""))
        print(f"{info.name:20s} {info.kind:10s} {state}{extra}")
    return 0


COMMANDS: dict[str, Command] = {
    "eval": Command("score predictions with the TuSimple, CULane or ego line metric", _eval_arguments, _run_eval),
    "detect": Command("run a lane detector (built-in or plug-in) over a split folder", _detect_arguments, _run_detect),
    "detectors": Command("list the lane detectors: built-ins and plug-ins (LANEVIL_DETECTORS, LANEVIL_DETECTORS_FILE, "
                         "installed lanevil.detectors), whether each can run here", _detectors_arguments,
                         _run_detectors),
    "report": Command("robustness tables and plot: original vs perturbed per category, type and severity, "
                      "for one detector or several side by side",
                      _report_arguments, _run_report),
}
