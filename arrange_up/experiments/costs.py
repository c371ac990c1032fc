"""What the experiments' measurements cost: a table of measured per-run costs, so that every
experiment command can say how long it will take before it starts.

The figures are those of the runs behind ``docs/results.md`` (its commands, on the 2-core
development machine while other jobs ran; docs/design/figures.md says how each was read
from the CSVs in ``docs/results/servo/``; every one was measured under the servo controller).
They are estimates: wall times on a shared machine vary by a factor of two, and a
configuration not in the table (another problem, planner or particle count) is reported as
unknown rather than guessed, except where a cost scales with something measured (nodes,
particles, rollouts).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    "ROLLOUT_SECONDS",
    "Estimate",
    "fixture_cost",
    "format_duration",
    "planning_cost",
    "rollout_cost",
    "search_cost",
]

#: Mean planning seconds and nodes expanded per run of the transition comparison (weighted A*,
#: default search, node limit 5000), by (problem, planner label).
PLANNING_SECONDS: dict[tuple[str, str], tuple[float, int]] = {
    ("blocks-4", "deterministic"): (0.2, 24),
    ("blocks-4", "particles-5"): (1.0, 55),
    ("blocks-4", "particles-25"): (2.4, 43),
    ("blocks-4", "particles-50"): (6.6, 68),
    ("blocks-4", "cbst"): (0.5, 43),
    ("blocks-7", "deterministic"): (3.7, 338),
    ("blocks-7", "particles-5"): (186.6, 5000),
    ("blocks-7", "particles-25"): (392.8, 3346),
    ("blocks-7", "particles-50"): (394.5, 3216),
    ("blocks-7", "cbst"): (1.4, 334),
}

#: Seconds and nodes expanded of each search of the search table (A*, node limit 5000), by
#: semantics and problem, in the order (BFS, Admiss., Inadmiss.) x (domination no, yes).
SEARCH_SECONDS: dict[str, dict[str, tuple[tuple[float, int], ...]]] = {
    "deterministic": {
        "blocks-1": ((0.07, 7), (0.01, 4), (0.02, 7), (0.02, 4), (0.02, 4), (0.01, 3)),
        "blocks-2": ((0.14, 114), (0.04, 17), (0.10, 71), (0.03, 11), (0.20, 132), (0.03, 9)),
        "blocks-3": ((3.75, 2751), (0.21, 78), (2.27, 1322), (0.17, 46), (3.51, 1815), (0.13, 36)),
        "blocks-4": (
            (6.60, 5000), (1.16, 386), (11.87, 5000), (0.40, 96), (12.91, 5000), (0.46, 106),
        ),
        "blocks-7": (
            (6.03, 5000), (11.11, 5000), (13.16, 5000), (33.62, 5000), (15.57, 5000),
            (23.11, 3742),
        ),
    },
    "cbst": {
        "blocks-1": ((1.39, 5), (0.01, 4), (0.01, 5), (0.01, 4), (0.01, 4), (0.01, 3)),
        "blocks-2": ((0.06, 34), (0.04, 17), (0.04, 22), (0.03, 11), (0.07, 36), (0.03, 9)),
        "blocks-3": ((1.11, 714), (0.14, 61), (0.96, 550), (0.12, 38), (0.39, 202), (0.10, 35)),
        "blocks-4": ((3.99, 2631), (0.31, 161), (1.65, 830), (0.20, 58), (2.82, 1230), (0.24, 65)),
        "blocks-7": (
            (7.06, 5000), (16.40, 4579), (13.39, 5000), (8.10, 1360), (14.32, 5000),
            (6.67, 1142),
        ),
    },
}  # fmt: skip

#: Seconds per noisy rollout of a plan that succeeds (a failing rollout stops early and costs
#: less), by problem, on all cores of the development machine.
ROLLOUT_SECONDS: dict[str, float] = {
    "blocks-4": 0.02,
    "blocks-7": 0.035,
}

#: Seconds per particle of a fixture repair (enhanced method, one process), and seconds of
#: finding the nominal plans, by problem; rollouts as in :data:`ROLLOUT_SECONDS`.
REPAIR_SECONDS_PER_PARTICLE: dict[str, float] = {
    "down-push": 0.13,
    "tt-mating": 0.36,
    "tz-mating": 0.43,
    "create-a-t": 0.31,
    "tt-mating-noisy": 0.36,
}
#: The same for a repair without fixtures (the fixtures' ablation: no placement candidates,
#: so about a twentieth of a full repair): one run with 40 particles on each problem's first
#: nominal plan under the servo (docs/design/figures.md gives the command).
ABLATION_SECONDS_PER_PARTICLE: dict[str, float] = {
    "down-push": 0.011,
    "tt-mating": 0.023,
    "tz-mating": 0.023,
    "create-a-t": 0.020,
    "tt-mating-noisy": 0.020,
}
FIXTURE_ROLLOUT_SECONDS = 0.003


@dataclass
class Estimate:
    """A duration estimate: ``seconds`` over the ``known`` measurements, and the names of the
    configurations with no measured cost (``unknown``)."""

    seconds: float = 0.0
    known: int = 0
    unknown: list[str] | None = None

    def add(self, seconds: float | None, what: str) -> None:
        """Count one measurement costing ``seconds`` (``None``: not measured, named ``what``)."""
        if seconds is None:
            self.unknown = [*(self.unknown or []), what]
        else:
            self.seconds += seconds
            self.known += 1

    def describe(self, measurements: int) -> str:
        """One line for the command line: how many measurements and about how long."""
        if measurements == 0:
            return "nothing to measure: every measurement is already in the CSV"
        text = f"{measurements} measurement{'s' if measurements != 1 else ''} to make"
        if self.known:
            text += f"; about {format_duration(self.seconds)}"
            if self.unknown:
                text += f" for {self.known} of them"
        unknown = list(dict.fromkeys(self.unknown or []))
        if unknown:
            shown = ", ".join(unknown[:4]) + (", ..." if len(unknown) > 4 else "")
            text += f" (no measured cost for {shown})"
        return text + " (estimated from measured runs; a shared machine may take twice as long)"


def format_duration(seconds: float) -> str:
    """``seconds`` as a rough duration: ``40 s``, ``12 min``, ``1 h 05 min``."""
    if seconds < 60:
        return f"{max(1, round(seconds))} s"
    minutes = round(seconds / 60)
    if minutes < 60:
        return f"{minutes} min"
    return f"{minutes // 60} h {minutes % 60:02d} min"


def _capped(seconds: float, expanded: int, max_nodes: int) -> float:
    """A measured run's cost at another node limit: the same run when it stopped within the
    limit, else the limit's share of it (per-node cost taken as constant)."""
    if expanded <= max_nodes and expanded < 5000:
        return seconds
    return seconds * max_nodes / max(1, expanded)


