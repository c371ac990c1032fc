"""Planning benchmark: time, nodes, simulations and peak memory, old code against new, paired.

Usage::

    python benchmarks/planning.py [--cases blocks-7:25,blocks-4:50] [--configs local:1,local:2]
        [--baseline GITREF] [--repeats 3] [--seed 0] [--output planning-bench.csv]

A case is ``PROBLEM:PARTICLES`` (0 particles: the deterministic planner) or ``PROBLEM:cbst``
(CBST's interval beliefs); ``PROBLEM`` is a shipped name or a problem file, optionally followed
by ``@CONTROLLER`` to plan it under that controller (``blocks-9@servo:cbst``: blocks-9 under
the servo, the controller whose CBST model plans it). A config is
``local:WORKERS`` or ``dask:WORKERS`` (a LocalCluster of that many processes). Every run is
its own Python process (so peak memory is that run's and no pool or cache carries over), with
``PYTHONPATH`` at this checkout, or, for ``--baseline GITREF``, at a copy of that commit made
with ``git archive``; the baseline runs each config as its code understands it (``--workers``
only: its ``plan`` knows no backend, so dask configs are not run for it). Old and new runs of a
case alternate, repeat by repeat and in alternating order, so a pair shares the machine's load.

Every run times the search alone: where the code validates particle plans on fresh rollouts
(and searches again when they fail, ``plan(validate=...)``), the benchmark turns that off
(``validate=0``), since the code before it had no such step and it is not search.

Each run prints one row: wall seconds of the ``plan`` call (for dask, after the LocalCluster
was started, which ``startup_s`` gives) and the CPU seconds of this process in it (``cpu_s``:
under load from other processes the steadier measure of a serial run), nodes expanded, transitions
evaluated, simulations (``transitions_simulated``), simulations per second, the process's peak
resident memory (MB; worker processes not included) and the plan length; and whether its plan
equals the first run's of the case (``same``). The summary gives, per case and config, the
median wall and CPU seconds and the ratios old / new of the medians (paired in the sense
above). Rows are
appended to ``--output`` as they are measured.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import inspect
import json
import os
import resource
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

FIELDS = [
    "code",
    "problem",
    "particles",
    "config",
    "repeat",
    "status",
    "seconds",
    "cpu_s",
    "startup_s",
    "expanded",
    "evaluated",
    "simulations",
    "simulations_per_s",
    "peak_mb",
    "plan_length",
    "plan_hash",
    "same",
]


def parse_case(case: str) -> tuple[str, str]:
    """``(problem, particles)`` of a case (see the module doc); ``particles`` is a count or
    ``cbst``."""
    problem, _, particles = case.rpartition(":")
    if not problem or not (particles == "cbst" or particles.isdigit()):
        raise SystemExit(f"--cases: {case!r} is not PROBLEM:PARTICLES or PROBLEM:cbst")
    return problem, particles


def child(
    problem_name: str, particles: str, seed: int, config: str, validated: bool = False
) -> None:
    """One planning run in this process (the code on ``PYTHONPATH``); prints a JSON row. With
    ``validated``, the code's own validation of particle plans is left on."""
    import arrange_up
    from arrange_up.model.problem import driven_by
    from arrange_up.planning.planner import plan

    backend, workers = config.split(":")
    options: dict = {"workers": int(workers)}
    if backend != "local":
        options["backend"] = backend
    if particles == "cbst":
        options.update(semantics="cbst")
    elif int(particles) == 0:
        options.update(semantics="deterministic", particles=1, workers=1)
    else:
        options.update(particles=int(particles))
    name, _, controller = problem_name.partition("@")
    problem = arrange_up.load(name)
    if controller:
        problem = driven_by(problem, controller)
    startup = 0.0
    if backend != "local":
        # the cluster is started (and cached) first: "seconds" is the planning on it, as
        # with --scheduler, and "startup_s" what starting a LocalCluster adds to a command
        from arrange_up.parallel import get_runner

        begin = time.perf_counter()
        get_runner(backend, int(workers))
        startup = time.perf_counter() - begin
    if "validate" in inspect.signature(plan).parameters and not validated:
        options["validate"] = 0  # the search alone (module docstring)
    start, cpu = time.perf_counter(), time.process_time()
    result = plan(problem, seed=seed, **options)
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    stats = result.stats
    actions = repr(result.actions).encode()
    print(
        json.dumps(
            {
                "status": str(result.status),
                "seconds": round(seconds, 3),
                "cpu_s": round(cpu, 3),
                "startup_s": round(startup, 3),
                "expanded": stats["expanded"],
                "evaluated": stats["evaluated"],
                "simulations": stats["transitions_simulated"],
                "simulations_per_s": round(stats["transitions_simulated"] / seconds, 1),
                "peak_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
                "plan_length": len(result.actions) if result.actions else 0,
                "plan_hash": hashlib.sha256(actions).hexdigest()[:12],
            }
        ),
        flush=True,
    )


