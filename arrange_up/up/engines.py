"""arrange-up's unified-planning engines: the planner ``OneshotPlanner(name="arrange-up")``, the
reliability validator ``PlanValidator(name="arrange-up-reliability")`` and the fixture-placement
repairer ``PlanRepairer(name="arrange-up-fixtures")``.

    >>> from unified_planning.shortcuts import OneshotPlanner
    >>> from arrange_up.up.compile import to_up
    >>> from arrange_up.io.domains import load
    >>> problem = to_up(load("blocks-1"))
    >>> with OneshotPlanner(name="arrange-up", params={"semantics": "deterministic"}) as p:
    ...     result = p.solve(problem, timeout=60)
    >>> result.status.name
    'SOLVED_SATISFICING'

**The planner** (:class:`ArrangeUpPlanner`) converts the UP problem back to an
:class:`~arrange_up.model.problem.ArrangementProblem` (:func:`arrange_up.up.compile.from_up`:
problems made by :func:`~arrange_up.up.compile.to_up`, and problems read by ``PDDLReader`` from
arrange-up's PDDL domain), runs :func:`arrange_up.planning.planner.plan` and returns a
``PlanGenerationResult`` with an honest status:

* ``SOLVED_SATISFICING``: a ``SequentialPlan`` of ``place``/``push``/``pick`` instances with
  exact ``Fraction`` real parameters (inches, degrees). For a problem read from PDDL, whose
  actions cannot carry real parameters, the instances belong to ``to_up`` of the same problem
  (a log message says so), with the names as ``PDDLReader`` read them (lowercase). The
  validator and the repairer read a plan's object names case-insensitively where the problem
  has no object of the exact name (PDDL names are case-insensitive), so such a plan is judged
  against ``to_up(load_pddl_problem(file))`` too; ``plan_from_up(plan, problem)`` names its
  actions' objects as ``problem`` does, for any other use.
* ``UNSOLVABLE_INCOMPLETELY``: the node limit was reached, or the search was exhausted (its
  candidates ran out under the action generators and the pruning: nothing is proven); the log
  message gives the planner's one line of why.
* ``UNSOLVABLE_PROVEN``: proven before searching, e.g. a goal part that cannot fit on the
  table.
* ``TIMEOUT``: the ``timeout`` ran out. unified-planning never enforces timeouts; the engine
  watches the clock itself.
* ``UNSUPPORTED_PROBLEM``: the problem is not an arrange-up problem, or (``cbst``) the model
  was trained under another controller than the problem's; ``INTERNAL_ERROR``: the planner
  failed, or reading the problem did. Both with a log message saying why.

Parameters (``OneshotPlanner(name="arrange-up", params={...})``): ``semantics`` (default
``"particles"``), ``particles`` (50), ``seed`` (0), ``max_nodes`` (the problem's hint or 5000),
``validate`` (fresh rollouts that check a found plan; under ``particles`` their failed starts join
the particles of up to three more searches; default twice ``particles``, at least 60, for
``particles``, 60 for ``cbst``, 0 (off) for ``deterministic``; 0 turns it off; the returned plan's
figures are the metrics ``validation_rollouts``, ``validation_successes`` and
``validation_searches``, and a log line), ``model`` (``cbst`` only: a shipped model name or the
card path of a model ``arrange-up train-cbst`` made; default the shipped one for the problem's
controller; it is loaded and checked when the engine is made, and a problem whose controller is not
the model's is refused), ``workers`` (1), ``backend`` (``"local"`` or ``"dask"``) and ``scheduler``
(a Dask scheduler address): where the search's successors are simulated, which does not change the
plan (:mod:`arrange_up.planning.successors`; ``cbst`` predicts in the planning process and starts
no workers or cluster); a scheduler that cannot be reached is an ``INTERNAL_ERROR`` with a log
message saying so.
Metrics hold the search statistics (expanded, generated, evaluated, pruned, elapsed, ...).

**The reliability validator** (:class:`ArrangeUpReliability`) judges a plan by Monte Carlo
rollouts under the problem's full noise (:func:`arrange_up.evaluation.evaluate.evaluate_plan`):
it answers ``VALID`` only when every rollout reaches the goal, ``INVALID`` otherwise (with a log
message breaking the failures down, and ``reason`` set from the most frequent failure:
``UNSATISFIED_GOALS`` when that is a missed goal, else ``INAPPLICABLE_ACTION`` naming the action
that failed most often), ``UNKNOWN`` when the problem or the plan cannot be converted or the
evaluation fails. Metrics: ``successes``, ``trials``, ``rate``, ``interval`` (the 95% Wilson
interval as ``[low, high]``), ``interval_low``, ``interval_high``, ``seed``, ``elapsed`` and the
failure counts per kind. Parameters: ``rollouts`` (1000), ``seed`` (0), ``workers`` (``None``:
all cores), ``backend`` (``"local"`` or ``"dask"``), ``scheduler`` (a Dask scheduler address),
``timeout`` (seconds, ``None``: none). unified-planning's ``validate`` takes no timeout, so it
is a parameter; it is checked as rollouts finish, and when it runs out the answer is ``UNKNOWN``
with a log message saying how many rollouts were done.

    >>> from unified_planning.shortcuts import PlanValidator
    >>> with PlanValidator(name="arrange-up-reliability", params={"rollouts": 100}) as v:
    ...     check = v.validate(problem, result.plan)
    >>> check.metrics["successes"], check.metrics["interval"]     # doctest: +SKIP
    ('100', '[0.963, 1]')

**The repairer** (:class:`ArrangeUpFixtureRepairer`): see its docstring. It answers
``SOLVED_SATISFICING`` only with a plan that reaches the goal in the deterministic semantics.

**Every engine answers, none raises** on any problem or plan unified-planning can build: a
problem that is not an arrange-up one is refused with a status (``UNSUPPORTED_PROBLEM``;
``UNKNOWN`` from the validator) and a log message, a failure inside arrange-up is reported as
``INTERNAL_ERROR`` (``UNKNOWN``) with the exception named. Only the parameters are checked when
the engine is made: a bad value raises ``ValueError``, an unknown name ``TypeError`` naming the
accepted ones. A ``solve`` ``timeout`` that is not a positive number of seconds raises
``ValueError`` too.

**Kinds and guarantees.** ``supports(kind)`` is true for exactly the kind of the problems
:func:`~arrange_up.up.compile.to_up` makes (:data:`SUPPORTED_KIND`), so selecting an engine by
problem kind never picks arrange-up for a problem it would refuse. Problems read by
``PDDLReader`` from arrange-up's domain have a generic numeric kind shared by many problems
arrange-up cannot read: the engines answer them when chosen by name (unified-planning then
warns that the kind alone does not tell). unified-planning's meta engines (``replanner``,
``oversubscription``) therefore no longer wrap arrange-up: they hand the engine problems they
edited, which :func:`~arrange_up.up.compile.from_up` refuses. The planner and the repairer are
satisficing (``satisfies(OptimalityGuarantee.SATISFICING)``), never optimal. Every engine has
credits (``get_credits``), which unified-planning prints when it makes the engine
(``get_environment().credits_stream = None`` silences them).

**Registration.** The classes are found by unified-planning's factory through their module and
class names (:data:`arrange_up.up.registration.ENGINES`); ``import arrange_up`` registers them
without importing this module or unified-planning (:mod:`arrange_up.up.registration`).
:func:`register` is re-exported here for existing callers. Programs that never import
``arrange_up`` (unified-planning's ``up`` command) find the engines through a configuration
file: ``python -m arrange_up.up`` prints it, ``python -m arrange_up.up --install`` adds it to the
environment's ``up.ini`` (:mod:`arrange_up.up.__main__`).
"""

