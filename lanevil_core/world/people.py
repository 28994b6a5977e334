"""Procedural low-poly people: a pedestrian (standing or in mid-stride) and a cyclist seated on a bicycle, in
shirts, trousers, skins and hair drawn from palettes.

Every builder returns a ``Mesh`` in its own local frame: +X forward (the way the person faces), +Y left, +Z up,
origin on the ground at the centre of the footprint; ``scenery`` places pedestrians on the sidewalks and
``illusions.traffic`` moves pedestrians and cyclists. Dimensions are real (metres); colours are linear albedo.
"""

from __future__ import annotations

import numpy as np
import trimesh

from ..typed import FloatArray
from .primitives import ColorLike, beam, box, merge, pick, prism, to_mesh, translation
from .props import RIM, TRIM, TYRE
from .scene import Mesh

# Linear albedos a person is drawn in: shirts, trousers, skins, hair.
SHIRTS = ((0.5, 0.04, 0.03), (0.03, 0.08, 0.35), (0.6, 0.6, 0.58), (0.05, 0.05, 0.05), (0.08, 0.25, 0.07),
          (0.7, 0.45, 0.02), (0.35, 0.12, 0.3), (0.8, 0.22, 0.02))
TROUSERS = ((0.02, 0.03, 0.1), (0.03, 0.03, 0.03), (0.15, 0.12, 0.08), (0.18, 0.18, 0.19), (0.05, 0.08, 0.2))
SKINS = ((0.6, 0.38, 0.27), (0.45, 0.27, 0.17), (0.25, 0.13, 0.07), (0.12, 0.06, 0.035), (0.7, 0.5, 0.38))
HAIRS = ((0.02, 0.015, 0.01), (0.12, 0.06, 0.02), (0.35, 0.25, 0.1), (0.3, 0.3, 0.3))


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
