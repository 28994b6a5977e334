"""ONNX export of a trained network (``Deployed``: probabilities under fixed names, dynamic batch)."""

from __future__ import annotations

import warnings
from pathlib import Path

import torch

from ..detect.model_spec import ONNX_FILE, WEIGHTS_FILE, ModelSpec
from .models import Deployed, LaneNet, build_model

OPSET = 17


def load_weights(model_dir: str | Path) -> LaneNet:
    """The network of a model folder (``config.json`` and ``weights.pt``, stored in half precision) in float32,
    on the CPU."""
    model_dir = Path(model_dir)
    model = build_model(ModelSpec.load(model_dir))
    state = torch.load(model_dir / WEIGHTS_FILE, map_location="cpu", weights_only=True)
    model.load_state_dict({k: v.float() if v.is_floating_point() else v for k, v in state.items()})
    return model.eval()


def export_model_dir(model_dir: str | Path) -> Path:
    """Write a model folder's ``model.onnx`` again from its ``config.json`` and ``weights.pt``: for weights trained
    elsewhere and copied back without it (``scripts/models-transfer-world``)."""
    return export_onnx(load_weights(model_dir), Path(model_dir) / ONNX_FILE)


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
