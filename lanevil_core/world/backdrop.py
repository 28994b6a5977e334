"""The backdrop beyond the roadside: distant hills, tree lines and hedgerows, the roofs and trees massing behind a
suburb's first row of houses, and the wooded ridge a tunnel enters.

A road photograph outside town nearly always shows, beyond the verge, rising ground and continuous vegetation; a
flat plain running to an empty horizon reads as a game. Everything here is a few large triangles (the renderer's
leaf-clump texture and aerial perspective do the rest), drawn from its own generator so it never moves a prop.
Distant hills stand beyond every road point; the tree lines and hedgerows keep clear of every road corridor,
beyond the props' setbacks, so nothing here touches the carriageway, its lanes or what the illusions place.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from ..typed import FloatArray
from . import buildings, props
from .facade import BRICK, RENDER, wall_finish
from .facade import LEAVES as LEAVES_FINISH
from .primitives import merge, pick, pose_on_road, transformed, with_finish
from .road_layout import RoadNetwork, RoadPiece
from .scene import Mesh
from .scenery import Clearance, RoadsideInputs, corridor_half_width, ground_h, own_rng
from .vegetation import LEAVES, tree

MAX_HILL_ELEVATION_DEG = 3.0  # the distant hills' crest seen from any point of the road, 1.5 m above it
HILL_MARGIN_M = 350.0  # the nearest ring of hills stands this far beyond the farthest road point from its centre
HILL_MIN_RADIUS_M = 650.0
FAR_RING = 1.7  # the second ring's radius over the first's
VALLEY_SHARE = 0.45  # hills fall to this share of their height where the main road heads (it runs up a valley)
VALLEY_HALF_WIDTH = np.radians(14.0)
CAMERA_HEIGHT_M = 1.5  # the eye the elevation limit is kept for
VIEW_HALF_ANGLE = np.radians(80.0)  # the widest camera's half field of view, and some
FOREST = ((0.05, 0.085, 0.035), (0.065, 0.1, 0.04), (0.045, 0.075, 0.04), (0.07, 0.09, 0.04))
FIELDS = ((0.11, 0.13, 0.05), (0.16, 0.14, 0.07), (0.08, 0.11, 0.04), (0.13, 0.12, 0.06))
UNDERSTOREY = 0.45  # the shade under a forest edge's canopy, as a share of its leaves' colour
CANOPY_SHADES = (UNDERSTOREY, 1.0, 1.05)  # understorey, crowns, their tops
CROWN_DOME = 0.9  # a crown's dome: its height over its radius
NEIGHBOUR_SPREAD = (0.9, 1.05)  # a crown's height over its stand's: a ragged top, no cliff between neighbours
EMERGENT_SHARE = 0.1  # the crowns that rise well above their neighbours
TAPER_M = 12.0  # a line of vegetation thins out over this length at its ends
DRIVE_AHEAD_M = 600.0  # tree lines stand along the main road from behind the ego's start to this far beyond its end
DRIVE_BEHIND_M = 40.0


@dataclass(frozen=True)
class Vegetation:
    """One kind of line of vegetation along a road: how far beyond the corridor it stands (min, max m), its
    crowns' height (min, max m) and radius (min, max m), the share of the road it lines at density 1 and its
    stretches' length (min, max m)."""

    setback: tuple[float, float]
    height: tuple[float, float]
    crown: tuple[float, float]
    cover: float
    stretch: tuple[float, float]
    name: str


TREE_LINE = Vegetation((50.0, 140.0), (8.0, 14.0), (3.0, 5.5), 0.55, (60.0, 260.0), "tree line")
FAR_WOOD = Vegetation((150.0, 230.0), (12.0, 20.0), (3.0, 6.0), 0.7, (120.0, 400.0), "wood")
HEDGEROW = Vegetation((32.0, 60.0), (1.6, 3.2), (1.0, 2.2), 0.5, (40.0, 160.0), "hedgerow")
SUBURB_BEHIND = Vegetation((26.0, 42.0), (7.0, 13.0), (2.5, 4.5), 0.6, (30.0, 110.0), "houses behind")
SUBURB_AHEAD_M = 250.0  # the houses behind the first row stand along the main road this far beyond the ego's end
HOUSE_SHARE = 0.6  # of what stands behind a suburb's first row, the houses (the rest garden trees)


