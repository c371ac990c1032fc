"""The commands about problem files: ``domains``, ``check`` and ``export``."""

from __future__ import annotations

import re
from pathlib import Path

import click

from arrange_up.cli.shared import (
    EXIT_BAD_INPUT,
    EXIT_NEGATIVE,
    OutputFile,
    fail,
    load_problem,
    writing_output,
)
from arrange_up.io.domains import (
    UnknownDomainError,
    check_problem_file,
    list_domains,
    resolve_problem,
)
from arrange_up.io.files import text_place
from arrange_up.io.pddl import PddlExportError, write_pddl_problem
from arrange_up.io.pddl_reader import problem_name_place
from arrange_up.io.planfile import write_text_atomic
from arrange_up.model.errors import printable
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


def _resolve(argument: str) -> tuple[Path | None, str | None]:
    """The file a ``check`` argument names (a path, or a shipped problem's name), or why
    there is none."""
    try:
        return resolve_problem(argument), None
    except UnknownDomainError as error:
        return None, str(error)


@click.command()
@click.argument("files", nargs=-1, required=True)
@click.option("--quiet", "-q", is_flag=True, help="Print only errors and warnings.")
def check(files: tuple[str, ...], quiet: bool) -> None:
    """Validate problem FILES (.yaml, or .pddl of the arrange-up domain).

    FILES are paths or shipped problems' names, as PROBLEM everywhere else. Every problem in
    every file is reported at once, as FILE:LINE:COL: severity: key.path: message; a file that
    cannot be read (or a folder) is reported and the others still checked. Two files of one
    folder may not hold problems of the same name, except a problem's YAML and PDDL twins
    (same file name, other suffix). Exits 2 if any file has errors (bad input, as plan,
    evaluate and show exit on the same file), 0 otherwise (warnings do not fail).
    """
    failed = 0
    names: dict[tuple[Path, str], Path] = {}
    for argument in files:
        path, reason = _resolve(argument)
        if path is None:
            click.echo(printable(f"{argument}: error: {reason}"), err=True)
            failed += 1
            continue
        # The file as the user named it, made printable: every line below starts with it.
        shown = printable(argument if Path(argument).expanduser().is_file() else str(path))
        problem, diagnostics = check_problem_file(path)
        for diagnostic in diagnostics:
            click.echo(str(diagnostic), err=True)
        if problem is None:
            failed += 1
            continue
        key = (path.resolve().parent, problem.name)
        other = names.get(key)
        if other is not None and other.stem != path.stem:
            click.echo(
                f"{shown}{_name_place(path)}: error: name: problem name {problem.name!r} is "
                "already used by "
                f"{other} in the same folder; names must be unique within a folder (a "
                "problem's YAML and PDDL twins share a file name)",
                err=True,
            )
            failed += 1
            continue
        names.setdefault(key, path)
        _warn_unfit(shown, problem)
        _warn_stiff(shown, problem)
        _warn_soft(shown, problem)
        if not quiet:
            click.echo(
                f"{shown}: ok: {printable(problem.name)} ({len(problem.parts)} "
                f"part{'s' if len(problem.parts) != 1 else ''}, "
                f"{'relative' if problem.goal.is_relative else 'absolute'} goal)"
            )
    if failed:
        # An invalid file is bad input, whichever command is given it: check reports it as
        # every other command does (exit 2), so a script need not know which one ran.
        fail(f"{failed} of {len(files)} file(s) failed", EXIT_BAD_INPUT)


def _warn_unfit(shown: str, problem: ArrangementProblem) -> None:
    """Warn of each goal part that the planner proves cannot fit the table at any pose its
    goal allows (:func:`arrange_up.planning.fitting.unfit_parts`): the file is valid, but no
    plan exists, and ``plan`` answers ``unsolvable``."""
    # Lazy: the proof needs numpy and shapely, which a check of a broken file never does.
    from arrange_up.planning.fitting import unfit_parts

    for unfit in unfit_parts(problem):
        where = "goal.relative" if problem.goal.is_relative else f"goal.poses.{unfit.part}"
        click.echo(
            f"{shown}: warning: {where}: {unfit.why}: no plan exists (plan answers unsolvable)",
            err=True,
        )


def _warn_stiff(shown: str, problem: ArrangementProblem) -> None:
    """Warn of each manipulator the compliant controller is too stiff for at the physics' time
    step (:func:`arrange_up.physics.simulation.stiff_manipulators`): the file is valid, but its
    simulated pushes oscillate and throw parts (a light, millimetre-scale paddle at the
    default ``kp``)."""
    from arrange_up.io.yaml_settings import controller_factors
    from arrange_up.physics.simulation import STABLE_RATE, stiff_manipulators

    for stiff in stiff_manipulators(problem):
        # the gain too stiff, as the file writes it (kp_angle is per the file's units)
        factor = controller_factors(problem.units)[stiff.gain]
        value = getattr(problem.controller, stiff.gain) / factor
        ratio = "sqrt(kp / m)" if stiff.gain == "kp" else "sqrt(kp_angle / I)"
        click.echo(
            f"{shown}: warning: controller: the compliant controller ({stiff.gain} "
            f"{value:g}) is too stiff for manipulator {stiff.name!r} at the "
            f"physics' time step ({ratio} x dt up to {stiff.rate:.3g}, stable below "
            f"{STABLE_RATE:g}): its pushes oscillate and throw parts; give "
            f"controller.{stiff.gain} at most {stiff.kp_max / factor:.3g}, or kind: servo",
            err=True,
        )


def _warn_soft(shown: str, problem: ArrangementProblem) -> None:
    """Warn of each part the compliant controller is too soft for
    (:func:`arrange_up.physics.stall.soft_parts`): the file is valid, but every push of the part
    stalls further short than a push on the table can make up for (densities in grams where
    the gains expect kilograms)."""
    from arrange_up.physics.stall import soft_parts

    for soft in soft_parts(problem):
        click.echo(
            f"{shown}: warning: controller: the compliant controller (kp "
            f"{problem.controller.kp:g}) is too soft for part {soft.name!r}: a push of it "
            f"stalls {soft.stall:.3g} in short of its set point (friction x g x density x area "
            f"/ kp), more than the table's {soft.reach:g} in, so no push gets it where the plan "
            f"says; check the density unit (per-area mass in the gains' unit), give "
            f"controller.kp above {soft.kp_min:.3g}, or kind: servo",
            err=True,
        )


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
    type=OutputFile(),
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
    with writing_output(output):
        write_text_atomic(Path(output), text)
    click.echo(f"wrote {output}")


def _name_place(path: Path) -> str:
    """``:LINE:COLUMN`` of the problem's name in the file (a YAML file's top-level ``name:``
    value, a PDDL file's ``(problem NAME)``), or "" when it is not found."""
    text = path.read_text(encoding="utf-8", errors="replace")
    if path.suffix.lower() == ".pddl":
        place = problem_name_place(text)
    else:
        match = re.search(r"(?m)^name[ \t]*:[ \t]*", text)
        place = None if match is None else text_place(text, match.end())
    return "" if place is None else f":{place[0]}:{place[1]}"
