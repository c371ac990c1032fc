"""The compliant controller in the engine's solver against the same controller run from Python.

Usage::

    python benchmarks/solver_controller.py [--pushes 200] [--rollouts 200] [--rounds 4]
        [--seed 0] [--particle-plan FILE]

Both ways run in this process, in alternating rounds (python, solver, then solver, python, ...),
timed in CPU seconds of this process (under load from other processes the steadier measure of
serial work); each figure is the median over the rounds:

* pushes per CPU second of the three scenes of ``arrange-up bench physics`` (one block pushed
  2 in across the open table, chains of 3 and 7 blocks pushed into the right wall), the same
  noisy pushes (``--pushes`` per round, drawn from ``--seed``) under both;
* rollouts per CPU second of evaluation of the compliant 25-particle plan of blocks-7 (read from
  ``--particle-plan``, or planned with 25 particles, seed 0, one worker, under the defaults),
  the same rollouts (seed 0) under both, with their successes.

The settings differ only in ``PhysicsSettings.compliant_in_solver``. Planning time, old code
against new, is measured by ``benchmarks/planning.py --baseline GITREF --validated``; the
accuracy and behaviour of the two by ``benchmarks/push_accuracy.py --versus
compliant_in_solver=false`` (and ``--behaviour N``).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from dataclasses import replace

import numpy as np

from arrange_up.evaluation.rollouts import Rollouts
from arrange_up.io.domains import load
from arrange_up.io.planfile import read_plan
from arrange_up.model.world import Action
from arrange_up.physics.bench import SCENES, _tasks, scene
from arrange_up.physics.settings import DEFAULT_SETTINGS, PhysicsSettings
from arrange_up.physics.simulation import simulate

WAYS: dict[str, PhysicsSettings] = {
    "python": replace(DEFAULT_SETTINGS, compliant_in_solver=False),
    "solver": replace(DEFAULT_SETTINGS, compliant_in_solver=True),
}


def _order(round_: int) -> tuple[str, ...]:
    return ("python", "solver") if round_ % 2 == 0 else ("solver", "python")


def _report(title: str, rates: dict[str, list[float]], unit: str, extra: str = "") -> None:
    python, solver = (statistics.median(rates[w]) for w in ("python", "solver"))
    print(
        f"{title:<34} python {python:>8.1f} {unit}  solver {solver:>8.1f} {unit}  "
        f"solver/python {solver / python:.2f}x{extra}"
    )


def pushes(n: int, rounds: int, seed: int) -> None:
    """Pushes per CPU second of each scene, both ways (module docstring)."""
    rng = np.random.default_rng(seed)
    for name in SCENES:
        problem, state, push = scene(name)
        tasks = _tasks(problem, state, push, n, rng)
        for s in WAYS.values():
            simulate(problem, tasks[0][0], push, tasks[0][1], s)  # warm caches
        rates: dict[str, list[float]] = {w: [] for w in WAYS}
        for r in range(rounds):
            for way in _order(r):
                s = WAYS[way]
                t0 = time.process_time()
                for start, noise in tasks:
                    simulate(problem, start, push, noise, s)
                rates[way].append(n / (time.process_time() - t0))
        _report(f"{name}: {n} pushes x {rounds}", rates, "pushes/s")


def _particle_plan(path: str | None) -> tuple[Action, ...]:
    problem = load("blocks-7")
    if path is not None:
        return tuple(read_plan(path, problem)[0])
    from arrange_up.planning.planner import plan  # noqa: PLC0415 - only without a plan file

    result = plan(problem, semantics="particles", particles=25, seed=0, workers=1)
    if not result.solved:
        sys.exit("no 25-particle plan of blocks-7")
    return tuple(result.actions)


def rollouts(n: int, rounds: int, particle_plan: str | None) -> None:
    """Rollouts per CPU second of the blocks-7 particle plan, both ways (module docstring)."""
    problem = load("blocks-7")
    actions = _particle_plan(particle_plan)
    runners = {w: Rollouts(problem, actions, s) for w, s in WAYS.items()}
    per_round = max(1, n // rounds)
    rates: dict[str, list[float]] = {w: [] for w in WAYS}
    wins = dict.fromkeys(WAYS, 0)
    for r in range(rounds):
        for way in _order(r):
            t0 = time.process_time()
            wins[way] += sum(
                runners[way].run(0, i).success for i in range(r * per_round, (r + 1) * per_round)
            )
            rates[way].append(per_round / (time.process_time() - t0))
    total = per_round * rounds
    extra = f"; successes python {wins['python']}/{total}, solver {wins['solver']}/{total}"
    _report(f"blocks-7 p25 plan: {total} rollouts", rates, "rollouts/s", extra)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pushes", type=int, default=200, help="pushes per scene and round")
    parser.add_argument("--rollouts", type=int, default=200, help="rollouts per way (0: none)")
    parser.add_argument("--rounds", type=int, default=4, help="alternating rounds")
    parser.add_argument("--seed", type=int, default=0, help="seed of the pushes' noise")
    parser.add_argument("--particle-plan", default=None, metavar="FILE", help="plan file")
    args = parser.parse_args()
    if args.pushes:
        pushes(args.pushes, args.rounds, args.seed)
    if args.rollouts:
        rollouts(args.rollouts, args.rounds, args.particle_plan)
    return 0


if __name__ == "__main__":
    sys.exit(main())