def periodic_noise(rng: np.random.Generator, theta: FloatArray, octaves: int = 5, base: int = 3) -> FloatArray:
    """(n,) smooth noise in about [-1, 1] around the circle at angles ``theta`` (n,): sums of sines of whole
    frequencies, each octave twice as fast and half as strong as the last (so it closes on itself)."""
    out = np.zeros_like(theta)
    total = 0.0
    for octave in range(octaves):
        amplitude = 0.5 ** octave
        for freq in base * 2 ** octave + rng.integers(0, base * 2 ** octave, 2):
            out += amplitude * np.sin(freq * theta + rng.uniform(0, 2 * np.pi))
            total += amplitude
    return out / (0.5 * total)


def road_points(network: RoadNetwork) -> FloatArray:
    """(n, 3) every 10 m of every piece's reference line, with its edges (world)."""
    rows = []
    for piece in network.pieces:
        s = np.append(np.arange(piece.s_start, piece.line.length, 10.0), piece.line.length)
        reach = corridor_half_width(piece)
        rows += [piece.line.to_world(s, t) for t in (-reach, 0.0, reach)]
    return np.concatenate(rows)


def patches(noise: FloatArray, palette: tuple[tuple[float, float, float], ...]) -> FloatArray:
    """(n, 3) colours of ``palette`` in patches: smooth ``noise`` (n,) (about [-1, 1]) cut into as many bands."""
    k = np.clip(((noise + 1.0) / 2.0 * len(palette)).astype(int), 0, len(palette) - 1)
    return np.asarray(palette)[k]


def view_sector(inputs: RoadsideInputs, network: RoadNetwork) -> tuple[float, float]:
    """(first, last) bearing (radians, increasing) the ego's camera can see along its drive: the main road's
    headings from its start to DRIVE_AHEAD_M beyond its end, VIEW_HALF_ANGLE to either side."""
    line = network.main.line
    s0, s1 = drive_window(inputs, 0, network.main)
    heading = np.unwrap(line.heading_at(np.linspace(s0, s1, 64)))
    return float(heading.min()) - VIEW_HALF_ANGLE, float(heading.max()) + VIEW_HALF_ANGLE


def hill_ring(network: RoadNetwork, sector: tuple[float, float], rng: np.random.Generator, scale: float,
              max_deg: float, step_deg: float, colors: tuple[tuple[float, float, float], ...], name: str,
              shoulder: bool = True) -> Mesh:
    """An arc of hills over the bearings of ``sector`` around the road network, ``scale`` times the nearest
    ring's radius, its crest at most ``max_deg`` above the horizontal seen from any road point 1.5 m up: every
    ``step_deg`` a quad from a foot sunk below the land up to a ``shoulder`` and one up to the crest (or one
    straight up to the crest), facing the road."""
    p_road = road_points(network)
    centre = 0.5 * (p_road[:, :2].min(0) + p_road[:, :2].max(0))
    radius = scale * max(HILL_MIN_RADIUS_M, float(np.linalg.norm(p_road[:, :2] - centre, axis=1).max())
                         + HILL_MARGIN_M)
    theta = np.arange(sector[0], sector[1] + 1e-9, np.radians(step_deg))
    around = np.stack([np.cos(theta), np.sin(theta)], 1)
    shape = np.clip(0.5 + 0.5 * periodic_noise(rng, theta), 0.12, 1.0)  # the crest's share of the allowed height
    heading = float(network.main.line.heading[0])
    for ahead in (heading, heading + np.pi):  # the road runs up a valley: lower hills where it heads
        off = np.angle(np.exp(1j * (theta - ahead)))
        shape *= 1.0 - (1.0 - VALLEY_SHARE) * np.exp(-0.5 * (off / VALLEY_HALF_WIDTH) ** 2)
    level = _land_level(p_road, centre, theta)
    foot = np.column_stack([centre + around * radius, level - 0.02 * radius])  # below the horizon from the road
    crest_xy = centre + around * radius * 1.1
    nearest = np.sqrt(((crest_xy[:, None] - p_road[None, :, :2]) ** 2).sum(-1)).min(1)
    top = np.maximum(p_road[:, 2].min() + CAMERA_HEIGHT_M + shape * np.tan(np.radians(max_deg)) * nearest,
                     level + 4.0)
    rows = [foot]
    if shoulder:  # a shoulder part way up, its own height: slopes facing several ways, lit unevenly
        share = 0.45 + 0.25 * periodic_noise(rng, theta, octaves=3, base=6)
        rows.append(np.column_stack([centre + around * radius * 1.05, level + share * (top - level)]))
    rows.append(np.column_stack([crest_xy, top]))
    vertices = np.concatenate(rows)
    faces = _ribbon_faces(len(theta), len(rows), closed=False)
    tone = patches(periodic_noise(rng, theta, octaves=3, base=10), colors)[:-1]
    mesh_colors = np.tile(tone, (2 * (len(rows) - 1), 1)) * rng.uniform(0.94, 1.06, (len(faces), 1))
    towards = np.column_stack([np.tile(-around, (len(rows), 1)), np.zeros(len(vertices))])[faces[:, 0]]
    return Mesh(vertices, facing(vertices, faces, towards), mesh_colors.astype(np.float32), name=name,
                kind="terrain", casts_shadow=False)


