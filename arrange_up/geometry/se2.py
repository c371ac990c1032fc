"""SE(2), the rigid motions of the plane: poses, their composition and inverse, and points and
vectors moved by them.

A :data:`Pose` ``(x, y, theta)`` places a frame in its parent (the world, or another pose's
frame): a point ``p`` of the frame lands at ``R(theta) @ p + (x, y)``, angles in radians,
counter-clockwise positive. Every hand-written rotation of the package goes through here.

Floating point: each function fixes the order of its operations, and callers rely on it (plans
and simulations are reproduced bit for bit). The scalar functions add the translation *first*
(``x + c*px - s*py``, left to right); the vectorised :func:`transform_points` adds it *last*
(``(px*c - py*s) + x``). The two can differ in the last bit; do not substitute one for the
other where results are pinned.
"""

from __future__ import annotations

import math

import numpy as np

Point = tuple[float, float]
"""``(x, y)``."""
Pose = tuple[float, float, float]
"""``(x, y, theta)``: position of a frame's origin in its parent and its rotation (radians)."""

__all__ = [
    "Point",
    "Pose",
    "compose",
    "inverse",
    "relative",
    "rotate",
    "rotate_cs",
    "transform_point",
    "transform_points",
]


def rotate_cs(vector: Point, c: float, s: float) -> Point:
    """``vector`` rotated by the angle whose cosine and sine are ``c`` and ``s``:
    ``(c*x - s*y, s*x + c*y)``. For exact rotations (quarter turns with integer ``c``, ``s``)."""
    x, y = vector
    return (c * x - s * y, s * x + c * y)


def rotate(vector: Point, theta: float) -> Point:
    """``vector`` rotated by ``theta``: ``R(theta) @ vector``."""
    return rotate_cs(vector, math.cos(theta), math.sin(theta))


def transform_point(point: Point, pose: Pose) -> Point:
    """``point`` of ``pose``'s frame in the parent frame: ``(x + c*px - s*py, y + s*px + c*py)``."""
    px, py = point
    x, y, theta = pose
    c, s = math.cos(theta), math.sin(theta)
    return (x + c * px - s * py, y + s * px + c * py)


def compose(parent: Pose, child: Pose) -> Pose:
    """The pose, in ``parent``'s parent frame, of ``child`` given in ``parent``'s frame."""
    x, y = transform_point((child[0], child[1]), parent)
    return (x, y, parent[2] + child[2])


def inverse(pose: Pose) -> Pose:
    """The pose of the parent frame in ``pose``'s frame: ``compose(pose, inverse(pose))`` is the
    identity (up to rounding)."""
    x, y, theta = pose
    c, s = math.cos(theta), math.sin(theta)
    return (-(c * x + s * y), s * x - c * y, -theta)


def relative(reference: Pose, pose: Pose) -> Pose:
    """``pose`` (in the parent frame) expressed in ``reference``'s frame:
    ``R(-theta_ref) @ (p - p_ref)`` and ``theta - theta_ref``."""
    dx, dy = pose[0] - reference[0], pose[1] - reference[1]
    c, s = math.cos(reference[2]), math.sin(reference[2])
    return (c * dx + s * dy, -s * dx + c * dy, pose[2] - reference[2])


def transform_points(points: np.ndarray, pose: Pose) -> np.ndarray:
    """Map ``(N, 2)`` points of ``pose``'s frame to the parent: ``R(theta) @ p + (x, y)``.

    Returns a new ``(N, 2)`` float array. Computed element-wise (not with a matrix product) so
    that equal input points always give bit-identical outputs, whichever array they are in;
    :func:`arrange_up.geometry.shapes.footprint` relies on that for shared edges of neighbouring
    parts to stay shared.
    """
    p = np.asarray(points, dtype=float)
    x, y, theta = pose
    c, s = math.cos(theta), math.sin(theta)
    out = np.empty(p.shape, dtype=float)
    out[..., 0] = p[..., 0] * c - p[..., 1] * s + x
    out[..., 1] = p[..., 0] * s + p[..., 1] * c + y
    return out
