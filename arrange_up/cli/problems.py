"""The commands about problem files: ``domains``, ``check`` and ``export``."""

from __future__ import annotations

from pathlib import Path

import click

from arrange_up.cli.shared import EXIT_NEGATIVE, fail, load_problem
from arrange_up.io.domains import list_domains
from arrange_up.io.pddl import PddlExportError, load_pddl_problem, write_pddl_problem
from arrange_up.io.planfile import write_text_atomic
from arrange_up.io.yaml_problem import check_problem
from arrange_up.model.errors import Diagnostic, ProblemFormatError
from arrange_up.model.problem import ArrangementProblem


@click.command()
def domains() -> None:
    """List the shipped problems, usable by name wherever a PROBLEM is asked for."""
    rows = list_domains()
    width = max((len(info.name) for info in rows), default=4)
    for info in rows:
        click.echo(
            f"{info.name:<{width}}  {info.parts:>2} parts  {info.goal_kind:<8}  {info.summary}"
        )


def _check_file(file: str) -> tuple[ArrangementProblem | None, list[Diagnostic]]:
    """The problem of a .yaml or .pddl file (None if it has errors) and its diagnostics."""
    if Path(file).suffix.lower() != ".pddl":
        return check_problem(file)
    try:
        return load_pddl_problem(file), []
    except ProblemFormatError as error:
        return None, list(error.diagnostics)


@click.command()
@click.argument("files", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option("--quiet", "-q", is_flag=True, help="Print only errors and warnings.")
def check(files: tuple[str, ...], quiet: bool) -> None:
    """Validate problem FILES (.yaml, or .pddl of the arrange-up domain).

    Every problem in every file is reported at once, as FILE:LINE:COL: severity: key.path:
    message. Exits 1 if any file has errors, 0 otherwise (warnings do not fail).
    """
    failed = 0
    names: dict[tuple[Path, str], str] = {}
    for file in files:
        problem, diagnostics = _check_file(file)
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
        fail(f"{failed} of {len(files)} file(s) failed", EXIT_NEGATIVE)


@click.command()
@click.argument("problem")
@click.option(
    "--to",
    "fmt",
    type=click.Choice(["pddl"]),
    default="pddl",
    show_default=True,
    help="Target format.",
)
@click.option(
    "--output",
    "-o",
    type=click.Path(dir_okay=False, writable=True),
    required=True,
    help="Where to write the problem.",
)
def export(problem: str, fmt: str, output: str) -> None:
    """Write PROBLEM as a PDDL 2.1 problem of the arrange-up domain (inches, degrees).

    The domain it refers to ships in semantics/arrange-up-domain.pddl. What PDDL cannot
    express (shapes outside the shape catalogue, planning hints, ...) is refused with every
    reason listed, and nothing is written (exit status 1).
    """
    loaded = load_problem(problem)
    try:
        text = write_pddl_problem(loaded)
    except PddlExportError as error:
        fail(str(error), EXIT_NEGATIVE)
    write_text_atomic(Path(output), text)
    click.echo(f"wrote {output}")
