"""The ``evaluate`` command: the reliability of a plan, by noisy rollouts."""

from __future__ import annotations

from collections.abc import Sequence

import click
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from arrange_up.cli.shared import (
    EXIT_NEGATIVE,
    OutputFile,
    backend_choice,
    echo_json,
    fail,
    json_option,
    landing_option,
    library_default,
    load_problem,
    parallel_options,
    quiet_option,
    read_plan_file,
    seed_option,
    stopped_early,
    terminal_progress,
)
from arrange_up.evaluation.evaluate import MAX_ROLLOUTS, evaluate_plan
from arrange_up.evaluation.records import RecordFileError, plan_hash
from arrange_up.evaluation.reliability import EvaluationProgress, FailureBreakdown
from arrange_up.model.problem import ArrangementProblem, problem_hash
from arrange_up.model.world import Action, Push
from arrange_up.parallel import BackendUnavailableError, RunnerConfig, WorkersLostError


def _describe_action(actions: Sequence[Action], index: int) -> str:
    """``action 3 (push paddle)``: 1-based, as in the plan table of ``arrange-up plan``;
    ``action 9`` alone past the end of ``actions`` (a closed-loop episode's replanned
    actions)."""
    if index >= len(actions):
        return f"action {index + 1}"
    action = actions[index]
    kind = type(action).__name__.lower()
    who = action.manipulator if isinstance(action, Push) else action.obj
    return f"action {index + 1} ({kind} {who})"


def _failure_lines(
    problem: ArrangementProblem, actions: Sequence[Action], failures: FailureBreakdown
) -> list[str]:
    """The failure breakdown as text, in the problem's units and names."""
    units = problem.units
    tol = problem.goal.tolerance
    lines = []
    if failures.goal_missed:
        lines.append(f"  goal missed      {failures.goal_missed:>7}")
        for miss in failures.goal_misses:
            if miss.dimension == "theta":
                worst = f"{units.angle_out(miss.worst):.3g} {units.angle}"
                bound = f"±{units.angle_out(tol[2] or 0.0):g} {units.angle}"
            elif miss.dimension in ("x", "y"):
                worst = f"{units.length_out(miss.worst):.3g} {units.length}"
                along = tol[0] if miss.dimension == "x" else tol[1]
                bound = f"±{units.length_out(along):g} {units.length}"
            else:
                lines.append(f"    {miss.part} {miss.dimension}: {miss.rollouts}")
                continue
            lines.append(
                f"    {miss.part} {miss.dimension}: {miss.rollouts} (worst {worst} beyond "
                f"the {bound} tolerance)"
            )
    if failures.action_failed:
        lines.append(f"  action failed    {failures.action_failed:>7}")
        for failure in failures.action_failures:
            lines.append(
                f"    {_describe_action(actions, failure.action)}: {failure.rollouts}: "
                f"{failure.reason}"
            )
    if failures.not_at_rest:
        lines.append(f"  not at rest      {failures.not_at_rest:>7}")
        for moving in failures.not_at_rest_actions:
            lines.append(f"    {_describe_action(actions, moving.action)}: {moving.rollouts}")
    if failures.off_table:
        lines.append(f"  off table        {failures.off_table:>7}")
        for fallen in failures.off_table_actions:
            lines.append(
                f"    {_describe_action(actions, fallen.action)}: {fallen.object} {fallen.rollouts}"
            )
    return lines


