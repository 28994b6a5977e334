"""Procedural low-poly props: vehicles, people, bicycles, buildings, street furniture, barriers, a tunnel portal.

Every builder returns a ``Mesh`` in its own local frame: +X forward, +Y left, +Z up, origin on the ground at
the centre of the footprint. Place it with ``primitives.transformed(mesh, primitives.pose_on_road(...))``.
Dimensions are real (metres); colours are linear albedo.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import trimesh

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
from .primitives import (
    ColorLike,
    PointsLike,
    beam,
    box,
    cylinder,
    loft,
    merge,
    pick,
    prism,
    quad,
    to_mesh,
    translation,
)
from .scene import Mesh

# Linear albedos shared by several props.
GLASS = (0.012, 0.016, 0.022)
WINDOW_FRAMES = ((0.55, 0.55, 0.52), (0.08, 0.08, 0.08))  # white-painted and dark aluminium
WINDOW_FRAME_M = 0.07
SILL_DEPTH_M = 0.12
TYRE = (0.018, 0.018, 0.02)
RIM = (0.22, 0.22, 0.23)
TRIM = (0.03, 0.03, 0.032)
HEADLIGHT = (0.8, 0.8, 0.75)
TAILLIGHT = (0.55, 0.01, 0.01)
CONCRETE = (0.36, 0.35, 0.33)
HEADLIGHT_GLOW = (6.0, 5.6, 4.8)
TAILLIGHT_GLOW = (2.5, 0.05, 0.02)

SHIRTS = ((0.5, 0.04, 0.03), (0.03, 0.08, 0.35), (0.6, 0.6, 0.58), (0.05, 0.05, 0.05), (0.08, 0.25, 0.07),
          (0.7, 0.45, 0.02), (0.35, 0.12, 0.3), (0.8, 0.22, 0.02))
TROUSERS = ((0.02, 0.03, 0.1), (0.03, 0.03, 0.03), (0.15, 0.12, 0.08), (0.18, 0.18, 0.19), (0.05, 0.08, 0.2))
SKINS = ((0.6, 0.38, 0.27), (0.45, 0.27, 0.17), (0.25, 0.13, 0.07), (0.12, 0.06, 0.035), (0.7, 0.5, 0.38))
HAIRS = ((0.02, 0.015, 0.01), (0.12, 0.06, 0.02), (0.35, 0.25, 0.1), (0.3, 0.3, 0.3))
ROOFS = ((0.2, 0.05, 0.03), (0.06, 0.06, 0.07), (0.15, 0.1, 0.07))


def _panel(corners: PointsLike, outward: ColorLike, color: ColorLike, **kw) -> Mesh:
    """A one-sided quad over (4, 3) ``corners`` (in order around it) facing ``outward`` (3,)."""
    corners = np.asarray(corners, np.float64)
    normal = np.cross(corners[1] - corners[0], corners[2] - corners[0])
    if np.dot(normal, outward) < 0:
        corners = corners[::-1]
    return quad(corners, color, **kw)


def _slanted_panel(a_xz: ColorLike, b_xz: ColorLike, half_y: float, inset: float, outward_xz: ColorLike,
                   color: ColorLike) -> Mesh:
    """A window on the slanted face through (x, z) points a and b, across |y| < half_y, inset along the edge
    by ``inset`` and lifted 2.5 cm off the face."""
    a, b = np.asarray(a_xz, np.float64), np.asarray(b_xz, np.float64)
    n = np.asarray(outward_xz, np.float64)
    n = n / np.linalg.norm(n)
    edge = (b - a) / np.linalg.norm(b - a)
    a, b = a + edge * inset + 0.025 * n, b - edge * inset + 0.025 * n
    corners = [(a[0], -half_y, a[1]), (b[0], -half_y, b[1]), (b[0], half_y, b[1]), (a[0], half_y, a[1])]
    return _panel(corners, (n[0], 0.0, n[1]), color)


def _side_panels(polygon_xz: PointsLike, half_y: float, color: ColorLike) -> list[Mesh]:
    """The same (4, 2) window outline on both sides (|y| = half_y + 2 cm), each facing outwards."""
    polygon_xz = np.asarray(polygon_xz, np.float64)
    panels = []
    for side in (-1.0, 1.0):
        y = side * (half_y + 0.02)
        corners = [(x, y, z) for x, z in polygon_xz]
        panels.append(_panel(corners, (0.0, side, 0.0), color))
    return panels


def _wheels(xs: ColorLike, radius: float, half_track: float, tyre_width: float, sections: int = 12) -> list[Mesh]:
    """Dark tyres with grey hubs at the axle positions ``xs``, both sides; ``sections`` round a tyre (a hub has
    two thirds as many; a tyre of fewer than 8 sections, too coarse for one, has none)."""
    parts = []
    for x in xs:
        for side in (-1.0, 1.0):
            y_out, y_in = side * half_track, side * (half_track - tyre_width)
            parts.append(cylinder(radius, color=TYRE, segment=[(x, y_in, radius), (x, y_out, radius)],
                                  sections=sections))
            if sections >= 8:
                parts.append(cylinder(radius * 0.55, color=RIM, segment=[(x, y_out - side * 0.02, radius),
                                                                         (x, y_out + side * 0.012, radius)],
                                      sections=2 * sections // 3))
    return parts


def _lamps(x: float, z: float, half_y: float, extents: ColorLike, color: ColorLike,
           glow: ColorLike | None) -> list[Mesh]:
    """A pair of lamp boxes centred at (x, +-half_y, z)."""
    return [box(extents, (x, side * half_y, z), color, emission=glow) for side in (-1.0, 1.0)]


def car(color: ColorLike = (0.45, 0.03, 0.03), *, lights_on: bool = False, length: float = 4.5,
        width: float = 1.8, height: float = 1.45, wheel_sections: int = 12, name: str = "car") -> Mesh:
    """A saloon car (about 440 faces; 210 with 6 ``wheel_sections``): body, glasshouse with dark windows, four
    wheels, head and tail lights."""
    hx, hy = length / 2, width / 2
    body = prism([(-hx, 0.22), (hx - 0.05, 0.22), (hx, 0.5), (hx - 0.2, 0.8), (-hx + 0.1, 0.86), (-hx, 0.6)],
                 -hy, hy, color)
    zb, zt = 0.82, height
    rear_b, front_b, front_t, rear_t = -0.41 * length, 0.19 * length, 0.0, -0.32 * length
    cabin_hy = hy - 0.07
    cabin = prism([(rear_b, zb), (front_b, zb), (front_t, zt), (rear_t, zt)], -cabin_hy, cabin_hy, color)
    parts = [body, cabin,
             _slanted_panel((front_b, zb), (front_t, zt), cabin_hy - 0.06, 0.05, (zt - zb, front_b - front_t), GLASS),
             _slanted_panel((rear_t, zt), (rear_b, zb), cabin_hy - 0.06, 0.05, (zb - zt, rear_t - rear_b), GLASS)]
    parts += _side_panels(_window_outline((rear_b, rear_t), (front_b, front_t), zb, zt, -0.12 * length, True),
                          cabin_hy, GLASS)
    parts += _side_panels(_window_outline((rear_b, rear_t), (front_b, front_t), zb, zt, -0.12 * length, False),
                          cabin_hy, GLASS)
    parts += _wheels((0.3 * length, -0.3 * length), 0.33, hy + 0.01, 0.22, wheel_sections)
    parts += _lamps(hx - 0.1, 0.63, hy - 0.28, (0.18, 0.36, 0.12), HEADLIGHT, HEADLIGHT_GLOW if lights_on else None)
    parts += _lamps(-hx + 0.02, 0.72, hy - 0.22, (0.1, 0.34, 0.13), TAILLIGHT, TAILLIGHT_GLOW if lights_on else None)
    parts.append(box((0.1, width - 0.1, 0.16), (hx - 0.02, 0.0, 0.3), TRIM))
    parts.append(box((0.1, width - 0.1, 0.16), (-hx + 0.02, 0.0, 0.32), TRIM))
    return merge(parts, name=name, kind="vehicle", gloss=0.6)


def _window_outline(rear: tuple[float, float], front: tuple[float, float], zb: float, zt: float, pillar: float,
                    front_window: bool) -> FloatArray:
    """(4, 2) x-z outline of the front or rear side window inside a trapezoid cabin side."""
    z0, z1 = zb + 0.07, zt - 0.06

    def along(edge: tuple[float, float], z: float) -> float:
        return edge[0] + (edge[1] - edge[0]) * (z - zb) / (zt - zb)

    if front_window:
        return np.array([(pillar + 0.05, z0), (along(front, z0) - 0.08, z0), (along(front, z1) - 0.08, z1),
                         (pillar + 0.05, z1)])
    return np.array([(along(rear, z0) + 0.08, z0), (pillar - 0.05, z0), (pillar - 0.05, z1),
                     (along(rear, z1) + 0.08, z1)])


def van(color: ColorLike = (0.6, 0.6, 0.6), *, lights_on: bool = False, length: float = 5.2, width: float = 2.0,
        height: float = 2.3, wheel_sections: int = 12, name: str = "van") -> Mesh:
    """A panel van (about 410 faces; 190 with 6 ``wheel_sections``): tall body with a short sloped nose, cab
    windows, four wheels, lamps."""
    hx, hy = length / 2, width / 2
    nose_z, shield_x = 1.15, hx - 0.95
    body = prism([(-hx, 0.3), (hx, 0.3), (hx, 0.95), (hx - 0.25, nose_z), (shield_x, height), (-hx, height)],
                 -hy, hy, color)
    parts = [body, _slanted_panel((hx - 0.25, nose_z), (shield_x, height), hy - 0.1, 0.08,
                                  (height - nose_z, shield_x - hx + 0.25), GLASS)]
    z0, z1 = 1.3, height - 0.2
    x_front = hx - 0.25 - (hx - 0.25 - shield_x) * (np.array([z0, z1]) - nose_z) / (height - nose_z) - 0.12
    parts += _side_panels([(hx - 1.9, z0), (x_front[0], z0), (x_front[1], z1), (hx - 1.9, z1)], hy, GLASS)
    parts += [_panel([(-hx - 0.01, side * 0.08, 1.35), (-hx - 0.01, side * (hy - 0.12), 1.35),
                      (-hx - 0.01, side * (hy - 0.12), height - 0.2), (-hx - 0.01, side * 0.08, height - 0.2)],
                     (-1.0, 0.0, 0.0), GLASS) for side in (-1.0, 1.0)]
    parts += _wheels((hx - 0.9, -hx + 1.0), 0.36, hy + 0.01, 0.24, wheel_sections)
    parts += _lamps(hx - 0.05, 0.82, hy - 0.25, (0.12, 0.36, 0.16), HEADLIGHT, HEADLIGHT_GLOW if lights_on else None)
    parts += _lamps(-hx + 0.02, 0.9, hy - 0.1, (0.08, 0.14, 0.4), TAILLIGHT, TAILLIGHT_GLOW if lights_on else None)
    parts.append(box((0.12, width - 0.05, 0.22), (hx, 0.0, 0.42), TRIM))
    return merge(parts, name=name, kind="vehicle", gloss=0.5)


def truck(color: ColorLike = (0.05, 0.12, 0.4), *, cargo_color: ColorLike = (0.6, 0.6, 0.58), lights_on: bool = False,
          length: float = 8.0, width: float = 2.5, height: float = 3.4, name: str = "truck") -> Mesh:
    """A box truck (about 580 faces): cab with windscreen, cargo box, dark chassis, six wheels, lamps."""
    hx, hy = length / 2, width / 2
    cab_x0, cab_top = hx - 1.9, min(height - 0.3, 3.0)
    parts = [box((1.9, width, cab_top - 0.55), (hx - 0.95, 0.0, (cab_top + 0.55) / 2), color),
             box((length - 2.05, width, height - 1.05), ((-hx + cab_x0 - 0.15) / 2, 0.0, (height + 1.05) / 2),
                 cargo_color),
             box((length - 0.6, width - 0.7, 0.5), (0.0, 0.0, 0.8), TRIM),
             box((0.2, width, 0.3), (hx - 0.08, 0.0, 0.55), TRIM)]
    x_glass, z_top = hx + 0.02, cab_top - 0.15
    parts.append(_panel([(x_glass, -hy + 0.1, 1.75), (x_glass, hy - 0.1, 1.75), (x_glass, hy - 0.1, z_top),
                         (x_glass, -hy + 0.1, z_top)], (1.0, 0.0, 0.0), GLASS))
    parts += _side_panels([(cab_x0 + 0.9, 1.75), (hx - 0.12, 1.75), (hx - 0.12, cab_top - 0.2),
                           (cab_x0 + 0.9, cab_top - 0.2)], hy, GLASS)
    parts += _wheels((hx - 1.2, -hx + 1.5, -hx + 2.6), 0.5, hy - 0.02, 0.3)
    parts += _lamps(hx - 0.03, 0.95, hy - 0.3, (0.1, 0.4, 0.2), HEADLIGHT, HEADLIGHT_GLOW if lights_on else None)
    parts += _lamps(-hx + 0.02, 1.2, hy - 0.2, (0.08, 0.25, 0.15), TAILLIGHT, TAILLIGHT_GLOW if lights_on else None)
    return merge(parts, name=name, kind="vehicle", gloss=0.4)


# Car paint (linear albedo) and how common each is on the street: white, black, grey and silver most, then blue,
# red, beige and green.
CAR_PAINTS = ((0.7, 0.7, 0.68), (0.018, 0.018, 0.02), (0.1, 0.1, 0.11), (0.36, 0.37, 0.38), (0.02, 0.05, 0.2),
              (0.42, 0.025, 0.02), (0.33, 0.27, 0.18), (0.03, 0.09, 0.05))
CAR_PAINT_SHARES = (0.25, 0.2, 0.17, 0.16, 0.09, 0.08, 0.03, 0.02)
VAN_SHARE = 0.15  # the parked vehicles that are panel vans


PARKED_WHEEL_SECTIONS = 6  # parked vehicles stand in rows by the hundred: hexagonal wheels keep them cheap


def parked_vehicle(rng: np.random.Generator) -> tuple[float, float, Callable[[], Mesh]]:
    """A parked car or van in a drawn paint and size, lights off: (length, width, builder of its mesh)."""
    paint = np.asarray(CAR_PAINTS[int(rng.choice(len(CAR_PAINTS), p=CAR_PAINT_SHARES))])
    paint = np.clip(paint * rng.uniform(0.85, 1.15), 0.0, 1.0)
    if rng.random() < VAN_SHARE:
        length, width = float(rng.uniform(4.8, 5.6)), 2.0
        return length, width, lambda: van(paint, length=length, width=width, wheel_sections=PARKED_WHEEL_SECTIONS)
    length, width, height = float(rng.uniform(3.9, 4.9)), float(rng.uniform(1.72, 1.86)), float(rng.uniform(1.4, 1.6))
    return length, width, lambda: car(paint, length=length, width=width, height=height,
                                      wheel_sections=PARKED_WHEEL_SECTIONS)


def _choose(rng: np.random.Generator | None, given: ColorLike | None, palette: tuple) -> FloatArray:
    if given is not None:
        return np.asarray(given, np.float64)
    return pick(rng, palette) if rng is not None else np.asarray(palette[0], np.float64)


def pedestrian(rng: np.random.Generator | None = None, *, shirt: ColorLike | None = None,
               trousers: ColorLike | None = None, skin: ColorLike | None = None, height: float = 1.75,
               walking: bool = False, name: str = "pedestrian") -> Mesh:
    """A person facing +X (about 200 faces): legs, shoes, torso, arms, hands, head with hair.

    Colours not given are drawn from ``rng`` (first palette entry without one); ``walking`` spreads the legs
    and swings the arms in mid-stride.
    """
    shirt, trousers = _choose(rng, shirt, SHIRTS), _choose(rng, trousers, TROUSERS)
    skin, hair = _choose(rng, skin, SKINS), _choose(rng, None, HAIRS)
    k = height / 1.75
    stride, swing = (0.28, 0.22) if walking else (0.0, 0.03)
    hip_z, shoulder_z = 0.92 * k, 1.44 * k
    parts = []
    for side, phase in ((-1.0, 1.0), (1.0, -1.0)):
        foot = np.array([phase * stride * k, side * 0.1 * k, 0.07 * k])
        parts.append(beam((0.0, side * 0.1 * k, hip_z + 0.04 * k), foot, 0.15 * k, 0.14 * k, trousers))
        parts.append(box((0.26 * k, 0.1 * k, 0.08 * k), foot + (0.05 * k, 0.0, -0.03 * k), TRIM))
        hand = np.array([-phase * swing * k, side * 0.27 * k, 0.84 * k])
        parts.append(beam((0.0, side * 0.24 * k, shoulder_z), hand, 0.09 * k, 0.1 * k, shirt))
        parts.append(box((0.07 * k, 0.06 * k, 0.1 * k), hand + (0.0, 0.0, -0.06 * k), skin))
    parts.append(prism([(-0.17 * k, hip_z - 0.04 * k), (0.17 * k, hip_z - 0.04 * k), (0.22 * k, shoulder_z + 0.04 * k),
                        (-0.22 * k, shoulder_z + 0.04 * k)], -0.12 * k, 0.12 * k, shirt, axis="x"))
    parts.append(box((0.09 * k, 0.09 * k, 0.1 * k), (0.0, 0.0, shoulder_z + 0.07 * k), skin))
    parts.append(_head(0.115 * k, np.array([0.0, 0.0, height - 0.12 * k]), skin, hair))
    return merge(parts, name=name, kind="pedestrian")


def _head(radius: float, center: FloatArray, skin: FloatArray, hair: FloatArray) -> Mesh:
    """A low-poly head (80 faces) with the top and back of the head in the hair colour."""
    tm = trimesh.creation.icosphere(subdivisions=1, radius=radius)
    tm.apply_scale((0.9, 0.82, 1.05))
    tm.apply_transform(translation(center))
    c = tm.triangles_center - center
    hairy = (c[:, 2] > 0.35 * radius) | ((c[:, 0] < -0.35 * radius) & (c[:, 2] > -0.3 * radius))
    return to_mesh(tm, np.where(hairy[:, None], hair, skin))


def _knee(hip: FloatArray, foot: FloatArray, bone: float) -> FloatArray:
    """Knee position bending forward (+X) for a two-bone leg of equal bones ``bone``."""
    mid, span = 0.5 * (hip + foot), foot - hip
    d = float(np.linalg.norm(span))
    rise = np.sqrt(max(bone**2 - (0.5 * d) ** 2, 0.0))
    forward = np.array([span[2], 0.0, -span[0]]) / max(d, 1e-9)
    if forward[0] < 0:
        forward = -forward
    return mid + forward * rise


def bicycle_with_rider(rng: np.random.Generator | None = None, *, frame_color: ColorLike | None = None,
                       shirt: ColorLike | None = None, trousers: ColorLike | None = None,
                       name: str = "bicycle") -> Mesh:
    """A bicycle (1.8 m long, wheels in the x-z plane) ridden by a seated person facing +X (about 640 faces)."""
    frame_color = _choose(rng, frame_color, SHIRTS[1:] + SHIRTS[:1])
    shirt, trousers = _choose(rng, shirt, SHIRTS), _choose(rng, trousers, TROUSERS)
    skin, hair = _choose(rng, None, SKINS), _choose(rng, None, HAIRS)
    r, hub = 0.34, 0.54
    parts = []
    for x in (-hub, hub):
        tm = trimesh.creation.torus(major_radius=r - 0.02, minor_radius=0.022, major_sections=16, minor_sections=4)
        tm.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, (1, 0, 0)))
        tm.apply_translation((x, 0.0, r))
        parts.append(to_mesh(tm, TYRE))
        parts += [beam((x - (r - 0.04), 0.0, r), (x + r - 0.04, 0.0, r), 0.01, 0.01, RIM),
                  beam((x, 0.0, 0.04), (x, 0.0, 2 * r - 0.04), 0.01, 0.01, RIM)]
    rear, front = np.array([-hub, 0.0, r]), np.array([hub, 0.0, r])
    bracket, seat = np.array([-0.05, 0.0, 0.3]), np.array([-0.22, 0.0, 0.86])
    head_top, head_low = np.array([0.36, 0.0, 0.88]), np.array([0.41, 0.0, 0.66])
    for p0, p1 in ((rear, bracket), (rear, seat), (bracket, seat), (seat, head_top), (bracket, head_low),
                   (head_low, front), (head_low, head_top)):
        parts.append(beam(p0, p1, 0.035, 0.035, frame_color))
    grips = head_top + (0.05, 0.0, 0.1)
    parts.append(beam(grips + (0.0, -0.26, 0.0), grips + (0.0, 0.26, 0.0), 0.03, 0.03, TRIM))
    parts.append(box((0.24, 0.12, 0.05), seat + (0.0, 0.0, 0.04), TRIM))
    parts += _rider(seat + (0.0, 0.0, 0.08), bracket, grips, shirt, trousers, skin, hair)
    return merge(parts, name=name, kind="bicycle")


def _rider(hip_c: FloatArray, bracket: FloatArray, grips: FloatArray, shirt: FloatArray, trousers: FloatArray,
           skin: FloatArray, hair: FloatArray) -> list[Mesh]:
    shoulder_c = hip_c + (0.3, 0.0, 0.5)
    parts = [beam(hip_c, shoulder_c, 0.4, 0.24, shirt)]
    neck = shoulder_c + (0.06, 0.0, 0.09)
    parts.append(box((0.09, 0.09, 0.1), neck, skin))
    parts.append(_head(0.115, neck + (0.05, 0.0, 0.15), skin, hair))
    for side, crank in ((-1.0, 0.0), (1.0, np.pi)):
        y = side * 0.1
        hip = hip_c + (0.0, y, 0.0)
        pedal = bracket + (0.17 * np.cos(crank), y + side * 0.05, 0.17 * np.sin(crank + 0.4))
        knee = _knee(hip, pedal, 0.46)
        parts += [beam(hip, knee, 0.14, 0.14, trousers), beam(knee, pedal, 0.11, 0.11, trousers),
                  box((0.22, 0.09, 0.07), pedal + (0.04, 0.0, 0.0), TRIM)]
        shoulder = shoulder_c + (0.0, side * 0.2, -0.03)
        hand = grips + (0.0, side * 0.22, 0.0)
        parts += [beam(shoulder, hand, 0.09, 0.09, shirt), box((0.08, 0.06, 0.07), hand, skin)]
    return parts

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
    pane = _panel(corners, (0.0, 1.0, 0.0), color)
    uv = np.array([(x - mid, z - z0) for x, _, z in pane.vertices], np.float32)
    return Mesh(pane.vertices, pane.faces, pane.colors, finish=np.full(len(pane.faces), finish, np.int8), uv=uv)


def _door(x: float, hy: float, width: float, height: float, color: ColorLike) -> Mesh:
    """An entrance door (a glazed door leaf in a dark frame) on the +Y front at x."""
    return _panel([(x - width / 2, hy + 0.02, 0.0), (x + width / 2, hy + 0.02, 0.0),
                   (x + width / 2, hy + 0.02, height), (x - width / 2, hy + 0.02, height)], (0.0, 1.0, 0.0), color)


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
        parts.append(_panel([(-half, hy, SHOP_GLASS_TOP_M + 0.05), (half, hy, SHOP_GLASS_TOP_M + 0.05),
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
    parts.append(_panel([(hx * 0.5 - 0.5, hy + 0.02, 0.0), (hx * 0.5 + 0.5, hy + 0.02, 0.0),
                         (hx * 0.5 + 0.5, hy + 0.02, 2.1), (hx * 0.5 - 0.5, hy + 0.02, 2.1)],
                        (0.0, 1.0, 0.0), (0.12, 0.06, 0.03)))
    return merge(parts, name=name, kind="building", gloss=0.05)


# Street furniture on the sidewalk: litter bins, bollards and sign posts (a traffic sign facing the oncoming
# driver: the red ring of a prohibition or speed limit, the blue disc of a mandatory sign, a yellow warning plate).
STREET_GREEN = (0.03, 0.07, 0.04)
BOLLARD_GREY = (0.1, 0.1, 0.1)
SIGN_FACES = ((0.55, 0.03, 0.02), (0.02, 0.1, 0.45), (0.7, 0.5, 0.02))
SIGN_BACK = (0.35, 0.35, 0.35)


def litter_bin(name: str = "bin") -> Mesh:
    """A round street litter bin (0.9 m tall): a dark green body under a lid."""
    return merge([cylinder(0.28, 0.85, (0.0, 0.0, 0.425), STREET_GREEN, sections=10),
                  cylinder(0.31, 0.08, (0.0, 0.0, 0.89), np.asarray(STREET_GREEN) * 0.7, sections=10)],
                 name=name, kind="pole", gloss=0.2)


def bollard(name: str = "bollard") -> Mesh:
    """A steel bollard (1 m tall) with a white reflective band near its top."""
    return merge([cylinder(0.09, 0.82, (0.0, 0.0, 0.41), BOLLARD_GREY, sections=8),
                  cylinder(0.095, 0.1, (0.0, 0.0, 0.87), (0.7, 0.7, 0.68), sections=8),
                  cylinder(0.09, 0.08, (0.0, 0.0, 0.96), BOLLARD_GREY, sections=8)], name=name, kind="pole",
                 gloss=0.3)


def sign_post(rng: np.random.Generator, name: str = "sign") -> Mesh:
    """A traffic sign on a 2.6 m galvanised post, its face towards -X (the driver coming along +X)."""
    face = pick(rng, SIGN_FACES)
    plate = [box((0.03, 0.62, 0.62), (0.02, 0.0, 2.55), SIGN_BACK),
             box((0.01, 0.56, 0.56), (-0.005, 0.0, 2.55), (0.75, 0.75, 0.72)),
             box((0.012, 0.44, 0.44), (-0.012, 0.0, 2.55), face)]
    return merge([cylinder(0.035, 2.9, (0.03, 0.0, 1.45), (0.45, 0.46, 0.47), sections=6), *plate], name=name,
                 kind="pole", gloss=0.3)


# Traffic signals: a dark housing of three lamps (red over amber over green), one lit; the lit lamp's radiance is
# that of a signal's LEDs (thousands of cd/m2: about a sunlit white wall's by day, far above everything at night).
SIGNAL_ASPECTS = ("red", "amber", "green")
SIGNAL_LAMPS = ((0.9, 0.03, 0.02), (0.95, 0.45, 0.02), (0.05, 0.85, 0.45))
SIGNAL_GLOW = 4.0
SIGNAL_HOUSING = (0.015, 0.015, 0.017)
SIGNAL_HEAD_Z_M = 2.9  # the head's lowest lamp's centre above the ground


def traffic_signal(aspect: str, name: str = "traffic signal") -> Mesh:
    """A traffic signal on a 3.6 m dark pole, its lamps towards -X (the driver coming along +X), ``aspect`` (one of
    ``SIGNAL_ASPECTS``) lit, the other lamps dark glass (about 100 faces)."""
    lit = SIGNAL_ASPECTS.index(aspect)
    z_lamps = SIGNAL_HEAD_Z_M + 0.3 * np.arange(3)[::-1]
    parts = [cylinder(0.06, 3.6, (0.0, 0.0, 1.8), SIGNAL_HOUSING, sections=8),
             box((0.22, 0.34, 1.0), (-0.08, 0.0, SIGNAL_HEAD_Z_M + 0.3), SIGNAL_HOUSING),
             box((0.02, 0.52, 1.2), (0.04, 0.0, SIGNAL_HEAD_Z_M + 0.3), SIGNAL_HOUSING)]  # backplate
    for k, (color, z) in enumerate(zip(SIGNAL_LAMPS, z_lamps)):
        on = k == lit
        parts.append(box((0.02, 0.2, 0.2), (-0.2, 0.0, z), color if on else np.asarray(color) * 0.08,
                         emission=np.asarray(color) * SIGNAL_GLOW if on else np.zeros(3)))
        parts.append(box((0.14, 0.24, 0.03), (-0.26, 0.0, z + 0.12), SIGNAL_HOUSING))  # the visor over it
    return merge(parts, name=name, kind="pole", gloss=0.3)


# New Jersey barrier cross-section (y, z), metres: 0.61 m base, 0.15 m top, 0.81 m tall.
JERSEY_PROFILE = ((-0.305, 0.0), (0.305, 0.0), (0.305, 0.075), (0.2, 0.33), (0.075, 0.81), (-0.075, 0.81),
                  (-0.2, 0.33), (-0.305, 0.075))


def jersey_barrier(length: float = 4.0, color: ColorLike = CONCRETE, name: str = "barrier") -> Mesh:
    """One concrete New Jersey barrier segment along X (28 faces), sunk 5 cm into the ground."""
    profile = np.array(JERSEY_PROFILE) - (0.0, 0.05)
    return prism(profile, -length / 2, length / 2, color, axis="x", name=name, kind="barrier")


def tunnel_portal(width: float = 14.0, height: float = 6.0, *, lining: float = 8.0, hill_height: float = 16.0,
                  hill_width: float = 45.0, hill_depth: float = 12.0, name: str = "tunnel portal") -> Mesh:
    """A tunnel mouth facing -X: a concrete portal wall around a ``width`` x ``height`` opening, a dark lining
    running ``lining`` m into +X, and a hillside rising around and over it up to x = ``hill_depth``.

    The opening spans |y| < width/2, 0 < z < height at x = 0; nothing else enters that box. At x = hill_depth
    the hill's cross-section on each side is ``hill_profile(width / 2 + 0.4, ...)`` so a swept continuation
    joins it.
    """
    hw, wall = width / 2, 1.2
    top = height + 2.2
    lining_dark = (0.03, 0.03, 0.03)
    parts = [box((0.8, wall + 1.5, top + 0.5), (-0.4, side * (hw + (wall + 1.5) / 2), (top - 0.5) / 2), CONCRETE)
             for side in (-1.0, 1.0)]
    parts.append(box((0.8, width + 0.1, top - height), (-0.4, 0.0, (top + height) / 2), CONCRETE))
    parts.append(box((1.2, width + 2 * wall + 3.4, 0.35), (-0.5, 0.0, top + 0.1), np.asarray(CONCRETE) * 0.8))
    parts += [box((lining, 0.4, height + 0.5), (lining / 2, side * (hw + 0.2), height / 2 - 0.25), lining_dark)
              for side in (-1.0, 1.0)]
    parts.append(box((lining, width + 0.8, 0.4), (lining / 2, 0.0, height + 0.2), lining_dark))
    crest = max(hill_height, top + 2.0)
    for side in (-1.0, 1.0):
        parts.append(_hill_side(hw + 0.4, hw + wall + 1.5, hill_width, crest, hill_depth, side))
    top_mass = prism([(-0.8, top), (hill_depth, top), (hill_depth, crest), (3.0, crest)], -hw - wall - 1.6,
                     hw + wall + 1.6, EARTH[0], axis="y")
    parts.append(top_mass)
    return merge(parts, name=name, kind="tunnel")


EARTH = ((0.06, 0.1, 0.03), (0.08, 0.11, 0.035), (0.1, 0.09, 0.045), (0.05, 0.08, 0.03))


def hill_profile(inner: float, hill_width: float, crest: float) -> FloatArray:
    """(5, 2) convex (|t|, h) cross-section of the hill beside a tunnel, from the tube wall at ``inner`` out."""
    return np.array([(inner, -0.3), (inner + hill_width, -0.3), (inner + hill_width, 0.25 * crest),
                     (inner + 0.45 * hill_width, 0.85 * crest), (inner, crest)])


def earth_colors(centers: FloatArray) -> FloatArray:
    """(m, 3) hillside greens and browns, varied face by face from the face centres (m, 3)."""
    palette = np.asarray(EARTH)
    key = np.floor(np.abs(centers @ np.array([0.37, 0.61, 0.23]))).astype(np.int64)
    return palette[key % len(palette)] * (0.85 + 0.3 * ((key * 7) % 5) / 4)[:, None]


def _hill_side(inner: float, portal_edge: float, hill_width: float, crest: float, depth: float,
               side: float) -> Mesh:
    """The hill beside the portal on ``side``: a loft from its foot in front of the portal (its inner edge
    at the portal wall's outer edge) back to the ``hill_profile`` section at x = depth."""
    back = [(depth, t, h) for t, h in hill_profile(inner, hill_width, crest)]
    front = [(-10.0, portal_edge, -0.3), (-4.0, inner + hill_width, -0.3), (0.0, inner + hill_width, 0.25 * crest),
             (2.0, inner + 0.45 * hill_width, 0.85 * crest), (1.0, portal_edge, crest)]
    rings = np.array([front, back]) * (1.0, side, 1.0)
    hill = loft(rings, name="hillside", kind="terrain")
    hill.colors = earth_colors(hill.vertices[hill.faces].mean(1)).astype(np.float32)
    return hill
