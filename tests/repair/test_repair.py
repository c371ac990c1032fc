"""Tests of fixture-placement plan repair (thesis ch. 4): nominal plans, the one-step fixture
problem, the multi-step repair, the plan file, the CLI, the UP engine and the heatmap.

Everything runs on a handful of particles, on down-push (one push) and on one step of
tz-mating, to stay within a few seconds each.
"""

from __future__ import annotations

import json
import math

import pytest
from catalogue import servo, tiny
from click.testing import CliRunner

import arrange_up.repair as rp
from arrange_up.cli import main
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.domains import load
from arrange_up.io.planfile import plan_document, read_plan, write_json_atomic
from arrange_up.model.world import Pick, Place, Push
from arrange_up.planning.planner import plan
from arrange_up.repair import candidates
from arrange_up.repair.repairer import Repairer
from arrange_up.transitions.particles import DeterministicSemantics


@pytest.fixture(scope="module")
def down_push():
    return load("down-push")


@pytest.fixture(scope="module")
def tz():
    return load("tz-mating")


@pytest.fixture(scope="module")
def down_nominal(down_push):
    return rp.nominal_plans(down_push, 1, seed=0)[0]


@pytest.fixture(scope="module")
def down_repair(down_push, down_nominal):
    return rp.repair_plan(down_push, down_nominal, particles=6, seed=3, method="enhanced")


def _reaches_goal(problem, actions) -> bool:
    from arrange_up.belief.goals import GoalTest

    model = DeterministicSemantics(problem)
    belief = model.initial_belief()
    for action in actions:
        belief = model.apply(belief, action)
        if belief is None:
            return False
    return GoalTest(problem).satisfied(belief.particles[0])


# -- nominal plans -------------------------------------------------------------------------------
def test_nominal_plans_are_distinct_valid_and_reproducible(tz):
    plans = rp.nominal_plans(tz, 3, seed=5)
    assert len(plans) == 3
    assert len(set(plans)) == 3
    assert all(_reaches_goal(tz, p) for p in plans)
    assert rp.nominal_plans(tz, 3, seed=5) == plans
    # the first is the deterministic planner's own plan (seeded tie-breaking, no variety)
    first = plan(tz, semantics="deterministic", seed=5, tie_break=True)
    assert plans[0] == first.actions


def test_tie_breaking_alone_gives_little_variety_and_variety_flag_more(tz):
    plain = {plan(tz, semantics="deterministic", seed=s, tie_break=True).actions for s in range(6)}
    varied = {
        plan(tz, semantics="deterministic", seed=s, tie_break=True, variety=True).actions
        for s in range(6)
    }
    assert len(plain) <= 2
    assert len(varied) >= 4
    again = plan(tz, semantics="deterministic", seed=3, tie_break=True, variety=True)
    assert (
        again.actions
        == plan(tz, semantics="deterministic", seed=3, tie_break=True, variety=True).actions
    )


def test_nominal_plans_returns_fewer_when_variety_runs_out(down_push):
    plans = rp.nominal_plans(down_push, 50, seed=0, max_tries=6)
    assert 1 <= len(plans) <= 6
    assert len(set(plans)) == len(plans)
    with pytest.raises(ValueError):
        rp.nominal_plans(down_push, 0)


# -- the repair ----------------------------------------------------------------------------------
def test_repair_solves_down_push_and_records_each_step(down_push, down_nominal, down_repair):
    result = down_repair
    assert result.solved and result.status == rp.SOLVED
    assert result.nominal == down_nominal
    assert len(result.steps) == len(down_nominal) == 1
    record = result.steps[0]
    assert record.kind == "push" and record.status == "ok"
    assert record.multiplier in rp.MULTIPLIERS
    assert record.distance <= record.nominal_distance + 1e-12
    assert record.placements > 0 and record.simulations > 0
    # the push keeps its heading; its distance is the nominal one times the multiplier plus
    # the approach back-off
    push = next(a for a in result.actions if isinstance(a, Push))
    nominal = down_nominal[0]
    assert push.pose[2] == nominal.pose[2]
    assert push.distance == pytest.approx(nominal.distance * record.multiplier + record.backoff)
    if record.fixture is None:
        assert result.actions == (push,)
    else:
        assert result.actions == (Place(record.fixture, record.pose), push, Pick(record.fixture))
    assert len(result.beliefs) == 2 and len(result.beliefs[0]) == 6


