"""The closed loop: execute, sense, update the belief, replan when the plan no longer fits.

:class:`ClosedLoop` is the library call a robot integration uses: given the problem, a plan
and an :class:`~arrange_up.execution.executor.Executor`, :meth:`ClosedLoop.run` executes the
plan one action at a time. After each action it conditions its particle belief on the
observation (:class:`~arrange_up.execution.belief.ParticleFilter`) and estimates the remaining
plan's success under the posterior with a few rollouts (``check_rollouts`` particles drawn
from the posterior, each running the rest of the plan under the model's noise, then the goal
test). When the estimate falls below ``threshold`` it replans from the posterior
(:func:`arrange_up.planning.planner.plan` with ``start=``) within ``budget`` seconds, scores
every plan found and the rest of the current plan on the same rollouts from the posterior,
and goes on with the best (a new plan only when it beats the current one). When the plan has
run out it checks the goal under the posterior (the fraction of particles that satisfy it)
and replans again if that is below the threshold. The loop ends when the plan has run out
and the posterior satisfies the goal, when no plan found beats stopping there, after
``max_replans`` replans, ``max_actions`` actions, or at the first action the executor could
not carry out.

The start belief of a replan depends on the semantics: ``particles`` plans from
``particles`` particles drawn from the posterior; ``deterministic`` from each of
``candidates`` single particles, the most central one (nearest the posterior's mean:
certainty-equivalent replanning) and others drawn from the posterior, a nominal plan per
particle, of which the scoring keeps the one most robust under the posterior; ``cbst`` from
the interval belief fitted over the posterior.

Everything random derives from ``seed`` and the episode number: the filter's propagation and
resampling, the checks' rollouts, and the replans' seeds.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from arrange_up.belief.compiled import compile_problem
from arrange_up.belief.states import ParticleBelief
from arrange_up.evaluation.outcomes import Failure
from arrange_up.evaluation.rollouts import Rollouts
from arrange_up.execution.belief import DEFAULT_GATE, ModelFailure, ParticleFilter
from arrange_up.execution.executor import ExecutionFailed, Executor, scaled_problem
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
    ``particles``, ``max_nodes`` and ``budget`` (seconds, for all of one replan's searches)
    configure a replan, ``candidates`` the start particles a ``deterministic`` replan plans
    from (the most central one, then others drawn from the posterior);
    ``max_replans`` and ``max_actions`` bound an episode; ``gate`` is the filter's
    model-failure gate; ``landing`` the rollouts' rule for a paddle put down on a part;
    ``adapt``: after a model failure recovered at a wider noise scale, the filter, the
    checks and the replans use that scale (:class:`~arrange_up.execution.belief.ParticleFilter`).
    """

    filter_particles: int = 256
    check_rollouts: int = 16
    threshold: float = 0.9
    semantics: str = "particles"
    particles: int = 10
    max_nodes: int = 300
    candidates: int = 4
    budget: float = 30.0
    max_replans: int = 4
    max_actions: int = 30
    gate: float = DEFAULT_GATE
    landing: str = "fail"
    adapt: bool = True

    def to_json(self) -> dict[str, Any]:
        return {name: getattr(self, name) for name in self.__dataclass_fields__}


