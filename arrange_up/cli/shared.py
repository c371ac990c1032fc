"""What every command of ``arrange-up`` shares: exit statuses, the clean failure, the option
types that validate values before any work (:data:`SEED`, :class:`FiniteFloat`,
:class:`OutputFile`, ...), loading a problem (with its warnings) or a plan file, the semantics
check, the parallel options, the progress display, JSON and table output, and the library
defaults the options show.

Exit status: 0 success; 1 the job ran but its answer is negative (e.g. ``plan`` found no
plan); 2 bad input (unreadable or invalid problem, also under ``check``, unknown domain, bad
option).
"""

from __future__ import annotations

import inspect
import json
import math
import os
import shlex
import signal
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any, NoReturn

import click
from rich.console import Console
from rich.progress import Progress, ProgressColumn, TaskID

from arrange_up.evaluation.rollouts import LANDINGS
from arrange_up.io.domains import UnknownDomainError, load_checked
from arrange_up.io.planfile import PlanFileError, action_to_json, plan_problem_mismatches, read_plan
from arrange_up.model.errors import ProblemFormatError, printable
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action
from arrange_up.parallel import BACKENDS, WORKERS_PER_CORE, check_workers, max_workers
from arrange_up.transitions import available

EXIT_NEGATIVE = 1
EXIT_BAD_INPUT = 2


def fail(message: str, code: int = EXIT_BAD_INPUT) -> NoReturn:
    """Print ``arrange-up: message`` on stderr and exit with ``code`` (default: bad input).
    Control characters in ``message`` (from a file name or a name in a file) are shown escaped
    (:func:`arrange_up.model.errors.printable`), never sent to the terminal raw."""
    click.echo(f"arrange-up: {printable(message, keep_newlines=True)}", err=True)
    sys.exit(code)


def command_line() -> str:
    """The running command as it was given (``arrange-up`` and its arguments, quoted for a
    POSIX shell), for a message that says to run it again; ``arrange-up`` alone outside a
    command."""
    from arrange_up.cli import ARGV_KEY

    ctx = click.get_current_context(silent=True)
    given = ctx.meta.get(ARGV_KEY, []) if ctx is not None else []
    return shlex.join(["arrange-up", *given])


def stopped_early(error: BaseException, kept: str, code: int = EXIT_NEGATIVE) -> NoReturn:
    """End a command whose workers were lost (:class:`arrange_up.parallel.WorkersLostError`)
    in one line: the error, then ``kept`` (what the command kept and how to go on, ending with
    "run again ..."), then the command to run, :func:`command_line`; exit status ``code`` (1,
    as an interrupt: the job ran, not to its end)."""
    fail(f"{error}{kept}: {command_line()}", code)


@contextmanager
def writing_output(output: str | os.PathLike[str]) -> Iterator[None]:
    """Around writing the file ``-o output``: an ``OSError`` (a full disk, ``/dev/full``, a
    directory) ends the command with one line naming the file, exit status 2."""
    try:
        yield
    except OSError as error:
        fail(f"{os.fsdecode(output)}: cannot write: {error.strerror or error}")


#: A seed: a non-negative integer (numpy's seed sequences refuse negative ones).
SEED = click.IntRange(0, None)


class FiniteFloat(click.FloatRange):
    """A float option within bounds (as :class:`click.FloatRange`) that is also finite:
    ``nan`` and ``inf`` are refused, they would pass every comparison or none."""

    name = "finite float"

    def convert(self, value: Any, param: Any, ctx: Any) -> Any:
        number = click.FLOAT.convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return super().convert(number, param, ctx)


class OutputFile(click.Path):
    """A file the command will write, checked before any work: not a directory, in a folder
    that exists or can be made and that a file can be created in, with one of ``suffixes``
    (any when empty, matched case-insensitively)."""

    name = "output file"

    def __init__(self, suffixes: Iterable[str] = ()) -> None:
        super().__init__(dir_okay=False)
        self.suffixes = tuple(suffix.lower() for suffix in suffixes)

    def convert(self, value: Any, param: Any, ctx: Any) -> Any:
        text = super().convert(value, param, ctx)
        path = Path(os.fsdecode(text))
        if self.suffixes and path.suffix.lower() not in self.suffixes:
            self.fail(
                f"{text!r} has the suffix {path.suffix or '(none)'!r}; expected one of "
                f"{', '.join(self.suffixes)}",
                param,
                ctx,
            )
        problem = unwritable(path)
        if problem is not None:
            self.fail(f"cannot write {text!r}: {problem}", param, ctx)
        return text