def test_repair_is_reproducible_and_independent_of_workers(down_push, down_nominal, down_repair):
    again = rp.repair_plan(down_push, down_nominal, particles=6, seed=3, workers=2)
    assert again.actions == down_repair.actions
    assert again.steps[0].distance == down_repair.steps[0].distance


def test_place_and_pick_actions_stay_as_they_are():
    problem = load("blocks-1")
    nominal = rp.nominal_plans(problem, 1, seed=0)[0]
    assert isinstance(nominal[0], Place)
    result = rp.repair_plan(problem, nominal, particles=4, seed=0)
    assert result.solved
    assert result.actions[0] == nominal[0]
    assert result.steps[0].kind == "place" and result.steps[0].actions == (nominal[0],)
    # a walled 10 x 5 board: blocks-1 has no fixture, so pushes stay bare pushes
    assert all(not isinstance(a, Pick) for a in result.actions)


def test_a_push_off_the_table_is_caught_by_a_fixture_but_a_plan_short_of_the_goal_fails(
    down_push,
):
    # nominally the block's centre stops 0.2 in from the open edge: with +-0.2 in of push
    # noise and +-15 deg of rotation some particles leave the table unless something stops
    # them; a fixture (clamped to the table) placed at the edge does. But the plan never
    # reaches the goal, so neither does its repair: the repair says so instead of "solved".
    # (A servo push: it ends where it was sent.)
    down_push = servo(down_push)
    nominal = (Push("paddle", (6.0, 6.816804, -math.pi), 6.0418),)
    assert _reaches_goal(down_push, nominal) is False  # valid, but misses the goal
    result = rp.repair_plan(down_push, nominal, particles=8, seed=0)
    assert result.status == rp.FAILED and result.actions is None
    assert "does not reach the goal nominally: block misses its goal in y" in result.reason
    kinds = [type(a) for a in result.partial]
    assert kinds == [Place, Push, Pick] and result.partial[0].obj == "bar"


def test_a_repair_of_an_empty_plan_says_it_misses_the_goal(down_push):
    result = rp.repair_plan(down_push, (), particles=2, seed=0)
    assert result.status == rp.FAILED
    assert result.reason.endswith("block misses its goal in y")  # it starts on the table


def test_a_push_off_the_table_fails_honestly_without_fixtures(down_push):
    import dataclasses

    bare = dataclasses.replace(
        servo(down_push), objects=tuple(o for o in down_push.objects if o.name != "bar")
    )
    nominal = (Push("paddle", (6.0, 6.816804, -math.pi), 6.0418),)
    result = rp.repair_plan(bare, nominal, particles=8, seed=0)
    assert result.status == rp.FAILED
    assert result.actions is None
    assert "step 1 (push)" in result.reason and "off the table" in result.reason
    assert result.steps[-1].status == "failed"
    document = result.document(bare)
    assert document["status"] == "failed" and "actions" not in document
    assert "off the table" in document["repair"]["reason"]


def test_a_plan_that_fails_nominally_is_refused(down_push):
    with pytest.raises(ValueError, match="not a nominal plan"):
        rp.repair_plan(down_push, (Push("paddle", (6.0, 6.816804, -math.pi), 9.0),), particles=2)


def test_bad_arguments_are_refused(down_push, down_nominal):
    with pytest.raises(ValueError, match="method"):
        rp.repair_plan(down_push, down_nominal, particles=2, method="clever")
    with pytest.raises(ValueError, match="particles"):
        rp.repair_plan(down_push, down_nominal, particles=0)


