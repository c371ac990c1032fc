"""Where a relative goal's reference is put down when it starts off the table
(arrange_up.planning.mating.Mates.homes): about the home that centres the goal arrangement,
else about the first other home with a clear place."""

from __future__ import annotations

from pathlib import Path

import shapely
import shapely.affinity

from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.geometry.shapes import footprint
from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.model.world import Place
from arrange_up.planning.actions import ActionGenerator
from arrange_up.planning.mating import Mates
from arrange_up.planning.planner import plan
from arrange_up.search import SearchStatus

#: The probe's problem: the wedge W (the reference) starts off the table, and a pillar stands
#: where the arrangement would be centred.
FRESH = Path(__file__).parents[1] / "problems" / "fresh"
P7 = (FRESH / "reference-off-table-pillar.yaml").read_text()
NO_PILLAR = P7.replace(
    "  pillar:\n    kind: obstacle\n"
    "    shape: {polygon: [[0,0],[1,0],[1.3,0.8],[0.5,1.3],[-0.3,0.8]]}\n"
    "    pose: [4, 4, 0.5]\n",
    "",
)


def _w_places(generator: ActionGenerator, belief: IntervalBelief) -> list[Place]:
    return [a for a in generator.places(belief) if a.obj == "W"]


def _near(pose, centre, reach: float) -> bool:
    return (
        max(abs(pose[0] - centre[0]), abs(pose[1] - centre[1])) <= reach + 1e-6
    )  # places are rounded to 1e-6 in


def test_a_reference_whose_home_is_blocked_by_an_obstacle_is_put_down_elsewhere():
    problem = load_problem_text(P7)
    assert problem.obstacles
    mates = Mates(problem)
    assert mates.homes[0] == mates.home and len(mates.homes) > 1
    assert Mates(problem).homes == mates.homes  # deterministic
    pillar = problem.object("pillar")
    obstacle = footprint(pillar.shape.parts, pillar.pose)
    arrangement = shapely.union_all(
        [footprint(problem.object("W").shape.parts, (0.0, 0.0, 0.0))]
        + [footprint(problem.object("S").shape.parts, problem.goal.target("S"))]
    )
    for x, y, theta in mates.homes[1:]:
        assert theta == 0.0
        there = shapely.affinity.translate(arrangement, x, y)
        x0, y0, x1, y1 = there.bounds
        assert x0 >= 0.0 and y0 >= 0.0 and x1 <= 8.0 and y1 <= 8.0
        assert not there.intersects(obstacle)
    result = plan(problem, semantics="deterministic")
    assert result.status is SearchStatus.SOLVED
    first = result.actions[0]
    assert isinstance(first, Place) and first.obj == "W"
    assert not _near(first.pose, mates.home, 0.5)


def test_where_the_home_has_a_clear_place_the_reference_is_placed_only_about_it():
    problem = load_problem_text(NO_PILLAR)
    assert not problem.obstacles
    generator = ActionGenerator(problem, CollisionChecker(problem))
    home = generator.mates.home
    step = max(abs(dx) for dx, _ in generator.place_generator.offsets["W"])
    places = _w_places(generator, IntervalBelief(()))
    assert len(places) == len(generator.place_generator.offsets["W"])
    assert all(_near(a.pose, home, step) for a in places)
    # A part standing on the home: the reference goes about the next home with a clear place.
    blocked = load_problem_text(
        NO_PILLAR.replace(
            "  paddle:", "  X: {kind: part, shape: {box: [2, 2]}}\n  paddle:"
        ).replace("goal:", f"initial:\n  X: {{pose: [{home[0]}, {home[1]}, 0]}}\ngoal:")
    )
    generator = ActionGenerator(blocked, CollisionChecker(blocked))
    belief = IntervalBelief((("X", ObjectInterval((home[0], home[1], 0.0), (0.0, 0.0, 0.0))),))
    places = _w_places(generator, belief)
    assert places and not any(_near(a.pose, home, step) for a in places)
    assert generator.place_poses(IntervalBelief(()), "W")  # no obstacle: about the home
