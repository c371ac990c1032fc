"""The compiled problem: one collision checker, angle frame and goal test per problem object,
shared by the planner's semantics and action generator."""

from __future__ import annotations

import dataclasses

from catalogue import tiny

from arrange_up.belief.compiled import CompiledProblem, compile_problem
from arrange_up.belief.states import AngleFrame
from arrange_up.model.world import WorldState
from arrange_up.planning.config import PlanConfig, SearchConfig
from arrange_up.planning.task import BeliefTask


def test_one_compiled_problem_per_problem_object():
    problem = tiny("two-blocks-row")
    compiled = compile_problem(problem)
    assert compile_problem(problem) is compiled
    assert compiled.checker is compiled.checker and compiled.goal is compiled.goal
    # An equal problem that is another object gets its own.
    twin = dataclasses.replace(problem)
    assert twin == problem and compile_problem(twin) is not compiled


def test_its_members_are_those_the_problem_derives():
    problem = tiny("l-part")
    compiled = CompiledProblem(problem)
    frame = AngleFrame.of(problem)
    assert (compiled.frame.reference, compiled.frame.period) == (frame.reference, frame.period)
    start = WorldState(tuple((e.name, e.pose) for e in problem.initial))
    assert compiled.goal.misses(start) == compile_problem(problem).goal.misses(start)


def test_the_planners_semantics_and_generator_share_one_checker():
    problem = tiny("two-blocks-row")
    task = BeliefTask.build(
        problem, PlanConfig(particles=2, seed=0, search=SearchConfig(heuristic="manhattan"))
    )
    try:
        compiled = compile_problem(problem)
        assert task.generator.checker is compiled.checker
        assert task.semantics.checker is compiled.checker
        assert task.goal is compiled.goal
    finally:
        task.close()
