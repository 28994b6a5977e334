"""Procedural low-poly buildings: apartment and office blocks (a shop on the ground floor of some) and detached
houses under gable roofs, their walls of brick, render or concrete panels (``facade``), framed windows on every
facade seen from the road, some of them lit at night (``light_windows``).

Every builder returns a ``Mesh`` in its own local frame: +X along the road, +Y towards it (the front), +Z up,
origin on the ground at the centre of the footprint; ``scenery`` places them beside the road and ``backdrop``
takes the colours of its roofs from ``ROOFS``. Dimensions are real (metres); colours are linear albedo.
"""

from __future__ import annotations

import numpy as np

from ..typed import FloatArray
from .facade import (
    AWNING_COLORS,
    BALCONY_SHARE,
    BRICK,
    FASCIA_COLORS,
    PANE_HEIGHT_M,
    PLAIN,
    RENDER,
    SHOP_AWNING_SHARE,
    SHOP_GLASS,
    TILES,
    wall_finish,
)
from .facade import GLASS as GLASS_FINISH
from .primitives import ColorLike, box, facing_quad, merge, pick, prism
from .props import GLASS
from .scene import Mesh

# Window frames (linear albedo; their width and a sill's depth in metres) and roof tiles.
WINDOW_FRAMES = ((0.55, 0.55, 0.52), (0.08, 0.08, 0.08))  # white-painted and dark aluminium
WINDOW_FRAME_M = 0.07
SILL_DEPTH_M = 0.12
ROOFS = ((0.2, 0.05, 0.03), (0.06, 0.06, 0.07), (0.15, 0.1, 0.07))


