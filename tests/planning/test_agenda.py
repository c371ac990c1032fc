"""The goal agenda: its order from the goal's geometry, subgoals, backtracking and fallback."""

from __future__ import annotations

import dataclasses

import pytest
from catalogue import tiny

from arrange_up.belief.compiled import compile_problem
from arrange_up.io.domains import load
from arrange_up.io.generate import generate_problem
from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.planning import agenda
from arrange_up.planning.agenda import goal_order, restricted
from arrange_up.planning.planner import plan


def test_parts_are_ordered_from_the_walls_corner_outwards():
    # blocks-9: a row of six along the bottom wall from the right corner (A-F) and three on
    # top against the right wall (G-I). Each part goes in once both its sides are held: by a
    # wall or a part already ordered.
    assert goal_order(load("blocks-9")) == ("A", "B", "G", "H", "C", "I", "D", "E", "F")
    assert goal_order(load("blocks-2")) == ("A", "B")


def test_the_agenda_does_not_apply_to_one_part_or_a_relative_goal():
    assert goal_order(tiny("one-block")) is None
    assert goal_order(tiny("relative-goal")) is None


def test_a_subgoal_holds_the_goal_of_its_parts_only():
    problem = load("blocks-9")
    sub = restricted(problem, ("A", "G"))
    assert sub.goal.parts == ("A", "G")
    assert sub.goal.target("G") == problem.goal.target("G")
    assert sub.goal.tolerance == problem.goal.tolerance and sub.objects == problem.objects


def test_the_agenda_plans_part_by_part_and_records_it():
    problem = load("blocks-3")
    stages = []
    result = plan(problem, semantics="deterministic", progress=stages.append)
    assert result.solved and result.agenda is not None
    assert result.agenda.solved_by == "agenda"
    assert result.agenda.subgoals == (("A",), ("B",), ("C",))
    assert result.agenda.line() == "solved by the agenda (3 subgoals: A B C)"
    # the beliefs run from the start through every subgoal's plan
    assert len(result.beliefs) == len(result.actions) + 1
    assert {s["stage"] for s in stages} == {"part 1 of 3 (A)", "part 2 of 3 (B)", "part 3 of 3 (C)"}
    assert result.stats["expanded"] == result.agenda.expanded
    # the plan file records the agenda
    assert result.document(problem)["agenda"]["order"] == ["A", "B", "C"]


def test_a_failed_subgoal_is_searched_again_with_its_predecessor(monkeypatch):
    # B first walls A out of the corner: A alone cannot follow, so B is searched again
    # together with A, from the start.
    monkeypatch.setattr(agenda, "goal_order", lambda problem: ("B", "A"))
    stages = []
    # (a small node limit: A alone fails only once its share of the limit is spent)
    result = plan(
        load("blocks-2"), semantics="deterministic", progress=stages.append, max_nodes=400
    )
    assert result.solved and result.agenda.solved_by == "agenda"
    assert result.agenda.subgoals == (("B", "A"),)
    # the progress counts a group's parts as the result line does: from the first it adds
    assert [s["stage"] for s in stages if "+" in s["stage"]][-1] == "parts 1-2 of 2 (B+A)"


def test_the_parts_a_subgoal_adds_are_labelled_from_its_first():
    assert agenda.parts_label(2, 1, 13) == "part 3 of 13"
    assert agenda.parts_label(0, 3, 13) == "parts 1-3 of 13"


def test_where_the_agenda_fails_the_full_search_plans(monkeypatch):
    monkeypatch.setattr(agenda, "goal_order", lambda problem: ("B", "A"))
    monkeypatch.setattr(agenda, "MAX_GROUP", 1)  # no regrouping: the agenda fails at A
    result = plan(load("blocks-2"), semantics="deterministic", max_nodes=400)
    assert result.solved and result.agenda.solved_by == "full search"
    assert result.agenda.failed_at == ("A",) and result.agenda.subgoals == (("B",),)
    assert result.agenda.line().startswith("solved by the full search (the agenda failed at part 2")
    # the run's statistics count the agenda's nodes and the full search's
    alone = plan(load("blocks-2"), semantics="deterministic", agenda=False, max_nodes=400)
    assert result.stats["expanded"] == result.agenda.expanded + alone.stats["expanded"]
    assert result.actions == alone.actions


@pytest.mark.parametrize("semantics", ["deterministic", "particles"])
def test_the_agenda_plans_for_every_particle(semantics):
    result = plan(load("blocks-3"), semantics=semantics, particles=5, workers=1, validate=0)
    assert result.solved and result.agenda.solved_by == "agenda"


def _relative(parts: int, walls: list[str] | None = None):
    problem = load_problem_text(generate_problem("relative", parts, 0))
    if walls is not None:
        problem = dataclasses.replace(
            problem, table=dataclasses.replace(problem.table, walls=tuple(walls))
        )
    return problem


def test_a_relative_goal_is_grounded_flush_in_the_corner_nearest_its_reference():
    problem = _relative(4)
    base = agenda.grounded(problem)
    assert base is not None and not base.goal.is_relative
    reference = problem.goal.reference
    assert base.goal.parts[0] == reference and base.goal.target(reference) == (0.5, 0.5, 0.0)
    # the mates keep their places in the reference's frame
    for name, (x, y, theta) in problem.goal.targets:
        assert base.goal.target(name) == pytest.approx((0.5 + x, 0.5 + y, theta))
    assert base.goal.tolerance == problem.goal.tolerance
    # without a corner of two walls, or for a pair, or an absolute goal: none
    assert agenda.grounded(_relative(4, ["left", "right"])) is None
    assert agenda.grounded(_relative(4, ["bottom", "right"])).goal.target(reference)[1] == 0.5
    assert agenda.grounded(_relative(2)) is None
    assert agenda.grounded(load("blocks-3")) is None


def test_a_grounded_relative_goal_is_built_part_by_part_then_checked_as_relative():
    problem = _relative(4)
    stages = []
    result = plan(problem, particles=5, workers=1, validate=0, progress=stages.append)
    assert result.solved and result.agenda.solved_by == "agenda"
    assert result.agenda.grounded == (0.5, 0.5, 0.0)
    assert result.agenda.line().startswith("solved by the agenda (grounded in a corner; 4 subgoals")
    assert {s["stage"] for s in stages} >= {"part 1 of 4 (A)", "the relative goal"}
    assert result.document(problem)["agenda"]["grounded"] is True
    # the plan reaches the relative goal itself in every particle
    assert compile_problem(problem).goal.satisfied_array(
        result.beliefs[-1].poses, result.beliefs[-1].names()
    )