def planning_cost(problem: str, planner: str, max_nodes: int) -> float | None:
    """Seconds of one transition-comparison planning run, or None when not measured."""
    entry = PLANNING_SECONDS.get((problem, planner))
    return None if entry is None else _capped(*entry, max_nodes)


def rollout_cost(problem: str, rollouts: int) -> float | None:
    """Seconds of evaluating one plan over ``rollouts`` rollouts, or None when not measured."""
    if rollouts == 0:
        return 0.0
    per = ROLLOUT_SECONDS.get(problem)
    return None if per is None else per * rollouts


def search_cost(
    semantics: str, problem: str, search: int, domination: bool, max_nodes: int
) -> float | None:
    """Seconds of one search-table search (``search`` indexes BFS, Admiss., Inadmiss.), or
    None when not measured."""
    table = SEARCH_SECONDS.get(semantics, {}).get(problem)
    if table is None:
        return None
    return _capped(*table[2 * search + int(domination)], max_nodes)


def fixture_cost(
    problem: str, particles: int | None, rollouts: int, *, fixtures: bool = True
) -> float | None:
    """Seconds of one row of the fixture experiment: a nominal plan's evaluation
    (``particles`` None) or a repair with ``particles`` (without fixtures unless ``fixtures``:
    the ablation) and its evaluation; None when the problem's repairs were not measured."""
    table = REPAIR_SECONDS_PER_PARTICLE if fixtures else ABLATION_SECONDS_PER_PARTICLE
    per = table.get(problem)
    if per is None:
        return None
    return per * (particles or 0) + FIXTURE_ROLLOUT_SECONDS * rollouts