def _land_level(p_road: FloatArray, centre: FloatArray, theta: FloatArray) -> FloatArray:
    """(n,) the land's height under the hills at angles ``theta``: the road's height where it heads that way
    (its highest point in a 30 degree sector), else the lowest road point."""
    bearing = np.arctan2(p_road[:, 1] - centre[1], p_road[:, 0] - centre[0])
    near = np.linalg.norm(p_road[:, :2] - centre, axis=1) > 20.0
    level = np.full(theta.shape, float(p_road[:, 2].min()))
    for k, angle in enumerate(theta):
        sector = near & (np.abs(np.angle(np.exp(1j * (bearing - angle)))) < np.radians(15.0))
        if sector.any():
            level[k] = max(level[k], float(p_road[sector, 2].max()))
    return level


def _ribbon_faces(n: int, rows: int, closed: bool) -> np.ndarray:
    """(2 * m * (rows - 1), 3) faces of a grid of ``rows`` rows of ``n`` vertices (row-major), m = n columns
    (closed: the last joins the first) or n - 1, counter-clockwise seen from the side the rows rise towards."""
    cols = np.arange(n if closed else n - 1)
    nxt = (cols + 1) % n
    faces = []
    for row in range(rows - 1):
        a, b = row * n + cols, row * n + nxt
        c, d = a + n, b + n
        faces += [np.stack([a, c, b], 1), np.stack([b, c, d], 1)]
    return np.concatenate(faces).astype(np.int32)


def crown_tops(s: FloatArray, rng: np.random.Generator, height: tuple[float, float],
               crown: tuple[float, float]) -> FloatArray:
    """(2, n) the top of a row of crowns over stations ``s`` (n,), and how far the crown standing there bulges
    out (m, its radius at its middle, none at its rims): domed crowns of random radius and height overlapping
    side by side, so the row reads as trees merging into a mass."""
    top = np.zeros_like(s)
    bulge = np.zeros_like(s)
    c = float(s[0]) - crown[1]
    stand = float(rng.uniform(*height))  # one stand's height: neighbours differ by a tenth, not by the whole range
    groves = smooth_tone(s, rng, 70.0, 0.2)  # stands of taller and lower trees
    while c < s[-1] + crown[1]:
        r = float(rng.uniform(*crown))
        h = stand * float(rng.uniform(*NEIGHBOUR_SPREAD)) * float(np.interp(c, s, groves))
        if rng.random() < EMERGENT_SHARE:  # a tree standing out of the mass
            h *= 1.12
        inside = np.flatnonzero(np.abs(s - c) < r)
        round_ = r * np.sqrt(1.0 - ((s[inside] - c) / r) ** 2)
        dome = h + CROWN_DOME * (round_ - r)
        wins = dome > top[inside]
        top[inside[wins]], bulge[inside[wins]] = dome[wins], round_[wins]
        c += r * float(rng.uniform(0.5, 1.1))
    return np.stack([np.maximum(top, 0.6 * height[0]), bulge])


