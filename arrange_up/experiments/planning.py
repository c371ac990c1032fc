"""The thesis's chapter-3 experiments, as resumable library functions.

* :func:`transition_comparison` (Figures 3-6 and 3-7): for each problem and planner
  (deterministic, particles with 5/25/50 particles, and any other registered semantics), R
  planning runs with different seeds: planning time, whether a plan was found within the node
  limit, and the plan's reliability over N noisy rollouts.
* :func:`search_table` (Table 3.1): blind, admissible and inadmissible heuristics, each with
  and without domination, on 1, 2, 3, 4 and 7 blocks: nodes expanded and plan cost.

Both append every raw measurement to a CSV as soon as it is made and skip the rows a previous
run already wrote, so an interrupted experiment resumes where it stopped; both draw a PNG
summary of the rows asked for (the problems, planners and runs of the call, even when the CSV
holds more) with the runs that found no plan marked, and :func:`transition_markdown` and
:func:`search_markdown` give those rows as a table. :func:`pending_transition_runs` and
:func:`pending_searches` list what a call would measure, for an estimate of its duration
(:mod:`arrange_up.experiments.costs`). Sizes scale down by arguments (the CLI's flags).

Both drive every problem by ``controller`` (a controller kind at its defaults) or, when it is
``None``, by its own controller; every row records the kind in its ``controller`` column, and
the CSV's settings record it, so a rerun under another controller is refused.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from matplotlib.patches import Patch

from arrange_up.evaluation.evaluate import evaluate_plan
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
from arrange_up.parallel import RunnerConfig, available_cores
from arrange_up.planning.planner import plan
from arrange_up.transitions import available

TRANSITION_FIELDS = [
    "problem",
    "controller",
    "planner",
    "semantics",
    "particles",
    "run",
    "seed",
    "status",
    "solved",
    "planning_seconds",
    "expanded",
    "transitions_simulated",
    "plan_length",
    "rollouts",
    "successes",
    "reliability",
    "interval_low",
    "interval_high",
]
SEARCH_FIELDS = [
    "search",
    "heuristic",
    "domination",
    "problem",
    "controller",
    "semantics",
    "status",
    "solved",
    "expanded",
    "cost",
    "seconds",
]
#: The number columns of each CSV, checked when a run resumes it.
TRANSITION_NUMBERS: Numbers = {
    **dict.fromkeys(
        ("particles", "run", "seed", "solved", "expanded", "transitions_simulated"), int
    ),
    **dict.fromkeys(("plan_length", "rollouts", "successes"), int),
    **dict.fromkeys(("planning_seconds", "reliability", "interval_low", "interval_high"), float),
}
SEARCH_NUMBERS: Numbers = {"solved": int, "expanded": int, "cost": int, "seconds": float}
SEARCH_TYPES = (("BFS", "blind"), ("Admiss.", "admissible"), ("Inadmiss.", "inadmissible"))
#: Receives each CSV row as soon as it is written.
Measured = Callable[[dict[str, Any]], None]
_TRANSITION_KEY = ("problem", "planner", "run")
_SEARCH_KEY = ("search", "domination", "problem", "semantics")
#: Hatching and colour of the bars and points of runs that found no plan.
UNSOLVED_HATCH = "///"
UNSOLVED_COLOR = "tab:red"


@dataclass(frozen=True)
class Planner:
    """One planner configuration of the transition comparison."""

    label: str
    semantics: str
    particles: int


def default_planners(particle_counts: Iterable[int] = (5, 25, 50)) -> list[Planner]:
    """Deterministic, particles with each count, and every other registered semantics."""
    planners = [Planner("deterministic", "deterministic", 1)]
    planners += [Planner(f"particles-{n}", "particles", n) for n in particle_counts]
    planners += [
        Planner(name, name, 1) for name in available() if name not in ("deterministic", "particles")
    ]
    return planners


def transition_comparison(
    output_dir: Path,
    *,
    problems: Sequence[str] = ("blocks-4", "blocks-7"),
    planners: Sequence[Planner] | None = None,
    runs: int = 10,
    rollouts: int = 1000,
    max_nodes: int = 5000,
    timeout: float | None = None,
    workers: int | None = None,
    controller: str | None = None,
    progress: Progress | None = None,
    measured: Measured | None = None,
) -> Path:
    """Run (or resume) the transition comparison; returns the CSV path. See module doc.

    ``controller`` (``"compliant"`` or ``"servo"``) drives every problem by that controller
    kind at its defaults, ``None`` by its own. ``progress`` gets a line as each planning run
    or evaluation starts, ``measured`` each row as it is written; the PNG shows the rows of
    ``problems``, ``planners`` and runs below ``runs``."""
    workers = workers or available_cores()
    planners = list(planners or default_planners())
    path = Path(output_dir) / "transition-comparison.csv"
    say = progress or (lambda _msg: None)
    loaded = driven_problems(problems, controller)
    settings = {
        "rollouts": rollouts,
        "max_nodes": max_nodes,
        "timeout": timeout,
        "controller": controller_setting(loaded),
        "physics": physics_setting(loaded),
    }
    with CsvAppender(
        path, TRANSITION_FIELDS, key=_TRANSITION_KEY, settings=settings, numbers=TRANSITION_NUMBERS
    ) as write:
        done = write.done  # grows as rows are written: a repeated planner is measured once
        for name in problems:
            problem = loaded[name]
            for planner in planners:
                for run in range(runs):
                    if (name, planner.label, str(run)) in done:
                        continue
                    say(f"{name} {planner.label} run {run + 1}/{runs}: planning")
                    start = time.perf_counter()
                    result = plan(
                        problem,
                        semantics=planner.semantics,
                        particles=planner.particles,
                        seed=run,
                        max_nodes=max_nodes,
                        timeout=timeout,
                        workers=workers,
                        agenda=False,  # the thesis's search, whose figures these reproduce
                    )
                    seconds = time.perf_counter() - start
                    row: dict[str, Any] = {
                        "problem": name,
                        "controller": problem.controller.kind.value,
                        "planner": planner.label,
                        "semantics": planner.semantics,
                        "particles": result.particles,
                        "run": run,
                        "seed": run,
                        "status": result.status,
                        "solved": int(result.solved),
                        "planning_seconds": round(seconds, 3),
                        "expanded": result.stats["expanded"],
                        "transitions_simulated": result.stats["transitions_simulated"],
                        "plan_length": len(result.actions) if result.actions else "",
                        "rollouts": "",
                        "successes": "",
                        "reliability": "",
                        "interval_low": "",
                        "interval_high": "",
                    }
                    if result.actions is not None and rollouts > 0:
                        say(f"{name} {planner.label} run {run + 1}/{runs}: {rollouts} rollouts")
                        reliability = evaluate_plan(
                            problem,
                            result.actions,
                            rollouts=rollouts,
                            seed=run,
                            runner=RunnerConfig(workers=workers),
                        )
                        row.update(
                            rollouts=reliability.trials,
                            successes=reliability.successes,
                            reliability=round(reliability.rate, 4),
                            interval_low=round(reliability.interval[0], 4),
                            interval_high=round(reliability.interval[1], 4),
                        )
                    write(row)
                    if measured is not None:
                        measured(row)
    rows = select_transition_rows(read_csv(path), problems, [p.label for p in planners], runs)
    plot_transition_comparison(rows, path.with_suffix(".png"), max_nodes=max_nodes)
    return path


def pending_transition_runs(
    output_dir: Path, problems: Sequence[str], planners: Sequence[Planner], runs: int
) -> list[tuple[str, str, int]]:
    """The (problem, planner label, run) a :func:`transition_comparison` call would measure:
    those not yet in ``output_dir``'s CSV."""
    done = done_keys(Path(output_dir) / "transition-comparison.csv", _TRANSITION_KEY)
    return [
        (name, planner.label, run)
        for name in problems
        for planner in planners
        for run in range(runs)
        if (name, planner.label, str(run)) not in done
    ]


