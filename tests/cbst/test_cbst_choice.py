"""A CBST model plans only problems of the controller it was trained under."""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from pathlib import Path

import pytest
from click.testing import CliRunner

from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.cbst.choice import card_controller, controller_record, model_for
from arrange_up.cbst.data import (
    COMPLIANT,
    SERVO,
    SHIPPED_WALL_PUSH,
    GenerationSettings,
    generate_dataset,
)
from arrange_up.cbst.features import TARGET_NAMES
from arrange_up.cbst.model import rescore_model, train_cbst
from arrange_up.cbst.store import SHIPPED_MODELS, load_model, model_dir, save_model
from arrange_up.cli import main
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.domains import load
from arrange_up.io.resources import shipped_dir
from arrange_up.model.problem import DEFAULT_CONTROLLER, Controller, ControllerKind
from arrange_up.planning.actions import ActionGenerator
from arrange_up.planning.planner import plan
from arrange_up.transitions.cbst import TRAINED_PUSH_REFUSAL, CBSTSemantics


def _with(problem, **controller):
    return dataclasses.replace(problem, controller=Controller(**controller))


@pytest.fixture(scope="module")
def compliant_model(tmp_path_factory) -> Path:
    """A tiny model trained under the compliant controller (as train-cbst makes one)."""
    folder = tmp_path_factory.mktemp("compliant")
    train_cbst(
        examples=12,
        rollouts_per_example=2,
        seed=3,
        workers=1,
        output_dir=folder,
        controller=COMPLIANT,
        test_examples=3,
        param_grid={"min_samples_leaf": [4]},
        n_estimators=3,
    )
    return folder / "compliant.json"


def test_the_card_names_its_controller_and_scores_every_target(compliant_model):
    card = json.loads(compliant_model.read_text())
    assert card["controller"] == {
        "kind": "compliant",
        "kp": 300.0,
        "kp_angle": "default",
        "speed": "default",
        "force": "default",
        "torque": "default",
    }
    assert card["data"]["settings"]["controller"]["kind"] == "compliant"
    scores = card["scores"]
    assert scores["cv_folds"] == 8
    for key in ("cv_rmse", "cv_r2", "test_rmse", "test_r2"):
        assert set(scores[key]) == set(TARGET_NAMES), key
        assert all(isinstance(v, float) for v in scores[key].values())
    assert scores["test"] == {
        "examples": 3,
        "invalid_examples": 0,
        "rows": scores["test"]["rows"],
        "rollouts_per_example": 2,
        "seed": 1,
        "file": "compliant.test.jsonl",
    }
    assert card_controller(card) == COMPLIANT


def test_a_model_from_another_controller_is_refused(compliant_model):
    servo_problem = _with(load("blocks-2"), kind=ControllerKind.SERVO)
    with pytest.raises(ValueError, match="trained under the compliant .* uses the servo"):
        model_for(servo_problem, compliant_model)
    with pytest.raises(ValueError, match="trained under the compliant"):
        plan(servo_problem, semantics="cbst", model=compliant_model, max_nodes=10)
    compliant_problem = _with(load("blocks-2"), kind=ControllerKind.COMPLIANT)
    with pytest.raises(ValueError, match="trained under the servo .* uses the compliant"):
        model_for(compliant_problem, "servo")
    assert model_for(compliant_problem, compliant_model).card_["controller"]["kind"] == (
        "compliant"
    )


def test_gains_must_match_too_but_unused_ones_do_not_matter(compliant_model):
    blocks = load("blocks-2")
    with pytest.raises(ValueError, match="kp 150"):
        model_for(_with(blocks, kind=ControllerKind.COMPLIANT, kp=150.0), compliant_model)
    # a default written out is the default; the servo ignores kp
    same = _with(blocks, kind=ControllerKind.COMPLIANT, speed=3.0)
    assert model_for(same, compliant_model)
    assert model_for(_with(blocks, kind=ControllerKind.SERVO, kp=100.0), "servo")


def test_no_model_means_the_shipped_one_of_the_problems_controller():
    blocks = load("blocks-2")
    for kind in ControllerKind:
        model = model_for(_with(blocks, kind=kind))
        assert model.card_path_ == (model_dir() / f"{SHIPPED_MODELS[kind]}.json").resolve()
        assert model.card_["controller"]["kind"] == kind.value
    default = load_model("default")
    assert default.card_["controller"]["kind"] == DEFAULT_CONTROLLER.kind.value