def smooth_tone(x: FloatArray, rng: np.random.Generator, wavelength: float, spread: float) -> FloatArray:
    """(n,) a tone 1 +- ``spread`` varying smoothly over ``x`` (n,) at about ``wavelength``: patches of lighter
    and darker vegetation instead of face-by-face stripes."""
    tone = np.zeros_like(x)
    for k in range(3):
        tone += np.sin(x * (2 ** k) * 2 * np.pi / wavelength + rng.uniform(0, 2 * np.pi)) / 2 ** k
    return 1.0 + spread * tone / 1.75


def canopy(base: FloatArray, back: FloatArray, crowns: FloatArray, rng: np.random.Generator, name: str) -> Mesh:
    """A forest edge or a hedge over the ground line ``base`` (n, 3) (world), its ``crowns`` (``crown_tops``,
    (2, n)): a shaded understorey, each crown bulging towards the road (against the horizontal ``back`` (n, 2),
    unit) so it is lit as a dome, their tops leaning away; leaves in patches of tone, lighter up in the sun."""
    n = len(base)
    along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(base[:, :2], axis=0), axis=1))])
    top, bulge = crowns * np.clip(np.minimum(along, along[-1] - along) / TAPER_M, 0.3, 1.0) ** 0.5
    green = pick(rng, LEAVES)
    levels = [(0.3 * top, 0.15 * top), (0.68 * top, 0.25 * top - 0.4 * bulge), (top, 0.25 * top)]
    levels = [(h, lean + rng.uniform(-0.02, 0.02, n) * top) for h, lean in levels]
    tone = smooth_tone(along, rng, 40.0, 0.25)
    faces_tone = np.tile(0.5 * (tone[:-1] + tone[1:]), 2)[:, None] * rng.uniform(0.92, 1.08, (2 * (n - 1), 1))
    colors = [green * faces_tone * shade for shade in CANOPY_SHADES]
    return with_finish(layered(base, back, levels, colors, name, "tree"), LEAVES_FINISH)


def layered(base: FloatArray, back: FloatArray, levels: list[tuple[FloatArray, FloatArray]],
            colors: list[FloatArray], name: str, kind: str) -> Mesh:
    """Bands of quads over the ground line ``base`` (n, 3): from just below the ground up through ``levels``
    ((height, setback along the horizontal ``back`` (n, 2)), each (n,)); each band's (2 (n - 1), 3) colours in
    ``colors``; the quads face against ``back``."""
    n = len(base)
    lean = np.column_stack([back, np.zeros(n)])
    up = np.array([0.0, 0.0, 1.0])
    rows = [base - 0.6 * up] + [base + lean * setback[:, None] + np.outer(height, up) for height, setback in levels]
    faces = _ribbon_faces(n, len(rows), closed=False)
    vertices = np.concatenate(rows)
    towards = -np.tile(lean, (len(rows), 1))[faces[:, 0]]
    return Mesh(vertices, facing(vertices, faces, towards), np.concatenate(colors).astype(np.float32), name=name,
                kind=kind)


