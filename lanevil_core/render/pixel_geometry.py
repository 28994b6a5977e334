"""Where a pixel lies (numba helpers inlined into ``shading``): its camera ray, the face's normal turned to the
viewer, the pixel's footprint on the face by ray differentials (in road coordinates, in a facade's coordinates,
as world steps), its road coordinates from the barycentric weights, and the ray mirrored about the normal."""

from __future__ import annotations

import numpy as np

from ._jit import kernel

MIN_SLOPE_SINE = 0.2  # a facade coordinate's footprint up a face no flatter than this (12 deg roofs and steeper)
FOOTPRINT_SCALE = 0.75  # box-filter width in pixels' worth of road coordinate
MAX_FOOTPRINT_M = 50.0


@kernel(inline="always")
def pixel_ray(R_world_camera: np.ndarray, x_cam: float, y_cam: float) -> tuple[float, float, float, float]:
    """(dx, dy, dz, norm): the unit world direction through camera-plane point (x_cam, y_cam, 1) and that
    point's length (camera z to distance along the ray)."""
    R = R_world_camera
    norm = np.sqrt(x_cam * x_cam + y_cam * y_cam + 1.0)
    inv_norm = 1.0 / norm
    dx = (R[0, 0] * x_cam + R[0, 1] * y_cam + R[0, 2]) * inv_norm
    dy = (R[1, 0] * x_cam + R[1, 1] * y_cam + R[1, 2]) * inv_norm
    dz = (R[2, 0] * x_cam + R[2, 1] * y_cam + R[2, 2]) * inv_norm
    return dx, dy, dz, norm


@kernel(inline="always")
def facing_normal(normal: np.ndarray, f: int, dx: float, dy: float,
                  dz: float) -> tuple[float, float, float, float]:
    """(nx, ny, nz, n.v): the face's world normal turned towards the viewer (faces are two-sided)."""
    nx, ny, nz = normal[f, 0], normal[f, 1], normal[f, 2]
    n_dot_v = -(nx * dx + ny * dy + nz * dz)
    if n_dot_v < 0.0:
        return -nx, -ny, -nz, -n_dot_v
    return nx, ny, nz, n_dot_v


@kernel(inline="always")
def gradients_camera(R_world_camera: np.ndarray, grad_st: np.ndarray,
                     f: int) -> tuple[float, float, float, float, float, float]:
    """The world gradients of s and of t on road face ``f`` in camera axes: (s_x, s_y, s_z, t_x, t_y, t_z)."""
    R = R_world_camera
    sx, sy, sz, tx, ty, tz = grad_st[f, 0], grad_st[f, 1], grad_st[f, 2], grad_st[f, 3], grad_st[f, 4], grad_st[f, 5]
    return (sx * R[0, 0] + sy * R[1, 0] + sz * R[2, 0], sx * R[0, 1] + sy * R[1, 1] + sz * R[2, 1],
            sx * R[0, 2] + sy * R[1, 2] + sz * R[2, 2], tx * R[0, 0] + ty * R[1, 0] + tz * R[2, 0],
            tx * R[0, 1] + ty * R[1, 1] + tz * R[2, 1], tx * R[0, 2] + ty * R[1, 2] + tz * R[2, 2])


@kernel(inline="always")
def coordinate_step(g_x_cam: float, g_y_cam: float, g_z_cam: float, x_cam: float, y_cam: float, k_u: float,
                    k_v: float, su: float, sv: float) -> float:
    """How much a road coordinate with gradient g (camera axes) changes across one pixel: its steps along the
    pixel's ray differentials u = su (x - r k_u) and v = sv (y - r k_v) on the face's plane, r = (x_cam, y_cam, 1)."""
    g_dot_r = g_x_cam * x_cam + g_y_cam * y_cam + g_z_cam
    step = abs(su * (g_x_cam - g_dot_r * k_u)) + abs(sv * (g_y_cam - g_dot_r * k_v))
    return min(FOOTPRINT_SCALE * step + 1e-3, MAX_FOOTPRINT_M)


