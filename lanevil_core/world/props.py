"""Procedural low-poly street furniture (litter bins, bollards, sign posts, traffic signals), New Jersey
barriers, a tunnel portal in its hillside, and the albedos shared by several builders of roadside things.

Every builder returns a ``Mesh`` in its own local frame: +X forward, +Y left, +Z up, origin on the ground at
the centre of the footprint. Place it with ``primitives.transformed(mesh, primitives.pose_on_road(...))``.
Dimensions are real (metres); colours are linear albedo. Vehicles are in ``vehicles``, people and cyclists in
``people``, buildings in ``buildings``, trees and bushes in ``vegetation``.
"""

from __future__ import annotations

import numpy as np

from ..typed import FloatArray
from .primitives import ColorLike, box, cylinder, loft, merge, pick, prism
from .scene import Mesh

# Linear albedos shared by several builders: the dark glass of windows (a vehicle's, what lies behind a
# building's), tyres, wheel hubs, black trim (bumpers, shoes, saddles), concrete.
GLASS = (0.012, 0.016, 0.022)
TYRE = (0.018, 0.018, 0.02)
RIM = (0.22, 0.22, 0.23)
TRIM = (0.03, 0.03, 0.032)
CONCRETE = (0.36, 0.35, 0.33)


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
