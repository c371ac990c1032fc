"""The goal agenda: its order from the goal's geometry, subgoals, backtracking and fallback."""

from __future__ import annotations

import pytest
from catalogue import tiny

from arrange_up.io.domains import load
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
    result = plan(load("blocks-2"), semantics="deterministic", progress=stages.append)
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
    result = plan(load("blocks-2"), semantics="deterministic")
    assert result.solved and result.agenda.solved_by == "full search"
    assert result.agenda.failed_at == ("A",) and result.agenda.subgoals == (("B",),)
    assert result.agenda.line().startswith("solved by the full search (the agenda failed at part 2")
    # the run's statistics count the agenda's nodes and the full search's
    alone = plan(load("blocks-2"), semantics="deterministic", agenda=False)
    assert result.stats["expanded"] == result.agenda.expanded + alone.stats["expanded"]
    assert result.actions == alone.actions


@pytest.mark.parametrize("semantics", ["deterministic", "particles"])
def test_the_agenda_plans_for_every_particle(semantics):
    result = plan(load("blocks-3"), semantics=semantics, particles=5, workers=1, validate=0)
    assert result.solved and result.agenda.solved_by == "agenda"
