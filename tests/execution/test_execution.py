"""Closed-loop execution: observations, belief update, the loop, records and the command."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

import arrange_up.cli.execute as execute_command
from arrange_up.belief.states import IntervalBelief, ObjectInterval, ParticleBelief
from arrange_up.cli import main
from arrange_up.execution import (
    ClosedLoop,
    ClosedLoopSettings,
    EpisodeRecord,
    ExecutionFailed,
    Executor,
    Observation,
    ParticleFilter,
    Replan,
    SimulatedExecutor,
    intersect_intervals,
    run_episodes,
    scaled_problem,
    sensor_for,
)
from arrange_up.io.domains import load
from arrange_up.model.world import Place, Push, WorldState
from arrange_up.physics.simulation import simulate
from arrange_up.planning.planner import plan


@pytest.fixture(scope="module")
def blocks2():
    problem = load("blocks-2")
    result = plan(problem, semantics="particles", particles=5, seed=0, max_nodes=300)
    assert result.solved
    return problem, result.actions


def first_push(actions):
    k = next(i for i, a in enumerate(actions) if isinstance(a, Push))
    return k, actions[k]


def test_a_push_reports_the_paddles_final_pose():
    problem = load("blocks-1")
    push = Push("paddle", (2.0, 2.0, 0.0), 1.0)
    outcome = simulate(problem, WorldState(()), push)
    assert outcome.manipulator_pose is not None
    # nothing in the way: the compliant paddle ends its full distance along its direction
    start = np.array(push.pose[:2])
    end = np.array(outcome.manipulator_pose[:2])
    assert np.linalg.norm(end - start) == pytest.approx(1.0, abs=0.02)
    assert simulate(problem, WorldState(()), Place("A", (3.0, 3.0, 0.0))).manipulator_pose is None


def test_the_sensor_draws_its_documented_noise_and_folds_symmetric_angles(blocks2):
    problem, actions = blocks2
    sensor = sensor_for(problem, "poses")
    state = WorldState((("A", (3.0, 3.0, 0.0)),))
    outcome = simulate(problem, WorldState(()), Place("A", (3.0, 3.0, 0.0)))
    rng = np.random.default_rng(0)
    draws = np.array([sensor.observe(Place("A", (3.0, 3.0, 0.0)), outcome, rng).poses[0][1]
                      for _ in range(2000)])  # fmt: skip
    assert draws.std(axis=0) == pytest.approx(sensor.poses_sigma, rel=0.1)
    # a square seen turned by a quarter turn is the same square: no residual
    turned = Observation(poses=(("A", (3.0, 3.0, math.pi / 2)),))
    delta, _ = sensor.residuals(turned, [Observation(poses=state.poses)])
    assert np.abs(delta).max() < 1e-9
    assert sensor_for(problem, "none").predict(actions[0], outcome) == Observation()
    both = Observation(paddle=(1.0, 2.0, 0.5), poses=(("A", (3.0, 3.0, 0.1)),))
    assert Observation.from_json(json.loads(json.dumps(both.to_json()))) == both


def test_a_paddle_observation_narrows_the_belief_to_the_particles_that_explain_it(blocks2):
    problem, actions = blocks2
    k, push = first_push(actions)
    sensor = sensor_for(problem, "paddle")
    executor = SimulatedExecutor(problem, sensor, seed=3, episode=0)
    belief_filter = ParticleFilter(problem, sensor, 40, np.random.default_rng(1))
    belief = belief_filter.initial()
    for i, action in enumerate(actions[: k + 1]):
        update = belief_filter.update(belief, action, i, executor.execute(action, i))
        assert update.failure is None
        belief = update.posterior
    # the posterior's particles predict the observation better than the prediction's did
    observed = update.posterior  # after the push
    assert update.ess < 40
    truth = np.array(executor.state.poses[0][1][:2])
    error_after = np.abs(observed.poses[:, 0, :2] - truth).mean()
    error_before = np.abs(update.predicted.poses[:, 0, :2] - truth).mean()
    assert error_after <= error_before


def test_an_observation_no_particle_explains_is_a_model_failure(blocks2):
    problem, actions = blocks2
    k, push = first_push(actions)
    sensor = sensor_for(problem, "paddle")
    executor = SimulatedExecutor(problem, sensor, seed=3, episode=0)
    belief_filter = ParticleFilter(problem, sensor, 20, np.random.default_rng(1))
    belief = belief_filter.initial()
    for i, action in enumerate(actions[:k]):
        belief = belief_filter.update(belief, action, i, executor.execute(action, i)).posterior
    seen = executor.execute(push, k)
    x, y, theta = seen.paddle
    far = Observation(paddle=(x + 3.0, y + 3.0, theta))
    update = belief_filter.update(belief, push, k, far)
    assert update.failure is not None and update.failure.action == k
    assert update.failure.excess > 4.0 and not update.failure.recovered


def test_scaled_noise_widens_every_half_width_and_range():
    problem = load("blocks-2")
    wide = scaled_problem(problem, 2.0)
    assert wide.uncertainty.place == tuple(2 * v for v in problem.uncertainty.place)
    low, high = problem.uncertainty.friction
    assert wide.uncertainty.friction[1] - wide.uncertainty.friction[0] == pytest.approx(
        2 * (high - low)
    )
    assert scaled_problem(problem, 1.0) is problem


def test_the_planner_plans_from_a_given_start_belief(blocks2):
    problem, actions = blocks2
    executor = SimulatedExecutor(problem, sensor_for(problem, "none"), seed=0, episode=0)
    for i, action in enumerate(actions):
        executor.execute(action, i)
    at_goal = ParticleBelief((executor.state,))
    result = plan(problem, semantics="deterministic", start=at_goal)
    assert result.solved and result.actions == ()


def test_a_truncated_plan_is_completed_by_replanning(blocks2):
    problem, actions = blocks2
    settings = ClosedLoopSettings(filter_particles=16, check_rollouts=4, particles=5)
    short = actions[: len(actions) // 2]
    result = run_episodes(problem, short, sense="paddle", episodes=2, seed=0, settings=settings)
    assert all(e.replans for e in result.episodes)
    assert result.reliability.successes == 2
    # without replans the same truncated plan cannot reach the goal
    open_loop = ClosedLoopSettings(filter_particles=4, max_replans=0)
    baseline = run_episodes(problem, short, sense="none", episodes=2, seed=0, settings=open_loop)
    assert baseline.reliability.successes == 0
    assert baseline.reliability.failures.goal_missed == 2


def test_a_replan_that_finds_no_plan_records_the_planners_reason(blocks2):
    problem, actions = blocks2
    settings = ClosedLoopSettings(
        filter_particles=16, check_rollouts=4, particles=5, max_nodes=1, max_replans=1
    )
    short = actions[: len(actions) // 2]
    [episode] = run_episodes(problem, short, episodes=1, seed=0, settings=settings).episodes
    [replan] = episode.replans
    assert replan.status == "node-limit" and replan.plans == 0
    # the replan's agenda spent its one node, then the whole goal's search its own
    assert replan.reason.startswith("node-limit after 2 nodes")
    assert Replan.from_json(replan.to_json()) == replan
    # records written before the reason was kept read back without one
    older = {k: v for k, v in replan.to_json().items() if k != "reason"}
    assert Replan.from_json(older).reason is None


def test_episodes_resume_from_their_record(blocks2, tmp_path):
    problem, actions = blocks2
    settings = ClosedLoopSettings(filter_particles=8, check_rollouts=4, particles=5)
    record = tmp_path / "run.jsonl"
    first = run_episodes(problem, actions, episodes=2, seed=1, settings=settings, record=record)
    again = run_episodes(problem, actions, episodes=3, seed=1, settings=settings, record=record)
    assert again.resumed == 2 and again.episodes[:2] == first.episodes
    lines = record.read_text().splitlines()
    assert len(lines) == 4 and json.loads(lines[0])["format"] == "arrange-up-episodes/1"
    for line in lines[1:]:
        data = json.loads(line)
        assert EpisodeRecord.from_json(data).to_json() == data
    # a line cut off by a killed run is dropped and its episode run again
    record.write_text(record.read_text() + lines[-1][:20])
    cut = run_episodes(problem, actions, episodes=3, seed=1, settings=settings, record=record)
    assert cut.resumed == 3 and cut.episodes == again.episodes
    assert record.read_text().count("\n") == 4
    # an episode recorded twice with different outcomes is refused, not read as the last one
    copy = {**json.loads(lines[1]), "actions": 5}
    assert copy != json.loads(lines[1])
    kept = record.read_text()
    record.write_text(kept + json.dumps(copy) + "\n")
    with pytest.raises(ValueError, match=r":5: episode 0 is recorded twice"):
        run_episodes(problem, actions, episodes=3, seed=1, settings=settings, record=record)
    record.write_text(kept)
    other = ClosedLoopSettings(filter_particles=9)
    with pytest.raises(ValueError, match="another closed-loop run"):
        run_episodes(problem, actions, episodes=1, seed=1, settings=other, record=record)
    # a file that is not an episode record is refused and left as it was, newline or not
    notes = tmp_path / "notes.json"
    notes.write_text('{"format": "arrange-up-plan/1"}')
    with pytest.raises(ValueError, match="not an arrange-up episode record"):
        run_episodes(problem, actions, episodes=1, seed=1, settings=settings, record=notes)
    assert notes.read_text() == '{"format": "arrange-up-plan/1"}'


def test_an_action_the_executor_cannot_carry_out_ends_the_episode(blocks2):
    problem, actions = blocks2

    class Refusing:
        def execute(self, action, index):
            from arrange_up.evaluation.outcomes import ACTION_FAILED, Failure

            raise ExecutionFailed(Failure(ACTION_FAILED, index, "the arm is out of reach"))

    assert isinstance(Refusing(), Executor)
    loop = ClosedLoop(problem, actions, sensor_for(problem, "paddle"), ClosedLoopSettings(8))
    outcome = loop.run(Refusing())
    assert outcome.stopped == "action failed" and outcome.executed == ()
    assert outcome.failure.reason == "the arm is out of reach"


def test_an_interval_belief_is_intersected_with_what_a_camera_bounds(blocks2):
    problem, _ = blocks2
    sensor = sensor_for(problem, "poses")
    belief = IntervalBelief((("A", ObjectInterval((3.0, 3.0, 0.0), (0.2, 0.2, 0.2))),))
    seen = Observation(poses=(("A", (3.1, 3.0, 0.0)),))
    narrowed, empty = intersect_intervals(belief, seen, sensor)
    assert empty == ()
    box = narrowed.get("A")
    assert box.half[0] < 0.2 and belief.get("A").contains(box)
    _, empty = intersect_intervals(belief, Observation(poses=(("A", (5.0, 3.0, 0.0)),)), sensor)
    assert empty == ("A",)
    assert intersect_intervals(belief, Observation(paddle=(1.0, 1.0, 0.0)), sensor)[0] is belief


def test_the_execute_command_reports_rate_replans_and_failures(blocks2, tmp_path):
    problem, actions = blocks2
    runner = CliRunner()
    result = runner.invoke(
        main,
        ["execute", "blocks-2", "--episodes", "2", "--semantics", "deterministic",
         "--filter-particles", "8", "--json"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["trials"] == 2 and len(data["interval"]) == 2
    assert set(data["replans"]) >= {"per_episode", "seconds", "total"}
    assert data["sense"] == "paddle" and len(data["episode_records"]) == 2
    bad = runner.invoke(main, ["execute", "blocks-2", "--sense", "sonar"])
    assert bad.exit_code == 2 and "sonar" in bad.output
    unknown = runner.invoke(main, ["execute", "blocks-2", "--semantics", "magic"])
    assert unknown.exit_code == 2 and "unknown semantics" in unknown.output
    beyond = runner.invoke(
        main,
        ["execute", "blocks-2", "--episodes", "2", "--storyboard", str(tmp_path / "s.png"),
         "--storyboard-episode", "5"],
    )  # fmt: skip
    assert beyond.exit_code == 2 and "expected one of the episodes run, 0 to 1" in beyond.output
    assert not (tmp_path / "s.png").exists()


def test_an_interrupted_execute_says_how_far_it_got_and_what_is_kept(blocks2, monkeypatch):
    def two_then_ctrl_c(*args, progress, **kwargs):
        for record in (EpisodeRecord(0, True, None, 3, (), (), "done"),) * 2:
            progress(record)
        raise KeyboardInterrupt

    monkeypatch.setattr(execute_command, "run_episodes", two_then_ctrl_c)
    args = ["execute", "blocks-2", "--episodes", "5", "--semantics", "deterministic"]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 1
    assert "interrupted after 2 of 5 episodes (2 reached the goal" in result.output
    assert "--record FILE keeps every finished episode" in result.output


def test_the_fake_robot_example_runs_the_loop(capsys):
    import runpy
    from pathlib import Path

    example = Path(__file__).resolve().parents[2] / "examples" / "fake_robot.py"
    runpy.run_path(str(example), run_name="__main__")
    printed = capsys.readouterr().out
    assert "push" in printed and "stopped: " in printed


def test_the_storyboard_of_an_episode_draws_observations_and_posteriors(blocks2, tmp_path):
    from arrange_up.execution import run_episode
    from arrange_up.figures.episode import draw_episode, episode_data

    problem, actions = blocks2
    settings = ClosedLoopSettings(filter_particles=6, check_rollouts=2, max_replans=0)
    _, outcome, executor = run_episode(problem, actions, "paddle", settings, 0, 0, trace=True)
    data = episode_data(executor.trace, outcome)
    assert len(data["beliefs"]) == len(outcome.trace) + 1 == len(data["nominal"])
    assert len(data["rollouts"]) == 6  # one grey trace per posterior particle
    written = draw_episode(problem, executor.trace, outcome, tmp_path / "episode.png")
    assert written.stat().st_size > 10_000
    _, untraced, _ = run_episode(problem, actions, "paddle", settings, 0, 0)
    with pytest.raises(ValueError, match="not traced"):
        episode_data(executor.trace, untraced)


@pytest.mark.parametrize("adapt", [True, False])
def test_a_placement_outside_the_model_is_recovered_and_adapted_to(blocks2, adapt):
    problem, actions = blocks2
    place = actions[0]
    assert isinstance(place, Place)
    sensor = sensor_for(problem, "poses")
    belief_filter = ParticleFilter(problem, sensor, 20, np.random.default_rng(2), adapt=adapt)
    x, y, theta = place.pose
    seen = Observation(poses=((place.obj, (x - 0.55, y, theta)),))  # place noise: ±0.2 in
    update = belief_filter.update(belief_filter.initial(), place, 0, seen)
    assert update.failure is not None and update.failure.scale == 2.0
    # the posterior follows the observation, not the model
    assert update.posterior.poses[:, 0, 0].mean() < x - 0.3
    assert belief_filter.scale == (2.0 if adapt else 1.0)
