"""The ``arrange-up`` command: a thin shell over the library.

Each command parses its arguments, calls one library function, renders the result and sets the
exit status. Heavy libraries (pymunk, matplotlib, unified-planning, rich) are imported inside
the commands, so ``arrange-up --help`` stays fast.

Exit status: 0 success; 1 the job ran but its answer is negative (e.g. a problem file has
errors under ``check``); 2 bad input (unreadable or invalid problem, unknown domain, bad option).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any, NoReturn

import click

from arrange_up import __version__

EXIT_NEGATIVE = 1
EXIT_BAD_INPUT = 2


def _fail(message: str, code: int = EXIT_BAD_INPUT) -> NoReturn:
    click.echo(f"arrange-up: {message}", err=True)
    sys.exit(code)


def _load(problem: str):  # -> ArrangementProblem
    """Resolve and load a problem, turning every refusal into a clean message and exit 2."""
    from arrange_up.io.domains import UnknownDomainError, load
    from arrange_up.model.errors import ProblemFormatError

    try:
        return load(problem)
    except UnknownDomainError as error:
        _fail(str(error))
    except ProblemFormatError as error:
        click.echo(str(error), err=True)
        n = sum(1 for d in error.diagnostics if d.severity == "error")
        _fail(f"{n} error{'s' if n != 1 else ''}; nothing was done")


def _read_plan_for(problem, plan_file: str):  # -> (actions, document)
    """Read a plan file for ``problem``: a clean message and exit 2 on a bad file, a warning
    when the plan was made for other problem content."""
    from arrange_up.io.planfile import PlanFileError, plan_problem_mismatch, read_plan

    try:
        actions, document = read_plan(plan_file, problem)
    except PlanFileError as error:
        _fail(str(error))
    mismatch = plan_problem_mismatch(document, problem)
    if mismatch:
        click.echo(f"arrange-up: warning: {plan_file}: {mismatch}; using it anyway", err=True)
    return actions, document


def _parallel_options(what: str):
    """The --workers, --backend and --scheduler options of commands that run batches of
    independent simulations (``what``: rollouts, examples, ...) on local processes or Dask."""

    def decorate(command):
        for option in reversed(
            (
                click.option(
                    "--workers",
                    type=click.IntRange(1, 1024),
                    default=None,
                    help="Worker processes (default: all cores; 1 runs in this process).",
                ),
                click.option(
                    "--backend",
                    type=click.Choice(["local", "dask"]),
                    default=None,
                    help=f"Where the {what} run: local processes (default) or a Dask cluster.",
                ),
                click.option(
                    "--scheduler",
                    metavar="ADDRESS",
                    default=None,
                    help="Address of a running Dask scheduler (implies --backend dask); "
                    "without it the dask backend starts a local cluster of "
                    "--workers processes.",
                ),
            )
        ):
            command = option(command)
        return command

    return decorate


def _backend_choice(backend: str | None, scheduler: str | None) -> str:
    """The backend to use: a scheduler address implies dask and contradicts local."""
    if scheduler is not None and backend == "local":
        _fail("--scheduler: a scheduler address needs --backend dask")
    return backend or ("dask" if scheduler is not None else "local")


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
    """Validate problem FILES (.yaml, or .pddl of the arrange-up domain).

    Every problem in every file is reported at once, as FILE:LINE:COL: severity: key.path:
    message. Exits 1 if any file has errors, 0 otherwise (warnings do not fail).
    """
    from arrange_up.io.yaml_problem import check_problem

    def check_any(file: str):
        if Path(file).suffix.lower() != ".pddl":
            return check_problem(file)
        from arrange_up.io.pddl import load_pddl_problem
        from arrange_up.model.errors import ProblemFormatError

        try:
            return load_pddl_problem(file), []
        except ProblemFormatError as error:
            return None, list(error.diagnostics)

    failed = 0
    names: dict[tuple[Path, str], str] = {}
    for file in files:
        problem, diagnostics = check_any(file)
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
    from arrange_up.io.domains import list_domains

    rows = list_domains()
    width = max((len(info.name) for info in rows), default=4)
    for info in rows:
        click.echo(
            f"{info.name:<{width}}  {info.parts:>2} parts  {info.goal_kind:<8}  {info.summary}"
        )


@main.command()
@click.argument("problem")
@click.option(
    "--output",
    "-o",
    type=click.Path(dir_okay=False, writable=True),
    required=True,
    help="Where to write the picture (.png).",
)
@click.option("--dpi", type=click.IntRange(30, 600), default=150, show_default=True)
@click.option(
    "--plan",
    "plan_file",
    type=click.Path(dir_okay=False),
    default=None,
    help="Draw a storyboard of this plan file: one panel per action.",
)
@click.option(
    "--rollouts",
    type=click.IntRange(0, 10_000),
    default=50,
    show_default=True,
    help="Noisy rollouts overlaid in grey on the storyboard.",
)
@click.option(
    "--seed",
    type=int,
    default=0,
    show_default=True,
    help="Seed of the storyboard's rollouts (as in `evaluate`).",
)
@click.option(
    "--heatmap",
    "heatmap_step",
    type=click.IntRange(1, None),
    default=None,
    metavar="STEP",
    help="With --plan: draw the fixture-placement scores of nominal step STEP "
    "(thesis Figure 4-11); for a repaired plan, the repair's step number.",
)
def show(
    problem: str,
    output: str,
    dpi: int,
    plan_file: str | None,
    rollouts: int,
    seed: int,
    heatmap_step: int | None,
) -> None:
    """Draw PROBLEM: table, walls, obstacles, parts with their belief shadows, and the goal.

    With --plan, draw the plan's storyboard instead (thesis Figure 3-11): one panel per action
    with the action, the nominal poses, the poses of --rollouts noisy rollouts in grey and the
    belief shadows the planner predicted.

    With --plan and --heatmap STEP, draw instead the score of every candidate fixture
    placement for that step of the plan (thesis Figure 4-11), invalid ones marked.

    \b
    Examples:
      arrange-up show blocks-4 -o blocks-4.png
      arrange-up show blocks-4 --plan blocks-4.plan.json --rollouts 100 -o story.png
      arrange-up show tz-mating --plan tz.json --heatmap 1 -o heat.png
    """
    loaded = _load(problem)
    if heatmap_step is not None and plan_file is None:
        _fail("--heatmap needs --plan")
    if plan_file is None:
        from arrange_up.figures.render import draw_problem

        path = draw_problem(loaded, Path(output), dpi=dpi)
        click.echo(f"wrote {path}")
        return
    actions, document = _read_plan_for(loaded, plan_file)
    if heatmap_step is not None:
        from arrange_up.figures.render import write_heatmap
        from arrange_up.parallel import available_cores
        from arrange_up.repair import step_scores

        try:
            scores = step_scores(
                loaded, actions, heatmap_step, document=document, workers=available_cores()
            )
        except ValueError as error:
            _fail(f"--heatmap: {error}")
        path = write_heatmap(loaded, scores, Path(output), dpi=dpi)
        click.echo(f"wrote {path}")
        return
    from arrange_up.figures.storyboard import draw_storyboard
    from arrange_up.transitions import available

    semantics = document.get("semantics")
    if semantics not in available():
        semantics = "deterministic"  # e.g. repaired plans: show the nominal prediction
    path = draw_storyboard(
        loaded,
        actions,
        Path(output),
        rollouts=rollouts,
        seed=seed,
        semantics=semantics,
        particles=int(document.get("particles") or 1),
        plan_seed=int(document.get("seed") or 0),
        dpi=min(dpi, 150),
    )
    click.echo(f"wrote {path}")


def _progress_printer(enabled: bool):
    """A progress callback for long work: a live status line on a terminal, else nothing."""
    if not enabled or not sys.stderr.isatty():
        return None, None
    from rich.console import Console
    from rich.live import Live
    from rich.text import Text

    live = Live(
        Text("starting…"), console=Console(stderr=True), refresh_per_second=5, transient=True
    )
    live.start()

    def update(stats: dict) -> None:
        best = stats.get("best_h")
        live.update(
            Text(
                f"expanded {stats['expanded']:>6}  generated {stats['generated']:>7}  "
                f"simulated {stats['transitions_simulated']:>8}  best h "
                f"{'-' if best is None else f'{best:g}'}  {stats['elapsed']:6.1f} s"
            )
        )

    return update, live


def _actions_table(problem, actions) -> str:
    """The plan as an aligned text table in the problem's units."""
    from arrange_up.io.planfile import action_to_json

    units = problem.units
    lines = [
        f"{'#':>3}  {'action':<6} {'object':<12} {'x':>8} {'y':>8} {'theta':>8} {'distance':>9}",
        f"{'':>3}  {'':<6} {'':<12} {units.length:>8} {units.length:>8} "
        f"{units.angle:>8} {units.length:>9}",
    ]
    for i, action in enumerate(actions, 1):
        data = action_to_json(action, units)
        pose = data.get("pose")
        xs = [f"{v:8.3f}" for v in pose] if pose else [f"{'':>8}"] * 3
        dist = f"{data['distance']:9.3f}" if "distance" in data else ""
        who = data.get("object") or data.get("manipulator")
        lines.append(f"{i:>3}  {data['type']:<6} {who:<12} {' '.join(xs)} {dist}")
    return "\n".join(lines)