@click.command()
@click.argument("problem")
@click.argument("plan_file", metavar="PLAN.json", type=click.Path(dir_okay=False))
@click.option(
    "--rollouts",
    type=click.IntRange(1, MAX_ROLLOUTS),
    default=library_default(evaluate_plan, "rollouts"),
    show_default=True,
    help=f"Noisy executions of the plan (at most {MAX_ROLLOUTS:,}).",
)
@seed_option("Rollout i draws its noise from (seed, i): equal seeds give equal results.")
@parallel_options("rollouts")
@click.option(
    "--record",
    type=OutputFile(),
    default=None,
    help="Append every rollout to this .jsonl file as it finishes; re-running with the same "
    "file resumes the evaluation.",
)
@landing_option()
@json_option("Print a machine-readable summary (JSON) on stdout.")
@quiet_option()
def evaluate(
    problem: str,
    plan_file: str,
    rollouts: int,
    seed: int,
    workers: int | None,
    backend: str | None,
    scheduler: str | None,
    record: str | None,
    landing: str,
    as_json: bool,
    quiet: bool,
) -> None:
    """Estimate how reliably PLAN.json achieves PROBLEM's goal, by noisy rollouts.

    Each rollout draws initial poses within the initial uncertainty, executes the plan open
    loop in the physics with fresh place/push noise, friction and densities for every action,
    and checks the goal. Prints successes / trials, the rate with its 95% Wilson interval, and
    why the failures failed.

    \b
    Examples:
      arrange-up evaluate blocks-4 blocks-4.plan.json --rollouts 1000
      arrange-up evaluate blocks-4 b4.json --record b4.rollouts.jsonl --json
      arrange-up evaluate blocks-4 b4.json --landing shove
      arrange-up evaluate blocks-4 b4.json --backend dask --scheduler tcp://10.0.0.5:8786

    Exit status: 0 the evaluation ran (whatever the rate), 1 interrupted or its workers lost
    (a worker process killed, a Dask scheduler gone: the rollouts recorded with --record are
    kept, and running the command again resumes), 2 bad input.
    """
    backend = backend_choice(backend, scheduler)
    loaded = load_problem(problem)
    actions, document = read_plan_file(loaded, plan_file, warn_mismatch=True)
    columns = (
        TextColumn("rollouts"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[summary]}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
    )
    done = [0]  # rollouts finished (resumed ones included), for a message if the run stops
    try:
        with terminal_progress(*columns, what="evaluate", quiet=quiet) as display:
            task = (
                None
                if display is None
                else display.add_task("rollouts", total=rollouts, summary="")
            )

            def update(state: EvaluationProgress) -> None:
                done[0] = state.done
                if display is not None and task is not None:
                    summary = f"{state.successes} ok ({100.0 * state.rate:.1f}%)"
                    display.update(task, completed=state.done, summary=summary)

            result = evaluate_plan(
                loaded,
                actions,
                rollouts=rollouts,
                seed=seed,
                runner=RunnerConfig(workers, backend, scheduler),
                record=record,
                progress=update,
                landing=landing,
            )
    except KeyboardInterrupt:
        kept = f"; the finished rollouts are in {record}: run again to resume" if record else ""
        fail(f"interrupted{kept}", EXIT_NEGATIVE)
    except WorkersLostError as error:
        if record:
            kept = f"; the {done[0]} finished rollouts are in {record}: run again to resume"
        else:
            kept = "; no rollout was kept (--record FILE keeps them to resume): run again"
        stopped_early(error, kept)
    except (RecordFileError, BackendUnavailableError, ValueError) as error:
        fail(str(error))
    low, high = result.interval
    if as_json:
        summary = result.to_json()
        summary.update(
            rollouts=rollouts,
            problem={"name": loaded.name, "hash": problem_hash(loaded), "source": loaded.source},
            plan={
                "path": plan_file,
                "hash": plan_hash(actions),
                "actions": len(actions),
                "problem": document.get("problem") or None,
            },
            record=record,
        )
        echo_json(summary)
        return
    where = f"{result.backend}, {result.workers} worker{'s' if result.workers != 1 else ''}"
    resumed = f", {result.resumed} resumed from {record}" if result.resumed else ""
    click.echo(
        f"{loaded.name}: {result.successes} of {result.trials} rollouts reached the goal: "
        f"{100.0 * result.rate:.1f}% (95% Wilson interval {100.0 * low:.1f}%-{100.0 * high:.1f}%)"
    )
    shoved = ", landing: shove" if landing == "shove" else ""
    click.echo(f"seed {seed}, {where}, {result.elapsed:.1f} s{resumed}{shoved}")
    if result.failures.total:
        click.echo(f"failures: {result.failures.total}")
        for line in _failure_lines(loaded, actions, result.failures):
            click.echo(line)
    if record:
        click.echo(f"rollouts recorded in {record}")
