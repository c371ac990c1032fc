"""The thesis's chapter-4 experiment (Figures 4-14 to 4-25): fixture repair, swept over particles.

:func:`fixture_experiment` measures, for each rearrangement problem, how much
:func:`arrange_up.repair.repair_plan` improves the reliability of nominal
(deterministic) plans and what it costs, as a function of the particles of the belief it scores
candidates on:

1. ``K`` distinct nominal plans from :func:`arrange_up.repair.nominal_plans`
   (seed ``seed``; the thesis used 20 per problem);
2. each nominal plan is evaluated by :func:`arrange_up.evaluation.evaluate.evaluate_plan` over
   ``rollouts`` noisy rollouts (one CSV row, stage ``nominal``);
3. each nominal plan is repaired once per particle count (repair seed ``seed``) and the repaired
   plan is evaluated on the same rollouts (evaluation seed ``seed``: common random numbers, so
   the nominal and repaired rates of a plan are compared on the same noise); one row each,
   stage ``repaired``;
4. unless ``ablation`` is off, each of those repairs is run again without fixtures (the same
   particles, method and seed; :func:`~arrange_up.repair.repair_plan` with ``fixtures=False``:
   no placement is ever a candidate, the approach back-off and the push multipliers stay) and
   evaluated on the same rollouts; one row each, stage ``ablation``. The repaired mean minus
   the ablation's mean is the fixtures' own share of the repair's gain
   (:func:`fixture_shares`).

Every problem is driven by ``controller`` (a controller kind at its defaults) or, when it is
``None``, by its own controller; every row records the kind in its ``controller`` column and
the CSV's settings record it too, so a rerun under another controller is refused.

Nothing is left out silently. A plan index for which ``nominal_plans`` found no plan gets a
``nominal`` row with status ``no-plan`` and the reason, and no repair rows. A repair that fails
or times out gets its row with that status and reason and no evaluation; summaries count it
as a failed repair and leave it out of the mean reliability of the repaired plans, and the
plots say how many failed.

The CSV (``fixtures.csv``) gets every row as soon as it is measured; a rerun skips the rows
already there (keyed by problem, seed, plan, stage, particles and method; changing
``rollouts`` does not redo them; turning ``ablation`` off skips the ablation rows, and on again
measures only those). Nominal plans are recomputed on every run, which is cheap
and reproducible: with ``max_tries`` left to its default the list for a smaller ``K`` is a
prefix of the list for a larger one, so ``K`` can grow between runs. Every row records its
plan's hash, and evaluated rows count their failed rollouts by kind. A rerun whose nominal
plan ``j`` differs from the one the CSV was measured on (the planner changed), or whose CSV
has other columns, stops with :class:`StaleResultsError` instead of mixing the two.

Plots (:func:`plot_fixture_experiment`): ``fixtures-overview.png`` (Figure 4-14: mean
reliability of the nominal and the repaired plans per problem, and of the repairs without
fixtures where the rows have them) and one
``fixtures-<problem>.png`` per problem with reliability against particles (Figures 4-16, 4-18,
4-20, 4-22, 4-24) and repair time and plan length against particles (Figures 4-17, 4-19, 4-21,
4-23, 4-25).
"""

from __future__ import annotations

import csv
import dataclasses
import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from matplotlib.patches import Patch

from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.evaluation.records import plan_hash
from arrange_up.experiments.csv_records import (
    CsvAppender,
    Numbers,
    Progress,
    done_keys,
    mean,
    read_csv,
)
from arrange_up.experiments.problems import controller_setting, driven_problems, physics_setting
from arrange_up.figures.backend import pyplot
from arrange_up.model.world import Push
from arrange_up.parallel import RunnerConfig, available_cores
from arrange_up.repair import METHODS, nominal_plans, repair_plan

__all__ = [
    "CSV_NAME",
    "DEFAULT_PARTICLES",
    "DEFAULT_PROBLEMS",
    "FAILURE_KINDS",
    "FIXTURE_FIELDS",
    "NO_PLAN",
    "StaleResultsError",
    "SummaryRow",
    "fixture_experiment",
    "fixture_shares",
    "markdown_table",
    "pending_rows",
    "plot_fixture_experiment",
    "read_rows",
    "select_rows",
    "summarize",
]