def checkout(ref: str, into: Path) -> Path:
    """The tree of commit ``ref`` extracted under ``into`` (``git archive``)."""
    archive = into / "tree.tar"
    with archive.open("wb") as handle:
        subprocess.run(["git", "-C", str(ROOT), "archive", ref], stdout=handle, check=True)
    tree = into / "tree"
    tree.mkdir()
    with tarfile.open(archive) as tar:
        tar.extractall(tree, filter="data")
    return tree


def run(
    code_root: Path, case: tuple[str, str], config: str, seed: int, validated: bool = False
) -> dict:
    env = {**os.environ, "PYTHONPATH": str(code_root)}
    command = [sys.executable, str(Path(__file__).resolve()), "--child"]
    command += [f"{case[0]}:{case[1]}", config, str(seed)] + (["validated"] if validated else [])
    done = subprocess.run(command, env=env, capture_output=True, text=True, cwd=code_root)
    if done.returncode != 0:
        raise SystemExit(f"run {case} {config} at {code_root} failed:\n{done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\nEvery run times")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--cases",
        default="blocks-7:25,blocks-4:50",
        help="comma-separated PROBLEM[@CONTROLLER]:PARTICLES or PROBLEM[@CONTROLLER]:cbst "
        "(default: %(default)s)",
    )
    parser.add_argument(
        "--configs",
        default="local:1,local:2",
        help="comma-separated local:WORKERS or dask:WORKERS (default: %(default)s)",
    )
    parser.add_argument(
        "--baseline",
        default=None,
        metavar="GITREF",
        help="also run the code of this commit, alternating with this checkout's (old / new)",
    )
    parser.add_argument(
        "--repeats", type=int, default=3, help="runs per case, config and code (default: 3)"
    )
    parser.add_argument("--seed", type=int, default=0, help="the planner's seed (default: 0)")
    parser.add_argument(
        "--output",
        type=Path,
        default=Path("planning-bench.csv"),
        help="CSV the rows are appended to as they are measured (default: %(default)s)",
    )
    parser.add_argument(
        "--validated",
        action="store_true",
        help="leave the code's validation of particle plans on (default: the search alone)",
    )
    parser.add_argument("--child", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        name, particles = parse_case(args.child[0])
        child(name, particles, int(args.child[2]), args.child[1], args.child[3:] == ["validated"])
        return

    cases = [parse_case(c) for c in args.cases.split(",")]
    configs = args.configs.split(",")
    with tempfile.TemporaryDirectory() as scratch:
        codes = {"new": ROOT}
        if args.baseline:
            codes = {"old": checkout(args.baseline, Path(scratch)), "new": ROOT}
        new_file = not args.output.exists()
        times: dict[tuple, list[float]] = {}
        cpus: dict[tuple, list[float]] = {}
        with args.output.open("a", newline="") as handle:
            writer = csv.DictWriter(handle, FIELDS)
            if new_file:
                writer.writeheader()
            print(" ".join(f"{f:>10}" for f in FIELDS if f != "plan_hash"), flush=True)
            for case in cases:
                first_hash = None
                for repeat in range(args.repeats):
                    for config in configs:
                        order = list(codes) if repeat % 2 == 0 else list(reversed(codes))
                        for code in order:
                            if code == "old" and not config.startswith("local:"):
                                continue
                            row = run(codes[code], case, config, args.seed, args.validated)
                            first_hash = first_hash or row["plan_hash"]
                            row.update(
                                code=code,
                                problem=case[0],
                                particles=case[1],
                                config=config,
                                repeat=repeat,
                                same=row["plan_hash"] == first_hash,
                            )
                            times.setdefault((case, config, code), []).append(row["seconds"])
                            cpus.setdefault((case, config, code), []).append(row["cpu_s"])
                            writer.writerow(row)
                            handle.flush()
                            shown = (f for f in FIELDS if f != "plan_hash")
                            print(" ".join(f"{str(row[f]):>10}" for f in shown), flush=True)
    print("\nmedian seconds (old / new: the ratio of the medians)")
    for case in cases:
        for config in configs:
            new = times.get((case, config, "new"))
            old = times.get((case, config, "old"))
            line = f"{case[0]}:{case[1]} {config}: new {statistics.median(new):.2f} s"
            new_cpu = statistics.median(cpus[(case, config, "new")])
            line += f" (CPU {new_cpu:.2f} s)"
            if old:
                old_median = statistics.median(old)
                old_cpu = statistics.median(cpus[(case, config, "old")])
                line += (
                    f", old {old_median:.2f} s (CPU {old_cpu:.2f} s), old/new "
                    f"{old_median / statistics.median(new):.2f}x (CPU {old_cpu / new_cpu:.2f}x)"
                )
            print(line)
    if args.baseline:
        for case in cases:
            base = times.get((case, "local:1", "old")) or times.get((case, configs[0], "old"))
            for config in configs:
                new = times.get((case, config, "new"))
                if base and new:
                    ratio = statistics.median(base) / statistics.median(new)
                    print(f"{case[0]}:{case[1]} old local:1 / new {config}: {ratio:.2f}x")


if __name__ == "__main__":
    main()
