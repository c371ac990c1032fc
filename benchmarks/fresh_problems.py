"""Problems written from the format alone: does each get a reliable plan?

Usage::

    python benchmarks/fresh_problems.py [--particles 20] [--semantics particles] [--validate V]
        [--seed 0] [--timeout 300] [--rollouts 200] [--problems tests/problems/fresh/*.yaml]
        [--output fresh.csv]

For each problem file (default: every file of ``tests/problems/fresh/``, written for issue 13's
kinds: a narrowing squeeze, a detour round a post, a relative pair whose reference must move, an
open-table goal that needs a fixture, an L part into a corner, a 5-block T, a column of four, a
tight row; four that need the planner's own fence (fence-corner; a corner of two fences on a
wall-less table twice, fence-open-corner and fence-middle-corner; and fence-row, a row pressed
against one); four with a fixed post: on the straight line to the goal in the open, on the wall
between a block lying on that wall and its goal, just beyond the goal, and flush with the goal;
and eight written blind by an outsider to the planner, in other units, shapes, walls and
paddles, four with relative goals), plans as ``arrange-up plan FILE --particles N --semantics S
[--validate V] --seed K`` does (``--seed``, default 0; one worker), then evaluates a found plan
with ``--rollouts`` noisy rollouts (seed 0) and prints a row: status, nodes expanded (of the
search whose plan was returned), planning seconds (validation and every search included), plan
length, the planner's validation rollouts, searches and validation successes, successes of the
evaluation, and the planner's reason when no plan was found. Each row is appended to the CSV (if
given) as soon as it is measured.

``tests/problems/fresh-large/`` holds seven problems of 12-16 parts written the same way (issue
32); with the command line's defaults (50 particles, 600 s)::

    python benchmarks/fresh_problems.py --problems tests/problems/fresh-large/*.yaml \
        --particles 50 --timeout 600 --rollouts 200 --output fresh-large.csv
"""

from __future__ import annotations

import argparse
import csv
import time
from pathlib import Path

from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.io.yaml_problem import load_problem
from arrange_up.parallel import SERIAL
from arrange_up.planning.planner import plan

FRESH = Path(__file__).resolve().parents[1] / "tests" / "problems" / "fresh"
FIELDS = [
    "problem",
    "seed",
    "controller",
    "semantics",
    "particles",
    "status",
    "expanded",
    "seconds",
    "plan_length",
    "validate",
    "searches",
    "validated",
    "rollouts",
    "successes",
    "reason",
]


def measure(
    path: Path,
    particles: int,
    timeout: float,
    rollouts: int,
    semantics: str = "particles",
    validate: int | None = None,
    seed: int = 0,
) -> dict[str, object]:
    problem = load_problem(path)
    started = time.perf_counter()
    result = plan(
        problem,
        semantics=semantics,
        particles=particles,
        seed=seed,
        workers=1,
        timeout=timeout,
        validate=validate,
    )
    validation = result.validation
    seconds = time.perf_counter() - started
    row: dict[str, object] = {
        "problem": problem.name,
        "seed": seed,
        "controller": problem.controller.kind.value,
        "semantics": result.semantics,
        "particles": result.particles,
        "status": str(result.status),
        "expanded": result.stats["expanded"],
        "seconds": round(seconds, 1),
        "plan_length": len(result.actions) if result.actions else "",
        "validate": validation.rollouts if validation else 0,
        "searches": len(validation.rounds) if validation else 1,
        "validated": validation.successes if validation else "",
        "rollouts": "",
        "successes": "",
        "reason": result.reason or "",
    }
    if result.solved and rollouts:
        reliability = evaluate_plan(
            problem, result.actions, rollouts=rollouts, seed=0, runner=SERIAL
        )
        row.update(rollouts=reliability.trials, successes=reliability.successes)
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--problems",
        nargs="*",
        type=Path,
        default=None,
        metavar="FILE",
        help="problem files to plan (default: every file of tests/problems/fresh/)",
    )
    parser.add_argument(
        "--particles",
        type=int,
        default=20,
        help="the planner's belief particles (default: %(default)s)",
    )
    parser.add_argument("--semantics", default="particles", help="deterministic, particles, ...")
    parser.add_argument("--timeout", type=float, default=300.0, help="planning seconds")
    parser.add_argument(
        "--rollouts",
        type=int,
        default=200,
        help="noisy rollouts (seed 0) evaluating each plan found; 0 skips the evaluation "
        "(default: %(default)s)",
    )
    parser.add_argument("--seed", type=int, default=0, help="the planner's seed")
    parser.add_argument(
        "--validate",
        type=int,
        default=None,
        help="the planner's validation rollouts (default: its own, twice the particles; 0 off)",
    )
    parser.add_argument(
        "--output",
        type=Path,
        default=None,
        help="CSV file each row is appended to as soon as it is measured (header written if "
        "the file is new; default: none, print only)",
    )
    args = parser.parse_args()
    paths = args.problems or sorted(FRESH.glob("*.yaml"))
    writer = None
    handle = None
    if args.output is not None:
        new = not args.output.exists()
        handle = args.output.open("a", newline="", encoding="utf-8")
        writer = csv.DictWriter(handle, FIELDS)
        if new:
            writer.writeheader()
    try:
        for path in paths:
            row = measure(
                path,
                args.particles,
                args.timeout,
                args.rollouts,
                args.semantics,
                args.validate,
                args.seed,
            )
            print(" ".join(f"{k}={row[k]}" for k in FIELDS if row[k] != ""), flush=True)
            if writer is not None and handle is not None:
                writer.writerow(row)
                handle.flush()
    finally:
        if handle is not None:
            handle.close()


if __name__ == "__main__":
    main()
