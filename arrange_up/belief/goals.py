"""Goal satisfaction (thesis §2.1.4), compiled once per problem into numpy operations.

A world state satisfies an absolute goal when every goal part is on the table with
``|x - gx| <= tol_x``, ``|y - gy| <= tol_y`` and (unless the tolerance allows any angle)
``|theta - gtheta| <= tol_theta``, the angle difference taken modulo the part's symmetry period
(a square block turned by 90 degrees is the same block). For a relative goal the same test is
applied to each part's pose expressed in the reference part's frame. A particle belief
satisfies the goal when every particle does (§1.2.2).

A fixture that starts off the table must be off it again at the end: a fence the planner puts
down is picked up before the goal counts as reached (the plans of the fixture repair always
were; a fixture that starts on the table may stay).

Everything is vectorised over particles: goal tests run in the search's inner loop, where going
through unified-planning expressions would cost ~100x more.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from arrange_up.belief.states import symmetry_period
from arrange_up.model.problem import ArrangementProblem, as_triple
from arrange_up.model.world import WorldState

#: Numerical slack on tolerance comparisons (inches / radians).
EPS = 1e-9


@dataclass(frozen=True)
class PartMiss:
    """How one part misses its goal in one state: per-dimension excess beyond the tolerance
    (0 where within), or ``missing`` when the part is not on the table; for a fixture that
    started off the table, ``left`` when it is still on it (``part`` then names the fixture)."""

    part: str
    missing: bool
    excess: tuple[float, float, float]
    left: bool = False

    def dimensions(self) -> tuple[str, ...]:
        if self.missing:
            return ("off table",)
        if self.left:
            return ("on table",)
        return tuple(d for d, e in zip(("x", "y", "theta"), self.excess, strict=True) if e > 0)


class GoalTest:
    """The goal of one problem, ready to test world states and particle arrays."""

    def __init__(self, problem: ArrangementProblem) -> None:
        goal = problem.goal
        self.problem = problem
        self.parts: tuple[str, ...] = goal.parts
        self.reference: str | None = goal.reference
        self.targets = np.array([goal.target(p) for p in self.parts], dtype=float).reshape(-1, 3)
        tol = goal.tolerance
        self.tolerance = np.array([tol[0], tol[1], math.inf if tol[2] is None else tol[2]])
        self.periods = np.array(
            [symmetry_period(problem.object(p).shape) for p in self.parts], dtype=float
        )
        #: Fixtures that start off the table, and so must end off it (module docstring).
        self.put_away: frozenset[str] = frozenset(problem.put_away)

    # -- coordinates ---------------------------------------------------------------------------
    def coordinates(self, poses: np.ndarray, names: Sequence[str]) -> np.ndarray | None:
        """Goal-frame coordinates of the goal parts, shape ``(P, n_goal_parts, 3)``.

        ``poses`` is ``(P, len(names), 3)``. For an absolute goal these are world poses; for a
        relative one, poses in the reference part's frame. Angles are wrapped into the period
        around their target. Returns ``None`` if a goal part (or the reference) is not among
        ``names``.
        """
        index = {name: i for i, name in enumerate(names)}
        if any(p not in index for p in self.parts):
            return None
        return self._coordinates(poses, index, list(range(len(self.parts))))

    def _coordinates(
        self, poses: np.ndarray, index: dict[str, int], which: list[int]
    ) -> np.ndarray | None:
        """:meth:`coordinates` of the goal parts ``which`` (indices into ``parts``), each of
        them among ``index``; None when the goal's reference is not."""
        coords = poses[:, [index[self.parts[k]] for k in which], :].copy()
        if self.reference is not None:
            if self.reference not in index:
                return None
            ref = poses[:, index[self.reference], :][:, None, :]
            dx, dy = coords[..., 0] - ref[..., 0], coords[..., 1] - ref[..., 1]
            c, s = np.cos(ref[..., 2]), np.sin(ref[..., 2])
            coords[..., 0] = c * dx + s * dy
            coords[..., 1] = -s * dx + c * dy
            coords[..., 2] = coords[..., 2] - ref[..., 2]
        targets = self.targets[which]
        periods = self.periods[which]
        half = 0.5 * periods
        coords[..., 2] = targets[:, 2] + ((coords[..., 2] - targets[:, 2] + half) % periods) - half
        return coords

    def excess(self, poses: np.ndarray, names: Sequence[str]) -> np.ndarray | None:
        """Per particle, part and dimension: how far beyond the tolerance (0 where within)."""
        coords = self.coordinates(poses, names)
        return None if coords is None else self._beyond(coords, self.targets)

    def _beyond(self, coords: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """How far goal-frame ``coords`` lie beyond the tolerance about ``targets`` (their
        goal parts' rows of :attr:`targets`), per dimension; 0 where within."""
        beyond: np.ndarray = np.maximum(np.abs(coords - targets) - self.tolerance - EPS, 0.0)
        return beyond

    # -- tests -----------------------------------------------------------------------------
    def satisfied_array(self, poses: np.ndarray, names: Sequence[str]) -> bool:
        """True if every particle of ``poses`` (``(P, n, 3)``) satisfies the goal."""
        if self.put_away and not self.put_away.isdisjoint(names):
            return False
        excess = self.excess(poses, names)
        return excess is not None and not bool(np.any(excess > 0.0))

    def satisfied(self, state: WorldState) -> bool:
        return self.satisfied_array(_as_array(state), state.names())

    def misses(self, state: WorldState) -> tuple[PartMiss, ...]:
        """Why ``state`` fails the goal, part by part (empty when it satisfies it)."""
        return self.misses_array(_as_array(state), state.names())

    def misses_array(self, poses: np.ndarray, names: Sequence[str]) -> tuple[PartMiss, ...]:
        """Why the particles ``poses`` (``(P, n, 3)``) fail the goal, part by part: the goal
        parts (and reference) not on the table, the fixtures to put away still on it, then the
        goal parts on the table that miss their goal, a part's excess in a dimension the
        largest over the particles (empty when all satisfy it). A part on the table is judged
        even while others are off it; a relative goal's mates only while its reference is on
        the table."""
        index = {name: i for i, name in enumerate(names)}
        missing = [p for p in self.parts if p not in index]
        if self.reference is not None and self.reference not in index:
            missing.append(self.reference)
        left = tuple(
            PartMiss(name, False, (0.0, 0.0, 0.0), left=True)
            for name in names
            if name in self.put_away
        )
        which = [k for k, p in enumerate(self.parts) if p in index]
        coords = self._coordinates(poses, index, which) if which else None
        judged: tuple[PartMiss, ...] = ()
        if coords is not None:
            worst = self._beyond(coords, self.targets[which]).max(axis=0)
            judged = tuple(
                PartMiss(self.parts[k], False, as_triple(float(v) for v in worst[i]))
                for i, k in enumerate(which)
                if np.any(worst[i] > 0.0)
            )
        return tuple(PartMiss(p, True, (0.0, 0.0, 0.0)) for p in missing) + left + judged


def _as_array(state: WorldState) -> np.ndarray:
    return np.array([[pose for _, pose in state.poses]], dtype=float).reshape(1, -1, 3)
