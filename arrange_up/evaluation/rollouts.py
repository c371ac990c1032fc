"""Rollouts: a plan executed open-loop in the physics under freshly drawn noise, judged as it
runs. This is the only loop that executes a sequence of actions in simulation.

Rollout ``i`` draws everything from one generator, ``numpy.random.default_rng([seed, i])``, so
its outcome depends only on ``(seed, i)``: not on the backend, the worker count, the chunking
or the order in which rollouts finish. In that stream, in this order:

1. The initial poses: each object of the initial belief uniformly within its interval
   (``problem.initial``), redrawn until nothing overlaps (rejection sampling,
   :func:`arrange_up.belief.states.sample_initial_particles`).
2. For every action in turn, its noise (:func:`arrange_up.model.world.draw_noise`: place and push
   pose offsets, friction, part and manipulator densities, drawn fresh per action), then the
   action is simulated (:func:`arrange_up.physics.simulation.simulate`).
3. At the end, the goal test (:class:`arrange_up.belief.goals.GoalTest`).

The rollout fails at the first of these (and records which):

* ``action_failed``: the action cannot be applied: the physics refuses it (placing an object
  already on the table, pushing with a manipulator that is on the table, picking an object that
  is not there: the physics' ``ValueError``, whose message is the reason); a push starts with
  shapes overlapping by more than the physics' ``overlap_tolerance`` (0.02 in; the paddle was
  put down on a part); or a place puts its object overlapping another object, a wall or an
  obstacle by more than that tolerance (the physics does not check places). Their reason and
  detail quote the tolerance and the depth in the problem's length unit, as every message does.
  With ``landing="shove"`` a push that starts overlapping is not a failure: the physics
  resolves the overlap (the paddle shoves what it was put down on aside) and the rollout goes
  on; the default ``landing="fail"`` is the rule above (:data:`LANDINGS`).
* ``not_at_rest``: a push's simulation hit its time cap before everything came to rest.
* ``off_table``: an object's centroid ended outside the table (open edges).
* ``goal_missed``: the plan ran through, but at least one goal part misses its tolerance (the
  record says which parts, in which dimensions ``x``, ``y``, ``theta``, by how much beyond the
  tolerance, or ``off table`` when a goal part is not on the table).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from arrange_up.belief.compiled import CompiledProblem, compile_problem
from arrange_up.belief.states import sample_initial_particles
from arrange_up.evaluation.outcomes import (
    ACTION_FAILED,
    GOAL_MISSED,
    NOT_AT_REST,
    OFF_TABLE,
    Failure,
    GoalMiss,
    RolloutRecord,
)
from arrange_up.geometry.collision import PenetrationDepths
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action, Place, WorldState, draw_noise
from arrange_up.physics import simulation  # simulate looked up per call: tests replace it
from arrange_up.physics.simulation import (
    DEFAULT_SETTINGS,
    PhysicsSettings,
    SimulationStatus,
    StepOutcome,
)

__all__ = [
    "LANDINGS",
    "PUSH_OVERLAP_REASON",
    "Execution",
    "RolloutContext",
    "Rollouts",
    "Step",
    "check_landing",
    "execute_plan",
    "rollout_start",
    "rollout_task",
    "simulate_rollout",
    "trace_rollout",
]

PUSH_OVERLAP_REASON = "the push started with shapes overlapping"
#: What a push whose paddle is put down onto a part does: ``fail`` the action (the default) or
#: ``shove`` (the physics resolves the overlap and the rollout goes on).
LANDINGS: tuple[str, ...] = ("fail", "shove")


def check_landing(landing: str) -> str:
    """``landing`` if it is one of :data:`LANDINGS`, else ``ValueError``."""
    if landing not in LANDINGS:
        raise ValueError(f"unknown landing {landing!r}; expected one of {', '.join(LANDINGS)}")
    return landing


@dataclass(frozen=True)
class Execution:
    """Actions executed from a state: ``states`` holds the state it started from, then the
    state after each action, up to the one that failed (whose state is not included);
    ``failure`` is ``None`` when every action went through."""

    states: tuple[WorldState, ...]
    failure: Failure | None

    @property
    def state(self) -> WorldState:
        """The last state reached."""
        return self.states[-1]

    @property
    def ok(self) -> bool:
        return self.failure is None


@dataclass(frozen=True)
class Step:
    """One action executed: the state reached (the state before the action when the action
    could not be applied), the physics' outcome (``None`` when the physics refused the call)
    and the failure, ``None`` when the action went through."""

    state: WorldState
    outcome: StepOutcome | None
    failure: Failure | None


class Rollouts:
    """The rollouts of one plan on one problem: what they need, built once (goal test, angle
    frame, penetration depths), and the loop that runs them."""

    def __init__(
        self,
        problem: ArrangementProblem,
        actions: Sequence[Action],
        settings: PhysicsSettings = DEFAULT_SETTINGS,
        landing: str = "fail",
    ) -> None:
        self.problem = problem
        self.actions = tuple(actions)
        self.settings = settings
        self.landing = check_landing(landing)
        # Shoving: the physics never reports a push's start as OVERLAP (places keep the check).
        self.push_settings = (
            settings if landing == "fail" else replace(settings, overlap_tolerance=math.inf)
        )
        self.compiled = compiled = compile_problem(problem)
        self.goal = compiled.goal
        self.frame = compiled.frame
        self.depths = PenetrationDepths(problem)

    def run(self, seed: int, index: int, trace: list[WorldState] | None = None) -> RolloutRecord:
        """Rollout ``index`` of an evaluation with ``seed``; the states it passes through are
        appended to ``trace`` when given (as :attr:`Execution.states`)."""
        rng = np.random.default_rng([seed, index])
        state = _draw_start(self.compiled, rng)
        states = [] if trace is None else trace
        states.append(state)
        state, failure = self._execute(state, rng, states)
        if failure is not None:
            return RolloutRecord(index, False, failure)
        failure = self.goal_failure(state)
        return RolloutRecord(index, failure is None, failure)

    def goal_failure(self, state: WorldState) -> Failure | None:
        """The ``goal_missed`` failure of a final ``state`` (which parts miss, in which
        dimensions, by how much), or None when it satisfies the goal."""
        misses = self.goal.misses(state)
        if not misses:
            return None
        return Failure(
            GOAL_MISSED,
            misses=tuple(
                GoalMiss(m.part, m.dimensions(), tuple(float(e) for e in m.excess))  # type: ignore[arg-type]
                for m in misses
            ),
        )

    def execute(self, state: WorldState, rng: np.random.Generator) -> Execution:
        """The plan's actions from ``state``, each one's noise drawn from ``rng`` just before it
        is simulated; stops at the first failure (no goal test)."""
        states = [state]
        _, failure = self._execute(state, rng, states)
        return Execution(tuple(states), failure)

    def _execute(
        self, state: WorldState, rng: np.random.Generator, states: list[WorldState]
    ) -> tuple[WorldState, Failure | None]:
        """The one loop: ``(last state, failure or None)``, each state reached appended."""
        for k, action in enumerate(self.actions):
            step = self.step(k, action, state, rng)
            state = step.state
            if step.failure is not None:
                return state, step.failure
            states.append(state)
        return state, None

    def step(self, k: int, action: Action, state: WorldState, rng: np.random.Generator) -> Step:
        """Action ``k`` of a plan executed from ``state``: its noise drawn from ``rng``, then
        simulated and judged as every rollout judges it (the failures of the module
        docstring). Closed-loop execution (:mod:`arrange_up.execution`) runs its actions one at
        a time through here."""
        problem = self.problem
        tolerance = self.settings.overlap_tolerance
        length = _length_text(problem)
        noise = draw_noise(problem, action, rng)
        try:
            outcome = simulation.simulate(problem, state, action, noise, self.push_settings)
        except ValueError as error:
            return Step(state, None, Failure(ACTION_FAILED, k, str(error)))
        if outcome.status is SimulationStatus.OVERLAP:
            return Step(
                state,
                outcome,
                Failure(
                    ACTION_FAILED,
                    k,
                    f"{PUSH_OVERLAP_REASON} (by more than {length(tolerance, 'g')})",
                    f"deepest overlap {length(outcome.overlap, '.4f')}",
                ),
            )
        if outcome.status is SimulationStatus.NOT_AT_REST:
            return Step(state, outcome, Failure(NOT_AT_REST, k))
        if outcome.status is SimulationStatus.OFF_TABLE:
            return Step(state, outcome, Failure(OFF_TABLE, k, objects=tuple(outcome.off_table)))
        state = outcome.state
        if isinstance(action, Place):
            other, depth = self.depths.deepest(state, action.obj)
            if depth > tolerance:
                return Step(
                    state,
                    outcome,
                    Failure(
                        ACTION_FAILED,
                        k,
                        f"placed overlapping {other} (by more than {length(tolerance, 'g')})",
                        f"overlap {length(depth, '.4f')}",
                    ),
                )
        return Step(state, outcome, None)


def _length_text(problem: ArrangementProblem):
    """``text(value, spec)``: a length in inches as the text of ``problem``'s file, converted to
    its length unit and formatted with ``spec`` (``text(0.02, "g")`` is ``"0.0508 cm"`` for a
    problem written in centimetres, ``"0.02 in"`` for one in inches)."""
    units = problem.units

    def text(value: float, spec: str) -> str:
        return f"{units.length_out(value):{spec}} {units.length}"

    return text


def execute_plan(
    problem: ArrangementProblem,
    state: WorldState,
    actions: Sequence[Action],
    rng: np.random.Generator,
    settings: PhysicsSettings = DEFAULT_SETTINGS,
    landing: str = "fail",
) -> Execution:
    """Execute ``actions`` from ``state`` as a rollout does (noise drawn from ``rng`` per
    action, the same failures), without sampling the start or testing the goal."""
    return Rollouts(problem, actions, settings, landing).execute(state, rng)


def _draw_start(compiled: CompiledProblem, rng: np.random.Generator) -> WorldState:
    """Step 1 of a rollout: its initial state, the first draws of its generator."""
    return sample_initial_particles(compiled, 1, rng).particles[0]


def rollout_start(problem: ArrangementProblem, seed: int, index: int) -> WorldState:
    """The initial state rollout ``index`` of an evaluation with ``seed`` starts from (the state
    :func:`trace_rollout` begins with), drawn without running the rollout."""
    rng = np.random.default_rng([seed, index])
    return _draw_start(compile_problem(problem), rng)


def simulate_rollout(
    problem: ArrangementProblem,
    actions: Sequence[Action],
    seed: int,
    index: int,
    landing: str = "fail",
) -> RolloutRecord:
    """Run rollout ``index`` of an evaluation with ``seed`` (see the module docstring).

    The same ``(seed, index)`` always gives the same record; use it to replay one rollout of
    an evaluation (:func:`trace_rollout` gives its states).
    """
    return Rollouts(problem, actions, landing=landing).run(seed, index)


def trace_rollout(
    problem: ArrangementProblem,
    actions: Sequence[Action],
    seed: int,
    index: int,
    landing: str = "fail",
) -> tuple[WorldState, ...]:
    """The world states of rollout ``index`` (the same rollout
    :func:`~arrange_up.evaluation.evaluate.evaluate_plan` runs with ``seed``): the initial
    state, then the state after each action, cut short where the rollout failed (the failing
    action's state is not included; a rollout that only missed the goal has all
    ``len(actions) + 1`` states)."""
    states: list[WorldState] = []
    Rollouts(problem, actions, landing=landing).run(seed, index, states)
    return tuple(states)


@dataclass(frozen=True)
class RolloutContext:
    """What a worker needs to run rollouts of one evaluation (pickled with each task); ``key``
    identifies the evaluation (its problem and plan hashes, and the landing rule)."""

    key: str
    problem: ArrangementProblem
    actions: tuple[Action, ...]
    seed: int
    landing: str = "fail"


def rollout_task(context: RolloutContext, index: int) -> RolloutRecord:
    """Rollout ``index`` of ``context``'s evaluation, reusing this process's :class:`Rollouts`
    of it."""
    return _cached(context).run(context.seed, index)


_CACHE: dict[str, Rollouts] = {}


def _cached(context: RolloutContext) -> Rollouts:
    # Keyed by the problem and plan hashes: a worker receiving the same evaluation's problem
    # again (a fresh unpickled copy per task) reuses the first copy, and with it the physics'
    # per-problem cache.
    hit = _CACHE.get(context.key)
    if hit is None:
        if len(_CACHE) >= 8:
            _CACHE.pop(next(iter(_CACHE)))
        hit = _CACHE[context.key] = Rollouts(
            context.problem, context.actions, landing=context.landing
        )
    return hit
