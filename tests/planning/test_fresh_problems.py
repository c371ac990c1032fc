"""The problems of tests/problems/fresh, written from the format alone for the kinds the action
generator once could not plan (benchmarks/fresh_problems.py measures them at full size): they
load, and the two that need the generator's narrowing pushes and reference ladder plan."""

from __future__ import annotations

from pathlib import Path

import pytest

import arrange_up
from arrange_up.belief.goals import GoalTest
from arrange_up.io.yaml_problem import load_problem
from arrange_up.model.world import Push

FRESH = Path(__file__).parents[1] / "problems" / "fresh"


@pytest.mark.parametrize("path", sorted(FRESH.glob("*.yaml")), ids=lambda p: p.stem)
def test_every_fresh_problem_loads(path: Path):
    assert load_problem(path).name == path.stem


def test_a_belief_centred_on_target_but_too_wide_is_narrowed_from_both_sides():
    problem = load_problem(FRESH / "narrow-squeeze.yaml")
    result = arrange_up.plan(problem, particles=10, workers=1)
    assert result.solved, result.reason
    directions = {round(a.pose[2], 3) for a in result.actions if isinstance(a, Push)}
    assert {-1.571, 1.571} <= directions  # pushed right and pushed left
    final = result.beliefs[-1]
    assert GoalTest(problem).satisfied_array(final.poses, final.names())


def test_a_relative_pair_plans_once_its_reference_has_moved_from_the_edge():
    problem = load_problem(FRESH / "relative-pair.yaml")
    result = arrange_up.plan(problem, particles=10, workers=1)
    assert result.solved, result.reason
    assert isinstance(result.actions[0], Push)  # A makes room before B is placed
