"""Nominal plans: distinct plans of the deterministic relaxation, reproducibly from a seed.

The thesis re-ran its deterministic search and got different plans from the non-unique
ordering of Python's priority queue. Here that variety is deliberate and reproducible: the
first plan is the deterministic planner's with seeded tie-breaking; the others come from the
planner's ``variety`` flag (every push it proposes is, by a seeded coin per belief, offered
whole or cut to 40-80% of its distance), and only plans that differ from those already found
are kept. ``tie_break`` alone gives little variety: the action generator proposes only
goal-directed pushes, so plans differ only in their order (how little and how much more the
flag gives: docs/repair.md, "Nominal plans").
"""

from __future__ import annotations

import numpy as np

from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action
from arrange_up.planning.planner import plan


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
