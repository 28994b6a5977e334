"""Procedural low-poly vehicles: a saloon car, a panel van and a box truck, with dark glass, wheels and lamps
(lit at night), and the parked cars and vans of a street in drawn car paint (``parked_vehicle``).

Every builder returns a ``Mesh`` in its own local frame: +X forward, +Y left, +Z up, origin on the ground at the
centre of the footprint; ``scenery`` parks them beside the road, ``illusions.traffic`` drives them and
``illusions.reflection`` mirrors them in a wet road. Dimensions are real (metres); colours are linear albedo.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..typed import FloatArray
from .primitives import ColorLike, PointsLike, box, cylinder, facing_quad, merge, prism
from .props import GLASS, RIM, TRIM, TYRE
from .scene import Mesh

# A saloon's body is drawn in at its sill and shoulders (the profile's points, m from each side), and its cabin's
# sides lean in towards the roof: a rounded car, not two boxes.
BODY_INSET = (0.05, 0.05, 0.02, 0.09, 0.09, 0.03)
TUMBLEHOME = 0.14

# Linear albedos of the lamps, and the radiance of the lit ones.
HEADLIGHT = (0.8, 0.8, 0.75)
TAILLIGHT = (0.55, 0.01, 0.01)
HEADLIGHT_GLOW = (6.0, 5.6, 4.8)
TAILLIGHT_GLOW = (2.5, 0.05, 0.02)


def _slanted_panel(a_xz: ColorLike, b_xz: ColorLike, half_y: float, inset: float, outward_xz: ColorLike,
                   color: ColorLike, narrow: tuple[float, float] = (0.0, 0.0)) -> Mesh:
    """A window on the slanted face through (x, z) points a and b, across |y| < half_y (less ``narrow`` at a and
    at b: a cabin whose sides lean in), inset along the edge by ``inset`` and lifted 2.5 cm off the face."""
    a, b = np.asarray(a_xz, np.float64), np.asarray(b_xz, np.float64)
    n = np.asarray(outward_xz, np.float64)
    n = n / np.linalg.norm(n)
    edge = (b - a) / np.linalg.norm(b - a)
    a, b = a + edge * inset + 0.025 * n, b - edge * inset + 0.025 * n
    ya, yb = half_y - narrow[0], half_y - narrow[1]
    corners = [(a[0], -ya, a[1]), (b[0], -yb, b[1]), (b[0], yb, b[1]), (a[0], ya, a[1])]
    return facing_quad(corners, (n[0], 0.0, n[1]), color)


def _side_panels(polygon_xz: PointsLike, half_y: float, color: ColorLike,
                 lean: tuple[float, float, float] = (0.0, 1.0, 0.0)) -> list[Mesh]:
    """The same (4, 2) window outline on both sides (|y| = half_y + 2 cm), each facing outwards; ``lean`` (z0, z1,
    inset): a side leaning in by ``inset`` from height z0 to z1 carries its window on its slope."""
    polygon_xz = np.asarray(polygon_xz, np.float64)
    z0, z1, inset = lean
    panels = []
    for side in (-1.0, 1.0):
        corners = [(x, side * (half_y + 0.02 - inset * (z - z0) / (z1 - z0)), z) for x, z in polygon_xz]
        outward = (0.0, side * (z1 - z0), inset)
        panels.append(facing_quad(corners, outward, color))
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
    """A saloon car (about 440 faces; 320 with 8 ``wheel_sections``): body, glasshouse with dark windows, four
    wheels, head and tail lights."""
    hx, hy = length / 2, width / 2
    body = prism([(-hx, 0.22), (hx - 0.05, 0.22), (hx, 0.5), (hx - 0.2, 0.8), (-hx + 0.1, 0.86), (-hx, 0.6)],
                 -hy, hy, color, inset=BODY_INSET)
    zb, zt = 0.82, height
    rear_b, front_b, front_t, rear_t = -0.41 * length, 0.19 * length, 0.0, -0.32 * length
    cabin_hy = hy - 0.07
    cabin = prism([(rear_b, zb), (front_b, zb), (front_t, zt), (rear_t, zt)], -cabin_hy, cabin_hy, color,
                  inset=(0.0, 0.0, TUMBLEHOME, TUMBLEHOME))
    narrow = (0.0, TUMBLEHOME - 0.01)  # the screens' ends: at the cabin's foot, at its roof
    parts = [body, cabin,
             _slanted_panel((front_b, zb), (front_t, zt), cabin_hy - 0.06, 0.05, (zt - zb, front_b - front_t), GLASS,
                            narrow),
             _slanted_panel((rear_t, zt), (rear_b, zb), cabin_hy - 0.06, 0.05, (zb - zt, rear_t - rear_b), GLASS,
                            narrow[::-1])]
    for front_window in (True, False):
        parts += _side_panels(_window_outline((rear_b, rear_t), (front_b, front_t), zb, zt, -0.12 * length,
                                              front_window), cabin_hy, GLASS, (zb, zt, TUMBLEHOME))
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
    """A panel van (about 410 faces; 300 with 8 ``wheel_sections``): tall body with a short sloped nose, cab
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
    parts += [facing_quad([(-hx - 0.01, side * 0.08, 1.35), (-hx - 0.01, side * (hy - 0.12), 1.35),
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
    parts.append(facing_quad([(x_glass, -hy + 0.1, 1.75), (x_glass, hy - 0.1, 1.75), (x_glass, hy - 0.1, z_top),
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


PARKED_WHEEL_SECTIONS = 8  # parked vehicles stand in rows by the hundred: octagonal wheels (with hubs) keep them cheap


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