@kernel(inline="always")
def road_footprint(R_world_camera: np.ndarray, fx: float, fy: float,
                   grad_cam: tuple[float, float, float, float, float, float], depth: float, norm: float,
                   x_cam: float, y_cam: float, nx: float, ny: float, nz: float, n_dot_v: float) -> tuple[float, float]:
    """(fs, ft): how much s and t change across the pixel, by ray differentials on the face's plane (exact for
    the affine (s, t) of a road triangle); ``grad_cam`` is the face's ``gradients_camera``."""
    R = R_world_camera
    n_dot_r = -max(n_dot_v, 1e-4) * norm  # n faces the viewer, so n.ray < 0
    k_u = (nx * R[0, 0] + ny * R[1, 0] + nz * R[2, 0]) / n_dot_r
    k_v = (nx * R[0, 1] + ny * R[1, 1] + nz * R[2, 1]) / n_dot_r
    su, sv = depth / fx, depth / fy
    fs = coordinate_step(grad_cam[0], grad_cam[1], grad_cam[2], x_cam, y_cam, k_u, k_v, su, sv)
    ft = coordinate_step(grad_cam[3], grad_cam[4], grad_cam[5], x_cam, y_cam, k_u, k_v, su, sv)
    return fs, ft


@kernel(inline="always")
def pixel_steps(R_world_camera: np.ndarray, fx: float, fy: float, depth: float, norm: float, dx: float, dy: float,
                dz: float, nx: float, ny: float, nz: float,
                n_dot_v: float) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """(du, dv): the world steps on the face's plane (normal n, facing the viewer) between the pixel and its
    neighbours across and down, by ray differentials (see ``road_footprint``)."""
    R = R_world_camera
    n_dot_r = -max(n_dot_v, 1e-4) * norm
    k_u = (nx * R[0, 0] + ny * R[1, 0] + nz * R[2, 0]) / n_dot_r
    k_v = (nx * R[0, 1] + ny * R[1, 1] + nz * R[2, 1]) / n_dot_r
    su, sv = depth / fx, depth / fy
    rx, ry, rz = dx * norm, dy * norm, dz * norm  # the pixel's ray (camera z = 1) in world axes
    return ((su * (R[0, 0] - k_u * rx), su * (R[1, 0] - k_u * ry), su * (R[2, 0] - k_u * rz)),
            (sv * (R[0, 1] - k_v * rx), sv * (R[1, 1] - k_v * ry), sv * (R[2, 1] - k_v * rz)))


@kernel(inline="always")
def facade_footprint(du: tuple[float, float, float], dv: tuple[float, float, float], nx: float, ny: float,
                     nz: float) -> tuple[float, float]:
    """(fu, fv): how far the pixel's footprint (world steps du, dv on the face's plane) reaches along a wall or
    roof (the horizontal in the face's plane) and up it (up a roof's slope: its rise over the slope's sine)."""
    hx, hy = -ny, nx
    h = np.sqrt(hx * hx + hy * hy)
    if h > 1e-6:
        hx, hy = hx / h, hy / h
    else:  # a horizontal face: "along" is any horizontal, x
        hx, hy = 1.0, 0.0
    fu = abs(du[0] * hx + du[1] * hy) + abs(dv[0] * hx + dv[1] * hy)
    fv = (abs(du[2]) + abs(dv[2])) / max(np.sqrt(max(1.0 - nz * nz, 0.0)), MIN_SLOPE_SINE)
    return min(FOOTPRINT_SCALE * fu + 1e-3, MAX_FOOTPRINT_M), min(FOOTPRINT_SCALE * fv + 1e-3, MAX_FOOTPRINT_M)


@kernel(inline="always")
def road_coordinates(faces: np.ndarray, vertex_st: np.ndarray, bary: np.ndarray, row: int, col: int,
                     f: int) -> tuple[float, float]:
    """(s, t) of the pixel on road face ``f`` from its perspective-correct barycentric weights."""
    b1 = bary[row, col, 0]
    b2 = bary[row, col, 1]
    b0 = 1.0 - b1 - b2
    i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
    s = b0 * vertex_st[i0, 0] + b1 * vertex_st[i1, 0] + b2 * vertex_st[i2, 0]
    t = b0 * vertex_st[i0, 1] + b1 * vertex_st[i1, 1] + b2 * vertex_st[i2, 1]
    return s, t


@kernel(inline="always")
def object_plane(px: float, py: float, pz: float, nx: float, ny: float, nz: float) -> tuple[float, float]:
    """Two world coordinates (m) across an object's face: the pair the face's normal is least aligned with."""
    ax, ay, az = abs(nx), abs(ny), abs(nz)
    if az >= ax and az >= ay:
        return px, py
    if ax >= ay:
        return py, pz
    return px, pz


@kernel(inline="always")
def mirrored_ray(dx: float, dy: float, dz: float, nx: float, ny: float, nz: float) -> tuple[float, float, float]:
    """The view ray reflected about the normal."""
    dot = dx * nx + dy * ny + dz * nz
    return dx - 2.0 * dot * nx, dy - 2.0 * dot * ny, dz - 2.0 * dot * nz