#: The five rearrangement problems of thesis §4.2 (Table 4.2).
DEFAULT_PROBLEMS = ("down-push", "tt-mating", "tz-mating", "tt-mating-noisy", "create-a-t")
#: Particle counts (thesis Table 4.1 without its 200 and 500).
DEFAULT_PARTICLES = (10, 20, 40, 80, 150)
CSV_NAME = "fixtures.csv"
#: Status of a nominal row whose plan index ``nominal_plans`` did not fill.
NO_PLAN = "no-plan"
#: Status of a repaired row whose ``repair_plan`` raised ``ValueError`` (a bug or a bad plan).
ERROR = "error"
NOMINAL = "nominal"
REPAIRED = "repaired"
#: Stage of the repairs without fixtures (the fixtures' ablation).
ABLATION = "ablation"
#: Plot colours of the nominal and the repaired plans, and of the repairs without fixtures.
NOMINAL_COLOR = "0.6"
COLOR = "tab:blue"
ABLATION_COLOR = "tab:purple"
#: How the table and the plots name the ablation's rows.
ABLATION_LABEL = "repaired, no fixtures"

FIXTURE_FIELDS = [
    "problem",
    "controller",
    "seed",
    "plan",
    "stage",
    "particles",
    "method",
    "status",
    "reason",
    "plan_hash",
    "nominal_length",
    "plan_length",
    "pushes",
    "fixtures_placed",
    "seconds",
    "simulations",
    "rollouts",
    "successes",
    "reliability",
    "interval_low",
    "interval_high",
    "goal_missed",
    "action_failed",
    "not_at_rest",
    "off_table",
]
#: The evaluation's failure kinds (:class:`arrange_up.evaluation.evaluate.FailureBreakdown`), one
#: column
#: each: how the failed rollouts failed.
FAILURE_KINDS = ("goal_missed", "action_failed", "not_at_rest", "off_table")
_KEY = ("problem", "seed", "plan", "stage", "particles", "method")
#: The number columns of ``fixtures.csv``, checked when a run resumes it.
FIXTURE_NUMBERS: Numbers = {
    **dict.fromkeys(("seed", "plan", "particles", "nominal_length", "plan_length"), int),
    **dict.fromkeys(("pushes", "fixtures_placed", "simulations", "rollouts", "successes"), int),
    **dict.fromkeys(FAILURE_KINDS, int),
    **dict.fromkeys(("seconds", "reliability", "interval_low", "interval_high"), float),
}


class StaleResultsError(RuntimeError):
    """The CSV holds rows measured on another nominal plan than the one made now, or was
    written with other columns."""


