"""Particle belief-state transitions (thesis §3.1) and the deterministic (nominal) planner.

``ParticleSemantics`` represents a belief by ``P`` world states. The initial belief is drawn
by rejection sampling from the initial intervals. A place moves every particle's object to the
commanded pose plus that particle's own place noise; a pick removes the object; a push is
simulated for every particle with its own noise and domain parameters (friction, densities)
drawn for that action.

Reproducibility: particle ``i``'s noise for an action is drawn from a generator seeded with
``(seed, i, digest(particle state, action))``. It depends on nothing else — not on the search
order, the worker count or the process — so equal inputs give bit-identical beliefs and plans.
:meth:`ParticleSemantics.common_noise` is the other noise scheme, keyed by a step number
alone: *common random numbers*, the same draw for every candidate action compared at a step
(the fixture repair's, :mod:`arrange_up.repair`).

One propagation, two faces: :meth:`ParticleSemantics.apply` is the planner's transition; the
batch face below it (:meth:`~ParticleSemantics.place_particles`,
:meth:`~ParticleSemantics.pick_particles`, :meth:`~ParticleSemantics.push_jobs`,
:meth:`~ParticleSemantics.simulate_pushes`, :meth:`~ParticleSemantics.moved_particles`) takes
the noise from its caller and simulates many beliefs' pushes in one batch, serially or on the
process's one worker pool (:func:`arrange_up.parallel.local_executor`). ``apply`` is built from
it, and so is the fixture repair's propagation and candidate scoring.

Work sharing: a push can only move what its manipulator can reach, directly or through a
train of objects. Before simulating, the objects whose belief shadows lie in the conservative
swept region of the manipulator (extended through every object it can reach, with a margin
for sideways drift) are collected; only those are simulated, the rest are copied unchanged. A
push that reaches nothing returns the belief itself, without simulation.

A transition is refused (``None``) when any particle's push fails: a part or fixture ends off
the table, or the simulation does not come to rest within the cap, or the push starts with
shapes overlapping. A conformant plan must not rely on such an action. ``reasons`` counts why,
one short sentence per refused transition (:meth:`Simulated.refusal` of the first failed
particle's push), for diagnostics: the planner names the most frequent in its reason line, as
it does CBST's.
"""

from __future__ import annotations

import hashlib
from collections import Counter
from collections.abc import Sequence
from concurrent.futures import Executor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from arrange_up.belief.compiled import compile_problem
from arrange_up.belief.states import (
    IntervalBelief,
    ParticleBelief,
    sample_initial_particles,
)
from arrange_up.geometry import shapes as geometry
from arrange_up.geometry.se2 import rotate
from arrange_up.model.problem import ArrangementProblem, Pose, as_triple
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
from arrange_up.parallel import local_executor, local_workers_lost
from arrange_up.physics.simulation import DEFAULT_SETTINGS, SimulationStatus, simulate

#: Extra reach of a push beyond its commanded distance, and sideways drift allowance (inches).
SWEEP_MARGIN = 0.3

#: One particle's push to simulate: the state of the objects it may reach, the push, its noise.
PushJob = tuple[WorldState, Push, ActionNoise]

# Generic place and push actions: the noise draw depends on the action's kind only.
_ANY_PLACE = Place("-", (0.0, 0.0, 0.0))
_ANY_PUSH = Push("-", (0.0, 0.0, 0.0), 0.0)