def select_transition_rows(
    rows: Sequence[dict[str, str]], problems: Sequence[str], planners: Sequence[str], runs: int
) -> list[dict[str, str]]:
    """The rows of those problems and planner labels with run below ``runs``, in the order
    of ``problems`` then ``planners`` (a resumed CSV may hold them in any order, and more)."""
    order = {(p, q): k for k, (p, q) in enumerate((p, q) for p in problems for q in planners)}
    chosen = [r for r in rows if (r["problem"], r["planner"]) in order and int(r["run"]) < runs]
    return sorted(chosen, key=lambda r: (order[r["problem"], r["planner"]], int(r["run"])))


def search_table(
    output_dir: Path,
    *,
    problems: Sequence[str] = ("blocks-1", "blocks-2", "blocks-3", "blocks-4", "blocks-7"),
    semantics: str = "deterministic",
    particles: int = 1,
    max_nodes: int = 5000,
    weight: float = 1.0,
    timeout: float | None = None,
    workers: int | None = None,
    controller: str | None = None,
    progress: Progress | None = None,
    measured: Measured | None = None,
) -> Path:
    """Run (or resume) the search table (A*, weight 1, as in the thesis); returns the CSV.

    ``controller`` (``"compliant"`` or ``"servo"``) drives every problem by that controller
    kind at its defaults, ``None`` by its own. ``progress`` gets a line as each search
    starts, ``measured`` each row as it is written; the PNG shows the rows of ``problems`` and
    ``semantics``."""
    path = Path(output_dir) / "search-table.csv"
    say = progress or (lambda _msg: None)
    loaded = driven_problems(problems, controller)
    settings = {
        "particles": particles,
        "max_nodes": max_nodes,
        "weight": weight,
        "timeout": timeout,
        "controller": controller_setting(loaded),
        "physics": physics_setting(loaded),
    }
    with CsvAppender(
        path, SEARCH_FIELDS, key=_SEARCH_KEY, settings=settings, numbers=SEARCH_NUMBERS
    ) as write:
        done = write.done  # grows as rows are written: a repeated problem is measured once
        for label, heuristic in SEARCH_TYPES:
            for domination in (False, True):
                for name in problems:
                    key = (label, "yes" if domination else "no", name, semantics)
                    if key in done:
                        continue
                    say(f"{label} domination={key[1]} {name}")
                    start = time.perf_counter()
                    result = plan(
                        loaded[name],
                        semantics=semantics,
                        particles=particles,
                        seed=0,
                        max_nodes=max_nodes,
                        heuristic=heuristic,
                        dominance=domination,
                        weight=weight,
                        timeout=timeout,
                        workers=workers or 1,
                        agenda=False,  # the configurations compared search the whole goal
                    )
                    row = {
                        "search": label,
                        "heuristic": heuristic,
                        "domination": key[1],
                        "problem": name,
                        "controller": loaded[name].controller.kind.value,
                        "semantics": semantics,
                        "status": result.status,
                        "solved": int(result.solved),
                        "expanded": result.stats["expanded"],
                        "cost": len(result.actions) if result.actions else "",
                        "seconds": round(time.perf_counter() - start, 3),
                    }
                    write(row)
                    if measured is not None:
                        measured(row)
    rows = select_search_rows(read_csv(path), problems, semantics)
    plot_search_table(
        rows, Path(output_dir) / f"search-table-{semantics}.png", semantics, max_nodes=max_nodes
    )
    return path


