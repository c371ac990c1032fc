"""Benchmark of big problem files: wall time and peak memory of ``check`` and ``plan``.

    python benchmarks/big_inputs.py                  # both problems, both commands
    python benchmarks/big_inputs.py --vertices 20000 # only the 20,000-vertex problem
    python benchmarks/big_inputs.py --limit-gb 4     # kill a child above 4 GB (default 4)

Generates YAML problems whose one part is a star polygon (alternating radii, so it is not
convex and must be decomposed) with ``--vertices`` vertices (default: 20,000, a file of about
half a megabyte, and 1,000, the per-polygon vertex cap of the YAML format), on the blocks-1
table. Runs, each in a fresh subprocess,

1. ``arrange-up check FILE``;
2. ``arrange-up plan FILE --semantics deterministic --max-nodes 5``;

and prints the file size, exit status, wall time and peak resident memory of each
(``ru_maxrss`` of that child's own resource usage, from ``os.wait4``). A child is stopped after
``--timeout`` seconds and its address space limited to ``--limit-gb`` so that a run that does
not scale fails instead of exhausting the machine. One run each: the figures are one run's.
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_HEADER = """format: arrange-up/1
name: big-{n}
description: One star-shaped part of {n} vertices (a benchmark of big inputs).
units: {{length: in, angle: deg}}
table:
  size: [10.0, 5.0]
  walls: [left, right, bottom, top]
objects:
  paddle: {{kind: manipulator, shape: {{box: [2.5, 0.15]}}}}
  A:
    kind: part
    shape:
      polygon: [{points}]
initial: {{}}
goal:
  tolerance: [0.2, 0.2, 15]
  poses:
    A: [5.0, 2.5, 0]
uncertainty:
  place: [0.2, 0.2, 15]
  push: [0.05, 0.05, 3]
  friction: [0.25, 0.55]
  part_density: [0.1, 0.15]
  manipulator_density: [0.35, 0.45]
"""


def star_problem(n: int) -> str:
    """A YAML problem whose part A is an ``n``-vertex star (radii 1.0 and 0.8 in alternately;
    ``n`` even), full double precision so that the file is as big as a real export's."""
    points = []
    for k in range(n):
        radius = 1.0 if k % 2 == 0 else 0.8
        angle = 2.0 * math.pi * k / n
        points.append(f"[{radius * math.cos(angle):.9f}, {radius * math.sin(angle):.9f}]")
    return _HEADER.format(n=n, points=", ".join(points))


def _limit(limit_bytes: int) -> None:
    resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))


def run(args: list[str], timeout: float, limit_bytes: int) -> tuple[str, float, float]:
    """Run ``python -m arrange_up ARGS`` in a child; ``(status, seconds, peak MB)``."""
    with tempfile.TemporaryFile("w+") as out:
        t0 = time.perf_counter()
        proc = subprocess.Popen(
            [sys.executable, "-m", "arrange_up", *args],
            stdout=out,
            stderr=subprocess.STDOUT,
            text=True,
            preexec_fn=lambda: _limit(limit_bytes),
        )
        # wait4 gives this child's own rusage (RUSAGE_CHILDREN would be the largest so far).
        while True:
            pid, code, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if time.perf_counter() - t0 > timeout:
                proc.kill()
                pid, code, usage = os.wait4(proc.pid, 0)
                break
            time.sleep(0.02)
        seconds = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(code)  # already reaped above
        out.seek(0)
        tail = out.read().strip().splitlines()
    if seconds > timeout:
        status = f"stopped after {timeout:.0f} s"
    else:
        status = f"exit {proc.returncode}" + (f" ({tail[-1][:100]})" if tail else "")
    return status, seconds, usage.ru_maxrss / 1024.0  # ru_maxrss is in kB on Linux


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vertices", type=int, nargs="+", default=[1000, 20000])
    parser.add_argument("--timeout", type=float, default=120.0)
    parser.add_argument("--limit-gb", type=float, default=4.0)
    options = parser.parse_args()
    limit = int(options.limit_gb * 2**30)
    with tempfile.TemporaryDirectory() as tmp:
        for n in sorted(options.vertices):
            path = Path(tmp) / f"big-{n}.yaml"
            path.write_text(star_problem(n))
            size_kb = os.path.getsize(path) / 1000.0
            print(f"{n} vertices, {size_kb:.0f} kB")
            for command in (
                ["check", str(path)],
                ["plan", str(path), "--semantics", "deterministic", "--max-nodes", "5"],
            ):
                status, seconds, peak = run(command, options.timeout, limit)
                print(f"  {command[0]:<6} {seconds:7.2f} s  peak RSS {peak:7.0f} MB  {status}")


if __name__ == "__main__":
    main()
