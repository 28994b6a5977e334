"""Every detector by name, the one resolution all entry points use: the built-in methods and the plug-ins.

Built-ins are ``detect.split.METHODS`` (six learned families, two classical baselines). Plug-ins
(``detect.plugin``'s contract) come from three places, read on every call so a change is picked up at once:

- the environment variable ``LANEVIL_DETECTORS``: ``NAME=SOURCE`` entries separated by ``;``, e.g.
  ``tusimple-laneatt=http://127.0.0.1:8500/detect;bdd-seg=onnx:models/bdd_seg.onnx``;
- the JSON file named by ``LANEVIL_DETECTORS_FILE``, which can set each detector's options::

      {"detectors": {"tusimple-laneatt": {"source": "http://127.0.0.1:8500/detect", "real_trained": true,
                                          "input_size": [1280, 720], "timeout_s": 10, "retries": 1,
                                          "concurrency": 1}}}

- the installed Python plug-ins of the entry-point group ``lanevil.detectors`` (``detect.plugin``);
- and, unless one of those takes the name, the model folders shipped beside the families' own
  (``learned.BUNDLED_MODELS``, the ``FAMILY-transfer`` models).

A SOURCE is ``http://HOST:PORT/PATH`` (or https: ``detect.http_detector``) or ``onnx:PATH`` (an ONNX model with a
sidecar: ``detect.onnx_detector``; or a model folder of ``lanevil train`` / ``lanevil adapt``, run as its family).
The command line also takes a SOURCE itself as a method
(``lanevil detect --method http://127.0.0.1:8500/detect``); the web app takes names only, so a request cannot make
the server call an address or open a file of the request's choosing. Names are 1-40 letters, digits, ``_``, ``.``
or ``-``; a built-in method's name, ``gt`` and ``none`` are taken.
"""

from __future__ import annotations

import os
import re
import threading
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, Literal

from ..files import read_json
from ..metrics.formats import LaneFileError
from .split import METHODS, Detector, builtin_detector

ENV_DETECTORS = "LANEVIL_DETECTORS"
ENV_DETECTORS_FILE = "LANEVIL_DETECTORS_FILE"
HTTP_PREFIXES = ("http://", "https://")
ONNX_PREFIX = "onnx:"
RESERVED_NAMES = ("gt", "none")  # the drive's projected ground truth, the editor's "no detector"
NAME_PATTERN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,39}")
PluginKind = Literal["http", "onnx", "plugin"]


@dataclass(frozen=True)
class PluginSpec:
    """A plug-in detector as configured.

    Attributes:
        name: the method name.
        kind: ``http``, ``onnx`` or ``plugin`` (an installed entry point).
        source: the URL, ``onnx:PATH``, or the entry point's ``module:object``.
        real_trained: trained on real roads (also read from an ONNX sidecar or a plug-in's attribute).
        input_size: (width, height) an HTTP detector's frames are resized to, or None.
        timeout_s, retries, concurrency: an HTTP detector's limits (``detect.http_detector``).
    """

    name: str
    kind: PluginKind
    source: str
    real_trained: bool = False
    input_size: tuple[int, int] | None = None
    timeout_s: float = 10.0
    retries: int = 1
    concurrency: int = 1


def is_source(text: str) -> bool:
    """Whether ``text`` is a detector SOURCE (a URL or ``onnx:PATH``) rather than a name."""
    return text.startswith((*HTTP_PREFIXES, ONNX_PREFIX))


def _source_kind(source: str, where: str) -> PluginKind:
    if source.startswith(HTTP_PREFIXES) and len(source) > len("https://"):
        return "http"
    if source.startswith(ONNX_PREFIX) and len(source) > len(ONNX_PREFIX):
        return "onnx"
    raise LaneFileError(f"{where}: {source!r} is not http://HOST:PORT/PATH or onnx:PATH")


def _checked_name(name: str, where: str) -> str:
    if not NAME_PATTERN.fullmatch(name):
        raise LaneFileError(f"{where}: the name {name!r} must be 1-40 letters, digits, '_', '.' or '-'")
    if name in METHODS or name in RESERVED_NAMES:
        raise LaneFileError(f"{where}: the name {name!r} is taken (a built-in method or {' / '.join(RESERVED_NAMES)})")
    return name


