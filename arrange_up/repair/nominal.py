"""Nominal plans: distinct plans of the deterministic relaxation, reproducibly from a seed.

The thesis re-ran its deterministic search and got different plans from the non-unique
ordering of Python's priority queue. Here that variety is deliberate and reproducible: the
first plan is the deterministic planner's with seeded tie-breaking; the others come from the
planner's ``variety`` flag (every push it proposes is, by a seeded coin per belief, offered
whole or cut to 40-80% of its distance), and only plans that differ from those already found
are kept. ``tie_break`` alone gives little variety: the action generator proposes only
goal-directed pushes, so plans differ only in their order (how little and how much more the
flag gives: docs/repair.md, "Nominal plans").

:class:`NominalReplay` runs a plan, or a repaired prefix followed by the rest of a nominal plan,
in that same deterministic semantics: the repair keeps only candidates whose plan stays
applicable there and still reaches the goal.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from arrange_up.belief.compiled import compile_problem
from arrange_up.belief.states import ParticleBelief
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action, WorldState
from arrange_up.planning.planner import plan
from arrange_up.transitions.particles import DeterministicSemantics


def nominal_plans(
    problem: ArrangementProblem,
    k: int,
    seed: int = 0,
    *,
    max_tries: int | None = None,
    max_nodes: int | None = None,
) -> list[tuple[Action, ...]]:
    """Up to ``k`` distinct nominal (deterministic) plans, reproducibly from ``seed``.

    Try 0 is the deterministic planner with seeded tie-breaking; try ``j >= 1`` adds the
    planner's ``variety`` flag with the seed ``SeedSequence([seed, j])`` draws (see the module
    docstring). Plans equal to one already found are skipped. Returns fewer than ``k`` plans
    when ``max_tries`` (default ``10 * k + 10``) tries found no more distinct ones, and an empty
    list when the deterministic planner solves none.
    """
    if k < 1:
        raise ValueError(f"k must be at least 1, got {k!r}")
    tries = max_tries if max_tries is not None else 10 * k + 10
    found: list[tuple[Action, ...]] = []
    seen: set[tuple[Action, ...]] = set()
    for j in range(tries):
        planner_seed = seed if j == 0 else _derived_seed(seed, j)
        result = plan(
            problem,
            semantics="deterministic",
            seed=planner_seed,
            tie_break=True,
            variety=j > 0,
            max_nodes=max_nodes,
            agenda=False,  # the thesis's nominal plans (ch. 4): the whole goal's search
        )
        if result.actions is None or result.actions in seen:
            continue
        seen.add(result.actions)
        found.append(result.actions)
        if len(found) == k:
            break
    return found


def _derived_seed(seed: int, j: int) -> int:
    return int(np.random.SeedSequence([seed, j]).generate_state(1)[0])


class NominalReplay:
    """Plans replayed in the deterministic semantics (the nominal planner's transition: one
    particle at the nominal initial poses, no noise), as the nominal states are computed.

    ``apply`` runs actions from a one-particle belief (``initial()`` or an earlier result);
    ``shortfall`` says why a repaired plan's remaining steps do not keep it a nominal plan.
    """

    def __init__(self, problem: ArrangementProblem) -> None:
        self.problem = problem
        self.model = DeterministicSemantics(problem)
        self._goal = compile_problem(problem).goal

    def initial(self) -> ParticleBelief:
        return self.model.initial_belief()

    def apply(
        self, belief: ParticleBelief, actions: Sequence[Action]
    ) -> tuple[ParticleBelief | None, str]:
        """``belief`` after ``actions``, or ``None`` and why the first that fails fails (it
        cannot be applied, or its push leaves an object off the table, never at rest or
        started on a part)."""
        for action in actions:
            kind = type(action).__name__.lower()
            try:
                after = self.model.apply(belief, action)
            except (ValueError, KeyError) as error:
                return None, f"its {kind} cannot be applied: {error}"
            if after is None:
                return None, (
                    f"its {kind} fails (an object leaves the table or never comes to rest, or "
                    "the push starts on a part)"
                )
            belief = after
        return belief, ""

    def goal_miss(self, state: WorldState) -> str:
        """Which parts ``state`` leaves outside the goal, as a phrase (empty when none)."""
        return ", ".join(
            f"{m.part} is not on the table"
            if m.missing
            else f"{m.part} misses its goal in " + "/".join(m.dimensions())
            for m in self._goal.misses(state)
        )

    def shortfall(
        self,
        belief: ParticleBelief,
        steps: Sequence[tuple[int, Sequence[Action]]],
        *,
        goal: bool,
    ) -> str:
        """Why running ``steps`` (``(nominal step index, actions)``, in order) from ``belief``
        is not a nominal plan's end: a step that fails, or (when ``goal``) the parts that miss
        the goal at the end. Empty when it is."""
        for index, actions in steps:
            after, reason = self.apply(belief, actions)
            if after is None:
                return f"step {index + 1}: {reason}"
            belief = after
        if goal:
            return self.goal_miss(belief.particles[0])
        return ""

    def close(self) -> None:
        self.model.close()
