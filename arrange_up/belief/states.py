"""Belief states (thesis §1.2.3, §2.1.2): particle sets and factored intervals.

* :class:`ParticleBelief` is a tuple of world states ("particles") that all have the same
  objects on the table (the thesis assumes no uncertainty about *which* objects are there).
* :class:`IntervalBelief` is factored: for each object on the table a box in SE(2),
  ``center ± half``. A particle belief converts to one by taking per-object min/max
  (§2.1.2, "Particle belief-state to factored interval belief-state").
* :func:`dominates` is the domination test of §2.1.2: same objects, and every object's box
  contained in the other's.

Angles. A shape that looks the same after a rotation by ``2*pi/k`` (a square: k = 4) has
physically identical poses ``theta`` and ``theta + 2*pi/k``; pymunk happily reports either.
Every belief therefore stores angles *canonically*: wrapped into the half-open period
``[ref - period/2, ref + period/2)`` around the object's reference angle (its absolute goal
angle if it has one, else its initial angle if it starts on the table, else for a fixture the
middle of the turns it is placed at, :func:`fixture_turns`, else 0).
:func:`symmetry_period` finds the period from the geometry.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache, cached_property
from typing import TYPE_CHECKING

import numpy as np

from arrange_up.model.problem import (
    ArrangementProblem,
    HalfWidths,
    ObjectKind,
    Pose,
    Shape,
    as_triple,
)
from arrange_up.model.world import WorldState

if TYPE_CHECKING:  # the compiled problem holds this module's AngleFrame: imported for types only
    from arrange_up.belief.compiled import CompiledProblem

TWO_PI = 2.0 * math.pi


# -- angles ------------------------------------------------------------------------------------
@cache
def symmetry_period(shape: Shape) -> float:
    """The smallest rotation ``2*pi/k`` (k in 8, 6, 4, 3, 2) mapping the shape onto itself,
    else ``2*pi``. Decided on the geometry, with a relative area tolerance of 1e-6."""
    from shapely import affinity
    from shapely.geometry import Polygon
    from shapely.ops import unary_union

    outline = unary_union([Polygon(part) for part in shape.parts])
    tolerance = 1e-6 * outline.area
    for k in (8, 6, 4, 3, 2):
        turned = affinity.rotate(outline, 360.0 / k, origin=(0.0, 0.0))
        if outline.symmetric_difference(turned).area <= tolerance:
            return TWO_PI / k
    return TWO_PI


def fixture_turns(shape: Shape) -> tuple[float, ...]:
    """The distinct right-angle turns (0 and 90 degrees, fewer for a shape that looks the same
    turned) at which the planner's fences and the repair's grid place a fixture, ascending."""
    period = symmetry_period(shape)
    return tuple(sorted({round(a % period, 9) for a in (0.0, 0.5 * math.pi)}))


def wrap_angle(theta: float, reference: float, period: float) -> float:
    """``theta`` shifted by a multiple of ``period`` into ``[reference - period/2,
    reference + period/2)``."""
    return reference + ((theta - reference + 0.5 * period) % period) - 0.5 * period


@dataclass(frozen=True, eq=False)
class AngleFrame:
    """Reference angle and symmetry period of each movable object of a problem."""

    reference: dict[str, float]
    period: dict[str, float]

    @classmethod
    def of(cls, problem: ArrangementProblem) -> AngleFrame:
        reference: dict[str, float] = {}
        period: dict[str, float] = {}
        goal = problem.goal
        for spec in problem.objects:
            if spec.kind is ObjectKind.OBSTACLE:
                continue
            period[spec.name] = symmetry_period(spec.shape)
            initial = problem.initial_of(spec.name)
            if not goal.is_relative and spec.name in goal.parts:
                reference[spec.name] = goal.target(spec.name)[2]
            elif initial is not None:
                # Centre the period on where the object starts: wrapping at the start angle
                # itself would split one belief across the period's two ends.
                reference[spec.name] = initial.pose[2]
            elif spec.kind is ObjectKind.FIXTURE:
                # A bar (period 180 degrees) is placed at 0 and at 90 degrees: wrapped around 0
                # the second would split across the period's ends (-90 and +90 degrees, one
                # belief spanning every angle); the middle of its turns keeps both inside.
                turns = fixture_turns(spec.shape)
                reference[spec.name] = 0.5 * (turns[0] + turns[-1])
            else:
                reference[spec.name] = 0.0
        return cls(reference, period)

    def canonical(self, state: WorldState) -> WorldState:
        """The same state with every angle wrapped canonically (see the module docstring)."""
        return WorldState(
            tuple(
                (name, (p[0], p[1], wrap_angle(p[2], self.reference[name], self.period[name])))
                for name, p in state.poses
            )
        )


# -- interval beliefs ----------------------------------------------------------------------------
@dataclass(frozen=True)
class ObjectInterval:
    """An object's belief box in SE(2): pose ``center`` ± ``half`` (inches, radians)."""

    center: Pose
    half: HalfWidths

    @property
    def low(self) -> Pose:
        c, h = self.center, self.half
        return (c[0] - h[0], c[1] - h[1], c[2] - h[2])

    @property
    def high(self) -> Pose:
        c, h = self.center, self.half
        return (c[0] + h[0], c[1] + h[1], c[2] + h[2])

    def contains(self, other: ObjectInterval, tol: float = 1e-9) -> bool:
        """True if ``other``'s box lies inside this box."""
        lo, hi, olo, ohi = self.low, self.high, other.low, other.high
        return all(lo[i] - tol <= olo[i] and ohi[i] <= hi[i] + tol for i in range(3))

    @classmethod
    def from_bounds(cls, low: Sequence[float], high: Sequence[float]) -> ObjectInterval:
        return cls(
            as_triple(0.5 * (lo + hi) for lo, hi in zip(low, high, strict=True)),
            as_triple(0.5 * (hi - lo) for lo, hi in zip(low, high, strict=True)),
        )


