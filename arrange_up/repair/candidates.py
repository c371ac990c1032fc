"""The candidates of a one-step fixture problem and how they are scored (thesis Figures 4-8 to
4-10).

A candidate is "no fixture" or a fixture placement from a grid over the table, with a push
distance multiplier. This module builds the grid (:func:`grid_placements`), the part motion
swaths that filter it (:func:`part_swaths`), the approach back-off of the push
(:func:`clear_approach`), scores a simulated candidate (:func:`mean_distance`,
:func:`normalise`) and picks the winner (:func:`choose`). Simulating the candidates is the
repairer's (:mod:`arrange_up.repair.repairer`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from enum import StrEnum
from typing import Any

import numpy as np

from arrange_up.belief.states import IntervalBelief, ParticleBelief
from arrange_up.geometry.boxes import boxes_union
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.geometry.se2 import rotate
from arrange_up.model.problem import ArrangementProblem, Pose
from arrange_up.model.world import Action, Pick, Place, Push, WorldState
from arrange_up.planning.fences import fixture_angles

#: Push distance multipliers (thesis §4.1.2, "Pushing multipliers").
MULTIPLIERS: tuple[float, ...] = (1.0, 1.25, 1.5, 1.75, 2.0)
#: The multiplier placements are selected and the swath is built with (thesis: 2x).
SELECTION_MULTIPLIER = 2.0
#: Spacing of the placement grid (inches).
GRID_STEP = 0.5
#: Placements whose multipliers are all tried (besides "no fixture").
REFINE = 3
#: Approach back-off: step, largest back-off, and clearance kept from the belief's shadows
#: (inches; see :func:`clear_approach`).
BACKOFF_STEP = 0.05
MAX_BACKOFF = 2.0
BACKOFF_GAP = 0.02
#: A fixture is chosen only if it lowers the mean distance below the best bare push's by more
#: than ``max(absolute, relative * bare distance)`` (inches, fraction): physics round-off alone
#: makes an untouched fixture's outcome differ a little from the bare push's.
MIN_FIXTURE_GAIN = (0.01, 0.01)

_ZERO = (0.0, 0.0, 0.0)

#: A candidate's key: ``(fixture, pose, multiplier)``, fixture and pose ``None`` for no fixture.
Key = tuple[str | None, Pose | None, float]
#: A swath: ``(part, (xmin, ymin, xmax, ymax))``.
Swath = tuple[str, tuple[float, float, float, float]]


class CandidateStatus(StrEnum):
    """How a candidate came out (its JSON form is the string)."""

    OK = "ok"
    """Simulated on every particle (or unreachable by the push: the no-fixture outcome)."""
    BLOCKED = "blocked"
    """The place precondition fails on the belief: not simulated."""
    INVALID = "invalid"
    """Some particle's push failed."""


OK = CandidateStatus.OK
BLOCKED = CandidateStatus.BLOCKED
INVALID = CandidateStatus.INVALID


