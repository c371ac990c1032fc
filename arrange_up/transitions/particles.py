"""Particle belief-state transitions (thesis §3.1) and the deterministic (nominal) planner.

``ParticleSemantics`` represents a belief by ``P`` world states. The initial belief is drawn
by rejection sampling from the initial intervals. A place moves every particle's object to the
commanded pose plus that particle's own place noise; a pick removes the object; a push is
simulated for every particle with its own noise and domain parameters (friction, densities)
drawn for that action.

Reproducibility: particle ``i``'s noise for an action is drawn from a generator seeded with
``(seed, i, digest(particle state, action))``. It depends on nothing else — not on the search
order, the worker count or the process — so equal inputs give bit-identical beliefs and plans.

Work sharing: a push can only move what its manipulator can reach, directly or through a
train of objects. Before simulating, the objects whose belief shadows lie in the conservative
swept region of the manipulator (extended through every object it can reach, with a margin
for sideways drift) are collected; only those are simulated, the rest are copied unchanged. A
push that reaches nothing returns the belief itself, without simulation.

A transition is refused (``None``) when any particle's push fails: a part or fixture ends off
the table, or the simulation does not come to rest within the cap. A conformant plan must not
rely on such an action.
"""

from __future__ import annotations

import hashlib
import os
from concurrent.futures import Executor

import numpy as np

from arrange_up.belief.states import (
    AngleFrame,
    IntervalBelief,
    ParticleBelief,
    sample_initial_particles,
)
from arrange_up.geometry import shapes as geometry
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import (
    Action,
    ActionNoise,
    Pick,
    Place,
    Push,
    WorldState,
    draw_noise,
    nominal_initial_state,
    nominal_noise,
)

#: Extra reach of a push beyond its commanded distance, and sideways drift allowance (inches).
SWEEP_MARGIN = 0.3


