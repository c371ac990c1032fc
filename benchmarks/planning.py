"""Planning benchmark: deterministic and particle planners on the block-world problems.

Usage::

    python benchmarks/planning.py [--problems blocks-2,blocks-3,blocks-4,blocks-7]
        [--particles 50] [--workers 2] [--output planning-bench.csv]

For each problem and semantics it prints and writes one row: status, wall time, nodes
expanded, successors generated, transitions evaluated, physics simulations run and plan length.
Each row is appended to the CSV as soon as it is measured, so an interrupted run keeps its rows.
"""

from __future__ import annotations

import argparse
import csv
import time
from pathlib import Path

from arrange_up.io.domains import load
from arrange_up.planning.planner import plan

FIELDS = [
    "problem",
    "semantics",
    "particles",
    "seed",
    "weight",
    "status",
    "seconds",
    "expanded",
    "generated",
    "evaluated",
    "transitions_simulated",
    "plan_length",
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--problems", default="blocks-2,blocks-3,blocks-4,blocks-7")
    parser.add_argument("--particles", type=int, default=50)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--weight", type=float, default=2.0)
    parser.add_argument("--output", type=Path, default=Path("planning-bench.csv"))
    args = parser.parse_args()

    new = not args.output.exists()
    with args.output.open("a", newline="") as handle:
        writer = csv.DictWriter(handle, FIELDS)
        if new:
            writer.writeheader()
        print(" ".join(f"{f:>12}" for f in FIELDS))
        for name in args.problems.split(","):
            problem = load(name)
            for semantics, particles in (("deterministic", 1), ("particles", args.particles)):
                start = time.perf_counter()
                result = plan(
                    problem,
                    semantics=semantics,
                    particles=particles,
                    seed=args.seed,
                    weight=args.weight,
                    workers=args.workers,
                )
                row = {
                    "problem": name,
                    "semantics": semantics,
                    "particles": result.particles,
                    "seed": args.seed,
                    "weight": args.weight,
                    "status": result.status,
                    "seconds": round(time.perf_counter() - start, 2),
                    "expanded": result.stats["expanded"],
                    "generated": result.stats["generated"],
                    "evaluated": result.stats["evaluated"],
                    "transitions_simulated": result.stats["transitions_simulated"],
                    "plan_length": len(result.actions) if result.actions else "",
                }
                writer.writerow(row)
                handle.flush()
                print(" ".join(f"{str(row[f]):>12}" for f in FIELDS), flush=True)


if __name__ == "__main__":
    main()