@dataclass(frozen=True)
class Candidate:
    """One candidate of a one-step fixture problem.

    ``fixture``/``pose`` are ``None`` for "no fixture". ``status`` is ``"ok"`` (simulated on
    every particle, or unreachable by the push and given the no-fixture outcome:
    ``reachable=False``), ``"blocked"`` (the place precondition fails; not simulated) or
    ``"invalid"`` (some particle's push failed; ``reason`` says how). ``distance`` is the mean
    Manhattan distance to the nominal next state (``inf`` when invalid, ``nan`` when blocked);
    ``score`` its min-max normalised value among the valid candidates of the same stage (0 is
    best; ``None`` unless ``ok``). ``reliability`` is the share of rollouts of the nominal
    plan's remaining actions from its outcome that reach the goal
    (:mod:`arrange_up.repair.reliability`; ``None`` when not estimated: candidates of the
    placement stage, invalid ones and those the plan check refused). ``push`` is the push it
    simulates: the nominal push's (backed-off, see :class:`StepScores`) approach pose, its
    distance times ``multiplier``. ``stop`` marks a placement made to stop a part where its
    end is uncertain (:func:`stop_placements`).
    """

    fixture: str | None
    pose: Pose | None
    multiplier: float
    status: str
    distance: float
    score: float | None = None
    reachable: bool = True
    reason: str = ""
    push: Push | None = None
    reliability: float | None = None
    stop: bool = False

    @property
    def valid(self) -> bool:
        return self.status == OK

    def actions(self) -> tuple[Action, ...]:
        """The actions this candidate replaces its nominal push with."""
        assert self.push is not None
        if self.fixture is None or self.pose is None:
            return (self.push,)
        return (Place(self.fixture, self.pose), self.push, Pick(self.fixture))

    def to_json(self, units: Any) -> dict[str, Any]:
        data: dict[str, Any] = {
            "fixture": self.fixture,
            "pose": None
            if self.pose is None
            else [json_round(v) for v in units.pose_out(self.pose)],
            "multiplier": self.multiplier,
            "status": self.status,
            "distance": json_float(self.distance),
            "score": None if self.score is None else json_round(self.score),
        }
        if self.reliability is not None:
            data["reliability"] = json_round(self.reliability)
        if self.stop:
            data["stop"] = True
        if not self.reachable:
            data["reachable"] = False
        if self.reason:
            data["reason"] = self.reason
        return data


@dataclass(frozen=True)
class StepScores:
    """Everything the one-step fixture problem of one push computed (for records, heatmaps).

    ``step`` is the 0-based index of the push in the nominal plan. ``placements`` are the
    placement-stage candidates at ``selection_multiplier`` ("no fixture" first, then the grid
    placements in grid order, blocked ones included), ``refined`` the push-distance stage
    (every multiplier of the best placements and of no fixture), ``best`` the winner (``None``
    when every candidate is invalid). ``swaths`` holds ``(part, (xmin, ymin, xmax, ymax))``.
    ``backoff`` is how far the push's approach pose was moved back along the push (its
    distance grown by as much) so that its approach shadow clears the belief's shadows; 0 when
    it already did. ``rejected`` holds the valid candidates (by key) that the repair checked in
    the deterministic semantics and refused, with why: with them the plan would no longer
    reach the goal nominally, or a later action would fail.
    """

    step: int
    push: Push
    backoff: float
    belief: ParticleBelief
    nominal_state: WorldState
    nominal_next: WorldState
    method: str
    selection_multiplier: float
    swaths: tuple[Swath, ...]
    placements: tuple[Candidate, ...]
    refined: tuple[Candidate, ...]
    best: Candidate | None
    simulations: int
    elapsed: float
    after: ParticleBelief | None = field(default=None, repr=False, compare=False)
    rejected: tuple[tuple[Key, str], ...] = ()

    @property
    def no_fixture(self) -> Candidate:
        """The "no fixture" candidate of the placement stage."""
        return self.placements[0]


@dataclass
class Outcome:
    """A candidate simulated on every particle: the belief after it, or why it failed."""

    belief: ParticleBelief | None
    distance: float
    reason: str = ""
    reachable: bool = True


# -- the grid, the swaths, the approach -------------------------------------------------------
def clear_approach(
    problem: ArrangementProblem, checker: CollisionChecker, intervals: IntervalBelief, push: Push
) -> tuple[Pose, float]:
    """The push's approach pose moved back along the push, in steps of :data:`BACKOFF_STEP`,
    until its approach shadow (pose +- push uncertainty) clears every shadow of ``intervals``
    with :data:`BACKOFF_GAP` to spare (the push precondition of
    :mod:`arrange_up.planning.actions`, on the belief instead of the nominal state); and how
    far. Gives up at :data:`MAX_BACKOFF` (the push then keeps its pose and fails in the
    particles it lands on)."""
    spec = problem.object(push.manipulator)
    ux, uy = rotate(spec.push_direction, push.pose[2])
    half = tuple(v + BACKOFF_GAP if k < 2 else v for k, v in enumerate(problem.uncertainty.push))
    others = [(name, iv.center, iv.half) for name, iv in intervals.objects]
    n = int(round(MAX_BACKOFF / BACKOFF_STEP))
    for k in range(n + 1):
        b = round(k * BACKOFF_STEP, 9)
        pose = (
            round_pose_value(push.pose[0] - b * ux),
            round_pose_value(push.pose[1] - b * uy),
            push.pose[2],
        )
        if not any(
            checker.shadows_overlap((push.manipulator, pose, half), other)  # type: ignore[arg-type]
            for other in others
        ):
            return pose, b
    return push.pose, 0.0


