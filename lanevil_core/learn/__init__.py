"""Training learned lane detectors in plain PyTorch (the ``learn`` extra): models, data, losses, loop, ONNX export.

Inference lives in ``lanevil_core.detect.learned`` and runs the exported ONNX file, so nothing outside this
package imports torch.
"""

# The methods of ``lanevil adapt`` (``learn/adapt.py``), here so that the command line offers them without torch.
ADAPT_METHODS = ("adabn", "self-train", "adabn+self-train", "dann", "adabn+dann", "dann+self-train", "view")
