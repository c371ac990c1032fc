"""Obstacles in a push's way: where a part's shadow meets one, and how to go round it.

A problem's obstacles (``kind: obstacle``) never move. A part pushed into one jams there (it
stops, or turns round the corner), and a paddle that sweeps into one stalls. The action
generator (:mod:`arrange_up.planning.actions`) asks this module three things, all by
axis-aligned boxes: the obstacles' (:attr:`CollisionChecker.obstacle_boxes
<arrange_up.geometry.collision.CollisionChecker.obstacle_boxes>`) and the belief shadows'.

* **The face ahead** (:meth:`Obstacles.face_ahead`): the nearest near face, along a push, of
  an obstacle (or of a given extra box, such as a fixture's shadow) across a band (the part's
  *swath*, its shadow's extent across the push): where a push would jam the part, so where a
  push is cut short or squeezes the part.
* **Blocking** (:meth:`Obstacles.blocking`): the obstacles across a band between the part's
  shadow and where its shadow would be moved a travel (to the goal's coordinate): the straight
  push there jams.
* **The sweep** (:meth:`Obstacles.swept`): the obstacles outside the part's swath that a
  paddle's approach shadow would meet while travelling a distance: the paddle must be shifted
  along its long side to pass them.

The generator widens the band by ``GAP`` for blocking, and moves a part sideways until its
shadow clears the obstacle by ``GAP``, so a part moved round an obstacle is no longer blocked.
"""

from __future__ import annotations

from arrange_up.geometry.boxes import Box
from arrange_up.geometry.collision import CollisionChecker

#: Gap (in) kept between a part's shadow and an obstacle: a push cut short stops the part's
#: shadow this far before the obstacle, and a detour moves it this far clear of the obstacle.
GAP = 0.1


def near_face(box: Box, axis: int, sign: int) -> float:
    """The signed coordinate (``sign * x``) of ``box``'s face that a push along ``axis`` in
    direction ``sign`` meets first (its rear, seen along the push)."""
    return sign * (box[axis] if sign > 0 else box[axis + 2])


def far_face(box: Box, axis: int, sign: int) -> float:
    """The signed coordinate of ``box``'s face that leads along ``axis`` in direction ``sign``."""
    return sign * (box[axis + 2] if sign > 0 else box[axis])


class Obstacles:
    """The fixed obstacles of one problem, as boxes (see the module docstring).

    Positions along a push are *signed* coordinates (``sign * x``, growing along the push);
    a band ``(low, high)`` is an interval of world coordinates across it."""

    def __init__(self, checker: CollisionChecker) -> None:
        self.boxes: dict[str, Box] = dict(checker.obstacle_boxes)

    def __bool__(self) -> bool:
        return bool(self.boxes)

    @staticmethod
    def crosses(box: Box, band: tuple[float, float], axis: int) -> bool:
        """Whether ``box`` overlaps ``band`` across a push along ``axis``."""
        other = 1 - axis
        return box[other] < band[1] - 1e-9 and box[other + 2] > band[0] + 1e-9

    @staticmethod
    def covers(box: Box, band: tuple[float, float], axis: int) -> bool:
        """Whether ``box`` spans all of ``band`` across a push along ``axis``."""
        other = 1 - axis
        return box[other] <= band[0] + 1e-9 and box[other + 2] >= band[1] - 1e-9

    def face_ahead(
        self,
        front: float,
        band: tuple[float, float],
        axis: int,
        sign: int,
        extra: tuple[Box, ...] = (),
        cover: bool = False,
    ) -> float | None:
        """The nearest near face, not behind ``front``, of an obstacle or an ``extra`` box
        crossing ``band`` (spanning all of it, with ``cover``); None if there is none."""
        meets = self.covers if cover else self.crosses
        faces = [
            near_face(box, axis, sign)
            for box in (*self.boxes.values(), *extra)
            if meets(box, band, axis) and near_face(box, axis, sign) >= front - 1e-9
        ]
        return min(faces, default=None)

    def blocking(
        self, front: float, band: tuple[float, float], axis: int, sign: int, travel: float
    ) -> list[Box]:
        """The obstacles crossing ``band`` whose near face lies between ``front`` and ``GAP``
        beyond ``front + travel``: a shadow with that front and swath, moved ``travel``, jams on
        them."""
        return [
            box
            for box in self.boxes.values()
            if self.crosses(box, band, axis)
            and front - 1e-9 <= near_face(box, axis, sign) < front + travel + GAP
        ]

    def swept(
        self,
        rear: float,
        front: float,
        distance: float,
        swath: tuple[float, float],
        axis: int,
        sign: int,
    ) -> list[Box]:
        """The obstacles that a box from ``rear`` to ``front`` along the push (a paddle's
        approach shadow) meets travelling ``distance``, leaving out those crossing ``swath``
        (the pushed part's): the part jams on those before the paddle gets there."""
        return [
            box
            for box in self.boxes.values()
            if not self.crosses(box, swath, axis)
            and near_face(box, axis, sign) < front + distance
            and far_face(box, axis, sign) > rear
        ]
