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
from pathlib import Path
from typing import Any, Self

from arrange_up.belief.goals import PartMiss
from arrange_up.belief.states import ParticleBelief
from arrange_up.io.planfile import plan_document
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action, WorldState
from arrange_up.parallel import Runner, SerialRunner, check_runner_options, get_runner
from arrange_up.planning.agenda import AgendaRecord, plan_by_agenda
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
    "PlanResult",
    "PlanStatistics",
    "ProgressCallback",
    "SearchSnapshot",
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

    @property
    def solved(self) -> bool:
        return self.status == SearchStatus.SOLVED

    def after(self, earlier: Sequence[PlanResult], max_nodes: int) -> PlanResult:
        """This result, of the last search of a run of several, with the statistics and the
        refusals of the ``earlier`` searches added, and the run's node limit ``max_nodes``."""
        statistics = self.statistics
        refusals = Counter(dict(self.refusals))
        for result in earlier:
            statistics = statistics.plus(result.statistics)
            refusals.update(dict(result.refusals))
        return dataclasses.replace(
            self,
            statistics=dataclasses.replace(statistics, max_nodes=max_nodes),
            refusals=tuple(refusals.most_common()),
        )

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


#: Receives ``SearchSnapshot.to_json()`` every :data:`arrange_up.search.PROGRESS_INTERVAL` seconds.
ProgressCallback = Callable[[dict[str, Any]], None]


DEFAULT_MAX_NODES = 5000
"""The thesis's node limit (§3.3)."""
DEFAULT_WEIGHT = 2.0
"""Weighted A* by default: with the (already inadmissible) per-dimension count, A* spends most
of its nodes on plateaus of equal f, and weight 2 solves within the node limit problems A* does
not, for plans an action or two longer (figures in docs/design/planning.md). ``weight=1`` gives
the thesis's A*."""


#: Open entries the workers look ahead into for pushes to simulate: the entries that follow
#: are mostly places (computed here when asked), so the next pushes lie a few levels down.
PREFETCH_DEPTH = 8