def grid_placements(
    problem: ArrangementProblem,
    checker: CollisionChecker,
    intervals: IntervalBelief,
    on_table: Sequence[str],
    push: Push,
) -> list[tuple[str, Pose, bool]]:
    """Grid placements of every fixture not in ``on_table``: ``(fixture, pose, allowed)``.

    ``allowed`` is the place precondition on the belief ``intervals`` (the place shadow on the
    table, clear of every shadow) with the push's approach shadow counted as an obstacle.
    """
    width, depth = problem.table.size
    allowed = _place_check(problem, checker, intervals, push)
    xs = _grid(width, GRID_STEP)
    ys = _grid(depth, GRID_STEP)
    out = []
    for spec in problem.fixtures:
        if spec.name in on_table:
            continue
        for theta in fixture_angles(problem, spec.name):
            for y in ys:
                for x in xs:
                    pose = (x, y, theta)
                    out.append((spec.name, pose, allowed(spec.name, pose)))
    return out


def stop_placements(
    problem: ArrangementProblem,
    checker: CollisionChecker,
    intervals: IntervalBelief,
    on_table: Sequence[str],
    push: Push,
    before: ParticleBelief,
    ends: ParticleBelief,
    nominal_next: WorldState,
    parts: Sequence[str],
) -> list[tuple[str, Pose, bool]]:
    """Grid placements where a fixture stops a pushed part along the direction its end is
    uncertain: ``(fixture, pose, allowed)`` as :func:`grid_placements` gives them.

    ``ends`` is the belief ``before`` after the bare push (the same particles, in order). For
    every part of ``parts`` that the push moved,
    the axis (x or y) along which its end positions spread most, and the other axis too when
    its spread is at least half as wide, is *uncertain*. On each side of the part's footprint
    in ``nominal_next`` along such an axis, each fixture off the table is turned its thin way
    towards the part and placed flush with that footprint, its centre moved to the two nearest
    points of the placement grid (:data:`GRID_STEP`) along the axis and across it. The side
    behind the part along the push is left out: a fixture there stands in the part's way.
    """
    spec_push = problem.object(push.manipulator)
    ux, uy = rotate(spec_push.push_direction, push.pose[2])
    along_push = (round(ux), round(uy))
    nominal = nominal_next.as_dict()
    names = ends.names()
    allowed = _place_check(problem, checker, intervals, push)
    width, depth = problem.table.size
    lines = (_grid(width, GRID_STEP), _grid(depth, GRID_STEP))
    out: dict[tuple[str, Pose], bool] = {}
    for k, name in enumerate(names):
        if name not in parts or name not in nominal:
            continue
        if name not in before.names() or np.allclose(
            before.poses[:, before.names().index(name), :2], ends.poses[:, k, :2], atol=1e-6
        ):
            continue
        spread = ends.poses[:, k, :2].std(axis=0)
        if not spread.max() > 0.0:
            continue
        box = checker.shadow_box(name, nominal[name], _ZERO)
        centre = ((box[0] + box[2]) / 2, (box[1] + box[3]) / 2)
        for axis in (0, 1):
            if spread[axis] < 0.5 * spread.max():
                continue
            across = 1 - axis
            for side in (-1, 1):
                if along_push[axis] == -side:  # behind the part: in its way
                    continue
                for spec in problem.fixtures:
                    if spec.name in on_table:
                        continue
                    theta, half = min(
                        (
                            (t, (b[2 + axis] - b[axis]) / 2)
                            for t in fixture_angles(problem, spec.name)
                            for b in (footprint(checker, spec.name, (0.0, 0.0, t)),)
                        ),
                        key=lambda th: th[1],
                    )
                    face = box[2 + axis] if side > 0 else box[axis]
                    flush = face + side * half
                    for a in _nearest(lines[axis], flush):
                        for c in _nearest(lines[across], centre[across]):
                            xy = (a, c) if axis == 0 else (c, a)
                            pose = (xy[0], xy[1], theta)
                            if (spec.name, pose) not in out:
                                out[(spec.name, pose)] = allowed(spec.name, pose)
    return [(fixture, pose, ok) for (fixture, pose), ok in out.items()]


