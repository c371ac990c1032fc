"""Benchmark of big problem files: wall time and peak memory of ``check`` and ``plan``.

    python benchmarks/big_inputs.py                  # both problems, both commands
    python benchmarks/big_inputs.py --vertices 20000 # only the 20,000-vertex problem
    python benchmarks/big_inputs.py --limit-gb 4     # kill a child above 4 GB (default 4)
    python benchmarks/big_inputs.py --files          # files up to 1 MB of every kind: parse, check
    python benchmarks/big_inputs.py --files --baseline REV   # and check them with the tree at REV
    python benchmarks/big_inputs.py --files --kinds tabs-8500 merges-8500   # only these files

Without ``--files``, generates YAML problems whose one part is a star polygon (alternating
radii, so it is not convex and must be decomposed) with ``--vertices`` vertices (default:
20,000, a file of about half a megabyte, and 1,000, the per-polygon vertex cap of the YAML
format), on the blocks-1 table. Runs, each in a fresh subprocess,

1. ``arrange-up check FILE``;
2. ``arrange-up plan FILE --semantics deterministic --max-nodes 5``;

and prints the file size, exit status, wall time and peak resident memory of each
(``ru_maxrss`` of that child's own resource usage, from ``os.wait4``). A child is stopped after
``--timeout`` seconds and its address space limited to ``--limit-gb`` so that a run that does
not scale fails instead of exhausting the machine. One run each: the figures are one run's.

``--files`` generates one file of each kind that makes checking expensive (see :data:`KINDS`: a
35,000-vertex polygon in 1 MB, the same file cut off mid-list, 8,500 uncertain objects, a
thousand objects stacked at one pose, a hundred objects sharing a 1,000-vertex shape, ten
1,000-vertex polygons, a shape of 2,500 convex parts, a 1,000-vertex part squeezed between two
walls, and the objects written with anchors, merge keys, explicit tags, directives or tabs
throughout, :func:`featured`) and prints, for each, the size, the time to parse it with ruamel's
round-trip loader (the reading before libyaml) and with :func:`arrange_up.io.yaml_tree.read`
(libyaml, ruamel for what it leaves), each the best of three in this process (one run when it
takes over 10 s), and the wall and CPU (user + system) time and peak resident memory of
``arrange-up check FILE`` in a fresh subprocess; with ``--baseline REV``, also ``check`` run
from the tree of the git revision REV (exported to a temporary folder), on the same files
(``+``: stopped after ``--timeout`` seconds). ``--kinds NAME ...`` runs only those files. One
run each: the figures are one run's.
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
from collections.abc import Callable
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
    return _HEADER.format(n=n, points=_star_points(n, 1.0, 0.8))


def many_objects(n: int, uncertain: bool = True) -> str:
    """``n`` unit boxes in a grid two inches apart, each with an initial uncertainty."""
    side = math.ceil(math.sqrt(n))
    noise = ", uncertainty: [0.1, 0.1, 5]" if uncertain else ""
    lines = [f"name: objects-{n}", f"table: {{size: [{2.0 * side}, {2.0 * side}]}}", "objects:"]
    lines += [f"  O{k}: {{kind: part, shape: {{box: [1.0, 1.0]}}}}" for k in range(n)]
    lines.append("initial:")
    for k in range(n):
        x, y = 1.0 + 2.0 * (k % side), 1.0 + 2.0 * (k // side)
        lines.append(f"  O{k}: {{pose: [{x:.6f}, {y:.6f}, 0]{noise}}}")
    lines += ["goal:", "  tolerance: [0.2, 0.2]", "  poses: {O0: [1.0, 1.0, 0]}"]
    return "\n".join(lines) + "\n"


def stacked(n: int) -> str:
    """``n`` unit boxes at one pose: every pair overlaps."""
    lines = [f"name: stacked-{n}", "table: {size: [10.0, 10.0]}", "objects:"]
    lines += [f"  O{k}: {{kind: part, shape: {{box: [1.0, 1.0]}}}}" for k in range(n)]
    lines += ["initial:"] + [f"  O{k}: {{pose: [5.0, 5.0, 0]}}" for k in range(n)]
    lines += ["goal:", "  tolerance: [0.2, 0.2]", "  poses: {O0: [5.0, 5.0, 0]}"]
    return "\n".join(lines) + "\n"


def _star_points(n: int, outer: float, inner: float) -> str:
    points = []
    for k in range(n):
        radius = outer if k % 2 == 0 else inner
        angle = 2.0 * math.pi * k / n
        points.append(f"[{radius * math.cos(angle):.9f}, {radius * math.sin(angle):.9f}]")
    return ", ".join(points)


def shared_shape(objects: int, vertices: int) -> str:
    """``objects`` parts sharing one ``vertices``-vertex star shape, each uncertain."""
    side = math.ceil(math.sqrt(objects))
    lines = [
        f"name: shared-{objects}",
        f"table: {{size: [{2.0 * side}, {2.0 * side}]}}",
        f"shapes:\n  star: {{polygon: [{_star_points(vertices, 0.5, 0.4)}]}}",
        "objects:",
    ]
    lines += [f"  O{k}: {{kind: part, shape: star}}" for k in range(objects)]
    lines.append("initial:")
    for k in range(objects):
        x, y = 1.0 + 2.0 * (k % side), 1.0 + 2.0 * (k // side)
        lines.append(f"  O{k}: {{pose: [{x}, {y}, 0], uncertainty: [0.1, 0.1, 5]}}")
    lines += ["goal:", "  tolerance: [0.2, 0.2]", "  poses: {O0: [1.0, 1.0, 0]}"]
    return "\n".join(lines) + "\n"


def many_polygons(n: int, vertices: int) -> str:
    """``n`` different ``vertices``-vertex star shapes, one uncertain part each (10 x 1,000
    vertices is the format's cap)."""
    shapes = "".join(
        f"  s{k}: {{polygon: [{_star_points(vertices, 0.5, 0.4 - 0.01 * k)}]}}\n" for k in range(n)
    )
    objects = "".join(f"  O{k}: {{kind: part, shape: s{k}}}\n" for k in range(n))
    initial = "".join(
        f"  O{k}: {{pose: [{1.0 + 2 * k}, 1.0, 0], uncertainty: [0.1, 0.1, 5]}}\n" for k in range(n)
    )
    return (
        f"name: polygons-{n}\ntable: {{size: [{2.0 * n + 1}, 3]}}\nshapes:\n{shapes}"
        f"objects:\n{objects}initial:\n{initial}goal:\n  tolerance: [0.2, 0.2]\n"
        "  poses: {O0: [1.0, 1.0, 0]}\n"
    )


def many_parts(n: int) -> str:
    """One part made of ``n`` thin convex rectangles side by side."""
    parts = ", ".join(
        f"[[{0.01 * k:.6f}, 0.0], [{0.01 * k + 0.01:.6f}, 0.0], [{0.01 * k + 0.01:.6f}, 1.0], "
        f"[{0.01 * k:.6f}, 1.0]]"
        for k in range(n)
    )
    return (
        f"name: parts-{n}\ntable: {{size: [100.0, 5.0]}}\nobjects:\n  A:\n    kind: part\n"
        f"    shape:\n      convex_parts: [{parts}]\ngoal:\n  tolerance: [0.2, 0.2]\n"
        "  poses: {A: [50.0, 2.5, 0]}\n"
    )


def squeezed(n: int) -> str:
    """An ``n``-vertex star exactly as wide as the table, uncertain in x: most draws of the
    initial state push it into a wall."""
    return (
        f"name: squeezed-{n}\ntable: {{size: [1.0, 3.0]}}\nobjects:\n"
        f"  A: {{kind: part, shape: {{polygon: [{_star_points(n, 0.5, 0.4)}]}}}}\n"
        "initial:\n  A: {pose: [0.5, 1.5, 0], uncertainty: [0.05, 0, 0]}\n"
        "goal:\n  tolerance: [0.2, 0.2]\n  poses: {A: [0.5, 1.5, 0]}\n"
    )


def featured(n: int, feature: str) -> str:
    """:func:`many_objects` (``n`` uncertain unit boxes) written with one YAML feature on every
    line: ``anchors`` (each pose's x anchored, the shared shape and noise aliased), ``merges``
    (each object and initial state merged from an anchored mapping by ``<<``), ``tags`` (``!!map``
    and ``!!float`` throughout), ``directives`` (``%YAML 1.1`` and a ``%TAG`` handle used on every
    number) or ``tabs`` (a tab after every colon and comma in block and flow context)."""
    side = math.ceil(math.sqrt(n))
    f = "!f!float " if feature == "directives" else "!!float " if feature == "tags" else ""
    m = "!!map " if feature == "tags" else ""
    lines = [f"name: {feature}-{n}", f"table: {{size: [{f}{2.0 * side}, {f}{2.0 * side}]}}"]
    lines.append("objects:")
    for k in range(n):
        if feature == "anchors":
            shape = "&shape {box: [1.0, 1.0]}" if k == 0 else "*shape"
            lines.append(f"  O{k}: {{kind: part, shape: {shape}}}")
        elif feature == "merges":
            body = "&part {kind: part, shape: {box: [1.0, 1.0]}}" if k == 0 else "{<<: *part}"
            lines.append(f"  O{k}: {body}")
        else:
            lines.append(f"  O{k}: {m}{{kind: part, shape: {m}{{box: [{f}1.0, {f}1.0]}}}}")
    lines.append("initial:")
    for k in range(n):
        x, y = 1.0 + 2.0 * (k % side), 1.0 + 2.0 * (k // side)
        if feature == "anchors":
            noise = "&noise [0.1, 0.1, 5]" if k == 0 else "*noise"
            lines.append(f"  O{k}: {{pose: [&x{k} {x:.6f}, {y:.6f}, 0], uncertainty: {noise}}}")
        elif feature == "merges":
            base = "&base {uncertainty: [0.1, 0.1, 5]}" if k == 0 else "*base"
            lines.append(f"  O{k}: {{<<: {base}, pose: [{x:.6f}, {y:.6f}, 0]}}")
        else:
            lines.append(
                f"  O{k}: {m}{{pose: [{f}{x:.6f}, {f}{y:.6f}, {f}0], uncertainty: "
                f"[{f}0.1, {f}0.1, {f}5]}}"
            )
    lines += ["goal:", "  tolerance: [0.2, 0.2]", "  poses: {O0: [1.0, 1.0, 0]}"]
    text = "\n".join(lines) + "\n"
    if feature == "directives":
        text = "%YAML 1.1\n%TAG !f! tag:yaml.org,2002:\n---\n" + text
    if feature == "tabs":
        text = text.replace(": ", ":\t").replace(", ", ",\t")
    return text


#: The files of ``--files``: name -> text (each at most 1 MB).
KINDS = {
    "star-35000": lambda: star_problem(35_000),
    "star-35000-cut-off": lambda: star_problem(35_000)[:1_000_000],
    "objects-8500": lambda: many_objects(8_500),
    "stacked-1000": lambda: stacked(1_000),
    "shared-100x1000": lambda: shared_shape(100, 1_000),
    "polygons-10x1000": lambda: many_polygons(10, 1_000),
    "parts-2500": lambda: many_parts(2_500),
    "squeezed-1000": lambda: squeezed(1_000),
    "anchors-8000": lambda: featured(8_000, "anchors"),
    "merges-8500": lambda: featured(8_500, "merges"),
    "tags-4000": lambda: featured(4_000, "tags"),
    "directives-4000": lambda: featured(4_000, "directives"),
    "tabs-8500": lambda: featured(8_500, "tabs"),
}


def _best_of_three(function: Callable[[], object]) -> float:
    """The least of three runs' seconds (of one run when it takes over 10 s: ruamel's reading of
    many merge keys is quadratic)."""
    times: list[float] = []
    for _ in range(3):
        if times and times[0] > 10.0:
            break
        t0 = time.perf_counter()
        try:
            function()
        except Exception:  # a refused file: the time to refuse it
            pass
        times.append(time.perf_counter() - t0)
    return min(times)


def _export(revision: str, into: Path) -> Path:
    """The tree of ``revision`` of this repository, exported into ``into``."""
    repository = Path(__file__).resolve().parents[1]
    into.mkdir()
    archive = subprocess.run(
        ["git", "-C", str(repository), "archive", revision],
        check=True,
        capture_output=True,
    ).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    return into


def files(timeout: float, limit: int, baseline: str | None, kinds: list[str]) -> None:
    from arrange_up.io import yaml_tree

    with tempfile.TemporaryDirectory() as tmp:
        old_tree = _export(baseline, Path(tmp) / "baseline") if baseline else None
        header = f"{'file':<20} {'kB':>6}  parse s: ruamel libyaml  check: wall s  CPU s  MB"
        print(header + (f"  at {baseline}: wall s  CPU s  MB" if baseline else ""), flush=True)
        for name in kinds:
            make = KINDS[name]
            text = make()
            path = Path(tmp) / f"{name}.yaml"
            path.write_text(text, encoding="utf-8")
            old_parse = _best_of_three(lambda text=text: yaml_tree.read_ruamel(text))
            new_parse = _best_of_three(lambda text=text: yaml_tree.read(text))
            status, seconds, peak, cpu = run_child(["check", str(path)], timeout, limit)
            line = (
                f"{name:<20} {len(text.encode()) / 1000:6.0f}  {old_parse:14.2f} "
                f"{new_parse:7.2f}  {seconds:13.2f}  {cpu:5.2f}  {peak:4.0f}"
            )
            if old_tree is not None:
                old_status, old_seconds, old_peak, old_cpu = run_child(
                    ["check", str(path)], timeout, limit, pythonpath=old_tree
                )
                stopped = "+" if old_status.startswith("stopped") else " "
                line += f"  {old_seconds:19.2f}{stopped} {old_cpu:5.2f}  {old_peak:4.0f}"
            print(line + f"  ({status[:40]})", flush=True)


def _limit(limit_bytes: int) -> None:
    resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))


