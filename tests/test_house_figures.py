"""``benchmarks/house.py`` counts what its docstring says, on a small package written here: the
walk's stops, climbs and returns, the sizes, and its room order is the house rule's."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from house import Index, measure, walk  # noqa: E402

PACKAGE = {
    "__init__.py": "",
    "model/__init__.py": "",
    "model/problem.py": """
def digest(problem):
    return hash(problem)
""",
    "geometry/__init__.py": "from arrange_up.geometry.collision import Checker\n",
    "geometry/collision.py": """
from arrange_up.model.problem import digest


class Checker:
    def __init__(self, problem):
        self.problem = problem
        self.walls = walls(problem)

    def hits(self):
        return digest(self.problem)

    def size(self):
        return 1


def walls(problem):
    return [problem]
""",
    "planning/__init__.py": "",
    "planning/task.py": """
from dataclasses import dataclass


@dataclass
class Task:
    problem: object

    def run(self):
        return _helper(self.problem)


def _helper(problem, a=1, b=2, c=3, d=4, e=5, f=6, g=7, h=8, *rest, **options):
    problem.check()
""",
    "planning/planner.py": """
from typing import Any

from arrange_up.geometry import Checker
from arrange_up.model import problem as model_problem
from arrange_up.planning.task import Task


def plan(problem: Any, limit: int) -> Any:  # type: ignore[misc]
    p = problem
    checker = Checker(p)
    key = model_problem.digest(problem.table)
    task = Task(problem=problem)
    again = Checker(problem)
    return task.run()
""",
}


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("checkout")
    for name, text in PACKAGE.items():
        path = root / "arrange_up" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text.lstrip(), encoding="utf-8")
    return root


def test_the_walk_counts_stops_climbs_and_returns(root: Path) -> None:
    found = walk(Index(root), "arrange_up.planning.planner:plan", "problem")
    stops = [(s.caller.split(":")[1], s.callee.split(":")[1], s.climb) for s in found.stops]
    assert sorted(stops) == sorted(
        [
            ("plan", "Checker.__init__", True),  # through the alias p, re-exported class
            ("plan", "Task", False),  # a dataclass's field, by keyword
            ("plan", "Checker.__init__", True),  # a second call: a stop, not a second visit
            ("Checker.__init__", "walls", False),
            ("Checker.hits", "digest", True),  # kept on self, handed on by a method
            ("Task.run", "_helper", False),
        ]
    )  # problem.table is derived, not the value: digest(problem.table) is no stop
    assert found.summary()["climbs"] == 3
    assert sorted(name.split(":")[1] for name in found.returns) == [
        "Checker.hits", "Task.run", "digest", "plan", "walls",
    ]  # fmt: skip
    assert "arrange_up.geometry.collision:Checker.size" not in found.reached
    assert len(found.reached) == 7


def test_the_sizes(root: Path) -> None:
    figures = measure(root, walks={})
    assert figures["largest_class"]["class"] == "arrange_up.geometry.collision:Checker"
    assert figures["largest_class"]["methods"] == 3
    assert figures["largest_class"]["attributes"] == 2
    assert figures["most_parameters"] == {"arrange_up.planning.task:_helper": 11}
    assert figures["type_ignore_comments"] == 1
    assert figures["any_in_annotations"] == 2
