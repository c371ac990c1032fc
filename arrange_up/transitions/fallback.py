"""CBST's simulated fallback: a push the learned model refuses, answered by the physics.

Where CBST's contact graph or model gives no prediction (a feature outside the training
domain, a contact the graph cannot settle, a predicted slip, a push that stops short of the
wall), :class:`SimulatedFallback` draws world states from the interval belief, simulates the
push in each with its own noise (friction, densities, the push's pose offset), and rebuilds
every reached object's box from the ends of the simulations: ``center ± half`` spanning them.

The states: the first ones put every reached object at the same corner of its box (all
``x``, ``y`` and ``theta`` at their lower or upper end: eight corners, a common shift of the
objects that keeps them apart), since the extremes of a box are what its ends must cover;
the rest are drawn uniformly in the boxes, rejecting states in which objects overlap each
other, an obstacle or a wall (as the particle semantics draws its initial states). A corner
that overlaps something is left out.

A box spanning the ends of a few simulations is narrower than the set of all ends it stands
for; like PREDICT's boxes, it is a prediction, not a bound, and a plan is checked on fresh
rollouts (:mod:`arrange_up.planning.validation`).

The answer is a function of the reached objects' boxes and the push (the random numbers are
seeded from the semantics' seed and a digest of both), so a search meets equal answers for
equal questions, and each is remembered.

When a simulation fails (a part pushed off the table, a simulation that does not come to rest,
a drawn state that starts overlapping the paddle) the push is refused: the physics says the
push is unsafe for some state of the belief.
"""

from __future__ import annotations

import hashlib
import itertools

import numpy as np

from arrange_up.belief.states import IntervalBelief, ObjectInterval, wrap_angle
from arrange_up.model.problem import ArrangementProblem, Pose, as_triple
from arrange_up.model.world import Push, WorldState, draw_noise
from arrange_up.transitions.particles import ParticleSemantics

__all__ = ["FALLBACK_CACHE", "SimulatedFallback"]

#: Fallback answers a semantics remembers; past it the memory starts again empty.
FALLBACK_CACHE = 50_000
#: Tries to draw one collision-free state in the boxes before the push is refused.
_DRAW_TRIES = 200
#: Why a fallback refuses a push when no collision-free state can be drawn from the boxes.
DRAW_REFUSAL = "the simulated fallback could not draw a state without overlaps from the belief"

#: A fallback's answer: the reached objects' new intervals, or why the push is refused.
FallbackAnswer = dict[str, ObjectInterval] | str
#: The boxes of the objects a push may reach, in the belief's order.
Boxes = tuple[tuple[str, ObjectInterval], ...]


class SimulatedFallback:
    """Simulate a push from ``particles`` states drawn from an interval belief (see the module
    docstring). ``seed`` seeds the draws; equal ``(seed, boxes, push)`` give equal answers."""

    def __init__(self, problem: ArrangementProblem, *, particles: int, seed: int) -> None:
        if particles < 1:
            raise ValueError("the simulated fallback needs at least one particle")
        self.problem = problem
        self.particles = particles
        self.seed = seed
        self._physics = ParticleSemantics(problem, particles=particles, seed=seed, workers=1)
        self._frame = self._physics.frame
        self._checker = self._physics.checker
        self._known: dict[tuple, FallbackAnswer] = {}
        #: Physics simulations run (one per drawn state and push).
        self.simulations = 0

    def push(self, belief: IntervalBelief, push: Push) -> FallbackAnswer:
        """The new intervals of the objects ``push`` may reach in ``belief`` (empty when it
        reaches none), or the reason it is refused (a string)."""
        affected = self._physics.affected_objects(belief, push)
        boxes = tuple((name, iv) for name, iv in belief.objects if name in affected)
        if not boxes:
            return {}
        key = (boxes, push)
        known = self._known.get(key)
        if known is not None:
            return known
        answer = self._simulate(boxes, push)
        if len(self._known) >= FALLBACK_CACHE:
            self._known.clear()
        self._known[key] = answer
        return answer

    def _simulate(self, boxes: Boxes, push: Push) -> FallbackAnswer:
        digest = hashlib.blake2b(repr((boxes, push)).encode(), digest_size=8).digest()
        rng = np.random.default_rng([self.seed, 0xFA11, int.from_bytes(digest, "little")])
        states = self._draw(boxes, rng)
        if states is None:
            return DRAW_REFUSAL
        jobs = [(state, push, draw_noise(self.problem, push, rng)) for state in states]
        [batch] = self._physics.simulate_pushes([jobs])
        self.simulations += batch.simulated
        if batch.failure is not None:
            return batch.failure.refusal()
        ends: dict[str, list[Pose]] = {name: [] for name, _ in boxes}
        for outcome in batch.outcomes:
            assert outcome is not None
            for name, pose in outcome.poses:
                if name in ends:
                    ends[name].append(pose)
        return {name: self._span(name, poses) for name, poses in ends.items()}

    def _draw(self, boxes: Boxes, rng: np.random.Generator) -> list[WorldState] | None:
        """The corner states that overlap nothing, then uniform collision-free draws, up to
        ``particles`` states; None when a uniform draw fails :data:`_DRAW_TRIES` times."""
        states: list[WorldState] = []
        for signs in itertools.product((-1.0, 1.0), repeat=3):
            if len(states) >= self.particles:
                return states
            state = self._state(
                {
                    name: as_triple(iv.center[k] + signs[k] * iv.half[k] for k in range(3))
                    for name, iv in boxes
                }
            )
            if not self._checker.state_collides(state):
                states.append(state)
        while len(states) < self.particles:
            for _ in range(_DRAW_TRIES):
                poses = {}
                for name, iv in boxes:
                    u = rng.uniform(-1.0, 1.0, size=3)
                    poses[name] = as_triple(iv.center[k] + u[k] * iv.half[k] for k in range(3))
                state = self._state(poses)
                if not self._checker.state_collides(state):
                    states.append(state)
                    break
            else:
                return None
        return states

    def _state(self, poses: dict[str, Pose]) -> WorldState:
        return WorldState.from_mapping(self.problem, poses)

    def _span(self, name: str, poses: list[Pose]) -> ObjectInterval:
        """The interval spanning ``poses`` of ``name``: angles wrapped into its symmetry
        period around the first pose's angle, so ends on either side of a period's edge are
        one narrow range."""
        period = self._frame.period[name]
        reference = poses[0][2]
        xs = [p[0] for p in poses]
        ys = [p[1] for p in poses]
        thetas = [wrap_angle(p[2], reference, period) for p in poses]
        low = (min(xs), min(ys), min(thetas))
        high = (max(xs), max(ys), max(thetas))
        return ObjectInterval.from_bounds(low, high)