def run(args: list[str], timeout: float, limit_bytes: int) -> tuple[str, float, float]:
    """Run ``python -m arrange_up ARGS`` in a child; ``(status, seconds, peak MB)``."""
    status, seconds, peak, _ = run_child(args, timeout, limit_bytes)
    return status, seconds, peak


def run_child(
    args: list[str],
    timeout: float,
    limit_bytes: int,
    pythonpath: Path | None = None,
    entry: tuple[str, ...] = ("-m", "arrange_up"),
    output: list[str] | None = None,
) -> tuple[str, float, float, float]:
    """Run ``python -m arrange_up ARGS`` in a child (the package of ``pythonpath`` when given,
    else the one this process imports; ``entry`` replaces ``-m arrange_up``, e.g. by a ``-c``
    program that runs the command); ``(status, wall seconds, peak MB, CPU seconds)``, CPU being
    the child's user + system time. The child's output lines are added to ``output`` if given."""
    env = dict(os.environ)
    if pythonpath is not None:
        env["PYTHONPATH"] = str(pythonpath)
    with tempfile.TemporaryFile("w+") as out:
        t0 = time.perf_counter()
        proc = subprocess.Popen(
            [sys.executable, *entry, *args],
            stdout=out,
            stderr=subprocess.STDOUT,
            text=True,
            env=env,
            cwd=pythonpath,  # python -m puts the working folder first on the path
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
    if output is not None:
        output += tail
    if seconds > timeout:
        status = f"stopped after {timeout:.0f} s"
    else:
        status = f"exit {proc.returncode}" + (f" ({tail[-1][:100]})" if tail else "")
    cpu = usage.ru_utime + usage.ru_stime
    return status, seconds, usage.ru_maxrss / 1024.0, cpu  # ru_maxrss is in kB on Linux


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--vertices",
        type=int,
        nargs="+",
        default=[1000, 20000],
        metavar="N",
        help="vertex counts of the star-polygon problems to generate, one problem each "
        "(without --files; default: 1000 20000)",
    )
    parser.add_argument(
        "--timeout",
        type=float,
        default=120.0,
        help="seconds after which a child command is stopped (default: %(default)s)",
    )
    parser.add_argument(
        "--limit-gb",
        type=float,
        default=4.0,
        help="address-space limit of each child command, in GiB (default: %(default)s)",
    )
    parser.add_argument("--files", action="store_true", help="files up to 1 MB of every kind")
    parser.add_argument("--baseline", help="with --files: also check with the tree at this rev")
    parser.add_argument(
        "--kinds",
        nargs="+",
        choices=sorted(KINDS),
        default=list(KINDS),
        metavar="KIND",
        help="with --files: generate and check only these kinds of file, from: "
        + ", ".join(sorted(KINDS))
        + " (default: all)",
    )
    options = parser.parse_args()
    limit = int(options.limit_gb * 2**30)
    if options.files:
        files(options.timeout, limit, options.baseline, options.kinds)
        return
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
