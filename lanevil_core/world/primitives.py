"""Small builders for flat-shaded ``Mesh`` objects: trimesh primitives, merging, posing on the road.

Props are built in a local frame (+X forward, +Y left, +Z up, origin on the ground) and moved into the world
with ``transformed(mesh, pose_on_road(line, s, t, yaw))``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from functools import lru_cache

import numpy as np
import numpy.typing as npt
import trimesh

from ..typed import Float32Array, FloatArray, IntArray
from .road_geometry import ReferenceLine
from .scene import Mesh

ColorLike = Sequence[float] | np.ndarray
PointsLike = npt.ArrayLike  # (n, k) coordinates: nested sequences or an array


def with_finish(mesh: Mesh, finish: int) -> Mesh:
    """``mesh`` with every face of ``finish`` (a ``facade.FINISHES`` index that needs no facade coordinates, such
    as ``LEAVES``)."""
    return dataclasses.replace(mesh, finish=np.full(len(mesh.faces), finish, np.int8),
                               uv=np.zeros((len(mesh.vertices), 2), np.float32))


def pick(rng: np.random.Generator, palette: Sequence[ColorLike]) -> FloatArray:
    """(3,) float64 colour of ``palette`` drawn uniformly by ``rng`` (one ``rng.integers`` draw)."""
    return np.asarray(palette[int(rng.integers(len(palette)))], np.float64)


def to_mesh(
    tm: trimesh.Trimesh,
    color: ColorLike,
    *,
    name: str = "object",
    kind: str = "prop",
    gloss: float = 0.0,
    emission: ColorLike | None = None,
    casts_shadow: bool = True,
) -> Mesh:
    """A ``Mesh`` from a trimesh: ``color`` (3,) or (m, 3) linear albedo; ``emission`` likewise or None."""
    return _mesh(np.array(tm.vertices, np.float64), np.array(tm.faces, np.int32), color, name=name, kind=kind,
                 gloss=gloss, emission=emission, casts_shadow=casts_shadow)


def _mesh(vertices: FloatArray, faces: IntArray, color: ColorLike, *, name: str = "object", kind: str = "prop",
          gloss: float = 0.0, emission: ColorLike | None = None, casts_shadow: bool = True) -> Mesh:
    """A ``Mesh`` of its own (n, 3) float64 ``vertices`` and (m, 3) int32 ``faces`` (see ``to_mesh``)."""
    m = len(faces)
    colors = np.broadcast_to(np.asarray(color, np.float32), (m, 3))
    emitted = None if emission is None else np.broadcast_to(np.asarray(emission, np.float32), (m, 3))
    return Mesh(vertices, faces, colors, name=name, kind=kind, casts_shadow=casts_shadow, gloss=gloss,
                emission=emitted)


def _key(values: PointsLike | None) -> tuple[float, ...] | None:
    """A hashable copy of a few coordinates (a cache key)."""
    return None if values is None else tuple(float(v) for v in np.asarray(values, np.float64).ravel())


@lru_cache(maxsize=1024)
def _box_arrays(extents: tuple[float, ...], center: tuple[float, ...]) -> tuple[FloatArray, IntArray]:
    """Vertices and faces of ``box`` (kept read-only: traffic builds the same few boxes for every vehicle)."""
    tm = trimesh.creation.box(extents=np.array(extents), transform=translation(center))
    return _frozen(tm)


@lru_cache(maxsize=1024)
def _cylinder_arrays(radius: float, height: float | None, center: tuple[float, ...],
                     segment: tuple[float, ...] | None, sections: int) -> tuple[FloatArray, IntArray]:
    """Vertices and faces of ``cylinder`` (kept read-only: every wheel of a vehicle type is the same)."""
    if segment is not None:
        tm = trimesh.creation.cylinder(radius=radius, segment=np.array(segment).reshape(2, 3), sections=sections)
    else:
        tm = trimesh.creation.cylinder(radius=radius, height=height, sections=sections,
                                       transform=translation(center))
    return _frozen(tm)


def _frozen(tm: trimesh.Trimesh) -> tuple[FloatArray, IntArray]:
    vertices, faces = np.array(tm.vertices, np.float64), np.array(tm.faces, np.int32)
    vertices.setflags(write=False)
    faces.setflags(write=False)
    return vertices, faces


def flat_trimesh(vertices: FloatArray, faces: IntArray, colors: Float32Array) -> trimesh.Trimesh:
    """A trimesh of (n, 3) ``vertices`` and (m, 3) ``faces`` with one (m, 3) linear colour per face, as 8-bit
    vertex colours (vertices unshared, so colours and normals stay flat); for the glTF scene and the editor."""
    p = np.asarray(vertices, np.float64)[faces].reshape(-1, 3)
    rgba = np.full((len(faces), 4), 255, np.uint8)
    rgba[:, :3] = np.clip(np.round(np.asarray(colors, np.float64) * 255.0), 0, 255).astype(np.uint8)
    return trimesh.Trimesh(vertices=p, faces=np.arange(len(p), dtype=np.int64).reshape(-1, 3),
                           vertex_colors=np.repeat(rgba, 3, axis=0), process=False)


def merge(meshes: Sequence[Mesh], name: str = "object", kind: str = "prop", gloss: float | None = None) -> Mesh:
    """One mesh from several, keeping per-face colours and emission (gloss: given, else the largest)."""
    if not meshes:
        raise ValueError("merge needs at least one mesh")
    offsets = np.cumsum([0] + [len(mesh.vertices) for mesh in meshes[:-1]])
    vertices = np.concatenate([mesh.vertices for mesh in meshes])
    faces = np.concatenate([mesh.faces + offset for mesh, offset in zip(meshes, offsets)])
    colors = np.concatenate([mesh.colors for mesh in meshes])
    emission = None
    if any(mesh.emission is not None for mesh in meshes):
        emission = np.concatenate([
            mesh.emission if mesh.emission is not None else np.zeros((len(mesh.faces), 3), np.float32)
            for mesh in meshes
        ])
    finish = uv = None
    if any(mesh.finish is not None for mesh in meshes):  # faces and vertices without a finish stay plain
        finish = np.concatenate([mesh.finish if mesh.finish is not None else np.zeros(len(mesh.faces), np.int8)
                                 for mesh in meshes])
        uv = np.concatenate([mesh.uv if mesh.uv is not None else np.zeros((len(mesh.vertices), 2), np.float32)
                             for mesh in meshes])
    return Mesh(vertices, faces, colors, name=name, kind=kind, gloss=max(m.gloss for m in meshes) if gloss is None
                else gloss, emission=emission, casts_shadow=any(mesh.casts_shadow for mesh in meshes), finish=finish,
                uv=uv)


def transformed(mesh: Mesh, T_world_local: FloatArray) -> Mesh:
    """A copy of ``mesh`` with its vertices mapped by the (4, 4) rigid transform ``T_world_local``."""
    p_world = mesh.vertices @ T_world_local[:3, :3].T + T_world_local[:3, 3]
    emission = None if mesh.emission is None else mesh.emission.copy()
    # A mirroring transform flips the winding; keep faces counter-clockwise from outside.
    faces = mesh.faces[:, ::-1] if np.linalg.det(T_world_local[:3, :3]) < 0 else mesh.faces
    return Mesh(p_world, faces.copy(), mesh.colors.copy(), name=mesh.name, kind=mesh.kind,
                casts_shadow=mesh.casts_shadow, gloss=mesh.gloss, emission=emission, visible=mesh.visible,
                source=mesh.source, finish=mesh.finish, uv=mesh.uv)


def translation(offset: ColorLike) -> FloatArray:
    """(4, 4) transform that moves by ``offset`` (3,)."""
    T = np.eye(4)
    T[:3, 3] = offset
    return T


def rotation_z(angle: float) -> FloatArray:
    """(4, 4) rotation by ``angle`` radians about +Z."""
    c, s = np.cos(angle), np.sin(angle)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    return T


def box(extents: ColorLike, center: ColorLike = (0.0, 0.0, 0.0), color: ColorLike = (0.2, 0.2, 0.2), **kw) -> Mesh:
    """An axis-aligned box (12 faces) with full ``extents`` (3,) centred at ``center`` (3,)."""
    vertices, faces = _box_arrays(_key(extents), _key(center))
    return _mesh(vertices.copy(), faces.copy(), color, **kw)


def cylinder(
    radius: float,
    height: float | None = None,
    center: ColorLike = (0.0, 0.0, 0.0),
    color: ColorLike = (0.2, 0.2, 0.2),
    *,
    segment: PointsLike | None = None,
    sections: int = 10,
    **kw,
) -> Mesh:
    """A closed cylinder: along +Z of ``height`` centred at ``center``, or along ``segment`` (2, 3) end to end."""
    if segment is None and height is None:
        raise ValueError("cylinder needs a height or a segment")
    vertices, faces = _cylinder_arrays(float(radius), None if height is None else float(height), _key(center),
                                       _key(segment), sections)
    return _mesh(vertices.copy(), faces.copy(), color, **kw)


def prism(profile: PointsLike, lo: float, hi: float, color: ColorLike = (0.2, 0.2, 0.2), *, axis: str = "y",
          inset: PointsLike | None = None, **kw) -> Mesh:
    """A closed prism: the convex polygon ``profile`` (k, 2) extruded from ``lo`` to ``hi`` along ``axis``.

    ``axis="y"``: profile points are (x, z); ``axis="x"``: profile points are (y, z). ``inset`` (k,): how far each
    profile point is drawn in from both ends (a car body's rounded shoulders, a cabin's sides leaning in).
    """
    profile = np.asarray(profile, np.float64)
    k = len(profile)
    pulled = np.zeros(k) if inset is None else np.asarray(inset, np.float64)
    ring = np.concatenate([_lift(profile, lo, axis), _lift(profile, hi, axis)])
    ring[:, 1 if axis == "y" else 0] += np.concatenate([pulled, -pulled]) * np.sign(hi - lo)
    sides = [[i, (i + 1) % k, k + (i + 1) % k] for i in range(k)] + [[i, k + (i + 1) % k, k + i] for i in range(k)]
    caps = [[0, i + 1, i] for i in range(1, k - 1)] + [[k, k + i, k + i + 1] for i in range(1, k - 1)]
    faces = np.array(sides + caps, np.int32)
    if _signed_volume(ring, faces) < 0:
        faces = faces[:, ::-1]
    return to_mesh(trimesh.Trimesh(ring, faces, process=False), color, **kw)


def _lift(profile: FloatArray, value: float, axis: str) -> FloatArray:
    """(k, 2) profile -> (k, 3) points at ``value`` along ``axis``."""
    along = np.full(len(profile), value)
    if axis == "y":
        return np.stack([profile[:, 0], along, profile[:, 1]], axis=1)
    if axis == "x":
        return np.stack([along, profile[:, 0], profile[:, 1]], axis=1)
    raise ValueError(f"axis must be 'x' or 'y', got {axis!r}")


def _signed_volume(vertices: FloatArray, faces: np.ndarray) -> float:
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def quad(corners: PointsLike, color: ColorLike = (0.2, 0.2, 0.2), **kw) -> Mesh:
    """A one-sided panel (2 faces) over the (4, 3) ``corners``, counter-clockwise seen from its front."""
    corners = np.asarray(corners, np.float64)
    return to_mesh(trimesh.Trimesh(corners, [[0, 1, 2], [0, 2, 3]], process=False), color, **kw)


def facing_quad(corners: PointsLike, outward: ColorLike, color: ColorLike, **kw) -> Mesh:
    """A one-sided quad over (4, 3) ``corners`` (in order around it) facing ``outward`` (3,)."""
    corners = np.asarray(corners, np.float64)
    normal = np.cross(corners[1] - corners[0], corners[2] - corners[0])
    if np.dot(normal, outward) < 0:
        corners = corners[::-1]
    return quad(corners, color, **kw)


def beam(p0: ColorLike, p1: ColorLike, width: float, depth: float | None = None,
         color: ColorLike = (0.2, 0.2, 0.2), **kw) -> Mesh:
    """A box of cross-section ``width`` x ``depth`` running from ``p0`` to ``p1`` (both (3,))."""
    p0, p1 = np.asarray(p0, np.float64), np.asarray(p1, np.float64)
    axis = p1 - p0
    length = float(np.linalg.norm(axis))
    T = np.eye(4)
    T[:3, :3] = trimesh.geometry.align_vectors([0.0, 0.0, 1.0], axis / max(length, 1e-9))[:3, :3]
    T[:3, 3] = 0.5 * (p0 + p1)
    tm = trimesh.creation.box(extents=(width, width if depth is None else depth, length), transform=T)
    return to_mesh(tm, color, **kw)


def loft(rings: PointsLike, color: ColorLike = (0.2, 0.2, 0.2), **kw) -> Mesh:
    """A closed solid through ``rings`` (n, k, 3): n >= 2 convex rings of k corresponding points, joined by
    quads and closed by fans at both ends."""
    rings = np.asarray(rings, np.float64)
    n, k = rings.shape[:2]
    ring, nxt = np.arange(k), (np.arange(k) + 1) % k
    sides = [np.stack([i * k + ring, i * k + nxt, (i + 1) * k + nxt], 1) for i in range(n - 1)]
    sides += [np.stack([i * k + ring, (i + 1) * k + nxt, (i + 1) * k + ring], 1) for i in range(n - 1)]
    fan = np.arange(1, k - 1)
    caps = [np.stack([np.zeros_like(fan), fan + 1, fan], 1),
            np.stack([np.zeros_like(fan), fan, fan + 1], 1) + (n - 1) * k]
    faces = np.concatenate(sides + caps).astype(np.int32)
    vertices = rings.reshape(-1, 3)
    if _signed_volume(vertices, faces) < 0:
        faces = faces[:, ::-1]
    return to_mesh(trimesh.Trimesh(vertices, faces, process=False), color, **kw)


def swept(line: ReferenceLine, s_road: PointsLike, profile_th: PointsLike, color: ColorLike = (0.2, 0.2, 0.2),
          **kw) -> Mesh:
    """A closed solid following the road: the convex (k, 2) cross-section ``profile_th`` ((t, h) road-frame
    points, h above the road surface) swept through the increasing stations ``s_road`` (n,)."""
    s_road = np.asarray(s_road, np.float64)
    profile = np.asarray(profile_th, np.float64)
    n, k = len(s_road), len(profile)
    p_world = line.to_world(np.repeat(s_road, k), np.tile(profile[:, 0], n), np.tile(profile[:, 1], n))
    return loft(p_world.reshape(n, k, 3), color, **kw)


def pose_on_road(line: ReferenceLine, s: float, t: float, yaw: float = 0.0, h: float = 0.0) -> FloatArray:
    """(4, 4) ``T_world_local`` of a prop standing on the road frame point (s, t), raised by ``h``.

    Local frame: +X along the horizontal road heading at ``s`` turned by ``yaw`` (radians, left positive),
    +Y to its left, +Z straight up; origin on the road surface at (s, t).
    """
    heading = float(line.heading_at(s)) + yaw
    T = rotation_z(heading)
    T[:3, 3] = line.to_world(s, t, h)
    return T