def source_spec(source: str, name: str | None = None, where: str = "--method", **options: Any) -> PluginSpec:
    """The spec of a SOURCE (named after itself unless ``name`` is given)."""
    return PluginSpec(name or source, _source_kind(source, where), source, **options)


def _file_specs(path: Path) -> list[PluginSpec]:
    where = f"{ENV_DETECTORS_FILE} {path}"
    data = read_json(path, where, LaneFileError)
    entries = data.get("detectors") if isinstance(data, dict) else None
    if not isinstance(entries, dict):
        raise LaneFileError(f"{where}: expected {{\"detectors\": {{NAME: {{\"source\": ...}}, ...}}}}")
    allowed = {field.name for field in fields(PluginSpec)} - {"name", "kind"}
    specs = []
    for name, entry in entries.items():
        at = f"{where}: detectors.{name}"
        if not isinstance(entry, dict) or not isinstance(entry.get("source"), str):
            raise LaneFileError(f"{at}: expected an object with a \"source\" string")
        unknown = sorted(set(entry) - allowed)
        if unknown:
            raise LaneFileError(f"{at}: unknown option {unknown[0]!r} (options: {', '.join(sorted(allowed))})")
        specs.append(source_spec(entry["source"], _checked_name(name, where), at, **_options(entry, at)))
    return specs


def _options(entry: dict[str, Any], where: str) -> dict[str, Any]:
    options: dict[str, Any] = {}
    if "real_trained" in entry:
        if not isinstance(entry["real_trained"], bool):
            raise LaneFileError(f"{where}: real_trained must be true or false")
        options["real_trained"] = entry["real_trained"]
    size = entry.get("input_size")
    if size is not None:
        if not (isinstance(size, list) and len(size) == 2 and all(isinstance(v, int) and 8 <= v <= 8192
                                                                   for v in size)):
            raise LaneFileError(f"{where}: input_size must be [width, height] in whole pixels (8 to 8192)")
        options["input_size"] = (size[0], size[1])
    for key, low, high, kind in (("timeout_s", 0.1, 600.0, float), ("retries", 0, 10, int),
                                 ("concurrency", 1, 64, int)):
        if key in entry:
            value = entry[key]
            if isinstance(value, bool) or not isinstance(value, int | float) or not low <= value <= high or \
                    (kind is int and not isinstance(value, int)):
                raise LaneFileError(f"{where}: {key} must be a{'n integer' if kind is int else ' number'} from "
                                    f"{low} to {high}")
            options[key] = kind(value)
    return options


def _env_specs(text: str) -> list[PluginSpec]:
    specs = []
    for entry in (part.strip() for part in text.split(";")):
        if not entry:
            continue
        name, sep, source = entry.partition("=")
        if not sep:
            raise LaneFileError(f"{ENV_DETECTORS}: {entry!r} is not NAME=SOURCE")
        specs.append(source_spec(source.strip(), _checked_name(name.strip(), ENV_DETECTORS), ENV_DETECTORS))
    return specs


def configured_specs() -> dict[str, PluginSpec]:
    """The detectors of ``LANEVIL_DETECTORS_FILE`` and ``LANEVIL_DETECTORS``, by name (raises ``LaneFileError`` for
    a malformed entry or a name given twice)."""
    specs: dict[str, PluginSpec] = {}
    file = os.environ.get(ENV_DETECTORS_FILE, "").strip()
    found = [*(_file_specs(Path(file)) if file else []), *_env_specs(os.environ.get(ENV_DETECTORS, ""))]
    for spec in found:
        if spec.name in specs:
            raise LaneFileError(f"{ENV_DETECTORS}: the detector {spec.name!r} is configured twice")
        specs[spec.name] = spec
    return specs


def bundled_specs() -> dict[str, PluginSpec]:
    """The model folders shipped beside the six families' (``learned.BUNDLED_MODELS``) that are present, by name:
    each an ``onnx:`` model folder, run as its family."""
    from .learned import BUNDLED_MODELS, SHIPPED_MODELS
    from .model_spec import ONNX_FILE

    return {name: PluginSpec(name, "onnx", f"{ONNX_PREFIX}{SHIPPED_MODELS / name}") for name in BUNDLED_MODELS
            if (SHIPPED_MODELS / name / ONNX_FILE).is_file()}