@main.command()
@click.argument("problem")
@click.option(
    "--semantics",
    default="particles",
    show_default=True,
    help="Belief transition: deterministic (nominal, one particle, no noise), particles "
    "(thesis §3.1: simulate every particle) or cbst (thesis §3.2: interval beliefs and the "
    "learned push model; square blocks and the 2.5 x 0.15 in paddle).",
)
@click.option(
    "--particles",
    type=click.IntRange(1, 100_000),
    default=50,
    show_default=True,
    help="Particles per belief (particle semantics).",
)
@click.option(
    "--seed",
    type=int,
    default=0,
    show_default=True,
    help="Seed for initial particles and noise: equal seeds give equal plans.",
)
@click.option(
    "--max-nodes",
    type=click.IntRange(1, None),
    default=None,
    help="Node limit (default: the problem's planning.max_nodes, else 5000).",
)
@click.option(
    "--timeout",
    type=click.FloatRange(0, None, min_open=True),
    default=None,
    help="Give up after this many seconds.",
)
@click.option(
    "--heuristic",
    default="inadmissible",
    show_default=True,
    type=click.Choice(["inadmissible", "admissible", "ordering", "manhattan", "blind"]),
    help="Search heuristic (thesis §2.2.2, §3.2).",
)
@click.option(
    "--weight",
    type=click.FloatRange(0, None),
    default=2.0,
    show_default=True,
    help="Weighted A*: f = g + weight * h (1 = A*).",
)
@click.option("--no-dominance", is_flag=True, help="Do not prune dominated beliefs.")
@click.option(
    "--workers",
    type=click.IntRange(1, 256),
    default=None,
    help="Processes simulating particles (default: all cores; 1 for deterministic).",
)
@click.option(
    "--output",
    "-o",
    type=click.Path(dir_okay=False),
    default=None,
    help="Write the plan file (JSON, documented in docs/plan-format.md).",
)
@click.option(
    "--json",
    "as_json",
    is_flag=True,
    help="Print a machine-readable summary (JSON) on stdout instead of the table.",
)
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
    workers: int | None,
    output: str | None,
    as_json: bool,
) -> None:
    """Search belief space for a conformant plan for PROBLEM.

    \b
    Examples:
      arrange-up plan blocks-2 --semantics deterministic
      arrange-up plan blocks-4 --particles 50 --seed 1 --output blocks-4.plan.json
      arrange-up plan my-problem.yaml --timeout 300 --json

    Exit status: 0 a plan was found, 1 none was found (node limit, timeout, exhausted),
    2 bad input.
    """
    import json

    from arrange_up.io.planfile import plan_document, write_json_atomic
    from arrange_up.planning.planner import plan as run_plan
    from arrange_up.transitions import available

    if semantics not in available():
        _fail(
            f"--semantics: unknown semantics {semantics!r}; expected one of "
            f"{', '.join(available())}"
        )
    loaded = _load(problem)
    if workers is None:
        from arrange_up.parallel import available_cores

        workers = 1 if semantics == "deterministic" else available_cores()
    update, live = _progress_printer(True)
    try:
        result = run_plan(
            loaded,
            semantics=semantics,
            particles=particles,
            seed=seed,
            max_nodes=max_nodes,
            timeout=timeout,
            heuristic=heuristic,
            weight=weight,
            dominance=not no_dominance,
            workers=workers,
            progress=update,
        )
    except KeyboardInterrupt:
        _fail("interrupted; no plan was written", EXIT_NEGATIVE)
    finally:
        if live is not None:
            live.stop()
    extra = {"particles": result.particles}
    document = plan_document(
        loaded,
        result.actions,
        status=result.status,
        semantics=result.semantics,
        seed=seed,
        search=result.stats,
        extra=extra,
    )
    if output:
        write_json_atomic(Path(output), document)
    if as_json:
        summary = {k: v for k, v in document.items() if k != "actions"}
        summary["plan_length"] = len(result.actions) if result.actions is not None else None
        summary["actions"] = document.get("actions")
        summary["output"] = output
        click.echo(json.dumps(summary, indent=2))
    else:
        stats = result.stats
        click.echo(
            f"{loaded.name}: {result.status} ({result.semantics}, "
            f"{result.particles} particle{'s' if result.particles != 1 else ''}, "
            f"seed {seed}) in {stats['elapsed']:.1f} s: expanded {stats['expanded']}, "
            f"generated {stats['generated']}, "
            f"transitions simulated {stats['transitions_simulated']}"
        )
        if result.actions is not None:
            click.echo(_actions_table(loaded, result.actions))
        if output:
            click.echo(f"wrote {output}")
    if not result.solved:
        sys.exit(EXIT_NEGATIVE)


