"""One problem's derived geometry, built once and shared by every consumer.

The planner's semantics, action generator, heuristics and goal test, the evaluation's rollouts
and the repair all derive the same things from an
:class:`~arrange_up.model.problem.ArrangementProblem`: its collision checker (shapes, walls,
obstacle boxes, belief shadows), its angle frame and its goal test. A :class:`CompiledProblem`
builds each on first use and keeps it; :func:`compile_problem` returns the one of a problem
object (kept for the few problems most recently asked for), so the consumers of one run share
one of each instead of each building its own. The planner compiles its problem once and hands
the compiled problem down (its search, task, action generator, heuristic, workers and
validation), not the problem.
"""

from __future__ import annotations

from collections import OrderedDict
from functools import cached_property

from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import AngleFrame
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem


class CompiledProblem:
    """What consumers derive from ``problem``, each built on first use (see the module
    docstring). Every member is a pure function of the problem: sharing one changes no
    result."""

    def __init__(self, problem: ArrangementProblem) -> None:
        self.problem = problem

    def __reduce__(self) -> tuple[object, tuple[ArrangementProblem]]:
        """Pickled as its problem alone, and compiled again where it is unpickled (a worker
        builds its own members on first use, where shipping them would cost more)."""
        return compile_problem, (self.problem,)

    @cached_property
    def checker(self) -> CollisionChecker:
        """The problem's collision checker (shapes, walls, obstacle boxes, shadows)."""
        return CollisionChecker(self.problem)

    @cached_property
    def frame(self) -> AngleFrame:
        """The problem's angle frame (reference angle and symmetry period per object)."""
        return AngleFrame.of(self.problem)

    @cached_property
    def goal(self) -> GoalTest:
        """The problem's goal test."""
        return GoalTest(self.problem)


#: How many problems' compiled geometry is kept (the most recently asked for): one run asks for
#: one problem's, the repair for a few scaled copies of it.
KEPT = 4
#: id(problem) -> its compiled problem, the most recently asked for last. Each entry holds its
#: problem, so no other object can take that id while the entry is kept.
_COMPILED: OrderedDict[int, CompiledProblem] = OrderedDict()


def compile_problem(problem: ArrangementProblem) -> CompiledProblem:
    """The :class:`CompiledProblem` of ``problem`` (this very object, not an equal one): the
    same one on every call while it is among the ``KEPT`` most recently asked for."""
    compiled = _COMPILED.get(id(problem))
    if compiled is None or compiled.problem is not problem:
        compiled = CompiledProblem(problem)
        _COMPILED[id(problem)] = compiled
        while len(_COMPILED) > KEPT:
            _COMPILED.popitem(last=False)
    _COMPILED.move_to_end(id(problem))
    return compiled
