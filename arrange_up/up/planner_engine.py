"""The planner engine ``OneshotPlanner(name="arrange-up")``.

    >>> from unified_planning.shortcuts import OneshotPlanner
    >>> from arrange_up.up.compile import to_up
    >>> from arrange_up.io.domains import load
    >>> problem = to_up(load("blocks-1"))
    >>> with OneshotPlanner(name="arrange-up", params={"semantics": "deterministic"}) as p:
    ...     result = p.solve(problem, timeout=60)
    >>> result.status.name
    'SOLVED_SATISFICING'

The planner (:class:`ArrangeUpPlanner`) converts the UP problem back to an
:class:`~arrange_up.model.problem.ArrangementProblem` (:func:`arrange_up.up.compile.from_up`:
problems made by :func:`~arrange_up.up.compile.to_up`, and problems read by ``PDDLReader`` from
arrange-up's PDDL domain), runs :func:`arrange_up.planning.planner.plan` and returns a
``PlanGenerationResult`` with an honest status:

* ``SOLVED_SATISFICING``: a ``SequentialPlan`` of ``place``/``push``/``pick`` instances with
  exact ``Fraction`` real parameters (inches, degrees). For a problem read from PDDL, whose
  actions cannot carry real parameters, the problem's ``place`` and ``push`` are first given
  them and their simulated effects, in place
  (:func:`~arrange_up.up.compile.equip_pddl_problem`; a log message says so), so the plan's
  actions are the problem's own and unified-planning's ``SequentialPlanValidator`` accepts
  them; the names are as ``PDDLReader`` read them (lowercase). The
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

What every engine shares (answers instead of exceptions, kinds, registration):
:mod:`arrange_up.up.engine_base`.
"""

from __future__ import annotations

import functools
import time
import warnings
from collections.abc import Callable
from typing import IO, Any

from unified_planning.engines import Engine, LogLevel, LogMessage, PlanGenerationResult
from unified_planning.engines import PlanGenerationResultStatus as Status
from unified_planning.engines.mixins import OneshotPlannerMixin
from unified_planning.model import AbstractProblem
from unified_planning.model.state import State
from unified_planning.plans import Plan

from arrange_up.counts import check_count
from arrange_up.model.problem import ArrangementProblem
from arrange_up.planning import planner
from arrange_up.planning.config import PlanConfig
from arrange_up.planning.validation import check_validate
from arrange_up.search import SearchStatus
from arrange_up.transitions import available
from arrange_up.up.engine_base import (
    ArrangeUpEngine,
    Satisficing,
    check_parallel_params,
    check_seed,
    check_timeout,
)
from arrange_up.up.engine_io import (
    Refusal,
    answer_plan,
    generation_result,
    metric_text,
    read_problem,
)
from arrange_up.up.plan_writer import install as install_plan_writer
from arrange_up.up.registration import ENGINE_NAME

__all__ = ["ArrangeUpPlanner"]

# unified-planning's PDDLWriter (and so `up oneshot-planning --plan FILE`) writes the engine's
# plans, whose actions have real parameters (arrange_up.up.plan_writer)
install_plan_writer()


class ArrangeUpPlanner(Satisficing, ArrangeUpEngine, OneshotPlannerMixin):
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
        check_parallel_params(ENGINE_NAME, workers, backend, scheduler)
        self._config = PlanConfig.of(
            semantics=semantics,
            particles=particles,
            seed=seed,
            max_nodes=max_nodes,
            model=model,
            validate=validate,
            workers=workers,
            backend=backend,
            scheduler=scheduler,
        )

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
        check_timeout(ENGINE_NAME, timeout)
        if heuristic is not None:
            warnings.warn(
                "arrange-up ignores the heuristic argument: it searches belief space with its "
                "own heuristics",
                UserWarning,
                stacklevel=3,  # unified-planning's solve(), which called _solve_with_params
            )
        stream = output_stream

        result = functools.partial(generation_result, ENGINE_NAME)

        arrangement = read_problem(problem)
        if isinstance(arrangement, Refusal):
            status = Status.INTERNAL_ERROR if arrangement.internal else Status.UNSUPPORTED_PROBLEM
            return result(status, logs=[LogMessage(LogLevel.ERROR, arrangement.message)])

        if self._config.semantics == "cbst":
            refusal = _model_refusal(arrangement, self._config.model)
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
                    "arrange-up: "
                    + " ".join(f"{k}={metric_text(v)}" for k, v in stats.items())
                    + "\n"
                )

        try:
            outcome = planner.plan(
                arrangement,
                self._config,
                timeout=None if deadline is None else max(0.0, deadline - time.monotonic()),
                progress=progress,
                should_stop=out_of_time,
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

        metrics = {key: metric_text(value) for key, value in outcome.stats.items()}
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
        if outcome.status == SearchStatus.SOLVED and outcome.actions is not None:
            plan, logs = answer_plan(problem, arrangement, outcome.actions)
            if outcome.validation is not None:
                logs = [*logs, LogMessage(LogLevel.INFO, outcome.validation.line())]
            return result(Status.SOLVED_SATISFICING, plan, logs, metrics)
        if outcome.status == SearchStatus.TIMEOUT or (
            outcome.status == SearchStatus.CANCELLED and out_of_time()
        ):
            message = f"timeout of {timeout} s reached without a plan"
            return result(Status.TIMEOUT, None, [LogMessage(LogLevel.INFO, message)], metrics)
        if outcome.status == SearchStatus.NODE_LIMIT:
            message = (
                f"node limit of {limit} expanded nodes reached without a plan; the search is "
                "incomplete, so the problem is not proven unsolvable"
            )
            return result(
                Status.UNSOLVABLE_INCOMPLETELY, None, [LogMessage(LogLevel.INFO, message)], metrics
            )
        if outcome.status == SearchStatus.EXHAUSTED:
            message = (
                f"{outcome.reason}; the action generators and dominance pruning make the search "
                "incomplete, so the problem is not proven unsolvable"
            )
            return result(
                Status.UNSOLVABLE_INCOMPLETELY, None, [LogMessage(LogLevel.INFO, message)], metrics
            )
        if outcome.status == SearchStatus.UNSOLVABLE:
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
    check_count(f"{ENGINE_NAME}: particles", particles)
    check_seed(ENGINE_NAME, seed)
    if max_nodes is not None:
        check_count(f"{ENGINE_NAME}: max_nodes", max_nodes)
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
        # (at module level scikit-learn's import would slow every import of this module).
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