@main.command()
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
    from arrange_up.io.pddl import PddlExportError, write_pddl_problem

    loaded = _load(problem)
    try:
        text = write_pddl_problem(loaded)
    except PddlExportError as error:
        _fail(str(error), EXIT_NEGATIVE)
    from arrange_up.io.planfile import write_text_atomic

    write_text_atomic(Path(output), text)
    click.echo(f"wrote {output}")


# ---------------------------------------------------------------------------------------------
# evaluate
# ---------------------------------------------------------------------------------------------
def _evaluation_progress(total: int):
    """A rich progress bar on stderr for ``evaluate`` (None, None when not a terminal)."""
    if not sys.stderr.isatty():
        return None, None
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    bar = Progress(
        TextColumn("rollouts"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[summary]}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
        console=Console(stderr=True),
        transient=True,
    )
    task = bar.add_task("evaluate", total=total, summary="")
    bar.start()

    def update(state) -> None:
        bar.update(
            task,
            completed=state.done,
            summary=f"{state.successes} ok ({100.0 * state.rate:.1f}%)",
        )

    return update, bar


def _describe_action(problem, actions, index: int) -> str:
    """``action 3 (push paddle)``: 1-based, as in the plan table of ``arrange-up plan``."""
    from arrange_up.model.world import Push

    action = actions[index]
    kind = type(action).__name__.lower()
    who = action.manipulator if isinstance(action, Push) else action.obj
    return f"action {index + 1} ({kind} {who})"


