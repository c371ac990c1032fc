"""Goal parts that cannot fit on the table: a proof, before any search, that no plan exists.

:func:`unfit_parts` (and :func:`~arrange_up.planning.planner.too_large`, its part names) finds
the goal parts (a relative goal's reference included: it must be on the table too) that can
be on the table at no pose the goal accepts. The planner then answers ``unsolvable`` without
searching, so every answer here must be a *proof*: a part is reported only when the argument
below holds for every orientation its goal allows; a borderline case is left to the search.

**What a part's footprint must satisfy.** The table is ``[0, W] x [0, D]``. Two facts bound
where a part can be:

1. A part that starts off the table must be placed, and the place precondition keeps its
   place shadow (which contains the nominal footprint) inside ``[0, W] x [0, D]``; a part that
   starts on the table lies inside it (the loader refuses any other start). So a goal part
   reaches the table only if its footprint fits ``[0, W] x [0, D]`` at *some* angle (to the
   loader's tolerance; :data:`START_SLACK` allows more): when it fits at no angle at all, no
   plan exists, whatever the walls. This holds on every table.
2. On a table with walls on all four edges, rigid walls keep every footprint inside the table
   at all times (up to the physics' contact slop; :data:`WALL_SLACK` allows ten times it), so
   at the goal the footprint must lie inside the table *at the goal's angle and position*. An
   open edge lets a part hang over it (only its centroid must stay on the table), and lets it
   reach round the end of the wall beside that edge, so this second fact is used only on a
   table closed on all four sides.

**Which poses the goal allows.** An absolute goal accepts angles within ``theta ± dtheta``
modulo the part's symmetry period ``P`` (:func:`~arrange_up.belief.states.symmetry_period`):
the union over ``k`` of ``[theta - dtheta + kP, theta + dtheta + kP]`` (every angle when the
tolerance allows any angle, or when ``2 dtheta >= P``), each copy checked on its own (no
reliance on the symmetry being exact), and positions ``x ± dx``, ``y ± dy``. A relative goal
fixes poses in the frame of the reference part, which may end anywhere at any angle, so each
of its parts (and the reference) is allowed every angle and every position. (The footprint of
the whole relative arrangement is not tested: its parts may shift and turn within the
tolerance, which makes a sound bound more work than it is worth; each part alone is.)

**The test at one angle.** Turned by ``a``, the part's vertices ``v`` (in its own frame, about
its centroid) project on x at ``px(v, a) = vx cos a - vy sin a``; with
``lo(a) = min_v px``, ``hi(a) = max_v px`` its footprint at centroid ``x`` spans
``[x + lo(a), x + hi(a)]``. Inside the table (with slack ``s``) needs ``x >= -lo(a) - s`` and
``x <= W - hi(a) + s``; with ``x`` in the goal's ``[x0, x1]`` that is possible only if
``-lo(a) - s <= x1``, ``W - hi(a) + s >= x0`` and ``hi(a) - lo(a) <= W + 2s`` (the x-extent);
likewise in y (``py = vx sin a + vy cos a``). Without a position (fact 1, relative goals) only
the extents count. An angle is ruled out when one of these conditions fails.

**Over an interval of angles, soundly.** A finite set of sampled angles proves nothing about
the angles between them; instead the allowed angles are covered by cells
``[c - h, c + h]`` (``2h`` at most :data:`ANGLE_STEP`) and each cell is ruled out as a whole
with lower bounds. Each ``px(v, a)`` changes with ``a`` at rate ``|vx sin a + vy cos a| <= |v|
<= r``, ``r`` the part's largest vertex distance from its centroid; a max or min of functions
of slope at most ``r`` has slope at most ``r``, and a difference of two such at most ``2r``.
So on the cell ``hi(a) >= hi(c) - r h``, ``-lo(a) >= -lo(c) - r h`` and
``hi(a) - lo(a) >= hi(c) - lo(c) - 2 r h``: a cell whose lower bound already breaks a
condition breaks it at every angle in the cell. A part is reported when every cell of its
allowed angles is ruled out. With the 0.1 degree step the bounds give away at most
``r * 0.00087`` (0.005 in for a 12 in bar), so only parts that miss by less than that and the
slack are left to the search.

The message (:attr:`Unfit.why`) names the part, its size, the table's and the goal's angles
(and positions, when the position was needed for the proof) in the problem's display units.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from arrange_up.belief.states import symmetry_period
from arrange_up.model.problem import WALL_EDGES, ArrangementProblem, Shape

__all__ = ["ANGLE_STEP", "START_SLACK", "WALL_SLACK", "Unfit", "too_large", "unfit_parts"]

#: How far (in) a footprint may be taken to press into a wall: ten times the physics' contact
#: slop (``PhysicsSettings.collision_slop``, 0.005 in), so that a part squeezed against walls
#: never counts as fitting less than it does.
WALL_SLACK = 0.05
#: Widest cell (rad) of allowed angles ruled out at once (0.1 degree; the module docstring).
ANGLE_STEP = math.radians(0.1)
#: How far (in) a part may stick out of the table at its start or place: the loader's
#: ``BOUNDS_TOLERANCE`` (1e-9), with room to spare.
START_SLACK = 1e-6
#: Slack on the goal's tolerances, as the goal test allows (``arrange_up.belief.goals.EPS``).
GOAL_EPS = 1e-9

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Unfit:
    """A goal part that cannot be on the table at any pose its goal allows, and why (one
    clause, in the problem's display units)."""

    part: str
    why: str


def too_large(problem: ArrangementProblem) -> tuple[str, ...]:
    """The goal parts that cannot lie on the table at any pose their goal allows (for a
    relative goal, the reference included): a proof that no plan exists, since every goal
    part must end on the table within its goal. The reasoning, and why it is sound, is in
    :mod:`arrange_up.planning.fitting`; :func:`unfit_parts` also says why."""
    return tuple(u.part for u in unfit_parts(problem))


def unfit_parts(problem: ArrangementProblem) -> tuple[Unfit, ...]:
    """:func:`too_large` with the reason of each part (:attr:`Unfit.why`)."""
    goal = problem.goal
    closed = set(WALL_EDGES) <= set(problem.table.walls)
    names = list(goal.parts)
    if goal.reference is not None and goal.reference not in names:
        names.insert(0, goal.reference)
    found = []
    for name in names:
        shape = problem.object(name).shape
        if shape is None:
            continue
        target = None if goal.is_relative else goal.target(name)
        fact = _unfit_fact(
            problem.table.size, closed and not goal.is_relative, shape, target, goal.tolerance
        )
        if fact is not None:
            found.append(
                Unfit(
                    name,
                    _why(problem, name, shape, None if fact == 1 else target, fact == 3),
                )
            )
    return tuple(found)


@functools.lru_cache(maxsize=4096)
def _unfit_fact(
    table: tuple[float, float],
    walled: bool,
    shape: Shape,
    target: tuple[float, float, float] | None,
    tolerance: tuple[float, ...],
) -> int | None:
    """Which fact rules a part of ``shape`` out (1: the table at any angle; 2: inside the
    walls at the goal's angles; 3: and positions), None when none does. ``walled``: the table
    is closed by walls and the goal absolute (``target`` set), so facts 2 and 3 apply.
    Remembered: the goal agenda asks again for every subgoal, and the answer depends on these
    values only."""
    vertices = np.array(list(shape.vertices()), dtype=float).reshape(-1, 2)
    if len(vertices) == 0:
        return None
    # Fact 1: fits the table at no angle at all.
    if _ruled_out(vertices, [(0.0, TWO_PI)], table, None, START_SLACK):
        return 1
    if not walled or target is None:
        # A relative goal allows every angle and position: fact 2 adds nothing to fact 1
        # but the slack, so it is not tried.
        return None
    intervals = _allowed_angles(target[2], tolerance[2], shape)
    if intervals is None:
        intervals = [(0.0, TWO_PI)]
    # Fact 2: the walls keep the footprint inside the table at the goal's angles ...
    if _ruled_out(vertices, intervals, table, None, WALL_SLACK):
        return 2
    # ... and positions.
    boxes = tuple(
        (target[i] - tolerance[i] - GOAL_EPS, target[i] + tolerance[i] + GOAL_EPS) for i in (0, 1)
    )
    if _ruled_out(vertices, intervals, table, boxes, WALL_SLACK):
        return 3
    return None


def _allowed_angles(
    theta: float, tolerance: float | None, shape: Shape
) -> list[tuple[float, float]] | None:
    """The angle intervals an absolute goal at ``theta`` accepts (the module docstring), or
    None when it accepts every angle."""
    if tolerance is None:
        return None
    period = symmetry_period(shape)
    half = tolerance + GOAL_EPS
    if 2.0 * half >= period:
        return None
    copies = max(1, round(TWO_PI / period))
    return [(theta + k * period - half, theta + k * period + half) for k in range(copies)]


def _ruled_out(
    vertices: np.ndarray,
    intervals: list[tuple[float, float]],
    table: tuple[float, float],
    boxes: tuple[tuple[float, float], tuple[float, float]] | None,
    slack: float = 0.0,
) -> bool:
    """Whether the part of ``vertices`` (about its centroid) fits inside ``[0, W] x [0, D]``
    (``table``, each side widened by ``slack``) at no angle of ``intervals``, with its
    centroid anywhere or (``boxes``) within ``[x0, x1]`` and ``[y0, y1]``: every cell of the
    intervals is ruled out by the lower bounds of the module docstring."""
    radius = float(np.hypot(vertices[:, 0], vertices[:, 1]).max())
    centres, halves = [], []
    for low, high in intervals:
        cells = max(1, math.ceil((high - low) / ANGLE_STEP))
        step = (high - low) / cells
        centres.append(low + step * (np.arange(cells) + 0.5))
        halves.append(np.full(cells, 0.5 * step))
    c = np.concatenate(centres)
    h = np.concatenate(halves)
    cos, sin = np.cos(c)[:, None], np.sin(c)[:, None]
    vx, vy = vertices[:, 0][None, :], vertices[:, 1][None, :]
    projections = (vx * cos - vy * sin, vx * sin + vy * cos)  # (cell, vertex) on x and on y
    out = np.zeros(len(c), dtype=bool)
    for axis, size in enumerate(table):
        p = projections[axis]
        hi = p.max(axis=1) - radius * h  # lower bounds over each cell
        neg_lo = -p.min(axis=1) - radius * h
        extent = p.max(axis=1) - p.min(axis=1) - 2.0 * radius * h
        out |= extent > size + 2.0 * slack
        if boxes is not None:
            low, high = boxes[axis]
            out |= neg_lo - slack > high  # the footprint crosses the low wall at any x <= high
            out |= size - hi + slack < low  # ... or the high wall at any x >= low
    return bool(out.all())


def _why(
    problem: ArrangementProblem,
    name: str,
    shape: Shape,
    target: tuple[float, float, float] | None,
    positioned: bool,
) -> str:
    """The clause of :attr:`Unfit.why`: "part A (12 x 1 in) fits the 10 x 5 in table at no
    angle its goal allows (0 ± 15°)"."""
    units = problem.units
    if shape.box is not None:
        sizes = shape.box
    else:
        xmin, ymin, xmax, ymax = shape.extent
        sizes = (xmax - xmin, ymax - ymin)
    size = " x ".join(_num(units.length_out(v)) for v in sizes)
    table = " x ".join(_num(units.length_out(v)) for v in problem.table.size)
    head = f"part {name} ({size} {units.length}) fits the {table} {units.length} table at no"
    if target is None:
        return f"{head} angle"
    tol = problem.goal.tolerance
    if tol[2] is None:
        angle = "any angle"
    else:
        angle = f"{_num(units.angle_out(target[2]))} ± {_num(units.angle_out(tol[2]))}"
        angle = "angle " + angle + ("°" if units.angle == "deg" else f" {units.angle}")
    if not positioned:
        return f"{head} angle its goal allows ({angle.removeprefix('angle ')})"
    x, y = (
        f"{axis} {_num(units.length_out(target[i]))} ± {_num(units.length_out(tol[i]))}"
        for i, axis in enumerate("xy")
    )
    return f"{head} pose its goal allows ({x}, {y} {units.length}, {angle})"


def _num(value: float) -> str:
    """``value`` to 4 significant digits, as short as it reads ("12", "0.2", "3.142")."""
    text = f"{value:.4g}"
    return "0" if text == "-0" else text