def test_timeout_is_reported(down_push, down_nominal):
    result = rp.repair_plan(down_push, down_nominal, particles=2, timeout=0.0)
    assert result.status == rp.TIMEOUT and result.actions is None


# -- the one-step fixture problem ---------------------------------------------------------------
@pytest.fixture(scope="module")
def tz_scores(tz):
    nominal = rp.nominal_plans(tz, 1, seed=0)[0]
    return rp.step_scores(tz, nominal, 1, particles=4, seed=0, method="enhanced")


def test_candidates_respect_the_place_precondition(tz, tz_scores):
    scores = tz_scores
    checker = CollisionChecker(tz)
    place, push_unc = tz.uncertainty.place, tz.uncertainty.push
    assert scores.no_fixture.fixture is None and scores.no_fixture.pose is None
    assert scores.selection_multiplier == rp.SELECTION_MULTIPLIER
    approach = scores.no_fixture.push
    others = [(n, iv.center, iv.half) for n, iv in scores.belief.intervals.objects]
    statuses = {c.status for c in scores.placements[1:]}
    assert statuses <= {"ok", "invalid", "blocked"} and "ok" in statuses and "blocked" in statuses
    for cand in scores.placements[1:]:
        assert cand.fixture == "bar"
        if cand.status == "blocked":
            assert math.isnan(cand.distance) and cand.score is None
            continue
        assert checker.shadow_inside_table("bar", cand.pose, place)
        # clear of every object's shadow (the canonical intervals are wider: conservative)
        # and of the paddle's approach shadow
        assert checker.shadow_clear(
            "bar", cand.pose, place, [(approach.manipulator, approach.pose, push_unc)]
        )
        assert checker.shadow_clear("bar", cand.pose, place, others[:1])


def test_scores_are_figure_4_10_normalised(tz_scores):
    valid = [c for c in tz_scores.placements if c.valid]
    invalid = [c for c in tz_scores.placements if c.status == "invalid"]
    assert min(c.score for c in valid) == 0.0
    assert max(c.score for c in valid) == 1.0
    best = min(valid, key=lambda c: c.distance)
    assert best.score == 0.0
    for cand in invalid:
        assert cand.score is None and cand.distance == math.inf and cand.reason


def test_enhanced_placements_meet_the_swath_and_are_a_subset_of_naive(tz):
    nominal = rp.nominal_plans(tz, 1, seed=0)[0]
    naive = rp.step_scores(tz, nominal, 1, particles=2, seed=0, method="naive")
    enhanced = rp.step_scores(tz, nominal, 1, particles=2, seed=0, method="enhanced")
    checker = CollisionChecker(tz)
    swath = dict(enhanced.swaths)
    assert set(swath) == {"Z"}  # the first push moves only Z
    n_poses = {c.pose for c in naive.placements[1:]}
    e_poses = {c.pose for c in enhanced.placements[1:]}
    assert e_poses < n_poses
    from arrange_up.geometry import shapes as geometry

    for pose in e_poses:
        assert geometry.boxes_overlap(checker.shadow_box("bar", pose, (0, 0, 0)), swath["Z"])
    # a naive placement the push cannot reach gets the bare push's outcome, unsimulated
    far = [c for c in naive.placements[1:] if c.valid and not c.reachable]
    assert far and all(c.distance == naive.no_fixture.distance for c in far)
    # common random numbers: the same candidate scores the same whatever the method
    common = {c.pose: c.distance for c in enhanced.placements[1:] if c.valid}
    for cand in naive.placements[1:]:
        if cand.pose in common:
            assert cand.distance == common[cand.pose]


