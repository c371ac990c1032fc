"""How reliably the rest of a nominal plan reaches the goal from a belief: the score the repair
ranks its candidates by.

A candidate of nominal step ``k`` leaves a particle belief (its simulated outcome). Its
*reliability* is the share of rollouts that reach the goal when the nominal plan's remaining
actions (``k + 1`` onwards) are run from that belief's particles, each particle rolled out
:func:`rollouts_per_particle` times with its own noise. A remaining push is run as the repair
will first try it: backed off the rolled-out particles' shadows (:func:`clear_approach`) and
lengthened by as much. A rollout whose push fails (off the table, not at rest, started on a
part) fails. After the last push the rollout counts as a success when the planner's goal test
holds.

The noise of rollout ``r`` of particle ``i`` at nominal step ``j`` is drawn from
``default_rng([seed, 0x5E11, j, i, r])`` whatever the candidate: every candidate of a step is
scored on the same worlds (common random numbers), so their reliabilities differ by what the
candidates do, not by the draw.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from arrange_up.belief.compiled import compile_problem
from arrange_up.belief.states import ParticleBelief
from arrange_up.model.world import ActionNoise, Pick, Place, Push, WorldState, draw_noise
from arrange_up.repair.candidates import clear_approach, round_pose_value

if TYPE_CHECKING:
    from arrange_up.model.world import Action
    from arrange_up.repair.repairer import Repairer

#: Rollouts a candidate's reliability is estimated from, at least: with fewer particles each
#: particle is rolled out several times (the remaining plan's noise is sampled more finely
#: than the belief itself).
MIN_ROLLOUTS = 40

_ANY_PLACE = Place("-", (0.0, 0.0, 0.0))
_ANY_PUSH = Push("-", (0.0, 0.0, 0.0), 0.0)


def rollouts_per_particle(particles: int, rest: Sequence[Action]) -> int:
    """Rollouts per particle: enough for :data:`MIN_ROLLOUTS` in all, and one when nothing
    noisy remains (no place or push), where every rollout of a particle would be the same."""
    if not any(isinstance(a, (Place, Push)) for a in rest):
        return 1
    return max(1, math.ceil(MIN_ROLLOUTS / particles))


class RemainingPlan:
    """The nominal plan's actions after step ``index``, rolled out from candidates' beliefs.

    :meth:`reliability` is a candidate belief's score (module docstring); it is computed once
    per belief object (candidates that share an outcome share it).
    """

    def __init__(self, repairer: Repairer, actions: Sequence[Action], index: int) -> None:
        self.repairer = repairer
        self.index = index
        self.rest = tuple(actions[index + 1 :])
        self.per_particle = rollouts_per_particle(repairer.particles, self.rest)
        self._goal = compile_problem(repairer.problem).goal
        self._scores: dict[int, tuple[ParticleBelief, float]] = {}

    def reliability(self, belief: ParticleBelief) -> float:
        """The share of rollouts of the remaining plan from ``belief`` that reach the goal."""
        cached = self._scores.get(id(belief))
        if cached is not None and cached[0] is belief:
            return cached[1]
        total = len(belief.particles) * self.per_particle
        states = [s for s in belief.particles for _ in range(self.per_particle)]
        labels = [(i, r) for i in range(len(belief.particles)) for r in range(self.per_particle)]
        for offset, action in enumerate(self.rest):
            if not states:
                break
            states, labels = self._run(self.index + 1 + offset, action, states, labels)
        successes = sum(1 for state in states if self._goal.satisfied(state))
        score = successes / total if total else 0.0
        self._scores[id(belief)] = (belief, score)
        return score

    def _noise(self, step: int, particle: int, rollout: int) -> tuple[ActionNoise, ActionNoise]:
        problem = self.repairer.problem
        rng = np.random.default_rng([self.repairer.seed, 0x5E11, step, particle, rollout])
        return draw_noise(problem, _ANY_PLACE, rng), draw_noise(problem, _ANY_PUSH, rng)

    def _run(
        self,
        step: int,
        action: Action,
        states: list[WorldState],
        labels: list[tuple[int, int]],
    ) -> tuple[list[WorldState], list[tuple[int, int]]]:
        """The rollouts still alive after ``action`` (nominal step ``step``), and their
        labels ``(particle, rollout)``."""
        r = self.repairer
        semantics = r.semantics
        belief = ParticleBelief(tuple(states))
        if isinstance(action, Pick):
            return list(r.pick(belief, action).particles), labels
        noises = [self._noise(step, i, k) for i, k in labels]
        if isinstance(action, Place):
            offsets = [place.pose_offset for place, _ in noises]
            return list(semantics.place_particles(belief, action, offsets).particles), labels
        if not isinstance(action, Push):
            raise TypeError(f"not an action: {action!r}")
        intervals = r.intervals(belief)
        approach, backoff = clear_approach(r.problem, r.checker, intervals, action)
        push = Push(action.manipulator, approach, round_pose_value(action.distance + backoff))
        affected = semantics.affected_objects(intervals, push)
        if not affected:
            return states, labels
        jobs = semantics.push_jobs(belief, push, affected, [push_noise for _, push_noise in noises])
        [batch] = semantics.simulate_pushes([jobs], stop_on_failure=False)
        r.simulations += batch.simulated
        alive: list[WorldState] = []
        alive_labels: list[tuple[int, int]] = []
        for state, label, outcome in zip(states, labels, batch.outcomes, strict=True):
            if outcome is None or not outcome.ok:
                continue
            poses = state.as_dict()
            poses.update(outcome.poses)
            alive.append(r.frame.canonical(WorldState.from_mapping(r.problem, poses)))
            alive_labels.append(label)
        return alive, alive_labels