class ParticleSemantics:
    """PBST: ``particles`` world states, each simulated with its own noise (see module doc)."""

    name = "particles"
    refuses_uncertain_contacts = False  # it predicts every push (see transitions.Semantics)

    def __init__(
        self, problem: ArrangementProblem, *, particles: int = 50, seed: int = 0, workers: int = 1
    ) -> None:
        if particles < 1:
            raise ValueError("particles must be at least 1")
        self.problem = problem
        self.particles = particles
        self.seed = seed
        self.workers = max(1, workers)
        self.simulations = 0
        self.frame = AngleFrame.of(problem)
        self.checker = CollisionChecker(problem)
        self._executor: Executor | None = None

    # -- noise -------------------------------------------------------------------------------
    def noise(self, index: int, state: WorldState, action: Action) -> ActionNoise:
        digest = hashlib.blake2b(repr((state.poses, action)).encode(), digest_size=8).digest()
        rng = np.random.default_rng([self.seed, index, int.from_bytes(digest, "little")])
        return draw_noise(self.problem, action, rng)

    # -- beliefs -----------------------------------------------------------------------------
    def initial_belief(self) -> ParticleBelief:
        rng = np.random.default_rng([self.seed, 0x1A1])
        return sample_initial_particles(self.problem, self.particles, rng, frame=self.frame)

    def apply(self, belief: ParticleBelief, action: Action) -> ParticleBelief | None:
        if isinstance(action, Push):
            return self._push(belief, action)
        states = []
        for i, state in enumerate(belief.particles):
            poses = state.as_dict()
            if isinstance(action, Place):
                offset = self.noise(i, state, action).pose_offset
                poses[action.obj] = tuple(a + b for a, b in zip(action.pose, offset, strict=True))
            elif isinstance(action, Pick):
                poses.pop(action.obj, None)
            else:
                raise TypeError(f"not an action: {action!r}")
            states.append(self.frame.canonical(WorldState.from_mapping(self.problem, poses)))
        return ParticleBelief(tuple(states))

    def _push(self, belief: ParticleBelief, push: Push) -> ParticleBelief | None:
        affected = self.affected_objects(belief.intervals, push)
        if not affected:
            return belief
        jobs = []
        for i, state in enumerate(belief.particles):
            sub = WorldState(tuple((n, p) for n, p in state.poses if n in affected))
            jobs.append((sub, push, self.noise(i, state, push)))
        outcomes = self._simulate_all(jobs)
        self.simulations += len(jobs)
        if outcomes is None:
            return None
        states = []
        for state, moved in zip(belief.particles, outcomes, strict=True):
            poses = state.as_dict()
            poses.update(moved)
            states.append(self.frame.canonical(WorldState.from_mapping(self.problem, poses)))
        return ParticleBelief(tuple(states))

    def affected_objects(self, intervals: IntervalBelief, push: Push) -> frozenset[str]:
        """Objects the push may touch, directly or through others (a conservative sweep)."""
        spec = self.problem.object(push.manipulator)
        px, py = spec.push_direction
        c, s = np.cos(push.pose[2]), np.sin(push.pose[2])
        direction = (round(c * px - s * py), round(s * px + c * py))
        boxes = {
            name: self.checker.shadow_box(name, iv.center, iv.half)
            for name, iv in intervals.objects
        }
        reach = push.distance + SWEEP_MARGIN
        start = self.checker.shadow_box(push.manipulator, push.pose, self.problem.uncertainty.push)
        frontier = [_widen(geometry.swept_box(start, direction, reach), direction)]
        affected: set[str] = set()
        while frontier:
            region = frontier.pop()
            for name, box in boxes.items():
                if name not in affected and geometry.boxes_overlap(region, box):
                    affected.add(name)
                    frontier.append(_widen(geometry.swept_box(box, direction, reach), direction))
        return frozenset(affected)

    # -- simulation --------------------------------------------------------------------------
    def _simulate_all(self, jobs) -> list[dict] | None:
        if self.workers > 1 and len(jobs) >= 2 * self.workers:
            executor = self._pool()
            chunks = [jobs[k :: self.workers] for k in range(self.workers)]
            results = list(executor.map(_simulate_chunk, [self.problem] * len(chunks), chunks))
            if any(r is None for r in results):
                return None
            merged: list[dict] = [{}] * len(jobs)
            for k, chunk_result in enumerate(results):
                merged[k :: self.workers] = chunk_result
            return merged
        return _simulate_chunk(self.problem, jobs)

    def _pool(self) -> Executor:
        if self._executor is None:
            # loky (joblib's process pool) rather than multiprocessing: it never re-imports the
            # caller's __main__ (so scripts need no main guard) and reuses its workers.
            from joblib.externals.loky import get_reusable_executor

            self._executor = get_reusable_executor(max_workers=self.workers)
        return self._executor

    def close(self) -> None:
        """Release the worker pool (loky keeps idle workers for reuse and reaps them later)."""
        self._executor = None


class DeterministicSemantics(ParticleSemantics):
    """The nominal planner: one particle at the nominal initial poses and no noise at all."""

    name = "deterministic"

    def __init__(
        self, problem: ArrangementProblem, *, particles: int = 1, seed: int = 0, workers: int = 1
    ) -> None:
        super().__init__(problem, particles=1, seed=seed, workers=1)
        self._nominal = nominal_noise(problem)

    def noise(self, index: int, state: WorldState, action: Action) -> ActionNoise:
        return self._nominal

    def initial_belief(self) -> ParticleBelief:
        return ParticleBelief((self.frame.canonical(nominal_initial_state(self.problem)),))


def _simulate_chunk(problem: ArrangementProblem, jobs) -> list[dict] | None:
    """Simulate pushes; the moved poses of each, or None as soon as one fails."""
    from arrange_up.physics.simulation import simulate

    results = []
    for state, push, noise in jobs:
        outcome = simulate(problem, state, push, noise)
        if not outcome.ok:
            return None
        results.append(outcome.state.as_dict())
    return results


def _widen(box, direction, margin: float = SWEEP_MARGIN):
    """Grow a swept box sideways (across the push) by ``margin`` on both sides."""
    xmin, ymin, xmax, ymax = box
    if direction[0]:
        return (xmin, ymin - margin, xmax, ymax + margin)
    return (xmin - margin, ymin, xmax + margin, ymax)


def default_workers() -> int:
    """Worker processes to use by default: every core the process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not on Linux
        return os.cpu_count() or 1