def _place_check(
    problem: ArrangementProblem, checker: CollisionChecker, intervals: IntervalBelief, push: Push
) -> Callable[[str, Pose], bool]:
    """The place precondition on the belief ``intervals``: the fixture's place shadow on the
    table, clear of every shadow and of the push's approach shadow."""
    place_unc = problem.uncertainty.place
    others = [(name, iv.center, iv.half) for name, iv in intervals.objects]
    others.append((push.manipulator, push.pose, problem.uncertainty.push))

    def allowed(fixture: str, pose: Pose) -> bool:
        return checker.shadow_inside_table(fixture, pose, place_unc) and checker.shadow_clear(
            fixture, pose, place_unc, others
        )

    return allowed


def _nearest(lines: Sequence[float], value: float) -> list[float]:
    """The two grid lines nearest ``value`` (one when it lies on a line or past the ends)."""
    below = [v for v in lines if v <= value + 1e-9]
    above = [v for v in lines if v >= value - 1e-9]
    return sorted({*below[-1:], *above[:1]})


def part_swaths(
    checker: CollisionChecker,
    parts: Sequence[str],
    belief: ParticleBelief,
    after: list[dict[str, Pose]],
) -> tuple[Swath, ...]:
    """Part motion swaths: per part that moved, the box over its footprints before/after."""
    out = []
    for name in belief.names():
        if name not in parts:
            continue
        before = [dict(s.poses)[name] for s in belief.particles]
        final = [p[name] for p in after if name in p]
        if all(
            math.dist(a[:2], b[:2]) < 1e-6 and abs(a[2] - b[2]) < 1e-6
            for a, b in zip(before, final, strict=True)
        ):
            continue
        boxes = [checker.shadow_box(name, pose, _ZERO) for pose in before + final]
        out.append((name, boxes_union(boxes)))
    return tuple(out)


def footprint(checker: CollisionChecker, fixture: str, pose: Pose) -> tuple[float, ...]:
    """The axis-aligned box of ``fixture``'s footprint at ``pose`` (no uncertainty)."""
    return checker.shadow_box(fixture, pose, _ZERO)


# -- scoring ---------------------------------------------------------------------------------
def mean_distance(belief: ParticleBelief, nominal: WorldState, parts: Sequence[str]) -> float:
    """SCOREACTIONS's DISTANCE averaged over particles: per particle the Manhattan distance
    (x + y) of every part from its nominal pose, summed over the parts."""
    names = belief.names()
    nominal_poses = nominal.as_dict()
    columns = [k for k, n in enumerate(names) if n in nominal_poses and n in parts]
    if not columns:
        return 0.0
    target = np.array([nominal_poses[names[k]][:2] for k in columns])
    diff = np.abs(belief.poses[:, columns, :2] - target[None, :, :])
    return float(diff.sum(axis=(1, 2)).mean())


def candidate(key: Key, outcome: Outcome, push: Push) -> Candidate:
    """The candidate of ``key`` from its simulated ``outcome``."""
    fixture, pose, multiplier = key
    if outcome.belief is None:
        return Candidate(
            fixture,
            pose,
            multiplier,
            INVALID,
            math.inf,
            reachable=outcome.reachable,
            reason=outcome.reason,
            push=push,
        )
    return Candidate(
        fixture, pose, multiplier, OK, outcome.distance, reachable=outcome.reachable, push=push
    )