def test_choice_needs_a_real_gain_for_a_fixture():
    push = Push("paddle", (0.0, 0.0, 0.0), 1.0)

    def cand(fixture, distance, multiplier=1.0):
        pose = None if fixture is None else (1.0, 1.0, 0.0)
        return rp.Candidate(fixture, pose, multiplier, "ok", distance, push=push)

    assert candidates.choose([]) is None
    bare = cand(None, 1.0)
    # 0.5% better: not worth two actions
    assert candidates.choose([bare, cand("bar", 0.995)]) is bare
    better = cand("bar", 0.9)
    assert candidates.choose([bare, better]) is better
    assert candidates.choose([cand(None, 1.0, 1.5), cand(None, 1.0, 1.25)]).multiplier == 1.25
    scored = candidates.normalise(
        [
            cand(None, 2.0),
            cand("bar", 1.0),
            rp.Candidate("bar", (2.0, 2.0, 0.0), 1.0, "invalid", math.inf, push=push),
        ]
    )
    assert [c.score for c in scored] == [1.0, 0.0, None]


def test_the_choice_skips_candidates_the_repair_rejects():
    push = Push("paddle", (0.0, 0.0, 0.0), 1.0)
    bare, longer = (
        rp.Candidate(None, None, m, "ok", d, push=push) for m, d in ((1.0, 1.0), (2.0, 0.5))
    )
    near = rp.Candidate("bar", (1.0, 1.0, 0.0), 1.0, "ok", 0.2, push=push)
    far = rp.Candidate("bar", (2.0, 1.0, 0.0), 1.0, "ok", 0.4, push=push)
    assert candidates.choose([bare, longer, near, far]) is near
    asked = []

    def rejects(c):
        asked.append(c)
        return "misses the goal" if c in (near, longer) else ""

    # the best accepted fixture still has to beat the best accepted bare push
    assert candidates.choose([bare, longer, near, far], rejects) is far
    assert asked == [longer, bare, near, far]  # best first, and no further than needed
    assert candidates.choose([bare, longer], lambda c: "no") is None
    # no bare push accepted: a fixture still has to beat the best bare push, or nothing wins
    no_bare = lambda c: "misses the goal" if c.fixture is None else ""  # noqa: E731
    assert candidates.choose([bare, longer, far], no_bare) is far  # 0.4 beats 0.5
    worse = rp.Candidate("bar", (3.0, 1.0, 0.0), 1.0, "ok", 0.6, push=push)
    assert candidates.choose([bare, longer, worse], no_bare) is None


def test_the_repair_keeps_the_plan_nominal_while_choosing():
    # With 3 particles the belief prefers, for a push of the tutorial's nominal plan, candidates
    # whose plan misses the goal nominally (the repair used to choose them and fail at the
    # end); each is now rejected while choosing, and the repair solves. The nominal plan is the
    # tutorial's: the whole goal searched at once (--no-agenda).
    problem = tiny("ell-and-box")
    nominal = plan(problem, semantics="deterministic", seed=0, agenda=False).actions
    assert _reaches_goal(problem, nominal)
    result = rp.repair_plan(problem, nominal, particles=3, seed=0)
    assert result.solved, result.reason
    assert _reaches_goal(problem, result.actions)
    assert sum(s.rejected for s in result.steps) > 0
    # the heatmap's scores see the same rule: the same choice at a step that rejected some
    # (steps are numbered by the nominal plan's actions, from 1)
    actions, document = result.actions, result.document(problem)
    k, step = next((k, s) for k, s in enumerate(result.steps) if s.rejected)
    scores = rp.step_scores(problem, actions, k + 1, document=document)
    assert scores.rejected and (scores.best.fixture, scores.best.pose) == (step.fixture, step.pose)
    for key, why in scores.rejected:
        assert why, key