from __future__ import annotations

import difflib
import functools
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import IO, Any

from unified_planning.engines import (
    Credits,
    Engine,
    LogLevel,
    LogMessage,
    PlanGenerationResult,
    ValidationResult,
)
from unified_planning.engines import PlanGenerationResultStatus as Status
from unified_planning.engines.mixins import (
    OneshotPlannerMixin,
    PlanRepairerMixin,
    PlanValidatorMixin,
)
from unified_planning.engines.mixins.oneshot_planner import OptimalityGuarantee
from unified_planning.engines.results import FailedValidationReason, ValidationResultStatus
from unified_planning.model import AbstractProblem, ProblemKind
from unified_planning.model.state import State
from unified_planning.plans import Plan, PlanKind

from arrange_up.belief.goals import GoalTest
from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.evaluation.outcomes import GOAL_MISSED
from arrange_up.evaluation.reliability import EvaluationProgress
from arrange_up.model.problem import ArrangementProblem, ObjectKind
from arrange_up.model.world import Action, Place, Push
from arrange_up.parallel import BACKENDS
from arrange_up.planning import planner
from arrange_up.planning.validation import check_validate
from arrange_up.repair import METHODS, TIMEOUT, repair_plan
from arrange_up.transitions import available
from arrange_up.transitions.particles import DeterministicSemantics
from arrange_up.up.compile import (
    TO_UP_KIND,
    from_up,
    made_by_to_up,
    plan_from_up,
    plan_to_up,
    to_up,
)
from arrange_up.up.registration import (
    ENGINE_CLASS,
    ENGINE_NAME,
    ENGINES,
    REPAIRER_CLASS,
    REPAIRER_NAME,
    VALIDATOR_CLASS,
    VALIDATOR_NAME,
    register,
)

__all__ = [
    "ENGINES",
    "ENGINE_CLASS",
    "ENGINE_NAME",
    "REPAIRER_CLASS",
    "REPAIRER_NAME",
    "VALIDATOR_CLASS",
    "VALIDATOR_NAME",
    "ArrangeUpFixtureRepairer",
    "ArrangeUpPlanner",
    "ArrangeUpReliability",
    "register",
]


#: The problem kind every arrange-up engine supports: exactly the kind of what ``to_up`` makes.
#: Problems read by ``PDDLReader`` from arrange-up's domain are of a generic numeric kind that
#: many problems arrange-up cannot read share, so they are not offered by kind; the engines
#: still answer them when chosen by name (unified-planning then warns that the kind alone does
#: not tell).
SUPPORTED_KIND = TO_UP_KIND

