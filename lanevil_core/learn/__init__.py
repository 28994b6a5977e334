"""Training learned lane detectors in plain PyTorch (the ``learn`` extra): models, data, losses, loop, ONNX export.

Inference lives in ``lanevil_core.detect.learned`` and runs the exported ONNX file, so nothing outside this
package imports torch.
"""
