"""The ``arrange-up`` command: a thin shell over the library.

Each command parses its arguments, calls one library function, renders the result and sets the
exit status. Heavy libraries (pymunk, matplotlib, unified-planning, rich) are imported inside
the commands, so ``arrange-up --help`` stays fast.

Exit status: 0 success; 1 the job ran but its answer is negative (e.g. a problem file has
errors under ``check``); 2 bad input (unreadable or invalid problem, unknown domain, bad option).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import NoReturn

import click

from arrange_up import __version__

EXIT_OK = 0
EXIT_NEGATIVE = 1
EXIT_BAD_INPUT = 2

PROBLEM_HELP = "A problem file (.yaml) or the name of a shipped domain (see `arrange-up domains`)."


def _fail(message: str, code: int = EXIT_BAD_INPUT) -> NoReturn:
    click.echo(f"arrange-up: {message}", err=True)
    sys.exit(code)


def _load(problem: str):  # -> ArrangementProblem
    """Resolve and load a problem, turning every refusal into a clean message and exit 2."""
    from arrange_up.domains import UnknownDomainError, load
    from arrange_up.errors import ProblemFormatError

    try:
        return load(problem)
    except UnknownDomainError as error:
        _fail(str(error))
    except ProblemFormatError as error:
        click.echo(str(error), err=True)
        n = sum(1 for d in error.diagnostics if d.severity == "error")
        _fail(f"{n} error{'s' if n != 1 else ''}; nothing was done")


@click.group(context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100})
@click.version_option(__version__, prog_name="arrange-up")
def main() -> None:
    """Find conformant plans for robot tabletop manipulation.

    arrange-up plans open-loop sequences of place, push and pick actions that build a goal
    arrangement of parts reliably despite uncertain initial poses, noisy actions and unknown
    friction and density (A. Anders, "Reliably arranging objects", MIT).

    \b
    Start here:
      arrange-up domains                      list the shipped problems
      arrange-up show blocks-4 -o b4.png      draw a problem with its belief shadows and goal
      arrange-up check my-problem.yaml        validate problem files
      arrange-up bench physics                measure simulated pushes per second

    PROBLEM arguments take a path to a .yaml file or a shipped domain's name.
    """


@main.command()
@click.argument("files", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option("--quiet", "-q", is_flag=True, help="Print only errors and warnings.")
def check(files: tuple[str, ...], quiet: bool) -> None:
    """Validate problem FILES against the problem format.

    Every problem in every file is reported at once, as FILE:LINE:COL: severity: key.path:
    message. Exits 1 if any file has errors, 0 otherwise (warnings do not fail).
    """
    from arrange_up.loader import check_problem

    failed = 0
    names: dict[tuple[Path, str], str] = {}
    for file in files:
        problem, diagnostics = check_problem(file)
        for diagnostic in diagnostics:
            click.echo(str(diagnostic), err=True)
        if problem is None:
            failed += 1
            continue
        key = (Path(file).resolve().parent, problem.name)
        if key in names:
            click.echo(
                f"{file}: error: name: problem name {problem.name!r} is already used by "
                f"{names[key]} in the same folder; names must be unique within a folder",
                err=True,
            )
            failed += 1
            continue
        names[key] = file
        if not quiet:
            click.echo(
                f"{file}: ok: {problem.name} ({len(problem.parts)} parts, "
                f"{'relative' if problem.goal.is_relative else 'absolute'} goal)"
            )
    if failed:
        _fail(f"{failed} of {len(files)} file(s) failed", EXIT_NEGATIVE)


@main.command()
def domains() -> None:
    """List the shipped problems, usable by name wherever a PROBLEM is asked for."""
    from arrange_up.domains import list_domains

    rows = list_domains()
    width = max((len(info.name) for info in rows), default=4)
    for info in rows:
        click.echo(f"{info.name:<{width}}  {info.parts:>2} parts  {info.goal_kind:<8}  "
                   f"{info.summary}")


@main.command()
@click.argument("problem")
@click.option("--output", "-o", type=click.Path(dir_okay=False, writable=True), required=True,
              help="Where to write the picture (.png).")
@click.option("--dpi", type=click.IntRange(30, 600), default=150, show_default=True)
def show(problem: str, output: str, dpi: int) -> None:
    """Draw PROBLEM: table, walls, obstacles, parts with their belief shadows, and the goal.

    PROBLEM is a .yaml file or a shipped domain's name.
    """
    from arrange_up.render import draw_problem

    loaded = _load(problem)
    path = draw_problem(loaded, Path(output), dpi=dpi)
    click.echo(f"wrote {path}")


@main.group()
def bench() -> None:
    """Measure the speed of the building blocks (figures printed, nothing written)."""


@bench.command("physics")
@click.option("--pushes", type=click.IntRange(10, 1_000_000), default=300, show_default=True,
              help="Pushes simulated per scene and worker count.")
@click.option("--workers", type=str, default="1,2", show_default=True,
              help="Comma-separated process counts to measure.")
@click.option("--seed", type=int, default=0, show_default=True)
def bench_physics_command(pushes: int, workers: str, seed: int) -> None:
    """Push rollouts per second: 1 block, a 3-block and a 7-block chain against a wall.

    Each push is a full place-to-rest simulation in a fresh space at dt 1/240 s.
    """
    try:
        counts = tuple(int(w) for w in workers.split(","))
    except ValueError:
        _fail(f"--workers: expected comma-separated integers, got {workers!r}")
    if any(c < 1 for c in counts):
        _fail("--workers: counts must be at least 1")
    from arrange_up.bench import bench_physics

    rows = bench_physics(n_pushes=pushes, workers=counts, seed=seed,
                         progress=lambda msg: click.echo(msg, err=True))
    click.echo(f"{'scene':<16} {'workers':>7} {'pushes':>7} {'seconds':>8} {'pushes/s':>9} "
               f"{'ms/push':>8} {'not at rest':>11}")
    for row in rows:
        click.echo(f"{row['scene']:<16} {row['workers']:>7} {row['pushes']:>7} "
                   f"{row['seconds']:>8.2f} {row['pushes_per_second']:>9.0f} "
                   f"{row['ms_per_push']:>8.2f} {row['not_at_rest']:>11}")


if __name__ == "__main__":  # pragma: no cover
    main()