def test_a_card_without_a_controller_is_the_servos(tmp_path):
    shipped = load_model("servo")
    card = {k: v for k, v in shipped.card_.items() if k not in ("format", "name", "arrays")}
    del card["controller"]
    old = save_model(shipped, card, tmp_path, "old")
    assert card_controller(json.loads(old.read_text())) == SERVO
    assert model_for(_with(load("blocks-2"), kind=ControllerKind.SERVO), old)
    with pytest.raises(ValueError, match="trained under the servo"):
        model_for(_with(load("blocks-2"), kind=ControllerKind.COMPLIANT), old)
    with pytest.raises(ValueError, match="controller kp must be a positive number"):
        card_controller({"controller": {**controller_record(COMPLIANT), "kp": "default"}})
    with pytest.raises(ValueError, match="kind one of compliant, servo"):
        card_controller({"controller": {"kind": "stiff"}})


def test_the_controller_is_a_generation_setting():
    servo = dataclasses.replace(GenerationSettings(), controller=SERVO)
    # the servo's digest is the one from before the controller was a setting
    assert servo.digest() == load_model("servo").card_["data"]["settings_digest"]
    assert GenerationSettings().controller == COMPLIANT
    assert GenerationSettings().digest() != servo.digest()
    assert GenerationSettings.from_dict(GenerationSettings().as_dict()) == GenerationSettings()


def test_a_data_file_of_another_controller_is_refused(tmp_path):
    path = tmp_path / "d.jsonl"
    generate_dataset(path, examples=1, rollouts=1, settings=GenerationSettings())
    servo = dataclasses.replace(GenerationSettings(), controller=SERVO)
    with pytest.raises(ValueError, match="generation settings"):
        generate_dataset(path, examples=2, rollouts=1, settings=servo)


def _blocks_2_file(folder: Path, controller: str) -> Path:
    source = shipped_dir("domains", "the shipped domains") / "blocks-2.yaml"
    path = folder / "blocks-2-controller.yaml"
    path.write_text(source.read_text() + f"controller: {controller}\n")
    return path


def test_the_cli_refuses_a_model_of_another_controller_with_exit_2(compliant_model, tmp_path):
    problem = _blocks_2_file(tmp_path, "{kind: servo}")
    runner = CliRunner()
    result = runner.invoke(
        main, ["plan", str(problem), "--semantics", "cbst", "--model", str(compliant_model)]
    )
    assert result.exit_code == 2, result.output
    assert "trained under the compliant" in result.output and "uses the servo" in result.output
    assert "Traceback" not in result.output


def test_the_cli_refuses_a_problem_no_shipped_model_fits_with_exit_2(tmp_path):
    problem = _blocks_2_file(tmp_path, "{kind: compliant, kp: 150}")
    result = CliRunner().invoke(main, ["plan", str(problem), "--semantics", "cbst"])
    assert result.exit_code == 2, result.output
    assert "blocks-2-controller.yaml" in result.output and "kp 150" in result.output


def test_the_engine_answers_a_model_of_another_controller_with_an_error(compliant_model):
    from unified_planning.engines import PlanGenerationResultStatus as Status
    from unified_planning.shortcuts import OneshotPlanner

    from arrange_up.up.compile import to_up

    problem = _with(load("blocks-2"), kind=ControllerKind.SERVO)
    params = {"semantics": "cbst", "max_nodes": 10, "model": str(compliant_model)}
    with OneshotPlanner(name="arrange-up", params=params) as planner:
        result = planner.solve(to_up(problem))
    assert result.status is Status.UNSUPPORTED_PROBLEM
    assert "trained under the compliant" in result.log_messages[0].message