@dataclass(frozen=True)
class IntervalBelief:
    """Factored interval belief: one :class:`ObjectInterval` per object on the table, in the
    problem's object order."""

    objects: tuple[tuple[str, ObjectInterval], ...]

    # The names and the lookup table are made once per belief: the action generator, the
    # heuristics and the dominance index ask for them many times per belief.
    @cached_property
    def _names(self) -> tuple[str, ...]:
        return tuple(name for name, _ in self.objects)

    @cached_property
    def _by_name(self) -> dict[str, ObjectInterval]:
        return dict(reversed(self.objects))  # an object listed twice: its first interval

    def names(self) -> tuple[str, ...]:
        return self._names

    def get(self, name: str) -> ObjectInterval | None:
        return self._by_name.get(name)

    def __contains__(self, name: object) -> bool:
        return name in self._by_name

    # The planner's view of a belief (shared with ParticleBelief): ``poses`` holds the box's
    # low and high corners as two pseudo-particles. Goal tests, heuristics and dominance only
    # use per-dimension minima and maxima of ``poses``, which are exactly the box's bounds.
    @cached_property
    def poses(self) -> np.ndarray:
        """Array ``(2, n_objects, 3)``: the low and the high corner of every object's box."""
        if not self.objects:
            return np.zeros((2, 0, 3))
        low = [iv.low for _, iv in self.objects]
        high = [iv.high for _, iv in self.objects]
        return np.array([low, high], dtype=float)

    @property
    def intervals(self) -> IntervalBelief:
        return self

    def __len__(self) -> int:
        return 2


