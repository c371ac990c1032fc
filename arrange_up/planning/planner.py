"""Planning in belief space: the library's main entry point.

:func:`plan` turns an :class:`~arrange_up.model.problem.ArrangementProblem` into a conformant plan
by best-first search over beliefs whose transitions are resolved by a named semantics
(``deterministic``, ``particles``, ...). The result is a :class:`PlanResult` with an honest
status.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, fields
from typing import Any, Self

from arrange_up.belief.compiled import CompiledProblem, compile_problem
from arrange_up.belief.goals import PartMiss
from arrange_up.belief.states import ParticleBelief
from arrange_up.io.planfile import plan_document
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action, WorldState
from arrange_up.parallel import SERIAL, Runner, SerialRunner
from arrange_up.planning.agenda import AgendaRecord, plan_by_agenda
from arrange_up.planning.config import (
    DEFAULT_MAX_NODES,
    DEFAULT_WEIGHT,
    PlanConfig,
    ProgressCallback,
    SearchConfig,
)
from arrange_up.planning.fitting import too_large, unfit_parts
from arrange_up.planning.successors import SuccessorEvaluator, WorkerSpec
from arrange_up.planning.task import VARIETY_SPLIT, BeliefTask
from arrange_up.planning.validation import (
    VALIDATION_REPLANS,
    Validation,
    ValidationRound,
    check_validate,
    choose_round,
    default_validation,
    research_budget,
    research_on_failure,
    validate_plan,
)
from arrange_up.search import SearchResult, SearchStats, SearchStatus, best_first_search
from arrange_up.transitions import simulates_pushes

__all__ = [
    "DEFAULT_MAX_NODES",
    "DEFAULT_WEIGHT",
    "VARIETY_SPLIT",
    "PartMiss",
    "PlanConfig",
    "PlanResult",
    "PlanStatistics",
    "ProgressCallback",
    "SearchSnapshot",
    "SearchConfig",
    "SearchStatus",
    "plan",
    "too_large",
]


@dataclass(frozen=True)
class SearchSnapshot:
    """The search statistics of a planning run at one moment: during the search, ``progress``
    receives them (as the dict of :meth:`to_json`); at its end they open :class:`PlanStatistics`.

    The counters are the search's (see :class:`~arrange_up.search.SearchStats`);
    ``transitions_simulated`` is the semantics' count of physics simulations (or model
    predictions); ``best_h`` is None until a finite heuristic value was seen.
    """

    expanded: int
    generated: int
    evaluated: int
    pruned_dominated: int
    pruned_infinite: int
    pruned_duplicate: int
    no_prediction: int
    transitions_simulated: int
    best_h: float | None
    elapsed: float

    @classmethod
    def of(cls, search: SearchStats, transitions_simulated: int) -> SearchSnapshot:
        """The statistics of ``search``, with the semantics' ``transitions_simulated``."""
        return cls(
            expanded=search.expanded,
            generated=search.generated,
            evaluated=search.evaluated,
            pruned_dominated=search.pruned_dominated,
            pruned_infinite=search.pruned_infinite,
            pruned_duplicate=search.pruned_duplicate,
            no_prediction=search.no_prediction,
            transitions_simulated=transitions_simulated,
            # JSON has no infinity: "no finite heuristic value seen yet" is None.
            best_h=search.best_h if math.isfinite(search.best_h) else None,
            elapsed=search.elapsed,
        )

    def to_json(self) -> dict[str, Any]:
        """The statistics as a JSON object, keys in field order (as plan files store them)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def plus(self, earlier: SearchSnapshot) -> Self:
        """These statistics with the counters and seconds of ``earlier`` (a search of the same
        run before this one) added, and the smaller ``best_h``; the rest (a
        :class:`PlanStatistics`' configuration) is this one's."""
        counted = {
            f.name: getattr(self, f.name) + getattr(earlier, f.name)
            for f in fields(SearchSnapshot)
            if f.name != "best_h"
        }
        seen = [h for h in (self.best_h, earlier.best_h) if h is not None]
        return dataclasses.replace(self, **counted, best_h=min(seen) if seen else None)


@dataclass(frozen=True)
class PlanStatistics(SearchSnapshot):
    """The statistics of a finished planning run: the search's, ``elapsed`` the wall-clock
    seconds of the whole :func:`plan` call, and the configuration searched with."""

    max_nodes: int
    heuristic: str
    dominance: bool
    weight: float


@dataclass(frozen=True)
class PlanResult:
    """The outcome of :func:`plan`.

    ``actions`` (internal units: poses and distances in inches, angles in **radians**, whatever
    the problem file's units; plan files and the command line show the file's units, degrees by
    default) and ``beliefs`` (the predicted belief before the first action and after each
    action, for storyboards) are set iff ``status == "solved"``.
    ``statistics`` holds the search statistics; :attr:`stats` is their JSON form.
    ``misses`` (None when solved) says how the belief of the smallest heuristic value the search
    reached still misses the goal (per part, the dimensions some particle is out of tolerance
    in); for ``unsolvable``, the parts that cannot fit on the table (``off table``), and
    ``unfit`` why each of them cannot (:func:`~arrange_up.planning.fitting.unfit_parts`: at no
    angle, or no pose, its goal allows), one clause each, in the problem's display units.
    ``refusals``: ``(reason, count)`` of the candidates the semantics refused, most frequent
    first, for a semantics that says why (its ``reasons``: CBST's, and the particle and
    deterministic semantics' failed simulations, such as a push that left a part off the table
    or did not come to rest; empty otherwise).
    ``unplaceable`` (empty when solved): the parts off the table that have a place target at the
    search's start but no place candidate there, every one failing the place precondition
    (their shadow must keep clear of walls, obstacles and the parts on the table: a part that
    fits its goal only touching them is never placed).
    ``fallbacks`` (None for a semantics without a fallback): ``(fell back, pushes)``, the push
    transitions a learned semantics answered by simulation where its model refused (CBST's
    simulated fallback, :mod:`arrange_up.transitions.fallback`) and all the push transitions
    it was asked for (its ``fallback_counts``).
    ``agenda`` (None when the run searched the whole goal only): what the goal agenda did and
    which search found the plan (:class:`~arrange_up.planning.agenda.AgendaRecord`).
    ``validation`` (None when the plan was not validated): how the plan, and each search, did
    on fresh rollouts (the ``validate`` argument of :func:`plan`). Of a validated run,
    ``statistics`` are those of the search whose plan is returned, but ``elapsed`` is the
    whole call's, and ``beliefs`` start from that search's particles (the requested ones and
    the counterexamples added before it).
    """

    status: SearchStatus
    actions: tuple[Action, ...] | None
    semantics: str
    seed: int
    particles: int
    statistics: PlanStatistics
    beliefs: tuple[Any, ...] | None = None
    misses: tuple[PartMiss, ...] | None = None
    refusals: tuple[tuple[str, int], ...] = ()
    validation: Validation | None = None
    unplaceable: tuple[str, ...] = ()
    unfit: tuple[str, ...] = ()
    agenda: AgendaRecord | None = None
    fallbacks: tuple[int, int] | None = None

    @property
    def solved(self) -> bool:
        return self.status == SearchStatus.SOLVED

    def after(self, earlier: Sequence[PlanResult], max_nodes: int) -> PlanResult:
        """This result, of the last search of a run of several, with the statistics and the
        refusals of the ``earlier`` searches added, and the run's node limit ``max_nodes``."""
        statistics = self.statistics
        refusals = Counter(dict(self.refusals))
        fallbacks = self.fallbacks
        for result in earlier:
            statistics = statistics.plus(result.statistics)
            refusals.update(dict(result.refusals))
            if result.fallbacks is not None:
                fell, pushes = fallbacks or (0, 0)
                fallbacks = (fell + result.fallbacks[0], pushes + result.fallbacks[1])
        return dataclasses.replace(
            self,
            statistics=dataclasses.replace(statistics, max_nodes=max_nodes),
            refusals=tuple(refusals.most_common()),
            fallbacks=fallbacks,
        )

    def fallback_line(self) -> str | None:
        """One line on the simulated fallback (None without one): how many push transitions
        fell back to simulation, of how many."""
        if self.fallbacks is None:
            return None
        fell, pushes = self.fallbacks
        return f"simulated fallback: {fell} of {pushes} push transitions fell back to the physics"

    @property
    def reason(self) -> str | None:
        """One line on why no plan was found (None when solved): the candidates refused by the
        semantics (no prediction, with its two most frequent reasons where it gives them),
        pruned as dominated and by the ordering filter (an infinite heuristic), and what the
        closest belief still misses."""
        if self.solved:
            return None
        s = self.statistics
        if self.status == SearchStatus.UNSOLVABLE:  # only proven so by unfit parts
            return "; ".join(self.unfit) + ": no plan exists"
        nodes = f"{s.expanded} node{'s' if s.expanded != 1 else ''}"
        why = "no prediction"
        if self.refusals:
            why += "; most often: " + ", ".join(
                f"{count} {reason}" for reason, count in self.refusals[:2]
            )
        line = (
            f"{self.status} after {nodes}: {s.no_prediction} candidates refused by the semantics "
            f"({why}), {s.pruned_dominated} pruned as dominated, {s.pruned_infinite} by "
            "the ordering filter"
        )
        if self.misses:
            missed = ", ".join(
                f"{m.part} (not on the table)"
                if m.missing
                else f"{m.part} (left on the table)"
                if m.left
                else f"{m.part} in {' and '.join(m.dimensions())}"
                for m in self.misses
            )
            line += f"; the best belief still misses {missed}"
        if self.unplaceable:
            line += (
                f"; no place of {', '.join(self.unplaceable)} is clear at the start (a placed "
                "part's shadow must keep clear of the walls, obstacles and parts on the table)"
            )
        return line

    def document(self, problem: ArrangementProblem, model: str | None = None) -> dict[str, Any]:
        """The plan file of this result for ``problem`` (docs/plan-format.md): its actions when
        solved, the search statistics, the particles, the validation when it was validated,
        and the ``model`` a CBST search used when given."""
        return plan_document(
            problem,
            self.actions,
            status=self.status,
            semantics=self.semantics,
            seed=self.seed,
            search=self.stats,
            extra={
                "particles": self.particles,
                **({"model": model} if model else {}),
                **({"agenda": self.agenda.to_json()} if self.agenda else {}),
                **({"validation": self.validation.to_json()} if self.validation else {}),
            },
        )

    @property
    def stats(self) -> dict[str, Any]:
        """``statistics.to_json()``: the dict plan files and ``--json`` output store, kept as
        the form callers index (``result.stats["expanded"]``)."""
        return self.statistics.to_json()


#: Open entries the workers look ahead into for pushes to simulate: the entries that follow
#: are mostly places (computed here when asked), so the next pushes lie a few levels down.
PREFETCH_DEPTH = 8


def plan(
    problem: ArrangementProblem,
    config: PlanConfig | None = None,
    *,
    progress: ProgressCallback | None = None,
    should_stop: Callable[[], bool] | None = None,
    start: Any = None,
    **options: Any,
) -> PlanResult:
    """Search for a conformant plan for ``problem``.

    Parameters
    ----------
    config
        How to plan (:class:`~arrange_up.planning.config.PlanConfig`: semantics, particles,
        seed, model, validation, the search and the runner); None: the defaults.
    options
        Flat overrides of ``config`` by the names of its fields, its search's and its
        runner's (``plan(problem, semantics="deterministic", max_nodes=100)``; see
        :meth:`PlanConfig.of <arrange_up.planning.config.PlanConfig.of>`). Bad values raise
        ``ValueError`` before anything is built, unknown names ``TypeError``.
    progress
        Receives the search statistics so far (``SearchSnapshot.to_json()``) every
        :data:`arrange_up.search.PROGRESS_INTERVAL` seconds and once at the end of each search
        (with ``stage`` while the goal agenda runs: ``"part k of N (P)"``, ``"full search"``);
        the searches a failed validation starts begin again from zero, and their dicts also
        hold ``search``, the search's number (2, 3, ...).
    should_stop
        Polled during the search; returning True cancels it (status ``cancelled``).
    start
        The belief to plan from instead of the problem's initial belief, in the semantics'
        representation: a :class:`~arrange_up.belief.states.ParticleBelief` for ``particles``
        and ``deterministic`` (any particle count; one particle plans for that state alone), an
        :class:`~arrange_up.belief.states.IntervalBelief` for ``cbst``. Closed-loop execution
        replans from its posterior this way (:mod:`arrange_up.execution.replanning`). A start
        belief (a posterior, not the problem's initial uncertainty) takes no validation: a
        positive ``validate`` with one raises ``ValueError``.

    Notes
    -----
    The search: by the goal agenda first (``search.agenda``, :mod:`arrange_up.planning.agenda`),
    one part at a time from the belief the last one reached, then, where it fails, the whole
    goal in the node limit and time left; :attr:`PlanResult.agenda` says which found the plan.
    Its ``timeout`` covers the whole run, validation included: a plan found before it runs out
    is returned with the validation rollouts that fitted.

    The runner computes successors the search will evaluate next while it deals with the
    current one (:mod:`arrange_up.planning.successors`); the plan and the statistics do not
    depend on where they run. A semantics that simulates no pushes (``cbst``) always computes
    them in this process and starts no pool or cluster (nor reaches the scheduler); for one
    that does, :class:`~arrange_up.parallel.BackendUnavailableError` says that dask is missing
    or the scheduler cannot be reached.

    Validation: a found plan is checked on ``config.validate`` fresh rollouts
    (:mod:`arrange_up.planning.validation`). Under the ``particles`` semantics, when some fail,
    their initial states join the search's particles (at most ``particles`` of them per round)
    and the search runs again, at most
    :data:`~arrange_up.planning.validation.VALIDATION_REPLANS` more times, while the timeout
    leaves time, each within
    :func:`~arrange_up.planning.validation.research_budget` of the first search's nodes; the
    plan returned is the one that did best. Under the other semantics the one
    plan is checked and returned as it did. :attr:`PlanResult.validation` says how each search
    did. The default (None) is twice ``particles``, at least 60, for the ``particles`` semantics
    and 60 for ``cbst`` (conformant plans), 0 (off) for ``deterministic`` (nominal plans).
    """
    config = PlanConfig.of(config, **options)
    check_validate(config.validate, start)
    validate = config.validate
    if validate is None:
        validate = default_validation(config.semantics, config.particles, start)
    research = research_on_failure(config.semantics)
    # The search's runner checks its plans too; a semantics that starts no workers or cluster
    # for its search (cbst predicts in this process) starts none to check its plan.
    runner = config.runner if simulates_pushes(config.semantics) else SERIAL
    timeout = config.search.timeout
    started = time.monotonic()

    def search(start: Any, particles: int, number: int = 1, first: int = 0) -> PlanResult:
        """Search ``number`` of the run, from ``start`` with ``particles``; after the first,
        within :func:`research_budget` of the ``first`` search's expanded nodes."""
        left = None if timeout is None else max(0.0, timeout - (time.monotonic() - started))
        report = progress
        if progress is not None and number > 1:
            report = functools.partial(_numbered, progress, number)
        sized = PlanConfig.of(config, particles=particles)

        def one(
            goal: ArrangementProblem,
            start: Any,
            nodes: int,
            seconds: float | None,
            tell: ProgressCallback | None,
        ) -> PlanResult:
            return _searched(
                compile_problem(goal),
                PlanConfig.of(sized, max_nodes=nodes),
                timeout=seconds,
                progress=tell,
                should_stop=should_stop,
                start=start,
            )

        limit = config.search.node_limit(problem.planning.max_nodes)
        if number > 1:
            limit = research_budget(first, limit)
        if config.search.agenda:
            return plan_by_agenda(
                problem, one, start=start, max_nodes=limit, timeout=left, progress=report
            )
        return one(problem, start, limit, left, report)

    stopped_by: list[str] = []  # what ended the validation early, once it has

    def stop() -> bool:
        """The time limit has come, or the caller asks to stop (and which, remembered)."""
        if not stopped_by:
            if timeout is not None and time.monotonic() - started >= timeout:
                stopped_by.append("the time limit")
            elif should_stop is not None and should_stop():
                stopped_by.append("a stop request")
        return bool(stopped_by)

    particles = config.particles
    result = search(start, particles)
    if not validate or not result.solved:
        return result
    found: list[PlanResult] = []
    rounds: list[ValidationRound] = []
    failed: tuple[WorldState, ...] = ()
    size: int | None = particles if research else None
    for round_ in range(VALIDATION_REPLANS + 1 if research else 1):
        if round_:
            belief = found[-1].beliefs[0]  # type: ignore[index]  # a solved search's start
            belief = ParticleBelief(belief.particles + failed[:particles])
            size = len(belief.poses)
            result = search(belief, size, round_ + 1, rounds[0].expanded)
        if not result.solved:
            rounds.append(ValidationRound(size, result.status, result.stats["expanded"], None))
            break
        run, successes, failed = validate_plan(
            compile_problem(problem),
            result.actions,  # type: ignore[arg-type]  # set when solved
            rollouts=validate,
            seed=config.seed,
            round_=round_,
            runner=runner,
            should_stop=stop,
        )
        rounds.append(
            ValidationRound(size, result.status, result.stats["expanded"], successes, run)
        )
        found.append(result)
        if not failed or stop():
            break
    chosen = choose_round(tuple(rounds))
    best = found[chosen]  # only the last round can be without a plan
    statistics = dataclasses.replace(best.statistics, elapsed=time.monotonic() - started)
    return dataclasses.replace(
        best,
        particles=particles if research else best.particles,  # the requested, not the grown
        statistics=statistics,
        validation=Validation(
            validate,
            tuple(rounds),
            chosen,
            # a stop that came after a round's last rollout cut nothing short
            stopped_by[0]
            if stopped_by and any(r.run not in (None, validate) for r in rounds)
            else None,
        ),
    )


def _numbered(progress: ProgressCallback, number: int, stats: dict[str, Any]) -> None:
    """``progress`` of search ``number`` of a validated run: its statistics and its number."""
    progress({**stats, "search": number})


def _searched(
    compiled: CompiledProblem, config: PlanConfig, *, timeout: float | None, **options: Any
) -> PlanResult:
    """:func:`_search`, and where the ordering filter left nothing to search (the search ran
    out of beliefs having cut some as dead ends, the start perhaps), the search again without
    the filter in the nodes and time left: the filter is a heuristic, and ``exhausted`` must
    mean that the space was searched. The statistics count both searches."""
    started = time.monotonic()
    first = _search(compiled, config, timeout=timeout, **options)
    if first.status != SearchStatus.EXHAUSTED or not first.statistics.pruned_infinite:
        return first
    max_nodes = config.search.node_limit(compiled.problem.planning.max_nodes)
    again = _search(
        compiled,
        PlanConfig.of(
            config, max_nodes=max_nodes - first.statistics.expanded, ordering_filter=False
        ),
        timeout=None if timeout is None else max(0.0, timeout - (time.monotonic() - started)),
        **options,
    )
    return again.after([first], max_nodes)


def _search(
    compiled: CompiledProblem,
    config: PlanConfig,
    *,
    timeout: float | None,
    progress: ProgressCallback | None,
    should_stop: Callable[[], bool] | None,
    start: Any,
) -> PlanResult:
    """One best-first search of :func:`plan` of ``compiled.problem`` under ``config``
    (``timeout`` the seconds left of the run), unvalidated."""
    started = time.monotonic()
    options = config.search
    problem = compiled.problem
    limit = options.node_limit(problem.planning.max_nodes)
    task = BeliefTask.build(compiled, config, start=start)
    # A learned prediction (CBST) costs less than shipping its job to a worker and back:
    # workers only slowed such a search down, so it runs in this process (same plan), and no
    # pool or cluster is started (nor a scheduler reached) for it.
    runner: Runner = SerialRunner()
    if task.semantics.simulates_pushes:
        try:
            runner = config.runner.runner()
        except BaseException:
            task.close()
            raise
    index = task.dominance_index()
    spec = WorkerSpec(compiled, config)
    evaluator = SuccessorEvaluator(task, runner, spec, index)

    def report(stats: SearchStats) -> None:
        if progress is not None:
            progress(SearchSnapshot.of(stats, evaluator.simulations).to_json())

    unfit = unfit_parts(problem)
    oversized = tuple(u.part for u in unfit)
    try:
        start_belief = task.initial_belief()
        # A goal part that cannot fit on the table is a proof: no search is needed.
        result = SearchResult(SearchStatus.UNSOLVABLE, None, None, None, SearchStats())
        if not oversized:
            result = best_first_search(
                start_belief,
                evaluator.successors,
                task.is_goal,
                evaluator.heuristic,
                weight=options.weight,
                deferred=options.deferred,
                dominance_index=index,
                max_nodes=limit,
                timeout=None
                if timeout is None
                else max(0.0, timeout - (time.monotonic() - started)),
                tie_break_seed=config.seed if options.tie_break else None,
                progress=report,
                should_stop=should_stop,
                prefetch=evaluator.prefetch if evaluator.ahead else None,
                prefetch_depth=PREFETCH_DEPTH,
            )
    finally:
        evaluator.close()
        task.close()
    misses = _misses(task, result, oversized, start_belief)
    statistics = PlanStatistics(
        **{
            **asdict(SearchSnapshot.of(result.stats, evaluator.simulations)),
            "elapsed": time.monotonic() - started,
        },
        max_nodes=limit,
        heuristic=options.heuristic,
        dominance=options.dominance,
        weight=options.weight,
    )
    return PlanResult(
        status=result.status,
        actions=tuple(result.plan) if result.plan is not None else None,
        semantics=task.semantics.name,
        seed=config.seed,
        particles=task.semantics.particles,
        statistics=statistics,
        beliefs=tuple(result.states) if result.states is not None else None,
        misses=misses,
        # counted where each child was computed, this process or a worker (successors)
        refusals=tuple(evaluator.reasons.most_common()),
        unplaceable=_unplaceable(task, start_belief, misses),
        unfit=tuple(u.why for u in unfit),
        fallbacks=_fallback_counts(task.semantics),
    )


def _fallback_counts(semantics: Any) -> tuple[int, int] | None:
    """:attr:`PlanResult.fallbacks` of ``semantics``: its ``fallback_counts()``, None for a
    semantics without one."""
    counts = getattr(semantics, "fallback_counts", None)
    return None if counts is None else counts()


def _misses(
    task: BeliefTask, result: SearchResult, oversized: tuple[str, ...], start: Any
) -> tuple[PartMiss, ...] | None:
    """:attr:`PlanResult.misses` of ``result``: the oversized parts (proven unsolvable), how the
    best belief misses the goal, the ``start`` belief's misses when the search accepted no
    belief (the ordering filter pruned the start), or None (solved)."""
    if oversized:
        return tuple(PartMiss(p, True, (0.0, 0.0, 0.0)) for p in oversized)
    if result.solved():
        return None
    best = start if result.best is None else result.best
    return task.goal.misses_array(best.poses, best.names())


def _unplaceable(
    task: BeliefTask, start: Any, misses: tuple[PartMiss, ...] | None
) -> tuple[str, ...]:
    """:attr:`PlanResult.unplaceable`: of the parts ``misses`` has off the table, those that
    have a place target at ``start`` but no place candidate there (each fails the place
    precondition)."""
    missing = [m.part for m in misses or () if m.missing]
    if not missing:
        return ()
    intervals = start.intervals
    placed = {action.obj for action in task.generator.places(intervals)}
    return tuple(
        name
        for name in missing
        if name not in intervals
        and name not in placed
        and task.generator.place_target(name, intervals) is not None
    )