class OutputDir(click.Path):
    """A folder the command will write files into, checked before any work: not a file,
    existing or creatable, and a file can be created in it."""

    name = "output folder"

    def __init__(self) -> None:
        super().__init__(file_okay=False)

    def convert(self, value: Any, param: Any, ctx: Any) -> Any:
        text = super().convert(value, param, ctx)
        problem = unwritable(Path(os.fsdecode(text)) / "file")
        if problem is not None:
            self.fail(f"cannot write into {text!r}: {problem}", param, ctx)
        return text


def unwritable(path: Path) -> str | None:
    """Why no file can be written at ``path``, or ``None``: a file is created (and removed)
    in the nearest existing folder, since permissions alone do not tell (a read-only file
    system, a process running as root)."""
    folder = path.parent
    while not folder.exists():
        if folder.is_symlink():
            return f"{folder} is a broken link"
        folder = folder.parent
    if not folder.is_dir():
        return f"{folder} is not a folder"
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as error:
        return f"no file can be created in {folder} ({error.strerror or error})"
    return None


class WorkerCount(click.ParamType):
    """A number of worker processes: a positive integer of at most
    :func:`arrange_up.parallel.max_workers` (refused beyond, not capped: the command does what
    it says or nothing)."""

    name = "integer"

    def convert(self, value: Any, param: Any, ctx: Any) -> Any:
        number = click.INT.convert(value, param, ctx)
        try:
            check_workers(number)
        except ValueError as error:
            self.fail(str(error), param, ctx)
        return number


def workers_limit_help() -> str:
    """The limit of every --workers option, as a sentence of its help."""
    return f"At most {WORKERS_PER_CORE} per core ({max_workers()} here)."


def workers_option(help: str) -> Callable[[Any], Any]:
    """``--workers``: worker processes (:class:`WorkerCount`), default None; ``help`` says what
    they run and the default, the limit's sentence follows."""
    return click.option(
        "--workers", type=WorkerCount(), default=None, help=f"{help} {workers_limit_help()}"
    )


def seed_option(help: str) -> Callable[[Any], Any]:
    """``--seed``: a non-negative integer, default 0; ``help`` says what it seeds."""
    return click.option("--seed", type=SEED, default=0, show_default=True, help=help)


def timeout_option(help: str) -> Callable[[Any], Any]:
    """``--timeout``: positive finite seconds, default none; ``help`` says what it limits."""
    return click.option(
        "--timeout", type=FiniteFloat(0, None, min_open=True), default=None, help=help
    )


def landing_option(where: str = "") -> Callable[[Any], Any]:
    """``--landing fail|shove``: the rule for a push whose paddle is put down onto a part;
    ``where`` ends the help (e.g. where the rule applies)."""
    return click.option(
        "--landing",
        type=click.Choice(LANDINGS),
        default="fail",
        show_default=True,
        help="A push whose paddle is put down onto a part: fail the action, or shove (let the "
        f"physics resolve the overlap and go on){where}.",
    )


def json_option(help: str) -> Callable[[Any], Any]:
    """``--json`` (the ``as_json`` flag): print a machine-readable summary on stdout."""
    return click.option("--json", "as_json", is_flag=True, help=help)


def library_default(function: Callable[..., Any], parameter: str) -> Any:
    """The default of ``function``'s ``parameter``: an option whose default is the library's
    shows and uses that one, so the two cannot drift apart."""
    return inspect.signature(function).parameters[parameter].default


def comma_separated(values: Sequence[Any]) -> str:
    """``values`` as a comma-separated option value (the defaults of list options)."""
    return ",".join(str(value) for value in values)


def comma_integers(option: str, text: str) -> list[int]:
    """The positive integers of a comma-separated option value (blank items skipped; at least
    one), exit 2 otherwise (every option of this kind counts things: particles, workers)."""
    try:
        values = [int(item) for item in text.split(",") if item.strip()]
    except ValueError:
        fail(f"{option}: expected comma-separated integers, got {text!r}")
    if not values or any(value < 1 for value in values):
        fail(f"{option}: expected comma-separated positive integers, got {text!r}")
    return values


