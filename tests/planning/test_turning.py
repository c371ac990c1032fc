"""Turning pushes (arrange_up.planning.actions, TURN_OFFSET): a part turned away from its goal
angle is also offered pushes that press one side of it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from catalogue import particle_task

from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.domains import load
from arrange_up.io.yaml_problem import load_problem
from arrange_up.model.world import Push
from arrange_up.planning.actions import ActionGenerator
from arrange_up.planning.generators.approach import TURN_OFFSET

ELL_NOOK = Path(__file__).resolve().parents[1] / "problems" / "fresh" / "mm-ell-nook.yaml"


def _pushes_down(push: Push) -> bool:
    """The paddle turned by pi (either sign), which pushes toward -y."""
    return abs(math.cos(push.pose[2]) + 1.0) < 1e-9


def test_an_ell_turned_away_from_its_goal_is_squared_by_a_push_on_one_side():
    # The L starts turned 0.6 rad and must end square (+-0.26 rad): centred pushes leave it
    # turned (29-64 degrees), a push down to the wall on its long arm's side squares it.
    problem = load_problem(ELL_NOOK)
    shift = TURN_OFFSET * problem.object("paddle").shape.box[0]
    with particle_task(problem, 10) as task:
        down = [
            edge
            for edge in task.successors(task.initial_belief())
            if isinstance(edge.action, Push) and _pushes_down(edge.action)
        ]
        # centred on the belief's centre, and shifted to either side
        xs = sorted({edge.action.pose[0] for edge in down})
        assert len(xs) == 3 and np.allclose(np.diff(xs), shift, atol=1e-5)
        centre = xs[1]

        def turned_by(edge) -> float:
            """The largest angle (rad) of the L over the particles after the push."""
            child = edge.make_child()
            return float(np.abs(child.poses[:, child.names().index("L"), 2]).max())

        tolerance = problem.goal.tolerance[2]
        centred = [edge for edge in down if abs(edge.action.pose[0] - centre) < 1e-9]
        long_arm = [edge for edge in down if edge.action.pose[0] > centre + 0.5 * shift]
        assert all(turned_by(edge) > tolerance for edge in centred)
        # on the long arm's side, a push down to the wall squares it in every particle
        assert min(turned_by(edge) for edge in long_arm) <= tolerance


def test_a_part_within_its_goal_angle_gets_no_turning_pushes():
    problem = load("blocks-2")
    gen = ActionGenerator(problem, CollisionChecker(problem))
    square = IntervalBelief((("A", ObjectInterval((5.0, 2.5, 0.0), (0.2, 0.2, 0.2))),))
    turned = IntervalBelief((("A", ObjectInterval((5.0, 2.5, 0.5), (0.2, 0.2, 0.2))),))

    def across(belief):
        return {p.pose[0] for p in gen.pushes(belief) if _pushes_down(p)}

    assert across(square) == {5.0}
    shift = TURN_OFFSET * 2.5
    assert across(turned) == {5.0, 5.0 - shift, 5.0 + shift}
