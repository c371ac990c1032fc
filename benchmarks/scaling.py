"""Scaling benchmark: planning cost against the number of parts, on generated problems.

Usage::

    python benchmarks/scaling.py [--parts 2,3,...,20] [--families row,staircase,pack]
        [--semantics deterministic,particles,cbst] [--particles 25] [--seed 0]
        [--rollouts 200] [--timeout 600] [--output scaling.csv] [--png scaling.png]

Every run plans a problem of ``arrange-up generate FAMILY --parts N --seed SEED``
(:func:`arrange_up.io.generate.generate_problem`) with :func:`arrange_up.planning.planner.plan`
(one worker, the library's defaults otherwise: a particle plan is validated as ``arrange-up
plan`` validates it) and measures its plan's reliability on ``--rollouts`` noisy rollouts with
:func:`arrange_up.evaluation.evaluate.evaluate_plan`, the function of ``arrange-up evaluate``.
Each run is its own Python process, so its peak memory is its own; ``--timeout`` limits the
search (the process is killed if it overruns the limit by a minute in all).

A run prints, and appends to ``--output`` as soon as it ends (a row computed is never lost;
run again, the rows already in the file are skipped): the CPU seconds of the ``plan`` call,
its wall seconds, nodes expanded, simulations (``transitions_simulated``), the process's peak
resident memory (MB), the status, the plan's length, and its successes out of the rollouts.
Then, per (family, semantics), the least-squares fit of log CPU seconds against log N over the
solved runs (the exponent k of time ~ N^k), and with ``--png`` a log-log plot of CPU seconds
against N.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

FIELDS = [
    "family",
    "parts",
    "semantics",
    "particles",
    "seed",
    "timeout",
    "status",
    "cpu_s",
    "wall_s",
    "expanded",
    "simulations",
    "peak_mb",
    "plan_length",
    "rollouts",
    "successes",
    "reliability",
]
KEY = ["family", "parts", "semantics", "particles", "seed", "timeout"]
#: seconds a run's process may take beyond its search timeout (loading, validation, rollouts)
#: before it is killed
OVERRUN = 60.0


def _integers(text: str) -> list[int]:
    values = [int(item) for item in text.split(",") if item.strip()]
    if not values or min(values) < 1:
        raise argparse.ArgumentTypeError(f"expected positive integers, got {text!r}")
    return values


def _names(text: str) -> list[str]:
    return [item.strip() for item in text.split(",") if item.strip()]


def _cpu() -> float:
    """CPU seconds (user and system) of this process and of its finished children."""
    return sum(
        usage.ru_utime + usage.ru_stime
        for usage in (
            resource.getrusage(resource.RUSAGE_SELF),
            resource.getrusage(resource.RUSAGE_CHILDREN),
        )
    )


def run_one(
    family: str,
    parts: int,
    semantics: str,
    particles: int,
    seed: int,
    timeout: float,
    rollouts: int,
) -> dict:
    """Plan and evaluate one generated problem in this process: the row's measured fields."""
    from arrange_up.evaluation.evaluate import evaluate_plan
    from arrange_up.io.generate import generate_problem
    from arrange_up.io.yaml_problem import load_problem_text
    from arrange_up.parallel import SERIAL
    from arrange_up.planning.planner import plan

    problem = load_problem_text(generate_problem(family, parts, seed))
    before = _cpu()
    wall = time.perf_counter()
    result = plan(
        problem, semantics=semantics, particles=particles, seed=seed, workers=1, timeout=timeout
    )
    wall = time.perf_counter() - wall
    cpu = _cpu() - before
    row = {
        "status": str(result.status),
        "cpu_s": round(cpu, 2),
        "wall_s": round(wall, 2),
        "expanded": result.stats["expanded"],
        "simulations": result.stats["transitions_simulated"],
        "plan_length": len(result.actions) if result.solved else "",
        "rollouts": "",
        "successes": "",
        "reliability": "",
    }
    if result.solved:
        reliability = evaluate_plan(
            problem, result.actions, rollouts=rollouts, seed=seed, runner=SERIAL
        )
        row.update(
            rollouts=reliability.trials,
            successes=reliability.successes,
            reliability=round(reliability.successes / reliability.trials, 4),
        )
    # ru_maxrss is in KiB on Linux
    row["peak_mb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)
    return row


def _measure(args: argparse.Namespace, key: dict) -> dict:
    """One run in its own process (killed after its timeout and :data:`OVERRUN`)."""
    command = [
        sys.executable,
        str(Path(__file__).resolve()),
        "--one",
        json.dumps({**key, "rollouts": args.rollouts}),
    ]
    try:
        done = subprocess.run(
            command, capture_output=True, text=True, cwd=ROOT, timeout=key["timeout"] + OVERRUN
        )
    except subprocess.TimeoutExpired:
        return {"status": "killed"}
    if done.returncode != 0:
        sys.stderr.write(done.stderr[-2000:])
        return {"status": f"crashed ({done.returncode})"}
    return json.loads(done.stdout.strip().splitlines()[-1])


def _done(path: Path) -> tuple[list[dict], set[tuple[str, ...]]]:
    if not path.exists():
        return [], set()
    with path.open(newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    return rows, {tuple(str(row[k]) for k in KEY) for row in rows}


def fit_exponents(rows: list[dict]) -> dict[tuple[str, str], tuple[float, float, int]]:
    """Per (family, semantics), the least-squares fit of log(cpu_s) = log(c) + k log(N) over
    the solved runs of at least two sizes: ``(k, c, runs)``."""
    import numpy as np

    groups: dict[tuple[str, str], list[tuple[float, float]]] = {}
    for row in rows:
        if row["status"] == "solved" and float(row["cpu_s"]) > 0:
            groups.setdefault((row["family"], row["semantics"]), []).append(
                (float(row["parts"]), float(row["cpu_s"]))
            )
    fits = {}
    for key, points in sorted(groups.items()):
        if len({n for n, _ in points}) < 2:
            continue
        n, t = (np.log(np.array(v)) for v in zip(*points, strict=True))
        slope, intercept = np.polyfit(n, t, 1)
        fits[key] = (float(slope), float(math.exp(intercept)), len(points))
    return fits


def plot(rows: list[dict], fits: dict, path: Path) -> None:
    """CPU seconds against N, log-log, a line per (family, semantics) with its exponent."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    figure, axes = plt.subplots(figsize=(7, 4.5), dpi=100)
    groups: dict[tuple[str, str], list[tuple[int, float]]] = {}
    for row in rows:
        if row["status"] == "solved" and float(row["cpu_s"]) > 0:
            groups.setdefault((row["family"], row["semantics"]), []).append(
                (int(row["parts"]), float(row["cpu_s"]))
            )
    for (family, semantics), points in sorted(groups.items()):
        points.sort()
        fit = fits.get((family, semantics))
        label = f"{family}, {semantics}" + (f" (N^{fit[0]:.2f})" if fit else "")
        axes.loglog(*zip(*points, strict=True), marker="o", label=label)
    sizes = sorted({n for points in groups.values() for n, _ in points})
    axes.set_xticks(sizes, [str(n) for n in sizes])
    axes.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    axes.set_xlabel("parts N")
    axes.set_ylabel("CPU seconds (plan, one worker)")
    axes.set_title("Planning time against the number of parts (generated problems)")
    axes.grid(True, which="both", alpha=0.3)
    if groups:
        axes.legend(fontsize=8)
    figure.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path)
    plt.close(figure)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--parts",
        type=_integers,
        default=list(range(2, 21)),
        help="comma-separated part counts N (default 2..20)",
    )
    parser.add_argument(
        "--families",
        type=_names,
        default=["row", "staircase", "pack"],
        help="comma-separated generated families (default row,staircase,pack)",
    )
    parser.add_argument(
        "--semantics",
        type=_names,
        default=["deterministic", "particles", "cbst"],
        help="comma-separated semantics (default deterministic,particles,cbst)",
    )
    parser.add_argument(
        "--particles",
        type=int,
        default=25,
        help="particles per belief for the particles semantics (default 25)",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of the generated problems, the search and the rollouts",
    )
    parser.add_argument(
        "--rollouts",
        type=int,
        default=200,
        help="noisy rollouts measuring each plan's reliability (default 200)",
    )
    parser.add_argument(
        "--timeout", type=float, default=600.0, help="seconds each search may take (default 600)"
    )
    parser.add_argument(
        "--output",
        type=Path,
        default=Path("scaling.csv"),
        help="CSV the rows are appended to; rows already in it are skipped",
    )
    parser.add_argument(
        "--png",
        type=Path,
        default=None,
        help="write the log-log plot of CPU seconds against N here",
    )
    parser.add_argument("--one", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one is not None:  # a run's own process
        key = json.loads(args.one)
        print(json.dumps(run_one(**key)))
        return

    from arrange_up.io.generate import FAMILIES

    unknown = [f for f in args.families if f not in FAMILIES]
    if unknown:
        parser.error(f"--families: unknown {', '.join(unknown)}; known: {', '.join(FAMILIES)}")
    rows, done = _done(args.output)
    new_file = not args.output.exists()
    print("  ".join(FIELDS), flush=True)
    with args.output.open("a", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, FIELDS)
        if new_file:
            writer.writeheader()
            handle.flush()
        for family in args.families:
            for semantics in args.semantics:
                for parts in args.parts:
                    key = {
                        "family": family,
                        "parts": parts,
                        "semantics": semantics,
                        "particles": 1 if semantics == "deterministic" else args.particles,
                        "seed": args.seed,
                        "timeout": args.timeout,
                    }
                    if tuple(str(key[k]) for k in KEY) in done:
                        continue
                    row = {**key, **_measure(args, key)}
                    row = {field: row.get(field, "") for field in FIELDS}
                    writer.writerow(row)
                    handle.flush()
                    rows.append({k: str(v) for k, v in row.items()})
                    print("  ".join(str(row[f]) for f in FIELDS), flush=True)
    fits = fit_exponents(rows)
    print("\nfit of CPU seconds ~ c * N^k over solved runs:")
    for (family, semantics), (k, c, runs) in fits.items():
        print(f"  {family:<10} {semantics:<13} k = {k:.2f}  c = {c:.3g} s  ({runs} runs)")
    if args.png is not None:
        plot(rows, fits, args.png)
        print(f"wrote {args.png}")


if __name__ == "__main__":
    main()