def facing(vertices: FloatArray, faces: np.ndarray, towards: FloatArray) -> np.ndarray:
    """``faces`` (m, 3) turned so each one's normal points along ``towards`` (m, 3) (counter-clockwise seen from
    there, as glTF viewers that cull back faces expect)."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    flip = (np.cross(b - a, c - a) * towards).sum(1) < 0
    return np.where(flip[:, None], faces[:, ::-1], faces).astype(np.int32)


def stretches(s0: float, s1: float, rng: np.random.Generator, veg: Vegetation,
              density: float) -> Iterator[tuple[float, float]]:
    """(start, end) of the stretches of ``veg`` between s0 and s1: lengths drawn from its ``stretch``, gaps such
    that it lines its ``cover`` share of the road at density 1, more at higher densities, none at 0."""
    cover = 1.0 - (1.0 - veg.cover) ** density
    if cover <= 1e-6:
        return
    mean_gap = 0.5 * (veg.stretch[0] + veg.stretch[1]) * (1.0 - cover) / cover
    s = s0 + float(rng.uniform(0.0, 2.0 * mean_gap + 1.0))
    while s < s1:
        length = float(rng.uniform(*veg.stretch))
        yield s, min(s + length, s1)
        s += length + float(rng.uniform(0.3, 1.7)) * mean_gap + 5.0


def clear_of_roads(clear: Clearance, index: int, p_xy: FloatArray, s_road: FloatArray, t_road: FloatArray,
                   margin: float) -> np.ndarray:
    """(n,) which ground points (n, 2), meant at (``s_road``, ``t_road``) of piece ``index``, lie there (not
    folded onto another part of its road nor beyond the inside of a bend), keep ``margin`` from every other
    piece's corridor and from the props' footprints, and stand beside no closed stretch of the main road."""
    piece = clear.pieces[index]
    s_back, t_back = clear.road_frame(index, p_xy)
    ok = (np.abs(s_back - s_road) < 2.0) & (np.abs(t_back - t_road) < 2.0)
    curvature = np.interp(s_road, piece.line.s, piece.line.curvature)
    ok &= ~((curvature * t_road > 0) & (np.abs(t_road) > 0.6 / np.maximum(np.abs(curvature), 1e-9)))
    for other, road in enumerate(clear.pieces):
        if other != index:
            s, t = clear.road_frame(other, p_xy)
            ok &= ~((s > -margin) & (s < road.line.length + margin) & (np.abs(t) < corridor_half_width(road) + margin))
    if len(clear.taken):
        centres = clear.taken.mean(1)
        radii = np.linalg.norm(clear.taken - centres[:, None], axis=2).max(1)
        ok &= (np.linalg.norm(p_xy[:, None] - centres[None], axis=2) > radii + margin).all(1)
    if clear.closed_s:
        s_main = s_road if index == 0 else clear.road_frame(0, p_xy)[0]
        for s0, s1 in clear.closed_s:
            ok &= ~((s_main >= s0) & (s_main <= s1))
    return ok


def runs(keep: np.ndarray, shortest: int = 4) -> Iterator[slice]:
    """Slices of the runs of True in ``keep`` (n,) at least ``shortest`` long."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], keep.astype(np.int8), [0]])))
    for a, b in zip(edges[::2], edges[1::2]):
        if b - a >= shortest:
            yield slice(int(a), int(b))


def drive_window(inputs: RoadsideInputs, index: int, piece: RoadPiece) -> tuple[float, float]:
    """The stretch of a piece the backdrop's lines follow: the main road around what the ego sees, arms whole."""
    if index:
        return piece.s_start, piece.line.length
    return max(0.0, inputs.start_s - DRIVE_BEHIND_M), min(piece.line.length, inputs.end_s + DRIVE_AHEAD_M)


def vegetation_lines(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance, rng: np.random.Generator,
                     veg: Vegetation) -> list[Mesh]:
    """Lines of ``veg`` (forest edges, hedgerows) along both sides of every piece, one mesh per piece and side,
    their setback wandering a little along the road."""
    out: list[Mesh] = []
    for index, piece in enumerate(network.pieces):
        reach = corridor_half_width(piece)
        for side in (-1, 1):
            parts = []
            for a, b in stretches(*drive_window(inputs, index, piece), rng, veg, inputs.density):
                setback = float(rng.uniform(*veg.setback))
                step = float(np.clip(setback / 50.0, 0.8, 3.0))
                s = np.arange(a, b, step)
                if s.size < 4:
                    continue
                wander = 0.08 * setback * np.sin(s / float(rng.uniform(40.0, 90.0)) + float(rng.uniform(0, 6.3)))
                t = side * (reach + setback + wander)
                base = piece.line.to_world(s, t, ground_h(piece))
                keep = clear_of_roads(clear, index, base[:, :2], s, t, margin=4.0)
                _, _, left = piece.line.frame(s)
                crowns = crown_tops(s, rng, veg.height, veg.crown)
                parts += [canopy(base[run], side * left[run, :2], crowns[:, run], own_rng(rng), veg.name)
                          for run in runs(keep)]
            if parts:
                label = "left" if side > 0 else "right"
                out.append(merge(parts, name=f"{veg.name} {label} piece {index}", kind="tree"))
    return out