def pending_searches(
    output_dir: Path, problems: Sequence[str], semantics: str
) -> list[tuple[int, bool, str]]:
    """The (search index into :data:`SEARCH_TYPES`, domination, problem) a
    :func:`search_table` call would measure: those not yet in ``output_dir``'s CSV."""
    done = done_keys(Path(output_dir) / "search-table.csv", _SEARCH_KEY)
    return [
        (k, domination, name)
        for k, (label, _) in enumerate(SEARCH_TYPES)
        for domination in (False, True)
        for name in problems
        if (label, "yes" if domination else "no", name, semantics) not in done
    ]


def select_search_rows(
    rows: Sequence[dict[str, str]], problems: Sequence[str], semantics: str
) -> list[dict[str, str]]:
    """The rows of those problems (in that order) and that semantics."""
    order = {name: k for k, name in enumerate(problems)}
    chosen = [r for r in rows if r["problem"] in order and r["semantics"] == semantics]
    return sorted(chosen, key=lambda r: order[r["problem"]])


# -- tables --------------------------------------------------------------------------------------
def _status(row: dict[str, str]) -> str:
    return "node limit" if row["status"] == "node-limit" else row["status"]


def transition_markdown(rows: Sequence[dict[str, str]]) -> str:
    """The transition comparison's rows as a Markdown table, one line per problem and planner
    (the table of docs/results.md): runs solved (with how the others ended), then per run the
    planning time, nodes expanded, plan length and reliability."""
    lines = [
        "| problem | planner | runs solved | planning time (s), per run | nodes expanded "
        "| plan length | reliability per run |",
        "|---|---|---|---|---|---|---|",
    ]
    for problem, planner in dict.fromkeys((r["problem"], r["planner"]) for r in rows):
        mine = [r for r in rows if r["problem"] == problem and r["planner"] == planner]
        solved = sum(r["solved"] == "1" for r in mine)
        others: dict[str, int] = {}
        for r in mine:
            if r["solved"] != "1":
                others[_status(r)] = others.get(_status(r), 0) + 1
        runs = f"{solved}/{len(mine)}" + (
            " (" + ", ".join(f"{n} {s}" for s, n in others.items()) + ")" if others else ""
        )
        reliability = [
            f"{100 * float(r['reliability']):.1f}% of {r['rollouts']}"
            if r["reliability"]
            else ("—" if r["solved"] == "1" else _status(r))
            for r in mine
        ]
        seconds = ", ".join(f"{float(r['planning_seconds']):.1f}" for r in mine)
        lines.append(
            f"| {problem} | {planner} | {runs} | {seconds} "
            f"| {', '.join(r['expanded'] for r in mine)} "
            f"| {', '.join(r['plan_length'] or '—' for r in mine)} "
            f"| {', '.join(reliability)} |"
        )
    return "\n".join(lines)


