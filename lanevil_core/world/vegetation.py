"""Procedural low-poly vegetation: trees of several species and bushes, the greens of their leaves, their bark.

A tree is a spruce (a tapering trunk under ragged, drooping tiers of branches) or a broadleaf (``BROADLEAVES``: a
round crown, a pale slender birch, a columnar poplar) whose trunk forks into main branches (``_limb``) reaching into
a crown of irregular leaf clusters (``_crown``, ``_leaf_cluster``); a bush is a low heap of leaf clusters. Every
builder returns a ``Mesh`` in its own local frame: +X forward, +Y left, +Z up, origin on the ground at the foot of
the plant; ``scenery`` places them beside the road and ``backdrop`` takes its greens from ``LEAVES``. Dimensions are
real (metres); colours are linear albedo.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import trimesh

from ..typed import FloatArray, IntArray
from .facade import LEAVES as LEAVES_FINISH
from .primitives import ColorLike, loft, merge, pick, to_mesh, with_finish
from .scene import Mesh

# Linear albedos: the bark of most trees, and the greens of broadleaf leaves, spruce needles, bushes and the
# backdrop's woods.
BARK = (0.09, 0.055, 0.03)
LEAVES = ((0.045, 0.1, 0.035), (0.055, 0.115, 0.04), (0.035, 0.075, 0.035), (0.07, 0.115, 0.035), (0.05, 0.09, 0.045))


def tree(rng: np.random.Generator, *, conifer: bool | None = None, height: float | None = None, near: bool = True,
         name: str = "tree") -> Mesh:
    """A tree 4-14 m tall of one of several species: a spruce (a tapering trunk under ragged, drooping tiers of
    branches), or a broadleaf (``BROADLEAVES``: a round crown, a pale slender birch, a columnar poplar), whose
    trunk forks into main branches reaching into a crown of irregular leaf clusters (``_crown``). A tree that is
    not ``near`` (only ever seen from afar) has fewer clusters and no sprigs on them (``FAR_DETAIL``)."""
    conifer = bool(rng.random() < 0.35) if conifer is None else conifer
    height = float(rng.uniform(5.0, 11.0)) if height is None else height
    if conifer:
        return merge(_spruce(rng, height), name=name, kind="tree")
    species = BROADLEAVES[int(rng.choice(len(BROADLEAVES), p=BROADLEAF_SHARES))]
    return merge(_broadleaf(rng, height * species.tall, species, near), name=name, kind="tree")


@dataclass(frozen=True)
class Broadleaf:
    """What sets a broadleaf species apart: its crown's radius and its height as shares of the tree's height,
    its bark, its main branches and leaf clusters, the palette of its leaves, its trunk's girth and how much
    taller than the drawn height it grows."""

    crown: float
    crown_height: float
    bark: tuple[float, float, float]
    branches: tuple[int, int]
    clusters: tuple[int, int]
    leaves: tuple[tuple[float, float, float], ...]
    trunk: float = 1.0
    tall: float = 1.0


BROADLEAF_SHARES = (0.7, 0.15, 0.15)  # most roadside broadleaves have round crowns; birches and poplars are fewer
BROADLEAVES = (
    Broadleaf(crown=0.36, crown_height=0.66, bark=BARK, branches=(4, 5), clusters=(8, 10),
              leaves=LEAVES),  # oak, maple, lime
    Broadleaf(crown=0.25, crown_height=0.62, bark=(0.5, 0.48, 0.44), branches=(3, 4), clusters=(7, 9),
              leaves=((0.1, 0.14, 0.035), (0.11, 0.15, 0.05), (0.085, 0.13, 0.04)), trunk=0.6),  # birch
    Broadleaf(crown=0.13, crown_height=0.82, bark=(0.13, 0.11, 0.085), branches=(3, 4), clusters=(7, 8),
              leaves=((0.05, 0.09, 0.03), (0.06, 0.1, 0.035)), tall=1.3),  # Lombardy poplar
)
LEAF_SPRIGS = 4  # small tetrahedra sticking out of every leaf cluster: the twigs' leaves breaking its outline
FAR_DETAIL = 0.7  # the share of its clusters a tree only seen from afar keeps (and none of their sprigs)
CROWN_CLUSTERS = 9  # a crown of this many clusters has them at their drawn size
TREE_TINT = 0.15  # each tree's leaves are its species' green times 1 +- this, and a little warmer or cooler
SELF_SHADE = 0.5  # a cluster deep inside or under the crown is this much darker than one on its sunny top


def _broadleaf(rng: np.random.Generator, height: float, species: Broadleaf, near: bool = True) -> list[Mesh]:
    """Trunk, main branches forking from it into the crown, and the crown's leaf clusters (local frame, foot at
    the origin)."""
    radius = species.crown * height * float(rng.uniform(0.85, 1.1))
    crown_h = species.crown_height * height
    centre = np.array([0.0, 0.0, height - crown_h / 2])
    fork = height - crown_h * 0.9
    trunk_r = (0.06 + 0.02 * height) * species.trunk
    lean = rng.uniform(-0.04, 0.04, 2) * height  # trunks are seldom plumb
    top = np.array([lean[0], lean[1], fork])
    parts = [_limb((0.0, 0.0, -0.2), top, trunk_r, trunk_r * 0.8, 5, species.bark)]
    half = np.array([radius, radius, crown_h / 2])
    count = int(rng.integers(species.branches[0], species.branches[1] + 1))
    ends = []
    for k in range(count):  # main branches: up and out to the crown's middle shell
        angle = 2 * np.pi * (k + float(rng.uniform(-0.3, 0.3))) / count
        out, up = float(rng.uniform(0.45, 0.7)), float(rng.uniform(-0.2, 0.5))
        end = centre + half * (out * np.cos(angle), out * np.sin(angle), up)
        ends.append(end)
        parts.append(_limb(top, end, trunk_r * 0.6, trunk_r * 0.2, 3, species.bark))
    parts.append(_limb(top, centre + half * (0.0, 0.0, 0.55), trunk_r * 0.6, trunk_r * 0.2, 3, species.bark))
    clusters = int(rng.integers(species.clusters[0], species.clusters[1] + 1))
    parts += _crown(rng, centre, half, np.array(ends), _tree_green(rng, species.leaves),
                    clusters if near else int(np.ceil(clusters * FAR_DETAIL)), LEAF_SPRIGS if near else 0)
    return parts


def _crown(rng: np.random.Generator, centre: FloatArray, half: FloatArray, anchors: FloatArray, green: FloatArray,
           count: int, sprigs: int = 0) -> list[Mesh]:
    """``count`` irregular leaf clusters filling the ellipsoid crown of semi-axes ``half`` (3,) about ``centre``
    (3,): one at its heart, then one at each of the branches' ends ``anchors`` (k, 3), the rest towards its shell
    (a ragged silhouette); each darker the deeper inside or lower in the crown it sits (the leaves above and
    around shade it), each with ``sprigs`` sprigs (``_leaf_cluster``)."""
    n_free = max(count - len(anchors) - 1, 0)
    direction = rng.normal(size=(n_free, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    direction[:, 2] = np.abs(direction[:, 2]) * 0.2 + direction[:, 2] * 0.8  # a few more high, where light is
    depth = rng.uniform(0.45, 0.85, (n_free, 1))
    core = centre + half * (0.0, 0.0, 0.15)  # a heart cluster: the crown is one mass, not a ring of puffs
    centres = np.vstack([core, anchors, centre + direction * depth * half])[:count]
    rel = (centres - centre) / half  # where each sits in the crown: (0, 0, 0) its heart, |rel| 1 its shell
    out = np.linalg.norm(rel, axis=1)
    fill = (CROWN_CLUSTERS / count) ** (1.0 / 3.0)  # fewer clusters, each larger: the crown stays full
    sizes = np.min(half) * rng.uniform(0.42, 0.6, count) * fill * (1.25 - 0.35 * out)
    sizes = np.minimum(sizes, np.min(half) * (1.2 - 0.6 * np.clip(out, 0, 1)) + 0.1)
    sizes[0] = np.min(half) * 0.7 * fill
    light = 1.0 - SELF_SHADE * np.clip(0.55 - 0.35 * out - 0.35 * rel[:, 2], 0.0, 1.0)
    squash = (1.0, 1.0, 0.85 * float(np.clip(half[2] / half[0], 1.0, 2.0)))  # upright clusters in a tall crown
    return [_leaf_cluster(rng, float(size), c, squash, green * float(lit), sprigs)
            for size, c, lit in zip(sizes, centres, light)]


def _tree_green(rng: np.random.Generator, palette: tuple[tuple[float, float, float], ...]) -> FloatArray:
    """One tree's leaf green: a palette colour, brighter or darker and warmer or cooler than its neighbours'."""
    warm = float(rng.uniform(-1.0, 1.0)) * np.array([0.1, 0.0, -0.1])
    return pick(rng, palette) * float(rng.uniform(1.0 - TREE_TINT, 1.0 + TREE_TINT)) * (1.0 + warm)


def _limb(p0: ColorLike, p1: ColorLike, r0: float, r1: float, sides: int, color: ColorLike) -> Mesh:
    """A tapering trunk or branch from ``p0`` (radius ``r0``) to ``p1`` (radius ``r1``): a loft of two
    ``sides``-gons (``4 * sides - 4`` faces)."""
    p0, p1 = np.asarray(p0, np.float64), np.asarray(p1, np.float64)
    axis = (p1 - p0) / max(float(np.linalg.norm(p1 - p0)), 1e-9)
    u = np.cross(axis, (1.0, 0.0, 0.0) if abs(axis[0]) < 0.9 else (0.0, 1.0, 0.0))
    u /= np.linalg.norm(u)
    v = np.cross(axis, u)
    angle = 2 * np.pi * np.arange(sides) / sides
    ring = np.cos(angle)[:, None] * u + np.sin(angle)[:, None] * v
    return loft([p0 + r0 * ring, p1 + r1 * ring], color)


SPRUCE_TIERS = 7
SPRUCE_TIPS = 6  # branch tips round a tier: its rim zigzags out to them and back in between


def _spruce(rng: np.random.Generator, height: float) -> list[Mesh]:
    """A spruce or fir: a tapering trunk and tiers of drooping branches, each tier a ragged star-shaped cone whose
    tips reach out and dip below its top, narrowing up the tree to a spire; lower and inner tiers darker."""
    trunk_h = 0.12 * height
    base_r = 0.21 * height * float(rng.uniform(0.9, 1.1))
    parts = [_limb((0.0, 0.0, -0.2), (0.0, 0.0, height * 0.93), 0.08 + 0.014 * height, 0.04, 6, BARK)]
    green = _tree_green(rng, LEAVES) * 0.72
    n = 2 * SPRUCE_TIPS
    ring, nxt = np.arange(n), (np.arange(n) + 1) % n
    faces = np.concatenate([np.stack([ring, nxt, np.full(n, n)], 1), np.stack([nxt, ring, np.full(n, n + 1)], 1)])
    for i in range(SPRUCE_TIERS):
        share = i / SPRUCE_TIERS
        z_rim = trunk_h + share * (height - trunk_h) * 0.9
        r = base_r * (1.0 - share) ** 0.95 + 0.12
        angles = 2 * np.pi * (np.arange(n) + float(rng.uniform(0, 2)) + rng.uniform(-0.25, 0.25, n)) / n
        reach = r * np.where(ring % 2 == 0, rng.uniform(0.85, 1.15, n), rng.uniform(0.45, 0.65, n))
        droop = np.where(ring % 2 == 0, rng.uniform(0.12, 0.35, n), rng.uniform(0.0, 0.1, n)) * r
        rim = np.stack([reach * np.cos(angles), reach * np.sin(angles), z_rim - droop], 1)
        apex = np.array([0.0, 0.0, z_rim + 0.75 * r + 0.3])
        vertices = np.vstack([rim, apex, (0.0, 0.0, z_rim - 0.05 * r)])
        shade = 1.0 - 0.35 * (1.0 - share) + 0.15 * share  # the lower tiers stand in the upper ones' shade
        colors = _leaf_colors(green * shade, rng, len(faces))
        colors[n:] *= 1.0 - SELF_SHADE  # the tier's underside
        parts.append(with_finish(to_mesh(trimesh.Trimesh(vertices, faces, process=False), colors), LEAVES_FINISH))
    return parts


@lru_cache(maxsize=2)
def _unit_icosphere(subdivisions: int) -> tuple[FloatArray, IntArray]:
    """(vertices, faces) of the unit icosphere (read-only): every leaf cluster is a jittered copy."""
    tm = trimesh.creation.icosphere(subdivisions=subdivisions)
    vertices, faces = np.array(tm.vertices, np.float64), np.array(tm.faces, np.int32)
    vertices.setflags(write=False)
    faces.setflags(write=False)
    return vertices, faces


def _leaf_cluster(rng: np.random.Generator, size: float, centre: FloatArray, squash: tuple[float, float, float],
                  green: FloatArray, sprigs: int = LEAF_SPRIGS, subdivisions: int = 0) -> Mesh:
    """A clump of leaves: a jagged, squashed icosahedron (20 faces; subdivided, 80) whose corners reach in and out,
    with ``sprigs`` small tetrahedra turned every way sticking out of it (a ragged outline, facets catching
    the light at every angle); faces varied in shade, those facing down darker (the clump shades its underside)."""
    unit, faces = _unit_icosphere(subdivisions)
    scale = size * np.asarray(squash)
    core = unit * (1.0 + 0.3 * rng.uniform(-1.0, 1.0, (len(unit), 1))) * 0.8 * scale + centre
    where = rng.normal(size=(sprigs, 3))
    where = centre + where / np.linalg.norm(where, axis=1, keepdims=True) * 0.75 * scale
    turn = np.linalg.qr(rng.normal(size=(sprigs, 3, 3)))[0]  # a random orientation per sprig ...
    turn[:, :, 0] *= np.sign(np.linalg.det(turn))[:, None]  # ... a rotation, not a mirror: faces stay outward
    tips = (TETRAHEDRON @ turn.transpose(0, 2, 1)) * (size * rng.uniform(0.3, 0.45, (sprigs, 1, 1))) + where[:, None]
    vertices = np.vstack([core, tips.reshape(-1, 3)])
    tetra = (np.arange(sprigs)[:, None, None] * 4 + len(unit) + TETRAHEDRON_FACES).reshape(-1, 3)
    all_faces = np.vstack([faces, tetra]).astype(np.int32)
    p = vertices[all_faces]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    down = normal[:, 2] / np.maximum(np.linalg.norm(normal, axis=1), 1e-12)
    colors = _leaf_colors(green, rng, len(all_faces))
    colors *= (1.0 - 0.5 * SELF_SHADE * np.clip(-down, 0.0, 1.0))[:, None]
    return with_finish(Mesh(vertices, all_faces, colors.astype(np.float32)), LEAVES_FINISH)


TETRAHEDRON = np.array([(1.0, 1.0, 1.0), (1.0, -1.0, -1.0), (-1.0, 1.0, -1.0), (-1.0, -1.0, 1.0)]) / np.sqrt(3.0)
TETRAHEDRON_FACES = np.array([(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)], np.int32)


def bush(rng: np.random.Generator, *, radius: float | None = None, near: bool = True, name: str = "bush") -> Mesh:
    """A low shrub: three or four jagged leaf clusters heaped on the ground, the inner and lower ones darker (with
    sprigs when ``near``)."""
    radius = float(rng.uniform(0.6, 1.3)) if radius is None else radius
    height = radius * float(rng.uniform(0.8, 1.2))
    centre = np.array([0.0, 0.0, 0.45 * height])
    half = np.array([radius, radius, 0.55 * height])
    green = _tree_green(rng, LEAVES) * 0.85  # low in the shade of the grass and its neighbours
    clusters = _crown(rng, centre, half, np.zeros((0, 3)), green, int(rng.integers(3, 5)), LEAF_SPRIGS if near else 0)
    shrub = merge(clusters, name=name, kind="bush")
    shrub.vertices[:, 2] -= shrub.vertices[:, 2].min() + 0.05  # resting on the ground, not floating
    return shrub


def _leaf_colors(green: FloatArray, rng: np.random.Generator, m: int) -> FloatArray:
    """(m, 3) foliage colours around ``green``: shade and hue varied face by face (sunlit leaves yellower,
    inner ones darker and bluer) so flat shading reads as leaves."""
    shade = rng.uniform(0.65, 1.2, (m, 1))
    warm = rng.uniform(-1.0, 1.0, (m, 1)) * np.array([0.08, 0.0, -0.08])
    return np.clip(green * shade * (1.0 + warm), 0.0, 1.0)

