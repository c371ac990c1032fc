"""The ``repair`` command: fixture placement for a nominal plan (thesis ch. 4)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import click
from rich.progress import Progress, TextColumn

from arrange_up.cli.shared import (
    EXIT_NEGATIVE,
    OutputFile,
    actions_table,
    document_summary,
    echo_json,
    fail,
    json_option,
    library_default,
    load_problem,
    quiet_option,
    read_plan_file,
    seed_option,
    stopped_early,
    terminal_progress,
    workers_option,
    writing_output,
)
from arrange_up.io.planfile import write_json_atomic
from arrange_up.model.problem import ArrangementProblem
from arrange_up.parallel import WorkersLostError, available_cores
from arrange_up.repair import (
    DEFAULT_PARTICLES,
    METHODS,
    RepairResult,
    nominal_plans,
    repair_plan,
)


def _progress_line(info: dict[str, Any]) -> str | None:
    """The line of a repair progress report: one per repaired step, and one when a push's
    candidates are scored; None for other reports."""
    if info["phase"] == "done":
        return (
            f"step {info['step']}/{info['steps']} {info['kind']}: {info['choice']} "
            f"({info['elapsed']:.1f} s)"
        )
    if info["phase"] == "placements":
        return f"step {info['step']}/{info['steps']} push: scoring {info['candidates']} candidates…"
    return None


def _step_lines(problem: ArrangementProblem, result: RepairResult) -> list[str]:
    """What the repair chose at each step, in the problem's units."""
    lines = []
    for record in result.steps:
        if record.kind != "push":
            lines.append(f"  step {record.index + 1}: {record.kind} kept")
            continue
        chosen = "every candidate invalid"
        if record.status == "ok":
            where = (
                "no fixture"
                if record.pose is None
                else f"{record.fixture} at "
                + ", ".join(f"{v:.3g}" for v in problem.units.pose_out(record.pose))
            )
            chosen = (
                f"{where}, push x{record.multiplier:g}: distance {record.distance:.3f} "
                f"(bare push {record.nominal_distance:.3f})"
            )
        lines.append(f"  step {record.index + 1}: {chosen}")
    return lines


@click.command()
@click.argument("problem")
@click.option(
    "--plan",
    "plan_file",
    type=click.Path(dir_okay=False),
    default=None,
    help="The nominal plan to repair (a plan file); default: make one with the deterministic "
    "planner.",
)
@click.option(
    "--particles",
    type=click.IntRange(1, 100_000),
    default=DEFAULT_PARTICLES,
    show_default=True,
    help="Particles of the belief the candidates are simulated and scored on.",
)
@seed_option("Seed for the particles, the noise and the nominal plan: equal seeds, equal plans.")
@click.option(
    "--method",
    type=click.Choice(METHODS),
    default=library_default(repair_plan, "method"),
    show_default=True,
    help="Candidate placements: the whole workspace grid (naive) or the grid placements that "
    "meet the part motion swath (enhanced).",
)
@click.option(
    "--no-fixtures",
    "no_fixtures",
    is_flag=True,
    help="The fixtures' ablation: repair exactly as usual but never place a fixture, keeping "
    "only the approach back-off and the push multipliers, to measure how much of a repair's "
    "gain the fixtures themselves bring (recorded as \"fixtures\": false under 'repair').",
)
@workers_option("Processes simulating particles (default: all cores).")
@click.option(
    "--output",
    "-o",
    type=OutputFile(),
    default=None,
    help="Write the repaired plan file (JSON; semantics 'fixtures', per-step choices under "
    "'repair').",
)
@json_option("Print a machine-readable summary (JSON) on stdout instead of the table.")
@quiet_option()
def repair(
    problem: str,
    plan_file: str | None,
    particles: int,
    seed: int,
    method: str,
    no_fixtures: bool,
    workers: int | None,
    output: str | None,
    as_json: bool,
    quiet: bool,
) -> None:
    """Make a nominal plan for PROBLEM robust by placing fixtures (thesis ch. 4).

    Every push of the nominal plan becomes place(fixture), push, pick(fixture) (or stays a
    bare push, with its distance multiplied by 1 to 2). The candidates (grid placements, see
    --method; placements that stop a part where its end is uncertain; bare pushes) are
    ranked by reliability: the share of rollouts of the plan's remaining actions, run from the
    candidate's simulated particles with the same noise for every candidate, that reach the
    goal. The mean distance to the nominal plan's next state breaks ties, and a fixture is
    kept only if it beats the best bare push. Place and pick actions stay. See docs/repair.md.

    \b
    Examples:
      arrange-up repair tz-mating --particles 10 --output tz.fixtures.json
      arrange-up repair tz-mating --plan tz.nominal.json --method naive --json
      arrange-up repair tz-mating --plan tz.nominal.json --no-fixtures -o tz.ablation.json

    Exit status: 0 repaired, 1 the repair failed (a step whose every candidate pushes a part
    off the table or never comes to rest), 2 bad input.
    """
    loaded = load_problem(problem)
    if plan_file is not None:
        nominal, _ = read_plan_file(loaded, plan_file, warn_mismatch=False)
    try:
        with terminal_progress(
            TextColumn("{task.description}"), what="repair", quiet=quiet
        ) as display:
            task = None if display is None else display.add_task("finding a nominal plan")
            if plan_file is None:
                found = nominal_plans(loaded, 1, seed)
                if not found:
                    fail("the deterministic planner found no nominal plan to repair", EXIT_NEGATIVE)
                nominal = found[0]

            def progress(info: dict[str, Any]) -> None:
                line = _progress_line(info)
                if display is None or task is None or line is None:
                    return
                if isinstance(display, Progress):  # on a terminal: a line per step, as before
                    display.console.print(line, highlight=False)
                display.update(task, description=line)  # off it, the progress line repeats it

            result = repair_plan(
                loaded,
                nominal,
                particles=particles,
                seed=seed,
                method=method,
                workers=available_cores() if workers is None else workers,
                progress=progress,
                fixtures=not no_fixtures,
            )
    except KeyboardInterrupt:
        fail("interrupted; no plan was written", EXIT_NEGATIVE)
    except WorkersLostError as error:
        stopped_early(error, "; no plan was written: run again")
    except ValueError as error:
        fail(str(error))
    document = result.document(loaded)
    if output:
        with writing_output(output):
            write_json_atomic(Path(output), document)
    if as_json:
        echo_json(document_summary(document, output, reason=result.reason or None))
    else:
        stats = result.stats()
        ablation = ", no fixtures" if no_fixtures else ""
        click.echo(
            f"{loaded.name}: {result.status} ({method}{ablation}, {particles} particles, "
            f"seed {seed}) in "
            f"{result.elapsed:.1f} s: {stats['pushes']} pushes, {stats['fixtures_placed']} "
            f"fixtures placed, {result.simulations} simulations"
        )
        if result.reason:
            click.echo(f"reason: {result.reason}")
        for line in _step_lines(loaded, result):
            click.echo(line)
        if result.actions is not None:
            click.echo(actions_table(loaded, result.actions))
        if output:
            click.echo(f"wrote {output}")
    if not result.solved:
        sys.exit(EXIT_NEGATIVE)