def field_hedges(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance,
                 rng: np.random.Generator) -> list[Mesh]:
    """Hedgerows between fields running away from the main road on both sides, about every 140 m / density of
    the stretch the ego sees, from just beyond the roadside trees to 80-220 m out."""
    piece = network.main
    reach = corridor_half_width(piece)
    parts = []
    s0, s1 = drive_window(inputs, 0, piece)
    spacing = 140.0 / inputs.density if inputs.density > 0 else np.inf
    for side in (-1, 1):
        s_hedge = s0 + float(rng.uniform(0.0, 60.0))
        while s_hedge < s1 and np.isfinite(spacing):
            t = side * (reach + np.arange(34.0, float(rng.uniform(80.0, 220.0)), 2.5))
            s = np.full(t.shape, s_hedge)
            base = piece.line.to_world(s, t, ground_h(piece))
            keep = clear_of_roads(clear, 0, base[:, :2], s, t, margin=4.0)
            _, tangent, _ = piece.line.frame(s)
            back = tangent[:, :2] / np.linalg.norm(tangent[:, :2], axis=1, keepdims=True)
            crowns = crown_tops(np.abs(t), rng, HEDGEROW.height, HEDGEROW.crown)
            parts += [canopy(base[run], back[run], crowns[:, run], own_rng(rng), "field hedge") for run in runs(keep)]
            s_hedge += spacing * float(rng.uniform(0.5, 1.5))
    return [merge(parts, name="field hedges", kind="tree")] if parts else []


def back_rows(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance, rng: np.random.Generator) -> list[Mesh]:
    """The houses and garden trees massing behind a suburb's first row of houses, along the main road ahead of
    the ego: stretches (``SUBURB_BEHIND``) of houses (``house_shell``) and garden trees (``garden_tree``) side by side,
    one mesh per side."""
    piece = network.main
    reach = corridor_half_width(piece)
    s0, s1 = max(0.0, inputs.start_s - DRIVE_BEHIND_M), min(piece.line.length, inputs.end_s + SUBURB_AHEAD_M)
    out: list[Mesh] = []
    for side in (-1, 1):
        parts = []
        for a, b in stretches(s0, s1, rng, SUBURB_BEHIND, inputs.density):
            s = a
            while s < b:
                own = own_rng(rng)
                house = rng.random() < HOUSE_SHARE
                width = float(rng.uniform(8.0, 13.0)) if house else float(rng.uniform(4.0, 8.0))
                t = side * (reach + float(rng.uniform(*SUBURB_BEHIND.setback)))
                centre = piece.line.to_world(np.array([s + width / 2]), np.array([t]))[:, :2]
                if s + width < piece.line.length and clear_of_roads(clear, 0, centre, np.array([s + width / 2]),
                                                                    np.array([t]), margin=width / 2 + 2.0)[0]:
                    # turned to face the road: on the right, local +X runs back along it, from the far end
                    T_world_local = pose_on_road(piece.line, s if side > 0 else s + width, t,
                                                 0.0 if side > 0 else np.pi, ground_h(piece))
                    parts.append(transformed(house_shell(own, width) if house else garden_tree(own, width),
                                             T_world_local))
                s += width + float(rng.uniform(1.0, 6.0))
        if parts:
            out.append(merge(parts, name=f"{SUBURB_BEHIND.name} {'left' if side > 0 else 'right'}", kind="building"))
    return out


def house_shell(rng: np.random.Generator, width: float) -> Mesh:
    """What the road sees of a house behind the first row (local frame: the front along +X from the origin, the
    house running back along +Y): its front wall, the front slope of its gable roof and its two gable ends."""
    depth, eaves = float(rng.uniform(7.0, 10.0)), float(rng.uniform(3.0, 6.0))
    ridge = eaves + float(rng.uniform(0.3, 0.5)) * depth
    _, wall = wall_finish(rng, (BRICK, RENDER), (0.5, 0.5))  # far away: the finish's colour, not its courses
    roof = pick(rng, buildings.ROOFS) * float(rng.uniform(0.8, 1.3))
    gable = [(0.0, -0.5), (depth, -0.5), (depth, eaves), (depth / 2, ridge), (0.0, eaves)]
    vertices = [(x, y, z) for x in (0.0, width) for y, z in gable]  # 0-4 one end, 5-9 the other
    faces = [(0, 5, 9), (0, 9, 4), (4, 9, 8), (4, 8, 3)]  # the front wall, the roof's front slope
    faces += [(k + 0, k + 1, k + 2) for k in (0, 5)] + [(k + 0, k + 2, k + 4) for k in (0, 5)] \
        + [(k + 4, k + 2, k + 3) for k in (0, 5)]  # the gable ends
    colors = [wall, wall, roof, roof] + [wall] * 6
    return Mesh(np.array(vertices), np.array(faces), np.array(colors, np.float32), name="house behind",
                kind="building")


