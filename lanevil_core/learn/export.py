"""ONNX export of a trained network (``Deployed``: probabilities under fixed names, dynamic batch)."""

from __future__ import annotations

import warnings
from pathlib import Path

import torch

from .models import Deployed, LaneNet

OPSET = 17


def export_onnx(model: LaneNet, path: str | Path) -> Path:
    """Write ``model`` (an ``UFLDNet`` or ``SegNet``) as ONNX with input ``image`` (N, 3, H, W) float32 0..1."""
    import onnx

    path = Path(path)
    deployed = Deployed(model).cpu().eval()
    width, height = model.spec.input_size
    dummy = torch.zeros(1, 3, height, width)
    names = deployed.output_names()
    tmp = path.with_suffix(".onnx.tmp")
    # The TorchScript exporter: about 1 s for these networks, byte-stable, and it needs no onnxscript; the
    # torch.export-based one takes 5-6 s and prints progress. Its deprecation notice is expected here.
    with torch.no_grad(), warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        torch.onnx.export(deployed, (dummy,), str(tmp), input_names=["image"], output_names=names,
                          dynamic_axes={"image": {0: "batch"}, **{n: {0: "batch"} for n in names}},
                          opset_version=OPSET, dynamo=False)
    onnx.checker.check_model(str(tmp))
    tmp.replace(path)
    return path