def _failure_lines(problem, actions, failures) -> list[str]:
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
                index = 0 if miss.dimension == "x" else 1
                bound = f"±{units.length_out(tol[index]):g} {units.length}"
            else:
                lines.append(f"    {miss.part} {miss.dimension}: {miss.rollouts}")
                continue
            lines.append(
                f"    {miss.part} {miss.dimension}: {miss.rollouts} (worst {worst} beyond "
                f"the {bound} tolerance)"
            )
    if failures.action_failed:
        lines.append(f"  action failed    {failures.action_failed:>7}")
        for entry in failures.action_failures:
            lines.append(
                f"    {_describe_action(problem, actions, entry.action)}: {entry.rollouts}: "
                f"{entry.reason}"
            )
    if failures.not_at_rest:
        lines.append(f"  not at rest      {failures.not_at_rest:>7}")
        for entry in failures.not_at_rest_actions:
            lines.append(
                f"    {_describe_action(problem, actions, entry.action)}: {entry.rollouts}"
            )
    if failures.off_table:
        lines.append(f"  off table        {failures.off_table:>7}")
        for entry in failures.off_table_actions:
            lines.append(
                f"    {_describe_action(problem, actions, entry.action)}: {entry.object} "
                f"{entry.rollouts}"
            )
    return lines


