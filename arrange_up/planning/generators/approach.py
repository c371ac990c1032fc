"""Where the manipulator stands for a push: its centre across the push direction.

The manipulator is put behind the part's belief shadow, turned so that it pushes along the
direction, centred on the part's belief centre across the direction — shifted along its long
side just enough to stay clear of walls and of the shadows beside it, as long as it still
covers the part's centre (:meth:`Approach.across`).

With ``unclipped_pushes`` (the planner sets it for semantics that refuse uncertain contacts,
i.e. CBST), when that position *clips* a shadow ahead (its long side overlaps the shadow's side
without covering it whole, so whether it touches that part is uncertain), the same push is
offered a second time from the nearest position that misses or wholly covers every shadow
ahead. The first position keeps plans that move a neighbouring row along; the second makes
contacts certain where CBST must refuse a clipped one (a row of blocks built against a wall,
where each new block's push down clips the block beside it). Particle semantics simulate
clipped contacts, and for them the extra pushes only widen the search, so it is off by default
(the cases that motivate both positions are in docs/design/planning-pushes.md).

**Turning pushes** (:meth:`Approach.turning_centres`): a part whose belief is centred on an
angle outside its goal's tolerance (modulo its symmetry period), and a relative goal's
reference that :meth:`~arrange_up.planning.mating.Mates.square` says to square, are also
offered their pushes that press them against what stops them (the distances with no part
travel of their own) with the manipulator shifted across by ``TURN_OFFSET`` of its length to
either side: it presses one side, and the part turns until its face lies flat against the wall
(a centred push leaves a turned part resting on two corners, still turned).

A paddle whose travel would sweep it into an obstacle outside the part's swath
(:meth:`~arrange_up.planning.generators.detours.Detours.sweeps`) is shifted along its long
side to pass it clear; for a part that needs a fence (:mod:`arrange_up.planning.fences`) the
centre is moved so that its path misses the fixtures on the table
(:meth:`Approach.clear_of_fences`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.geometry.boxes import Box
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem, ObjectSpec
from arrange_up.planning.fences import Fences
from arrange_up.planning.generators.common import APPROACH_GAP, PushOptions

#: Turning pushes (a part turned away from its goal angle): the manipulator's centre shifted
#: across the push from the part's centre by this fraction of the manipulator's length, to
#: either side, so that it presses one side of the part and turns it
#: (docs/design/planning-pushes.md, "Turning pushes").
TURN_OFFSET = 0.3


@dataclass(frozen=True)
class Manipulator:
    """A manipulator as the push generators see it."""

    spec: ObjectSpec
    length: float  # along the long side
    thickness: float  # along the push direction
    push_angle: float  # angle of the push direction in the manipulator's frame


def describe(spec: ObjectSpec) -> Manipulator:
    """The :class:`Manipulator` of ``spec``: its extents across and along its push direction."""
    xmin, ymin, xmax, ymax = spec.shape.extent
    px, py = spec.push_direction
    length, thickness = (xmax - xmin, ymax - ymin) if py else (ymax - ymin, xmax - xmin)
    return Manipulator(spec, length, thickness, math.atan2(py, px))


def shrink(box: Box, axis: int, margin: float) -> Box:
    """``box`` narrowed by ``margin`` on both sides along ``axis`` (to its centre at most)."""
    low, high = box[axis] + margin, box[axis + 2] - margin
    if low > high:
        low = high = 0.5 * (box[axis] + box[axis + 2])
    bounds = list(box)
    bounds[axis], bounds[axis + 2] = low, high
    return tuple(bounds)  # type: ignore[return-value]


class Approach:
    """The manipulator's centres across one problem's pushes (see the module docstring)."""

    def __init__(
        self,
        problem: ArrangementProblem,
        checker: CollisionChecker,
        options: PushOptions,
        fences: Fences,
    ) -> None:
        self.problem = problem
        self.checker = checker
        self.options = options
        self.fences = fences
        self._limits = (self._across_limits(0), self._across_limits(1))

    def across(
        self,
        manip: Manipulator,
        name: str,
        interval: ObjectInterval,
        axis: int,
        sign: int,
        along: float,
        m_box: Box,
        boxes: Sequence[tuple[str, Box]],
        sweep: Sequence[Box] = (),
        unclipped: bool = False,
    ) -> list[float]:
        """Where to centre the manipulator across the push (at most two centres).

        The first is as near the part's centre as the walls, the shadows beside the approach
        and the obstacle boxes in ``sweep`` (those its travel would meet) allow, while the
        manipulator's long side still covers the part's centre (with 0.1 in to spare). With
        ``unclipped_pushes`` (or ``unclipped``: a passing push, :mod:`~arrange_up.planning.fences`),
        when it clips the side of a shadow *ahead* of the approach (the
        manipulator's span overlaps that shadow's span without covering it whole, so the
        contact may or may not happen), the second is the nearest centre at which every
        shadow ahead is either missed or covered whole. Empty if no centre fits.
        """
        other = 1 - axis
        centre = interval.center[other]
        low, high = self.across_span(manip, interval, other, m_box)
        if low > high:
            return []
        a_lo, a_hi = along + m_box[axis], along + m_box[axis + 2]
        others = [box for other_name, box in boxes if other_name != name]
        # Shadows (and obstacles) level with the approach forbid the centres that would make
        # them overlap: each gives the open interval of such centres.
        forbidden = [
            (
                box[other] - m_box[other + 2] - APPROACH_GAP,
                box[other + 2] - m_box[other] + APPROACH_GAP,
            )
            for box in others + list(self.checker.obstacle_boxes.values())
            if box[axis + 2] > a_lo - APPROACH_GAP and box[axis] < a_hi + APPROACH_GAP
        ] + [
            (
                box[other] - m_box[other + 2] - APPROACH_GAP,
                box[other + 2] - m_box[other] + APPROACH_GAP,
            )
            for box in sweep
        ]
        # Shadows ahead (only with unclipped_pushes): the centres at which the approach shadow
        # touches one (the interval it is forbidden from when level) and those at which the
        # nominal manipulator covers it whole. Touching without covering is clipping.
        half_length = 0.5 * manip.length
        ahead = [
            (
                box[other] - m_box[other + 2] - APPROACH_GAP,
                box[other + 2] - m_box[other] + APPROACH_GAP,
                box[other + 2] - half_length,
                box[other] + half_length,
            )
            for box in (others if self.options.unclipped_pushes or unclipped else [])
            if (
                box[axis] >= a_hi - APPROACH_GAP
                if sign > 0
                else box[axis + 2] <= a_lo + APPROACH_GAP
            )
        ]
        # Candidate centres: the preferred one and the edges of every interval above.
        candidates = [min(max(centre, low), high)]
        candidates += [v for bounds in forbidden + ahead for v in bounds if low <= v <= high]
        candidates.sort(key=lambda v: abs(v - centre))
        # The nearest allowed centre, and the nearest allowed one that clips no shadow ahead.
        first = None
        for value in candidates:
            if any(lo < value < hi for lo, hi in forbidden):
                continue
            if first is None:
                first = value
            if not any(
                touch_lo < value < touch_hi and not cover_lo <= value <= cover_hi
                for touch_lo, touch_hi, cover_lo, cover_hi in ahead
            ):
                return [first] if abs(value - first) <= 1e-6 else [first, value]
        return [] if first is None else [first]

    def across_span(
        self, manip: Manipulator, interval: ObjectInterval, other: int, m_box: Box
    ) -> tuple[float, float]:
        """The range of centres across the push (along axis ``other``) at which the
        manipulator's long side covers the part's centre with 0.1 in to spare and its approach
        shadow (extents ``m_box``) keeps clear of the walls; empty (low > high) if none."""
        reach = 0.5 * manip.length - 0.1
        low_lim, high_lim = self._limits[other]
        return (
            max(interval.center[other] - reach, low_lim - m_box[other]),
            min(interval.center[other] + reach, high_lim - m_box[other + 2]),
        )

    def _across_limits(self, other: int) -> tuple[float, float]:
        """The coordinate range across a push that keeps clear of walls on that axis."""
        walls = set(self.problem.table.walls)
        size = self.problem.table.size[other]
        low_name, high_name = ("left", "right") if other == 0 else ("bottom", "top")
        low = 0.0 + APPROACH_GAP if low_name in walls else -math.inf
        high = size - APPROACH_GAP if high_name in walls else math.inf
        return low, high

    def turning_centres(
        self,
        manip: Manipulator,
        interval: ObjectInterval,
        axis: int,
        m_box: Box,
        centres: Sequence[float],
    ) -> list[float]:
        """Turning pushes: centres across the push shifted from the part's centre by
        :data:`TURN_OFFSET` of the manipulator's length to either side (within the span at
        which it still covers the part's centre and clears the walls), so that it presses one
        side of a part turned away from its goal angle and turns it flat against the wall,
        fence or obstacle it is pressed against (only the distances that press a part are
        offered with them: a free push on one side leaves the angle to chance); those not
        already in ``centres``. The approach's clearance is checked with every other centre's."""
        other = 1 - axis
        low, high = self.across_span(manip, interval, other, m_box)
        shift = TURN_OFFSET * manip.length
        found: list[float] = []
        for side in (-1.0, 1.0):
            value = interval.center[other] + side * shift
            if low <= value <= high and all(abs(value - c) > 1e-6 for c in (*centres, *found)):
                found.append(value)
        return found

    def clear_of_fences(
        self,
        manip: Manipulator,
        name: str,
        interval: ObjectInterval,
        belief: IntervalBelief,
        axis: int,
        sign: int,
        along: float,
        m_box: Box,
        centres: list[float],
        distances: Sequence[tuple[float, float | None]],
    ) -> list[float]:
        """``centres`` moved so that the manipulator's path misses the fences of the other axis
        on the table (:meth:`~arrange_up.planning.fences.Fences.clear_paths`), for a part that
        needs a fence."""
        other = 1 - axis
        return self.fences.clear_paths(
            name,
            belief,
            axis,
            sign,
            centres,
            self.across_span(manip, interval, other, m_box),
            (along + m_box[axis], along + m_box[axis + 2]),
            (m_box[other], m_box[other + 2]),
            max(d for d, _ in distances),
        )
