"""Search heuristics of the thesis (§2.2.2, §3.2), evaluated on particle beliefs.

A particle belief's heuristic is computed from the interval fitted over its particles, which
for the per-dimension count equals the maximum over particles that the thesis prescribes for
particle beliefs (§3.1): an interval is inside the goal interval iff every particle is.

* ``blind``: 0 everywhere (uniform-cost search).
* ``manhattan``: the sum over goal parts of the Manhattan distance (x plus y, in inches) from
  the belief centre to the target (Figure 2-12). Not measured in actions, so neither
  admissible nor comparable to action costs; useful for greedy search and fixture scoring.
* ``ordering``: the part-ordering filter (Figure 2-13, §3.2's "admissible" heuristic):
  infinite when two parts that share a row (column) in the goal sit in that row (column) in the
  wrong order, so that no sequence of pushes can reorder them, or when a goal part still off
  the table can never be placed: each of its place candidates overlaps both the current shadow
  and the goal footprint of some part on the table (parts placed out of order have walled it
  in; the planner only moves parts towards their goals, so the overlap stays), or two goal
  parts still off the table can be placed in neither order (each placed first, at any of its
  open candidates, walls in every open candidate of the other by the same rule: the cells of a
  corner pocket, which must be filled from the walls outwards); else 0.
* ``admissible``: ``ordering`` plus one per goal part not yet on the table (each needs at least
  one place action) and one per fixture on the table that must be put away (each needs a pick:
  :mod:`arrange_up.belief.goals`). Still admissible, and a little better informed than the bare
  filter.
* ``inadmissible``: §3.2's per-dimension count: per goal part 2 if it is off the table, 2 if
  neither its x nor its y interval lies within the goal interval, 1 if exactly one does, else 0
  — plus 1 when x and y do but the angle interval does not (our goals also constrain the
  angle) — plus 1 per fixture on the table that must be put away (a fence the planner put down:
  it costs a pick, and without the count a search would put down fences in every combination
  before using one), combined with the ordering filter. Beliefs with equal counts are ordered by a
  fraction below one that grows with their Manhattan distance (a tie-breaker: it never
  outweighs a unit of the count).

The ordering filter applies to absolute goals only: for a relative goal the rows and columns
turn with the reference part.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from arrange_up.belief.compiled import CompiledProblem
from arrange_up.belief.goals import EPS, GoalTest
from arrange_up.belief.states import ParticleBelief
from arrange_up.geometry.boxes import boxes_overlap, boxes_union
from arrange_up.geometry.collision import CLEARANCE
from arrange_up.planning.actions import ActionGenerator

HEURISTICS = ("inadmissible", "admissible", "ordering", "manhattan", "blind")

Heuristic = Callable[[ParticleBelief], float]

#: Answers "which place candidates of that part does this part's belief block for good" the
#: ordering filter remembers.
BLOCKING_CACHE = 200_000
#: Pairs of goal parts whose blocking tables (the ordering filter's ``_pair_blocking``) are kept
#: across searches: the goal agenda searches the same problem with its goal restricted to more
#: and more parts, and a pair's table depends only on the world and the two parts' targets, so
#: each pair is computed once per run instead of once per subgoal.
PAIR_MEMO = 100_000
_PAIR_MEMO: dict[tuple, tuple | None] = {}


def check_heuristic(name: str) -> None:
    """``ValueError`` naming :data:`HEURISTICS` unless ``name`` is one of them."""
    if name not in HEURISTICS:
        raise ValueError(f"unknown heuristic {name!r}; expected one of {', '.join(HEURISTICS)}")


def make_heuristic(
    name: str,
    compiled: CompiledProblem,
    generator: ActionGenerator | None = None,
    ordering_filter: bool = True,
) -> Heuristic:
    """Build the named heuristic for ``compiled.problem``, on its goal test and collision
    checker (see the module docstring).

    ``generator`` (the planner's action generator) lets the ordering filter recognise goal
    parts that can no longer be placed; without it that part of the filter is off.
    ``ordering_filter=False`` leaves the filter out of every heuristic (none is ever infinite):
    the filter is itself a heuristic, and where it leaves nothing to search the planner searches
    again without it.
    """
    check_heuristic(name)
    problem, goal = compiled.problem, compiled.goal
    ordering = _OrderingFilter(compiled, generator)
    violated = ordering.violated if ordering_filter else _never

    def blind(_: ParticleBelief) -> float:
        return 0.0

    def manhattan(belief: ParticleBelief) -> float:
        coords = _coords(goal, belief)
        total = 0.0
        for k, part in enumerate(goal.parts):
            if coords is None or part not in belief.names():
                continue
            center = 0.5 * (coords[:, k, :2].min(axis=0) + coords[:, k, :2].max(axis=0))
            total += float(np.abs(center - goal.targets[k, :2]).sum())
        return total

    def admissible(belief: ParticleBelief) -> float:
        if violated(belief):
            return math.inf
        names = belief.names()
        return float(sum(1 for p in goal.parts if p not in names) + _left(goal, names))

    # The count is coarse: many beliefs share a value. A fraction below one, growing with
    # the Manhattan distance, orders beliefs of equal count by how far their parts still are
    # from the goal, without ever outweighing one unit of the count.
    span = (len(goal.parts) + 1) * (problem.table.width + problem.table.depth) + 1.0

    def inadmissible(belief: ParticleBelief) -> float:
        if violated(belief):
            return math.inf
        return per_dimension_count(goal, belief) + min(manhattan(belief) / span, 0.999)

    return {
        "blind": blind,
        "manhattan": manhattan,
        "ordering": lambda b: math.inf if violated(b) else 0.0,
        "admissible": admissible,
        "inadmissible": inadmissible,
    }[name]


def _never(_: ParticleBelief) -> bool:
    """The ordering filter left out: no belief violates it."""
    return False


def per_dimension_count(goal: GoalTest, belief: ParticleBelief) -> float:
    """The §3.2 count (see the module docstring), without the ordering filter."""
    names = belief.names()
    present = [p in names for p in goal.parts]
    if goal.reference is not None and goal.reference not in names:
        present = [False] * len(goal.parts)
    total = 2.0 * sum(1 for ok in present if not ok) + _left(goal, names)
    if not any(present):
        return total
    coords = _coords_partial(goal, belief, present)
    low, high = coords.min(axis=0), coords.max(axis=0)
    inside = (low >= goal.targets - goal.tolerance - EPS) & (
        high <= goal.targets + goal.tolerance + EPS
    )
    for k, ok in enumerate(present):
        if not ok:
            continue
        x_in, y_in, theta_in = bool(inside[k, 0]), bool(inside[k, 1]), bool(inside[k, 2])
        total += (not x_in) + (not y_in)
        if x_in and y_in and not theta_in:
            total += 1
    return total


def _left(goal: GoalTest, names) -> int:
    """The fixtures among ``names`` that must be off the table at the end (one pick each)."""
    return sum(1 for name in names if name in goal.put_away) if goal.put_away else 0


def _coords(goal: GoalTest, belief: ParticleBelief) -> np.ndarray | None:
    return goal.coordinates(belief.poses, belief.names())


def _coords_partial(goal: GoalTest, belief: ParticleBelief, present: list[bool]) -> np.ndarray:
    """Goal coordinates of every goal part; absent parts are padded with their own targets so
    one vectorised call serves all parts (their rows are ignored by the caller)."""
    names = list(belief.names())
    poses = belief.poses
    absent = [k for k, ok in enumerate(present) if not ok]
    if absent:
        extra = np.broadcast_to(goal.targets[absent], (len(belief), len(absent), 3))
        poses = np.concatenate([poses, extra], axis=1)
        names += [goal.parts[k] for k in absent]
    coords = goal.coordinates(poses, names)
    assert coords is not None
    return coords


class _OrderingFilter:
    """Detects goal parts that share a goal row/column but sit in it in the wrong order."""

    def __init__(self, compiled: CompiledProblem, generator: ActionGenerator | None):
        self.checker = checker = compiled.checker
        goal = compiled.goal
        self.generator = generator if goal.reference is None else None
        self.goal = goal
        self.goal_parts = goal.parts
        self.targets = {p: tuple(goal.targets[k]) for k, p in enumerate(goal.parts)}
        self.pairs: list[tuple[str, str, int]] = []  # (a, b, axis): goal has a before b on axis
        self._place_cache: dict[str, list] = {}
        self._goal_overlaps: dict[tuple[str, int, str], bool] = {}
        self._blocking: dict[tuple, frozenset[int]] = {}
        self._pairs_blocking = None
        #: What a pair's blocking table depends on besides the pair and its targets.
        problem = compiled.problem
        self._world = (
            problem.table,
            problem.objects,
            problem.uncertainty.place,
            problem.planning,
        )
        if goal.reference is not None:
            return
        boxes = {
            p: checker.shadow_box(p, tuple(goal.targets[k]), (0.0, 0.0, 0.0))
            for k, p in enumerate(goal.parts)
        }
        for i, a in enumerate(goal.parts):
            for b in goal.parts[i + 1 :]:
                for axis in (0, 1):
                    other = 1 - axis
                    ba, bb = boxes[a], boxes[b]
                    share = min(ba[other + 2], bb[other + 2]) - max(ba[other], bb[other]) > EPS
                    if not share:
                        continue
                    ca = goal.targets[goal.parts.index(a), axis]
                    cb = goal.targets[goal.parts.index(b), axis]
                    if ca < cb - EPS:
                        self.pairs.append((a, b, axis))
                    elif cb < ca - EPS:
                        self.pairs.append((b, a, axis))

    def violated(self, belief: ParticleBelief) -> bool:
        intervals = belief.intervals
        if self.generator is not None and len(intervals.objects) < len(self.goal_parts):
            placed = [(q, iv) for q, iv in intervals.objects if q in self.targets]
            alive: dict[str, list[int]] = {}
            for part in self.goal_parts:
                if part not in intervals:
                    alive[part] = self._open_candidates(part, intervals, placed)
                    if not alive[part]:
                        return True
            if self._no_place_order(alive, intervals):
                return True
        return self._row_order_violated(intervals)

    def _open_candidates(self, part: str, intervals, placed) -> list[int]:
        """The indices of ``part``'s place candidates that are not blocked for good.

        A candidate is blocked for good by a goal part ``q`` on the table when it overlaps both
        ``q``'s current shadow and ``q``'s goal footprint: the planner only ever moves ``q``
        towards its goal, and between two overlapping positions ``q`` keeps overlapping.
        """
        poses = self._candidates(part, intervals)
        blocked: set[int] = set()
        for q, interval in placed:
            blocked |= self._blocked_by(part, poses, q, interval)
        return [k for k in range(len(poses)) if k not in blocked]

    def _blocked_by(self, part: str, poses, q: str, interval) -> frozenset[int]:
        """The indices of ``part``'s place candidates (``poses``, fixed for an absolute goal)
        that ``q`` at ``interval`` blocks for good (:meth:`_open_candidates`); remembered,
        since the same parts' beliefs recur in many beliefs (up to :data:`BLOCKING_CACHE`)."""
        key = (part, q, interval)
        blocked = self._blocking.get(key)
        if blocked is None:
            half = self.generator.place_unc
            blocked = frozenset(
                k
                for k, pose in enumerate(poses)
                if self._meets_goal(part, k, pose, q)
                and self.checker.shadows_overlap(
                    (part, pose, half), (q, interval.center, interval.half)
                )
            )
            if len(self._blocking) >= BLOCKING_CACHE:
                self._blocking.clear()
            self._blocking[key] = blocked
        return blocked

    def _meets_goal(self, part: str, k: int, pose, q: str) -> bool:
        """Whether ``part``'s place candidate ``k`` (at ``pose``) overlaps ``q``'s goal
        footprint; both are fixed for an absolute goal, so each answer is computed once."""
        key = (part, k, q)
        meets = self._goal_overlaps.get(key)
        if meets is None:
            meets = self.checker.shadows_overlap(
                (part, pose, self.generator.place_unc), (q, self.targets[q], (0.0, 0.0, 0.0))
            )
            self._goal_overlaps[key] = meets
        return meets

    def _candidates(self, part: str, intervals) -> list:
        """``part``'s place candidates; for an absolute goal they never change, so cached."""
        if part not in self._place_cache:
            self._place_cache[part] = self.generator.place_poses(intervals, part)
        return self._place_cache[part]

    def _no_place_order(self, alive: dict[str, list[int]], intervals) -> bool:
        """True if two goal parts off the table can be placed in neither order.

        ``q`` can follow ``p`` when some open candidate of ``q`` is not blocked for good by
        ``p`` placed at one of its open candidates (the same rule as for parts on the table,
        with ``p`` anywhere between that candidate and its goal). Only pairs whose candidate
        shadows can reach each other's goal footprints are checked (:meth:`_pair_blocking`).
        """
        for (p, q), blocked in self._pair_blocking(intervals).items():
            if p not in alive or q not in alive:
                continue
            p_then_q = any(not blocked[0][i][j] for i in alive[p] for j in alive[q])
            q_then_p = any(not blocked[1][j][i] for i in alive[p] for j in alive[q])
            if not p_then_q and not q_then_p:
                return True
        return False

    def _pair_blocking(self, intervals):
        """For each unordered pair ``(p, q)`` of goal parts: ``(after_p, after_q)`` where
        ``after_p[i][j]`` says whether ``q``'s candidate ``j`` is blocked for good by ``p`` at
        its candidate ``i``, and ``after_q[j][i]`` the reverse; pairs where nothing is blocked
        are left out. Computed once (absolute goals: the candidates are fixed)."""
        if self._pairs_blocking is not None:
            return self._pairs_blocking
        half = self.generator.place_unc
        none = (0.0, 0.0, 0.0)
        poses = {p: self._candidates(p, intervals) for p in self.goal_parts}

        def blocked(a: str, pa, b: str, pb) -> bool:
            candidate = (b, pb, half)
            return self.checker.shadows_overlap(
                candidate, (a, pa, half)
            ) and self.checker.shadows_overlap(candidate, (a, self.targets[a], none))

        # ``q``'s candidate blocks ``p`` only where its shadow meets ``p``'s goal footprint, so
        # a pair whose candidates' boxes reach neither goal box blocks nothing: a box test
        # settles most pairs of a large problem instead of one shadow test per candidate pair.
        reach = {
            p: boxes_union(self.checker.shadow_box(p, c, half) for c in poses[p])
            for p in poses
            if poses[p]
        }
        goal_box = {p: self.checker.shadow_box(p, self.targets[p], none) for p in poses}

        def apart(p: str, q: str) -> bool:
            if p not in reach or q not in reach:
                return True  # a part without place candidates blocks nothing and is not blocked
            return not (
                boxes_overlap(reach[q], goal_box[p], -CLEARANCE)
                or boxes_overlap(reach[p], goal_box[q], -CLEARANCE)
            )

        table = {}
        for i, p in enumerate(self.goal_parts):
            for q in self.goal_parts[i + 1 :]:
                key = (self._world, p, self.targets[p], q, self.targets[q])
                if key in _PAIR_MEMO:
                    entry = _PAIR_MEMO[key]
                elif apart(p, q):
                    entry = None
                else:
                    after_p = [[blocked(p, pa, q, pb) for pb in poses[q]] for pa in poses[p]]
                    after_q = [[blocked(q, pb, p, pa) for pa in poses[p]] for pb in poses[q]]
                    entry = (
                        (after_p, after_q)
                        if any(any(row) for row in after_p) or any(any(row) for row in after_q)
                        else None
                    )
                    if len(_PAIR_MEMO) >= PAIR_MEMO:
                        _PAIR_MEMO.pop(next(iter(_PAIR_MEMO)))
                    _PAIR_MEMO[key] = entry
                if entry is not None:
                    table[(p, q)] = entry
        self._pairs_blocking = table
        return table

    def _row_order_violated(self, intervals) -> bool:
        for a, b, axis in self.pairs:
            ia, ib = intervals.get(a), intervals.get(b)
            if ia is None or ib is None:
                continue
            box_a = self.checker.shadow_box(a, ia.center, ia.half)
            box_b = self.checker.shadow_box(b, ib.center, ib.half)
            other = 1 - axis
            same_line = (
                min(box_a[other + 2], box_b[other + 2]) - max(box_a[other], box_b[other]) > EPS
            )
            # Wrong order: a must end before b along the axis, but lies entirely beyond it.
            if same_line and box_a[axis] >= box_b[axis + 2] - EPS:
                return True
        return False
