"""Plan a shipped problem through unified-planning and validate the plan with UP's validator.

    python examples/plan_with_unified_planning.py            # blocks-2
    python examples/plan_with_unified_planning.py blocks-1

The problem is compiled to a UP model (real-valued place/push parameters, effects simulated by
arrange-up's physics at the nominal, noise-free parameters), solved by the ``arrange-up``
engine with the deterministic semantics, and the plan is checked by UP's own
``SequentialPlanValidator``, which re-simulates every action. Importing ``arrange_up`` is what
makes the ``arrange-up`` engine known to unified-planning, in either import order.
"""

from __future__ import annotations

import sys

from unified_planning.shortcuts import OneshotPlanner, PlanValidator, get_environment

import arrange_up


def main(name: str = "blocks-2") -> int:
    # unified-planning prints each engine's credits (a coloured banner) on standard output when
    # it makes the engine, in among the answers below; the engine's get_credits() still has them.
    get_environment().credits_stream = None
    problem = arrange_up.to_up(arrange_up.load(name))
    params = {"semantics": "deterministic", "seed": 0}
    with OneshotPlanner(name="arrange-up", params=params) as planner:
        result = planner.solve(problem, timeout=120)
    print(f"{name}: {result.status.name} ({result.metrics.get('expanded')} nodes expanded)")
    if result.plan is None:
        return 1
    print(result.plan)  # lengths in inches, angles in degrees, exact fractions
    with PlanValidator(name="sequential_plan_validator") as validator:
        check = validator.validate(problem, result.plan)
    print(f"unified-planning's validator: {check.status.name}")
    return 0 if check.status.name == "VALID" else 1


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:2]))