def search_markdown(rows: Sequence[dict[str, str]]) -> str:
    """The search table's rows as a Markdown table like thesis Table 3.1: one line per search
    type and domination, one column per problem, cells ``nodes expanded / plan cost`` or how
    the search ended (``node limit``, ``timeout``)."""
    problems = list(dict.fromkeys(r["problem"] for r in rows))
    lines = [
        "| search | domination | solved | " + " | ".join(problems) + " |",
        "|---|---|---|" + "---|" * len(problems),
    ]
    for label, _ in SEARCH_TYPES:
        for domination in ("no", "yes"):
            mine = {
                r["problem"]: r
                for r in rows
                if (r["search"], r["domination"]) == (label, domination)
            }
            if not mine:
                continue
            cells = []
            for problem in problems:
                r = mine.get(problem)
                if r is None:
                    cells.append("—")
                elif r["solved"] == "1":
                    cells.append(f"{r['expanded']} / {r['cost']}")
                else:
                    cells.append(f"{_status(r)} ({r['expanded']})")
            solved = sum(r["solved"] == "1" for r in mine.values())
            lines.append(
                f"| {label} | {domination} | {solved}/{len(mine)} | " + " | ".join(cells) + " |"
            )
    return "\n".join(lines)


# -- plots ---------------------------------------------------------------------------------------
def plot_transition_comparison(
    rows: Sequence[dict[str, str]], png_path: Path, *, max_nodes: int | None = None
) -> Path:
    """Bar charts of mean planning time and mean reliability per planner and problem of
    ``rows`` (see :func:`select_transition_rows`). A problem and planner with runs that found
    no plan has its time bar hatched and labelled with how many (``2/3 node limit``), and no
    reliability bar but that label; ``max_nodes`` goes into the title."""
    problems = list(dict.fromkeys(r["problem"] for r in rows))
    planners = list(dict.fromkeys(r["planner"] for r in rows))
    plt = pyplot()
    fig, (ax_time, ax_rel) = plt.subplots(1, 2, figsize=(11, 4))
    width = 0.8 / max(1, len(planners))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    unsolved_drawn = False
    for j, planner in enumerate(planners):
        color = colors[j % len(colors)]
        for i, problem in enumerate(problems):
            sel = [r for r in rows if r["problem"] == problem and r["planner"] == planner]
            if not sel:
                continue
            x = i + j * width
            seconds = mean(float(r["planning_seconds"]) for r in sel)
            failed = [r for r in sel if r["solved"] != "1"]
            ax_time.bar(
                x,
                seconds,
                width,
                color=color,
                label=planner if i == 0 else None,
                hatch=UNSOLVED_HATCH if failed else None,
                edgecolor=UNSOLVED_COLOR if failed else None,
            )
            rel = mean(float(r["reliability"]) for r in sel if r["reliability"])
            if not math.isnan(rel):
                ax_rel.bar(x, 100 * rel, width, color=color)
            if failed:
                unsolved_drawn = True
                kinds = ", ".join(dict.fromkeys(_status(r) for r in failed))
                note = f"{len(failed)}/{len(sel)} {kinds}"
                ax_time.annotate(
                    note,
                    (x, seconds),
                    ha="center",
                    va="bottom",
                    rotation=90,
                    fontsize=7,
                    color=UNSOLVED_COLOR,
                    xytext=(0, 2),
                    textcoords="offset points",
                )
                ax_rel.text(
                    x,
                    2,
                    note,
                    ha="center",
                    va="bottom",
                    rotation=90,
                    fontsize=7,
                    color=UNSOLVED_COLOR,
                )
    limit = f", node limit {max_nodes}" if max_nodes is not None else ""
    for ax, title, unit in (
        (ax_time, f"planning time (Figure 3-6){limit}", "seconds (mean of runs)"),
        (ax_rel, "execution reliability (Figure 3-7)", "% of rollouts (mean of solved runs)"),
    ):
        ax.set_xticks([i + 0.4 - width / 2 for i in range(len(problems))], problems)
        ax.set_title(title, fontsize=10)
        ax.set_ylabel(unit)
    ax_time.set_yscale("log")
    ax_rel.set_ylim(0, 100)
    handles, labels = ax_time.get_legend_handles_labels()
    if unsolved_drawn:
        handles.append(Patch(facecolor="white", edgecolor=UNSOLVED_COLOR, hatch=UNSOLVED_HATCH))
        labels.append("runs without a plan")
    ax_rel.legend(handles, labels, fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)
    plt.close(fig)
    return png_path