def fixture_experiment(
    output_dir: Path,
    *,
    problems: Sequence[str] = DEFAULT_PROBLEMS,
    plans: int = 20,
    particles: Sequence[int] = DEFAULT_PARTICLES,
    rollouts: int = 1000,
    seed: int = 0,
    method: str = "enhanced",
    timeout: float | None = None,
    runner: RunnerConfig | None = None,
    max_tries: int | None = None,
    ablation: bool = True,
    controller: str | None = None,
    progress: Progress | None = None,
    measured: Callable[[dict[str, Any]], None] | None = None,
) -> Path:
    """Run (or resume) the chapter-4 experiment; returns the CSV path (module docstring).

    Rows go to ``output_dir/fixtures.csv`` (columns :data:`FIXTURE_FIELDS`), then the PNGs
    are drawn next to it. ``plans`` is ``K``; ``rollouts`` 0 skips every evaluation (the
    evaluation columns stay empty). ``method`` and ``timeout`` (seconds per repair; the thesis
    allowed 24 hours) go to :func:`~arrange_up.repair.repair_plan`; ``runner`` (None: local
    processes on every core) is where the evaluations run
    (:func:`~arrange_up.evaluation.evaluate.evaluate_plan`), and its worker count (every core
    when it has none) goes to the repair too. ``max_tries`` is passed to ``nominal_plans``
    (default ``10 * max(plans, 20) + 10``, independent of ``plans`` up to 20, which keeps the
    plan lists of different ``plans`` prefixes of each other). ``ablation`` adds the repairs
    without fixtures (stage ``ablation``); ``controller`` (``"compliant"`` or ``"servo"``)
    drives every problem by that controller kind at its defaults, ``None`` by its own.

    ``progress`` gets a line of text at each stage, ``measured`` every row as it is written.

    Raises ``ValueError`` for bad sizes, :class:`StaleResultsError` (see module docstring),
    and whatever the evaluation raises for a bad backend.
    """
    if plans < 1:
        raise ValueError(f"plans must be at least 1, got {plans!r}")
    if not particles or any(n < 1 for n in particles):
        raise ValueError(f"particle counts must be positive, got {list(particles)!r}")
    if rollouts < 0:
        raise ValueError(f"rollouts must be 0 or more, got {rollouts!r}")
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; expected one of {', '.join(METHODS)}")
    runner = runner or RunnerConfig(workers=None)
    workers = runner.workers or available_cores()
    runner = dataclasses.replace(runner, workers=workers)
    tries = max_tries if max_tries is not None else 10 * max(plans, 20) + 10
    path = Path(output_dir) / CSV_NAME
    _check_columns(path)
    say = progress or (lambda _msg: None)
    loaded = driven_problems(problems, controller)

    def evaluate(problem: Any, actions: Sequence[Any], what: str) -> dict[str, Any]:
        """The evaluation columns of a row (none when ``rollouts`` is 0)."""
        if rollouts == 0:
            return {}
        say(f"{what}: {rollouts} rollouts")
        result = evaluate_plan(
            problem,
            actions,
            rollouts=rollouts,
            seed=seed,
            runner=runner,
        )
        say(f"{what}: {result.successes}/{result.trials} rollouts reached the goal")
        return {
            "rollouts": result.trials,
            "successes": result.successes,
            "reliability": round(result.rate, 4),
            "interval_low": round(result.interval[0], 4),
            "interval_high": round(result.interval[1], 4),
            **{kind: getattr(result.failures, kind) for kind in FAILURE_KINDS},
        }

    settings = {
        "rollouts": rollouts,
        "timeout": timeout,
        "controller": controller_setting(loaded),
        "physics": physics_setting(loaded),
    }
    with CsvAppender(
        path, FIXTURE_FIELDS, key=_KEY, settings=settings, numbers=FIXTURE_NUMBERS
    ) as append:
        existing = read_csv(path)  # under the lock: what an earlier run measured
        done = append.done  # grows as rows are written: a repeated problem or count is done too

        def write(row: dict[str, Any]) -> None:
            append(row)
            if measured is not None:
                measured(row)

        for name in problems:
            problem = loaded[name]
            say(f"{name}: finding {plans} nominal plan{'s' if plans != 1 else ''}")
            started = time.perf_counter()
            found = nominal_plans(problem, plans, seed, max_tries=tries)
            nominal_seconds = time.perf_counter() - started
            plural = "s" if len(found) != 1 else ""
            say(f"{name}: {len(found)} distinct nominal plan{plural} in {nominal_seconds:.1f} s")
            for j in range(plans):
                nominal = found[j] if j < len(found) else None
                digest = plan_hash(nominal) if nominal is not None else ""
                _check_not_stale(existing, name, seed, j, digest)
                base = {
                    "problem": name,
                    "controller": problem.controller.kind.value,
                    "seed": seed,
                    "plan": j,
                }
                key = _key(name, seed, j, NOMINAL, "", "")
                if nominal is None:
                    if key not in done:
                        reason = (
                            "the deterministic planner found no nominal plan"
                            if not found
                            else f"only {len(found)} distinct nominal plans in {tries} tries"
                        )
                        say(f"{name} plan {j + 1}/{plans}: {NO_PLAN} ({reason})")
                        write(_row(base, stage=NOMINAL, status=NO_PLAN, reason=reason))
                    continue
                label = f"{name} plan {j + 1}/{plans}"
                if key not in done:
                    row = _row(
                        base,
                        stage=NOMINAL,
                        status="solved",
                        plan_hash=digest,
                        nominal_length=len(nominal),
                        plan_length=len(nominal),
                        pushes=_pushes(nominal),
                        fixtures_placed=0,
                        seconds=round(nominal_seconds, 3),
                    )
                    row.update(evaluate(problem, nominal, f"{label} nominal"))
                    write(row)
                for count in particles:
                    for stage in _repair_stages(ablation):
                        key = _key(name, seed, j, stage, str(count), method)
                        if key in done:
                            continue
                        what = f"{label} {_STAGE_WHAT[stage]} with {count} particles"
                        say(f"{what}: repairing")
                        row = _repair_row(
                            problem, nominal, count, seed, method, timeout, workers, base, digest,
                            stage=stage,
                        )  # fmt: skip
                        length = row["plan_length"]
                        say(
                            f"{what}: {row['status']} in {row['seconds']} s"
                            + (f", plan length {length}" if length != "" else "")
                            + (f" ({row['reason']})" if row["reason"] else "")
                        )
                        repaired = row.pop("_actions", None)
                        if repaired is not None:
                            row.update(evaluate(problem, repaired, what))
                        write(row)
    selected = select_rows(
        read_csv(path),
        problems=problems,
        plans=plans,
        particles=particles,
        seed=seed,
        method=method,
    )
    plot_fixture_experiment(selected, Path(output_dir))
    return path


