"""The closed loop: execute, sense, update the belief, replan when the plan no longer fits.

:class:`ClosedLoop` is the library call a robot integration uses: given the problem, a plan
and an :class:`~arrange_up.execution.executor.Executor`, :meth:`ClosedLoop.run` executes the
plan one action at a time. After each action it conditions its particle belief on the
observation (:class:`~arrange_up.execution.belief.ParticleFilter`) and estimates the remaining
plan's success under the posterior with a few rollouts (``check_rollouts`` particles drawn
from the posterior, each running the rest of the plan under the model's noise, then the goal
test). When the estimate falls below ``threshold`` it replans from the posterior
(:func:`arrange_up.planning.planner.plan` with ``start=``) within ``budget`` seconds, and goes
on with the new plan when one is found (else with the old one). When the plan has run out it
checks the goal under the posterior (the fraction of particles that satisfy it) and replans
again if that is below the threshold. The loop ends when the plan has run out and the
posterior satisfies the goal, after ``max_replans`` replans, ``max_actions`` actions, or the
first action the executor could not carry out.

The start belief of a replan depends on the semantics: ``particles`` plans from
``particles`` particles drawn from the posterior; ``deterministic`` from its most central
particle (the one nearest the posterior's mean: certainty-equivalent replanning);
``cbst`` from the interval belief fitted over the posterior.

Everything random derives from ``seed`` and the episode number: the filter's propagation and
resampling, the checks' rollouts, and the replans' seeds.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import ParticleBelief
from arrange_up.evaluation.outcomes import Failure
from arrange_up.evaluation.rollouts import Rollouts
from arrange_up.execution.belief import DEFAULT_GATE, ModelFailure, ParticleFilter
from arrange_up.execution.executor import ExecutionFailed, Executor
from arrange_up.execution.observations import Observation, Sensor
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action
from arrange_up.planning.planner import plan

__all__ = [
    "ClosedLoop",
    "ClosedLoopSettings",
    "LoopOutcome",
    "Replan",
    "StepTrace",
]


@dataclass(frozen=True)
class ClosedLoopSettings:
    """How the loop senses, estimates and replans (module docstring).

    ``filter_particles`` is the belief's size; ``check_rollouts`` the rollouts of one success
    estimate; ``threshold`` the estimate below which it replans; ``semantics``,
    ``particles``, ``max_nodes`` and ``budget`` (seconds) configure a replan;
    ``max_replans`` and ``max_actions`` bound an episode; ``gate`` is the filter's
    model-failure gate; ``landing`` the rollouts' rule for a paddle put down on a part.
    """

    filter_particles: int = 64
    check_rollouts: int = 16
    threshold: float = 0.9
    semantics: str = "particles"
    particles: int = 10
    max_nodes: int = 300
    budget: float = 30.0
    max_replans: int = 4
    max_actions: int = 30
    gate: float = DEFAULT_GATE
    landing: str = "fail"

    def to_json(self) -> dict[str, Any]:
        return {name: getattr(self, name) for name in self.__dataclass_fields__}


@dataclass(frozen=True)
class Replan:
    """One replan: after ``after`` actions, triggered by the success ``estimate``; the
    planner's ``status``, its wall-clock ``seconds``, the new plan's length (0 unsolved)."""

    after: int
    estimate: float
    status: str
    seconds: float
    actions: int

    def to_json(self) -> dict[str, Any]:
        return {
            "after": self.after,
            "estimate": self.estimate,
            "status": self.status,
            "seconds": self.seconds,
            "actions": self.actions,
        }

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Replan:
        return cls(
            int(data["after"]),
            float(data["estimate"]),
            str(data["status"]),
            float(data["seconds"]),
            int(data["actions"]),
        )


@dataclass(frozen=True)
class StepTrace:
    """One executed action, for storyboards: the observation, the filter's prediction and
    posterior, and the success estimate of the rest of the plan (None when not estimated)."""

    action: Action
    observation: Observation
    predicted: ParticleBelief | None
    posterior: ParticleBelief
    estimate: float | None


@dataclass(frozen=True)
class LoopOutcome:
    """What one run of the loop did: the actions executed (in order), the replans, the model
    failures, the failure that ended it (an action the executor could not carry out), why it
    stopped, the final posterior and the goal's estimate under it."""

    executed: tuple[Action, ...]
    replans: tuple[Replan, ...]
    model_failures: tuple[ModelFailure, ...]
    failure: Failure | None
    stopped: str
    belief: ParticleBelief
    estimate: float
    trace: tuple[StepTrace, ...] = field(default=(), compare=False)