def test_rescoring_a_saved_model_replaces_only_its_scores(compliant_model, tmp_path):
    folder = tmp_path / "copy"
    folder.mkdir()
    for suffix in (".json", ".npz"):
        (folder / f"compliant{suffix}").write_bytes(
            compliant_model.with_suffix(suffix).read_bytes()
        )
    card_path = folder / "compliant.json"
    before = json.loads(card_path.read_text())
    arrays = hashlib.sha256((folder / "compliant.npz").read_bytes()).hexdigest()
    scores = rescore_model(
        card_path,
        data_path=tmp_path / "d.jsonl",
        test_data_path=tmp_path / "t.jsonl",
        test_examples=2,
        test_seed=7,
        write=True,
    )
    after = json.loads(card_path.read_text())
    assert after["scores"] == scores and scores["test"]["seed"] == 7
    assert scores["cv_data"]["examples"] == before["data"]["examples"]
    # the same data regenerated, the same hyperparameters: the same out-of-fold figures
    assert scores["cv_rmse"] == pytest.approx(before["scores"]["cv_rmse"])
    assert {k: v for k, v in after.items() if k != "scores"} == {
        k: v for k, v in before.items() if k != "scores"
    }
    assert hashlib.sha256((folder / "compliant.npz").read_bytes()).hexdigest() == arrays
    assert load_model(card_path).card_["scores"]["test"]["seed"] == 7
    with pytest.raises(ValueError, match="another seed"):
        rescore_model(
            card_path, data_path=tmp_path / "d.jsonl", test_data_path=tmp_path / "u", test_seed=3
        )


def test_rescore_cli_refuses_an_unknown_model_with_exit_2(tmp_path):
    args = ["rescore-cbst", "no-such", "--data", str(tmp_path / "d"), "--test-data", "t"]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 2 and "unknown CBST model 'no-such'" in result.output


def test_a_model_of_the_planners_wall_pushes_predicts_those_pushes_only(tmp_path):
    # Trained with wall_push="planner", a model knows the push that stops just past the
    # compressed train (the one CBST's planner offers) and no other: a push to the wall
    # itself is refused with TRAINED_PUSH_REFUSAL. A model of uniform pushes is not.
    def tiny(wall_push: str):
        return train_cbst(
            examples=12,
            rollouts_per_example=2,
            seed=3,
            workers=1,
            output_dir=tmp_path / wall_push,
            settings=dataclasses.replace(GenerationSettings(), wall_push=wall_push),
            test_examples=3,
            param_grid={"min_samples_leaf": [4]},
            n_estimators=3,
        )

    card = tiny("planner")
    assert card["data"]["settings"]["wall_push"] == "planner"
    problem = load("blocks-2")
    belief = IntervalBelief((("A", ObjectInterval((9.0, 0.912, 0.0), (0.1, 0.1, 0.1))),))

    def wall_push(compressed: bool):
        generator = ActionGenerator(
            problem, CollisionChecker(problem), compressed_wall_pushes=compressed
        )
        rightwards = [p for p in generator.pushes(belief) if p.pose[2] == -math.pi / 2]
        return max(rightwards, key=lambda p: p.distance)  # the push to the wall

    planner = CBSTSemantics(problem, model=tmp_path / "planner" / "compliant.json")
    assert planner.apply(belief, wall_push(compressed=True)) is not None
    # the model refuses the other push, which the simulated fallback answers
    assert planner.apply(belief, wall_push(compressed=False)) is not None
    assert planner.fallback_reasons == {TRAINED_PUSH_REFUSAL: 1}
    assert planner.fallback_counts() == (1, 2)
    assert tiny("uniform")["data"]["settings"]["wall_push"] == "uniform"
    uniform = CBSTSemantics(problem, model=tmp_path / "uniform" / "compliant.json")
    uniform.apply(belief, wall_push(compressed=False))
    assert TRAINED_PUSH_REFUSAL not in uniform.reasons + uniform.fallback_reasons


def test_the_shipped_compliant_model_learnt_the_planners_wall_pushes():
    # so that CBST's pushes to a wall under the default controller are the ones it predicts;
    # train-cbst's default rule for each controller is its shipped model's
    card = json.loads((model_dir() / "compliant.json").read_text())
    assert card["data"]["settings"]["wall_push"] == SHIPPED_WALL_PUSH["compliant"] == "planner"
    assert card["data"]["rollouts_per_example"] == 1000
    servo = json.loads((model_dir() / "servo.json").read_text())
    assert servo["data"]["settings"].get("wall_push", "uniform") == SHIPPED_WALL_PUSH["servo"]