def dominates(a: IntervalBelief, b: IntervalBelief, tol: float = 1e-9) -> bool:
    """Thesis §2.1.2: ``a`` dominates ``b`` iff both are defined on the same objects and every
    object's box in ``a`` is a subset of its box in ``b`` (``a`` is at least as certain)."""
    if a.names() != b.names():
        return False
    return all(ib.contains(ia, tol) for (_, ia), (_, ib) in zip(a.objects, b.objects, strict=True))


# -- particle beliefs --------------------------------------------------------------------------
class ParticleBelief:
    """A set of world states with the same objects on the table (thesis §2.1.2).

    ``particles[i]`` keeps its index across transitions, so particle ``i``'s noise can be
    drawn from ``(seed, i, step)`` and a plan's belief sequence is reproducible.

    Stored as one read-only float array of every particle's poses (:attr:`poses`) and the
    names of the objects on the table: a search holds thousands of beliefs, and the poses as
    Python tuples took some 300 bytes each against 24 in the array. :attr:`particles` builds
    the :class:`WorldState` values from the array when asked (the same floats). Beliefs are
    equal (and hash equal) when their names and every pose coordinate are equal.
    """

    def __init__(self, particles: Sequence[WorldState]) -> None:
        if not particles:
            raise ValueError("a particle belief needs at least one particle")
        self._names = particles[0].names()
        poses = np.array([[pose for _, pose in s.poses] for s in particles], dtype=float)
        #: Array ``(P, n_objects, 3)`` of every particle's poses, in ``names()`` order.
        self.poses = poses.reshape(len(particles), len(self._names), 3)
        self.poses.flags.writeable = False
        self._hash = self._hash_of_poses()

    def _hash_of_poses(self) -> int:
        # -0.0 == 0.0, so hash the array with its zeros made positive (adding 0.0 does that).
        return hash((self._names, (self.poses + 0.0).tobytes()))

    def __getstate__(self) -> dict[str, object]:
        # the hash is Python's, of a tuple holding strings: salted per process, so a belief
        # that crosses to another process (a worker simulating a successor) hashes anew
        state = dict(self.__dict__)
        del state["_hash"]
        return state

    def __setstate__(self, state: dict[str, object]) -> None:
        self.__dict__.update(state)
        self.poses.flags.writeable = False
        self._hash = self._hash_of_poses()

    def names(self) -> tuple[str, ...]:
        return self._names

    @property
    def particles(self) -> tuple[WorldState, ...]:
        """The particles as world states (built anew on every access)."""
        names = self._names
        return tuple(
            WorldState(tuple((name, tuple(pose)) for name, pose in zip(names, state, strict=True)))
            for state in self.poses.tolist()
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ParticleBelief):
            return NotImplemented
        return (
            self._hash == other._hash
            and self._names == other._names
            and bool(np.array_equal(self.poses, other.poses))
        )

    def __hash__(self) -> int:
        return self._hash

    def __repr__(self) -> str:
        return f"ParticleBelief({len(self)} particles of {', '.join(self._names) or 'nothing'})"

    @cached_property
    def intervals(self) -> IntervalBelief:
        """The interval belief fitted over the particles (min/max per object and dimension)."""
        names = self.names()
        if not names:
            return IntervalBelief(())
        arr = self.poses
        low, high = arr.min(axis=0), arr.max(axis=0)
        return IntervalBelief(
            tuple(
                (name, ObjectInterval.from_bounds(low[i], high[i])) for i, name in enumerate(names)
            )
        )

    def __len__(self) -> int:
        return len(self.poses)