def plot_search_table(
    rows: Sequence[dict[str, str]],
    png_path: Path,
    semantics: str,
    *,
    max_nodes: int | None = None,
) -> Path:
    """Nodes expanded per problem of ``rows`` (see :func:`select_search_rows`) for each search
    type and domination setting (log scale). A search that found no plan is drawn as a red
    cross at the nodes it expanded, labelled with how it ended (``node limit``)."""
    problems = list(dict.fromkeys(r["problem"] for r in rows))
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4))
    unsolved_drawn = False
    for label, _ in SEARCH_TYPES:
        for domination, style in (("no", "--"), ("yes", "-")):
            ys = []
            for i, problem in enumerate(problems):
                sel = [
                    r
                    for r in rows
                    if r["search"] == label
                    and r["domination"] == domination
                    and r["problem"] == problem
                ]
                solved = [r for r in sel if r["solved"] == "1"]
                ys.append(float(solved[0]["expanded"]) if solved else float("nan"))
                for r in sel:
                    if r["solved"] != "1":
                        unsolved_drawn = True
                        ax.plot(i, float(r["expanded"]), "x", color=UNSOLVED_COLOR, ms=8)
            if any(not math.isnan(y) for y in ys):
                ax.plot(
                    range(len(problems)),
                    ys,
                    style,
                    marker="o",
                    label=f"{label}, domination {domination}",
                )
    if unsolved_drawn:
        ax.plot([], [], "x", color=UNSOLVED_COLOR, ms=8, label="no plan (node limit or timeout)")
    ax.set_yscale("log")
    ax.set_xticks(range(len(problems)), problems)
    ax.set_xlim(-0.4, len(problems) - 0.6)
    ax.set_ylabel("nodes expanded")
    limit = f", node limit {max_nodes}" if max_nodes is not None else ""
    ax.set_title(f"search table (Table 3.1), {semantics} transitions{limit}", fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)
    plt.close(fig)
    return png_path
