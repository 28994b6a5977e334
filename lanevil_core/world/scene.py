"""The compiled scene: what the renderer draws, built once per case.

Data flows one way: ``Case`` (declarative) -> ``compile_scene`` (road surface, roadside props, illusions
-> meshes, surface layers, lights, environment) -> renderer.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from pydantic import BaseModel

from ..typed import Float32Array, FloatArray, IntArray

if TYPE_CHECKING:
    from ..camera import EgoPath
    from ..case import Case
    from .paint import RoadPaint
    from .road_layout import RoadNetwork

# Object ids in the per-pixel id buffer.
ID_SKY = 0
ID_ROAD = 1  # carriageway asphalt (any road piece)
ID_ROADSIDE = 2  # shoulders, kerbs, sidewalks, terrain
ID_EGO = 3  # the ego's own bonnet in view
FIRST_OBJECT_ID = 16


@dataclass
class Mesh:
    """A triangle mesh in the world frame, flat-shaded with one linear-RGB albedo per face.

    Attributes:
        vertices: (n, 3) float64 world positions.
        faces: (m, 3) int32 vertex indices, counter-clockwise seen from outside.
        colors: (m, 3) float32 linear albedo in [0, 1].
        name: human-readable name (shown in the editor and exports).
        kind: what it is (``building``, ``tree``, ``vehicle``, ``pedestrian``, ``pole`` ...).
        casts_shadow: whether it is drawn into the sun's shadow map.
        gloss: specular strength in [0, 1] (car paint ~0.6, metal ~0.4, matte 0).
        emission: (m, 3) float32 emitted linear radiance per face (lamps, headlights), or None.
        visible: drawn in the camera (False = shadow caster only, e.g. a structure above the view).
        source: the illusion index that added it, or -1 for the road and roadside.
        heading: world yaw (radians, counter-clockwise from +X) of a traffic participant's forward axis, set where it
            is placed (exports need it: a footprint's long axis cannot tell front from back, nor a person's facing).
        finish: (m,) int8 what a building face is made of (``facade.FINISHES`` index: plain, brick, render, panels,
            glass, shop glass), or None (all plain); the renderer draws its structure per pixel.
        uv: (n, 2) float32 facade coordinates of each vertex (m): along a wall and up it, or across a pane from its
            centre and up from its foot; or None. Read where ``finish`` is not plain.
    """

    vertices: FloatArray
    faces: IntArray
    colors: Float32Array
    name: str = "object"
    kind: str = "prop"
    casts_shadow: bool = True
    gloss: float = 0.0
    emission: Float32Array | None = None
    visible: bool = True
    source: int = -1
    heading: float | None = None
    finish: np.ndarray | None = None
    uv: Float32Array | None = None

    def __post_init__(self) -> None:
        self.vertices = np.ascontiguousarray(self.vertices, dtype=np.float64)
        self.faces = np.ascontiguousarray(self.faces, dtype=np.int32)
        colors = np.asarray(self.colors, dtype=np.float32)
        if colors.ndim == 1:
            colors = np.broadcast_to(colors, (len(self.faces), 3))
        self.colors = np.ascontiguousarray(colors)
        if self.emission is not None:
            emission = np.asarray(self.emission, dtype=np.float32)
            if emission.ndim == 1:
                emission = np.broadcast_to(emission, (len(self.faces), 3))
            self.emission = np.ascontiguousarray(emission)

    def renamed(self, name: str) -> Mesh:
        """The same mesh under another name."""
        return replace(self, name=name)


@dataclass
class SurfaceLayer:
    """A texture lying on a road piece's surface, addressed in that piece's road frame.

    Texel (row i, col j) covers s in [s0 + i*texel, s0 + (i+1)*texel), t in [t0 + j*texel, ...).

    Attributes:
        piece: index of the road piece (0 = main road).
        s0, t0: road-frame corner of texel (0, 0) (m).
        texel: texel size (m).
        rgba: (h, w, 4) float32: linear albedo and coverage alpha; blended over the asphalt.
        wet: (h, w) float32 puddle depth/coverage in [0, 1] (mirror-like water), or None.
        over_paint: drawn over lane paint (sealant, tire marks) instead of under it (cracks in the asphalt).
    """

    piece: int
    s0: float
    t0: float
    texel: float
    rgba: Float32Array
    wet: Float32Array | None = None
    over_paint: bool = False
    name: str = "layer"
    source: int = -1


@dataclass
class PointLight:
    """A lamp: position, linear RGB colour and intensity (radiance scale at 1 m), and how its light is spread
    (``beam``, one of ``BEAMS``): ``omni`` alike in every direction, ``street`` a full cut-off street lamp (its light
    falls downwards, nothing above about 80 degrees from the nadir, so a lamp lights a pool of road and the foot of
    the walls near it, not the houses and trees around it)."""

    p_world: FloatArray
    color: Float32Array
    intensity: float
    name: str = "lamp"
    source: int = -1
    beam: str = "omni"


# How a lamp spreads its light (``PointLight.beam``, the light table's beam column; ``low`` is the ego's low-beam
# headlights, which the renderer adds per frame).
BEAMS = ("omni", "street", "low")


@dataclass
class Environment:
    """Lighting and atmosphere, derived from the case's weather and sun (illusions may change it).

    ``sun_dir_world`` points from the ground towards the sun.
    """

    sun_dir_world: FloatArray
    sun_intensity: float  # direct sun irradiance scale (0 at night)
    sun_color: Float32Array
    sky_zenith: Float32Array
    sky_horizon: Float32Array
    ambient: float  # sky irradiance scale
    wetness: float  # road wetness in [0, 1]
    puddles: float  # puddle coverage in [0, 1]
    fog_density: float  # extinction per metre
    fog_distance: float  # fog starts here (m)
    cloudiness: float  # [0, 1]
    penumbra: float  # shadow softness in metres of blur at 1 m occluder distance
    exposure: float
    night: bool
    headlights: float = 0.0  # intensity of the ego's two headlights (0 = off)
    detail: float = 0.0  # surface texture a photograph shows (0 = the ideal render's smooth surfaces)
    sun_set_by: tuple[int, ...] = ()  # illusions (indices) that moved the sun or put out its light, in order


def array_bytes(root: Any) -> int:
    """Summed ``nbytes`` of the distinct numpy arrays reachable from ``root`` through dataclass fields, object
    attributes, lists, tuples and dicts (pydantic models, strings and numbers hold none worth counting)."""
    seen: set[int] = set()
    total, stack = 0, [root]
    while stack:
        item = stack.pop()
        if id(item) in seen or item is None or isinstance(item, (str, bytes, int, float, bool, BaseModel)):
            continue
        seen.add(id(item))
        if isinstance(item, np.ndarray):
            # A view of another array costs nothing beyond that array. Any other base owns the data: an array a
            # numba kernel returned has numba's MemInfo as its base (the crack and paint layers: 100s of MB).
            if isinstance(item.base, np.ndarray):
                stack.append(item.base)
            else:
                total += item.nbytes
        elif isinstance(item, dict):
            stack.extend(item.values())
        elif isinstance(item, (list, tuple, set, frozenset)):
            stack.extend(item)
        elif hasattr(item, "__dict__") or hasattr(item, "__slots__"):
            stack.extend(getattr(item, "__dict__", {}).values())
            stack.extend(getattr(item, name) for name in getattr(item, "__slots__", ()) if hasattr(item, name))
    return total


@dataclass
class CompiledScene:
    """Everything the renderer, the label generator and the exporters need for any frame of a case; they read
    nothing else of the case (``case`` is kept for the drive, the editor and recompiles)."""

    case: Case
    network: RoadNetwork
    env: Environment
    paint: RoadPaint  # the main road's markings and the paint switch
    ego: EgoPath  # the camera mount and the scripted drive
    meshes: list[Mesh] = field(default_factory=list)
    layers: list[SurfaceLayer] = field(default_factory=list)
    lights: list[PointLight] = field(default_factory=list)
    cache: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)  # renderer's packed arrays

    def nbytes(self) -> int:
        """Bytes of the numpy arrays the scene holds (meshes, layers, network, the renderer's packed cache): what
        keeping it in memory costs, for caches bounded by bytes."""
        return array_bytes([self.network, self.env, self.paint, self.ego, self.meshes, self.layers, self.lights,
                            self.cache])

    def object_names(self) -> dict[int, str]:
        """Object id (as in the id buffer) -> mesh name."""
        return {FIRST_OBJECT_ID + i: mesh.name for i, mesh in enumerate(self.meshes)}