@dataclass(frozen=True)
class Replan:
    """One replan: after ``after`` actions, triggered by the success ``estimate``; the
    planner's ``status`` (``solved`` when any start gave a plan), the wall-clock ``seconds``
    of the whole replan (planning and scoring the candidates), the distinct ``plans`` found,
    the length of the plan adopted (None: no plan beat the current one, which goes on), the
    estimated success of what goes on (``adopted_estimate``), and when no start gave a plan,
    the planner's line on why (:attr:`~arrange_up.planning.planner.PlanResult.reason` of the
    first search; None when a plan was found, when the budget ran out before any search, and
    in records written before it was kept)."""

    after: int
    estimate: float
    status: str
    seconds: float
    plans: int
    adopted: int | None
    adopted_estimate: float
    reason: str | None = None

    def to_json(self) -> dict[str, Any]:
        return {name: getattr(self, name) for name in self.__dataclass_fields__}

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Replan:
        adopted = data["adopted"]
        return cls(
            int(data["after"]),
            float(data["estimate"]),
            str(data["status"]),
            float(data["seconds"]),
            int(data["plans"]),
            None if adopted is None else int(adopted),
            float(data["adopted_estimate"]),
            data.get("reason"),
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
    stopped, the final posterior and the goal's estimate under it; with ``trace``, every
    step (:class:`StepTrace`) and the belief before the first action (``prior``)."""

    executed: tuple[Action, ...]
    replans: tuple[Replan, ...]
    model_failures: tuple[ModelFailure, ...]
    failure: Failure | None
    stopped: str
    belief: ParticleBelief
    estimate: float
    trace: tuple[StepTrace, ...] = field(default=(), compare=False)
    prior: ParticleBelief | None = field(default=None, compare=False)


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
        self.goal = compile_problem(problem).goal
        self._models: dict[float, ArrangementProblem] = {}
        self._filter: ParticleFilter | None = None  # the running episode's

    def run(self, executor: Executor, episode: int = 0, *, trace: bool = False) -> LoopOutcome:
        """Execute the plan on ``executor`` as episode ``episode``; ``trace`` keeps every step's
        beliefs (:attr:`LoopOutcome.trace`)."""
        s = self.settings
        rng = np.random.default_rng([self.seed, episode, 0xC105ED])
        belief_filter = self._filter = ParticleFilter(
            self.problem,
            self.sensor,
            s.filter_particles,
            rng,
            gate=s.gate,
            landing=s.landing,
            adapt=s.adapt,
        )
        belief = prior = belief_filter.initial()
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
                found = self._replan(
                    belief, remaining, len(executed), estimate, episode, len(replans), rng
                )
                replans.append(found[0])
                if not found[1]:  # nothing better than stopping here
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
                        belief, remaining, len(executed), estimate, episode, len(replans), rng
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
            prior if trace else None,
        )

    # -- estimates ---------------------------------------------------------------------------
    def _model(self) -> ArrangementProblem:
        """The problem with the noise scale the filter has adapted to (1: as modelled)."""
        scale = 1.0 if self._filter is None else self._filter.scale
        cached = self._models.get(scale)
        if cached is None:
            cached = self._models[scale] = scaled_problem(self.problem, scale)
        return cached

    def _goal_rate(self, belief: ParticleBelief) -> float:
        """The fraction of the posterior's particles that satisfy the goal."""
        return float(np.mean([not self.goal.misses(state) for state in belief.particles]))

    def _plan_rate(
        self, belief: ParticleBelief, actions: Sequence[Action], rng: np.random.Generator
    ) -> float:
        """The success rate of ``actions`` from ``belief`` over ``check_rollouts`` rollouts from
        particles drawn from it (model noise, the rollouts' failures, then the goal test); the
        goal's rate under ``belief`` when ``actions`` is empty."""
        if not actions:
            return self._goal_rate(belief)
        rollouts = Rollouts(self._model(), actions, landing=self.settings.landing)
        particles = belief.particles
        picks = rng.integers(0, len(particles), size=self.settings.check_rollouts)
        good = 0
        for i in picks:
            execution = rollouts.execute(particles[int(i)], rng)
            good += execution.ok and not self.goal.misses(execution.state)
        return good / len(picks)

    # -- replanning --------------------------------------------------------------------------
    def _starts(self, belief: ParticleBelief, rng: np.random.Generator) -> list[Any]:
        """The replan's start beliefs in its semantics' representation (module docstring)."""
        s = self.settings
        if s.semantics == "cbst":
            return [belief.intervals]
        particles = belief.particles
        if s.semantics == "deterministic":
            poses = belief.poses.reshape(len(belief), -1)
            spread = poses.std(axis=0) + 1e-9
            distance = np.sum(((poses - poses.mean(axis=0)) / spread) ** 2, axis=1)
            central = int(np.argmin(distance))
            others = [i for i in range(len(particles)) if i != central]
            count = min(s.candidates - 1, len(others))
            drawn = rng.choice(len(others), size=count, replace=False) if count else []
            chosen = [central, *(others[int(i)] for i in drawn)]
            return [ParticleBelief((particles[i],)) for i in chosen]
        count = min(s.particles, len(particles))
        chosen = rng.choice(len(particles), size=count, replace=False)
        return [ParticleBelief(tuple(particles[int(i)] for i in sorted(chosen)))]

    def _replan(
        self,
        belief: ParticleBelief,
        remaining: Sequence[Action],
        after: int,
        estimate: float,
        episode: int,
        number: int,
        rng: np.random.Generator,
    ) -> tuple[Replan, tuple[Action, ...] | None]:
        """Plan from the posterior within the budget, then keep the best plan found if it
        beats the rest of the current plan: the record, and that plan (None: go on as
        before). Every candidate and the current plan are scored on the same rollouts
        (common random numbers), so the comparison is paired."""
        s = self.settings
        started = time.monotonic()
        plans: list[tuple[Action, ...]] = []
        status = reason = None
        for k, start in enumerate(self._starts(belief, rng)):
            left = s.budget - (time.monotonic() - started)
            if left <= 0.0:
                break
            seed = int(
                np.random.default_rng([self.seed, episode, number, k, 0x2E9]).integers(2**31)
            )
            result = plan(
                self._model(),
                semantics=s.semantics,
                particles=s.particles,
                seed=seed,
                max_nodes=s.max_nodes,
                timeout=left,
                start=start,
            )
            if result.solved:
                status = "solved"
                if result.actions not in plans:
                    plans.append(result.actions or ())
            elif status is None:
                status, reason = str(result.status), result.reason
        key = [self.seed, episode, number, 0xE57]
        best: tuple[Action, ...] | None = None
        best_rate = self._plan_rate(belief, remaining, np.random.default_rng(key))
        for candidate in plans:
            rate = self._plan_rate(belief, candidate, np.random.default_rng(key))
            if rate > best_rate:
                best, best_rate = candidate, rate
        record = Replan(
            after,
            estimate,
            status or "timeout",
            time.monotonic() - started,
            len(plans),
            None if best is None else len(best),
            best_rate,
            None if status == "solved" else reason,
        )
        return record, best