def pending_rows(
    output_dir: Path,
    *,
    problems: Sequence[str],
    plans: int,
    particles: Sequence[int],
    seed: int,
    method: str,
    ablation: bool = True,
) -> list[tuple[str, int | None, str]]:
    """The (problem, particles, stage) of each row a :func:`fixture_experiment` call would
    write, if every nominal plan is found: those not yet in ``output_dir``'s CSV. Particles
    are ``None`` for the nominal plan's row (stage ``nominal``); the stages of repairs are
    ``repaired`` and, with ``ablation``, ``ablation`` (a repair without fixtures)."""
    done = done_keys(Path(output_dir) / CSV_NAME, _KEY)
    pending: list[tuple[str, int | None, str]] = []
    for name in dict.fromkeys(problems):
        for j in range(plans):
            if _key(name, seed, j, NOMINAL, "", "") not in done:
                pending.append((name, None, NOMINAL))
            pending += [
                (name, n, stage)
                for n in dict.fromkeys(particles)
                for stage in _repair_stages(ablation)
                if _key(name, seed, j, stage, str(n), method) not in done
            ]
    return pending


def read_rows(path: Path) -> list[dict[str, str]]:
    """The rows of a ``fixtures.csv`` as dicts of strings (empty cells are ``""``)."""
    return read_csv(path)


def select_rows(
    rows: Sequence[dict[str, str]],
    *,
    problems: Sequence[str],
    plans: int,
    particles: Sequence[int],
    seed: int,
    method: str,
) -> list[dict[str, str]]:
    """The rows of one configuration (a CSV may hold several): those problems, plan indices
    below ``plans``, those particle counts, that seed and method (the ablation's rows too,
    where there are any); grouped by problem in the order of ``problems`` (a resumed CSV may
    have them in any order)."""
    counts = {str(n) for n in particles}
    order = {name: k for k, name in enumerate(problems)}
    selected = [
        r
        for r in rows
        if r["problem"] in order
        and int(r["plan"]) < plans
        and r["seed"] == str(seed)
        and (r["stage"] == NOMINAL or (r["particles"] in counts and r["method"] == method))
    ]
    return sorted(selected, key=lambda r: order[r["problem"]])


#: How a progress line names a repair of each stage.
_STAGE_WHAT = {REPAIRED: "repaired", ABLATION: "repaired without fixtures"}


def _repair_stages(ablation: bool) -> tuple[str, ...]:
    """The stages of the repairs of each nominal plan and particle count, in order."""
    return (REPAIRED, ABLATION) if ablation else (REPAIRED,)


def _key(*values: Any) -> tuple[str, ...]:
    return tuple(str(v) for v in values)