def load_problem(problem: str) -> ArrangementProblem:
    """Resolve and load a problem, turning every refusal into a clean message and exit 2.

    The warnings found in the file (an unknown key, a default tolerance, ...) are printed on
    stderr, as ``check`` prints them: every command that loads a problem goes through here.
    """
    try:
        loaded, diagnostics = load_checked(problem)
    except UnknownDomainError as error:
        fail(str(error))
    except ProblemFormatError as error:
        click.echo(str(error), err=True)
        n = sum(1 for d in error.diagnostics if d.severity == "error")
        fail(f"{n} error{'s' if n != 1 else ''}; nothing was done")
    for diagnostic in diagnostics:
        click.echo(str(diagnostic), err=True)
    return loaded


def read_plan_file(
    problem: ArrangementProblem, plan_file: str, *, warn_mismatch: bool
) -> tuple[tuple[Action, ...], dict[str, Any]]:
    """Read a plan file for ``problem`` as (actions, document): a clean message and exit 2 on a
    bad file; with ``warn_mismatch``, one warning for each way the plan was made for other than
    ``problem`` (other problem content, another controller: :func:`plan_problem_mismatches`)."""
    try:
        actions, document = read_plan(plan_file, problem)
    except PlanFileError as error:
        fail(str(error))
    # One line each: a plan of another problem under another controller is wrong twice, and
    # each line reads alone, as every diagnostic does.
    for mismatch in plan_problem_mismatches(document, problem) if warn_mismatch else ():
        click.echo(f"arrange-up: warning: {plan_file}: {mismatch}; using it anyway", err=True)
    return actions, document


def check_semantics(name: str) -> None:
    """Exit 2 naming the registered semantics unless ``name`` is one."""
    if name not in available():
        fail(f"--semantics: unknown semantics {name!r}; expected one of {', '.join(available())}")


