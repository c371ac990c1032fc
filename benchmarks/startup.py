"""Start-up cost of ``arrange-up --help``, as a ratio to ``python -c pass``, in CPU time.

    python benchmarks/startup.py                          # the checkout this file is in
    python benchmarks/startup.py --root OLD --root NEW    # checkouts side by side
    python benchmarks/startup.py --repeat 20 --json

Each round runs, for every checkout in turn (alternating, so that a busy machine slows them
alike), ``python -c pass`` and then the ``arrange-up`` console script's entry point (read from
that checkout's ``pyproject.toml``) with ``--help``, in a fresh interpreter whose ``PYTHONPATH``
starts with the checkout, so that its ``arrange_up`` is the one imported. A run's cost is the
CPU time (user + system) the child used, from :func:`resource.getrusage` of the children;
wall-clock time would count the other processes of a shared machine. Reported per checkout:
the median CPU seconds of each command over the rounds and the median of the per-round ratios
``arrange-up --help / python -c pass``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tomllib
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent
SCRIPT = "arrange-up"


def entry_point(root: Path) -> tuple[str, str]:
    """The module and function ``arrange-up`` runs in the checkout at ``root``."""
    project = tomllib.loads((root / "pyproject.toml").read_text())["project"]
    module, _, function = project["scripts"][SCRIPT].partition(":")
    return module, function


def cpu_seconds(command: list[str], env: dict[str, str]) -> float:
    """The user + system CPU seconds of running ``command`` to its end (output discarded)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(command, env=env, check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def measure(roots: list[Path], repeat: int) -> dict[str, dict[str, float]]:
    """Per checkout: median CPU seconds of ``python -c pass`` and of ``arrange-up --help``,
    and the median of their per-round ratio, over ``repeat`` alternating rounds."""
    runs: dict[Path, dict[str, list[float]]] = {r: {"pass": [], "help": []} for r in roots}
    commands = {}
    for root in roots:
        module, function = entry_point(root)
        path = [str(root), *filter(None, [os.environ.get("PYTHONPATH")])]
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(path)}
        code = f"import sys; from {module} import {function}; sys.exit({function}())"
        commands[root] = (env, [sys.executable, "-c", code, "--help"])
    for root in roots:  # one unmeasured round: files into the page cache, bytecode compiled
        env, command = commands[root]
        cpu_seconds([sys.executable, "-c", "pass"], env)
        cpu_seconds(command, env)
    for _ in range(repeat):
        for root in roots:
            env, command = commands[root]
            runs[root]["pass"].append(cpu_seconds([sys.executable, "-c", "pass"], env))
            runs[root]["help"].append(cpu_seconds(command, env))
    figures = {}
    for root, run in runs.items():
        ratios = [h / p for h, p in zip(run["help"], run["pass"], strict=True) if p > 0]
        figures[str(root)] = {
            "python -c pass": statistics.median(run["pass"]),
            "arrange-up --help": statistics.median(run["help"]),
            "ratio": statistics.median(ratios),
        }
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--root",
        type=Path,
        action="append",
        help="a checkout to measure (the folder holding arrange_up/); repeat to compare; "
        "default: this one",
    )
    parser.add_argument("--repeat", type=int, default=10, help="rounds (default 10)")
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args()
    roots = [r.resolve() for r in args.root or [HERE]]
    figures = measure(roots, args.repeat)
    if args.json:
        print(json.dumps(figures, indent=2))
        return
    for root, values in figures.items():
        print(
            f"{root}: python -c pass {values['python -c pass'] * 1000:.0f} ms, "
            f"arrange-up --help {values['arrange-up --help'] * 1000:.0f} ms CPU, "
            f"ratio {values['ratio']:.2f} (medians of {args.repeat} rounds)"
        )


if __name__ == "__main__":
    main()