def test_a_plan_guard_rejects_a_push_that_overshoots_the_goal(down_push):
    from arrange_up.repair.nominal import NominalReplay
    from arrange_up.repair.repairer import PlanGuard

    nominal = rp.nominal_plans(down_push, 1, seed=0)[0]
    replay = NominalReplay(down_push)
    try:
        guard = PlanGuard(replay, replay.initial(), 0, nominal, True)
        push = nominal[0]
        as_planned = rp.Candidate(None, None, 1.0, "ok", 0.0, push=push)
        twice = rp.Candidate(
            None, None, 2.0, "ok", 0.0, push=Push(push.manipulator, push.pose, 2 * push.distance)
        )
        assert guard(as_planned) == ""
        assert guard(twice)  # off the table or past the goal: rejected, with why
        assert [key for key, _ in guard.rejected] == [(None, None, 2.0)]
    finally:
        replay.close()


def test_the_plan_guard_runs_the_next_push_as_its_lookahead_gives_it(tz):
    from arrange_up.repair.nominal import NominalReplay
    from arrange_up.repair.repairer import PlanGuard

    nominal = rp.nominal_plans(tz, 1, seed=0)[0]
    assert len(nominal) == 2 and all(isinstance(a, Push) for a in nominal)
    replay = NominalReplay(tz)
    try:
        as_planned = rp.Candidate(None, None, 1.0, "ok", 0.0, push=nominal[0])
        guard = PlanGuard(replay, replay.initial(), 0, nominal, True)
        assert guard(as_planned) == ""  # the nominal plan itself
        guard = PlanGuard(replay, replay.initial(), 0, nominal, True)
        guard.lookahead = lambda c, push: Push(push.manipulator, push.pose, 0.5 * push.distance)
        assert guard(as_planned)  # the next push, so run, stops short of the goal
    finally:
        replay.close()


def test_belief_intervals_span_angles_the_short_way(tz):
    # Z (symmetry period 180 deg) starts at 90 deg +- 1 deg: its canonical angle period is
    # centred on that start, so its interval is +-1 deg, not the whole period
    repairer = Repairer(tz, 30, 0, "enhanced", 1, None)
    belief = repairer.initial_belief()
    assert belief.intervals.get("Z").half[2] <= math.radians(1.0) + 1e-9
    assert repairer.intervals(belief).get("Z").half[2] <= math.radians(1.0) + 1e-9


# -- the fixtures' ablation -----------------------------------------------------------------
def test_the_ablation_places_no_fixture_and_keeps_the_bare_candidates(tmp_path, down_push):
    nominal = rp.nominal_plans(down_push, 1, seed=0)[0]
    # with 5 particles and seed 2 the full repair places the bar
    full = rp.repair_plan(down_push, nominal, particles=5, seed=2, workers=1)
    assert full.solved and full.steps[0].fixture is not None
    ablation = rp.repair_plan(down_push, nominal, particles=5, seed=2, workers=1, fixtures=False)
    assert ablation.solved and not ablation.fixtures and full.fixtures
    assert not any(isinstance(a, Place | Pick) for a in ablation.actions)
    (record,) = ablation.steps
    assert (
        record.fixture is None
        and record.placements == 0
        and ablation.stats()["fixtures_placed"] == 0
    )
    # the same no-fixture candidates as the full repair's (same noise), the best of them kept
    scores = rp.step_scores(down_push, nominal, 1, particles=5, seed=2)
    bare = min(
        (c for c in scores.refined if c.fixture is None and c.valid),
        key=lambda c: (c.distance, c.multiplier),
    )
    assert (record.multiplier, record.distance) == (bare.multiplier, bare.distance)
    assert record.backoff == scores.backoff
    # the plan document says so; a full repair's names no fixtures key (as it always was)
    document = ablation.document(down_push)
    assert document["repair"]["fixtures"] is False
    assert "fixtures" not in full.document(down_push)["repair"]
    path = write_json_atomic(tmp_path / "ablation.json", document)
    actions, read = read_plan(path, down_push)
    _, _, settings = rp.plan_groups(down_push, actions, read)
    assert settings["fixtures"] is False
    # its heatmap scores are the ablation's: no placement
    again = rp.step_scores(down_push, actions, 1, document=read)
    assert [c.fixture for c in again.placements] == [None]