@main.command()
@click.argument("problem")
@click.argument("plan_file", metavar="PLAN.json", type=click.Path(dir_okay=False))
@click.option(
    "--rollouts",
    type=click.IntRange(1, None),
    default=1000,
    show_default=True,
    help="Noisy executions of the plan.",
)
@click.option(
    "--seed",
    type=click.IntRange(0, None),
    default=0,
    show_default=True,
    help="Rollout i draws its noise from (seed, i): equal seeds give equal results.",
)
@_parallel_options("rollouts")
@click.option(
    "--record",
    type=click.Path(dir_okay=False),
    default=None,
    help="Append every rollout to this .jsonl file as it finishes; re-running with the same "
    "file resumes the evaluation.",
)
@click.option(
    "--json",
    "as_json",
    is_flag=True,
    help="Print a machine-readable summary (JSON) on stdout.",
)
def evaluate(
    problem: str,
    plan_file: str,
    rollouts: int,
    seed: int,
    workers: int | None,
    backend: str | None,
    scheduler: str | None,
    record: str | None,
    as_json: bool,
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
      arrange-up evaluate blocks-4 b4.json --backend dask --scheduler tcp://10.0.0.5:8786

    Exit status: 0 the evaluation ran (whatever the rate), 1 interrupted, 2 bad input.
    """
    import json

    from arrange_up.evaluation.evaluate import RecordFileError, evaluate_plan, plan_hash
    from arrange_up.model.problem import problem_hash
    from arrange_up.parallel import BackendUnavailableError

    backend = _backend_choice(backend, scheduler)
    loaded = _load(problem)
    actions, document = _read_plan_for(loaded, plan_file)
    this_hash = problem_hash(loaded)
    update, bar = _evaluation_progress(rollouts)
    try:
        result = evaluate_plan(
            loaded,
            actions,
            rollouts=rollouts,
            seed=seed,
            workers=workers,
            backend=backend,
            scheduler=scheduler,
            record=record,
            progress=update,
        )
    except KeyboardInterrupt:
        if bar is not None:
            bar.stop()
        kept = f"; the finished rollouts are in {record}: run again to resume" if record else ""
        _fail(f"interrupted{kept}", EXIT_NEGATIVE)
    except (RecordFileError, BackendUnavailableError, ValueError) as error:
        _fail(str(error))
    finally:
        if bar is not None:
            bar.stop()
    low, high = result.interval
    if as_json:
        summary = result.to_json()
        summary.update(
            rollouts=rollouts,
            problem={"name": loaded.name, "hash": this_hash, "source": loaded.source},
            plan={
                "path": plan_file,
                "hash": plan_hash(actions),
                "actions": len(actions),
                "problem": document.get("problem") or None,
            },
            record=record,
        )
        click.echo(json.dumps(summary, indent=2))
        return
    where = f"{result.backend}, {result.workers} worker{'s' if result.workers != 1 else ''}"
    resumed = f", {result.resumed} resumed from {record}" if result.resumed else ""
    click.echo(
        f"{loaded.name}: {result.successes} of {result.trials} rollouts reached the goal: "
        f"{100.0 * result.rate:.1f}% (95% Wilson interval {100.0 * low:.1f}%-{100.0 * high:.1f}%)"
    )
    click.echo(f"seed {seed}, {where}, {result.elapsed:.1f} s{resumed}")
    if result.failures.total:
        click.echo(f"failures: {result.failures.total}")
        for line in _failure_lines(loaded, actions, result.failures):
            click.echo(line)
    if record:
        click.echo(f"rollouts recorded in {record}")


# ---------------------------------------------------------------------------------------------
# repair
# ---------------------------------------------------------------------------------------------
@main.command()
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
    default=150,
    show_default=True,
    help="Particles of the belief the candidates are scored on.",
)
@click.option(
    "--seed",
    type=int,
    default=0,
    show_default=True,
    help="Seed for the particles, the noise and the nominal plan: equal seeds, equal plans.",
)
@click.option(
    "--method",
    type=click.Choice(["naive", "enhanced"]),
    default="enhanced",
    show_default=True,
    help="Candidate placements: the whole workspace grid (naive) or the grid placements that "
    "meet the part motion swath (enhanced).",
)
@click.option(
    "--workers",
    type=click.IntRange(1, 256),
    default=None,
    help="Processes simulating particles (default: all cores).",
)
@click.option(
    "--output",
    "-o",
    type=click.Path(dir_okay=False),
    default=None,
    help="Write the repaired plan file (JSON; semantics 'fixtures', per-step choices under "
    "'repair').",
)
@click.option(
    "--json",
    "as_json",
    is_flag=True,
    help="Print a machine-readable summary (JSON) on stdout instead of the table.",
)
def repair(
    problem: str,
    plan_file: str | None,
    particles: int,
    seed: int,
    method: str,
    workers: int | None,
    output: str | None,
    as_json: bool,
) -> None:
    """Make a nominal plan for PROBLEM robust by placing fixtures (thesis ch. 4).

    Every push of the nominal plan becomes place(fixture), push, pick(fixture) (or stays a
    bare push, with its distance multiplied by 1 to 2) choosing what keeps the particle belief
    closest to the nominal trajectory; place and pick actions stay. See docs/repair.md.

    \b
    Examples:
      arrange-up repair tz-mating --particles 150 --output tz.fixtures.json
      arrange-up repair tz-mating --plan tz.nominal.json --method naive --json

    Exit status: 0 repaired, 1 the repair failed (a step whose every candidate pushes a part
    off the table or never comes to rest), 2 bad input.
    """
    import json

    from arrange_up.io.planfile import PlanFileError, read_plan, write_json_atomic
    from arrange_up.repair import nominal_plans, repair_plan

    loaded = _load(problem)
    if plan_file is not None:
        try:
            nominal, _ = read_plan(plan_file, loaded)
        except PlanFileError as error:
            _fail(str(error))
    else:
        found = nominal_plans(loaded, 1, seed)
        if not found:
            _fail("the deterministic planner found no nominal plan to repair", EXIT_NEGATIVE)
        nominal = found[0]
    if workers is None:
        from arrange_up.parallel import available_cores

        workers = available_cores()
    interactive = sys.stderr.isatty()

    def progress(info: dict) -> None:
        if info["phase"] == "done":
            click.echo(
                f"step {info['step']}/{info['steps']} {info['kind']}: {info['choice']} "
                f"({info['elapsed']:.1f} s)",
                err=True,
            )
        elif info["phase"] == "placements":
            click.echo(
                f"step {info['step']}/{info['steps']} push: scoring {info['candidates']} "
                "candidates…",
                err=True,
            )

    try:
        result = repair_plan(
            loaded,
            nominal,
            particles=particles,
            seed=seed,
            method=method,
            workers=workers,
            progress=progress if interactive else None,
        )
    except KeyboardInterrupt:
        _fail("interrupted; no plan was written", EXIT_NEGATIVE)
    except ValueError as error:
        _fail(str(error))
    document = result.document(loaded)
    if output:
        write_json_atomic(Path(output), document)
    if as_json:
        summary = {k: v for k, v in document.items() if k != "actions"}
        summary["reason"] = result.reason or None
        summary["actions"] = document.get("actions")
        summary["output"] = output
        click.echo(json.dumps(summary, indent=2))
    else:
        stats = result.stats()
        click.echo(
            f"{loaded.name}: {result.status} ({method}, {particles} particles, seed {seed}) in "
            f"{result.elapsed:.1f} s: {stats['pushes']} pushes, {stats['fixtures_placed']} "
            f"fixtures placed, {result.simulations} simulations"
        )
        if result.reason:
            click.echo(f"reason: {result.reason}")
        for record in result.steps:
            if record.kind != "push":
                click.echo(f"  step {record.index + 1}: {record.kind} kept")
                continue
            chosen = "every candidate invalid"
            if record.status == "ok":
                where = (
                    "no fixture"
                    if record.pose is None
                    else f"{record.fixture} at "
                    + ", ".join(f"{v:.3g}" for v in loaded.units.pose_out(record.pose))
                )
                chosen = (
                    f"{where}, push x{record.multiplier:g}: distance {record.distance:.3f} "
                    f"(bare push {record.nominal_distance:.3f})"
                )
            click.echo(f"  step {record.index + 1}: {chosen}")
        if result.actions is not None:
            click.echo(_actions_table(loaded, result.actions))
        if output:
            click.echo(f"wrote {output}")
    if not result.solved:
        sys.exit(EXIT_NEGATIVE)


def _training_progress():
    """A progress bar for CBST training on a terminal (stderr), else nothing."""
    if not sys.stderr.isatty():
        return None, None
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    bar = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
        console=Console(stderr=True),
        transient=True,
    )
    tasks: dict[str, Any] = {}
    bar.start()

    def update(stage: str, done: int, total: int) -> None:
        if stage not in tasks:
            label = {"data": "examples", "fit": "grid search"}.get(stage, stage)
            tasks[stage] = bar.add_task(label, total=total)
        bar.update(tasks[stage], completed=done)

    return update, bar


@main.command("train-cbst")
@click.option(
    "--examples",
    type=click.IntRange(10, None),
    default=1800,
    show_default=True,
    help="Random interval beliefs (thesis: 1800).",
)
@click.option(
    "--rollouts-per-example",
    type=click.IntRange(1, None),
    default=100,
    show_default=True,
    help="Simulated pushes per example (thesis: 1000, ~45 min on 2 cores here; the "
    "shipped model used 100, ~6 min).",
)
@click.option(
    "--seed",
    type=click.IntRange(0, None),
    default=0,
    show_default=True,
    help="Example i depends only on (seed, i); also seeds the split and the forest.",
)
@_parallel_options("examples")
@click.option(
    "--output-dir",
    type=click.Path(file_okay=False),
    default="cbst-model",
    show_default=True,
    help="Where NAME.npz and NAME.json go (semantics/cbst ships the default).",
)
@click.option(
    "--name", default="default", show_default=True, help="Model name, as load_model(NAME) finds it."
)
@click.option(
    "--data",
    "data_path",
    type=click.Path(dir_okay=False),
    default=None,
    help="Resumable .jsonl data file (default OUTPUT_DIR/NAME.data.jsonl).",
)
@click.option("--json", "as_json", is_flag=True, help="Print the model card (JSON) on stdout.")
def train_cbst(
    examples,
    rollouts_per_example,
    seed,
    workers,
    backend,
    scheduler,
    output_dir,
    name,
    data_path,
    as_json,
) -> None:
    """Generate CBST training data, then tune, evaluate and save its push model (thesis §3.2).

    Re-running with the same --data file resumes: examples already there are skipped.

    \b
    Example:
      arrange-up train-cbst --examples 1800 --rollouts-per-example 100 --output-dir my-model
    """
    import json

    from arrange_up.cbst.model import train_cbst as run
    from arrange_up.parallel import BackendUnavailableError

    backend = _backend_choice(backend, scheduler)
    update, bar = _training_progress()
    try:
        card = run(
            examples=examples,
            rollouts_per_example=rollouts_per_example,
            seed=seed,
            workers=workers,
            output_dir=output_dir,
            backend=backend,
            scheduler=scheduler,
            name=name,
            data_path=data_path,
            progress=update,
        )
    except KeyboardInterrupt:
        _fail(
            "interrupted; finished examples are kept in the data file: run again to resume",
            EXIT_NEGATIVE,
        )
    except (ValueError, BackendUnavailableError) as err:
        _fail(str(err))
    finally:
        if bar is not None:
            bar.stop()
    if as_json:
        click.echo(json.dumps(card, indent=2))
        return
    scores = card["scores"]
    for target, unit in (("dx", "in"), ("dy", "in"), ("dth", "deg"), ("slip", "in")):
        thesis = scores["thesis_test_rmse"].get(target)
        click.echo(
            f"{target:>4}: test RMSE {scores['test_rmse'][target]:.4f} {unit} "
            f"(8-fold CV {scores['cv_rmse'][target]:.4f}"
            + (f"; thesis {thesis}" if thesis is not None else "")
            + ")"
        )
    click.echo(
        f"saved {output_dir}/{name}.npz + {name}.json ({card['data']['examples']} "
        f"examples x {card['data']['rollouts_per_example']} rollouts, "
        f"{card['training_seconds']:.0f} s)"
    )


@main.group()
def experiment() -> None:
    """Reproduce the thesis's experiments (CSV of every measurement + PNG summary).

    Results are appended as they are measured; re-running the same command resumes, skipping
    what the CSV already holds.
    """


def _say(message: str) -> None:
    click.echo(f"[{time.strftime('%H:%M:%S')}] {message}", err=True)


@experiment.command("transition-comparison")
@click.option(
    "--problems", default="blocks-4,blocks-7", show_default=True, help="Comma-separated problems."
)
@click.option(
    "--particles",
    "particle_counts",
    default="5,25,50",
    show_default=True,
    help="Comma-separated particle counts of the particle planners.",
)
@click.option(
    "--semantics",
    "extra",
    default=None,
    help="Comma-separated further semantics (default: every other registered one).",
)
@click.option(
    "--runs",
    type=click.IntRange(1, 1000),
    default=10,
    show_default=True,
    help="Planning runs (seeds 0..R-1) per problem and planner.",
)
@click.option(
    "--rollouts",
    type=click.IntRange(0, 1_000_000),
    default=1000,
    show_default=True,
    help="Noisy rollouts per plan (0: no evaluation).",
)
@click.option("--max-nodes", type=click.IntRange(1, None), default=5000, show_default=True)
@click.option(
    "--timeout",
    type=click.FloatRange(0, None, min_open=True),
    default=None,
    help="Planning time limit per run, seconds.",
)
@click.option(
    "--workers",
    type=click.IntRange(1, 256),
    default=None,
    help="Worker processes (default: all cores).",
)
@click.option(
    "--output-dir", type=click.Path(file_okay=False), default="results", show_default=True
)
def experiment_transition_comparison(
    problems, particle_counts, extra, runs, rollouts, max_nodes, timeout, workers, output_dir
) -> None:
    """Figures 3-6 and 3-7: planning time and reliability of each belief transition."""
    from arrange_up.experiments.planning import Planner, default_planners, transition_comparison
    from arrange_up.transitions import available

    try:
        counts = [int(n) for n in particle_counts.split(",") if n]
    except ValueError:
        _fail(f"--particles: expected comma-separated integers, got {particle_counts!r}")
    planners = [
        p for p in default_planners(counts) if p.semantics in ("deterministic", "particles")
    ]
    names = (
        extra.split(",")
        if extra
        else [n for n in available() if n not in ("deterministic", "particles")]
    )
    for name in names:
        if name not in available():
            _fail(
                f"--semantics: unknown semantics {name!r}; expected one of {', '.join(available())}"
            )
        planners.append(Planner(name, name, 1))
    for name in problems.split(","):
        _load(name)  # refuse bad problems before hours of work
    path = transition_comparison(
        Path(output_dir),
        problems=problems.split(","),
        planners=planners,
        runs=runs,
        rollouts=rollouts,
        max_nodes=max_nodes,
        timeout=timeout,
        workers=workers,
        progress=_say,
    )
    click.echo(f"wrote {path} and {path.with_suffix('.png')}")


@experiment.command("search-table")
@click.option(
    "--problems",
    default="blocks-1,blocks-2,blocks-3,blocks-4,blocks-7",
    show_default=True,
    help="Comma-separated problems.",
)
@click.option(
    "--semantics",
    default=None,
    help="Belief transition (default: cbst when available, as in the thesis; else deterministic).",
)
@click.option("--particles", type=click.IntRange(1, 100_000), default=1, show_default=True)
@click.option("--max-nodes", type=click.IntRange(1, None), default=5000, show_default=True)
@click.option(
    "--weight",
    type=click.FloatRange(0, None),
    default=1.0,
    show_default=True,
    help="1 = A*, as in the thesis's table.",
)
@click.option(
    "--timeout",
    type=click.FloatRange(0, None, min_open=True),
    default=None,
    help="Time limit per search, seconds.",
)
@click.option(
    "--output-dir", type=click.Path(file_okay=False), default="results", show_default=True
)
def experiment_search_table(
    problems, semantics, particles, max_nodes, weight, timeout, output_dir
) -> None:
    """Table 3.1: nodes expanded and plan cost for each heuristic, with and without
    domination."""
    from arrange_up.experiments.planning import search_table
    from arrange_up.transitions import available

    if semantics is None:
        semantics = "cbst" if "cbst" in available() else "deterministic"
    if semantics not in available():
        _fail(
            f"--semantics: unknown semantics {semantics!r}; expected one of "
            f"{', '.join(available())}"
        )
    for name in problems.split(","):
        _load(name)
    path = search_table(
        Path(output_dir),
        problems=problems.split(","),
        semantics=semantics,
        particles=particles,
        max_nodes=max_nodes,
        weight=weight,
        timeout=timeout,
        progress=_say,
    )
    click.echo(f"wrote {path} and {path.parent / f'search-table-{semantics}.png'}")


@experiment.command("fixtures")
@click.option(
    "--problems",
    default="down-push,tt-mating,tz-mating,tt-mating-noisy,create-a-t",
    show_default=True,
    help="Comma-separated problems (names or .yaml paths).",
)
@click.option(
    "--plans",
    type=click.IntRange(1, 1000),
    default=20,
    show_default=True,
    help="Distinct nominal plans per problem (thesis: 20).",
)
@click.option(
    "--particles",
    "particle_counts",
    default="10,20,40,80,150",
    show_default=True,
    help="Comma-separated particle counts; every nominal plan is repaired once per count.",
)
@click.option(
    "--rollouts",
    type=click.IntRange(0, 1_000_000),
    default=1000,
    show_default=True,
    help="Noisy rollouts per nominal and per repaired plan (0: no evaluation).",
)
@click.option(
    "--seed",
    type=click.IntRange(0, None),
    default=0,
    show_default=True,
    help="Seeds the nominal plans, the repairs' particles and noise, and the rollouts.",
)
@click.option(
    "--method",
    type=click.Choice(["naive", "enhanced"]),
    default="enhanced",
    show_default=True,
    help="Candidate placements of the repair (see 'arrange-up repair --help').",
)
@click.option(
    "--timeout",
    type=click.FloatRange(0, None, min_open=True),
    default=None,
    help="Time limit per repair, seconds (the thesis allowed 24 hours); a repair that reaches "
    "it is recorded with status 'timeout'.",
)
@_parallel_options("rollouts")
@click.option(
    "--output-dir",
    type=click.Path(file_okay=False),
    default="results",
    show_default=True,
    help="Where fixtures.csv and the PNGs go; a fixtures.csv already there is resumed.",
)
def experiment_fixtures(
    problems,
    plans,
    particle_counts,
    rollouts,
    seed,
    method,
    timeout,
    workers,
    backend,
    scheduler,
    output_dir,
) -> None:
    """Figures 4-14 to 4-25: reliability of nominal plans before and after fixture repair.

    For each problem: --plans distinct nominal (deterministic) plans; each is evaluated over
    --rollouts noisy rollouts, then repaired once per --particles count (arrange-up repair)
    and the repaired plan evaluated on the same rollouts. --workers processes run both the
    repairs and the rollouts (on 2 cores, --workers 1 was the faster: with up to 150
    particles a repair's process pool costs more than it saves); --backend/--scheduler apply
    to the rollouts only.

    \b
    Writes into --output-dir:
      fixtures.csv             one row per measurement: the nominal plan, or one repair
      fixtures-overview.png    mean reliability, nominal vs repaired (Figure 4-14)
      fixtures-PROBLEM.png     reliability, repair time and plan length vs particles
                               (Figures 4-16 to 4-25)
    and prints a Markdown summary table on stdout; progress lines go to stderr.

    Nothing is skipped silently: a plan the deterministic planner cannot find is a row with
    status 'no-plan', a repair that fails or times out is a row with that status and its
    reason (and no evaluation).

    Rows are written as they are measured, and rerunning resumes: rows already in the CSV
    (same problem, seed, plan, particles, method) are not measured again, whatever
    --rollouts. So you can interrupt a run, or grow --plans and --particles later.

    \b
    Examples:
      arrange-up experiment fixtures --problems tz-mating --plans 2 --particles 10,40 \\
          --rollouts 100 --output-dir tz-quick
      arrange-up experiment fixtures --plans 5 --particles 10,40,150 --workers 1 \\
          --output-dir docs/results      # docs/results.md: ~32 min on 2 cores
      arrange-up experiment fixtures --workers 1   # thesis scale: ~2-3 h on 2 cores (est.)

    Exit status: 0 the sweep ran (whatever the results), 1 interrupted, 2 bad input or a CSV
    measured on other nominal plans.
    """
    from arrange_up.experiments.fixtures import (
        StaleResultsError,
        fixture_experiment,
        markdown_table,
        read_rows,
        select_rows,
        summarize,
    )
    from arrange_up.parallel import BackendUnavailableError

    backend = _backend_choice(backend, scheduler)
    try:
        counts = [int(n) for n in particle_counts.split(",") if n.strip()]
    except ValueError:
        _fail(f"--particles: expected comma-separated integers, got {particle_counts!r}")
    if not counts or any(n < 1 for n in counts):
        _fail(f"--particles: expected positive integers, got {particle_counts!r}")
    names = [n.strip() for n in problems.split(",") if n.strip()]
    if not names:
        _fail("--problems: expected at least one problem")
    for name in names:
        _load(name)  # refuse bad problems before hours of work
    try:
        path = fixture_experiment(
            Path(output_dir),
            problems=names,
            plans=plans,
            particles=counts,
            rollouts=rollouts,
            seed=seed,
            method=method,
            timeout=timeout,
            workers=workers,
            backend=backend,
            scheduler=scheduler,
            progress=_say,
        )
    except KeyboardInterrupt:
        _fail(
            f"interrupted; the rows measured so far are in {Path(output_dir) / 'fixtures.csv'}: "
            "run again to resume",
            EXIT_NEGATIVE,
        )
    except (StaleResultsError, BackendUnavailableError, ValueError) as error:
        _fail(str(error))
    rows = select_rows(
        read_rows(path), problems=names, plans=plans, particles=counts, seed=seed, method=method
    )
    click.echo(markdown_table(summarize(rows)))
    click.echo(f"wrote {path} and {path.parent / 'fixtures-*.png'}")


@main.group()
def bench() -> None:
    """Measure the speed of the building blocks (figures printed, nothing written)."""


@bench.command("physics")
@click.option(
    "--pushes",
    type=click.IntRange(10, 1_000_000),
    default=300,
    show_default=True,
    help="Pushes simulated per scene and worker count.",
)
@click.option(
    "--workers",
    type=str,
    default="1,2",
    show_default=True,
    help="Comma-separated process counts to measure.",
)
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
    from arrange_up.physics.bench import bench_physics

    rows = bench_physics(
        n_pushes=pushes, workers=counts, seed=seed, progress=lambda msg: click.echo(msg, err=True)
    )
    click.echo(
        f"{'scene':<16} {'workers':>7} {'pushes':>7} {'seconds':>8} {'pushes/s':>9} "
        f"{'ms/push':>8} {'not at rest':>11}"
    )
    for row in rows:
        click.echo(
            f"{row['scene']:<16} {row['workers']:>7} {row['pushes']:>7} "
            f"{row['seconds']:>8.2f} {row['pushes_per_second']:>9.0f} "
            f"{row['ms_per_push']:>8.2f} {row['not_at_rest']:>11}"
        )


if __name__ == "__main__":  # pragma: no cover
    main()
