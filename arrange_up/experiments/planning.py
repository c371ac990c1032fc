"""The thesis's chapter-3 experiments, as resumable library functions.

* :func:`transition_comparison` (Figures 3-6 and 3-7): for each problem and planner
  (deterministic, particles with 5/25/50 particles, and any other registered semantics), R
  planning runs with different seeds: planning time, whether a plan was found within the node
  limit, and the plan's reliability over N noisy rollouts.
* :func:`search_table` (Table 3.1): blind, admissible and inadmissible heuristics, each with
  and without domination, on 1, 2, 3, 4 and 7 blocks: nodes expanded and plan cost.

Both append every raw measurement to a CSV as soon as it is made and skip the rows a previous
run already wrote, so an interrupted experiment resumes where it stopped; both draw a PNG
summary. Sizes scale down by arguments (the CLI's flags).
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.experiments.csv_records import CsvAppender, Progress, done_keys, mean, read_csv
from arrange_up.figures.backend import pyplot
from arrange_up.io.domains import load
from arrange_up.parallel import available_cores
from arrange_up.planning.planner import plan
from arrange_up.transitions import available

TRANSITION_FIELDS = [
    "problem",
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
    "semantics",
    "status",
    "solved",
    "expanded",
    "cost",
    "seconds",
]
SEARCH_TYPES = (("BFS", "blind"), ("Admiss.", "admissible"), ("Inadmiss.", "inadmissible"))


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
    progress: Progress | None = None,
) -> Path:
    """Run (or resume) the transition comparison; returns the CSV path. See module doc."""
    workers = workers or available_cores()
    planners = list(planners or default_planners())
    path = Path(output_dir) / "transition-comparison.csv"
    done = done_keys(path, ("problem", "planner", "run"))
    say = progress or (lambda _msg: None)
    with CsvAppender(path, TRANSITION_FIELDS) as write:
        for name in problems:
            problem = load(name)
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
                    )
                    seconds = time.perf_counter() - start
                    row: dict[str, Any] = {
                        "problem": name,
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
                            workers=workers,
                        )
                        row.update(
                            rollouts=reliability.trials,
                            successes=reliability.successes,
                            reliability=round(reliability.rate, 4),
                            interval_low=round(reliability.interval[0], 4),
                            interval_high=round(reliability.interval[1], 4),
                        )
                    write(row)
    plot_transition_comparison(path, path.with_suffix(".png"))
    return path


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
    progress: Progress | None = None,
) -> Path:
    """Run (or resume) the search table (A*, weight 1, as in the thesis); returns the CSV."""
    path = Path(output_dir) / "search-table.csv"
    done = done_keys(path, ("search", "domination", "problem", "semantics"))
    say = progress or (lambda _msg: None)
    with CsvAppender(path, SEARCH_FIELDS) as write:
        for label, heuristic in SEARCH_TYPES:
            for domination in (False, True):
                for name in problems:
                    key = (label, "yes" if domination else "no", name, semantics)
                    if key in done:
                        continue
                    say(f"{label} domination={key[1]} {name}")
                    start = time.perf_counter()
                    result = plan(
                        load(name),
                        semantics=semantics,
                        particles=particles,
                        seed=0,
                        max_nodes=max_nodes,
                        heuristic=heuristic,
                        dominance=domination,
                        weight=weight,
                        timeout=timeout,
                        workers=workers or 1,
                    )
                    write(
                        {
                            "search": label,
                            "heuristic": heuristic,
                            "domination": key[1],
                            "problem": name,
                            "semantics": semantics,
                            "status": result.status,
                            "solved": int(result.solved),
                            "expanded": result.stats["expanded"],
                            "cost": len(result.actions) if result.actions else "",
                            "seconds": round(time.perf_counter() - start, 3),
                        }
                    )
    plot_search_table(path, Path(output_dir) / f"search-table-{semantics}.png", semantics)
    return path


# -- plots ---------------------------------------------------------------------------------------
def plot_transition_comparison(csv_path: Path, png_path: Path) -> Path:
    """Bar charts of mean planning time and mean reliability per planner and problem."""
    rows = read_csv(csv_path)
    problems = sorted({r["problem"] for r in rows})
    planners = list(dict.fromkeys(r["planner"] for r in rows))
    plt = pyplot()
    fig, (ax_time, ax_rel) = plt.subplots(1, 2, figsize=(11, 4))
    width = 0.8 / max(1, len(planners))
    for j, planner in enumerate(planners):
        times, rels = [], []
        for problem in problems:
            sel = [r for r in rows if r["problem"] == problem and r["planner"] == planner]
            times.append(mean(float(r["planning_seconds"]) for r in sel))
            rels.append(100 * mean(float(r["reliability"]) for r in sel if r["reliability"]))
        xs = [i + j * width for i in range(len(problems))]
        ax_time.bar(xs, times, width, label=planner)
        ax_rel.bar(xs, rels, width, label=planner)
    for ax, title, unit in (
        (ax_time, "planning time (Figure 3-6)", "seconds (mean)"),
        (ax_rel, "execution reliability (Figure 3-7)", "% of rollouts"),
    ):
        ax.set_xticks([i + 0.4 - width / 2 for i in range(len(problems))], problems)
        ax.set_title(title, fontsize=10)
        ax.set_ylabel(unit)
    ax_time.set_yscale("log")
    ax_rel.set_ylim(0, 100)
    ax_rel.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)
    plt.close(fig)
    return png_path


def plot_search_table(csv_path: Path, png_path: Path, semantics: str) -> Path:
    """Nodes expanded per problem for each search type and domination setting (log scale),
    for the rows of one semantics."""
    rows = [r for r in read_csv(csv_path) if r["semantics"] == semantics]
    problems = list(dict.fromkeys(r["problem"] for r in rows))
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4))
    for label, _ in SEARCH_TYPES:
        for domination, style in (("no", "--"), ("yes", "-")):
            ys = []
            for problem in problems:
                sel = [
                    r
                    for r in rows
                    if r["search"] == label
                    and r["domination"] == domination
                    and r["problem"] == problem
                    and r["solved"] == "1"
                ]
                ys.append(float(sel[0]["expanded"]) if sel else float("nan"))
            ax.plot(problems, ys, style, marker="o", label=f"{label}, domination {domination}")
    ax.set_yscale("log")
    ax.set_ylabel("nodes expanded (solved runs)")
    ax.set_title(f"search table (Table 3.1), {semantics} transitions", fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)
    plt.close(fig)
    return png_path