def stage_candidates(
    grid: list[tuple[str | None, Pose | None, bool]],
    multiplier: float,
    outcomes: dict[Key, Outcome],
    pushed: Callable[[float], Push],
) -> list[Candidate]:
    """The normalised candidates of ``grid`` at ``multiplier``: blocked ones as they are, the
    others from their ``outcomes``."""
    out = []
    for fixture, pose, allowed in grid:
        if not allowed:
            out.append(
                Candidate(
                    fixture,
                    pose,
                    multiplier,
                    BLOCKED,
                    math.nan,
                    reason="the place precondition fails on the belief's shadows",
                    push=pushed(multiplier),
                )
            )
            continue
        key = (fixture, pose, multiplier)
        out.append(candidate(key, outcomes[key], pushed(multiplier)))
    return normalise(out)


def choose(
    valid: list[Candidate], rejects: Callable[[Candidate], str] | None = None
) -> Candidate | None:
    """The winner among valid candidates: the most reliable (:attr:`Candidate.reliability`,
    0 when not estimated), ties broken by the smaller distance, then the smaller multiplier;
    except that a fixture must beat the best bare push: be more reliable, or as reliable and
    closer by more than :data:`MIN_FIXTURE_GAIN`.

    ``rejects`` (when given) says why a candidate may not win (empty when it may): the repair
    rejects a candidate whose plan is no longer a nominal plan. It is asked lazily, best
    candidate first, until the best bare push and the best fixture it accepts are found. The
    fixture must beat the best accepted bare push or, when no bare push is accepted, the best
    bare push: ``None`` when it does not.
    """
    if not valid:
        return None

    def best(group: list[Candidate]) -> Candidate | None:
        for c in sorted(group, key=rank):
            if rejects is None or not rejects(c):
                return c
        return None

    bare = [c for c in valid if c.fixture is None or not c.reachable]
    best_bare = best(bare)
    best_fixed = best([c for c in valid if c.fixture is not None and c.reachable])
    if best_fixed is None:
        return best_bare
    # the bar a fixture must clear is the best bare push; when ``rejects`` refuses every bare
    # push, still the best of them: a fixture that scores worse than pushing without it is
    # never placed (no candidate wins then)
    reference = best_bare or min(bare, key=rank, default=None)
    if reference is None:
        return best_fixed
    gained = _reliability(best_fixed) - _reliability(reference)
    if gained > 0:
        return best_fixed
    gain = reference.distance - best_fixed.distance
    if gained == 0 and gain > max(MIN_FIXTURE_GAIN[0], MIN_FIXTURE_GAIN[1] * reference.distance):
        return best_fixed
    return best_bare


def rank(c: Candidate) -> tuple[float, float, float]:
    """The order :func:`choose` prefers candidates in: most reliable, closest, shortest."""
    return (-_reliability(c), c.distance, c.multiplier)


def _reliability(c: Candidate) -> float:
    return 0.0 if c.reliability is None else c.reliability


def normalise(candidates: list[Candidate]) -> list[Candidate]:
    """Figure 4-10's min-max scaling over the valid candidates (invalid ones keep None)."""
    finite = [c.distance for c in candidates if c.valid]
    if not finite:
        return candidates
    low, high = min(finite), max(finite)
    span = high - low
    return [
        replace(c, score=(c.distance - low) / span if span > 0 else 0.0) if c.valid else c
        for c in candidates
    ]


# -- numbers ---------------------------------------------------------------------------------
def _grid(size: float, step: float) -> list[float]:
    n = int(math.floor(size / step + 1e-9))
    return [round(k * step, 9) for k in range(1, n) if k * step < size - 1e-9]


def round_pose_value(value: float) -> float:
    """A computed pose coordinate or push distance, rounded to 1e-6 (and never ``-0.0``)."""
    return round(float(value), 6) + 0.0


def json_round(value: float) -> float:
    """A float as written in a plan file: 12 significant digits."""
    return float(f"{value:.12g}")


def json_float(value: float | None) -> float | None:
    """JSON has no infinity or NaN: those are written as null."""
    if value is None or not math.isfinite(value):
        return None
    return json_round(value)
