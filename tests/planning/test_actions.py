"""Tests of ``arrange_up.planning.actions``: the candidate places, pushes and picks of a belief,
their preconditions, the planning hints that shape them and the unclipped-pushes option."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from catalogue import servo, tiny, variant, with_planning

from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.yaml_problem import load_problem, load_problem_text
from arrange_up.model.world import Pick, Place, Push
from arrange_up.planning.actions import ActionGenerator
from arrange_up.planning.generators.common import MIN_PUSH
from arrange_up.planning.obstacles import GAP

FRESH = Path(__file__).parents[1] / "problems" / "fresh"
NONE = (0.0, 0.0, 0.0)
SMALL = (0.1, 0.1, 0.05)  # a belief interval's half-widths after a push or two
#: Paddle angle that pushes along each direction (the paddle pushes along its own +y).
THETA = {"+x": -math.pi / 2, "-x": math.pi / 2, "+y": 0.0, "-y": -math.pi}
PADDLE_HALF_THICKNESS = 0.075


def generator(problem, **options) -> ActionGenerator:
    return ActionGenerator(problem, CollisionChecker(problem), **options)


def belief(**intervals) -> IntervalBelief:
    """An interval belief from ``name=(center, half)`` (in the problem's object order)."""
    return IntervalBelief(
        tuple((name, ObjectInterval(tuple(c), tuple(h))) for name, (c, h) in intervals.items())
    )


def direction_of(push: Push) -> str:
    (name,) = [d for d, theta in THETA.items() if math.isclose(push.pose[2], theta)]
    return name


def distances(pushes, direction: str) -> list[float]:
    return sorted({p.distance for p in pushes if direction_of(p) == direction})


# -- candidates ----------------------------------------------------------------------------
def test_candidates_are_places_then_pushes_then_picks():
    problem = tiny("block-and-fixture")
    gen = generator(problem)
    bar = (problem.initial_of("bar").pose, NONE)
    start = gen.candidates(belief(bar=bar))
    assert [type(a) for a in start] == [Place, Pick]
    assert start[-1] == Pick("bar")
    placed = gen.candidates(belief(A=((3.0, 1.5, 0.0), SMALL), bar=bar))
    kinds = [type(a).__name__ for a in placed]
    assert kinds == sorted(kinds, key=["Place", "Push", "Pick"].index)
    assert "Place" not in kinds and "Push" in kinds and placed[-1] == Pick("bar")


def test_generated_actions_satisfy_their_preconditions():
    p = tiny("two-blocks-row")
    checker = CollisionChecker(p)
    gen = ActionGenerator(p, checker)
    empty = IntervalBelief(())
    places = gen.places(empty)
    assert {a.obj for a in places} == {"A", "B"}
    for action in places:
        assert checker.shadow_inside_table(action.obj, action.pose, p.uncertainty.place)
        assert not checker.shadow_hits_fixed(action.obj, action.pose, p.uncertainty.place)
    a_placed = IntervalBelief((("A", ObjectInterval((9.088, 0.912, 0.0), p.uncertainty.place)),))
    pushes = gen.pushes(a_placed)
    assert pushes and all(isinstance(a, Push) for a in pushes)
    directions = set()
    for push in pushes:
        shadows = [("A", (9.088, 0.912, 0.0), p.uncertainty.place)]
        assert checker.shadow_clear("paddle", push.pose, p.uncertainty.push, shadows)
        directions.add(round(push.pose[2], 3))
    # Against the right and bottom walls only +x (theta -pi/2) and -y (theta pi) fit.
    assert directions == {round(-math.pi / 2, 3), round(-math.pi, 3)}
    # A push towards the wall and one to the goal coordinate are both offered.
    assert len({p.distance for p in pushes if round(p.pose[2], 3) == round(-math.pi / 2, 3)}) == 2


def test_the_same_problem_in_millimetres_gets_the_same_candidates():
    inch, mm = generator(tiny("one-block")), generator(tiny("millimetres"))
    assert mm.candidates(IntervalBelief(())) == inch.candidates(IntervalBelief(()))
    on_table = belief(A=((2.5, 1.5, 0.0), SMALL))
    # Exactly: generated poses and distances are rounded (to 1e-6 in and 1e-4 in).
    assert mm.candidates(on_table) == inch.candidates(on_table)


# -- place ---------------------------------------------------------------------------------
def test_default_place_grid_steps_by_the_shadow_growth_plus_a_tenth():
    problem = tiny("one-block")
    gen = generator(problem)
    checker = gen.checker
    nominal = checker.shadow_box("A", NONE, NONE)
    shadow = checker.shadow_box("A", NONE, problem.uncertainty.place)
    step = round(nominal[0] - shadow[0] + 0.1, 3)
    assert step == 0.412
    grid = gen.place_generator.offsets["A"]
    assert len(grid) == 9 and set(grid) == {
        (i * step, j * step) for i in (-1, 0, 1) for j in (-1, 0, 1)
    }
    # In the corner, only the offset up and to the left keeps the place shadow on the table.
    (place,) = gen.places(IntervalBelief(()))
    assert place.obj == "A" and place.pose == pytest.approx((4.5 - step, 0.5 + step, 0.0))


def test_a_part_with_no_clear_place_on_the_grid_is_offered_the_nearest_clear_ring():
    # A cube into a bracket with 0.15 in of clearance a side, less than the place uncertainty:
    # no place of the 3 x 3 grid about the goal keeps the shadow clear of the bracket.
    problem = load_problem(FRESH / "bracket-clearance.yaml")
    gen = generator(problem)
    step = max(abs(dx) for dx, _ in gen.place_generator.offsets["A"])
    goal = problem.goal.target("A")
    places = gen.places(IntervalBelief(()))
    assert places
    rings = {
        round(max(abs(p.pose[0] - goal[0]), abs(p.pose[1] - goal[1])) / step, 6) for p in places
    }
    (ring,) = rings  # every place from one ring: the first with a clear place
    assert ring >= 2 and ring == int(ring)
    half = problem.uncertainty.place
    for k in range(1, int(ring)):  # the nearer rings have none
        lattice = [(i, j) for i in range(-k, k + 1) for j in range(-k, k + 1)]
        for dx, dy in [(i * step, j * step) for i, j in lattice if max(abs(i), abs(j)) == k]:
            pose = (goal[0] + dx, goal[1] + dy, goal[2])
            assert not gen.place_generator._place_ok("A", pose, half, [], [])
    # Offsets the problem gives replace the grid and its rings.
    hinted = load_problem_text(
        (FRESH / "bracket-clearance.yaml").read_text() + "planning: {place_offsets: [[0, 0]]}\n"
    )
    assert generator(hinted).places(IntervalBelief(())) == []
    # And a semantics that turns the rings off gets the grid's places only: none here.
    assert generator(problem, place_rings=False).places(IntervalBelief(())) == []


def test_place_hints_replace_the_grid_and_add_angles():
    hints = "{place_offsets: [[-1, 1], [-2, 1], [0, 0]], place_angles: [0, 45]}"
    problem = with_planning("one-block", hints)
    gen = generator(problem)
    assert gen.place_generator.offsets["A"] == ((-1.0, 1.0), (-2.0, 1.0), (0.0, 0.0))
    quarter = math.radians(45)
    # The target's own angle once (the 0 offset repeats it), then 45 degrees from it; the
    # offset (0, 0) puts the shadow over the walls and is refused.
    assert gen.places(IntervalBelief(())) == [
        Place("A", (3.5, 1.5, 0.0)),
        Place("A", (3.5, 1.5, quarter)),
        Place("A", (2.5, 1.5, 0.0)),
        Place("A", (2.5, 1.5, quarter)),
    ]


def test_places_skip_parts_on_the_table_and_honour_only():
    gen = generator(tiny("two-blocks-row"))
    empty = IntervalBelief(())
    assert {a.obj for a in gen.places(empty, only="B")} == {"B"}
    a_on = belief(A=((5.0, 2.5, 0.0), SMALL))
    assert {a.obj for a in gen.places(a_on)} == {"B"}
    assert gen.places(a_on, only="A") == []


def test_place_poses_ignore_the_objects_on_the_table_but_not_the_walls():
    problem = tiny("two-blocks-row")
    gen = generator(problem)
    # A sits on B's target: no place of B's grid is clear of it (B's places come from a ring
    # farther out), yet B's place poses (the half of the precondition about the table, walls
    # and obstacles) are all still there.
    blocking = belief(A=((8.5, 0.9, 0.0), problem.uncertainty.place))
    step = max(abs(dx) for dx, _ in gen.place_generator.offsets["B"])
    target = problem.goal.target("B")
    far = gen.places(blocking, only="B")
    assert far and all(
        max(abs(p.pose[0] - target[0]), abs(p.pose[1] - target[1])) > step + 1e-9 for p in far
    )
    poses = gen.place_poses(blocking, "B")
    assert poses and poses == gen.place_poses(IntervalBelief(()), "B")
    for pose in poses:
        assert gen.checker.shadow_inside_table("B", pose, gen.place_unc)
        assert not gen.checker.shadow_hits_fixed("B", pose, gen.place_unc)
    assert gen.place_poses(blocking, "paddle") == []  # no goal, no target


def test_place_target_of_an_absolute_goal_is_the_goal_pose():
    problem = tiny("two-blocks-row")
    gen = generator(problem)
    assert gen.place_target("A", IntervalBelief(())) == problem.goal.target("A")
    assert gen.place_target("paddle", IntervalBelief(())) is None


# Two cubes side by side on a 3 x 1 bar, wherever the bar ends (issue 32: a relative goal of
# eleven mates placed five of them, each mate flush against a placed one having no place).
TWO_MATES = """
name: two-mates
table: {size: [12, 8]}
objects:
  R: {kind: part, shape: {box: [3, 1]}}
  A: {kind: part, shape: {box: [1, 1]}}
  B: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
initial:
  R: {pose: [6, 4, 0], uncertainty: [0.1, 0.1, 3]}
goal:
  tolerance: [0.2, 0.2, 15]
  relative: {reference: R, poses: {A: [0, 1, 0], B: [1, 1, 0]}}
uncertainty: {place: [0.2, 0.2, 15]}
"""


def test_a_mate_blocked_by_the_reference_and_a_placed_mate_is_placed_on_a_ring():
    gen = generator(load_problem_text(TWO_MATES, "two-mates"))
    # R and A at their goal, squared: every place of B's grid overlaps A's shadow or R's, and
    # moving R (its ladder) moves A's target and B's with it, so only a ring helps.
    both = belief(R=((6.0, 4.0, 0.0), SMALL), A=((6.0, 5.0, 0.0), SMALL))
    step = max(abs(dx) for dx, _ in gen.place_generator.offsets["B"])
    far = gen.places(both, only="B")
    assert far and all(max(abs(p.pose[0] - 7.0), abs(p.pose[1] - 5.0)) > step + 1e-9 for p in far)


def test_place_candidates_for_relative_goal_follow_reference():
    p = variant("relative-goal", "  U: {pose: [8, 8, 0], uncertainty: [0.3, 0.3, 5]}\n", "")
    gen = ActionGenerator(p, CollisionChecker(p))
    t = IntervalBelief((("T", ObjectInterval((4.0, 4.0, math.pi / 2), (0.0, 0.0, 0.0))),))
    target = gen.place_target("U", t)
    assert target == pytest.approx((4.0, 6.0, math.pi / 2))
    assert all(isinstance(a, Place) and a.obj == "U" for a in gen.places(t))
    # Without the reference on the table there is no target, hence no place.
    assert gen.place_target("U", IntervalBelief(())) is None
    assert [a for a in gen.places(IntervalBelief(())) if a.obj == "U"] == []


# -- push ----------------------------------------------------------------------------------
def test_pushes_go_towards_the_goal_to_the_wall_and_to_the_goal_coordinate():
    # goal A at (4.5, 0.5), against the right and bottom walls
    gen = generator(servo(tiny("one-block")))
    pushes = gen.pushes(belief(A=((2.5, 1.5, 0.0), SMALL)))
    assert {direction_of(p) for p in pushes} == {"+x", "-y"}  # never away from the goal
    (plus_x,) = {p.pose for p in pushes if direction_of(p) == "+x"}
    front = plus_x[0] + PADDLE_HALF_THICKNESS
    # Until A's centre reaches the goal's x (A's rear, at 2.0, travels 2.0), and the paddle's
    # front all the way to the right wall (x = 5).
    assert distances(pushes, "+x") == pytest.approx([4.0 - front, 5.0 - front], abs=1e-4)
    assert plus_x[1] == 1.5  # centred on the part across the push
    # The approach shadow stops short of the part's shadow.
    part = gen.checker.shadow_box("A", (2.5, 1.5, 0.0), SMALL)
    paddle = gen.checker.shadow_box("paddle", plus_x, gen.push_unc)
    assert 0.0 < part[0] - paddle[2] < 0.05


def test_a_part_is_never_pushed_away_from_its_goal_beyond_the_tolerance():
    # An extra push distance makes every direction a candidate; the goal (A at x = 5, y = 0.5,
    # tolerance 0.2) rules out the directions away from it.
    gen = generator(with_planning("obstacle", "{push_distances: [0.5]}"))

    def directions(x):
        return {direction_of(p) for p in gen.pushes(belief(A=((x, 2.5, 0.0), SMALL)))}

    assert directions(2.5) == {"+x", "-y"}
    assert directions(4.7) == {"+x", "-y"}  # 0.3 short of the goal: -x would move it away
    assert directions(4.9) == {"+x", "-x", "-y"}  # within the tolerance: either way


def test_no_push_to_a_missing_wall():
    gen = generator(tiny("obstacle"))  # walls left and bottom only; goal A at (5, 0.5)
    # (A's shadow clear of the post's x, so that no push is cut short above it.)
    pushes = gen.pushes(belief(A=((1.8, 2.5, 0.0), SMALL)))
    # +x: to the goal's x only, since there is no right wall; -y: to the goal's y and to the
    # bottom wall, which holds A in the goal.
    assert len(distances(pushes, "+x")) == 1
    assert len(distances(pushes, "-y")) == 2


def test_a_push_beside_an_obstacle_is_shifted_clear_of_it_or_dropped():
    with_post = generator(tiny("obstacle"))  # the post covers [2.5, 3.5] x [0, 1]
    post = "  post: {kind: obstacle, shape: {box: [1, 1]}, pose: [3, 0.5, 0]}\n"
    without = generator(variant("obstacle", post, ""))

    def east(gen, y):
        pushes = gen.pushes(belief(A=((4.2, y, 0.0), SMALL)))
        return {p.pose for p in pushes if direction_of(p) == "+x"}

    # The paddle behind A stands level with the post: it moves up along its long side ...
    ((_, y_clear, _),) = east(with_post, 1.6)
    ((_, y_free, _),) = east(without, 1.6)
    assert y_free == 1.6 and y_clear > 1.6
    for gen in (with_post, without):
        for pose in east(gen, 1.6):
            assert not gen.checker.shadow_hits_fixed("paddle", pose, gen.push_unc)
    # ... unless that would leave A's centre uncovered: then there is no such push.
    assert east(with_post, 1.0) == set() and len(east(without, 1.0)) == 1


def test_a_push_beside_a_wall_is_shifted_along_the_paddle_but_still_covers_the_part():
    gen = generator(tiny("one-block"))
    pushes = gen.pushes(belief(A=((0.5, 2.0, 0.0), NONE)))  # flush with the left wall
    assert {direction_of(p) for p in pushes} == {"-y"}  # no room behind it for +x
    (x,) = {p.pose[0] for p in pushes}
    assert x > 0.5  # moved right, clear of the left wall ...
    assert x - 0.5 <= 0.5 * 2.5 - 0.1 + 1e-9  # ... while still covering the part's centre
    box = gen.checker.shadow_box("paddle", pushes[0].pose, gen.push_unc)
    assert box[0] > 0.0


def test_wall_pushes_wait_for_the_train_of_parts_ahead():
    gen = generator(servo(tiny("two-blocks-row")))
    # The goal holds B against the right wall only through A; A against the right wall itself.
    assert gen.wall_trains[("B", "+x")] == ("A",)
    assert gen.wall_trains[("A", "+x")] == ()
    assert gen.wall_trains[("B", "-y")] == ()
    assert gen.wall_trains[("A", "+y")] is None and gen.wall_trains[("B", "-x")] is None
    b_alone = belief(B=((5.0, 2.5, 0.0), SMALL))
    both = belief(A=((9.3, 0.7, 0.0), SMALL), B=((5.0, 2.5, 0.0), SMALL))

    def b_east(b):
        return [p for p in gen.pushes(b) if direction_of(p) == "+x" and p.pose[1] == 2.5]

    (to_goal,) = distances(b_east(b_alone), "+x")  # to B's goal x only: A is not there yet
    to_goal_too, to_wall = distances(b_east(both), "+x")
    assert to_goal_too == to_goal
    # To the goal: until B's centre reaches x = 8.5 (the paddle's front at 8.0); to the wall:
    # the paddle's front all the way to x = 10 (the controller stalls against the train).
    assert to_wall == pytest.approx(to_goal + 2.0, abs=1e-4)


def test_relative_goals_have_no_wall_trains():
    assert generator(tiny("relative-goal")).wall_trains == {}


def test_push_hints_restrict_directions_and_add_distances():
    problem = with_planning("one-block", '{push_directions: ["+x"], push_distances: [0.5, 0.501]}')
    gen = generator(servo(problem))
    assert gen.push_generator.directions == ("+x",)
    pushes = gen.pushes(belief(A=((2.5, 1.5, 0.0), SMALL)))
    assert {direction_of(p) for p in pushes} == {"+x"}
    gap = 2.0 - (pushes[0].pose[0] + PADDLE_HALF_THICKNESS)
    # 0.5 and 0.501 are one candidate (DISTANCE_RESOLUTION); wall and goal as before.
    assert distances(pushes, "+x") == pytest.approx([gap + 0.5, gap + 2.0, gap + 3.0], abs=1e-4)


def test_a_part_at_its_goal_coordinate_gets_no_push_to_it():
    gen = generator(servo(tiny("one-block")))
    at_x = belief(A=((4.5 - MIN_PUSH / 2, 1.5, 0.0), SMALL))
    pushes = gen.pushes(at_x)
    (pose,) = {p.pose for p in pushes if direction_of(p) == "+x"}
    # To the right wall only: the goal's x is less than MIN_PUSH ahead.
    assert distances(pushes, "+x") == pytest.approx(
        [5.0 - pose[0] - PADDLE_HALF_THICKNESS], abs=1e-4
    )
    obstacle = servo(tiny("obstacle"))
    pushes = generator(obstacle).pushes(belief(A=((5.0 - MIN_PUSH / 2, 2.5, 0.0), SMALL)))
    assert "+x" not in {direction_of(p) for p in pushes}  # nothing to gain, and no wall


def test_push_poses_and_distances_are_rounded():
    pushes = generator(tiny("l-part")).pushes(belief(L=((2.0, 2.0, 0.0), (0.1, 0.1, 0.0873))))
    assert pushes
    for push in pushes:
        assert push.pose[:2] == tuple(round(v, 6) for v in push.pose[:2])
        assert push.distance == round(push.distance, 4) and push.distance > MIN_PUSH


def test_a_manipulator_on_the_table_does_not_push_and_may_be_picked():
    gen = generator(tiny("one-block"))
    on = belief(A=((2.5, 1.5, 0.0), SMALL), paddle=((2.5, 0.2, 0.0), NONE))
    assert gen.pushes(on) == []
    assert gen.picks(on) == [Pick("paddle")]


def test_parts_are_never_picked():
    gen = generator(tiny("block-and-fixture"))
    on = belief(A=((3.0, 1.5, 0.0), SMALL), bar=((1.0, 2.0, 0.0), NONE))
    assert gen.picks(on) == [Pick("bar")]
    assert gen.picks(belief(A=((3.0, 1.5, 0.0), SMALL))) == []


def test_push_that_clips_a_neighbour_is_also_offered_clear_of_it():
    # A row of three blocks ends at C (here A); D (here B) has just been placed beside it.
    # Pushing D down from a paddle centred on D clips the side of C's shadow (the paddle may or
    # may not touch C), so with unclipped_pushes the same push is offered a second time from
    # where the paddle misses C or covers it whole.
    p = tiny("two-blocks-row")
    checker = CollisionChecker(p)
    gen = ActionGenerator(p, checker, unclipped_pushes=True)
    c_iv = ObjectInterval((7.513, 0.564, 0.0), (0.027, 0.064, math.radians(3.2)))
    d_iv = ObjectInterval((6.088, 0.912, 0.0), p.uncertainty.place)
    state = IntervalBelief((("A", c_iv), ("B", d_iv)))
    half = 0.5 * 2.5  # the paddle's half length

    def centres_pushing_d_down(state, gen=gen):
        # Pushes down (theta -pi) whose paddle covers D's centre with 0.1 in to spare.
        return sorted(
            {
                a.pose[0]
                for a in gen.pushes(state)
                if round(a.pose[2], 3) == round(-math.pi, 3) and abs(a.pose[0] - 6.088) < half
            }
        )

    centres = centres_pushing_d_down(state)
    assert len(centres) == 2
    assert 6.088 in centres  # the first stays centred on the pushed block
    c_low, _, c_high, _ = checker.shadow_box("A", c_iv.center, c_iv.half)
    assert c_low < 6.088 + half < c_high  # ... and clips C
    (clear,) = [x for x in centres if x != 6.088]
    missed = clear + half <= c_low
    covered = clear - half <= c_low and clear + half >= c_high
    assert missed or covered
    assert abs(clear - 6.088) <= half - 0.1
    # Nothing ahead to clip: one position only.
    assert centres_pushing_d_down(IntervalBelief((("B", d_iv),))) == [6.088]
    # Off by default (particle semantics simulate clipped contacts): one position only.
    assert centres_pushing_d_down(state, ActionGenerator(p, checker)) == [6.088]


# -- pushes where the goal-directed ones cannot make progress (issue: complete generation) ----
def test_a_belief_centred_on_its_goal_but_too_wide_is_offered_narrowing_pushes_both_ways():
    # Goal A at (2.5, 0.5): no wall holds it in x; the belief is centred on that x, spread
    # +-0.3 in x against a tolerance of +-0.2.
    problem = variant("one-block", "poses: {A: [4.5, 0.5, 0]}", "poses: {A: [2.5, 0.5, 0]}")
    gen = generator(servo(problem))
    wide = belief(A=((2.5, 1.5, 0.0), (0.3, 0.1, 0.05)))
    pushes = gen.pushes(wide)
    assert {"+x", "-x"} <= {direction_of(p) for p in pushes}
    for direction, sign in (("+x", 1), ("-x", -1)):
        (pose,) = {p.pose for p in pushes if direction_of(p) == direction}
        (d,) = distances(pushes, direction)
        # The paddle's front ends where the nominal part's rear sits at the target.
        front_end = pose[0] + sign * (PADDLE_HALF_THICKNESS + d)
        assert front_end == pytest.approx(2.5 - sign * 0.5, abs=1e-4)
    # Within the tolerance already: nothing to narrow, no push along x.
    narrow = belief(A=((2.5, 1.5, 0.0), (0.1, 0.1, 0.05)))
    assert not {"+x", "-x"} & {direction_of(p) for p in gen.pushes(narrow)}


RELATIVE_PAIR = """
name: pair
table: {size: [8, 6], walls: []}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  B: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
initial:
  A: {pose: [7.2, 3, 0], uncertainty: [0.05, 0.05, 2]}
goal:
  tolerance: [0.3, 0.3, 15]
  relative: {reference: A, poses: {B: [1.0, 0.0, 0]}}
uncertainty: {place: [0.2, 0.2, 15], push: [0.05, 0.05, 3]}
"""


def test_the_reference_of_a_relative_goal_gets_a_ladder_only_when_a_part_cannot_be_placed():
    problem = servo(load_problem_text(RELATIVE_PAIR, "pair.yaml"))
    gen = generator(problem)
    # A near the right edge: B's place beside it falls off the table, so A must move.
    edge = belief(A=((7.2, 3.0, 0.0), (0.05, 0.05, 0.03)))
    assert gen.places(edge) == []
    west = distances(gen.pushes(edge), "-x")
    assert west and len(west) == 3  # the ladder's three travels, each on the table
    # None that would push A's footprint off the table's right edge.
    assert "+x" not in {direction_of(p) for p in gen.pushes(edge)}
    # A in the middle: B can be placed, no ladder.
    middle = belief(A=((3.0, 3.0, 0.0), (0.05, 0.05, 0.03)))
    assert gen.places(middle) and gen.pushes(middle) == []


# -- obstacles: pushes cut short, detours, squeezes, the paddle's sweep (planning.obstacles) --
def test_a_push_that_would_jam_on_an_obstacle_is_also_offered_cut_short():
    # The post covers [2.5, 3.5] x [0, 1]; A's shadow (x 1.38 to 2.62) overlaps its top, so
    # pushed down to its goal's y or to the bottom wall it lands on the post.
    gen = generator(servo(tiny("obstacle")))
    shape = belief(A=((2.0, 2.5, 0.0), SMALL))
    pushes = [p for p in gen.pushes(shape) if direction_of(p) == "-y"]
    (pose,) = {p.pose for p in pushes}
    front = pose[1] - PADDLE_HALF_THICKNESS
    short, *full = distances(pushes, "-y")
    assert len(full) == 2  # to the goal's y and to the wall, as before
    turned = gen.checker.shadow_box("A", (2.0, 2.5, 0.0), (0.0, 0.0, SMALL[2]))
    depth = turned[3] - turned[1]
    # Cut short: the shadow's lowest point ends GAP above the post, with the approach noise.
    lowest = front - short - depth - gen.push_unc[1]
    assert lowest == pytest.approx(1.0 + GAP, abs=1e-4)
    # Clear of the post's x: nothing to cut short.
    clear = belief(A=((1.8, 2.5, 0.0), SMALL))
    assert len(distances(gen.pushes(clear), "-y")) == 2


POST_ON_THE_WAY = """
name: post-on-the-way
table: {size: [10, 5], walls: [left, right, bottom, top]}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
  post: {kind: obstacle, shape: {box: [0.6, 0.6]}, pose: [6, 0.3, 0]}
initial:
  A: {pose: [3, 1.2, 0], uncertainty: [0.15, 0.15, 5]}
goal:
  tolerance: [0.2, 0.2, 15]
  poses: {A: [9.5, 0.5, 0]}
uncertainty: {place: [0.2, 0.2, 15], push: [0.05, 0.05, 3]}
"""


def test_a_part_whose_straight_push_is_blocked_is_offered_a_detour_instead():
    # The post covers [5.7, 6.3] x [0, 0.6]; A's shadow reaches down to y 0.51, so pushed
    # right towards its goal x it catches the post's corner.
    gen = generator(servo(load_problem_text(POST_ON_THE_WAY, "post.yaml")))
    start = ((3.0, 1.2, 0.0), (0.15, 0.15, math.radians(5)))
    pushes = gen.pushes(belief(A=start))
    # Up, away from the goal's y: just far enough for the shadow, with the spread a push
    # leaves across it, to clear the post's top by GAP.
    ups = [p for p in pushes if direction_of(p) == "+y"]
    assert len(ups) == 1
    (up,) = ups
    end = gen.checker.shadow_box("A", start[0], (0.15, gen.push_unc[1], start[1][2]))
    rear = start[0][1] - 0.5  # the nominal part's, where the paddle meets it
    gap = rear - (up.pose[1] + PADDLE_HALF_THICKNESS)
    assert end[1] + (up.distance - gap) == pytest.approx(0.6 + GAP, abs=1e-4)
    # Right: cut short before the post; the pushes that would run into it are not offered,
    # since the part can go round.
    rights = [p for p in pushes if direction_of(p) == "+x"]
    assert rights
    depth = 1.0
    for push in rights:
        assert push.pose[0] + PADDLE_HALF_THICKNESS + push.distance + depth <= 5.7
    # Above the post's top already: no detour, and the push to the goal's x is offered.
    above = gen.pushes(belief(A=((3.0, 2.5, 0.0), SMALL)))
    assert "+y" not in {direction_of(p) for p in above}
    assert len(distances(above, "+x")) == 2  # to the goal's x and to the wall


def test_a_part_that_cannot_go_round_keeps_the_push_into_the_obstacle():
    # A lies on the bottom wall: no paddle fits under it, so the detour up is not possible
    # and the push along the wall (the part catching the post) is kept beside the cut one.
    gen = generator(servo(load_problem_text(POST_ON_THE_WAY, "post.yaml")))
    pushes = gen.pushes(belief(A=((3.0, 0.6, 0.0), (0.1, 0.1, 0.05))))
    assert "+y" not in {direction_of(p) for p in pushes}
    rights = distances(pushes, "+x")
    assert len(rights) == 3  # cut short, to the goal's x, to the wall


SQUEEZE = """
name: squeeze
table: {size: [8, 5], walls: [bottom]}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
  post: {kind: obstacle, shape: {box: [0.5, 1.5]}, pose: [6.25, 0.75, 0]}
goal:
  tolerance: [0.1, 0.15, 15]
  poses: {A: [5.5, 0.5, 0]}
uncertainty: {place: [0.03, 0.03, 2], push: [0.1, 0.1, 3]}
"""


def test_a_belief_too_wide_at_its_goal_is_squeezed_against_the_obstacle_ahead():
    gen = generator(servo(load_problem_text(SQUEEZE, "squeeze.yaml")))
    wide = belief(A=((5.45, 0.55, 0.0), (0.2, 0.05, 0.03)))  # centred (within MIN_PUSH)
    pushes = gen.pushes(wide)
    (pose,) = {p.pose for p in pushes if direction_of(p) == "+x"}
    front = pose[0] + PADDLE_HALF_THICKNESS
    narrowing, squeeze = distances(pushes, "+x")
    assert front + narrowing == pytest.approx(5.0, abs=1e-4)  # A's rear at the goal's
    assert front + squeeze == pytest.approx(6.0, abs=1e-4)  # the paddle to the post's face
    # Within its tolerance along x: nothing to squeeze.
    narrow = belief(A=((5.5, 0.55, 0.0), (0.05, 0.05, 0.03)))
    assert "+x" not in {direction_of(p) for p in gen.pushes(narrow)}


def test_the_paddle_is_shifted_clear_of_an_obstacle_it_would_sweep_into():
    # Pushed down to the wall from above the post's top, A's shadow (x 4.68 to 5.92) passes
    # the post (x 6 to 6.5, top 1.5), but the paddle centred on A (x 4.05 to 6.55) would come
    # down on it: it moves left along its long side, still covering A's centre.
    gen = generator(servo(load_problem_text(SQUEEZE, "squeeze.yaml")))
    pushes = [p for p in gen.pushes(belief(A=((5.3, 2.5, 0.0), SMALL))) if direction_of(p) == "-y"]
    assert len(distances(pushes, "-y")) == 2  # to the goal's y and to the wall
    for push in pushes:
        box = gen.checker.shadow_box("paddle", push.pose, gen.push_unc)
        assert box[2] < 6.0  # clear of the post
        assert abs(push.pose[0] - 5.3) <= 0.5 * 2.5 - 0.1 + 1e-9