def sample_initial_particles(
    compiled: CompiledProblem,
    n: int,
    rng: np.random.Generator,
    *,
    max_tries_per_particle: int = 1000,
) -> ParticleBelief:
    """Draw ``n`` initial world states of ``compiled.problem`` uniformly from the initial
    intervals, rejecting samples in which objects overlap each other, an obstacle or a wall
    (thesis §3.1), by the compiled problem's collision checker and in its angle frame.

    Raises ``ValueError`` if a particle cannot be drawn in ``max_tries_per_particle`` tries
    (an initial belief that is almost all collisions).
    """
    problem, checker, frame = compiled.problem, compiled.checker, compiled.frame
    states = []
    for _ in range(n):
        for _attempt in range(max_tries_per_particle):
            poses = {}
            for entry in problem.initial:
                u = rng.uniform(-1.0, 1.0, size=3)
                poses[entry.name] = as_triple(
                    float(entry.pose[k] + u[k] * entry.uncertainty[k]) for k in range(3)
                )
            state = WorldState.from_mapping(problem, poses)
            if not checker.state_collides(state):
                states.append(frame.canonical(state))
                break
        else:
            raise ValueError(
                f"problem {problem.name!r}: could not draw a collision-free initial state in "
                f"{max_tries_per_particle} tries; the initial uncertainties overlap too much"
            )
    return ParticleBelief(tuple(states))


class IntervalDominanceIndex:
    """Dominance pruning over many beliefs at once (thesis §2.1.2), vectorised with numpy.

    Beliefs are bucketed by the objects on the table. A belief ``b`` is dominated when some
    stored belief's box lies inside ``b``'s box, every dimension widened by ``tolerance``
    (inches, inches, radians). The tolerance makes beliefs that differ only by simulation
    round-off (the same pushes in another order, say) count as one — without it the
    deterministic planner drowns in near-copies of the states it has already seen. Path cost
    is ignored, as in the thesis: the first belief to reach a box keeps it.

    Implements the search's :class:`~arrange_up.search.DominanceIndex` protocol for
    :class:`ParticleBelief` states.
    """

    def __init__(self, tolerance: tuple[float, float, float] = (0.01, 0.01, 0.01)) -> None:
        self.tolerance = np.asarray(tolerance, dtype=float)
        self._buckets: dict[tuple[str, ...], _Bucket] = {}
        self._tolerances: dict[int, np.ndarray] = {}  # the tolerance tiled, per width
        self._last: tuple[ParticleBelief, np.ndarray, np.ndarray] | None = None

    def _bounds(self, belief: ParticleBelief) -> tuple[np.ndarray, np.ndarray]:
        # The search asks whether a belief is dominated, then adds it: the last belief's
        # bounds are kept for the second question.
        last = self._last
        if last is not None and last[0] is belief:
            return last[1], last[2]
        poses = belief.poses
        low, high = poses.min(axis=0).ravel(), poses.max(axis=0).ravel()
        self._last = (belief, low, high)
        return low, high

    def dominated(self, belief: ParticleBelief, g: float) -> bool:
        bucket = self._buckets.get(belief.names())
        if bucket is None or bucket.size == 0:
            return False
        low, high = self._bounds(belief)
        tol = self._tolerances.get(len(low))
        if tol is None:
            tol = self._tolerances[len(low)] = np.tile(self.tolerance, len(low) // 3)
        lows, highs = bucket.low[: bucket.size], bucket.high[: bucket.size]
        inside = np.all(lows >= low - tol, axis=1) & np.all(highs <= high + tol, axis=1)
        return bool(inside.any())

    def add(self, belief: ParticleBelief, g: float) -> None:
        low, high = self._bounds(belief)
        bucket = self._buckets.get(belief.names())
        if bucket is None:
            bucket = self._buckets[belief.names()] = _Bucket(len(low))
        bucket.append(low, high)


class _Bucket:
    """Growable arrays of box bounds (amortised O(1) append)."""

    def __init__(self, width: int) -> None:
        self.size = 0
        self.low = np.empty((16, width))
        self.high = np.empty((16, width))

    def append(self, low: np.ndarray, high: np.ndarray) -> None:
        if self.size == len(self.low):
            self.low = np.concatenate([self.low, np.empty_like(self.low)])
            self.high = np.concatenate([self.high, np.empty_like(self.high)])
        self.low[self.size] = low
        self.high[self.size] = high
        self.size += 1
