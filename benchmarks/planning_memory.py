"""Benchmark of planning memory: peak resident memory of ``plan`` with particle beliefs.

    python benchmarks/planning_memory.py                 # plan blocks-4 --particles 25
    python benchmarks/planning_memory.py --blocks-7      # and blocks-7 --particles 25 (minutes)
    python benchmarks/planning_memory.py --holders blocks-4  # in this process, tracemalloc

Runs ``arrange-up plan PROBLEM --particles 25 --seed 0 --workers 1 --output FILE`` in a fresh
subprocess and prints its wall time, peak resident memory (the child's own ``ru_maxrss``, from
``os.wait4``), status, plan length, a digest of the plan's actions and nodes expanded, so that
runs before and after a change can be compared plan for plan. ``--holders PROBLEM`` plans
PROBLEM in this process under ``tracemalloc`` instead and prints the source lines holding the
most memory when the search ends (the belief states, caches and tables still alive). One run
each: the figures are one run's.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import tempfile
import tracemalloc
from pathlib import Path

from big_inputs import run

from arrange_up.io.domains import load
from arrange_up.planning.planner import plan


def _plan_child(problem: str, timeout: float, limit_bytes: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "plan.json"
        args = [
            "plan", problem, "--particles", "25", "--seed", "0", "--workers", "1",
            "--output", str(out),
        ]  # fmt: skip
        status, seconds, peak = run(args, timeout, limit_bytes)
        summary = ""
        if out.exists():
            doc = json.loads(out.read_text())
            digest = hashlib.sha256(json.dumps(doc["actions"], sort_keys=True).encode())
            summary = (
                f"{len(doc['actions'])} actions (sha256 {digest.hexdigest()[:12]}), "
                f"{doc['search']['expanded']} expanded"
            )
        print(f"{problem} --particles 25: {seconds:.1f} s, peak RSS {peak:.0f} MB, {summary}")
        print(f"  {status}")


def _holders(name: str, top: int) -> None:
    problem = load(name)
    snapshots: list[tracemalloc.Snapshot] = []

    def progress(stats: dict) -> None:
        # Called as the search finishes too, while its tables are still alive: the last
        # snapshot is what the search holds at its end (its peak: it frees nothing).
        snapshots[:] = [tracemalloc.take_snapshot()]

    tracemalloc.start(1)
    result = plan(
        problem, semantics="particles", particles=25, seed=0, workers=1, progress=progress
    )
    current, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    print(
        f"{name} --particles 25: {result.status}, {len(result.actions or ())} actions; "
        f"traced {peak / 1e6:.0f} MB at the peak"
    )
    snapshot = snapshots[-1]
    for stat in snapshot.statistics("lineno")[:top]:
        frame = stat.traceback[0]
        print(
            f"  {stat.size / 1e6:7.1f} MB {stat.count:9d} blocks  {frame.filename}:{frame.lineno}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blocks-7", action="store_true", help="also plan blocks-7 (minutes)")
    parser.add_argument("--holders", metavar="PROBLEM", help="tracemalloc on PROBLEM instead")
    parser.add_argument(
        "--timeout",
        type=float,
        default=3600.0,
        help="seconds after which a planning child is stopped (default: %(default)s)",
    )
    parser.add_argument(
        "--limit-gb",
        type=float,
        default=4.0,
        help="address-space limit of each planning child, in GiB (default: %(default)s)",
    )
    options = parser.parse_args()
    if options.holders:
        _holders(options.holders, 15)
        return
    limit = int(options.limit_gb * 2**30)
    _plan_child("blocks-4", options.timeout, limit)
    if options.blocks_7:
        _plan_child("blocks-7", options.timeout, limit)


if __name__ == "__main__":
    main()