def test_cli_repair_no_fixtures(tmp_path):
    out = tmp_path / "ablation.json"
    args = ["repair", "down-push", "--particles", "5", "--seed", "2", "--workers", "1"]
    result = CliRunner().invoke(
        main, [*args, "--no-fixtures", "-o", str(out)], catch_exceptions=False
    )
    assert result.exit_code == 0, result.output
    assert "no fixtures" in result.output and "0 fixtures placed" in result.output
    assert json.loads(out.read_text())["repair"]["fixtures"] is False
    helped = CliRunner().invoke(main, ["repair", "--help"])
    assert "--no-fixtures" in helped.output and "ablation" in helped.output


# -- plan files, CLI, UP, heatmap ---------------------------------------------------------------
def test_plan_file_round_trip_and_heatmap_scores(tmp_path, down_push, down_repair):
    path = write_json_atomic(tmp_path / "fixed.json", down_repair.document(down_push))
    actions, document = read_plan(path, down_push)
    assert document["semantics"] == rp.REPAIR_SEMANTICS
    assert len(actions) == len(down_repair.actions)
    assert document["repair"]["steps"][0]["plan_actions"] == [0, len(actions)]
    nominal, groups, settings = rp.plan_groups(down_push, actions, document)
    assert len(nominal) == len(groups) == 1
    assert settings == {"particles": 6, "seed": 3, "method": "enhanced"}
    scores = rp.step_scores(down_push, actions, 1, document=document)
    assert len(scores.belief) == 6
    assert scores.best.multiplier == down_repair.steps[0].multiplier
    assert scores.best.distance == pytest.approx(down_repair.steps[0].distance, rel=1e-6)
    with pytest.raises(ValueError, match="out of range"):
        rp.step_scores(down_push, actions, 2, document=document)


def test_draw_heatmap_writes_a_png(tmp_path, tz, tz_scores):
    from arrange_up.figures.render import write_heatmap

    path = write_heatmap(tz, tz_scores, tmp_path / "heat.png", dpi=40)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_repair_writes_a_plan_file(tmp_path, down_push, down_nominal):
    nominal_file = write_json_atomic(
        tmp_path / "nominal.json",
        plan_document(
            down_push, down_nominal, status="solved", semantics="deterministic", seed=0, search={}
        ),
    )
    out = tmp_path / "fixed.json"
    result = CliRunner().invoke(
        main,
        [
            "repair",
            "down-push",
            "--plan",
            str(nominal_file),
            "--particles",
            "4",
            "--workers",
            "1",
            "--output",
            str(out),
            "--json",
        ],
        catch_exceptions=False,
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)  # progress lines go to stderr
    assert summary["status"] == "solved" and summary["semantics"] == "fixtures"
    assert summary["repair"]["steps"][0]["kind"] == "push"
    actions, _ = read_plan(out, down_push)
    assert actions


def test_cli_repair_bad_input(tmp_path):
    runner = CliRunner()
    bad = runner.invoke(main, ["repair", "down-push", "--method", "clever"])
    assert bad.exit_code == 2
    missing = runner.invoke(main, ["repair", "down-push", "--plan", str(tmp_path / "no.json")])
    assert missing.exit_code == 2 and "cannot read plan file" in missing.output


def test_up_plan_repairer(down_push):
    from unified_planning.engines import PlanGenerationResultStatus as Status
    from unified_planning.shortcuts import PlanRepairer

    from arrange_up.up.compile import plan_from_up, plan_to_up, to_up
    from arrange_up.up.registration import register

    register()
    problem = to_up(down_push)
    nominal = plan_to_up(problem, rp.nominal_plans(down_push, 1, seed=0)[0])
    with PlanRepairer(name="arrange-up-fixtures", params={"particles": 4, "seed": 1}) as repairer:
        result = repairer.repair(problem, nominal)
    assert result.status is Status.SOLVED_SATISFICING
    assert result.engine_name == "arrange-up-fixtures"
    assert result.metrics["status"] == "solved" and "step_1" in result.metrics
    direct = rp.repair_plan(down_push, plan_from_up(nominal), particles=4, seed=1)
    repaired = plan_from_up(result.plan)
    assert len(repaired) == len(direct.actions)
    for got, want in zip(repaired, direct.actions, strict=True):
        assert type(got) is type(want)
        if isinstance(want, Push):
            assert got.distance == pytest.approx(want.distance, abs=1e-6)
    with pytest.raises(ValueError, match="method"):
        PlanRepairer(name="arrange-up-fixtures", params={"method": "clever"})