def parallel_options(what: str) -> Callable[[Any], Any]:
    """The --workers, --backend and --scheduler options of commands that run batches of
    independent simulations (``what``: rollouts, examples, ...) on local processes or Dask."""
    options = (
        workers_option("Worker processes (default: all cores; 1 runs in this process)."),
        click.option(
            "--backend",
            type=click.Choice(BACKENDS),
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

    def decorate(command: Any) -> Any:
        for option in reversed(options):
            command = option(command)
        return command

    return decorate


def backend_choice(backend: str | None, scheduler: str | None) -> str:
    """The backend to use: a scheduler address implies dask and contradicts local."""
    if scheduler is not None and backend == "local":
        fail("--scheduler: a scheduler address needs --backend dask")
    return backend or ("dask" if scheduler is not None else "local")


#: How often, in seconds, a long command prints its progress line on stderr when stderr is not a
#: terminal (a log, CI, a notebook, a launch file): under the 10 s that docs/design/cli.md
#: promises.
PROGRESS_INTERVAL = 9.0


@contextmanager
def terminal_progress(
    *columns: str | ProgressColumn, what: str = "", quiet: bool = False
) -> Iterator[Progress | LineProgress | None]:
    """The progress display of a long command (``what`` names it in lines: "plan") while the
    block runs:

    * stderr is a terminal: a transient rich display with ``columns``, gone when the block
      exits (messages printed after it, e.g. on an interrupt, are not overdrawn);
    * it is not: a :class:`LineProgress`, one line on stderr every
      :data:`PROGRESS_INTERVAL` seconds (what, how far, elapsed, an estimate of the time left
      where the total is known);
    * ``quiet``: None, nothing is shown.

    Both displays take ``add_task``, ``update`` and ``console.print`` alike."""
    if quiet:
        yield None
        return
    if not sys.stderr.isatty():
        lines = LineProgress(what)
        try:
            yield lines
        finally:
            lines.stop()
        return
    with Progress(*columns, console=Console(stderr=True), transient=True) as display:
        yield display


class LineProgress:
    """Progress as plain lines on stderr, for when it is not a terminal: the subset of rich's
    ``Progress`` the commands use (``add_task``, ``update``, ``console.print``), and a daemon
    thread that prints the state of the tasks every ``interval`` seconds until :meth:`stop`,
    whether or not anything was updated in between (a search can run minutes between two
    callbacks)."""

    def __init__(self, what: str, interval: float | None = None) -> None:
        self.what = what
        self.console = _StderrConsole()
        self._tasks: list[dict[str, Any]] = []
        self._lock = threading.Lock()
        self._started = time.monotonic()
        self._stopped = threading.Event()
        self._interval = PROGRESS_INTERVAL if interval is None else interval
        self._thread = threading.Thread(target=self._beat, name="progress-lines", daemon=True)
        self._thread.start()

    def add_task(self, description: str, total: float | None = None, **fields: Any) -> TaskID:
        with self._lock:
            self._tasks.append(
                {
                    "description": description,
                    "total": total,
                    "completed": 0,
                    "fields": dict(fields),
                    "started": time.monotonic(),
                }
            )
            return TaskID(len(self._tasks) - 1)

    def update(
        self,
        task: TaskID,
        *,
        description: str | None = None,
        total: float | None = None,
        completed: float | None = None,
        advance: float | None = None,
        **fields: Any,
    ) -> None:
        with self._lock:
            state = self._tasks[task]
            if description is not None:
                state["description"] = description
            if total is not None:
                state["total"] = total
            if completed is not None:
                state["completed"] = completed
            if advance is not None:
                state["completed"] += advance
            state["fields"].update(fields)

    def line(self) -> str:
        """The progress line: each task's description, count and estimate, and the time
        elapsed since the command began."""
        now = time.monotonic()
        with self._lock:
            parts = [_task_text(state, now) for state in self._tasks]
        elapsed = _clock(now - self._started)
        head = f"arrange-up {self.what}: " if self.what else "arrange-up: "
        return head + "; ".join(parts or ["starting"]) + f" [{elapsed} elapsed]"

    def stop(self) -> None:
        self._stopped.set()
        self._thread.join(timeout=1.0)

    def _beat(self) -> None:
        while not self._stopped.wait(self._interval):
            self.console.print(self.line())


class _StderrConsole:
    """``console.print`` of :class:`LineProgress`: the text as one line on stderr."""

    _lock = threading.Lock()

    def print(self, text: str, **_: Any) -> None:
        with self._lock:
            sys.stderr.write(f"{text}\n")
            sys.stderr.flush()


def _task_text(state: dict[str, Any], now: float) -> str:
    text = " ".join(str(state["description"]).split())  # a terminal line's padding, squeezed
    done, total = state["completed"], state["total"]
    if total:
        text += f" {done:g}/{total:g} ({100.0 * done / total:.0f}%)"
        if 0 < done < total:
            left = (now - state["started"]) / done * (total - done)
            text += f", about {_clock(left)} left"
    summary = state["fields"].get("summary")
    if summary:
        text += f", {summary}"
    return text


def _clock(seconds: float) -> str:
    """``h:mm:ss``."""
    whole = int(max(0.0, seconds))
    return f"{whole // 3600}:{whole % 3600 // 60:02d}:{whole % 60:02d}"


def quiet_option() -> Callable[[Any], Any]:
    """``--quiet``: no progress display or progress lines on stderr."""
    return click.option(
        "--quiet",
        "-q",
        is_flag=True,
        help="Print no progress on stderr (by default a live display on a terminal, else a "
        f"line every {PROGRESS_INTERVAL:g} s).",
    )


@contextmanager
def first_interrupt_stops(what: str) -> Iterator[Callable[[], bool]]:
    """While the block runs, the first Ctrl-C (SIGINT) asks for an orderly stop instead of
    raising: the block polls the yielded callable, which turns True, and keeps what it has
    computed. A line on stderr says so and that a second Ctrl-C aborts (it raises
    ``KeyboardInterrupt`` as usual). ``what`` names what stops (``"the search"``). Outside the
    main thread, where no handler can be set, the callable stays False."""
    asked: list[bool] = []
    if threading.current_thread() is not threading.main_thread():
        yield lambda: False
        return

    def handler(signum: int, frame: Any) -> None:
        asked.append(True)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        click.echo(f"interrupt: stopping {what}; Ctrl-C again to abort", err=True)

    previous = signal.signal(signal.SIGINT, handler)
    try:
        yield lambda: bool(asked)
    finally:
        signal.signal(signal.SIGINT, previous)


def echo_json(data: Any) -> None:
    """Print ``data`` as indented JSON on stdout (the --json summaries)."""
    click.echo(json.dumps(data, indent=2))


def document_summary(document: dict[str, Any], output: str | None, **extra: Any) -> dict[str, Any]:
    """The --json summary of a plan document: its fields but the actions, then ``extra``,
    then the actions and the file written (``output``, or None)."""
    summary = {k: v for k, v in document.items() if k != "actions"}
    summary.update(extra)
    summary["actions"] = document.get("actions")
    summary["output"] = output
    return summary


def actions_table(problem: ArrangementProblem, actions: Sequence[Action]) -> str:
    """The plan as an aligned text table in the problem's units."""
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
