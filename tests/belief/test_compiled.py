"""The compiled problem: one collision checker, angle frame and goal test per problem object,
shared by the planner's semantics and action generator."""

from __future__ import annotations

import dataclasses
import pickle

import numpy as np
from catalogue import tiny

from arrange_up.belief.compiled import CompiledProblem, compile_problem
from arrange_up.belief.states import AngleFrame, sample_initial_particles
from arrange_up.model.world import WorldState
from arrange_up.planning.config import PlanConfig, SearchConfig
from arrange_up.planning.heuristics import make_heuristic
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
        compile_problem(problem),
        PlanConfig(particles=2, seed=0, search=SearchConfig(heuristic="manhattan")),
    )
    try:
        compiled = compile_problem(problem)
        assert task.generator.checker is compiled.checker
        assert task.semantics.checker is compiled.checker
        assert task.goal is compiled.goal
    finally:
        task.close()


def test_a_pickled_compiled_problem_travels_as_its_problem():
    problem = tiny("two-blocks-row")
    compiled = compile_problem(problem)
    assert compiled.checker is not None  # built here; a worker builds its own
    travelled = pickle.loads(pickle.dumps(compiled))
    assert travelled.problem == problem and travelled.problem is not problem
    assert "checker" not in vars(travelled)
    assert compile_problem(travelled.problem) is travelled


def test_the_heuristic_and_the_initial_particles_use_the_compiled_members():
    problem = tiny("two-blocks-row")
    compiled = compile_problem(problem)
    belief = sample_initial_particles(compiled, 3, np.random.default_rng(0))
    assert not any(compiled.checker.state_collides(s) for s in belief.particles)
    assert belief.particles == tuple(compiled.frame.canonical(s) for s in belief.particles)
    assert make_heuristic("inadmissible", compiled)(belief) > 0  # both parts still to place
