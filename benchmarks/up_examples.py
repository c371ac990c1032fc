"""How arrange-up's engines answer every example problem of unified-planning.

    PYTHONPATH=. python benchmarks/up_examples.py

Loops over ``unified_planning.test.examples.get_example_problems()`` (66 problems in
unified-planning 1.3.0) and asks each engine: ``arrange-up`` to solve (``particles`` 2, timeout
5 s), ``arrange-up-reliability`` to validate the example's first plan (2 rollouts, 1 worker)
and ``arrange-up-fixtures`` to repair it (2 particles); an example without a plan gets an empty
``SequentialPlan``. Prints, per engine, how many answers had each status and how many raised,
and lists the exceptions. It uses only what every version of the engines accepts, so it runs
on older commits too (the figures before issue 14 in ``docs/history/up.md``).
``tests/up/test_answers.py`` asserts the outcome: a status from every engine, never an
exception.
"""

from __future__ import annotations

import collections
import warnings


def main() -> int:
    warnings.simplefilter("ignore")  # "We cannot establish whether ..." for every problem
    from unified_planning.plans import SequentialPlan
    from unified_planning.shortcuts import (
        OneshotPlanner,
        PlanRepairer,
        PlanValidator,
        get_environment,
    )
    from unified_planning.test.examples import get_example_problems

    import arrange_up  # noqa: F401  (registers the engines)

    get_environment().credits_stream = None
    examples = get_example_problems()
    counts: collections.Counter[tuple[str, str]] = collections.Counter()
    raised: list[tuple[str, str, str]] = []
    engines = {
        "arrange-up": lambda: OneshotPlanner(name="arrange-up", params={"particles": 2}),
        "arrange-up-reliability": lambda: PlanValidator(
            name="arrange-up-reliability", params={"rollouts": 2, "workers": 1}
        ),
        "arrange-up-fixtures": lambda: PlanRepairer(
            name="arrange-up-fixtures", params={"particles": 2}
        ),
    }
    for case_name, case in sorted(examples.items()):
        plans = [*case.valid_plans, *case.invalid_plans]
        plan = plans[0] if plans else SequentialPlan([])
        for name, make in engines.items():
            try:
                with make() as engine:
                    if name == "arrange-up":
                        result = engine.solve(case.problem, timeout=5)
                    elif name == "arrange-up-reliability":
                        result = engine.validate(case.problem, plan)
                    else:
                        result = engine.repair(case.problem, plan)
                counts[(name, result.status.name)] += 1
            except Exception as error:  # what is measured: an engine that raises
                counts[(name, "raised")] += 1
                raised.append((name, case_name, f"{type(error).__name__}: {error}"[:100]))
    print(f"{len(examples)} example problems")
    for name in engines:
        answers = {s: n for (e, s), n in sorted(counts.items()) if e == name}
        answered = sum(n for s, n in answers.items() if s != "raised")
        print(
            f"{name}: {answered} answered with a status; "
            + ", ".join(f"{s} {n}" for s, n in answers.items())
        )
    for name, case_name, error in raised:
        print(f"  {name} raised on {case_name}: {error}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
