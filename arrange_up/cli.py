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
    """Validate problem FILES (.yaml, or .pddl of the arrange-up domain).

    Every problem in every file is reported at once, as FILE:LINE:COL: severity: key.path:
    message. Exits 1 if any file has errors, 0 otherwise (warnings do not fail).
    """
    from arrange_up.loader import check_problem

    def check_any(file: str):
        if Path(file).suffix.lower() != ".pddl":
            return check_problem(file)
        from arrange_up.errors import ProblemFormatError
        from arrange_up.pddl import load_pddl_problem

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
    from arrange_up.domains import list_domains

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
def show(problem: str, output: str, dpi: int) -> None:
    """Draw PROBLEM: table, walls, obstacles, parts with their belief shadows, and the goal.

    PROBLEM is a .yaml file or a shipped domain's name.
    """
    from arrange_up.render import draw_problem

    loaded = _load(problem)
    path = draw_problem(loaded, Path(output), dpi=dpi)
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
    from arrange_up.planfile import action_to_json

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
    help="Belief transition: deterministic (nominal, one particle, no noise) or "
    "particles (thesis §3.1).",
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

    from arrange_up.planfile import plan_document, write_json_atomic
    from arrange_up.planner import plan as run_plan
    from arrange_up.transitions import available

    if semantics not in available():
        _fail(
            f"--semantics: unknown semantics {semantics!r}; expected one of "
            f"{', '.join(available())}"
        )
    loaded = _load(problem)
    if workers is None:
        from arrange_up.transitions.particles import default_workers

        workers = 1 if semantics == "deterministic" else default_workers()
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
    from arrange_up.pddl import PddlExportError, write_pddl_problem

    loaded = _load(problem)
    try:
        text = write_pddl_problem(loaded)
    except PddlExportError as error:
        _fail(str(error), EXIT_NEGATIVE)
    from arrange_up.planfile import write_text_atomic

    write_text_atomic(Path(output), text)
    click.echo(f"wrote {output}")


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
    from arrange_up.bench import bench_physics

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