class Simulated(NamedTuple):
    """One particle's simulated push: its status (a :class:`SimulationStatus` value), the
    objects it put off the table, and the poses of the simulated objects afterwards (also when
    it failed)."""

    status: str
    off_table: tuple[str, ...]
    poses: tuple[tuple[str, Pose], ...]

    @property
    def ok(self) -> bool:
        return self.status == SimulationStatus.OK

    def reason(self) -> str:
        """Why the push failed, as a sentence about "a particle's push"."""
        if self.status == SimulationStatus.OFF_TABLE:
            return f"a particle's push put {', '.join(self.off_table)} off the table"
        if self.status == SimulationStatus.NOT_AT_REST:
            return "a particle's push did not come to rest"
        if self.status == SimulationStatus.OVERLAP:
            return "a particle's push started with shapes overlapping"
        return f"a particle's push failed ({self.status})"

    def refusal(self) -> str:
        """Why a transition whose push failed so is refused: a short sentence for the planner's
        reason line (a key of :attr:`ParticleSemantics.reasons`), naming the cause."""
        if self.status == SimulationStatus.OFF_TABLE:
            return f"a push left {', '.join(self.off_table)} off the table"
        if self.status == SimulationStatus.NOT_AT_REST:
            return NOT_AT_REST_REFUSAL
        if self.status == SimulationStatus.OVERLAP:
            return OVERLAP_REFUSAL
        return f"a push failed in the simulation ({self.status})"


#: :meth:`Simulated.refusal` of a push the simulation's time cap stopped
#: (:attr:`~arrange_up.physics.settings.PhysicsSettings.max_time`, ``travel_margin``).
NOT_AT_REST_REFUSAL = (
    "a push did not come to rest within the simulation's time limit "
    f"({DEFAULT_SETTINGS.max_time:g} s, or its travel time plus "
    f"{DEFAULT_SETTINGS.travel_margin:g} s for a long push)"
)
#: :meth:`Simulated.refusal` of a push that started with shapes overlapping.
OVERLAP_REFUSAL = (
    "a push started with shapes overlapping (its approach pose or an earlier place put one "
    "shape into another)"
)


@dataclass(frozen=True)
class PushBatch:
    """The simulated pushes of one belief's particles (one group of
    :meth:`ParticleSemantics.simulate_pushes`).

    ``outcomes[i]`` is particle ``i``'s, or ``None`` when it was not simulated (its share of
    the particles stopped at an earlier failure). ``failure`` is the first failed outcome in
    the order the shares were simulated (share by share, each in particle order), ``None``
    when every particle's push succeeded; ``simulated`` counts the simulations run.
    """

    outcomes: tuple[Simulated | None, ...]
    failure: Simulated | None
    simulated: int

    @property
    def ok(self) -> bool:
        return self.failure is None


