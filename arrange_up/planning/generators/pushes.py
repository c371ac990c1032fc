"""Pushes of parts (thesis Figure 2-11): "object-centric" pushes.

For every part on the table and every axis direction (``planning.push_directions`` restricts
them), and every manipulator off the table: the manipulator is put behind the part's belief
shadow, turned so that it pushes along the direction
(:mod:`~arrange_up.planning.generators.approach` says where across), and sent each of the
distances of :mod:`~arrange_up.planning.generators.distances`. A part is never pushed away
from its own goal (beyond the goal tolerance along the direction), but for a detour
(:mod:`~arrange_up.planning.generators.detours`): such a push cannot help it, and it
multiplies the search's plateaus. A push meant to move a part by a given travel has its
distance solved for under the compliant controller
(:mod:`~arrange_up.planning.generators.stall`).

The precondition is tested on belief shadows (:mod:`arrange_up.geometry.collision`): the
manipulator's approach shadow (approach pose +- push uncertainty) must not touch any shadow of
an object on the table, a wall or an obstacle.
"""

from __future__ import annotations

import math

from arrange_up.belief.states import IntervalBelief, ObjectInterval, wrap_angle
from arrange_up.geometry.boxes import Box
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem, Pose
from arrange_up.model.world import Place, Push
from arrange_up.planning.fences import NO_FENCE, Fences
from arrange_up.planning.generators.approach import Approach, Manipulator, describe, shrink
from arrange_up.planning.generators.common import (
    APPROACH_GAP,
    DIRECTIONS,
    PushOptions,
    clean_pose,
)
from arrange_up.planning.generators.detours import Detours
from arrange_up.planning.generators.distances import PushDistances
from arrange_up.planning.generators.stall import PushStall
from arrange_up.planning.generators.targets import GoalTargets
from arrange_up.planning.mating import Mates
from arrange_up.planning.obstacles import Obstacles

#: A belief's shadows: ``(name, centre, half-widths)``.
Shadows = list[tuple[str, Pose, tuple[float, float, float]]]
#: Fence places keyed by the ``(part, axis, sign)`` of the push that would press the part.
Routes = dict[tuple[str, int, int], list[Place]]