def garden_tree(rng: np.random.Generator, width: float) -> Mesh:
    """A garden tree behind the first row (local frame, along +X from the origin, its foot ``width / 2`` along):
    a tree of ``vegetation.tree`` as seen from afar (``near=False``: trunk, branches and leaf clusters, fewer of
    them, no sprigs), ``SUBURB_BEHIND``'s heights tall, so its outline is a tree's, not a lump's."""
    T_local_tree = np.eye(4)
    T_local_tree[0, 3] = width / 2
    planted = tree(rng, height=float(rng.uniform(*SUBURB_BEHIND.height)), near=False, name="garden tree behind")
    return transformed(planted, T_local_tree)


RIDGE_HALF_LENGTH_M = 900.0  # the ridge a tunnel enters runs this far to both sides of the road
RIDGE_CREST_M = (34.0, 58.0)  # its crest's height over the portal (min, max)
RIDGE_ROWS = ((12.0, 0.0), (45.0, 0.5), (95.0, 0.85), (170.0, 1.0), (280.0, 0.9))  # (m behind the portal, share)
RIDGE_STEP_M = 6.0


def wooded_ridge(network: RoadNetwork, s_portal: float, crest: float, inner: float, hill_width: float,
                 rng: np.random.Generator) -> list[Mesh]:
    """The wooded ridge a tunnel runs into: rising behind the portal's hill (its foot sunk in that hill's
    surface, ``props.hill_profile(inner, hill_width, crest)``, and always above the tube's roof), running
    RIDGE_HALF_LENGTH_M to both sides under a crest of seeded noise, with a forest edge along its foot beside the
    portal's hill."""
    line = network.main.line
    T_world_portal = pose_on_road(line, s_portal, 0.0)
    y = np.arange(-RIDGE_HALF_LENGTH_M, RIDGE_HALF_LENGTH_M + 1e-9, RIDGE_STEP_M)
    angle = np.pi * (y / RIDGE_HALF_LENGTH_M)  # the noise closes on itself: the ridge's ends match in height
    height = RIDGE_CREST_M[0] + (RIDGE_CREST_M[1] - RIDGE_CREST_M[0]) * (0.5 + 0.5 * periodic_noise(rng, angle, base=2))
    height *= 1.0 - 0.5 * (np.abs(y) / RIDGE_HALF_LENGTH_M) ** 2  # falling away towards its ends
    profile = props.hill_profile(inner, hill_width, crest)
    hill_surface = np.interp(np.abs(y), profile[[4, 3, 2, 1], 0], profile[[4, 3, 2, 1], 1], right=0.0)
    rows = []
    for k, (x, share) in enumerate(RIDGE_ROWS):
        z = hill_surface - 0.5 if k == 0 else np.maximum(share * height, crest + 3.0 * k)
        rows.append(np.column_stack([np.full(y.shape, x), y, z, np.ones(y.shape)]))
    p_world = (np.concatenate(rows) @ T_world_portal.T)[:, :3]
    faces = _ribbon_faces(len(y), len(rows), closed=False)
    bands = len(RIDGE_ROWS) - 1
    lower = patches(periodic_noise(rng, angle, octaves=3, base=8), FOREST + FIELDS[:2])[:-1]  # meadows low down
    upper = patches(periodic_noise(rng, angle, octaves=3, base=6), FOREST)[:-1]
    colors = np.concatenate([np.tile(lower if k == 0 else upper, (2, 1)) for k in range(bands)]) \
        * rng.uniform(0.94, 1.06, (len(faces), 1))
    towards = np.tile(-T_world_portal[:3, 0], (len(faces), 1))
    ridge = Mesh(p_world, facing(p_world, faces, towards), colors.astype(np.float32), name="wooded ridge",
                 kind="terrain", casts_shadow=False)
    return [ridge, *_ridge_edge(T_world_portal, y, inner + hill_width, rng)]