# -- typed results --------------------------------------------------------------------------------
def test_statuses_are_string_enums_and_statistics_a_dataclass(down_push, down_repair):
    assert isinstance(down_repair.status, rp.RepairStatus)
    assert down_repair.status == "solved" and json.dumps(down_repair.status) == '"solved"'
    assert down_repair.steps[0].status == rp.StepRepairStatus.OK == "ok"
    assert all(isinstance(c.status, rp.CandidateStatus) for c in down_repair_scores(down_push))
    stats = down_repair.statistics
    assert isinstance(stats, rp.RepairStats)
    assert list(down_repair.stats()) == [
        "elapsed",
        "simulations",
        "steps",
        "pushes",
        "fixtures_placed",
        "nominal_length",
        "plan_length",
    ]
    assert down_repair.document(down_push)["search"] == stats.to_json()
    assert stats.plan_length == len(down_repair.actions)


def down_repair_scores(problem):
    nominal = rp.nominal_plans(problem, 1, seed=0)[0]
    return rp.step_scores(problem, nominal, 1, particles=4, seed=3).placements


def test_a_choice_line_calls_its_score_a_mean_distance_not_a_push_length():
    # "distance 0.198" beside a push of 4.1 in read as the push's length
    from arrange_up.model.world import Push
    from arrange_up.repair.records import StepRecord

    push = Push("paddle", (1.0, 1.0, 0.0), 4.112)
    record = StepRecord(0, "push", push, (push,), multiplier=1.0, distance=0.198)
    line = record.describe_choice(load("blocks-1"))
    assert line == "no fixture, x1, mean distance to the nominal state 0.198 (bare push invalid)"
    bare = StepRecord(0, "push", push, (push,), multiplier=1.0, distance=0.2, nominal_distance=0.3)
    assert bare.describe_choice(load("blocks-1")).endswith("state 0.200 (bare push 0.300)")


def test_the_choice_ranks_by_reliability_with_the_distance_as_tie_break():
    push = Push("paddle", (0.0, 0.0, 0.0), 1.0)

    def cand(fixture, distance, reliability, multiplier=1.0):
        pose = None if fixture is None else (1.0, 1.0, 0.0)
        return rp.Candidate(
            fixture, pose, multiplier, "ok", distance, push=push, reliability=reliability
        )

    close_bare = cand(None, 0.1, 0.5)
    reliable_bare = cand(None, 0.3, 0.6, 1.5)
    assert candidates.choose([close_bare, reliable_bare]) is reliable_bare
    # a fixture farther from the nominal state wins when more reliable
    stop = cand("bar", 0.4, 0.7)
    assert candidates.choose([close_bare, reliable_bare, stop]) is stop
    # as reliable as the best bare push: it needs the distance gain of MIN_FIXTURE_GAIN
    assert candidates.choose([reliable_bare, cand("bar", 0.299, 0.6)]) is reliable_bare
    tied = cand("bar", 0.2, 0.6)
    assert candidates.choose([reliable_bare, tied]) is tied
    # less reliable: never, however close
    assert candidates.choose([reliable_bare, cand("bar", 0.0, 0.55)]) is reliable_bare


