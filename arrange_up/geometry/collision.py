"""Collision tests on a problem's table: exact footprints for world states, belief shadows for
action preconditions (thesis §2.1.3), and penetration depths of a placed object.

Shadow tests are the hot path of action generation, so they run in two stages: axis-aligned
shadow boxes first (numpy, microseconds), and only when two boxes overlap, the exact convex
shadow hulls (shapely). Both shadows truly cover their object over the whole pose interval, so
"clear" answers are conservative: a place or push judged clear cannot touch what it was tested
against, whatever the pose within the intervals.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from functools import lru_cache

import numpy as np
import shapely
import shapely.geometry.base
from shapely.geometry import box as shapely_box

from arrange_up.geometry import shapes as geometry
from arrange_up.geometry.boxes import Box, box_corners, wall_boxes
from arrange_up.geometry.polygons import convex_penetration
from arrange_up.geometry.se2 import transform_points
from arrange_up.model.problem import ArrangementProblem, HalfWidths, Pose, as_triple
from arrange_up.model.world import WorldState

#: Overlap area (square inches) below which two footprints count as touching, not overlapping.
AREA_TOLERANCE = 1e-9
#: Minimum clearance kept between shadows judged clear (inches): a hair, so that touching
#: shadows count as a collision and float noise never flips a decision.
CLEARANCE = 1e-6


class CollisionChecker:
    """Footprint and shadow tests for one problem (walls, obstacles and object shapes fixed)."""

    def __init__(self, problem: ArrangementProblem) -> None:
        self.problem = problem
        self.shapes = {spec.name: spec.shape for spec in problem.objects}
        self.walls = geometry.wall_boxes(problem.table.size, problem.table.walls)
        self.obstacles = {
            spec.name: geometry.footprint(spec.shape.parts, spec.pose)
            for spec in problem.obstacles
            if spec.pose is not None
        }
        self.obstacle_boxes = {name: geom.bounds for name, geom in self.obstacles.items()}
        self._fixed = list(self.obstacles.values()) + [_box_geom(b) for b in self.walls.values()]
        self._wall_geoms = {edge: _box_geom(box) for edge, box in self.walls.items()}
        #: Objects whose convex parts leave part of their hull empty: their shadows are the
        #: union of the parts' (:meth:`shadow_hull`, :meth:`piece_boxes`).
        self.concave = frozenset(
            name
            for name, shape in self.shapes.items()
            if shape is not None
            and len(shape.parts) > 1
            and geometry.footprint(shape.parts, (0.0, 0.0, 0.0)).convex_hull.area
            > shape.area * (1.0 + 1e-6)
        )
        self._shadow_box = lru_cache(maxsize=200_000)(self._shadow_box_uncached)
        self._shadow_hull = lru_cache(maxsize=20_000)(self._shadow_hull_uncached)
        self._piece_boxes = lru_cache(maxsize=20_000)(self._piece_boxes_uncached)
        # a search tests the same shadows (and pairs of them) again and again, since the same
        # objects' beliefs recur in many beliefs; the hulls' distances are the costly part
        self._hulls_meet = lru_cache(maxsize=200_000)(self._hulls_meet_uncached)
        self._hits_fixed = lru_cache(maxsize=100_000)(self._hits_fixed_uncached)

    # -- world states ------------------------------------------------------------------------
    def state_collides(self, state: WorldState) -> bool:
        """True if any two objects of ``state`` overlap, or one overlaps an obstacle or a wall."""
        footprints = [
            geometry.footprint(self.shapes[name].parts, pose) for name, pose in state.poses
        ]
        for i, a in enumerate(footprints):
            for b in footprints[i + 1 :] + self._fixed:
                if a.intersects(b) and a.intersection(b).area > AREA_TOLERANCE:
                    return True
        return False

    # -- shadows -----------------------------------------------------------------------------
    def _shadow_box_uncached(self, name: str, pose: Pose, half: HalfWidths) -> Box:
        return geometry.shadow_box(self.shapes[name].parts, pose, half)

    def _shadow_hull_uncached(
        self, name: str, pose: Pose, half: HalfWidths
    ) -> shapely.geometry.base.BaseGeometry:
        parts = self.shapes[name].parts
        if name not in self.concave:
            return geometry.shadow_hull(parts, pose, half)
        return shapely.union_all([geometry.shadow_hull([part], pose, half) for part in parts])

    def _piece_boxes_uncached(self, name: str, pose: Pose, half: HalfWidths) -> tuple[Box, ...]:
        if name not in self.concave:
            return (self.shadow_box(name, pose, half),)
        return tuple(geometry.shadow_box([part], pose, half) for part in self.shapes[name].parts)

    def shadow_box(self, name: str, pose: Pose, half: HalfWidths) -> Box:
        return self._shadow_box(name, as_triple(pose), as_triple(half))

    def shadow_hull(
        self, name: str, pose: Pose, half: HalfWidths
    ) -> shapely.geometry.base.BaseGeometry:
        """The object's shadow: a convex polygon containing it at every pose of the interval
        (:func:`~arrange_up.geometry.shadows.shadow_hull`), or for a concave object (one whose
        convex parts do not fill their hull: an L, a T, a U) the union of its parts' shadows,
        so that its notches stay open to what fits in them."""
        return self._shadow_hull(name, as_triple(pose), as_triple(half))

    def piece_boxes(self, name: str, pose: Pose, half: HalfWidths) -> tuple[Box, ...]:
        """The shadow boxes of the object's convex parts if it is concave (their union holds
        its shadow, notches left open), else its one shadow box."""
        return self._piece_boxes(name, as_triple(pose), as_triple(half))

    def shadows_overlap(
        self, a: tuple[str, Pose, HalfWidths], b: tuple[str, Pose, HalfWidths]
    ) -> bool:
        """True if the belief shadows of two objects may overlap (boxes, then hulls)."""
        return self._overlap(self.shadow_box(*a), a[0], as_triple(a[1]), as_triple(a[2]), b)

    def _overlap(
        self,
        box: Box,
        name: str,
        pose: Pose,
        half: HalfWidths,
        other: tuple[str, Pose, HalfWidths],
        other_box: Box | None = None,
    ) -> bool:
        """:meth:`shadows_overlap` of ``(name, pose, half)``, whose shadow box is ``box``
        (tuples), and ``other``, whose shadow box is ``other_box`` if given."""
        if other_box is None:
            other_box = self.shadow_box(*other)
        if not geometry.boxes_overlap(box, other_box, -CLEARANCE):
            return False
        return self._hulls_meet(
            name, pose, half, other[0], as_triple(other[1]), as_triple(other[2])
        )

    def _hulls_meet_uncached(
        self, a: str, a_pose: Pose, a_half: HalfWidths, b: str, b_pose: Pose, b_half: HalfWidths
    ) -> bool:
        hull_a, hull_b = self.shadow_hull(a, a_pose, a_half), self.shadow_hull(b, b_pose, b_half)
        return hull_a.distance(hull_b) < CLEARANCE

    def shadow_hits_fixed(self, name: str, pose: Pose, half: HalfWidths) -> bool:
        """True if the object's shadow may touch a wall or an obstacle."""
        return self._hits_fixed(name, as_triple(pose), as_triple(half))

    def _hits_fixed_uncached(self, name: str, pose: Pose, half: HalfWidths) -> bool:
        box = self.shadow_box(name, pose, half)
        hull = None
        for edge, wall in self.walls.items():
            if geometry.boxes_overlap(box, wall, -CLEARANCE):
                hull = hull or self.shadow_hull(name, pose, half)
                if hull.distance(self._wall_geoms[edge]) < CLEARANCE:
                    return True
        for obstacle_name, obstacle in self.obstacles.items():
            if geometry.boxes_overlap(box, self.obstacle_boxes[obstacle_name], -CLEARANCE):
                hull = hull or self.shadow_hull(name, pose, half)
                if hull.distance(obstacle) < CLEARANCE:
                    return True
        return False

    def shadow_inside_table(self, name: str, pose: Pose, half: HalfWidths) -> bool:
        """True if the object's shadow box lies on the table."""
        xmin, ymin, xmax, ymax = self.shadow_box(name, pose, half)
        width, depth = self.problem.table.size
        return xmin >= 0.0 and ymin >= 0.0 and xmax <= width and ymax <= depth

    def shadow_clear(
        self,
        name: str,
        pose: Pose,
        half: HalfWidths,
        others: Iterable[tuple[str, Pose, HalfWidths]],
        boxes: Iterable[Box] | None = None,
    ) -> bool:
        """The place precondition: ``name``'s shadow touches no other shadow, wall or obstacle.
        ``boxes``: the others' shadow boxes in their order, when the caller has them (an
        action generator tests many poses against one belief's shadows)."""
        pose, half = as_triple(pose), as_triple(half)
        if self._hits_fixed(name, pose, half):
            return False
        box = self._shadow_box(name, pose, half)
        if boxes is None:
            return not any(self._overlap(box, name, pose, half, other) for other in others)
        return not any(
            self._overlap(box, name, pose, half, other, other_box)
            for other, other_box in zip(others, boxes, strict=True)
        )


