"""The canonical "push toward +u" frame of CBST.

Every axis-aligned push is handled by one implementation written for a push toward ``+x``
(thesis §3.2: "for other axis-aligned pushes it is essentially the same, up to changing signs
and/or swapping x and y coordinates"). A :class:`CanonicalFrame` maps world poses, half-widths
and boxes into coordinates ``(u, v, phi)`` in which the push goes toward ``+u``, and back.

The map is the rotation of the plane by ``-alpha``, ``alpha`` the push direction's angle (a
multiple of 90 degrees), so coordinates are only swapped and negated::

    +x: (u, v) = ( x,  y)      -x: (u, v) = (-x, -y)
    +y: (u, v) = ( y, -x)      -y: (u, v) = (-y,  x)

It is a proper rotation (never a mirror), so the physics is exactly the same in both frames:
friction is isotropic, and the walls of a rectangular table map onto walls.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from arrange_up.geometry.se2 import rotate_cs
from arrange_up.geometry.shapes import Box, HalfWidths, Pose

__all__ = ["CanonicalFrame", "DIRECTION_NAMES"]

#: Direction name -> (unit vector, world wall ahead, world wall at low v, world wall at high v).
_DIRECTIONS: dict[str, tuple[tuple[int, int], str, str, str]] = {
    "+x": ((1, 0), "right", "bottom", "top"),
    "-x": ((-1, 0), "left", "top", "bottom"),
    "+y": ((0, 1), "top", "right", "left"),
    "-y": ((0, -1), "bottom", "left", "right"),
}
DIRECTION_NAMES: tuple[str, ...] = tuple(_DIRECTIONS)


@dataclass(frozen=True)
class CanonicalFrame:
    """The frame in which a push along ``direction`` (``"+x"``, ``"-x"``, ``"+y"``, ``"-y"``)
    goes toward ``+u``."""

    direction: str

    def __post_init__(self) -> None:
        if self.direction not in _DIRECTIONS:
            raise ValueError(
                f"unknown push direction {self.direction!r}; expected one of "
                + ", ".join(DIRECTION_NAMES)
            )

    # -- construction ----------------------------------------------------------------------
    @classmethod
    def of_vector(cls, ux: float, uy: float, tol: float = 1e-6) -> CanonicalFrame | None:
        """The frame of a push along the unit vector ``(ux, uy)``; None if it is not
        axis-aligned within ``tol``."""
        for name, ((cx, cy), *_rest) in _DIRECTIONS.items():
            if abs(ux - cx) <= tol and abs(uy - cy) <= tol:
                return cls(name)
        return None

    # -- properties ------------------------------------------------------------------------
    @property
    def vector(self) -> tuple[int, int]:
        """The push direction in the world frame."""
        return _DIRECTIONS[self.direction][0]

    @property
    def angle(self) -> float:
        """``alpha``: the angle of the push direction in the world (radians)."""
        cx, cy = self.vector
        return math.atan2(cy, cx)

    @property
    def swaps(self) -> bool:
        """True when ``u`` runs along the world's ``y`` axis (half-widths swap)."""
        return self.vector[0] == 0

    @property
    def wall_ahead(self) -> str:
        """Name of the table wall the push moves toward."""
        return _DIRECTIONS[self.direction][1]

    @property
    def side_walls(self) -> tuple[str, str]:
        """Names of the walls bounding ``v`` from below and from above."""
        _, _, low, high = _DIRECTIONS[self.direction]
        return low, high

    # -- points and poses ------------------------------------------------------------------
    def point_to(self, x: float, y: float) -> tuple[float, float]:
        c, s = self.vector
        u, v = rotate_cs((x, y), c, -s)  # by -alpha
        return (u + 0.0, v + 0.0)  # + 0.0: no negative zeros

    def point_from(self, u: float, v: float) -> tuple[float, float]:
        c, s = self.vector
        x, y = rotate_cs((u, v), c, s)  # by +alpha
        return (x + 0.0, y + 0.0)

    def pose_to(self, pose: Pose) -> Pose:
        u, v = self.point_to(pose[0], pose[1])
        return (u, v, pose[2] - self.angle)

    def pose_from(self, pose: Pose) -> Pose:
        x, y = self.point_from(pose[0], pose[1])
        return (x, y, pose[2] + self.angle)

    def half_to(self, half: HalfWidths) -> HalfWidths:
        return (half[1], half[0], half[2]) if self.swaps else tuple(half)  # type: ignore[return-value]

    half_from = half_to  # swapping is its own inverse

    def box_to(self, box: Box) -> Box:
        """A world box ``(xmin, ymin, xmax, ymax)`` as a canonical ``(umin, vmin, umax, vmax)``."""
        u0, v0 = self.point_to(box[0], box[1])
        u1, v1 = self.point_to(box[2], box[3])
        return (min(u0, u1), min(v0, v1), max(u0, u1), max(v0, v1))

    def table_box(self, size: tuple[float, float]) -> Box:
        """The table ``[0, W] x [0, D]`` in canonical coordinates."""
        return self.box_to((0.0, 0.0, float(size[0]), float(size[1])))