def plan(
    problem: ArrangementProblem,
    *,
    semantics: str = "particles",
    particles: int = 50,
    seed: int = 0,
    max_nodes: int | None = None,
    timeout: float | None = None,
    heuristic: str = "inadmissible",
    dominance: bool = True,
    weight: float = DEFAULT_WEIGHT,
    deferred: bool = True,
    workers: int = 1,
    backend: str = "local",
    scheduler: str | None = None,
    tie_break: bool = False,
    variety: bool = False,
    progress: ProgressCallback | None = None,
    should_stop: Callable[[], bool] | None = None,
    model: str | Path | None = None,
    start: Any = None,
    validate: int | None = None,
    agenda: bool = True,
) -> PlanResult:
    """Search for a conformant plan for ``problem``.

    Parameters
    ----------
    semantics
        The belief transition, by name (see :mod:`arrange_up.transitions`).
    particles
        Particles per belief, for particle semantics (``deterministic`` always uses one).
    seed
        Makes the run reproducible: initial particles, per-particle noise and (with
        ``tie_break``) the order among equally good nodes all derive from it.
    max_nodes
        Limit on expanded nodes; defaults to the problem's ``planning.max_nodes`` or 5000.
    timeout
        Wall-clock seconds for the whole run, validation included: the search returns status
        ``timeout`` when it runs out; a plan found before it is returned with the validation
        rollouts that fitted (:attr:`PlanResult.validation` says how many ran).
    heuristic
        One of :data:`arrange_up.planning.heuristics.HEURISTICS` (default: the thesis's inadmissible
        per-dimension count with the part-ordering filter, its fastest configuration).
    dominance
        Prune beliefs dominated by an already reached belief (thesis §2.1.2, in its form: a
        dominated belief is pruned whatever its path cost), with a 0.01 in / 0.01 rad
        tolerance (see :class:`~arrange_up.belief.states.IntervalDominanceIndex`).
    weight
        ``f = g + weight * h``; 1 is A*, the default 2 weighted A* (see :data:`DEFAULT_WEIGHT`).
    deferred
        Deferred evaluation: a successor is simulated only when it is taken off the open list,
        not when generated. Most generated successors are never expanded, and simulating them
        is where the time goes.
    workers, backend, scheduler
        Where successor beliefs are computed (:func:`arrange_up.parallel.get_runner`):
        ``"local"`` with ``workers`` processes (1: in this process), or ``"dask"``, a
        LocalCluster of ``workers`` processes or the cluster at ``scheduler``. The workers
        compute the successors the search will evaluate next while it deals with the current
        one (:mod:`arrange_up.planning.successors`); the plan and the statistics do not depend
        on where they run. A semantics that simulates no pushes (``cbst``) always computes
        them in this process and starts no pool or cluster (nor reaches the scheduler). Bad
        options raise ``ValueError`` before anything is built
        (:func:`~arrange_up.parallel.check_runner_options`); for a semantics that simulates
        pushes, :class:`~arrange_up.parallel.BackendUnavailableError` says that dask is
        missing or the scheduler cannot be reached.
    tie_break
        Break ties among equally good nodes at random from ``seed`` (gives different but
        equally good plans for different seeds, e.g. for plan repair); default first-in
        first-out.
    variety
        Deliberate variety for nominal plans (plan repair, thesis ch. 4): every push the action
        generator proposes is, with probability :data:`VARIETY_SPLIT`, offered cut short to a
        random 40-80% of its distance instead of whole. The draws derive from ``seed`` and the
        belief, so a run is reproducible, and different seeds search different action sets:
        they return different plans (pushes in another order, or split in two), where
        ``tie_break`` alone only reorders the few goal-directed pushes of a belief. Plans stay
        valid plans of the unchanged problem.
    progress
        Receives the search statistics so far (``SearchSnapshot.to_json()``) every
        :data:`arrange_up.search.PROGRESS_INTERVAL` seconds and once at the end of each search;
        the searches a failed validation starts (``validate``) begin again from zero, and
        their dicts also hold ``search``, the search's number (2, 3, ...).
    should_stop
        Polled during the search; returning True cancels it (status ``cancelled``).
    model
        The learned model of a semantics that has one (``cbst``: a shipped name or the card
        of a model ``arrange-up train-cbst`` made); ``None``: the shipped default. A model for
        another semantics, or one that does not load, raises ``ValueError``.
    start
        The belief to plan from instead of the problem's initial belief, in the semantics'
        representation: a :class:`~arrange_up.belief.states.ParticleBelief` for ``particles``
        and ``deterministic`` (any particle count; one particle plans for that state alone), an
        :class:`~arrange_up.belief.states.IntervalBelief` for ``cbst``. Closed-loop execution
        replans from its posterior this way (:mod:`arrange_up.execution.replanning`).
    validate
        Rollouts that check a found plan on fresh initial states and noise
        (:mod:`arrange_up.planning.validation`). Under the ``particles`` semantics, when some
        fail, their initial states join the search's particles (at most ``particles`` of them
        per round) and the search runs again, at most
        :data:`~arrange_up.planning.validation.VALIDATION_REPLANS` more times, while ``timeout``
        leaves time; the plan returned is the one that did best. Under the other semantics the
        one plan is checked and returned as it did. :attr:`PlanResult.validation` says how each
        search did. ``None`` (default): twice ``particles``, at least 60, for the ``particles``
        semantics and 60 for ``cbst`` (conformant plans), 0 (off) for ``deterministic`` (nominal
        plans); 0 turns it off. A ``start`` belief (a posterior, not the problem's initial
        uncertainty) takes no validation: a positive value with one raises ``ValueError``.
    agenda
        Search by the goal agenda first (:mod:`arrange_up.planning.agenda`): one part at a
        time in an order taken from the goal's geometry, each from the belief the previous
        part's plan reached; where it fails, the whole goal is searched (with the whole node
        limit, in the time left). :attr:`PlanResult.agenda` says which found the plan. False:
        the whole goal only. Each search, of a subgoal or of the whole goal, runs again
        without the ordering filter where the filter left nothing to search.
    """
    check_validate(validate, start)
    if validate is None:
        validate = default_validation(semantics, particles, start)
    research = research_on_failure(semantics)
    # The search's runner checks its plans too; a semantics that starts no workers or cluster
    # for its search (cbst predicts in this process) starts none to check its plan.
    runner = (
        {"workers": workers, "backend": backend, "scheduler": scheduler}
        if simulates_pushes(semantics)
        else {"workers": 1, "backend": "local", "scheduler": None}
    )
    started = time.monotonic()

    def search(start: Any, particles: int, number: int = 1) -> PlanResult:
        left = None if timeout is None else max(0.0, timeout - (time.monotonic() - started))
        report = progress
        if progress is not None and number > 1:
            report = functools.partial(_numbered, progress, number)

        def one(
            goal: ArrangementProblem,
            start: Any,
            nodes: int,
            seconds: float | None,
            tell: ProgressCallback | None,
        ) -> PlanResult:
            return _searched(
                goal,
                semantics=semantics,
                particles=particles,
                seed=seed,
                max_nodes=nodes,
                timeout=seconds,
                heuristic=heuristic,
                dominance=dominance,
                weight=weight,
                deferred=deferred,
                workers=workers,
                backend=backend,
                scheduler=scheduler,
                tie_break=tie_break,
                variety=variety,
                progress=tell,
                should_stop=should_stop,
                model=model,
                start=start,
            )

        limit = _node_limit(problem, max_nodes)
        if agenda:
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
            result = search(belief, size, round_ + 1)
        if not result.solved:
            rounds.append(ValidationRound(size, result.status, result.stats["expanded"], None))
            break
        run, successes, failed = validate_plan(
            problem,
            result.actions,  # type: ignore[arg-type]  # set when solved
            rollouts=validate,
            seed=seed,
            round_=round_,
            should_stop=stop,
            **runner,
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


def _node_limit(problem: ArrangementProblem, max_nodes: int | None) -> int:
    """The node limit of a run: ``max_nodes``, else the problem's, else the default."""
    return max_nodes if max_nodes is not None else (problem.planning.max_nodes or DEFAULT_MAX_NODES)


def _searched(
    problem: ArrangementProblem, *, max_nodes: int, timeout: float | None, **options: Any
) -> PlanResult:
    """:func:`_search`, and where the ordering filter left nothing to search (the search ran
    out of beliefs having cut some as dead ends, the start perhaps), the search again without
    the filter in the nodes and time left: the filter is a heuristic, and ``exhausted`` must
    mean that the space was searched. The statistics count both searches."""
    started = time.monotonic()
    first = _search(problem, max_nodes=max_nodes, timeout=timeout, **options)
    if first.status != SearchStatus.EXHAUSTED or not first.statistics.pruned_infinite:
        return first
    again = _search(
        problem,
        max_nodes=max_nodes - first.statistics.expanded,
        timeout=None if timeout is None else max(0.0, timeout - (time.monotonic() - started)),
        ordering_filter=False,
        **options,
    )
    return again.after([first], max_nodes)


def _search(
    problem: ArrangementProblem,
    *,
    semantics: str,
    particles: int,
    seed: int,
    max_nodes: int | None,
    timeout: float | None,
    heuristic: str,
    dominance: bool,
    weight: float,
    deferred: bool,
    workers: int,
    backend: str,
    scheduler: str | None,
    tie_break: bool,
    variety: bool,
    progress: ProgressCallback | None,
    should_stop: Callable[[], bool] | None,
    model: str | Path | None,
    start: Any,
    ordering_filter: bool = True,
) -> PlanResult:
    """One best-first search of :func:`plan` (its arguments of the same names), unvalidated;
    ``ordering_filter=False`` leaves the ordering filter out of the heuristic."""
    started = time.monotonic()
    limit = _node_limit(problem, max_nodes)
    # bad backend options fail before the task is built, whether a runner is made or not
    check_runner_options(backend, workers, scheduler)
    task = BeliefTask.build(
        problem,
        semantics=semantics,
        particles=particles,
        seed=seed,
        workers=1,  # the runner computes whole successors; no pool per transition
        heuristic=heuristic,
        dominance=dominance,
        variety=variety,
        model=model,
        start=start,
        ordering_filter=ordering_filter,
    )
    # A learned prediction (CBST) costs less than shipping its job to a worker and back:
    # workers only slowed such a search down, so it runs in this process (same plan), and no
    # pool or cluster is started (nor a scheduler reached) for it.
    runner: Runner = SerialRunner()
    if task.semantics.simulates_pushes:
        try:
            runner = get_runner(backend, workers, scheduler)
        except BaseException:
            task.close()
            raise
    index = task.dominance_index()
    spec = WorkerSpec(problem, semantics, particles, seed, heuristic, model, ordering_filter)
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
                weight=weight,
                deferred=deferred,
                dominance_index=index,
                max_nodes=limit,
                timeout=None
                if timeout is None
                else max(0.0, timeout - (time.monotonic() - started)),
                tie_break_seed=seed if tie_break else None,
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
        heuristic=heuristic,
        dominance=dominance,
        weight=weight,
    )
    return PlanResult(
        status=result.status,
        actions=tuple(result.plan) if result.plan is not None else None,
        semantics=task.semantics.name,
        seed=seed,
        particles=task.semantics.particles,
        statistics=statistics,
        beliefs=tuple(result.states) if result.states is not None else None,
        misses=misses,
        # counted where each child was computed, this process or a worker (successors)
        refusals=tuple(evaluator.reasons.most_common()),
        unplaceable=_unplaceable(task, start_belief, misses),
        unfit=tuple(u.why for u in unfit),
    )


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
