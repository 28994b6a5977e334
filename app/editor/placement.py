"""Where a click lands on the road, in road coordinates, and what that means for an illusion's fields.

Pure functions over numpy arrays. A click in the 3D view arrives as a ray in the world frame (+Z up); it is
intersected with the swept road surface (``lanevil_core.world.road_mesh.road_surface``) and the hit is expressed in the
main road's frame: ``s_road`` along the reference line, ``t_road`` to its left (both metres). An illusion stores its
position as ``s`` (every type) and, where the type has them, ``side`` (left/right of the road) and ``offset``
(lateral distance beyond the paved edge).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, get_args

import numpy as np
from pydantic import BaseModel

from lanevil_core.case import Case
from lanevil_core.illusions import Illusion
from lanevil_core.illusions.shadow import roadside_t
from lanevil_core.pipeline.compile import ego_drive
from lanevil_core.typed import FloatArray
from lanevil_core.world.road_geometry import ReferenceLine
from lanevil_core.world.road_layout import RoadNetwork
from lanevil_core.world.road_mesh import RoadSurface

EDGE_EPS = 1e-9  # barycentric slack, so a ray through an edge between two faces hits one of them
RAY_EPS = 1e-9


@dataclass(frozen=True)
class RoadHit:
    """Where a ray meets the road surface.

    Attributes:
        p_world: (3,) hit point.
        s_road, t_road: road-frame coordinates in the hit road piece (m).
        piece: road piece index (0 = main road, others junction arms).
        distance: ray parameter of the hit (m along a unit direction).
    """

    p_world: FloatArray
    s_road: float
    t_road: float
    piece: int
    distance: float


def ray_surface_hit(surface: RoadSurface, ray_origin_world: FloatArray, ray_dir_world: FloatArray,
                    main_line: ReferenceLine | None = None) -> RoadHit | None:
    """The nearest intersection of a ray with the road surface mesh, or None if the ray misses it.

    Möller–Trumbore over every face at once; (s, t) is interpolated from the hit face's vertices, then, on the main
    road when ``main_line`` is given, solved exactly from the hit point (flat triangles chord a bend's arcs).
    """
    origin = np.asarray(ray_origin_world, np.float64)
    direction = np.asarray(ray_dir_world, np.float64)
    direction = direction / np.linalg.norm(direction)
    tri = surface.vertices[surface.faces]  # (m, 3, 3)
    edge1, edge2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    p_vec = np.cross(direction, edge2)
    det = np.einsum("ij,ij->i", edge1, p_vec)
    ok = np.abs(det) > RAY_EPS
    inv_det = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    t_vec = origin - tri[:, 0]
    u = np.einsum("ij,ij->i", t_vec, p_vec) * inv_det
    q_vec = np.cross(t_vec, edge1)
    v = (q_vec @ direction) * inv_det
    dist = np.einsum("ij,ij->i", edge2, q_vec) * inv_det
    hit = ok & (u >= -EDGE_EPS) & (v >= -EDGE_EPS) & (u + v <= 1 + EDGE_EPS) & (dist > 0)  # shared edges count
    if not hit.any():
        return None
    face = int(np.flatnonzero(hit)[np.argmin(dist[hit])])
    corners = surface.faces[face]
    weights = np.array([1.0 - u[face] - v[face], u[face], v[face]])
    s_road, t_road = weights @ surface.st[corners]
    p_world = origin + dist[face] * direction
    piece = int(surface.piece[corners[0]])
    if main_line is not None and piece == 0:
        s_exact, t_exact, _h = road_coordinates(main_line, p_world)
        s_road, t_road = s_exact[0], t_exact[0]
    return RoadHit(p_world=p_world, s_road=float(s_road), t_road=float(t_road), piece=piece,
                   distance=float(dist[face]))


def road_coordinates(line: ReferenceLine, p_world: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """World points (n, 3) -> (s_road, t_road, h_road), each (n,), in ``line``'s road frame
    (``ReferenceLine.road_coordinates``)."""
    return line.road_coordinates(p_world)


def _literal_options(model: type[Illusion], name: str) -> tuple[Any, ...]:
    annotation = model.model_fields[name].annotation
    return tuple(get_args(annotation))


def field_bounds(model: type[BaseModel], name: str) -> tuple[float, float]:
    """(low, high) of a numeric field from its ge/gt/le/lt constraints (infinite where unbounded)."""
    low, high = -np.inf, np.inf
    for meta in model.model_fields[name].metadata:
        for attr in ("ge", "gt"):
            if getattr(meta, attr, None) is not None:
                low = max(low, float(getattr(meta, attr)))
        for attr in ("le", "lt"):
            if getattr(meta, attr, None) is not None:
                high = min(high, float(getattr(meta, attr)))
    return low, high


def placement_fields(model: type[Illusion], network: RoadNetwork, s_road: float, t_road: float,
                     current: Illusion | None = None) -> dict[str, Any]:
    """The fields of an illusion of type ``model`` that put it at (s_road, t_road) on the main road.

    ``s`` always; ``side`` (left for t > 0) where the type has a left/right side and is not set to "both";
    ``offset`` beyond the paved edge where the type has one and the point lies beyond that edge.
    """
    piece = network.main
    fields: dict[str, Any] = {"s": round(float(np.clip(s_road, 0.0, piece.line.length)), 2)}
    names = model.model_fields
    if "side" in names and {"left", "right"} <= set(_literal_options(model, "side")):
        if current is None or getattr(current, "side", None) != "both":
            fields["side"] = "left" if t_road > 0 else "right"
    if "offset" in names:
        paved = roadside_t(piece, 0.0, 1.0)
        if abs(t_road) > paved:
            low, high = field_bounds(model, "offset")
            fields["offset"] = round(float(np.clip(abs(t_road) - paved, low, high)), 2)
    return fields


def anchor_road(illusion: Illusion, case: Case, network: RoadNetwork) -> tuple[float, float]:
    """(s_road, t_road) where the editor draws an illusion's handle: its start along the road and, for types
    standing on one side, that side's edge (plus its offset); otherwise the ego's lane centre."""
    first_s = getattr(illusion, "first_s", None)
    drive = ego_drive(case)
    s_road = float(first_s(drive) if callable(first_s) else illusion.start_s(drive))
    side = getattr(illusion, "side", None)
    if side in ("left", "right"):
        sign = 1.0 if side == "left" else -1.0
        offset = getattr(illusion, "offset", None)
        t_road = roadside_t(network.main, float(offset or 0.0), sign)
    else:
        t_road = network.lane_center_t(case.ego.lane)
    return s_road, float(t_road)