class ParticleSemantics:
    """PBST: ``particles`` world states, each simulated with its own noise (see module doc)."""

    name = "particles"
    refuses_uncertain_contacts = False  # it predicts every push (see transitions.Semantics)
    simulates_pushes = True
    place_rings = True

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
        #: Why transitions were refused (:meth:`Simulated.refusal`), one count per refusal.
        self.reasons: Counter[str] = Counter()
        self.compiled = compiled = compile_problem(problem)
        self.frame = compiled.frame
        self.checker = compiled.checker
        self._executor: Executor | None = None
        self._common: dict[int, list[tuple[ActionNoise, ActionNoise]]] = {}

    # -- noise -------------------------------------------------------------------------------
    def noise(self, index: int, state: WorldState, action: Action) -> ActionNoise:
        digest = hashlib.blake2b(repr((state.poses, action)).encode(), digest_size=8).digest()
        rng = np.random.default_rng([self.seed, index, int.from_bytes(digest, "little")])
        return draw_noise(self.problem, action, rng)

    def common_noise(self, step: int) -> list[tuple[ActionNoise, ActionNoise]]:
        """Common random numbers: per particle, the ``(place noise, push noise)`` of ``step``.

        Particle ``i`` draws both from ``default_rng([seed, 0xF1C, step, i])``, whatever the
        state and the action, so every candidate action compared at one step meets the same
        worlds. Cached per step.
        """
        draws = self._common.get(step)
        if draws is None:
            draws = []
            for i in range(self.particles):
                rng = np.random.default_rng([self.seed, 0xF1C, step, i])
                draws.append(
                    (
                        draw_noise(self.problem, _ANY_PLACE, rng),
                        draw_noise(self.problem, _ANY_PUSH, rng),
                    )
                )
            self._common[step] = draws
        return draws

    # -- beliefs -----------------------------------------------------------------------------
    def initial_belief(self) -> ParticleBelief:
        rng = np.random.default_rng([self.seed, 0x1A1])
        return sample_initial_particles(self.compiled, self.particles, rng)

    def apply(self, belief: ParticleBelief, action: Action) -> ParticleBelief | None:
        if isinstance(action, Push):
            return self._push(belief, action)
        if isinstance(action, Place):
            offsets = [
                self.noise(i, state, action).pose_offset for i, state in enumerate(belief.particles)
            ]
            return self.place_particles(belief, action, offsets)
        if isinstance(action, Pick):
            return self.pick_particles(belief, action)
        raise TypeError(f"not an action: {action!r}")

    def _push(self, belief: ParticleBelief, push: Push) -> ParticleBelief | None:
        affected = self.affected_objects(belief.intervals, push)
        if not affected:
            return belief
        noises = [self.noise(i, state, push) for i, state in enumerate(belief.particles)]
        [batch] = self.simulate_pushes([self.push_jobs(belief, push, affected, noises)])
        # the planner's statistic counts every particle's push, also those a failure cut short
        self.simulations += len(belief.particles)
        if batch.failure is not None:
            self.reasons[batch.failure.refusal()] += 1
            return None
        return self.moved_particles(belief, batch.outcomes)

    def push_share(
        self, belief: ParticleBelief, push: Push, indices: Sequence[int], affected: frozenset[str]
    ) -> tuple[PushBatch, ParticleBelief | None]:
        """Particles ``indices`` of ``belief`` pushed, simulating the ``affected`` objects (a
        share of :meth:`apply`'s work, for a push that reaches something): their
        :class:`PushBatch` and, when it is ok, the belief of those particles alone after the
        push (the full child's rows at ``indices``). A failed share refuses the child: its
        reason is counted in :attr:`reasons`, as :meth:`apply` counts it.

        Each particle's outcome is the one :meth:`apply` computes (its noise depends on its
        index and state only), so shares put together (:meth:`moved_particles` over every
        particle's outcome) give :meth:`apply`'s child.
        """
        states = belief.particles
        share = ParticleBelief([states[i] for i in indices])
        noises = [self.noise(i, states[i], push) for i in indices]
        [batch] = self.simulate_pushes([self.push_jobs(share, push, affected, noises)])
        self.simulations += len(indices)  # counted as _push counts: the share's every particle
        if batch.failure is not None:
            self.reasons[batch.failure.refusal()] += 1
            return batch, None
        return batch, self.moved_particles(share, batch.outcomes)

    def affected_objects(self, intervals: IntervalBelief, push: Push) -> frozenset[str]:
        """Objects the push may touch, directly or through others (a conservative sweep)."""
        spec = self.problem.object(push.manipulator)
        ux, uy = rotate(spec.push_direction, push.pose[2])
        direction = (round(ux), round(uy))
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

    # -- the batch face ----------------------------------------------------------------------
    def place_particles(
        self, belief: ParticleBelief, place: Place, offsets: Sequence[Pose]
    ) -> ParticleBelief:
        """Every particle with ``place.obj`` at the commanded pose plus its own offset."""
        states = []
        for state, offset in zip(belief.particles, offsets, strict=True):
            poses = state.as_dict()
            poses[place.obj] = as_triple(a + b for a, b in zip(place.pose, offset, strict=True))
            states.append(self.frame.canonical(WorldState.from_mapping(self.problem, poses)))
        return ParticleBelief(tuple(states))

    def pick_particles(
        self, belief: ParticleBelief, pick: Pick, *, canonical: bool = True
    ) -> ParticleBelief:
        """Every particle without ``pick.obj``. ``canonical=False`` leaves the other angles as
        they are instead of wrapping them again (wrapping is not exactly idempotent in floating
        point, so the two differ in the last bits)."""
        states = []
        for state in belief.particles:
            poses = state.as_dict()
            poses.pop(pick.obj, None)
            after = WorldState.from_mapping(self.problem, poses)
            states.append(self.frame.canonical(after) if canonical else after)
        return ParticleBelief(tuple(states))

    def push_jobs(
        self,
        belief: ParticleBelief,
        push: Push,
        affected: frozenset[str],
        noises: Sequence[ActionNoise],
    ) -> list[PushJob]:
        """One job per particle: its ``affected`` objects, ``push``, and its noise."""
        return [
            (WorldState(tuple((n, p) for n, p in state.poses if n in affected)), push, noise)
            for state, noise in zip(belief.particles, noises, strict=True)
        ]

    def simulate_pushes(
        self, groups: Sequence[Sequence[PushJob]], *, stop_on_failure: bool = True
    ) -> list[PushBatch]:
        """Simulate every group of jobs (one group per belief and push), all in one batch.

        A group of at least ``2 * workers`` jobs is split into ``workers`` interleaved shares;
        with ``workers > 1`` and more than one share in the batch, the shares run on the
        process's worker pool, else here. With ``stop_on_failure`` a share stops at its first
        failure (the group's outcome is a failure anyway). The outcomes do not depend on
        ``workers``. A pool whose worker ended abruptly raises
        :class:`~arrange_up.parallel.WorkersLostError`, one line, not loky's error.
        """
        tasks: list[tuple[int, range]] = []
        for g, jobs in enumerate(groups):
            shares = self.workers if self.workers > 1 and len(jobs) >= 2 * self.workers else 1
            tasks.extend((g, range(k, len(jobs), shares)) for k in range(shares))
        chunks = [[groups[g][i] for i in indices] for g, indices in tasks]
        if self.workers > 1 and len(tasks) > 1:
            n = len(chunks)
            try:
                results = list(
                    self._pool().map(
                        _simulate_chunk, [self.problem] * n, chunks, [stop_on_failure] * n
                    )
                )
            except BrokenProcessPool as error:  # loky's TerminatedWorkerError too
                raise local_workers_lost(error) from error
        else:
            results = [_simulate_chunk(self.problem, chunk, stop_on_failure) for chunk in chunks]
        outcomes: list[list[Simulated | None]] = [[None] * len(jobs) for jobs in groups]
        failures: list[Simulated | None] = [None] * len(groups)
        simulated = [0] * len(groups)
        for (g, indices), result in zip(tasks, results, strict=True):
            simulated[g] += len(result)
            for i, outcome in zip(indices, result, strict=False):
                outcomes[g][i] = outcome
                if not outcome.ok and failures[g] is None:
                    failures[g] = outcome
        return [
            PushBatch(tuple(outcomes[g]), failures[g], simulated[g]) for g in range(len(groups))
        ]

    def moved_particles(
        self, belief: ParticleBelief, outcomes: Sequence[Simulated | None]
    ) -> ParticleBelief:
        """``belief`` with every particle's simulated objects at their poses after the push."""
        states = []
        for state, outcome in zip(belief.particles, outcomes, strict=True):
            assert outcome is not None
            poses = state.as_dict()
            poses.update(outcome.poses)
            states.append(self.frame.canonical(WorldState.from_mapping(self.problem, poses)))
        return ParticleBelief(tuple(states))

    def _pool(self) -> Executor:
        if self._executor is None:
            self._executor = local_executor(self.workers)
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


def _simulate_chunk(
    problem: ArrangementProblem, jobs: Sequence[PushJob], stop_on_failure: bool
) -> list[Simulated]:
    """Simulate pushes in order; with ``stop_on_failure`` the list ends at the first failure."""
    out = []
    for state, push, noise in jobs:
        outcome = simulate(problem, state, push, noise)
        out.append(Simulated(outcome.status.value, outcome.off_table, outcome.state.poses))
        if stop_on_failure and not outcome.ok:
            break
    return out


def _widen(box, direction, margin: float = SWEEP_MARGIN):
    """Grow a swept box sideways (across the push) by ``margin`` on both sides."""
    xmin, ymin, xmax, ymax = box
    if direction[0]:
        return (xmin, ymin - margin, xmax, ymax + margin)
    return (xmin - margin, ymin, xmax + margin, ymax)