def _box_geom(box: Box) -> shapely.Polygon:
    return shapely_box(*box)


class PenetrationDepths:
    """How deeply an object overlaps the others, the walls and the obstacles of one problem's
    table: the deepest :func:`~arrange_up.geometry.polygons.convex_penetration` over pairs of
    convex parts (exact shapes at exact poses, no shadows)."""

    def __init__(self, problem: ArrangementProblem) -> None:
        self.parts = {
            spec.name: [np.asarray(part, dtype=float) for part in spec.shape.parts]
            for spec in problem.objects
        }
        self.radius = {spec.name: spec.shape.radius for spec in problem.objects}
        fixed: list[tuple[str, np.ndarray]] = []
        for edge, box in wall_boxes(problem.table.size, problem.table.walls).items():
            fixed.append((f"the {edge} wall", np.array(box_corners(box))))
        for spec in problem.obstacles:
            if spec.pose is not None:
                for part in self.parts[spec.name]:
                    fixed.append((spec.name, transform_points(part, spec.pose)))
        self.fixed = fixed
        """``(label, world polygon)`` of every wall (``"the left wall"``) and obstacle part."""
        self._fixed_bounds = [
            (*poly.min(axis=0).tolist(), *poly.max(axis=0).tolist()) for _, poly in fixed
        ]

    def deepest(self, state: WorldState, name: str) -> tuple[str, float]:
        """The deepest overlap of ``name`` (on the table in ``state``) with any other object of
        ``state``, wall or obstacle: ``(what, depth)``, ``("nothing", 0.0)`` when none. The
        first found wins a tie (objects in state order, then walls, then obstacles)."""
        pose = state.pose(name)
        assert pose is not None
        return self.deepest_at(state, name, pose)

    def deepest_at(self, state: WorldState, name: str, pose: Pose) -> tuple[str, float]:
        """:meth:`deepest` for ``name`` put down at ``pose``, whether or not ``state`` holds it
        (a manipulator about to push, say); ``name``'s own entry in ``state`` is ignored."""
        placed = [transform_points(part, pose) for part in self.parts[name]]
        reach = self.radius[name]
        worst = ("nothing", 0.0)
        for other, other_pose in state.poses:
            if (
                other == name
                or math.hypot(other_pose[0] - pose[0], other_pose[1] - pose[1])
                > reach + self.radius[other]
            ):
                continue
            for part in self.parts[other]:
                world = transform_points(part, other_pose)
                for mine in placed:
                    depth = convex_penetration(mine, world)
                    if depth > worst[1]:
                        worst = (other, depth)
        x, y = pose[0], pose[1]
        for (label, poly), (x0, y0, x1, y1) in zip(self.fixed, self._fixed_bounds, strict=True):
            if x1 < x - reach or y1 < y - reach or x0 > x + reach or y0 > y + reach:
                continue
            for mine in placed:
                depth = convex_penetration(mine, poly)
                if depth > worst[1]:
                    worst = (label, depth)
        return worst
