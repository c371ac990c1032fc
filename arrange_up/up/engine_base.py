"""What arrange-up's three unified-planning engines share: their base class (name, credits,
problem and plan kinds, refusal of unknown parameters), the satisficing guarantee, and the checks
of the parameters more than one engine takes.

The engines, one module each: the planner ``OneshotPlanner(name="arrange-up")``
(:mod:`arrange_up.up.planner_engine`), the reliability validator
``PlanValidator(name="arrange-up-reliability")`` (:mod:`arrange_up.up.validator_engine`) and the
fixture-placement repairer ``PlanRepairer(name="arrange-up-fixtures")``
(:mod:`arrange_up.up.repairer_engine`); what they read and answer is converted by
:mod:`arrange_up.up.engine_io`.

**Every engine answers, none raises** on any problem or plan unified-planning can build: a
problem that is not an arrange-up one is refused with a status (``UNSUPPORTED_PROBLEM``;
``UNKNOWN`` from the validator) and a log message, a failure inside arrange-up is reported as
``INTERNAL_ERROR`` (``UNKNOWN``) with the exception named. Only the parameters are checked when
the engine is made: a bad value raises ``ValueError``, an unknown name ``TypeError`` naming the
accepted ones. A ``solve`` ``timeout`` that is not a positive number of seconds raises
``ValueError`` too.

**Kinds and guarantees.** ``supported_kind()`` is the widest kind
:func:`~arrange_up.up.compile.from_up` reads (:data:`SUPPORTED_KIND`): the kind of the problems
:func:`~arrange_up.up.compile.to_up` makes and the kind of those ``PDDLReader`` reads from
arrange-up's domain. ``supports(kind)`` is true for the kinds between it and the features every
arrange-up problem has (:data:`~arrange_up.up.compile.ARRANGE_UP_CORE_KIND`), so
``OneshotPlanner(problem_kind=problem.kind)`` finds arrange-up for both, and never for a
classical problem. A foreign numeric problem of the same kind is answered
``UNSUPPORTED_PROBLEM`` with the reason. unified-planning's meta engines (``replanner[...]``,
``oversubscription[...]``) ask about the bare ``ACTION_BASED`` kind, so they do not wrap
arrange-up; ``Replanner(problem, name="arrange-up")``, which makes the engine with a problem,
is refused with a ``TypeError`` saying so: a replanner hands the engine edited problems, which
cannot be mapped back to an arrangement. The planner and the repairer are
satisficing (``satisfies(OptimalityGuarantee.SATISFICING)``), never optimal. Every engine has
credits (``get_credits``), which unified-planning prints when it makes the engine
(``get_environment().credits_stream = None`` silences them).

**Registration.** The classes are found by unified-planning's factory through their module and
class names (:data:`arrange_up.up.registration.ENGINES`); ``import arrange_up`` registers them
without importing the engines' modules or unified-planning (:mod:`arrange_up.up.registration`).
Programs that never import ``arrange_up`` (unified-planning's ``up`` command) find the engines
through a configuration file: ``python -m arrange_up.up`` prints it,
``python -m arrange_up.up --install`` adds it to the environment's ``up.ini``
(:mod:`arrange_up.up.__main__`).
"""

from __future__ import annotations

import difflib
from typing import Any

from unified_planning.engines import Credits, Engine
from unified_planning.engines.mixins.oneshot_planner import OptimalityGuarantee
from unified_planning.model import ProblemKind
from unified_planning.plans import PlanKind

from arrange_up.counts import check_count, is_number
from arrange_up.parallel import BACKENDS
from arrange_up.up.compile import ARRANGE_UP_CORE_KIND, READABLE_KIND
from arrange_up.up.registration import ENGINE_NAME, REPAIRER_NAME, VALIDATOR_NAME

#: The widest problem kind every arrange-up engine supports: what ``to_up`` makes and what
#: ``PDDLReader`` makes of arrange-up's domain (``supports`` also asks for the core features).
SUPPORTED_KIND = READABLE_KIND

#: The keyword arguments unified-planning passes to an engine class made for an operation that
#: takes the problem up front (``Replanner``, ``SequentialSimulator``), which no arrange-up
#: engine implements.
_PROBLEM_BOUND_ARGUMENTS = frozenset({"problem", "error_on_failed_checks"})

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


class ArrangeUpEngine(Engine):
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
        return bool(ARRANGE_UP_CORE_KIND <= problem_kind and problem_kind <= SUPPORTED_KIND)

    @staticmethod
    def supports_plan(plan_kind: PlanKind) -> bool:
        return bool(plan_kind == PlanKind.SEQUENTIAL_PLAN)

    @classmethod
    def _refuse_unknown(cls, unknown: dict[str, Any]) -> None:
        """Raise ``TypeError`` naming the unknown parameters, close matches and the accepted
        parameters (a bare ``__init__() got an unexpected keyword`` names none of them)."""
        if not unknown:
            return
        if _PROBLEM_BOUND_ARGUMENTS <= set(unknown):
            raise TypeError(
                f"{cls._NAME} is not a replanner: unified-planning's Replanner and its meta "
                "engines (replanner[...], oversubscription[...]) are not supported, since they "
                "hand the engine problems they edited, which cannot be mapped back to an "
                "arrange-up problem; use OneshotPlanner(name='arrange-up') on the whole problem"
            )
        parts = []
        for name in sorted(unknown):
            close = difflib.get_close_matches(name, cls._PARAMETERS, n=1)
            parts.append(f"{name!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
        raise TypeError(
            f"{cls._NAME}: unknown parameter{'s' if len(parts) > 1 else ''} "
            f"{', '.join(parts)}; the accepted parameters are {', '.join(cls._PARAMETERS)}"
        )


class Satisficing:
    """For the engines that return plans: satisficing only; no plan is claimed optimal (the
    planner runs weighted A* with an incomplete action generator, the repairer scores
    candidates on a sample)."""

    @staticmethod
    def satisfies(optimality_guarantee: OptimalityGuarantee) -> bool:
        return optimality_guarantee is OptimalityGuarantee.SATISFICING


def check_seed(engine: str, seed: Any) -> None:
    """The engines' ``seed`` parameter: a non-negative integer (as the command line's
    ``--seed``; numpy's seed sequences refuse negative ones, so the check is made up front)."""
    check_count(f"{engine}: seed", seed, minimum=0)


def check_timeout(engine: str, timeout: Any) -> None:
    if timeout is not None and (not is_number(timeout) or not timeout > 0):
        raise ValueError(f"{engine}: timeout must be a positive number of seconds, got {timeout!r}")


def check_parallel_params(engine: str, workers: Any, backend: Any, scheduler: Any) -> None:
    """The ``workers`` (None: all cores), ``backend`` and ``scheduler`` parameters of an engine
    that runs simulations on :func:`arrange_up.parallel.get_runner`."""
    if workers is not None:
        check_count(f"{engine}: workers", workers)
    if backend not in BACKENDS:
        expected = " or ".join(repr(b) for b in BACKENDS)
        raise ValueError(f"{engine}: backend must be {expected}, got {backend!r}")
    if scheduler is not None and (backend != "dask" or not isinstance(scheduler, str)):
        raise ValueError(f"{engine}: a scheduler address needs backend='dask'")