def building(rng: np.random.Generator, width: float = 20.0, depth: float = 14.0, height: float = 15.0, *,
             facade: ColorLike | None = None, shopfront: bool = False, lit: bool = False,
             name: str = "building") -> Mesh:
    """An apartment or office block: ``width`` along X, ``depth`` along Y, walls of brick, render or concrete panels
    (``facade.wall_finish``; ``facade`` overrides the colour), a grid of framed windows on every facade seen from
    the road, a cornice at the roof line. ``shopfront``: the front (+Y) ground floor is a shop window under a
    coloured fascia, half of them under an awning; otherwise the block has an entrance door, and half of such
    (residential) blocks have balconies. ``lit`` (night): a share of the windows glows (``light_windows``), and half
    the shops keep their window lit."""
    finish, wall = wall_finish(rng)
    wall = np.asarray(facade, np.float64) if facade is not None else wall
    hy = depth / 2
    parts = [_walls(width, depth, height, wall, finish),
             box((width + 0.5, depth + 0.5, 0.6), (0.0, 0.0, height + 0.1), wall * 0.75)]  # cornice
    storeys = max(int(height // STOREY_M), 1)
    pitch = float(rng.uniform(2.6, 3.6))
    glass = np.asarray(GLASS) * 2.0
    first = 1 if shopfront else 0
    shop = _shopfront(rng, width, hy) if shopfront else []
    panes = []
    for axis_len, across, sign, along_x in _facades_seen(width, depth):
        grid = _window_grid(axis_len, across, sign, along_x, storeys, pitch, first, glass, rng)
        parts += grid
        panes += grid[1::3]
    if not shopfront:
        parts.append(_door(0.0, hy, 1.4, 2.4, DOOR_COLORS[int(rng.integers(len(DOOR_COLORS)))]))
        if storeys > 1 and rng.random() < BALCONY_SHARE:
            parts.append(_balconies(width, hy, storeys, pitch, wall))
    parts += shop
    if lit:  # drawn after everything else, so a night block has the day's shape and colours
        light_windows(panes, rng)
        if shopfront and rng.random() < SHOP_LIT_SHARE:
            glow = np.asarray(ROOM_LIGHTS[2], np.float32) * np.float32(rng.uniform(*SHOP_GLOW))
            shop[0].emission = np.ascontiguousarray(np.broadcast_to(glow, (len(shop[0].faces), 3)))
    return merge(parts, name=name, kind="building", gloss=0.1)


STOREY_M = 3.2
DOOR_COLORS = ((0.10, 0.05, 0.025), (0.02, 0.05, 0.03), (0.03, 0.03, 0.035), (0.25, 0.24, 0.22))
SHOP_GLASS_TOP_M = 2.9  # the shop window reaches from its stall riser to here; the fascia sits above it


def _walls(width: float, depth: float, height: float, color: ColorLike, finish: int, footing: float = 0.5) -> Mesh:
    """Four walls (from ``footing`` below the ground to ``height``) and a flat roof of a block centred on the
    origin, each wall with facade coordinates (u along it, v = height above the ground) for its ``finish``; 10
    faces."""
    hx, hy, z0 = width / 2, depth / 2, -footing
    corners = np.array([(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)])  # counter-clockwise seen from above
    vertices: list[tuple[float, float, float]] = []
    uv: list[tuple[float, float]] = []
    faces: list[tuple[int, int, int]] = []
    along = 0.0
    for i in range(4):
        (x0, y0), (x1, y1) = corners[i], corners[(i + 1) % 4]
        length = float(np.hypot(x1 - x0, y1 - y0))
        k = len(vertices)
        vertices += [(x0, y0, z0), (x1, y1, z0), (x1, y1, height), (x0, y0, height)]
        uv += [(along, z0), (along + length, z0), (along + length, height), (along, height)]
        faces += [(k, k + 1, k + 2), (k, k + 2, k + 3)]
        along += length
    k = len(vertices)
    vertices += [(x, y, height) for x, y in corners]
    uv += [(x, y) for x, y in corners]
    faces += [(k, k + 1, k + 2), (k, k + 2, k + 3)]
    finishes = np.full(10, finish, np.int8)
    finishes[8:] = PLAIN  # the roof is seen from above only
    return Mesh(np.array(vertices), np.array(faces), np.asarray(color, np.float32), finish=finishes,
                uv=np.array(uv, np.float32))


def _glazing(u0: float, u1: float, z0: float, z1: float, y: float, color: ColorLike, finish: int) -> Mesh:
    """A pane facing +Y at ``y`` over x in [u0, u1], z in [z0, z1], its facade coordinates across it from its
    centre and up from its foot."""
    corners = [(u0, y, z0), (u1, y, z0), (u1, y, z1), (u0, y, z1)]
    mid = (u0 + u1) / 2
    pane = facing_quad(corners, (0.0, 1.0, 0.0), color)
    uv = np.array([(x - mid, z - z0) for x, _, z in pane.vertices], np.float32)
    return Mesh(pane.vertices, pane.faces, pane.colors, finish=np.full(len(pane.faces), finish, np.int8), uv=uv)


def _door(x: float, hy: float, width: float, height: float, color: ColorLike) -> Mesh:
    """An entrance door (a glazed door leaf in a dark frame) on the +Y front at x."""
    return facing_quad([(x - width / 2, hy + 0.02, 0.0), (x + width / 2, hy + 0.02, 0.0),
                        (x + width / 2, hy + 0.02, height), (x - width / 2, hy + 0.02, height)], (0.0, 1.0, 0.0),
                       color)


def _shopfront(rng: np.random.Generator, width: float, hy: float) -> list[Mesh]:
    """The front ground floor of a shop: its window (first, ``SHOP_GLASS`` finish: bays, transom, stall riser), a
    fascia band in the trade's colour above it and, for ``SHOP_AWNING_SHARE`` of shops, an awning over it."""
    half = width / 2 - 0.5
    interior = np.asarray(GLASS) * rng.uniform(2.0, 5.0)
    parts = [_glazing(-half, half, 0.0, SHOP_GLASS_TOP_M, hy + 0.03, interior, SHOP_GLASS),
             box((width - 0.6, 0.2, 0.7), (0.0, hy + 0.1, SHOP_GLASS_TOP_M + 0.4),
                 FASCIA_COLORS[int(rng.integers(len(FASCIA_COLORS)))])]
    if rng.random() < SHOP_AWNING_SHARE:
        reach, drop = float(rng.uniform(1.0, 1.6)), 0.5
        cloth = AWNING_COLORS[int(rng.integers(len(AWNING_COLORS)))]
        parts.append(facing_quad([(-half, hy, SHOP_GLASS_TOP_M + 0.05), (half, hy, SHOP_GLASS_TOP_M + 0.05),
                                  (half, hy + reach, SHOP_GLASS_TOP_M + 0.05 - drop),
                                  (-half, hy + reach, SHOP_GLASS_TOP_M + 0.05 - drop)], (0.0, drop, reach), cloth))
    return parts


def _balconies(width: float, hy: float, storeys: int, pitch: float, wall: FloatArray) -> Mesh:
    """Balconies with solid fronts on the +Y facade, under every other window column from the first floor up
    (one box each: slab and parapet 1.05 m high, 1.1 m deep)."""
    centres, _, half_w = _grid_columns(width, pitch)
    columns = centres[::2]
    levels = np.arange(1, storeys) * STOREY_M
    c, z = (grid.ravel() for grid in np.meshgrid(columns, levels))
    slab = box((2 * half_w + 0.6, 1.1, 1.05))
    offsets = np.stack([c, np.full_like(c, hy + 0.55), z + 0.525], 1)
    vertices = (slab.vertices[None] + offsets[:, None]).reshape(-1, 3)
    faces = (slab.faces[None] + np.arange(len(c))[:, None, None] * len(slab.vertices)).reshape(-1, 3)
    return Mesh(vertices, faces, np.asarray(wall * 0.85, np.float32))


def _facades_seen(width: float, depth: float) -> tuple[tuple[float, float, float, bool], ...]:
    """(span, distance from the centre, sign, runs along X) of the facades with windows: the front (+Y, towards the
    road) and both ends; the back is never seen from the road."""
    hx, hy = width / 2, depth / 2
    return (width, hy, 1.0, True), (depth, hx, 1.0, False), (depth, hx, -1.0, False)


# Rooms lit at night, seen through their windows (linear sRGB of the light): tungsten bulbs of 2700 K and 3000 K,
# a neutral 4000 K LED or fluorescent tube, and the cold blue of a television or a screen, in these shares.
ROOM_LIGHTS = ((1.0, 0.40, 0.095), (1.0, 0.46, 0.15), (1.0, 0.64, 0.37), (0.42, 0.58, 1.0))
ROOM_LIGHT_SHARES = (0.4, 0.3, 0.15, 0.15)
# Curtains drawn across a lit window pass a dimmer light tinted by their cloth: cream, orange, red.
CURTAIN_TINTS = ((0.95, 0.85, 0.6), (1.0, 0.55, 0.25), (0.9, 0.25, 0.12))
CURTAINED_SHARE = 0.4
LIT_SHARE = (0.08, 0.45)  # the share of a building's windows lit at night, drawn per building
WINDOW_GLOW = (0.05, 0.45)  # radiance of a lit window pane (times its light's colour): a few to tens of cd/m2,
# against about 1 cd/m2 of a road under street lamps
SHOP_LIT_SHARE = 0.5  # the shops whose window stays lit at night
SHOP_GLOW = (0.2, 0.5)


def light_windows(panes: list[Mesh], rng: np.random.Generator) -> None:
    """Make a share (drawn from ``LIT_SHARE``) of the window panes glow: each lit pane gets one of ``ROOM_LIGHTS``
    at a drawn brightness, dimmed and tinted where a curtain is drawn. ``panes`` are ``_window_grid``'s pane meshes
    (two triangles per window: window k is faces k and k + n); their ``emission`` is set in place."""
    share = float(rng.uniform(*LIT_SHARE))
    for pane in panes:
        n = len(pane.faces) // 2
        lit = rng.random(n) < share
        light = np.asarray(ROOM_LIGHTS)[rng.choice(len(ROOM_LIGHTS), n, p=ROOM_LIGHT_SHARES)]
        curtain = np.asarray(CURTAIN_TINTS)[rng.integers(len(CURTAIN_TINTS), size=n)] * 0.45
        curtained = rng.random(n) < CURTAINED_SHARE
        glow = light * rng.uniform(*WINDOW_GLOW, (n, 1)) * np.where(curtained[:, None], curtain, 1.0)
        glow[~lit] = 0.0
        pane.emission = np.concatenate([glow, glow]).astype(np.float32)


def _window_grid(span: float, across: float, sign: float, along_x: bool, storeys: int, pitch: float,
                 first_storey: int, color: FloatArray, rng: np.random.Generator | None = None) -> list[Mesh]:
    """Windows on one facade (the facade plane at ``sign * across``: y if ``along_x`` else x): each a frame, a
    pane and a sill under it. The panes have the ``GLASS`` finish (the renderer draws their bars and mirrors the
    sky in them) and facade coordinates from the pane's centre and foot; their colours (``color`` times a drawn
    factor per pane, when ``rng`` is given) are what lies behind the glass: a dark room, a drawn curtain."""
    centres, _, half_w = _grid_columns(span, pitch)
    levels = np.arange(first_storey, storeys) * STOREY_M
    if levels.size == 0:
        return []
    c, z = (grid.ravel() for grid in np.meshgrid(centres, levels))
    n = len(c)
    frame = WINDOW_FRAME_M
    # (n, 4) corners along the facade (u) and up it (v), and their offsets off the wall (w): frame, pane and sill
    # (a quad jutting out and down from the frame's foot)
    rects = [(c - half_w - frame, c + half_w + frame, z + 0.95 - frame, z + 2.55 + frame, 0.01, 0.01),
             (c - half_w, c + half_w, z + 0.95, z + 0.95 + PANE_HEIGHT_M, 0.02, 0.02),
             (c - half_w - 0.08, c + half_w + 0.08, z + 0.95 - frame, z + 0.95 - frame - 0.05, 0.01, SILL_DEPTH_M)]
    pane: np.ndarray
    if rng is None:
        pane = np.broadcast_to(np.asarray(color, np.float32), (n, 3))
    else:
        pane = np.asarray(color) * rng.uniform(0.6, 2.0, (n, 1))
        curtains = rng.random(n) < 0.2
        pane[curtains] = rng.choice([0.12, 0.25], curtains.sum())[:, None] * np.array([0.55, 0.5, 0.42])
    frame_color = np.broadcast_to(np.asarray(WINDOW_FRAMES[0 if rng is None else int(rng.integers(2))]), (n, 3))
    meshes = []
    for i, ((a, b, z0, z1, w0, w1), colors) in enumerate(zip(rects, (frame_color, pane, frame_color))):
        u = np.stack([a, b, b, a], 1)
        v = np.stack([z0, z0, z1, z1], 1)
        finish, uv = None, None
        if i == 1:  # the pane
            finish = np.full(2 * n, GLASS_FINISH, np.int8)
            uv = np.stack([u - c[:, None], v - z0[:, None]], -1).reshape(-1, 2).astype(np.float32)
        w = sign * (across + np.stack([np.full(n, w0), np.full(n, w0), np.full(n, w1), np.full(n, w1)], 1))
        corners = np.stack([u, w, v] if along_x else [w, u, v], -1).reshape(-1, 3)
        quads = np.arange(n)[:, None] * 4
        faces = np.concatenate([quads + [0, 1, 2], quads + [0, 2, 3]])
        # The (u, v) order is counter-clockwise seen from +Y for an x-running facade and from -X otherwise.
        if (sign > 0) == along_x:
            faces = faces[:, ::-1]
        meshes.append(Mesh(corners, faces, np.concatenate([colors, colors]).astype(np.float32), finish=finish,
                           uv=uv))
    return meshes


def _grid_columns(span: float, pitch: float) -> tuple[FloatArray, int, float]:
    """(centres along the facade, number of columns, half width of a pane) of the window columns on ``span``."""
    columns = max(int(span // pitch), 1)
    centres = (np.arange(columns) - (columns - 1) / 2.0) * (span / columns)
    return centres.astype(np.float64), columns, min(0.7, 0.3 * span / columns)


def gable_roof(half_length: float, half_span: float, eaves: float, rise: float, color: ColorLike) -> Mesh:
    """A gable roof (local frame: the ridge along X over the origin, ``half_length`` to both ends, the eaves
    ``half_span`` to both sides at height ``eaves``, the ridge ``rise`` above them): its two slopes tiled (finish
    ``TILES``: u along the eaves, v up the slope from them), its soffit and gable ends plain."""
    roof = prism([(-half_span, eaves), (half_span, eaves), (0.0, eaves + rise)], -half_length, half_length, color,
                 axis="x")
    up_slope = np.where(roof.vertices[:, 2] > eaves + 1e-6, float(np.hypot(half_span, rise)), 0.0)
    p = roof.vertices[roof.faces]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    nz = normal[:, 2] / np.linalg.norm(normal, axis=1)
    roof.finish = np.where((np.abs(nz) > 0.1) & (np.abs(nz) < 0.999), TILES, PLAIN).astype(np.int8)
    roof.uv = np.column_stack([roof.vertices[:, 0], up_slope]).astype(np.float32)
    return roof


def house(rng: np.random.Generator, width: float = 10.0, depth: float = 8.0, *, storeys: int | None = None,
          lit: bool = False, name: str = "house") -> Mesh:
    """A detached house: walls, a gable roof (ridge along X), windows all round and a door on the +Y front;
    ``lit`` (night): a share of the windows glows (``light_windows``)."""
    storeys = int(rng.integers(1, 3)) if storeys is None else storeys
    wall_h = 2.9 * storeys
    hx, hy = width / 2, depth / 2
    finish, wall = wall_finish(rng, (BRICK, RENDER), (0.5, 0.5))
    roof_h = float(rng.uniform(0.3, 0.45)) * depth
    parts = [_walls(width, depth, wall_h, wall, finish, footing=0.3),
             gable_roof(hx + 0.3, hy + 0.4, wall_h - 0.05, roof_h + 0.05, pick(rng, ROOFS))]
    glass = np.asarray(GLASS) * 2.0
    pitch = float(rng.uniform(2.8, 3.6))
    panes = []
    for span, across, sign, along_x in _facades_seen(width, depth):
        grid = _window_grid(span, across, sign, along_x, storeys, pitch, 0, glass, rng)
        parts += grid
        panes += grid[1::3]
    if lit:
        light_windows(panes, rng)
    parts.append(facing_quad([(hx * 0.5 - 0.5, hy + 0.02, 0.0), (hx * 0.5 + 0.5, hy + 0.02, 0.0),
                              (hx * 0.5 + 0.5, hy + 0.02, 2.1), (hx * 0.5 - 0.5, hy + 0.02, 2.1)],
                             (0.0, 1.0, 0.0), (0.12, 0.06, 0.03)))
    return merge(parts, name=name, kind="building", gloss=0.05)