def _check_not_stale(
    rows: Sequence[dict[str, str]], problem: str, seed: int, plan: int, digest: str
) -> None:
    for row in rows:
        if (row["problem"], row["seed"], row["plan"]) != (problem, str(seed), str(plan)):
            continue
        if row["plan_hash"] != digest:
            raise StaleResultsError(
                f"{problem} plan {plan}: the CSV's rows were measured on another nominal plan "
                f"({row['plan_hash'] or 'none'}) than the planner makes now ({digest or 'none'}); "
                "write to another output directory"
            )


def _check_columns(path: Path) -> None:
    if not path.exists() or path.stat().st_size == 0:
        return
    with path.open(newline="") as handle:
        header = next(csv.reader(handle), [])
    if header != FIXTURE_FIELDS:
        raise StaleResultsError(
            f"{path}: its columns are not those of this version ({', '.join(FIXTURE_FIELDS)}); "
            "write to another output directory"
        )


def _row(base: dict[str, Any], **values: Any) -> dict[str, Any]:
    row = dict.fromkeys(FIXTURE_FIELDS, "")
    row.update(base)
    row.update(values)
    return row


def _pushes(actions: Iterable[Any]) -> int:
    return sum(1 for a in actions if isinstance(a, Push))


def _repair_row(
    problem: Any,
    nominal: tuple[Any, ...],
    count: int,
    seed: int,
    method: str,
    timeout: float | None,
    workers: int,
    base: dict[str, Any],
    digest: str,
    *,
    stage: str = REPAIRED,
) -> dict[str, Any]:
    """One repair as a row of ``stage`` (``repaired``, or ``ablation``: the repair without
    fixtures); the repaired actions ride along under ``_actions`` (not a column)."""
    started = time.perf_counter()
    try:
        result = repair_plan(
            problem,
            nominal,
            particles=count,
            seed=seed,
            method=method,
            workers=workers,
            timeout=timeout,
            fixtures=stage != ABLATION,
        )
    except ValueError as error:  # recorded, so that one bad repair does not end a long sweep
        return _row(
            base,
            stage=stage,
            particles=count,
            method=method,
            status=ERROR,
            reason=str(error),
            plan_hash=digest,
            nominal_length=len(nominal),
            seconds=round(time.perf_counter() - started, 3),
        )
    stats = result.stats()
    return _row(
        base,
        stage=stage,
        particles=count,
        method=method,
        status=result.status,
        reason=result.reason,
        plan_hash=digest,
        nominal_length=len(nominal),
        plan_length="" if result.actions is None else len(result.actions),
        pushes=stats["pushes"],
        fixtures_placed=stats["fixtures_placed"] if result.actions is not None else "",
        seconds=round(result.elapsed, 3),
        simulations=result.simulations,
        _actions=result.actions,
    )


# -- summaries -----------------------------------------------------------------------------------
@dataclass(frozen=True)
class SummaryRow:
    """Aggregate of one problem's nominal rows (``particles`` None) or of its repairs of one
    ``stage`` (``repaired``, or ``ablation``: without fixtures) with one particle count, over
    the plans.

    ``plans`` counts the rows; ``solved`` those with a plan (nominal: found; repaired: the
    repair succeeded). ``reliability`` is the mean rate over the solved, evaluated rows with
    its ``low``/``high`` (min/max over plans; NaN when none); ``seconds`` the mean planning time
    (repair time; for nominal rows the time ``nominal_plans`` took for all plans), ``length``
    the mean plan length and ``fixtures`` the mean fixtures placed, all over solved rows.
    ``statuses`` lists every status that is not ``solved`` with its count; ``failures`` the
    failed rollouts of the evaluated rows by kind (:data:`FAILURE_KINDS`), summed over plans.
    """

    problem: str
    particles: int | None
    plans: int
    solved: int
    evaluated: int
    reliability: float
    low: float
    high: float
    seconds: float
    length: float
    fixtures: float
    statuses: tuple[tuple[str, int], ...]
    failures: tuple[int, ...] = (0, 0, 0, 0)
    stage: str = REPAIRED


