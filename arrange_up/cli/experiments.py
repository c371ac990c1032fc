"""The ``experiment`` commands: the thesis's experiments, resumable, as CSV and PNG.

Every command prints, before it starts, how many measurements it will make and about how long
they take (from the measured costs of :mod:`arrange_up.experiments.costs`), then a line per
measurement as it is made (on a terminal, a live line with the count and the elapsed time, the
finished measurements printed above it), and at the end the result table on stdout.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, TypeVar

import click
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
)

from arrange_up.cli.shared import (
    EXIT_NEGATIVE,
    FiniteFloat,
    OutputDir,
    backend_choice,
    check_semantics,
    comma_integers,
    comma_separated,
    fail,
    library_default,
    load_problem,
    parallel_options,
    quiet_option,
    seed_option,
    stopped_early,
    terminal_progress,
    timeout_option,
    workers_option,
)
from arrange_up.evaluation.evaluate import MAX_ROLLOUTS
from arrange_up.experiments import costs
from arrange_up.experiments.csv_records import CsvRecordsError, read_csv
from arrange_up.experiments.fixtures import (
    CSV_NAME,
    DEFAULT_PARTICLES,
    DEFAULT_PROBLEMS,
    StaleResultsError,
    fixture_experiment,
    markdown_table,
    pending_rows,
    read_rows,
    select_rows,
    summarize,
)
from arrange_up.experiments.planning import (
    SEARCH_TYPES,
    Planner,
    default_planners,
    pending_searches,
    pending_transition_runs,
    search_markdown,
    search_table,
    select_search_rows,
    select_transition_rows,
    transition_comparison,
    transition_markdown,
)
from arrange_up.model.problem import ControllerKind
from arrange_up.parallel import BackendUnavailableError, RunnerConfig, WorkersLostError
from arrange_up.repair import METHODS
from arrange_up.transitions import available

#: What a pending-measurements function returns.
_Pending = TypeVar("_Pending")

#: The semantics whose planners --particles makes; --semantics names the others.
_PARTICLE_PLANNERS = ("deterministic", "particles")


@click.group()
def experiment() -> None:
    """Reproduce the thesis's experiments (CSV of every measurement + PNG summary).

    Results are appended as they are measured; re-running the same command resumes, skipping
    what the CSV already holds. Each command first prints how many measurements it will make
    and about how long they take (from measured costs), then a line per measurement as it
    ends, and the result table on stdout at the end.
    """


def _controller_option(function: Any) -> Any:
    """``--controller``: the controller kind every problem of the experiment is driven by."""
    return click.option(
        "--controller",
        type=click.Choice([kind.value for kind in ControllerKind]),
        default=None,
        help="Drive every problem with this push controller at its defaults (default: each "
        "problem's own, compliant for the shipped ones). Recorded in every row and in the "
        "CSV's settings: a CSV measured under another controller is refused.",
    )(function)


def _say(message: str) -> None:
    click.echo(f"[{time.strftime('%H:%M:%S')}] {message}", err=True)


class _Measurements:
    """Progress per measurement: ``say`` a stage, ``done`` a finished measurement (counted, with
    the elapsed time and, from the pace so far, the time left). ``opening`` (the duration
    estimate) is printed before the first of them: the experiment reports its first stage only
    after it has accepted its CSV, so a CSV it refuses is not preceded by an estimate of work
    that will not be done. On a terminal the lines go above the live display; otherwise they
    are lines on stderr, and the display (a :class:`~arrange_up.cli.shared.LineProgress`)
    repeats the current stage every few seconds while a measurement runs; ``quiet``: nothing."""

    def __init__(self, display: Any, total: int, opening: str, quiet: bool = False) -> None:
        self.display, self.total, self.count = display, total, 0
        self.quiet = quiet
        self.live = isinstance(display, Progress)
        self.opening: str | None = opening
        self.started = time.perf_counter()
        self.task = display.add_task("starting", total=total) if display is not None else None

    def _print(self, line: str) -> None:
        if self.quiet:
            return
        if self.live:
            self.display.console.print(f"[{time.strftime('%H:%M:%S')}] {line}", highlight=False)
        else:
            _say(line)

    def _open(self) -> None:
        if self.opening is None:
            return
        self._print(self.opening)
        self.opening = None

    def say(self, message: str) -> None:
        self._open()
        if self.display is not None:
            self.display.update(self.task, description=message)
        if not self.live:
            self._print(message)

    def done(self, line: str) -> None:
        self._open()
        self.count += 1
        elapsed = time.perf_counter() - self.started
        left = elapsed / self.count * max(0, self.total - self.count)
        pace = f"{self.count}/{self.total} done, {costs.format_duration(elapsed)} elapsed"
        if self.count < self.total:
            pace += f", about {costs.format_duration(left)} left"
        self._print(line if self.live else f"{line} [{pace}]")
        if self.display is not None:
            self.display.update(self.task, completed=self.count)


@contextmanager
def _measurements(
    estimate: costs.Estimate, total: int, what: str, quiet: bool = False
) -> Iterator[_Measurements]:
    """Report each measurement of the experiment ``what`` (the CLI's progress display on a
    terminal, lines on stderr otherwise, nothing when ``quiet``), after the duration
    estimate."""
    columns = (
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
    )
    with terminal_progress(*columns, what=f"experiment {what}", quiet=quiet) as display:
        yield _Measurements(display, total, f"estimate: {estimate.describe(total)}", quiet)


def _transition_line(row: dict[str, Any]) -> str:
    """One finished planning run (and its evaluation), saying how it ended."""
    head = f"{row['problem']} {row['planner']} run {int(row['run']) + 1}"
    seconds, nodes = row["planning_seconds"], row["expanded"]
    if not row["solved"]:
        ended = "node limit" if row["status"] == "node-limit" else row["status"]
        return f"{head}: no plan: {ended} after {nodes} nodes, {seconds} s"
    line = f"{head}: solved in {seconds} s, {nodes} nodes, {row['plan_length']} actions"
    if row["rollouts"] != "":
        line += f"; {row['successes']}/{row['rollouts']} rollouts reached the goal"
    return line


def _search_line(row: dict[str, Any]) -> str:
    head = f"{row['search']} domination={row['domination']} {row['problem']}"
    if not row["solved"]:
        ended = "node limit" if row["status"] == "node-limit" else row["status"]
        return f"{head}: no plan: {ended} after {row['expanded']} nodes, {row['seconds']} s"
    return f"{head}: solved, {row['expanded']} nodes, cost {row['cost']}, {row['seconds']} s"


def _fixture_line(row: dict[str, Any]) -> str:
    what = f"{row['problem']} plan {int(row['plan']) + 1} {row['stage']}"
    if row["particles"] != "":
        what += f" ({row['particles']} particles)"
    line = f"{what}: {row['status']}"
    if row["reason"]:
        line += f" ({row['reason']})"
    if row.get("rollouts", "") != "":
        line += f"; {row['successes']}/{row['rollouts']} rollouts reached the goal"
    return line


def _problem_names(problems: str) -> list[str]:
    """The comma-separated ``--problems``; exit 2 when there is none, or on the first that
    does not load, before hours of work."""
    names = [n.strip() for n in problems.split(",") if n.strip()]
    if not names:
        fail("--problems: expected at least one problem")
    for name in names:
        load_problem(name)
    return names


def _resumed(pending: Callable[[], _Pending]) -> _Pending:
    """What ``pending`` lists as still to measure, read from a CSV that may be resumed; a CSV
    that cannot be (other columns, bytes that are not UTF-8, ...) ends the command by the
    error contract (one line, exit 2)."""
    try:
        return pending()
    except CsvRecordsError as error:
        fail(str(error))


def _interrupted(csv: Path) -> None:
    """Exit 1 after Ctrl-C, saying where the rows measured so far are."""
    fail(f"interrupted; the rows measured so far are in {csv}: run again to resume", EXIT_NEGATIVE)


def _workers_lost(error: WorkersLostError, csv: Path) -> None:
    """Exit 1 after the workers were lost, saying where the rows so far are and what resumes."""
    stopped_early(error, f"; the rows measured so far are in {csv}: run again to resume")


def _output_dir_option(csv: str) -> Any:
    """``--output-dir`` of an experiment that writes ``csv`` and its picture there."""
    return click.option(
        "--output-dir",
        type=OutputDir(),
        default="results",
        show_default=True,
        help=f"Where {csv} and its picture go; a {csv} already there is resumed.",
    )


@experiment.command("transition-comparison")
@click.option(
    "--problems",
    default=comma_separated(library_default(transition_comparison, "problems")),
    show_default=True,
    help="Comma-separated problems.",
)
@click.option(
    "--particles",
    "particle_counts",
    default=comma_separated(library_default(default_planners, "particle_counts")),
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
    default=library_default(transition_comparison, "runs"),
    show_default=True,
    help="Planning runs (seeds 0..R-1) per problem and planner.",
)
@click.option(
    "--rollouts",
    type=click.IntRange(0, MAX_ROLLOUTS),
    default=library_default(transition_comparison, "rollouts"),
    show_default=True,
    help="Noisy rollouts per plan (0: no evaluation).",
)
@click.option(
    "--max-nodes",
    type=click.IntRange(1, None),
    default=library_default(transition_comparison, "max_nodes"),
    show_default=True,
    help="Node limit of each planning run.",
)
@timeout_option("Planning time limit per run, seconds.")
@workers_option("Worker processes (default: all cores).")
@_controller_option
@_output_dir_option("transition-comparison.csv")
@quiet_option()
def experiment_transition_comparison(
    problems: str,
    particle_counts: str,
    extra: str | None,
    runs: int,
    rollouts: int,
    max_nodes: int,
    timeout: float | None,
    workers: int | None,
    controller: str | None,
    output_dir: str,
    quiet: bool,
) -> None:
    """Figures 3-6 and 3-7: planning time and reliability of each belief transition.

    For each problem and planner (the particle planners of --particles, and the other
    semantics), --runs planning runs with seeds 0..R-1, each plan evaluated over --rollouts
    noisy rollouts.

    \b
    Writes into --output-dir:
      transition-comparison.csv   one row per planning run (and its evaluation)
      transition-comparison.png   planning time and reliability per planner
    and prints a Markdown table on stdout; progress lines go to stderr. Rows are written as
    they are measured, and rerunning resumes (grow --runs or --problems later); a CSV measured
    with other settings (--rollouts, --max-nodes, --timeout, --controller) is refused.

    \b
    Example:
      arrange-up experiment transition-comparison --problems blocks-1,blocks-2 \\
          --particles 5 --runs 2 --rollouts 100 --output-dir tc

    Exit status: 0 the runs were made (whatever they found), 1 interrupted, 2 bad input or a
    CSV of other settings.
    """
    counts = comma_integers("--particles", particle_counts)
    planners = [p for p in default_planners(counts) if p.semantics in _PARTICLE_PLANNERS]
    names = extra.split(",") if extra else [n for n in available() if n not in _PARTICLE_PLANNERS]
    for name in names:
        check_semantics(name)
        planners.append(Planner(name, name, 1))
    names = _problem_names(problems)
    pending = _resumed(lambda: pending_transition_runs(Path(output_dir), names, planners, runs))
    estimate = costs.Estimate()
    for name, label, _run in pending:
        planning = costs.planning_cost(name, label, max_nodes)
        if planning is not None and timeout is not None:
            planning = min(planning, timeout)
        evaluation = costs.rollout_cost(name, rollouts)
        total = None if planning is None or evaluation is None else planning + evaluation
        estimate.add(total, f"{name} {label}")
    try:
        with _measurements(estimate, len(pending), "transition-comparison", quiet) as report:
            path = transition_comparison(
                Path(output_dir),
                problems=names,
                planners=planners,
                runs=runs,
                rollouts=rollouts,
                max_nodes=max_nodes,
                timeout=timeout,
                workers=workers,
                controller=controller,
                progress=report.say,
                measured=lambda row: report.done(_transition_line(row)),
            )
    except KeyboardInterrupt:
        _interrupted(Path(output_dir) / "transition-comparison.csv")
    except WorkersLostError as error:
        _workers_lost(error, Path(output_dir) / "transition-comparison.csv")
    except CsvRecordsError as error:
        fail(str(error))
    rows = select_transition_rows(read_csv(path), names, [p.label for p in planners], runs)
    click.echo(transition_markdown(rows))
    click.echo(f"wrote {path} and {path.with_suffix('.png')}")


@experiment.command("search-table")
@click.option(
    "--problems",
    default=comma_separated(library_default(search_table, "problems")),
    show_default=True,
    help="Comma-separated problems.",
)
@click.option(
    "--semantics",
    default=None,
    help="Belief transition (default: cbst when available, as in the thesis; else deterministic).",
)
@click.option(
    "--particles",
    type=click.IntRange(1, 100_000),
    default=library_default(search_table, "particles"),
    show_default=True,
    help="Particles per belief, for the particles semantics.",
)
@click.option(
    "--max-nodes",
    type=click.IntRange(1, None),
    default=library_default(search_table, "max_nodes"),
    show_default=True,
    help="Node limit of each search.",
)
@click.option(
    "--weight",
    type=FiniteFloat(0, None),
    default=library_default(search_table, "weight"),
    show_default=True,
    help="f = g + weight * h: 1 = A*, as in the thesis's table; more is greedier; 0 ignores "
    "the heuristic (uniform-cost search).",
)
@timeout_option("Time limit per search, seconds.")
@_controller_option
@_output_dir_option("search-table.csv")
@quiet_option()
def experiment_search_table(
    problems: str,
    semantics: str | None,
    particles: int,
    max_nodes: int,
    weight: float,
    timeout: float | None,
    controller: str | None,
    output_dir: str,
    quiet: bool,
) -> None:
    """Table 3.1: nodes expanded and plan cost for each heuristic, with and without
    domination.

    \b
    Writes into --output-dir:
      search-table.csv              one row per search
      search-table-SEMANTICS.png    nodes expanded per search type
    and prints a Markdown table on stdout; progress lines go to stderr. Rows are written as
    they are measured, and rerunning resumes; a CSV measured with other settings
    (--particles, --max-nodes, --weight, --timeout, --controller) is refused.

    \b
    Example:
      arrange-up experiment search-table --problems blocks-1,blocks-2 \\
          --semantics deterministic --output-dir st

    Exit status: 0 the searches ran (whatever they found), 1 interrupted, 2 bad input or a CSV
    of other settings.
    """
    if semantics is None:
        semantics = "cbst" if "cbst" in available() else "deterministic"
    check_semantics(semantics)
    names = _problem_names(problems)
    pending = _resumed(lambda: pending_searches(Path(output_dir), names, semantics))
    estimate = costs.Estimate()
    for k, domination, name in pending:
        cost = costs.search_cost(semantics, name, k, domination, max_nodes)
        if cost is not None and timeout is not None:
            cost = min(cost, timeout)
        if particles != library_default(search_table, "particles") or weight != 1.0:
            cost = None  # measured with one particle and A* only
        estimate.add(cost, f"{SEARCH_TYPES[k][0]} {name}")
    try:
        with _measurements(estimate, len(pending), "search-table", quiet) as report:
            path = search_table(
                Path(output_dir),
                problems=names,
                semantics=semantics,
                particles=particles,
                max_nodes=max_nodes,
                weight=weight,
                timeout=timeout,
                controller=controller,
                progress=report.say,
                measured=lambda row: report.done(_search_line(row)),
            )
    except KeyboardInterrupt:
        _interrupted(Path(output_dir) / "search-table.csv")
    except WorkersLostError as error:
        _workers_lost(error, Path(output_dir) / "search-table.csv")
    except CsvRecordsError as error:
        fail(str(error))
    click.echo(search_markdown(select_search_rows(read_csv(path), names, semantics)))
    click.echo(f"wrote {path} and {path.parent / f'search-table-{semantics}.png'}")


@experiment.command("fixtures")
@click.option(
    "--problems",
    default=comma_separated(DEFAULT_PROBLEMS),
    show_default=True,
    help="Comma-separated problems (names or .yaml paths).",
)
@click.option(
    "--plans",
    type=click.IntRange(1, 1000),
    default=library_default(fixture_experiment, "plans"),
    show_default=True,
    help="Distinct nominal plans per problem (thesis: 20).",
)
@click.option(
    "--particles",
    "particle_counts",
    default=comma_separated(DEFAULT_PARTICLES),
    show_default=True,
    help="Comma-separated particle counts; every nominal plan is repaired once per count.",
)
@click.option(
    "--rollouts",
    type=click.IntRange(0, MAX_ROLLOUTS),
    default=library_default(fixture_experiment, "rollouts"),
    show_default=True,
    help="Noisy rollouts per nominal and per repaired plan (0: no evaluation).",
)
@seed_option("Seeds the nominal plans, the repairs' particles and noise, and the rollouts.")
@click.option(
    "--method",
    type=click.Choice(METHODS),
    default=library_default(fixture_experiment, "method"),
    show_default=True,
    help="Candidate placements of the repair (see 'arrange-up repair --help').",
)
@timeout_option(
    "Time limit per repair, seconds (the thesis allowed 24 hours); a repair that reaches "
    "it is recorded with status 'timeout'."
)
@click.option(
    "--ablation/--no-ablation",
    default=library_default(fixture_experiment, "ablation"),
    show_default=True,
    help="Also run each repair without fixtures (the same particles, method and seed; only "
    "the approach back-off and the push multipliers: 'arrange-up repair --no-fixtures') and "
    "evaluate it on the same rollouts, so that the fixtures' own share of the gain is a number.",
)
@_controller_option
@parallel_options("rollouts")
@click.option(
    "--output-dir",
    type=OutputDir(),
    default="results",
    show_default=True,
    help="Where fixtures.csv and the PNGs go; a fixtures.csv already there is resumed.",
)
@quiet_option()
def experiment_fixtures(
    problems: str,
    plans: int,
    particle_counts: str,
    rollouts: int,
    seed: int,
    method: str,
    timeout: float | None,
    ablation: bool,
    controller: str | None,
    workers: int | None,
    backend: str | None,
    scheduler: str | None,
    output_dir: str,
    quiet: bool,
) -> None:
    """Figures 4-14 to 4-25: reliability of nominal plans before and after fixture repair.

    For each problem: --plans distinct nominal (deterministic) plans; each is evaluated over
    --rollouts noisy rollouts, then repaired once per --particles count (arrange-up repair)
    and the repaired plan evaluated on the same rollouts; unless --no-ablation, each repair
    is run again without fixtures (arrange-up repair --no-fixtures) and evaluated on the same
    rollouts too, and the table says how much the fixtures themselves add. --workers
    processes run both the repairs and the rollouts (on 2 cores, --workers 1 was the faster:
    with up to 150 particles a repair's process pool costs more than it saves);
    --backend/--scheduler apply to the rollouts only. --controller drives every problem with
    that controller (default: its own).

    \b
    Writes into --output-dir:
      fixtures.csv             one row per measurement: the nominal plan, one repair, or
                               one repair without fixtures (stage 'ablation')
      fixtures-overview.png    mean reliability, nominal vs repaired (Figure 4-14)
      fixtures-PROBLEM.png     reliability, repair time and plan length vs particles
                               (Figures 4-16 to 4-25)
    and prints a Markdown summary table on stdout; progress lines go to stderr.

    Nothing is skipped silently: a plan the deterministic planner cannot find is a row with
    status 'no-plan', a repair that fails or times out is a row with that status and its
    reason (and no evaluation).

    Rows are written as they are measured, and rerunning resumes: rows already in the CSV
    (same problem, seed, plan, particles, method) are not measured again, so you can
    interrupt a run, or grow --plans and --particles later. A CSV measured with other
    --rollouts, --timeout or --controller is refused rather than mixed.

    \b
    Examples:
      arrange-up experiment fixtures --problems tz-mating --plans 2 --particles 10,40 \\
          --rollouts 100 --output-dir tz-quick
      arrange-up experiment fixtures --plans 5 --particles 10,40,150 --workers 1 \\
          --controller servo --no-ablation --output-dir docs/results/servo
                                       # docs/results.md's servo rows
      arrange-up experiment fixtures --workers 1   # thesis scale

    Before it starts, the sweep prints how many measurements it will make and about how long
    they take (estimated from measured runs).

    Exit status: 0 the sweep ran (whatever the results), 1 interrupted, 2 bad input or a CSV
    measured on other nominal plans.
    """
    backend = backend_choice(backend, scheduler)
    counts = comma_integers("--particles", particle_counts)
    if not counts or any(n < 1 for n in counts):
        fail(f"--particles: expected positive integers, got {particle_counts!r}")
    names = _problem_names(problems)
    pending = _resumed(
        lambda: pending_rows(
            Path(output_dir),
            problems=names,
            plans=plans,
            particles=counts,
            seed=seed,
            method=method,
            ablation=ablation,
        )
    )
    estimate = costs.Estimate()
    for name, count, stage in pending:
        estimate.add(costs.fixture_cost(name, count, rollouts, fixtures=stage != "ablation"), name)
    try:
        with _measurements(estimate, len(pending), "fixtures", quiet) as report:
            path = fixture_experiment(
                Path(output_dir),
                problems=names,
                plans=plans,
                particles=counts,
                rollouts=rollouts,
                seed=seed,
                method=method,
                timeout=timeout,
                runner=RunnerConfig(workers, backend, scheduler),
                ablation=ablation,
                controller=controller,
                progress=report.say,
                measured=lambda row: report.done(_fixture_line(row)),
            )
    except KeyboardInterrupt:
        _interrupted(Path(output_dir) / CSV_NAME)
    except WorkersLostError as error:
        _workers_lost(error, Path(output_dir) / CSV_NAME)
    except (StaleResultsError, BackendUnavailableError, ValueError) as error:
        fail(str(error))
    rows = select_rows(
        read_rows(path), problems=names, plans=plans, particles=counts, seed=seed, method=method
    )
    click.echo(markdown_table(summarize(rows)))
    click.echo(f"wrote {path} and {path.parent / 'fixtures-*.png'}")