def test_rollouts_per_particle_reach_the_minimum_only_when_noise_remains():
    from arrange_up.repair.reliability import MIN_ROLLOUTS, rollouts_per_particle

    push = Push("paddle", (0.0, 0.0, 0.0), 1.0)
    assert rollouts_per_particle(10, (push,)) * 10 >= MIN_ROLLOUTS
    assert rollouts_per_particle(10 * MIN_ROLLOUTS, (push,)) == 1
    assert rollouts_per_particle(10, ()) == 1
    assert rollouts_per_particle(10, (Pick("bar"),)) == 1


def test_reliability_is_the_share_of_rollouts_of_the_rest_that_reach_the_goal(tz):
    from arrange_up.repair.reliability import RemainingPlan

    nominal = rp.nominal_plans(tz, 1, seed=0)[0]
    repairer = Repairer(tz, 8, 0, "enhanced", 1, None)
    try:
        states = repairer.nominal_states(nominal)
        nominal_end = repairer.replay.initial()
        for action in nominal:
            nominal_end, _ = repairer.replay.apply(nominal_end, (action,))
        # nothing left to do: the share of particles in the goal
        done = RemainingPlan(repairer, nominal, len(nominal) - 1)
        assert done.reliability(nominal_end) == 1.0
        start = RemainingPlan(repairer, nominal, -1)  # the whole plan from the initial belief
        assert done.reliability(repairer.replay.initial()) == 0.0
        belief = repairer.initial_belief()
        share = start.reliability(belief)
        assert 0.0 <= share <= 1.0
        # common random numbers: the same belief, another object, scores the same
        again = RemainingPlan(repairer, nominal, -1)
        assert again.reliability(belief) == share
        # from the nominal state itself, with noise, the plan reaches the goal at least
        # sometimes (the plan is a nominal plan)
        assert (
            RemainingPlan(repairer, nominal, -1).reliability(repairer.replay.initial()) > 0.0
            or not states
        )
    finally:
        repairer.close()


def test_stop_placements_lie_on_the_grid_flush_with_the_nominal_end(tz):
    nominal = rp.nominal_plans(tz, 1, seed=0)[0]
    repairer = Repairer(tz, 10, 0, "enhanced", 1, None)
    try:
        states = repairer.nominal_states(nominal)
        belief = repairer.initial_belief()
        push = nominal[0]
        [ends] = repairer.pushes([(belief, push)], 0)
        assert ends.belief is not None
        stops = candidates.stop_placements(
            tz,
            repairer.checker,
            repairer.intervals(belief),
            belief.names(),
            push,
            belief,
            ends.belief,
            states[1],
            repairer.parts,
        )
    finally:
        repairer.close()
    assert stops
    moved = [
        name for name, pose in states[1].poses if pose != dict(states[0].poses).get(name, pose)
    ]
    for fixture, pose, _allowed in stops:
        assert fixture == "bar"
        for v in pose[:2]:
            assert v / candidates.GRID_STEP == pytest.approx(round(v / candidates.GRID_STEP))
        bar = candidates.footprint(repairer.checker, fixture, pose)
        # within one grid step of a moved part's nominal end footprint, on some side
        near = False
        for name in moved:
            box = repairer.checker.shadow_box(name, dict(states[1].poses)[name], (0.0, 0.0, 0.0))
            gaps = (box[0] - bar[2], bar[0] - box[2], box[1] - bar[3], bar[1] - box[3])
            near = near or any(-candidates.GRID_STEP <= g <= candidates.GRID_STEP for g in gaps)
        assert near, pose


def test_a_tz_repair_places_a_fixture_more_reliable_than_the_bare_push(tz):
    nominal = rp.nominal_plans(tz, 1, seed=0)[0]
    result = rp.repair_plan(tz, nominal, particles=10, seed=0)
    assert result.solved
    placed = [s for s in result.steps if s.fixture is not None]
    assert placed
    for step in placed:
        assert step.reliability is not None and step.nominal_reliability is not None
        assert step.reliability > step.nominal_reliability
    document = result.document(tz)
    record = document["repair"]["steps"][0]
    assert "reliability" in record and "nominal_reliability" in record and "stops" in record