def summarize(rows: Sequence[dict[str, str]]) -> list[SummaryRow]:
    """Aggregate CSV rows per problem: the nominal plans, then each particle count (ascending):
    its repairs, then its repairs without fixtures (where ``rows`` has any).

    Rows of every seed and method in ``rows`` are pooled; filter them first to separate them.
    """
    out: list[SummaryRow] = []
    for problem in dict.fromkeys(r["problem"] for r in rows):
        mine = [r for r in rows if r["problem"] == problem]
        groups: list[tuple[int | None, str, list[dict[str, str]]]] = [
            (None, NOMINAL, [r for r in mine if r["stage"] == NOMINAL])
        ]
        counts = sorted({int(r["particles"]) for r in mine if r["stage"] != NOMINAL})
        for n in counts:
            for stage in (REPAIRED, ABLATION):
                group = [r for r in mine if r["stage"] == stage and r["particles"] == str(n)]
                if group:
                    groups.append((n, stage, group))
        for count, stage, group in groups:
            solved = [r for r in group if r["status"] == "solved"]
            rates = [float(r["reliability"]) for r in solved if r["reliability"] != ""]
            others: dict[str, int] = {}
            for r in group:
                if r["status"] != "solved":
                    others[r["status"]] = others.get(r["status"], 0) + 1
            out.append(
                SummaryRow(
                    problem=problem,
                    particles=count,
                    plans=len(group),
                    solved=len(solved),
                    evaluated=len(rates),
                    reliability=mean(rates),
                    low=min(rates, default=math.nan),
                    high=max(rates, default=math.nan),
                    seconds=mean(float(r["seconds"]) for r in solved),
                    length=mean(float(r["plan_length"]) for r in solved),
                    fixtures=mean(float(r["fixtures_placed"]) for r in solved),
                    statuses=tuple(sorted(others.items())),
                    failures=tuple(
                        sum(int(r[kind]) for r in solved if r["reliability"] != "")
                        for kind in FAILURE_KINDS
                    ),
                    stage=stage,
                )
            )
    return out


def fixture_shares(summary: Sequence[SummaryRow]) -> list[tuple[str, int, float, float]]:
    """The fixtures' own share of the repairs' gain: per problem and particle count whose
    repairs and repairs without fixtures were both evaluated, ``(problem, particles, repaired
    mean reliability, ablation mean reliability)``; the share is the difference of the two."""
    ablations = {(s.problem, s.particles): s for s in summary if s.stage == ABLATION}
    out = []
    for s in summary:
        other = ablations.get((s.problem, s.particles))
        if s.stage == REPAIRED and other is not None and s.evaluated and other.evaluated:
            assert s.particles is not None
            out.append((s.problem, s.particles, s.reliability, other.reliability))
    return out