class PushGenerator:
    """The push candidates of one problem's beliefs (see the module docstring)."""

    def __init__(
        self,
        problem: ArrangementProblem,
        checker: CollisionChecker,
        options: PushOptions,
        *,
        targets: GoalTargets,
        stall: PushStall,
        detours: Detours,
        distances: PushDistances,
        approach: Approach,
        fences: Fences,
        obstacles: Obstacles,
        mates: Mates,
    ) -> None:
        self.problem = problem
        self.checker = checker
        self.options = options
        self.targets = targets
        self.stall = stall
        self.detours = detours
        self.distances = distances
        self.approach = approach
        self.fences = fences
        self.obstacles = obstacles
        self.mates = mates
        self.directions = tuple(problem.planning.push_directions or DIRECTIONS)
        self.push_unc = problem.uncertainty.push
        self.manipulators = tuple(describe(spec) for spec in problem.manipulators)

    def pushes(self, belief: IntervalBelief, placeable: set[str], routes: Routes) -> list[Push]:
        """The push candidates of ``belief``; ``placeable`` are the parts that have a place
        candidate, ``routes`` the fence places
        (:meth:`~arrange_up.planning.fences.Fences.placements`)."""
        on_table = [(name, iv.center, iv.half) for name, iv in belief.objects]
        # The ladder for parts without a goal position only when a goal part cannot be placed:
        # otherwise the goal-directed actions make progress, and the ladder only widens the
        # search (relative matings expanded 13 times the nodes with it always on).
        ladder = any(
            spec.name not in belief and spec.name not in placeable
            for spec in self.problem.parts
            if spec.name in self.problem.goal.parts
        )
        boxes = [(name, self.checker.shadow_box(name, c, h)) for name, c, h in on_table]
        # The approach's clearance across is sought against each convex part of a concave
        # shadow: its whole box would close the notch a part is pushed into.
        pieces = boxes
        if any(name in self.checker.concave for name, _, _ in on_table):
            pieces = [
                (name, box)
                for name, c, h in on_table
                for box in self.checker.piece_boxes(name, c, h)
            ]
        actions: list[Push] = []
        for manip in self.manipulators:
            if manip.spec.name in belief:
                continue
            for spec in self.problem.parts:
                interval = belief.get(spec.name)
                if interval is None:
                    continue
                detours = (
                    self.detours.detours(spec.name, interval, belief) if self.obstacles else {}
                )
                turning = self.targets.turned_away(spec.name, interval, belief) or (
                    bool(self.mates) and self.mates.square(spec.name, interval.half)
                )
                jams: list[Push] = []
                mine: list[Push] = []
                detoured = False
                for direction in self.directions:
                    pushes = self._pushes_of(
                        manip,
                        spec.name,
                        interval,
                        direction,
                        belief,
                        on_table,
                        boxes,
                        pieces,
                        ladder,
                        routes,
                        detours.get(direction),
                        jams,
                        turning,
                    )
                    detoured = detoured or (direction in detours and bool(pushes))
                    mine.extend(pushes)
                # A push that drives the part into an obstacle only where it cannot go round.
                if detoured and jams:
                    mine = [push for push in mine if push not in jams]
                actions.extend(mine)
        return actions

    def _pushes_of(
        self,
        manip: Manipulator,
        name: str,
        interval: ObjectInterval,
        direction: str,
        belief: IntervalBelief,
        on_table: Shadows,
        boxes: list[tuple[str, Box]],
        pieces: list[tuple[str, Box]],
        ladder: bool,
        routes: Routes,
        detour: float | None,
        jams: list[Push],
        turning: bool,
    ) -> list[Push]:
        """The pushes of part ``name`` along ``direction``; ``on_table`` are the belief's
        shadows ``(name, centre, half)``, ``boxes`` their ``(name, shadow box)`` and ``pieces``
        the same with a concave shadow's box split into its parts'. Those that would drive a
        state of the part into an obstacle
        (:meth:`~arrange_up.planning.generators.detours.Detours.cut_short`) are also appended
        to ``jams``. ``turning``: the part is also offered turning pushes (decided once per
        part by :meth:`pushes`)."""
        ux, uy = DIRECTIONS[direction]
        axis = 0 if ux else 1
        sign = int(ux + uy)  # +1 or -1
        target = self.targets.place_target(name, belief)
        tolerance = self.problem.goal.tolerance[axis]
        away = target is not None and sign * (target[axis] - interval.center[axis]) < -tolerance
        if away and detour is None:
            return []  # it would push the part away from where it must end
        theta = wrap_angle(math.atan2(uy, ux) - manip.push_angle, 0.0, 2.0 * math.pi)
        part_box = self.checker.shadow_box(name, interval.center, interval.half)
        # Extents of the manipulator's approach shadow relative to its commanded centre.
        m_box = self.checker.shadow_box(manip.spec.name, (0.0, 0.0, theta), self.push_unc)
        # Along the push: the manipulator's shadow front stops APPROACH_GAP short of the part's.
        if sign > 0:
            along = part_box[axis] - APPROACH_GAP - m_box[axis + 2]
        else:
            along = part_box[axis + 2] + APPROACH_GAP - m_box[axis]
        front_nominal = sign * along + 0.5 * manip.thickness  # signed coordinate of the front
        fence = (
            self.fences.ahead(name, interval, belief, axis, sign, routes)
            if self.fences.needs
            else NO_FENCE
        )
        # An open push of a part that needs a fence no fence can press yet is a passage (past
        # another part, say): it is also offered where it clips no shadow ahead.
        passing = fence.passing
        distances, jammed = self.distances.distances(
            name, interval, belief, axis, sign, front_nominal, ladder, routes, detour, away, fence
        )
        approach = self.approach
        pushes = []
        for sweep, group in self.detours.sweeps(distances, along, m_box, part_box, axis, sign):
            # Clear of the obstacles the paddle would sweep into where its approach shadow can
            # be; else where the nominal paddle can (the obstacles' boxes shrunk by the margin
            # the shadow and APPROACH_GAP add across: only a noisy approach grazes them); else
            # where it was (it stops on one as the part reaches its end).
            centres = approach.across(
                manip, name, interval, axis, sign, along, m_box, pieces, sweep, passing
            )
            if sweep and not centres:
                other = 1 - axis
                margin = 0.5 * (m_box[other + 2] - m_box[other] - manip.length) + APPROACH_GAP
                shrunk = tuple(shrink(box, other, margin) for box in sweep)
                centres = approach.across(
                    manip, name, interval, axis, sign, along, m_box, pieces, shrunk, passing
                )
            if sweep and not centres:
                centres = approach.across(
                    manip, name, interval, axis, sign, along, m_box, pieces, (), passing
                )
            if self.fences.needs and group:
                centres = approach.clear_of_fences(
                    manip, name, interval, belief, axis, sign, along, m_box, centres, group
                )
            turns = (
                approach.turning_centres(manip, interval, axis, m_box, centres) if turning else []
            )
            for across in centres + turns:
                pose = (along, across, theta) if axis == 0 else (across, along, theta)
                if self.checker.shadow_clear(
                    manip.spec.name, pose, self.push_unc, on_table, [box for _, box in boxes]
                ):
                    for d, travel in group:
                        if travel is not None and across in turns:
                            continue  # a turning push presses the part against what stops it
                        push = Push(manip.spec.name, clean_pose(pose), round(float(d), 4))
                        if (
                            self.stall.per_area
                            and self.options.solve_distances
                            and travel is not None
                        ):
                            distance = self.stall.solve_distance(
                                push, name, axis, sign, travel, belief
                            )
                            push = Push(push.manipulator, push.pose, distance)
                        pushes.append(push)
                        if d in jammed:
                            jams.append(push)
        return pushes
