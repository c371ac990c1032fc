"""Fixtures as planner actions (planning/fences.py): a goal part whose goal no free push can
stop it within, on a table without the wall it needs, gets a fence the planner puts down and
picks up again; problems that do not need one are planned as before."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

import arrange_up
from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.planfile import plan_document, read_plan, write_json_atomic
from arrange_up.io.yaml_problem import load_problem
from arrange_up.model.problem import Uncertainty
from arrange_up.model.world import Pick, Place, Push, WorldState
from arrange_up.parallel import SERIAL
from arrange_up.physics.stall import wall_overdrive, wall_push_front
from arrange_up.planning.actions import ActionGenerator
from arrange_up.transitions import make_semantics
from arrange_up.transitions.cbst import FIXTURE_REFUSAL

FRESH = Path(__file__).parents[1] / "problems" / "fresh"


@pytest.fixture(scope="module")
def corner():
    return load_problem(FRESH / "fence-corner.yaml")


def _generator(problem):
    return ActionGenerator(problem, CollisionChecker(problem))


def test_a_fence_is_needed_only_where_a_free_push_cannot_stop_the_part(corner):
    # x: push +-0.15 in and the stall's spread exceed the +-0.1 in tolerance, the place's
    # +-0.03 in does not, and the table has no wall there; y: the bottom wall holds it.
    assert set(_generator(corner).fences.needs) == {("A", 0)}


@pytest.mark.parametrize("name", ["down-push", "create-a-t", "tz-mating", "tt-mating"])
def test_no_shipped_problem_with_fixtures_needs_a_fence(name):
    assert _generator(arrange_up.load(name)).fences.needs == {}


def test_fence_places_stand_at_the_goal_face_and_replace_the_open_pushes_along_that_axis(corner):
    gen = _generator(corner)
    belief = IntervalBelief((("A", ObjectInterval((2.0, 0.5, 0.0), (0.1, 0.05, 0.05))),))
    candidates = gen.candidates(belief)
    fences = [a for a in candidates if isinstance(a, Place)]
    # the bar's left face on A's goal face (x = 6.5), standing, centred on A's goal y as far
    # as the bottom wall allows (A is at its goal y already: no second place)
    assert fences == [Place("bar", (6.65, 1.304473, 0.0))]
    rightwards = [a for a in candidates if isinstance(a, Push) and abs(a.pose[2] + 1.5708) < 1e-3]
    assert rightwards == []  # no push ending in the open along x while a fence can stand
    fenced = IntervalBelief(
        (*belief.objects, ("bar", ObjectInterval((6.65, 1.304473, 0.0), (0.03, 0.03, 0.035))))
    )
    pushes = [p for p in gen.pushes(fenced) if abs(p.pose[2] + 1.5708) < 1e-3]
    assert len(pushes) == 1  # the one push: to the fence's face
    paddle_front = pushes[0].pose[0] + 0.075
    assert paddle_front + pushes[0].distance == pytest.approx(6.5, abs=1e-3)
    assert Pick("bar") in gen.candidates(fenced)


def test_a_fence_covers_the_goal_across_and_the_part_where_it_can_do_both(corner):
    gen = _generator(corner)
    high = IntervalBelief((("A", ObjectInterval((2.0, 2.0, 0.0), (0.1, 0.1, 0.05))),))
    fences = [a for a in gen.candidates(high) if isinstance(a, Place)]
    # centred on A's goal y (as far as the wall allows), then nearest A's y (2.0): as high as
    # it still covers A's goal y with a quarter of A to spare (it covers A at y 2.0 too)
    assert fences == [Place("bar", (6.65, 1.304473, 0.0)), Place("bar", (6.65, 1.5, 0.0))]
    # a bar centred on A's present y would not hold A at its goal: none is offered
    higher = IntervalBelief((("A", ObjectInterval((2.0, 3.5, 0.0), (0.1, 0.1, 0.05))),))
    poses = [a.pose for a in gen.candidates(higher) if isinstance(a, Place)]
    assert poses == [(6.65, 1.304473, 0.0), (6.65, 1.5, 0.0)]


@pytest.fixture(scope="module")
def open_corner():
    return load_problem(FRESH / "fence-open-corner.yaml")


def test_a_bar_placed_turned_keeps_one_interval_of_angles_and_serves_as_a_fence(open_corner):
    # a bar looks the same turned by 180 degrees; placed at 90 degrees, its particles once
    # wrapped to either end of [-90, 90) and the belief said "any angle", which made the
    # bar seen at 0 degrees, no fence for the push down onto it
    semantics = make_semantics("particles", open_corner, particles=10, seed=0)
    try:
        belief = semantics.initial_belief()
        for action in (Place("bar2", (6.0, 2.35, math.pi / 2)), Place("bar1", (6.65, 4.0, 0.0))):
            belief = semantics.apply(belief, action)
        bar = belief.intervals.get("bar2")
        assert bar.center[2] == pytest.approx(math.pi / 2, abs=0.01)
        assert bar.half[2] < math.radians(2.5)  # the place noise, +-2 degrees
        block = ("A", ObjectInterval((6.0, 5.0, 0.0), (0.05, 0.3, 0.05)))
        intervals = IntervalBelief((block, *belief.intervals.objects[1:]))
        assert _generator(open_corner).fences.face_ahead(
            "A", block[1], intervals, 1, -1
        ) == pytest.approx(2.5, abs=0.05)  # its top face, within its place noise
    finally:
        semantics.close()


def test_a_push_onto_one_fence_keeps_the_paddle_clear_of_the_other(open_corner):
    # A pressed against bar1 (x face 6.5, y 2.75..5.25) is pushed down onto bar2: a 2.5 in
    # paddle centred on A (x 6) would run into bar1's top end and stall there
    gen = _generator(open_corner)
    belief = IntervalBelief(
        (
            ("A", ObjectInterval((6.0, 5.0, 0.0), (0.05, 0.3, 0.05))),
            ("bar1", ObjectInterval((6.65, 4.0, 0.0), (0.03, 0.03, 0.035))),
            ("bar2", ObjectInterval((6.0, 2.35, math.pi / 2), (0.03, 0.03, 0.035))),
        )
    )
    (down,) = [p for p in gen.pushes(belief) if abs(abs(p.pose[2]) - math.pi) < 1e-3]
    paddle_right = down.pose[0] + 1.25 + open_corner.uncertainty.push[0]
    assert paddle_right < 6.5 - 0.03  # clear of bar1's left face and its place noise
    assert down.pose[0] + 1.25 - 0.1 >= 6.0  # and still covering A's centre
    assert down.pose[1] - 0.075 - down.distance == pytest.approx(2.5, abs=1e-3)  # to bar2


def test_the_planner_builds_a_corner_whose_fences_hold_the_block_at_its_goal(open_corner):
    result = arrange_up.plan(open_corner, particles=20, workers=1)
    assert result.solved, result.reason
    goal_x, goal_y, _ = open_corner.goal.target("A")
    fences = [a for a in result.actions if isinstance(a, Place)]
    assert {a.obj for a in fences} == {"bar1", "bar2"}
    for fence in fences:
        # each bar covers A's goal coordinate across the push that presses A against it,
        # with a quarter of A to spare (a bar at A's start, y 5, was left on the way)
        x, y, theta = fence.pose
        across, goal = (x, goal_x) if abs(math.sin(theta)) > 0.5 else (y, goal_y)
        assert abs(across - goal) <= 1.25 - 0.25 + 1e-6
    assert set(result.actions[-2:]) == {Pick("bar1"), Pick("bar2")}


def test_a_part_no_fence_can_stand_in_front_of_yet_is_first_brought_level_with_one():
    # fence-middle-corner: A (1.2 x 0.8 in) from (9, 2.5) to (5, 6); both axes need a fence.
    # A 3 in bar at A's goal face x 4.4 must cover A's goal y (6) with a quarter of A to
    # spare, so it stands at y 4.7 at the lowest and covers y 3.2..6.2: A at y 2.5 is in
    # front of no such bar, and pushes along x would leave any fence of y behind.
    problem = load_problem(FRESH / "fence-middle-corner.yaml")
    gen = _generator(problem)
    start = ("A", ObjectInterval((9.0, 2.5, 0.0), (0.25, 0.25, 0.09)))
    belief = IntervalBelief((start,))
    routes = gen.fence_routes(belief)
    # up to where that bar covers A, with A's own free push end spread (0.15 in) inside it
    level = gen.fences.level("A", start[1], belief, 1, routes)
    assert level == pytest.approx(3.2 + 0.2 + 0.12 + 0.0322 * 0.96, abs=1e-3)
    ups = [p for p in gen.pushes(belief) if abs(p.pose[2]) < 1e-3]
    assert len(ups) == 1  # the levelling push: no other push that ends in the open along y
    # once level, no levelling push: the fences' own pushes take over
    there = ("A", ObjectInterval((9.0, level, 0.0), (0.25, 0.15, 0.09)))
    assert gen.fences.level("A", there[1], IntervalBelief((there,)), 1, routes) is None


def test_a_row_is_pressed_against_one_fence_at_its_last_part():
    # fence-row: A (goal x 5.5) touches B (6.5) ahead of it; a fence at A's own goal face
    # (x 6) would stand on B's goal, so A's fence is B's, at x 7, through the row
    problem = load_problem(FRESH / "fence-row.yaml")
    gen = _generator(problem)
    assert set(gen.fences.needs) == {("A", 0), ("B", 0)}  # the bottom wall holds y
    assert gen.fences.train("A", 0, 1) == ("B",)
    assert gen.fences.goal_face("A", 0, 1) == pytest.approx(7.0)
    low = ("A", ObjectInterval((3.0, 0.55, 0.0), (0.1, 0.05, 0.05)))
    bar = ("bar", ObjectInterval((7.15, 1.304473, 0.0), (0.03, 0.03, 0.035)))
    # pressed against the bar only once B, the row's last part, is on the table
    assert gen.fences.face_ahead("A", low[1], IntervalBelief((low, bar)), 0, 1) is None
    high = ("B", ObjectInterval((2.0, 4.5, 0.0), (0.1, 0.1, 0.05)))
    belief = IntervalBelief((low, high, bar))
    assert gen.fences.face_ahead("A", low[1], belief, 0, 1) == pytest.approx(7.0)


def test_a_part_no_fence_can_press_yet_passes_towards_it_short_of_its_place():
    # fence-row: B starts above A, beyond the reach of any bar that covers the row's y (0.5):
    # no fence can press it, and it cannot come down to the row through A, so its open push
    # along the row is offered (it was not while a bar could be put down anywhere), stopping
    # short of where the bar must stand (the bar's left face at x 7), and once with the paddle
    # clear of A (a clipped A is dragged along in some states only)
    problem = load_problem(FRESH / "fence-row.yaml")
    gen = _generator(problem)
    a = ("A", ObjectInterval((2.0, 3.0, 0.0), (0.3, 0.3, 0.09)))
    b = ("B", ObjectInterval((2.0, 4.5, 0.0), (0.3, 0.3, 0.09)))
    belief = IntervalBelief((a, b))
    routes = gen.fence_routes(belief)
    assert ("B", 0, 1) in routes and gen.fences.ahead("B", b[1], belief, 0, 1, routes).passing
    aim = gen.fences.passing_aim("B", b[1], 0, 1)
    # B's shadow there (its depth at its angle spread, 0.54 in), widened by the free push's
    # end spread and one more push's noise, clears the bar's place shadow
    bar_shadow = gen.checker.shadow_box("bar", (7.15, 1.3, 0.0), problem.uncertainty.place)
    assert aim + 0.54 + 0.18 + 0.15 < bar_shadow[0]
    a_top = gen.checker.shadow_box("A", a[1].center, a[1].half)[3]
    rightwards = [
        p for p in gen.pushes(belief) if abs(p.pose[2] + math.pi / 2) < 1e-3 and p.pose[1] > 4
    ]
    assert len(rightwards) == 2
    for push in rightwards:
        # the paddle's front carries B's rear face to about the aim's (the distance adds the
        # compliant controller's nominal stall, under 0.15 in)
        rear = push.pose[0] + 0.075 + push.distance
        assert rear + 0.5 == pytest.approx(aim, abs=0.15)
    assert (
        min(p.pose[1] for p in rightwards) - 1.25
        < a_top
        < max(p.pose[1] for p in rightwards) - 1.25
    )
    # B at the row, where a bar can stand in front of it: the bar's push replaces the open ones
    low = ("A", ObjectInterval((2.0, 0.55, 0.0), (0.3, 0.05, 0.09)))
    there = ("B", ObjectInterval((6.0, 0.55, 0.0), (0.3, 0.05, 0.09)))
    row = IntervalBelief((low, there))
    assert not gen.fences.ahead("B", there[1], row, 0, 1, gen.fence_routes(row)).passing
    assert not [p for p in gen.pushes(row) if abs(p.pose[2] + math.pi / 2) < 1e-3 and p.pose[0] > 4]


def test_a_post_standing_at_the_goal_face_is_a_fence_already_down():
    # squeeze-post: A's goal (x 5.5 +- 0.1) is flush with the post's left face (x 6); a free
    # push ends within +-0.13 in, so along x A needs a fence, and the post is one: in front of
    # it, the only push right presses A against it (no push ending in the open, as before)
    problem = load_problem(FRESH / "squeeze-post.yaml")
    gen = _generator(problem)
    assert set(gen.fences.needs) == {("A", 0)}  # y: the bottom wall holds it
    belief = IntervalBelief((("A", ObjectInterval((4.0, 0.55, 0.0), (0.2, 0.05, 0.05))),))
    rightwards = [p for p in gen.pushes(belief) if abs(p.pose[2] + math.pi / 2) < 1e-3]
    assert len(rightwards) == 1
    assert rightwards[0].pose[0] + 0.075 + rightwards[0].distance == pytest.approx(6.0, abs=1e-3)
    # above the post (it does not cover A across), the open push is offered as before
    high = IntervalBelief((("A", ObjectInterval((2.5, 2.5, 0.0), (0.3, 0.3, 0.09))),))
    assert [p for p in gen.pushes(high) if abs(p.pose[2] + math.pi / 2) < 1e-3]


def test_a_fixture_put_down_must_be_picked_up_before_the_goal_is_reached(corner):
    goal = GoalTest(corner)
    at_goal = {"A": (6.0, 0.5, 0.0)}
    assert goal.satisfied(WorldState.from_mapping(corner, at_goal))
    left = WorldState.from_mapping(corner, {**at_goal, "bar": (6.65, 1.3, 0.0)})
    assert not goal.satisfied(left)
    (miss,) = goal.misses(left)
    assert (miss.part, miss.dimensions()) == ("bar", ("on table",))


# Successes of 40 rollouts (seed 0) the plans must reach, well below what they score (25 and
# 40; the plans of the generator without fences score 23 and 29; the 200-rollout rates measured
# as the fences were added are in docs/history/planning.md). The deterministic plan's approach
# poses ignore the initial spread, so some of its pushes start overlapping the block.
FLOORS = {"deterministic": 15, "particles": 32}


@pytest.mark.parametrize("semantics", ["deterministic", "particles"])
def test_the_planner_builds_its_own_fence_and_its_plan_reaches_the_goal_in_rollouts(
    corner, semantics, tmp_path
):
    result = arrange_up.plan(corner, semantics=semantics, particles=6, workers=1)
    assert result.solved, result.reason
    kinds = [(type(a).__name__, getattr(a, "obj", None)) for a in result.actions]
    assert ("Place", "bar") in kinds and result.actions[-1] == Pick("bar")
    assert kinds.index(("Place", "bar")) < len(kinds) - 2  # a push between place and pick
    # the plan file keeps the fence, and evaluate reads it back
    path = tmp_path / "plan.json"
    document = plan_document(
        corner,
        result.actions,
        status=result.status,
        semantics=result.semantics,
        seed=result.seed,
        search=result.stats,
    )
    write_json_atomic(path, document)
    actions, read = read_plan(path, corner)
    assert actions == result.actions and read["status"] == "solved"
    reliability = evaluate_plan(corner, result.actions, rollouts=40, seed=0, runner=SERIAL)
    assert reliability.successes >= FLOORS[semantics], reliability.failures


def test_cbst_takes_a_fence_for_the_wall_ahead_and_not_one_the_block_may_slip_past(corner):
    # CBST's training domain needs the thesis's +-0.05 in push noise, and its model's
    # pushes to a wall or fence were sent for the training's friction and density ranges
    problem = dataclasses.replace(
        corner,
        uncertainty=Uncertainty(
            place=(0.03, 0.03, math.radians(2)),
            push=(0.05, 0.05, math.radians(3)),
            friction=(0.25, 0.55),
            part_density=(0.1, 0.15),
            manipulator_density=(0.35, 0.45),
        ),
    )
    semantics = make_semantics("cbst", problem)
    gen = ActionGenerator(
        problem, CollisionChecker(problem), unclipped_pushes=True, settled_wall_pushes=True
    )
    block = ("A", ObjectInterval((4.0, 0.55, 0.0), (0.05, 0.05, 0.02)))
    bar = ("bar", ObjectInterval((6.65, 1.304473, 0.0), (0.03, 0.03, math.radians(2))))
    belief = IntervalBelief((block, bar))
    (push,) = [p for p in gen.pushes(belief) if abs(p.pose[2] + math.pi / 2) < 1e-3]
    # the push to the bar's face (x = 6.5) as CBST's planner sends it to a wall, and the
    # shipped compliant model learnt it: the paddle's front past the compressed block by the
    # wall overdrive
    over = wall_overdrive(problem.controller, (0.25, 0.55), (0.1, 0.15), 1.0, 0.05)
    front = push.pose[0] + 0.5 * 0.15
    pressed = Push(push.manipulator, push.pose, wall_push_front(6.5, 1.0, over) - front)
    after = semantics.apply(belief, pressed).get("A")
    # pressed against the bar's face: A's centre at 6 within the face's own spread (0.03 in of
    # place, 2 degrees over the bar's 2.5 in) and the model's dx and slop
    assert after.center[0] - after.half[0] < 6.0 < after.center[0] + after.half[0]
    assert after.half[0] < 0.15
    # the bar moved up: A's centre lies below its end, so A may slip past it
    high = ("bar", ObjectInterval((6.65, 2.3, 0.0), bar[1].half))
    # the model refuses it, and the simulated fallback answers from the physics instead
    assert semantics.apply(IntervalBelief((block, high)), pressed) is not None
    assert semantics.fallback_reasons == {FIXTURE_REFUSAL: 1}
    assert semantics.fallback_counts() == (1, 2)


def test_a_fence_holding_a_part_is_kept_while_the_part_has_pushes_to_come(corner):
    gen = _generator(corner)
    bar = ("bar", ObjectInterval((6.65, 2.0, 0.0), (0.03, 0.03, 0.035)))
    at_x = ("A", ObjectInterval((6.0, 2.0, 0.0), (0.05, 0.3, 0.05)))  # x done, y still to go
    assert Pick("bar") not in gen.candidates(IntervalBelief((at_x, bar)))
    done = ("A", ObjectInterval((6.0, 0.55, 0.0), (0.05, 0.05, 0.05)))
    assert Pick("bar") in gen.candidates(IntervalBelief((done, bar)))


def test_a_fence_is_not_offered_where_its_own_place_is_as_uncertain_as_the_goal_is_tight():
    # open-table-fence: the bar lands within +-0.2 in, the goal allows +-0.12 in
    problem = load_problem(FRESH / "open-table-fence.yaml")
    assert _generator(problem).fences.needs == {}