def _ridge_edge(T_world_portal: FloatArray, y: FloatArray, beside: float, rng: np.random.Generator) -> list[Mesh]:
    """The forest edge along the ridge's foot on both sides of the portal's hill (beyond |y| = ``beside``)."""
    parts = []
    for side in (-1.0, 1.0):
        y_edge = side * np.arange(beside + 4.0, RIDGE_HALF_LENGTH_M * 0.6, 2.5)
        local = np.column_stack([np.full(y_edge.shape, RIDGE_ROWS[0][0] + 6.0), y_edge, np.zeros(y_edge.shape),
                                 np.ones(y_edge.shape)])
        base = (local @ T_world_portal.T)[:, :3]
        back = np.tile(T_world_portal[:2, 0], (len(y_edge), 1))
        crowns = crown_tops(np.abs(y_edge), rng, FAR_WOOD.height, FAR_WOOD.crown)
        parts.append(canopy(base, back, crowns, own_rng(rng), "ridge forest edge"))
    return [merge(parts, name="ridge forest edge", kind="tree")]


def distant_hills(inputs: RoadsideInputs, network: RoadNetwork, rng: np.random.Generator,
                  far: bool = True) -> list[Mesh]:
    """Arcs of hills around the road where the ego's camera looks: wooded nearer ones, and (``far``) higher
    ones further out that the haze turns blue-grey (the renderer's aerial perspective). A suburb, whose houses
    hide most of them, gets the near ones only, in coarser steps."""
    sector = view_sector(inputs, network)
    near = hill_ring(network, sector, own_rng(rng), 1.0, 0.7 * MAX_HILL_ELEVATION_DEG, 0.5 if far else 1.5,
                     FOREST + FIELDS[:1], "near hills", shoulder=far)
    if not far:
        return [near]
    return [near, hill_ring(network, sector, own_rng(rng), FAR_RING, MAX_HILL_ELEVATION_DEG, 1.0, FOREST + FIELDS,
                            "far hills")]


def _lines(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance, rng: np.random.Generator,
           *kinds: Vegetation) -> list[Mesh]:
    return [mesh for veg in kinds for mesh in vegetation_lines(inputs, network, clear, own_rng(rng), veg)]


def _suburban(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance, rng: np.random.Generator) -> list[Mesh]:
    return distant_hills(inputs, network, own_rng(rng), far=False) + back_rows(inputs, network, clear, own_rng(rng))


def _highway(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance, rng: np.random.Generator) -> list[Mesh]:
    return distant_hills(inputs, network, own_rng(rng)) + _lines(inputs, network, clear, rng, TREE_LINE, FAR_WOOD)


def _rural(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance, rng: np.random.Generator) -> list[Mesh]:
    return distant_hills(inputs, network, own_rng(rng)) \
        + _lines(inputs, network, clear, rng, HEDGEROW, TREE_LINE, FAR_WOOD) \
        + field_hedges(inputs, network, clear, own_rng(rng))


def _tunnel_approach(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance,
                     rng: np.random.Generator) -> list[Mesh]:
    return distant_hills(inputs, network, own_rng(rng)) + _lines(inputs, network, clear, rng, TREE_LINE)


BACKDROPS: dict[str, Callable[[RoadsideInputs, RoadNetwork, Clearance, np.random.Generator], list[Mesh]]] = {
    "urban": lambda inputs, network, clear, rng: [],  # the blocks fill the frontage: nothing shows behind them
    "suburban": _suburban,
    "highway": _highway,
    "rural": _rural,
    "tunnel_approach": _tunnel_approach,  # and the ridge the tunnel enters (``wooded_ridge``, with the tunnel)
}


BACKDROP_NAMES = ("near hills", "far hills", TREE_LINE.name, FAR_WOOD.name, HEDGEROW.name, "field hedges",
                  SUBURB_BEHIND.name, "wooded ridge", "ridge forest edge")  # how the backdrop's meshes are named


def is_backdrop(mesh: Mesh) -> bool:
    """Whether ``mesh`` is part of the backdrop (by its name: ``BACKDROP_NAMES``)."""
    return mesh.name.startswith(BACKDROP_NAMES)


def backdrop_meshes(inputs: RoadsideInputs, network: RoadNetwork, clear: Clearance,
                    rng: np.random.Generator) -> list[Mesh]:
    """World-frame meshes of the backdrop of ``inputs``' scene kind and density, beyond the roadside that
    ``clear`` holds (its props' footprints, its closed stretches)."""
    return BACKDROPS[inputs.kind](inputs, network, clear, rng)
