"""Planning in belief space: the library's main entry point.

:func:`plan` turns an :class:`~arrange_up.model.problem.ArrangementProblem` into a conformant plan
by best-first search over beliefs whose transitions are resolved by a named semantics
(``deterministic``, ``particles``, ...). The result is a :class:`PlanResult` with an honest
status.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action, Push

#: Statuses of a planning run, as they appear in plan files and ``--json`` output.
SOLVED = "solved"
NODE_LIMIT = "node-limit"
TIMEOUT = "timeout"
UNSOLVABLE = "unsolvable"
CANCELLED = "cancelled"


@dataclass(frozen=True)
class PlanResult:
    """The outcome of :func:`plan`.

    ``actions`` (internal units) and ``beliefs`` (the predicted belief before the first action
    and after each action, for storyboards) are set iff ``status == "solved"``. ``stats`` holds
    the search statistics (expanded, generated, evaluated, pruned counts, transitions simulated,
    elapsed seconds, ...).
    """

    status: str
    actions: tuple[Action, ...] | None
    semantics: str
    seed: int
    particles: int
    stats: dict[str, Any] = field(default_factory=dict)
    beliefs: tuple[Any, ...] | None = None

    @property
    def solved(self) -> bool:
        return self.status == SOLVED


ProgressCallback = Callable[[dict[str, Any]], None]


DEFAULT_MAX_NODES = 5000
"""The thesis's node limit (§3.3)."""
DEFAULT_WEIGHT = 2.0
"""Weighted A* by default: with the (already inadmissible) per-dimension count, A* spends most
of its nodes on plateaus of equal f; weight 2 found the 50-particle 7-block plan within the
node limit (3,303 nodes) where A* did not, and cut 50-particle blocks-4 from 766 nodes to 50,
for plans one or two actions longer. ``weight=1`` gives the thesis's A*."""


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
    tie_break: bool = False,
    variety: bool = False,
    progress: ProgressCallback | None = None,
    should_stop: Callable[[], bool] | None = None,
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
        Wall-clock seconds; the search returns status ``timeout`` when it runs out.
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
    workers
        Processes that simulate a belief's particles in parallel (1: in this process).
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
        Receives a dict of search statistics about every 0.2 s.
    should_stop
        Polled during the search; returning True cancels it (status ``cancelled``).
    """
    import time

    from arrange_up.belief.goals import GoalTest
    from arrange_up.belief.states import IntervalDominanceIndex, ParticleBelief
    from arrange_up.geometry.collision import CollisionChecker
    from arrange_up.planning.actions import ActionGenerator
    from arrange_up.planning.heuristics import make_heuristic
    from arrange_up.search import Edge, SearchStatus, best_first_search
    from arrange_up.transitions import make_semantics

    started = time.monotonic()
    limit = (
        max_nodes if max_nodes is not None else (problem.planning.max_nodes or DEFAULT_MAX_NODES)
    )
    model = make_semantics(semantics, problem, particles=particles, seed=seed, workers=workers)
    checker = CollisionChecker(problem)
    goal = GoalTest(problem)
    generator = ActionGenerator(
        problem, checker, unclipped_pushes=getattr(model, "refuses_uncertain_contacts", False)
    )
    h = make_heuristic(heuristic, problem, goal, checker, generator)

    def successors(belief: ParticleBelief):
        for action in generator.candidates(belief.intervals):
            if variety and isinstance(action, Push):
                action = _vary_push(action, belief, seed)
            yield Edge(action, 1.0, _bind(model.apply, belief, action))

    def is_goal(belief: ParticleBelief) -> bool:
        return goal.satisfied_array(belief.poses, belief.names())

    def report(stats) -> None:
        if progress is not None:
            progress(_stats_dict(stats, model))

    try:
        start = model.initial_belief()
        result = best_first_search(
            start,
            successors,
            is_goal,
            h,
            weight=weight,
            deferred=deferred,
            dominance_index=IntervalDominanceIndex() if dominance else None,
            max_nodes=limit,
            timeout=None if timeout is None else max(0.0, timeout - (time.monotonic() - started)),
            tie_break_seed=seed if tie_break else None,
            progress=report,
            should_stop=should_stop,
        )
    finally:
        model.close()
    status = {
        SearchStatus.SOLVED: SOLVED,
        SearchStatus.NODE_LIMIT: NODE_LIMIT,
        SearchStatus.TIMEOUT: TIMEOUT,
        SearchStatus.UNSOLVABLE: UNSOLVABLE,
        SearchStatus.CANCELLED: CANCELLED,
    }[result.status]
    stats = _stats_dict(result.stats, model)
    stats["elapsed"] = time.monotonic() - started
    stats["max_nodes"] = limit
    stats["heuristic"] = heuristic
    stats["dominance"] = dominance
    stats["weight"] = weight
    return PlanResult(
        status=status,
        actions=tuple(result.plan) if result.plan is not None else None,
        semantics=model.name,
        seed=seed,
        particles=model.particles,
        stats=stats,
        beliefs=tuple(result.states) if result.states is not None else None,
    )


#: Probability that ``variety`` offers a push cut short instead of whole.
VARIETY_SPLIT = 0.5


def _vary_push(push: Push, belief: Any, seed: int) -> Push:
    """``push`` as ``variety`` offers it: whole, or cut to 40-80% of its distance, drawn from
    ``(seed, belief, push)`` (see :func:`plan`)."""
    import dataclasses
    import hashlib

    import numpy as np

    key = repr((belief.names(), belief.poses.tolist(), push)).encode()
    digest = int.from_bytes(hashlib.blake2b(key, digest_size=8).digest(), "little")
    rng = np.random.default_rng([seed, 0x7A41E7, digest])
    if rng.random() >= VARIETY_SPLIT:
        return push
    return dataclasses.replace(push, distance=round(push.distance * rng.uniform(0.4, 0.8), 4))


def _bind(apply: Callable[[Any, Any], Any], belief: Any, action: Any) -> Callable[[], Any]:
    return lambda: apply(belief, action)


def _stats_dict(stats: Any, model: Any) -> dict[str, Any]:
    return {
        "expanded": stats.expanded,
        "generated": stats.generated,
        "evaluated": stats.evaluated,
        "pruned_dominated": stats.pruned_dominated,
        "pruned_infinite": stats.pruned_infinite,
        "pruned_duplicate": stats.pruned_duplicate,
        "no_prediction": stats.no_prediction,
        "transitions_simulated": model.simulations,
        # JSON has no infinity: "no finite heuristic value seen yet" is written as null.
        "best_h": stats.best_h if math.isfinite(stats.best_h) else None,
        "elapsed": stats.elapsed,
    }
