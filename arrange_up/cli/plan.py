"""The ``plan`` command: belief-space search for a conformant plan."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import click
from rich.progress import TextColumn

from arrange_up.cli.shared import (
    EXIT_NEGATIVE,
    FiniteFloat,
    OutputFile,
    actions_table,
    backend_choice,
    check_semantics,
    document_summary,
    echo_json,
    fail,
    first_interrupt_stops,
    json_option,
    library_default,
    load_problem,
    parallel_options,
    quiet_option,
    seed_option,
    stopped_early,
    terminal_progress,
    writing_output,
)
from arrange_up.evaluation.evaluate import MAX_ROLLOUTS
from arrange_up.io.planfile import write_json_atomic
from arrange_up.model.problem import ArrangementProblem
from arrange_up.parallel import (
    BackendUnavailableError,
    RunnerConfig,
    WorkersLostError,
    available_cores,
)
from arrange_up.planning.config import DEFAULT_MAX_NODES, DEFAULT_WEIGHT, PlanConfig, SearchConfig
from arrange_up.planning.heuristics import HEURISTICS
from arrange_up.planning.planner import plan as run_plan
from arrange_up.planning.validation import check_validate

#: ``plan --timeout``'s default, in seconds: a run is not left going for hours unattended
#: (docs/design/cli.md).
DEFAULT_PLAN_TIMEOUT = 600.0


def _status_line(stats: dict[str, Any]) -> str:
    """The live search status shown on a terminal."""
    best = stats.get("best_h")
    again = f"search {stats['search']} (validation failed): " if "search" in stats else ""
    stage = f"{stats['stage']}: " if "stage" in stats else ""
    return (
        again
        + stage
        + (
            f"expanded {stats['expanded']:>6}  generated {stats['generated']:>7}  "
            f"simulated {stats['transitions_simulated']:>8}  best h "
            f"{'-' if best is None else f'{best:g}'}  {stats['elapsed']:6.1f} s"
        )
    )


def _check_model(problem: ArrangementProblem, model: str | None) -> None:
    """Exit 2 when the cbst model (``None``: the shipped one for the problem's controller) is
    unknown, unsound or trained under another controller than the problem's."""
    # Lazy: only the cbst semantics needs scikit-learn, whose import is slow (see
    # arrange_up.up.planner_engine); the planner imports it next anyway.
    from arrange_up.cbst.choice import model_for

    try:
        model_for(problem, "default" if model is None else model)
    except (LookupError, ValueError) as error:
        fail(
            f"--model {model}: {error}"
            if model is not None
            else f"{problem.source or problem.name}: {error}"
        )


@click.command()
@click.argument("problem")
@click.option(
    "--semantics",
    default=library_default(PlanConfig, "semantics"),
    show_default=True,
    help="Belief transition: deterministic (nominal, one particle, no noise), particles "
    "(thesis §3.1: simulate every particle) or cbst (thesis §3.2: interval beliefs and the "
    "learned push model; square blocks and the 2.5 x 0.15 in paddle).",
)
@click.option(
    "--particles",
    type=click.IntRange(1, 100_000),
    default=library_default(PlanConfig, "particles"),
    show_default=True,
    help="Particles per belief (particle semantics; deterministic plans from one, CBST from "
    "intervals).",
)
@seed_option("Seed for initial particles and noise: equal seeds give equal plans.")
@click.option(
    "--max-nodes",
    type=click.IntRange(1, None),
    default=None,
    help=f"Node limit (default: the problem's planning.max_nodes, else {DEFAULT_MAX_NODES}).",
)
@click.option(
    "--timeout",
    type=FiniteFloat(0, None, min_open=True),
    default=DEFAULT_PLAN_TIMEOUT,
    show_default=True,
    help="Give up after this many seconds (validation included: a plan found in time is "
    f"kept). The default, {DEFAULT_PLAN_TIMEOUT:g} s ({DEFAULT_PLAN_TIMEOUT / 60:g} minutes), "
    "ends a run that would otherwise go on for hours; raise it for larger problems.",
)
@click.option(
    "--heuristic",
    default=library_default(SearchConfig, "heuristic"),
    show_default=True,
    type=click.Choice(HEURISTICS),
    help="Search heuristic (thesis §2.2.2, §3.2).",
)
@click.option(
    "--weight",
    type=FiniteFloat(0, None),
    default=DEFAULT_WEIGHT,
    show_default=True,
    help="Weighted A*: f = g + weight * h (1 = A*).",
)
@click.option("--no-dominance", is_flag=True, help="Do not prune dominated beliefs.")
@click.option(
    "--agenda/--no-agenda",
    default=library_default(SearchConfig, "agenda"),
    show_default=True,
    help="Search one part at a time, in an order taken from the goal's geometry (the goal "
    "agenda), before the whole goal; --no-agenda searches the whole goal only.",
)
@click.option(
    "--validate",
    type=click.IntRange(0, MAX_ROLLOUTS),
    default=None,
    help="Check a found plan on this many fresh rollouts (new initial states and noise, "
    "judged as evaluate judges them). Particle semantics: when some fail, search again with "
    "their initial states added to the particles, up to 3 more times, and return the plan "
    "that did best; other semantics report how the one plan did. 0 turns it off; at most "
    f"{MAX_ROLLOUTS:,}. [default: "
    "twice --particles, at least 60; 60 for cbst; off for deterministic]",
)
@parallel_options("simulations of the successors the search will evaluate next")
@click.option(
    "--model",
    default=None,
    help="CBST model (--semantics cbst): a shipped name or the .json card train-cbst wrote; "
    "it must have been trained under the problem's controller [default: the shipped model "
    "of the problem's controller].",
)
@click.option(
    "--output",
    "-o",
    type=OutputFile(),
    default=None,
    help="Write the plan file (JSON, documented in docs/plan-format.md).",
)
@json_option("Print a machine-readable summary (JSON) on stdout instead of the table.")
@quiet_option()
def plan(
    problem: str,
    semantics: str,
    particles: int,
    seed: int,
    max_nodes: int | None,
    timeout: float | None,
    heuristic: str,
    weight: float,
    no_dominance: bool,
    agenda: bool,
    validate: int | None,
    workers: int | None,
    backend: str | None,
    scheduler: str | None,
    model: str | None,
    output: str | None,
    as_json: bool,
    quiet: bool,
) -> None:
    """Search belief space for a conformant plan for PROBLEM.

    \b
    Examples:
      arrange-up plan blocks-2 --semantics deterministic
      arrange-up plan blocks-4 --particles 50 --seed 1 --output blocks-4.plan.json
      arrange-up plan my-problem.yaml --timeout 300 --json
      arrange-up plan blocks-7 --particles 25 --backend dask --scheduler tcp://10.0.0.5:8786

    The workers simulate the pushes the search will evaluate next while it deals with the
    current one; the plan does not depend on --workers or --backend (equal seeds give equal
    plans). --workers defaults to all cores (1 for the deterministic semantics). The cbst
    semantics predicts in this process: it starts no workers or cluster.

    A particle plan is conformant for its particles only, so it is checked on twice --particles
    fresh rollouts, at least 60 (--validate); their failed starts become further particles of up
    to three more searches, and the line after the statistics says how the returned plan did.
    A cbst plan is checked on 60 (its beliefs are learned predictions, not bounds); it has no
    particles to add failed starts to, so the line reports how it did. A deterministic plan is
    checked only with --validate. The rollouts are seeded apart from evaluate's, which stays a
    fresh test. --timeout covers them too: a plan found in time is returned with the rollouts
    that fitted, and the line says how many of the asked-for ones ran.

    Ctrl-C stops the run in order: during a search, the status is cancelled (written to
    --output like any other); during a validation, the plan found is kept with the rollouts
    already run. A second Ctrl-C aborts at once and writes nothing.

    Progress: a live line on a terminal; otherwise (a log, CI) a line on stderr every few
    seconds with the search's state and the time elapsed; --quiet prints neither.

    Exit status: 0 a plan was found, 1 none was found (node limit, timeout, exhausted: the
    candidates ran out, unsolvable: proven, e.g. a goal part larger than the table, cancelled:
    interrupted) or aborted, 2 bad input. An unsolved run prints one line of why.
    """
    check_semantics(semantics)
    try:
        check_validate(validate)
    except ValueError as error:  # the message starts with the option's name
        fail(f"--{error}")
    backend = backend_choice(backend, scheduler)
    loaded = load_problem(problem)
    if semantics == "cbst":
        _check_model(loaded, model)
    if workers is None:
        workers = 1 if semantics == "deterministic" else available_cores()
    try:
        with (
            first_interrupt_stops("the planning run (a plan already found is kept)") as interrupted,
            terminal_progress(
                TextColumn("{task.description}"), what="plan", quiet=quiet
            ) as display,
        ):
            update = None
            if display is not None:
                task = display.add_task("starting…", total=None)

                def update(stats: dict[str, Any]) -> None:
                    display.update(task, description=_status_line(stats))

            config = PlanConfig(
                semantics=semantics,
                particles=particles,
                seed=seed,
                model=model,
                validate=validate,
                search=SearchConfig(
                    weight=weight,
                    heuristic=heuristic,
                    dominance=not no_dominance,
                    max_nodes=max_nodes,
                    timeout=timeout,
                    agenda=agenda,
                ),
                runner=RunnerConfig(workers=workers, backend=backend, scheduler=scheduler),
            )
            result = run_plan(loaded, config, progress=update, should_stop=interrupted)
    except BackendUnavailableError as error:  # dask missing, or the scheduler unreachable
        fail(f"--backend {backend}: {error}")
    except (LookupError, ValueError) as error:  # a --model not found, unsound or not for cbst
        if model is None:
            raise
        fail(f"--model {model}: {error}")
    except KeyboardInterrupt:  # the second Ctrl-C
        fail("interrupted; no plan was written", EXIT_NEGATIVE)
    except WorkersLostError as error:
        stopped_early(error, "; no plan was written: run again")
    document = result.document(loaded, model)
    if output:
        with writing_output(output):
            write_json_atomic(Path(output), document)
    if as_json:
        plan_length = len(result.actions) if result.actions is not None else None
        echo_json(document_summary(document, output, plan_length=plan_length, reason=result.reason))
    else:
        stats = result.stats
        # CBST's belief is an interval per object; its "2 particles" are the corner
        # pseudo-particles the planner sees, nothing the user asked for
        belief = (
            "interval belief"
            if result.semantics == "cbst"
            else f"{result.particles} particle{'s' if result.particles != 1 else ''}"
        )
        click.echo(
            f"{loaded.name}: {result.status} ({result.semantics}, {belief}, "
            f"seed {seed}) in {stats['elapsed']:.1f} s: expanded {stats['expanded']}, "
            f"generated {stats['generated']}, "
            f"transitions simulated {stats['transitions_simulated']}"
        )
        if result.fallbacks is not None:
            click.echo(result.fallback_line())
        if result.agenda is not None:
            click.echo(result.agenda.line())
        if result.reason is not None:
            click.echo(result.reason)
        if result.validation is not None:
            click.echo(result.validation.line())
        if result.actions is not None:
            click.echo(actions_table(loaded, result.actions))
        if output:
            click.echo(f"wrote {output}")
    if not result.solved:
        sys.exit(EXIT_NEGATIVE)