def plugin_specs() -> dict[str, PluginSpec]:
    """Every plug-in by name: the configured ones, then the bundled models and the installed entry points (a
    configured name wins; entry points with a taken or malformed name are left out)."""
    from .plugin import entry_points

    specs = configured_specs()
    for name, spec in bundled_specs().items():
        specs.setdefault(name, spec)
    for name, point in sorted(entry_points().items()):
        if name not in specs and name not in METHODS and name not in RESERVED_NAMES and NAME_PATTERN.fullmatch(name):
            specs[name] = PluginSpec(name, "plugin", point.value)
    return specs


def detector_names() -> tuple[str, ...]:
    """Every detector name: the built-in methods, then the plug-ins."""
    return (*METHODS, *plugin_specs())


def plugin_spec(name: str, sources: bool = False) -> PluginSpec | None:
    """The plug-in called ``name`` (None for a built-in method); with ``sources``, a SOURCE names itself. Raises
    ``LaneFileError`` (``detector: unknown detector ...``) for anything else."""
    if name in METHODS:
        return None
    if sources and is_source(name):
        return source_spec(name)
    spec = plugin_specs().get(name)
    if spec is None:
        hint = " or a source http://HOST:PORT/PATH, onnx:PATH" if sources else ""
        raise LaneFileError(f"detector: unknown detector {name!r} (choose from {', '.join(detector_names())}{hint})")
    return spec


def plugin_real_trained(spec: PluginSpec) -> bool:
    """Whether a plug-in is marked trained on real roads: in its configuration, or by the plug-in itself (an ONNX
    sidecar's ``real_trained``, a Python plug-in's attribute); loads it."""
    return spec.real_trained or bool(getattr(getattr(loaded_plugin(spec), "plugin", None), "real_trained", False))


_HTTP_CLIENTS: dict[PluginSpec, Any] = {}
_HTTP_LOCK = threading.Lock()


def _http(spec: PluginSpec) -> Any:
    """One client per spec, made under a lock: two callers never get two clients (and twice the concurrency)."""
    from .http_detector import HttpLaneDetector

    with _HTTP_LOCK:
        client = _HTTP_CLIENTS.get(spec)
        if client is None:
            client = _HTTP_CLIENTS[spec] = HttpLaneDetector(spec.name, spec.source, spec.input_size,
                                                            spec.real_trained, spec.timeout_s, spec.retries,
                                                            spec.concurrency)
        return client


def loaded_plugin(spec: PluginSpec) -> Any:
    """The ``PolylineDetector`` of a plug-in (one HTTP client per spec, so its concurrency limit is shared)."""
    from .plugin import PolylineDetector, plugin_detector

    if spec.kind == "http":
        return PolylineDetector(spec.name, _http(spec))
    if spec.kind == "onnx":
        from .onnx_detector import onnx_detector

        path = Path(spec.source.removeprefix(ONNX_PREFIX))
        if path.is_dir():  # a model folder of `lanevil train` or `lanevil adapt`: run as its family is
            from .learned import load_detector
            from .model_spec import ModelSpecError

            try:
                return load_detector(str(path.resolve()))
            except ModelSpecError as error:
                raise LaneFileError(f"detector: {spec.name}: {error}") from None
        return PolylineDetector(spec.name, onnx_detector(spec.name, path))
    return plugin_detector(spec.name)


def detector_for(method: str, weights: str | Path | None = None, sources: bool = True) -> Detector:
    """The detector called ``method``: a built-in (``weights``: a learned family's model folder) or a plug-in, or
    with ``sources`` a SOURCE. Raises ``LaneFileError`` for an unknown or unusable one."""
    spec = plugin_spec(method, sources)
    if spec is None:
        return builtin_detector(method, weights)
    if weights is not None:
        raise LaneFileError(f"--weights: the plug-in {method} has no weights folder")
    return loaded_plugin(spec)


PROBE_SIZE = (640, 360)  # a black frame posted once to tell whether an HTTP detector answers


def ready_detector(method: str, weights: str | Path | None = None, sources: bool = True) -> Detector:
    """``detector_for``, and an HTTP detector asked once (a black frame) so that a server that is down or answers
    nonsense is reported before a long run starts (raises ``LaneFileError``)."""
    detector = detector_for(method, weights, sources)
    spec = plugin_spec(method, sources)
    if spec is not None and spec.kind == "http":
        import numpy as np

        detector(np.zeros((PROBE_SIZE[1], PROBE_SIZE[0], 3), np.uint8), [PROBE_SIZE[1] - 1])
    return detector