#: Credits unified-planning prints when it makes one of the engines (``get_credits``).
_CREDITS = {
    "author": "arrange-up developers",
    "contact": "the arrange-up developers (see the package's README)",
    "website": "none published; see the README of the arrange-up package",
    "license": "MIT",
}
_DESCRIPTIONS = {
    ENGINE_NAME: (
        "Conformant belief-space planning for tabletop place/push/pick problems.",
        "Conformant belief-space A* for robot tabletop manipulation: plans place, push and pick "
        "actions whose outcome is simulated with rigid-body physics (pymunk), over particle or "
        "interval beliefs of the uncertain initial poses and action noise.",
    ),
    VALIDATOR_NAME: (
        "Monte Carlo reliability of place/push/pick plans under the problem's noise.",
        "Validates a place/push/pick plan by Monte Carlo rollouts under the problem's full "
        "noise; VALID only when every rollout reaches the goal, with the 95% Wilson interval of "
        "the success rate.",
    ),
    REPAIRER_NAME: (
        "Fixture-placement repair of nominal place/push/pick plans.",
        "Makes a nominal plan robust by placing fixtures that guide each push (plan repair with "
        "fixtures), choosing placements and push distances on a particle belief.",
    ),
}


class _ArrangeUpEngine(Engine):
    """The shared base of arrange-up's engines: the engine's name from the class attribute
    ``_NAME``, credits, the parameter names it accepts (``_PARAMETERS``), and the problem kinds
    and plan kinds every arrange-up engine supports."""

    _NAME = ""
    #: The names of the engine's parameters (``params={...}``), as its ``__init__`` takes them.
    _PARAMETERS: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        return self._NAME

    @classmethod
    def get_credits(cls, **kwargs: Any) -> Credits | None:
        short, long = _DESCRIPTIONS[cls._NAME]
        return Credits(name=cls._NAME, short_description=short, long_description=long, **_CREDITS)

    @staticmethod
    def supported_kind() -> ProblemKind:
        return SUPPORTED_KIND

    @staticmethod
    def supports(problem_kind: ProblemKind) -> bool:
        return bool(problem_kind <= SUPPORTED_KIND and SUPPORTED_KIND <= problem_kind)

    @staticmethod
    def supports_plan(plan_kind: PlanKind) -> bool:
        return bool(plan_kind == PlanKind.SEQUENTIAL_PLAN)

    @classmethod
    def _refuse_unknown(cls, unknown: dict[str, Any]) -> None:
        """Raise ``TypeError`` naming the unknown parameters, close matches and the accepted
        parameters (a bare ``__init__() got an unexpected keyword`` names none of them)."""
        if not unknown:
            return
        parts = []
        for name in sorted(unknown):
            close = difflib.get_close_matches(name, cls._PARAMETERS, n=1)
            parts.append(f"{name!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
        raise TypeError(
            f"{cls._NAME}: unknown parameter{'s' if len(parts) > 1 else ''} "
            f"{', '.join(parts)}; the accepted parameters are {', '.join(cls._PARAMETERS)}"
        )


class _Satisficing:
    """For the engines that return plans: satisficing only; no plan is claimed optimal (the
    planner runs weighted A* with an incomplete action generator, the repairer scores
    candidates on a sample)."""

    @staticmethod
    def satisfies(optimality_guarantee: OptimalityGuarantee) -> bool:
        return optimality_guarantee is OptimalityGuarantee.SATISFICING


@dataclass(frozen=True)
class _Refusal:
    """Why a problem or plan cannot be read: ``internal`` False when it is not arrange-up's,
    True when reading it failed (an arrange-up defect). Engines answer with the message, they
    never raise."""

    message: str
    internal: bool = False


def _read_problem(problem: AbstractProblem) -> ArrangementProblem | _Refusal:
    """The arrange-up problem of a unified-planning ``problem``, or why there is none."""
    try:
        return from_up(problem)
    except ValueError as error:  # ProblemFormatError is a ValueError
        return _Refusal(f"not an arrange-up problem: {error}")
    except Exception as error:  # from_up refuses foreign problems with ValueError; anything
        # else is a defect of the reader, reported as such rather than raised
        return _Refusal(f"reading the problem failed: {type(error).__name__}: {error}", True)


def _nominal_shortfall(
    problem: ArrangementProblem, actions: Sequence[Action]
) -> str | _Refusal | None:
    """Why ``actions`` do not reach ``problem``'s goal in the deterministic semantics (the
    nominal planner's transition: no noise, nominal initial poses), ``None`` when they do, or a
    :class:`_Refusal` when the replay itself failed.

    The replay applies the symbolic preconditions of :func:`arrange_up.up.compile.to_up`'s
    actions (place an off-table part or fixture, push with an off-table manipulator, pick an
    on-table object), then each action's deterministic outcome
    (:class:`~arrange_up.transitions.particles.DeterministicSemantics`), then the planner's goal
    test (:class:`~arrange_up.belief.goals.GoalTest`)."""
    try:
        return _replay_shortfall(problem, actions)
    except Exception as error:  # the engines answer, they never raise
        message = f"the nominal replay failed: {type(error).__name__}: {error}"
        return _Refusal(message, internal=True)


def _replay_shortfall(problem: ArrangementProblem, actions: Sequence[Action]) -> str | None:
    kinds = {spec.name: spec.kind for spec in problem.objects}
    model = DeterministicSemantics(problem)
    try:
        belief = model.initial_belief()
        for k, action in enumerate(actions):
            on_table = belief.particles[0].names()
            refusal = _precondition_failure(action, kinds, on_table)
            if refusal:
                return f"action {k + 1} ({_describe(action)}) {refusal}"
            after = model.apply(belief, action)
            if after is None:
                return (
                    f"action {k + 1} ({_describe(action)}) fails: an object leaves the table or "
                    "never comes to rest"
                )
            belief = after
    finally:
        model.close()
    misses = GoalTest(problem).misses(belief.particles[0])
    if not misses:
        return None
    where = "; ".join(
        f"{miss.part} {', '.join(miss.dimensions())}"
        + (
            ""
            if miss.missing
            else " (by " + ", ".join(f"{e:.4g}" for e in miss.excess if e > 0) + ")"
        )
        for miss in misses
    )
    return f"after its {len(actions)} action(s) the goal is not reached: {where}"


def _precondition_failure(
    action: Action, kinds: dict[str, ObjectKind], on_table: Sequence[str]
) -> str | None:
    name = action.manipulator if isinstance(action, Push) else action.obj
    kind = kinds.get(name)
    if kind is None:
        return f"names {name!r}, which is not an object of the problem"
    if isinstance(action, Place):
        if kind not in (ObjectKind.PART, ObjectKind.FIXTURE):
            return f"places {name}, a {kind.value}: only parts and fixtures are placed"
        if name in on_table:
            return f"places {name}, which is already on the table"
    elif isinstance(action, Push):
        if kind is not ObjectKind.MANIPULATOR:
            return f"pushes with {name}, a {kind.value}, not a manipulator"
        if name in on_table:
            return f"pushes with {name}, which is on the table"
    elif kind is ObjectKind.OBSTACLE or name not in on_table:
        return f"picks {name}, which is not a movable object on the table"
    return None


def _describe(action: Action) -> str:
    if isinstance(action, Push):
        return f"push with {action.manipulator}"
    return f"{type(action).__name__.lower()} {action.obj}"


# ---------------------------------------------------------------------------------------------
# the planner
# ---------------------------------------------------------------------------------------------
class ArrangeUpPlanner(_Satisficing, _ArrangeUpEngine, OneshotPlannerMixin):
    """Conformant belief-space planning for arrange-up problems (see the module doc)."""

    _NAME = ENGINE_NAME
    _PARAMETERS = (
        "semantics",
        "particles",
        "seed",
        "max_nodes",
        "model",
        "validate",
        "workers",
        "backend",
        "scheduler",
    )

    def __init__(
        self,
        semantics: str = "particles",
        particles: int = 50,
        seed: int = 0,
        max_nodes: int | None = None,
        model: str | None = None,
        validate: int | None = None,
        workers: int = 1,
        backend: str = "local",
        scheduler: str | None = None,
        **unknown: Any,
    ) -> None:
        self._refuse_unknown(unknown)
        Engine.__init__(self)
        OneshotPlannerMixin.__init__(self)
        _check_params(semantics, particles, seed, max_nodes, model, validate)
        _check_parallel_params(ENGINE_NAME, workers, backend, scheduler)
        self._semantics = semantics
        self._particles = particles
        self._seed = seed
        self._max_nodes = max_nodes
        self._model = model
        self._validate = validate
        self._parallel = {"workers": workers, "backend": backend, "scheduler": scheduler}

    def _solve_with_params(
        self,
        problem: AbstractProblem,
        heuristic: Callable[[State], float | None] | None = None,
        timeout: float | None = None,
        output_stream: IO[str] | None = None,
        warm_start_plan: Plan | None = None,
        **kwargs: Any,
    ) -> PlanGenerationResult:
        if warm_start_plan is not None:
            warnings.warn("arrange-up ignores warm_start_plan", UserWarning, stacklevel=3)
        if kwargs:
            warnings.warn(
                f"arrange-up ignores the solve() arguments {', '.join(sorted(kwargs))}; "
                "give engine parameters through OneshotPlanner(params={...})",
                UserWarning,
                stacklevel=3,
            )
        return self._solve(problem, heuristic, timeout, output_stream)

    def _solve(
        self,
        problem: AbstractProblem,
        heuristic: Callable[[State], float | None] | None = None,
        timeout: float | None = None,
        output_stream: IO[str] | None = None,
    ) -> PlanGenerationResult:
        started = time.monotonic()
        _check_timeout(ENGINE_NAME, timeout)
        if heuristic is not None:
            warnings.warn(
                "arrange-up ignores the heuristic argument: it searches belief space with its "
                "own heuristics",
                UserWarning,
                stacklevel=3,  # unified-planning's solve(), which called _solve_with_params
            )
        stream = output_stream

        result = functools.partial(_generation_result, ENGINE_NAME)

        arrangement = _read_problem(problem)
        if isinstance(arrangement, _Refusal):
            status = Status.INTERNAL_ERROR if arrangement.internal else Status.UNSUPPORTED_PROBLEM
            return result(status, logs=[LogMessage(LogLevel.ERROR, arrangement.message)])

        if self._semantics == "cbst":
            refusal = _model_refusal(arrangement, self._model)
            if refusal is not None:
                return result(
                    Status.UNSUPPORTED_PROBLEM, logs=[LogMessage(LogLevel.ERROR, refusal)]
                )

        deadline = None if timeout is None else started + max(0.0, float(timeout))

        def out_of_time() -> bool:
            return deadline is not None and time.monotonic() >= deadline

        def progress(stats: dict[str, Any]) -> None:
            if stream is not None:
                stream.write(
                    "arrange-up: " + " ".join(f"{k}={_short(v)}" for k, v in stats.items()) + "\n"
                )

        try:
            outcome = planner.plan(
                arrangement,
                semantics=self._semantics,
                particles=self._particles,
                seed=self._seed,
                max_nodes=self._max_nodes,
                timeout=None if deadline is None else max(0.0, deadline - time.monotonic()),
                progress=progress,
                should_stop=out_of_time,
                model=self._model,
                validate=self._validate,
                **self._parallel,
            )
        except Exception as error:  # the engine must answer, not raise
            return result(
                Status.INTERNAL_ERROR,
                logs=[
                    LogMessage(
                        LogLevel.ERROR, f"arrange-up failed: {type(error).__name__}: {error}"
                    )
                ],
            )

        metrics = {key: _short(value) for key, value in outcome.stats.items()}
        metrics.update(
            status=str(outcome.status),  # a plain string, as every metric is
            semantics=outcome.semantics,
            particles=str(outcome.particles),
            seed=str(outcome.seed),
        )
        if outcome.validation is not None:
            metrics.update(
                validation_rollouts=str(outcome.validation.rollouts),
                validation_run=str(outcome.validation.run),
                validation_successes=str(outcome.validation.successes),
                validation_searches=str(len(outcome.validation.rounds)),
            )
        limit = outcome.stats.get("max_nodes")
        if outcome.status == planner.SOLVED and outcome.actions is not None:
            plan, logs = _plan_to_up(problem, arrangement, outcome.actions)
            if outcome.validation is not None:
                logs = [*logs, LogMessage(LogLevel.INFO, outcome.validation.line())]
            return result(Status.SOLVED_SATISFICING, plan, logs, metrics)
        if outcome.status == planner.TIMEOUT or (
            outcome.status == planner.CANCELLED and out_of_time()
        ):
            message = f"timeout of {timeout} s reached without a plan"
            return result(Status.TIMEOUT, None, [LogMessage(LogLevel.INFO, message)], metrics)
        if outcome.status == planner.NODE_LIMIT:
            message = (
                f"node limit of {limit} expanded nodes reached without a plan; the search is "
                "incomplete, so the problem is not proven unsolvable"
            )
            return result(
                Status.UNSOLVABLE_INCOMPLETELY, None, [LogMessage(LogLevel.INFO, message)], metrics
            )
        if outcome.status == planner.EXHAUSTED:
            message = (
                f"{outcome.reason}; the action generators and dominance pruning make the search "
                "incomplete, so the problem is not proven unsolvable"
            )
            return result(
                Status.UNSOLVABLE_INCOMPLETELY, None, [LogMessage(LogLevel.INFO, message)], metrics
            )
        if outcome.status == planner.UNSOLVABLE:
            message = str(outcome.reason)
            return result(
                Status.UNSOLVABLE_PROVEN, None, [LogMessage(LogLevel.INFO, message)], metrics
            )
        message = f"the planner stopped with status {str(outcome.status)!r}"
        return result(Status.INTERNAL_ERROR, None, [LogMessage(LogLevel.ERROR, message)], metrics)


def _check_params(
    semantics: Any, particles: Any, seed: Any, max_nodes: Any, model: Any, validate: Any = None
) -> None:
    if semantics not in available():
        raise ValueError(
            f"arrange-up: unknown semantics {semantics!r}; expected one of {', '.join(available())}"
        )
    if not _positive(particles):
        raise ValueError(f"arrange-up: particles must be a positive integer, got {particles!r}")
    _check_seed(ENGINE_NAME, seed)
    if max_nodes is not None and not _positive(max_nodes):
        raise ValueError(f"arrange-up: max_nodes must be a positive integer, got {max_nodes!r}")
    try:
        check_validate(validate)
    except ValueError as error:
        raise ValueError(f"arrange-up: {error}") from None
    if model is not None:
        if semantics != "cbst":
            raise ValueError(
                f"arrange-up: model selects the cbst semantics' learned model; the {semantics} "
                "semantics has none"
            )
        if not isinstance(model, str):
            raise ValueError(
                f"arrange-up: model must be a shipped model name or a card path, got {model!r}"
            )
        # Lazy: the model room imports scikit-learn, which the engines need only for cbst
        # (at module level it would add 0.13 s, measured, to importing this module).
        from arrange_up.cbst.store import load_model

        try:
            load_model(model)  # a model that does not load is refused when the engine is made
        except (LookupError, ValueError) as error:
            raise ValueError(f"arrange-up: model {model!r}: {error}") from None


def _model_refusal(problem: ArrangementProblem, model: str | None) -> str | None:
    """Why the cbst semantics' model (``None``: the shipped one for the problem's controller)
    cannot plan ``problem`` (it was trained under another controller), or ``None``."""
    from arrange_up.cbst.choice import model_for  # lazy: scikit-learn, see _check_params

    try:
        model_for(problem, "default" if model is None else model)
    except (LookupError, ValueError) as error:
        return f"arrange-up: {error}"
    return None


def _plan_to_up(
    problem: AbstractProblem, arrangement: ArrangementProblem, actions: Sequence[Action]
) -> tuple[Plan, list[LogMessage]]:
    """The unified-planning plan of ``actions`` for ``problem``, and the log messages to return
    with it. A problem that did not come from :func:`arrange_up.up.compile.to_up` (one read from
    PDDL) has no actions with real parameters, so the plan is one of ``to_up(arrangement)``."""
    logs = []
    target = problem
    if not made_by_to_up(problem):
        target = to_up(arrangement, environment=problem.environment)
        logs.append(
            LogMessage(
                LogLevel.INFO,
                "the problem came from PDDL, whose actions have no real parameters: the "
                "plan's actions are those of arrange_up.up.compile.to_up(from_up(problem))",
            )
        )
    return plan_to_up(target, [_plain(a) for a in actions]), logs


def _plain(action: Action) -> Action:
    """The action with plain Python floats (the planner may hand out numpy scalars)."""
    pose = tuple(float(v) for v in getattr(action, "pose", ()))
    if isinstance(action, Push):
        return replace(action, pose=pose, distance=float(action.distance))
    if pose:
        return replace(action, pose=pose)
    return action


def _short(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def _read_problem_and_plan(
    problem: AbstractProblem, plan: Plan
) -> tuple[ArrangementProblem, tuple[Action, ...]] | _Refusal:
    """The arrange-up problem and action list of a unified-planning ``problem`` and ``plan``,
    or why not (the validator and the repairer answer with it; engines never raise)."""
    arrangement = _read_problem(problem)
    if isinstance(arrangement, _Refusal):
        return arrangement
    try:
        actions = plan_from_up(plan, arrangement)
    except ValueError as error:
        return _Refusal(f"not a sequential plan of place/push/pick actions: {error}")
    except Exception as error:  # plan_from_up refuses foreign plans with ValueError
        return _Refusal(f"reading the plan failed: {type(error).__name__}: {error}", True)
    return arrangement, actions


def _check_seed(engine: str, seed: Any) -> None:
    """The engines' ``seed`` parameter: a non-negative integer (as the command line's
    ``--seed``; numpy's seed sequences refuse negative ones, so the check is made up front)."""
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise ValueError(f"{engine}: seed must be a non-negative integer, got {seed!r}")


def _check_timeout(engine: str, timeout: Any) -> None:
    if timeout is not None and (
        isinstance(timeout, bool) or not isinstance(timeout, int | float) or not timeout > 0
    ):
        raise ValueError(f"{engine}: timeout must be a positive number of seconds, got {timeout!r}")


class _OutOfTime(Exception):
    """Raised from an evaluation's progress callback when the validator's timeout ran out."""


def _generation_result(
    engine: str,
    status: Status,
    plan: Plan | None = None,
    logs: Sequence[LogMessage] = (),
    metrics: dict[str, str] | None = None,
) -> PlanGenerationResult:
    """The planner's or the repairer's answer, named ``engine`` (no log list when empty)."""
    return PlanGenerationResult(
        status, plan, engine, metrics=metrics, log_messages=list(logs) or None
    )


def _positive(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 1


# ---------------------------------------------------------------------------------------------
# the reliability validator
# ---------------------------------------------------------------------------------------------
class ArrangeUpReliability(_ArrangeUpEngine, PlanValidatorMixin):
    """Monte Carlo reliability of a plan under the problem's noise (see the module doc)."""

    _NAME = VALIDATOR_NAME
    _PARAMETERS = ("rollouts", "seed", "workers", "backend", "scheduler", "timeout")

    def __init__(
        self,
        rollouts: int = 1000,
        seed: int = 0,
        workers: int | None = None,
        backend: str = "local",
        scheduler: str | None = None,
        timeout: float | None = None,
        **unknown: Any,
    ) -> None:
        self._refuse_unknown(unknown)
        Engine.__init__(self)
        PlanValidatorMixin.__init__(self)
        _check_validator_params(rollouts, seed, workers, backend, scheduler)
        _check_timeout(VALIDATOR_NAME, timeout)
        self._rollouts = rollouts
        self._seed = seed
        self._workers = workers
        self._backend = backend
        self._scheduler = scheduler
        self._timeout = timeout

    def _validate(self, problem: AbstractProblem, plan: Plan) -> ValidationResult:
        started = time.monotonic()

        def unknown(
            message: str, level: LogLevel = LogLevel.ERROR, metrics: dict[str, str] | None = None
        ) -> ValidationResult:
            return ValidationResult(
                ValidationResultStatus.UNKNOWN,
                VALIDATOR_NAME,
                log_messages=[LogMessage(level, message)],
                metrics=metrics,
            )

        read = _read_problem_and_plan(problem, plan)
        if isinstance(read, _Refusal):
            return unknown(read.message)
        arrangement, actions = read
        deadline = None if self._timeout is None else started + self._timeout
        seen: list[EvaluationProgress] = []

        def watch(progress: EvaluationProgress) -> None:
            seen[:] = [progress]
            if deadline is not None and time.monotonic() >= deadline:
                raise _OutOfTime

        try:
            outcome = evaluate_plan(
                arrangement,
                actions,
                rollouts=self._rollouts,
                seed=self._seed,
                workers=self._workers,
                backend=self._backend,
                scheduler=self._scheduler,
                progress=watch,
            )
        except _OutOfTime:
            done = seen[0].done if seen else 0
            successes = seen[0].successes if seen else 0
            message = (
                f"timeout of {self._timeout} s reached after {done} of {self._rollouts} "
                f"rollouts ({successes} reached the goal): no verdict"
            )
            metrics = {
                "done": str(done),
                "successes": str(successes),
                "rollouts": str(self._rollouts),
            }
            return unknown(message, LogLevel.INFO, metrics)
        except Exception as error:  # the engine must answer, not raise
            return unknown(f"the evaluation failed: {type(error).__name__}: {error}")

        failures = outcome.failures
        low, high = outcome.interval
        metrics = {
            "successes": str(outcome.successes),
            "trials": str(outcome.trials),
            "rate": f"{outcome.rate:.6g}",
            "interval": f"[{low:.6g}, {high:.6g}]",
            "interval_low": f"{low:.6g}",
            "interval_high": f"{high:.6g}",
            "seed": str(outcome.seed),
            "elapsed": f"{outcome.elapsed:.6g}",
            "goal_missed": str(failures.goal_missed),
            "action_failed": str(failures.action_failed),
            "not_at_rest": str(failures.not_at_rest),
            "off_table": str(failures.off_table),
        }
        summary = (
            f"{outcome.successes} of {outcome.trials} rollouts reached the goal (rate "
            f"{outcome.rate:.4g}, 95% Wilson interval [{low:.4g}, {high:.4g}], "
            f"seed {outcome.seed})"
        )
        if outcome.successes == outcome.trials:
            return ValidationResult(
                ValidationResultStatus.VALID,
                VALIDATOR_NAME,
                log_messages=[LogMessage(LogLevel.INFO, summary)],
                metrics=metrics,
            )
        # the most frequent failure decides UP's reason
        per_action: dict[int, int] = {}
        for entry in (
            *failures.action_failures,
            *failures.not_at_rest_actions,
            *failures.off_table_actions,
        ):
            per_action[entry.action] = per_action.get(entry.action, 0) + entry.rollouts
        worst_action = max(per_action, key=lambda a: (per_action[a], -a), default=None)
        lines = [summary + "; failures:"]
        if failures.goal_missed:
            parts = ", ".join(f"{m.part} {m.dimension} {m.rollouts}" for m in failures.goal_misses)
            lines.append(f"  {GOAL_MISSED}: {failures.goal_missed} ({parts})")
        for entry in failures.action_failures:
            lines.append(f"  action {entry.action} failed in {entry.rollouts}: {entry.reason}")
        for entry in failures.not_at_rest_actions:
            lines.append(f"  action {entry.action} did not come to rest in {entry.rollouts}")
        for entry in failures.off_table_actions:
            lines.append(
                f"  action {entry.action} put {entry.object} off the table in {entry.rollouts}"
            )
        if worst_action is None or failures.goal_missed >= per_action[worst_action]:
            reason, inapplicable = FailedValidationReason.UNSATISFIED_GOALS, None
        else:
            reason = FailedValidationReason.INAPPLICABLE_ACTION
            inapplicable = plan.actions[worst_action]
        return ValidationResult(
            ValidationResultStatus.INVALID,
            VALIDATOR_NAME,
            log_messages=[LogMessage(LogLevel.INFO, "\n".join(lines))],
            reason=reason,
            inapplicable_action=inapplicable,
            metrics=metrics,
        )


def _check_validator_params(
    rollouts: Any, seed: Any, workers: Any, backend: Any, scheduler: Any
) -> None:
    if not _positive(rollouts):
        raise ValueError(f"{VALIDATOR_NAME}: rollouts must be a positive integer, got {rollouts!r}")
    _check_seed(VALIDATOR_NAME, seed)
    _check_parallel_params(VALIDATOR_NAME, workers, backend, scheduler)


def _check_parallel_params(engine: str, workers: Any, backend: Any, scheduler: Any) -> None:
    """The ``workers`` (None: all cores), ``backend`` and ``scheduler`` parameters of an engine
    that runs simulations on :func:`arrange_up.parallel.get_runner`."""
    if workers is not None and not _positive(workers):
        raise ValueError(f"{engine}: workers must be a positive integer, got {workers!r}")
    if backend not in BACKENDS:
        expected = " or ".join(repr(b) for b in BACKENDS)
        raise ValueError(f"{engine}: backend must be {expected}, got {backend!r}")
    if scheduler is not None and (backend != "dask" or not isinstance(scheduler, str)):
        raise ValueError(f"{engine}: a scheduler address needs backend='dask'")


# ---------------------------------------------------------------------------------------------
# the fixture-placement plan repairer
# ---------------------------------------------------------------------------------------------
class ArrangeUpFixtureRepairer(_Satisficing, _ArrangeUpEngine, PlanRepairerMixin):
    """Fixture-placement plan repair (thesis ch. 4,
    :func:`arrange_up.repair.repair_plan`):
    ``PlanRepairer(name="arrange-up-fixtures", params={...}).repair(problem, plan)``.

    Parameters: ``particles`` (150), ``seed`` (0), ``method`` (``"enhanced"`` or
    ``"naive"``), ``workers`` (1), ``timeout`` (seconds, ``None``: none; unified-planning's
    ``repair`` takes no timeout, so it is an engine parameter). The plan is the nominal plan to
    repair (a ``SequentialPlan`` of place/push/pick) and must reach the goal in the
    deterministic semantics: fixtures make a nominal plan robust, they do not complete one.
    The result is a ``PlanGenerationResult``:

    * ``SOLVED_SATISFICING`` with the repaired plan, which reaches the goal in the
      deterministic semantics (replayed before answering);
    * ``UNSOLVABLE_INCOMPLETELY`` when the given plan does not reach the goal nominally (an
      action fails or is inapplicable, or the goal is missed: nothing is repaired), when a step
      could not be repaired, or when the repaired plan misses the goal nominally; the log
      message says which and why (the repair is greedy, so nothing is proven);
    * ``TIMEOUT`` when ``timeout`` ran out (checked between batches of candidates);
    * ``UNSUPPORTED_PROBLEM`` when the problem or the plan is not arrange-up's;
    * ``INTERNAL_ERROR`` when the repair raised.

    Metrics: ``status``, ``elapsed``, ``simulations``, ``pushes``, ``fixtures_placed``,
    ``plan_length``, ``method``, ``particles``, ``seed`` and ``step_K`` (the choice made for
    nominal step K).
    """

    _NAME = REPAIRER_NAME
    _PARAMETERS = ("particles", "seed", "method", "workers", "timeout")

    def __init__(
        self,
        particles: int = 150,
        seed: int = 0,
        method: str = "enhanced",
        workers: int = 1,
        timeout: float | None = None,
        **unknown: Any,
    ) -> None:
        self._refuse_unknown(unknown)
        Engine.__init__(self)
        PlanRepairerMixin.__init__(self)
        _check_repairer_params(particles, seed, method, workers)
        _check_timeout(REPAIRER_NAME, timeout)
        self._particles = particles
        self._seed = seed
        self._method = method
        self._workers = workers
        self._timeout = timeout

    def _repair(self, problem: AbstractProblem, plan: Plan) -> PlanGenerationResult:
        started = time.monotonic()

        result = functools.partial(_generation_result, REPAIRER_NAME)

        def refuse(
            message: str, status: Status = Status.UNSUPPORTED_PROBLEM
        ) -> PlanGenerationResult:
            return result(status, logs=[LogMessage(LogLevel.ERROR, message)])

        read = _read_problem_and_plan(problem, plan)
        if isinstance(read, _Refusal):
            status = Status.INTERNAL_ERROR if read.internal else Status.UNSUPPORTED_PROBLEM
            return refuse(read.message, status)
        arrangement, nominal = read
        shortfall = _nominal_shortfall(arrangement, nominal)
        if isinstance(shortfall, _Refusal):
            return refuse(shortfall.message, Status.INTERNAL_ERROR)
        if shortfall is not None:
            return refuse(
                f"the plan is not a nominal plan of {arrangement.name!r}, so there is nothing "
                f"to repair: {shortfall} in the deterministic semantics. {REPAIRER_NAME} makes a "
                "plan that reaches the goal nominally robust with fixtures; it does not complete "
                "plans (plan one with OneshotPlanner(name='arrange-up', params={'semantics': "
                "'deterministic'}))",
                Status.UNSOLVABLE_INCOMPLETELY,
            )
        remaining = None
        if self._timeout is not None:
            remaining = max(0.0, started + self._timeout - time.monotonic())
        try:
            outcome = repair_plan(
                arrangement,
                nominal,
                particles=self._particles,
                seed=self._seed,
                method=self._method,
                workers=self._workers,
                timeout=remaining,
            )
        except ValueError as error:
            return refuse(f"the plan cannot be repaired: {error}", Status.UNSOLVABLE_INCOMPLETELY)
        except Exception as error:  # the engine must answer, not raise
            return result(
                Status.INTERNAL_ERROR,
                logs=[
                    LogMessage(
                        LogLevel.ERROR, f"{REPAIRER_NAME} failed: {type(error).__name__}: {error}"
                    )
                ],
            )
        stats = outcome.stats()
        metrics = {key: _short(value) for key, value in stats.items()}
        metrics.update(
            status=outcome.status,
            method=outcome.method,
            particles=str(outcome.particles),
            seed=str(outcome.seed),
        )
        for record in outcome.steps:
            if record.kind != "push":
                metrics[f"step_{record.index + 1}"] = f"{record.kind} kept"
            elif record.status != "ok":
                metrics[f"step_{record.index + 1}"] = "failed"
            else:
                where = (
                    "no fixture" if record.pose is None else f"{record.fixture} at {record.pose}"
                )
                metrics[f"step_{record.index + 1}"] = f"{where}, x{record.multiplier:g}"
        if outcome.status == TIMEOUT:
            message = f"timeout of {self._timeout} s reached before the plan was repaired"
            return result(Status.TIMEOUT, None, [LogMessage(LogLevel.INFO, message)], metrics)
        if not outcome.solved or outcome.actions is None:
            return result(
                Status.UNSOLVABLE_INCOMPLETELY,
                None,
                [LogMessage(LogLevel.INFO, f"the repair {outcome.status}: {outcome.reason}")],
                metrics,
            )
        repaired, logs = _plan_to_up(problem, arrangement, outcome.actions)
        # the plan handed out, as exact decimals, must reach the goal nominally: check it
        shortfall = _nominal_shortfall(arrangement, plan_from_up(repaired))
        if isinstance(shortfall, _Refusal):
            return refuse(shortfall.message, Status.INTERNAL_ERROR)
        if shortfall is not None:
            metrics["status"] = "missed-goal"
            message = (
                f"the repair made a plan, but it does not reach the goal in the deterministic "
                f"semantics: {shortfall}; no plan is returned"
            )
            return result(
                Status.UNSOLVABLE_INCOMPLETELY, None, [LogMessage(LogLevel.INFO, message)], metrics
            )
        return result(Status.SOLVED_SATISFICING, repaired, logs, metrics)


def _check_repairer_params(particles: Any, seed: Any, method: Any, workers: Any) -> None:
    if not _positive(particles):
        raise ValueError(
            f"{REPAIRER_NAME}: particles must be a positive integer, got {particles!r}"
        )
    _check_seed(REPAIRER_NAME, seed)
    if method not in METHODS:
        expected = " or ".join(repr(m) for m in METHODS)
        raise ValueError(f"{REPAIRER_NAME}: method must be {expected}, got {method!r}")
    if not _positive(workers):
        raise ValueError(f"{REPAIRER_NAME}: workers must be a positive integer, got {workers!r}")
