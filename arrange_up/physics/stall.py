"""How far a compliant push stops short of its set point, as the push generators plan for it
(a fact of the controller, kept with the physics so that the training data, the CBST semantics
and the action generators, rooms above it, share it).

Under the compliant controller (:mod:`arrange_up.physics.simulation`) the paddle tracks its set
point through a low-gain PD, so a push that moves parts lags behind the set point by about the
resisting friction / Kp and stops short by as much. Under the servo it does not stall (0).

* :func:`stall_per_area`: inches of nominal stall per square inch of part pushed (friction and
  part density at the middle of their ranges): what the generators add to a push meant to move
  a part by a given travel (:mod:`arrange_up.planning.actions`).
* :func:`stall_spread`: half the range of that stall over the friction and density ranges: how
  much less precisely than its push noise a push ending in the open stops its part
  (:mod:`arrange_up.planning.fences`).
* :func:`wall_overdrive`: how far beyond the fully compressed train a push *to a wall* sets its
  set point. A set point at the wall itself, a whole train length beyond where the paddle stops,
  leaves the PD's error at that length, so the paddle presses the train with the full force clip
  (400 against the few tens the train's friction needs), and a compressed train of two or three
  blocks buckles: a block squeezes out sideways (``docs/cbst.md``, measured by
  ``benchmarks/cbst_wall_push.py``). The overdrive is the stall at the *upper* ends of the
  friction and density ranges (so every draw of the problem still compresses the train), plus
  the paddle's pose uncertainty along the push (its start, hence its set point, may lie that
  much behind), plus :data:`WALL_MARGIN`.

With ``wall_push="planner"`` the CBST training data (:mod:`arrange_up.cbst.data`) draws its
pushes to the wall with the same :func:`wall_overdrive`, so that the model predicts the pushes
the planner offers (the planner gives CBST these pushes: ``compressed_wall_pushes`` in
:mod:`arrange_up.planning.actions`; the particle semantics still push to the wall itself).
"""

from __future__ import annotations

from typing import NamedTuple

from arrange_up.model.problem import (
    STANDARD_GRAVITY,
    ArrangementProblem,
    Controller,
    ControllerKind,
)

__all__ = [
    "SoftPart",
    "WALL_MARGIN",
    "soft_parts",
    "stall_per_area",
    "stall_spread",
    "wall_overdrive",
    "wall_push_front",
]

#: Inches the set point of a compliant push to a wall goes beyond the worst-case stall and the
#: paddle's pose uncertainty: the contact slop and what the PD still lags when it settles.
WALL_MARGIN = 0.1


def stall_per_area(problem: ArrangementProblem) -> float:
    """Inches a compliant push stops short per square inch of part it moves, at the middle of
    the problem's friction and part-density ranges (``mu g rho / Kp``; 0 under the servo)."""
    controller = problem.controller
    if controller.kind is not ControllerKind.COMPLIANT:
        return 0.0
    u = problem.uncertainty
    friction = 0.5 * (u.friction[0] + u.friction[1])
    density = 0.5 * (u.part_density[0] + u.part_density[1])
    return friction * STANDARD_GRAVITY * density / controller.kp


class SoftPart(NamedTuple):
    """A part the compliant controller is too soft for (:func:`soft_parts`)."""

    name: str
    stall: float
    """Inches a nominal push of the part alone stops short of its set point."""
    reach: float
    """The table's shorter side (in): the most a push's set point can be moved on to make up
    for the stall."""
    kp_min: float
    """The smallest ``kp`` whose stall for this part is ``reach``."""


def soft_parts(problem: ArrangementProblem) -> list[SoftPart]:
    """The parts the problem's compliant controller is too soft for: those whose nominal stall
    (:func:`stall_per_area` times the part's area: a push of the part alone, at mid-range
    friction and density) is longer than the table's shorter side. The push generators add
    the stall to every push's travel, so a stall of an inch or two is planned for (the shipped
    problems stall up to 1.8 in on a 12 in table), but a set point that must go a table's length
    beyond the part is off the table: no push gets the part where the plan says (a file with
    densities in grams per cm², a thousand times the kilogram ones, stalls about 57 in on that
    table). Empty under the servo, which does not stall."""
    per_area = stall_per_area(problem)
    if per_area <= 0.0:
        return []
    reach = min(problem.table.width, problem.table.depth)
    found = []
    for part in problem.parts:
        stall = per_area * part.shape.area
        if stall > reach:
            found.append(SoftPart(part.name, stall, reach, problem.controller.kp * stall / reach))
    return found


def stall_spread(problem: ArrangementProblem) -> float:
    """Half the range of the compliant controller's stall per square inch of part moved, over
    the problem's friction and part-density ranges (0 under the servo)."""
    controller = problem.controller
    if controller.kind is not ControllerKind.COMPLIANT:
        return 0.0
    u = problem.uncertainty
    low = u.friction[0] * u.part_density[0]
    high = u.friction[1] * u.part_density[1]
    return 0.5 * (high - low) * STANDARD_GRAVITY / controller.kp


def wall_overdrive(
    controller: Controller,
    friction: tuple[float, float],
    part_density: tuple[float, float],
    area: float,
    along: float,
) -> float | None:
    """How far (in) beyond the fully compressed train a push to a wall sets its set point
    (module docstring): ``mu_max g rho_max area / Kp + along + WALL_MARGIN`` under the compliant
    controller, for a train of ``area`` square inches of parts, friction and part density in
    the given ranges and the paddle's pose uncertainty ``along`` the push (in). ``None`` under
    the servo: its pushes to a wall go to the wall, as they always have (its stiff paddle does
    not turn, and its trains buckled in 36 of the 3,592 training rows)."""
    if controller.kind is not ControllerKind.COMPLIANT:
        return None
    stall = friction[1] * STANDARD_GRAVITY * part_density[1] * area / controller.kp
    return stall + along + WALL_MARGIN


def wall_push_front(face: float, length: float, overdrive: float | None) -> float:
    """Where a push to the wall (or fence) face at ``face`` sends the manipulator's front, as
    a coordinate growing along the push: ``overdrive`` (:func:`wall_overdrive`) past the front
    of the train of ``length`` compressed against the face, never beyond the face; the face
    itself when ``overdrive`` is None (the servo)."""
    if overdrive is None:
        return face
    return min(face, face - length + overdrive)