class ClosedLoop:
    """Closed-loop execution of ``actions`` on ``problem`` (module docstring)."""

    def __init__(
        self,
        problem: ArrangementProblem,
        actions: Sequence[Action],
        sensor: Sensor,
        settings: ClosedLoopSettings = ClosedLoopSettings(),  # noqa: B008 - frozen
        seed: int = 0,
    ) -> None:
        self.problem = problem
        self.actions = tuple(actions)
        self.sensor = sensor
        self.settings = settings
        self.seed = seed
        self.goal = GoalTest(problem)

    def run(self, executor: Executor, episode: int = 0, *, trace: bool = False) -> LoopOutcome:
        """Execute the plan on ``executor`` as episode ``episode``; ``trace`` keeps every step's
        beliefs (:attr:`LoopOutcome.trace`)."""
        s = self.settings
        rng = np.random.default_rng([self.seed, episode, 0xC105ED])
        belief_filter = ParticleFilter(
            self.problem, self.sensor, s.filter_particles, rng, gate=s.gate, landing=s.landing
        )
        belief = belief_filter.initial()
        remaining = list(self.actions)
        executed: list[Action] = []
        replans: list[Replan] = []
        failures: list[ModelFailure] = []
        steps: list[StepTrace] = []
        failure: Failure | None = None
        stopped = "done"
        while True:
            if not remaining:
                estimate = self._goal_rate(belief)
                if estimate >= s.threshold:
                    break
                if len(replans) >= s.max_replans:
                    stopped = "replans exhausted"
                    break
                found = self._replan(belief, len(executed), estimate, episode, len(replans), rng)
                replans.append(found[0])
                if found[1] is None:
                    stopped = "no plan"
                    break
                remaining = list(found[1])
                continue
            if len(executed) >= s.max_actions:
                stopped = "action limit"
                break
            action = remaining.pop(0)
            try:
                observation = executor.execute(action, len(executed))
            except ExecutionFailed as error:
                failure = error.failure
                stopped = "action failed"
                break
            update = belief_filter.update(belief, action, len(executed), observation)
            executed.append(action)
            belief = update.posterior
            if update.failure is not None:
                failures.append(update.failure)
            estimate: float | None = None
            # The estimate only decides whether to replan: none when no replan is left.
            if remaining and len(replans) < s.max_replans:
                estimate = self._plan_rate(belief, remaining, rng)
                if estimate < s.threshold:
                    found = self._replan(
                        belief, len(executed), estimate, episode, len(replans), rng
                    )
                    replans.append(found[0])
                    if found[1] is not None:
                        remaining = list(found[1])
            if trace:
                steps.append(StepTrace(action, observation, update.predicted, belief, estimate))
        return LoopOutcome(
            tuple(executed),
            tuple(replans),
            tuple(failures),
            failure,
            stopped,
            belief,
            self._goal_rate(belief),
            tuple(steps),
        )

    # -- estimates ---------------------------------------------------------------------------
    def _goal_rate(self, belief: ParticleBelief) -> float:
        """The fraction of the posterior's particles that satisfy the goal."""
        return float(np.mean([not self.goal.misses(state) for state in belief.particles]))

    def _plan_rate(
        self, belief: ParticleBelief, remaining: Sequence[Action], rng: np.random.Generator
    ) -> float:
        """The rest of the plan's success rate over ``check_rollouts`` rollouts from particles
        drawn from ``belief`` (model noise, the rollouts' failures, then the goal test)."""
        rollouts = Rollouts(self.problem, remaining, landing=self.settings.landing)
        particles = belief.particles
        picks = rng.integers(0, len(particles), size=self.settings.check_rollouts)
        good = 0
        for i in picks:
            execution = rollouts.execute(particles[int(i)], rng)
            good += execution.ok and not self.goal.misses(execution.state)
        return good / len(picks)

    # -- replanning --------------------------------------------------------------------------
    def _start(self, belief: ParticleBelief, rng: np.random.Generator) -> Any:
        """The replan's start belief in its semantics' representation (module docstring)."""
        s = self.settings
        if s.semantics == "cbst":
            return belief.intervals
        particles = belief.particles
        if s.semantics == "deterministic":
            poses = belief.poses.reshape(len(belief), -1)
            spread = poses.std(axis=0) + 1e-9
            distance = np.sum(((poses - poses.mean(axis=0)) / spread) ** 2, axis=1)
            return ParticleBelief((particles[int(np.argmin(distance))],))
        count = min(s.particles, len(particles))
        chosen = rng.choice(len(particles), size=count, replace=False)
        return ParticleBelief(tuple(particles[int(i)] for i in sorted(chosen)))

    def _replan(
        self,
        belief: ParticleBelief,
        after: int,
        estimate: float,
        episode: int,
        number: int,
        rng: np.random.Generator,
    ) -> tuple[Replan, tuple[Action, ...] | None]:
        """Plan from the posterior within the budget: the record, and the plan (None when
        the planner found none)."""
        s = self.settings
        started = time.monotonic()
        seed = int(np.random.default_rng([self.seed, episode, number, 0x2E9]).integers(2**31))
        result = plan(
            self.problem,
            semantics=s.semantics,
            particles=s.particles,
            seed=seed,
            max_nodes=s.max_nodes,
            timeout=s.budget,
            start=self._start(belief, rng),
        )
        seconds = time.monotonic() - started
        actions = result.actions if result.solved else None
        record = Replan(after, estimate, str(result.status), seconds, len(actions or ()))
        return record, actions