def markdown_table(summary: Sequence[SummaryRow]) -> str:
    """The summary as a Markdown table: one line for the nominal plans of each problem, one
    per particle count of its repairs. Reliability is in percent, mean (min-max over plans);
    the failed rollouts are summed over plans, by kind: goal missed / an action failed (e.g.
    the paddle put down on a part) / not at rest / off the table. The repairs without
    fixtures (stage ``ablation``) are labelled ``repaired, no fixtures``; when there are any, a
    second table gives the fixtures' own share (:func:`fixture_shares`) in points."""
    lines = [
        "| problem | plans | particles | solved | reliability, mean (min–max) | time (s) "
        "| plan length | fixtures placed | failed rollouts: goal / action / rest / off |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for s in summary:
        nominal = s.particles is None
        solved = f"{s.solved}/{s.plans}"
        if s.statuses:
            solved += " (" + ", ".join(f"{n} {status}" for status, n in s.statuses) + ")"
        if s.evaluated:
            rel = f"{100 * s.reliability:.1f} % ({100 * s.low:.1f}–{100 * s.high:.1f})"
        else:
            rel = "—"
        label = "nominal" if nominal else ABLATION_LABEL if s.stage == ABLATION else "repaired"
        lines.append(
            f"| {s.problem} | {label} "
            f"| {'—' if nominal else s.particles} | {solved} | {rel} "
            f"| {_fmt(s.seconds, '.1f')} | {_fmt(s.length, '.1f')} "
            f"| {'—' if nominal else _fmt(s.fixtures, '.1f')} "
            f"| {' / '.join(map(str, s.failures)) if s.evaluated else '—'} |"
        )
    shares = fixture_shares(summary)
    if shares:
        lines += [
            "",
            "| problem | particles | repaired, mean | repaired, no fixtures, mean "
            "| fixtures' own share (points) |",
            "|---|---|---|---|---|",
        ]
        for problem, count, repaired, ablation in shares:
            lines.append(
                f"| {problem} | {count} | {100 * repaired:.1f} % | {100 * ablation:.1f} % "
                f"| {100 * (repaired - ablation):+.1f} |"
            )
    return "\n".join(lines)


# -- plots ---------------------------------------------------------------------------------------
def plot_fixture_experiment(rows: Sequence[dict[str, str]], output_dir: Path) -> list[Path]:
    """Draw ``fixtures-overview.png`` and one ``fixtures-<problem>.png`` per problem of
    ``rows`` (CSV rows, see :func:`select_rows`) into ``output_dir``; returns the paths written
    (overview first). A problem given as a file is named by the file's stem
    (``fixtures-tz-variant.png`` for ``/some/dir/tz-variant.yaml``)."""
    summary = summarize(rows)
    problems = list(dict.fromkeys(s.problem for s in summary))
    output_dir = Path(output_dir)
    written = [_plot_overview(summary, problems, output_dir / "fixtures-overview.png")]
    for problem in problems:
        problem_rows = [s for s in summary if s.problem == problem]
        png = output_dir / f"fixtures-{Path(problem).stem if _is_file(problem) else problem}.png"
        written.append(_plot_problem(problem, problem_rows, png))
    return written


def _is_file(problem: str) -> bool:
    """Whether ``problem`` (as the CSV records it) names a problem file, not a shipped one."""
    return "/" in problem or "\\" in problem or Path(problem).suffix in (".yaml", ".yml", ".pddl")


def _plot_overview(summary: Sequence[SummaryRow], problems: list[str], png: Path) -> Path:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4))
    ablated = any(s.stage == ABLATION for s in summary)
    width = 0.27 if ablated else 0.38
    used: set[int] = set()
    for i, problem in enumerate(problems):
        nominal = next(s for s in summary if s.problem == problem and s.particles is None)
        repaired = [s for s in summary if s.problem == problem and s.stage == REPAIRED]
        # The thesis's overview (Figure 4-14) used 150 particles; else the largest count run.
        best = next((s for s in repaired if s.particles == 150), repaired[-1] if repaired else None)
        if best is not None and best.particles is not None:
            used.add(best.particles)
        if nominal.solved == 0:
            ax.text(i, 2, "no nominal plan", ha="center", va="bottom", fontsize=8)
            continue
        bars = [(nominal, NOMINAL_COLOR), (best, COLOR)]
        if ablated:  # the same repairs without fixtures, beside them
            without = next(
                (
                    s
                    for s in summary
                    if s.problem == problem
                    and s.stage == ABLATION
                    and best is not None
                    and s.particles == best.particles
                ),
                None,
            )
            bars.append((without, ABLATION_COLOR))
        for k, (s, color) in enumerate(bars):
            offset = (k - (len(bars) - 1) / 2) * width
            if s is None or not s.evaluated:
                ax.text(i + offset, 2, "not evaluated", rotation=90, ha="center", fontsize=7)
                continue
            ax.bar(
                i + offset,
                100 * s.reliability,
                width,
                color=color,
                yerr=[[100 * (s.reliability - s.low)], [100 * (s.high - s.reliability)]],
                capsize=3,
            )
    counts = ", ".join(str(n) for n in sorted(used))
    handles = [
        Patch(color=NOMINAL_COLOR, label="nominal (deterministic)"),
        Patch(color=COLOR, label=f"repaired ({counts} particles)"),
    ]
    if ablated:
        handles.append(Patch(color=ABLATION_COLOR, label=f"{ABLATION_LABEL} (same repairs)"))
    ax.legend(
        handles=handles,
        fontsize=8,
        loc="upper right",
    )
    ax.set_xticks(range(len(problems)), problems)
    ax.set_xlim(-0.6, len(problems) - 0.4)
    ax.set_ylim(0, 115)
    ax.set_ylabel("% of rollouts reaching the goal")
    ax.set_title("mean reliability over nominal plans, bars min–max (Figure 4-14)", fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return png


def _reliability_bars(ax, rows: Sequence[SummaryRow], **style) -> None:
    """The mean reliability of evaluated ``rows`` against particles, with min–max bars."""
    xs = [s.particles for s in rows]
    ys = [100 * s.reliability for s in rows]
    low = [y - 100 * s.low for y, s in zip(ys, rows, strict=True)]
    high = [100 * s.high - y for y, s in zip(ys, rows, strict=True)]
    ax.errorbar(xs, ys, yerr=[low, high], capsize=3, **style)


def _plot_problem(problem: str, rows: Sequence[SummaryRow], png: Path) -> Path:
    plt = pyplot()
    nominal = rows[0]
    repaired = [s for s in rows if s.stage == REPAIRED]
    ablation = [s for s in rows if s.stage == ABLATION and s.evaluated]
    fig, (ax_rel, ax_time) = plt.subplots(1, 2, figsize=(11, 4))
    if nominal.solved == 0:
        for ax in (ax_rel, ax_time):
            ax.text(
                0.5,
                0.5,
                "no nominal plan:\nthe deterministic planner found none",
                ha="center",
                va="center",
                transform=ax.transAxes,
            )
    if nominal.evaluated:
        ax_rel.axhspan(
            100 * nominal.low, 100 * nominal.high, color="0.88", label="nominal (min–max)"
        )
        ax_rel.axhline(
            100 * nominal.reliability, color=NOMINAL_COLOR, ls="--", label="nominal (mean)"
        )
    shown = [s for s in repaired if s.evaluated]
    if shown:
        _reliability_bars(ax_rel, shown, marker="o", color=COLOR, label="repaired (mean, min–max)")
    if ablation:
        _reliability_bars(
            ax_rel,
            ablation,
            marker="s",
            ls="--",
            color=ABLATION_COLOR,
            label=f"{ABLATION_LABEL} (mean, min–max)",
        )
    for s in [s for s in rows if s.stage != NOMINAL]:
        failed = s.plans - s.solved
        if failed:
            without = s.stage == ABLATION
            ax_rel.annotate(
                f"{failed}/{s.plans} repairs\n{'without fixtures ' if without else ''}not solved",
                (s.particles, 14 if without else 2),
                ha="center",
                fontsize=7,
                color="tab:red",
            )
    counts = [s.particles for s in repaired]
    for ax in (ax_rel, ax_time):
        if counts:
            ax.set_xticks(counts)
    ax_rel.set_ylim(0, 105)
    ax_rel.set_xlabel("particles of the repair's belief")
    ax_rel.set_ylabel("% of rollouts reaching the goal")
    ax_rel.set_title(f"{problem}: reliability", fontsize=10)
    if nominal.evaluated or shown or ablation:
        ax_rel.legend(fontsize=7, loc="upper left")
    timed = [s for s in repaired if s.solved]
    if timed:
        xs = [s.particles for s in timed]
        ax_time.plot(xs, [s.seconds for s in timed], "o-", color="tab:orange", label="repair time")
        ax_len = ax_time.twinx()
        ax_len.plot(xs, [s.length for s in timed], "s-", color="tab:green", label="repaired length")
        if nominal.solved:
            ax_len.axhline(nominal.length, color="tab:green", ls="--", label="nominal length")
        ax_len.set_ylabel("plan length (actions, mean)")
        lengths = [s.length for s in timed] + ([nominal.length] if nominal.solved else [])
        ax_len.set_ylim(0, max(lengths) * 1.3)
        handles = ax_time.get_legend_handles_labels()
        more = ax_len.get_legend_handles_labels()
        ax_time.legend(handles[0] + more[0], handles[1] + more[1], fontsize=7, loc="upper left")
        ax_time.set_ylim(0, None)
    ax_time.set_xlabel("particles of the repair's belief")
    ax_time.set_ylabel("repair time (s, mean of solved repairs)")
    ax_time.set_title(f"{problem}: repair time and plan length", fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return png


def _fmt(value: float, spec: str) -> str:
    return "—" if math.isnan(value) else format(value, spec)
