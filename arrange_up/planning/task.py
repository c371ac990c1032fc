"""The belief-space search problem of one planning run, as one object.

In the manner of pyperplan's ``Task``: a :class:`BeliefTask` holds what
:func:`arrange_up.search.best_first_search` is asked to solve (the initial belief, the goal
test, the successors, the heuristic and the dominance index), built from an
:class:`~arrange_up.model.problem.ArrangementProblem` and a named semantics.
:func:`arrange_up.planning.planner.plan` builds one, hands its members to the search and closes
it.
"""

from __future__ import annotations

import dataclasses
import hashlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from arrange_up.belief.compiled import CompiledProblem
from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import IntervalDominanceIndex
from arrange_up.model.world import Action, Push
from arrange_up.planning.actions import ActionGenerator
from arrange_up.planning.config import PlanConfig
from arrange_up.planning.heuristics import make_heuristic
from arrange_up.search import Edge
from arrange_up.transitions import Semantics, make_semantics

#: Probability that ``variety`` offers a push cut short instead of whole.
VARIETY_SPLIT = 0.5


@dataclass(frozen=True, eq=False)
class BeliefTask:
    """Belief-space search for one problem under one semantics.

    Attributes
    ----------
    semantics
        Resolves ``(belief, action)`` to the next belief (or None: no prediction); owns the
        resources :meth:`close` releases.
    goal
        The problem's goal test; a belief is a goal when every particle satisfies it.
    generator
        Proposes the candidate actions of a belief.
    heuristic
        Estimate of the actions still needed from a belief (``math.inf``: dead end).
    dominance
        Whether beliefs dominated by an already reached one are pruned.
    variety_seed
        None: successors are the generator's candidates as proposed. An integer: every push is
        offered whole or cut short, drawn from this seed (see :func:`vary_push`).
    start
        None: the search starts from the semantics' initial belief (the problem's initial
        uncertainty). Otherwise the belief it starts from, in the semantics' representation
        (replanning from a posterior, :mod:`arrange_up.execution`).
    """

    semantics: Semantics
    goal: GoalTest
    generator: ActionGenerator
    heuristic: Callable[[Any], float]
    dominance: bool
    variety_seed: int | None
    start: Any = None

    @classmethod
    def build(
        cls, compiled: CompiledProblem, config: PlanConfig, *, start: Any = None
    ) -> BeliefTask:
        """The task of one search of ``compiled.problem`` under ``config`` from ``start`` (None:
        the problem's initial belief), its goal test, collision checker and action generator's
        geometry taken from ``compiled``. Successors are computed whole by the search's runner,
        so the semantics starts no pool of its own.

        The semantics is instantiated first (it may start worker processes); it is closed
        again if building the rest fails.
        """
        search = config.search
        problem = compiled.problem
        model = make_semantics(
            config.semantics,
            problem,
            particles=config.particles,
            seed=config.seed,
            workers=1,  # the runner computes whole successors; no pool per transition
            model=config.model,
        )
        try:
            generator = ActionGenerator(
                problem,
                compiled.checker,
                unclipped_pushes=model.refuses_uncertain_contacts,
                settled_wall_pushes=not model.simulates_pushes,
                compressed_wall_pushes=not model.simulates_pushes,
                solve_distances=model.simulates_pushes,
                clearance_pushes=model.particles > 1,
                place_rings=model.place_rings,
            )
            estimate = make_heuristic(
                search.heuristic, compiled, generator, ordering_filter=search.ordering_filter
            )
        except BaseException:
            model.close()
            raise
        variety_seed = config.seed if search.variety else None
        return cls(model, compiled.goal, generator, estimate, search.dominance, variety_seed, start)

    def initial_belief(self) -> Any:
        """The belief the search starts from: :attr:`start` when given, else the semantics'
        initial belief."""
        return self.semantics.initial_belief() if self.start is None else self.start

    def is_goal(self, belief: Any) -> bool:
        """True iff every particle of ``belief`` satisfies the goal."""
        return self.goal.satisfied_array(belief.poses, belief.names())

    def successors(self, belief: Any) -> Iterator[Edge[Any, Action]]:
        """The unit-cost edges of ``belief``: one per candidate action, its child predicted by
        the semantics only when the search asks for it."""
        for action in self.generator.candidates(belief.intervals):
            if self.variety_seed is not None and isinstance(action, Push):
                action = vary_push(action, belief, self.variety_seed)
            yield Edge(action, 1.0, _bind(self.semantics.apply, belief, action))

    def dominance_index(self) -> IntervalDominanceIndex | None:
        """A new, empty dominance index for one search (None when dominance is off)."""
        return IntervalDominanceIndex() if self.dominance else None

    def close(self) -> None:
        """Release the semantics' resources (worker processes, ...)."""
        self.semantics.close()


def vary_push(push: Push, belief: Any, seed: int) -> Push:
    """``push`` as ``variety`` offers it: whole, or (with probability :data:`VARIETY_SPLIT`) cut
    to 40-80% of its distance, drawn from ``(seed, belief, push)`` so a run is reproducible."""
    key = repr((belief.names(), belief.poses.tolist(), push)).encode()
    digest = int.from_bytes(hashlib.blake2b(key, digest_size=8).digest(), "little")
    rng = np.random.default_rng([seed, 0x7A41E7, digest])
    if rng.random() >= VARIETY_SPLIT:
        return push
    return dataclasses.replace(push, distance=round(push.distance * rng.uniform(0.4, 0.8), 4))


def _bind(apply: Callable[[Any, Any], Any], belief: Any, action: Any) -> Callable[[], Any]:
    # A named factory, not a lambda in the loop, so each edge closes over its own action.
    return lambda: apply(belief, action)
