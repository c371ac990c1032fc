"""The compliant controller's stall, as the push generators allow for it.

Under the compliant controller (``problem.controller.kind == "compliant"``) a resisted push
stops short of its set point by about the resisting friction / Kp, so the distances to a goal
coordinate and the ``push_distances`` are lengthened by the nominal stall of what the push
moves (:meth:`PushStall.stall`): ``mu g rho A / Kp`` at the middle of the friction and
part-density ranges, ``A`` the area of the pushed part and of the parts in a row ahead of it
whose shadows it would reach within ``CONTACT_GAP``. Pushes to a wall need none: their set
point lies at the wall, or with ``compressed_wall_pushes`` (:meth:`PushStall.stop_front`) at
the front of the compressed train (the part and its train, by their nominal extents) plus
:func:`~arrange_up.physics.stall.wall_overdrive`, the worst-case stall of the train and the
push's pose uncertainty, because a set point at the wall presses the train with the full force
clip and buckles trains of two or three blocks (docs/cbst.md), and because CBST's model is
trained on pushes to the wall drawn so. Under the servo the stall is zero and the distances are
as before.

A push meant to move a part by a given travel then has its distance solved for
(:meth:`PushStall.solve_distance`) in up to ``SOLVER_STEPS`` noise-free simulations from the
belief's centres, unless ``solve_distances`` is off (the planner turns it off for semantics
that do not simulate pushes, i.e. CBST: its model predicts only pushes that compress a train
against a wall, and the simulations took half of a CBST search's time).
"""

from __future__ import annotations

from arrange_up.belief.states import IntervalBelief
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Push, WorldState
from arrange_up.physics.stall import stall_per_area, wall_overdrive, wall_push_front
from arrange_up.planning.generators.common import MIN_PUSH, PushOptions

#: Parts ahead of a pushed part within this gap (in) count as moved with it by the push, for
#: the compliant controller's stall.
CONTACT_GAP = 0.1
#: Under the compliant controller: simulations per candidate push spent solving for its
#: distance, and the error in the part's travel (in) at which the solver stops.
SOLVER_STEPS = 3
SOLVER_TOLERANCE = 0.002


class PushStall:
    """The stall allowances of one problem's pushes (see the module docstring)."""

    def __init__(
        self, problem: ArrangementProblem, checker: CollisionChecker, options: PushOptions
    ) -> None:
        self.problem = problem
        self.checker = checker
        self.options = options
        self.push_unc = problem.uncertainty.push
        #: The nominal stall per square inch of parts pushed (zero under the servo).
        self.per_area = stall_per_area(problem)
        #: Part name -> its area (square inches).
        self.areas = {spec.name: spec.shape.area for spec in problem.parts}

    def stall(self, name: str, belief: IntervalBelief, axis: int, sign: int) -> float:
        """The compliant controller's nominal stall pushing ``name`` (module docstring): the
        pushed part and the row of parts ahead of it within ``CONTACT_GAP``, by nominal
        boxes at the belief centres."""
        other = 1 - axis
        boxes = {
            n: self.checker.shadow_box(n, iv.center, (0.0, 0.0, 0.0))
            for n, iv in belief.objects
            if n in self.areas
        }
        row, box = [name], boxes[name]
        while True:
            front = box[axis + 2] if sign > 0 else -box[axis]
            ahead = [
                (rear, q)
                for q, b in boxes.items()
                if q not in row
                and min(b[other + 2], box[other + 2]) - max(b[other], box[other]) > 1e-6
                and -1e-6
                <= (rear := (b[axis] if sign > 0 else -b[axis + 2]) - front)
                <= CONTACT_GAP
            ]
            if not ahead:
                break
            _, nearest = min(ahead)
            row.append(nearest)
            box = boxes[nearest]
        return self.per_area * sum(self.areas[q] for q in row)

    def overdrive(self, area: float, axis: int) -> float | None:
        """The problem's :func:`~arrange_up.physics.stall.wall_overdrive` for ``area`` square
        inches of parts pressed along ``axis`` (None under the servo)."""
        u = self.problem.uncertainty
        return wall_overdrive(
            self.problem.controller, u.friction, u.part_density, area, self.push_unc[axis]
        )

    def stop_front(
        self, stop: float, parts: tuple[str, ...], belief: IntervalBelief, axis: int
    ) -> float:
        """Where (signed coordinate along the push) a push of ``parts``, the pushed part and
        the train ahead of it, against the wall or fence face at ``stop`` sends the
        manipulator's front: the face itself; with ``compressed_wall_pushes`` under the
        compliant controller, the front of the compressed train (the parts' nominal extents
        along the push, at their belief centres) plus its
        :func:`~arrange_up.physics.stall.wall_overdrive`."""
        if not self.options.compressed_wall_pushes:
            return stop
        over = self.overdrive(sum(self.areas[q] for q in parts), axis)
        if over is None:
            return stop
        length = 0.0
        for q in parts:
            box = self.checker.shadow_box(q, belief.get(q).center, (0.0, 0.0, 0.0))  # type: ignore[union-attr]
            length += box[axis + 2] - box[axis]
        return wall_push_front(stop, length, over)

    def solve_distance(
        self, push: Push, name: str, axis: int, sign: int, travel: float, belief: IntervalBelief
    ) -> float:
        """The distance at which ``push`` moves ``name`` by ``travel`` along its direction in a
        noise-free simulation from the belief's centres, under the compliant controller: up to
        ``SOLVER_STEPS`` fixed-point steps ``d += travel - achieved`` from ``push.distance``
        (the stall changes little with the distance, so each step removes most of the error),
        stopping within ``SOLVER_TOLERANCE``. A simulation that does not end at rest, or a
        distance that falls to the free travel, keeps the last good distance."""
        # Imported here: importing the physics (pymunk) is slow, and importing the planner
        # should not pay for it until a plan is made.
        from arrange_up.physics.simulation import simulate

        state = WorldState(tuple((n, iv.center) for n, iv in belief.objects))
        start = belief.get(name).center[axis]  # type: ignore[union-attr]
        distance = push.distance
        for _ in range(SOLVER_STEPS):
            outcome = simulate(self.problem, state, push)
            if not outcome.ok or name not in outcome.state:
                break
            error = travel - sign * (outcome.state.as_dict()[name][axis] - start)
            if abs(error) <= SOLVER_TOLERANCE or distance + error <= MIN_PUSH:
                break
            distance += error
            push = Push(push.manipulator, push.pose, round(float(distance), 4))
        return push.distance
