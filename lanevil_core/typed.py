"""Array aliases and choice types shared across the library.

Shapes are written in docstrings as ``(n, 3) float64``; these aliases name the dtype.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
Float32Array = npt.NDArray[np.float32]
IntArray = npt.NDArray[np.int32]
Int64Array = npt.NDArray[np.int64]
IndexArray = npt.NDArray[np.intp]
UInt8Array = npt.NDArray[np.uint8]
BoolArray = npt.NDArray[np.bool_]

RoadType = Literal["straight", "bend", "s_curve", "uphill", "downhill", "t_junction", "crossroad"]
ROAD_TYPES: tuple[RoadType, ...] = (
    "straight", "bend", "s_curve", "uphill", "downhill", "t_junction", "crossroad",
)

LineType = Literal[
    "white_solid",
    "white_dashed",
    "white_double_solid",
    "yellow_solid",
    "yellow_dashed",
    "yellow_double_solid",
    "white_solid_dashed",
    "yellow_solid_dashed",
    "botts_dots",
    "none",
]
LINE_TYPES: tuple[LineType, ...] = (
    "white_solid", "white_dashed", "white_double_solid",
    "yellow_solid", "yellow_dashed", "yellow_double_solid",
    "white_solid_dashed", "yellow_solid_dashed", "botts_dots", "none",
)

# A country's and road class's marking standard (``world/marking_standards.py``); ``custom``: each marking's own.
MarkingStandardName = Literal[
    "custom", "us_mutcd", "de_autobahn", "de_urban", "cn_fast", "cn_slow", "jp_expressway", "jp_general",
]
MARKING_STANDARD_NAMES: tuple[MarkingStandardName, ...] = (
    "custom", "us_mutcd", "de_autobahn", "de_urban", "cn_fast", "cn_slow", "jp_expressway", "jp_general",
)

SceneKind = Literal["urban", "suburban", "highway", "rural", "tunnel_approach"]
SCENE_KINDS: tuple[SceneKind, ...] = ("urban", "suburban", "highway", "rural", "tunnel_approach")

Turn = Literal["left", "right"]

# Surface materials of the road cross-section (index = material id in the renderer). ``slab`` is a carriageway of
# jointed concrete slabs (a concrete road or bridge deck); ``concrete`` is a sidewalk's or verge's.
Material = Literal["asphalt", "concrete", "grass", "gravel", "kerb", "dirt", "slab"]
MATERIALS: tuple[Material, ...] = ("asphalt", "concrete", "grass", "gravel", "kerb", "dirt", "slab")

# What the carriageway is paved with.
Pavement = Literal["asphalt", "concrete"]
PAVEMENTS: tuple[Pavement, ...] = ("asphalt", "concrete")
