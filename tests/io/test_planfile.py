"""Tests of ``arrange_up.io.planfile``: actions to and from JSON in the problem's units, plan
documents, atomic writes, and reading plan files (errors name the file and the place)."""

from __future__ import annotations

import json
import math
import os
import re
import stat
from pathlib import Path

import pytest
from catalogue import servo, tiny, variant

from arrange_up.io.planfile import (
    PLAN_FORMAT,
    PlanFileError,
    action_from_json,
    action_to_json,
    plan_document,
    plan_problem_mismatches,
    read_plan,
    write_json_atomic,
    write_text_atomic,
)
from arrange_up.model.problem import problem_hash
from arrange_up.model.world import Pick, Place, Push
from arrange_up.search import SearchStatus

#: A plan of block-and-fixture in internal units (inches, radians), one action of each kind.
ACTIONS = (
    Place("A", (5.088, 0.912, 0.0)),
    Push("paddle", (4.377683, 1.322212, -math.pi / 2), 0.5473),
    Pick("bar"),
)


def document(problem, actions=ACTIONS, status="solved", **extra):
    return plan_document(
        problem,
        actions,
        status=status,
        semantics="particles",
        seed=3,
        search={"expanded": 2, "elapsed": 0.1},
        extra=extra or None,
    )


def write(tmp_path: Path, doc, name="plan.json") -> Path:
    return write_json_atomic(tmp_path / name, doc)


def assert_same_actions(got, want):
    assert len(got) == len(want)
    for a, b in zip(got, want, strict=True):
        assert type(a) is type(b)
        if isinstance(b, Pick):
            assert a == b
        elif isinstance(b, Place):
            assert a.obj == b.obj and a.pose == pytest.approx(b.pose, abs=1e-12)
        else:
            assert a.manipulator == b.manipulator
            assert a.pose == pytest.approx(b.pose, abs=1e-12)
            assert a.distance == pytest.approx(b.distance, abs=1e-12)


# -- actions -------------------------------------------------------------------------------
def test_actions_to_json_in_inches_and_degrees():
    units = tiny("block-and-fixture").units
    assert [action_to_json(a, units) for a in ACTIONS] == [
        {"type": "place", "object": "A", "pose": [5.088, 0.912, 0.0]},
        {"type": "push", "manipulator": "paddle", "pose": [4.377683, 1.322212, -90.0],
         "distance": 0.5473},
        {"type": "pick", "object": "bar"},
    ]  # fmt: skip


def test_actions_to_json_in_millimetres_and_without_binary_noise():
    units = tiny("millimetres").units
    place = action_to_json(Place("A", (0.1 + 0.2, 1.0, math.pi)), units)
    assert place["pose"] == [7.62, 25.4, 180.0]  # 0.30000000000000004 in is 7.62 mm
    push = action_to_json(Push("paddle", (1.0, 2.0, -math.pi), 0.5), units)
    assert push["pose"] == [25.4, 50.8, -180.0] and push["distance"] == 12.7


def test_action_to_json_refuses_what_is_not_an_action():
    with pytest.raises(TypeError, match="not an action"):
        action_to_json(("place", "A"), tiny("one-block").units)  # type: ignore[arg-type]


@pytest.mark.parametrize("name", ["one-block", "millimetres"])
def test_actions_round_trip_through_json(name):
    problem = tiny(name)
    actions = (
        Place("A", (4.088, 0.912, math.radians(15))),
        Push("paddle", (3.377683, 1.322212, -math.pi / 2), 0.5473),
        Push("paddle", (3.677788, 1.622523, -math.pi), 0.0),
        Pick("A"),  # a plan file may pick a part (the planner never does)
    )
    back = [
        action_from_json(
            json.loads(json.dumps(action_to_json(a, problem.units))), problem.units, problem, "x"
        )
        for a in actions
    ]
    assert_same_actions(back, actions)


BAD_ACTIONS = [
    ("place A", "x: expected an object with a 'type'"),
    ({"type": "slide"}, "x.type: expected 'place', 'push' or 'pick', got 'slide'"),
    ({"type": "pick", "object": "Z"}, "x.object: expected an object of problem 'block-and-fix"),
    ({"type": "pick"}, "x.object: expected an object of problem .* got None"),
    ({"type": "place", "object": "paddle", "pose": [1, 1, 0]}, "'paddle' is a manipulator"),
    ({"type": "push", "manipulator": "A", "pose": [1, 1, 0], "distance": 1}, "'A' is a part"),
    ({"type": "place", "object": "A", "pose": [1, 1]}, r"x.pose: expected \[x, y, theta\]"),
    ({"type": "place", "object": "A", "pose": "1 1 0"}, "x.pose: expected"),
    ({"type": "place", "object": "A", "pose": [1, True, 0]}, "x.pose: expected"),
    ({"type": "place", "object": "A", "pose": [1, float("nan"), 0]}, "x.pose: expected"),
    (
        {"type": "push", "manipulator": "paddle", "pose": [1, 1, 0], "distance": -1},
        "x.distance: expected a non-negative number, got -1",
    ),
    (
        {"type": "push", "manipulator": "paddle", "pose": [1, 1, 0], "distance": "2"},
        "x.distance: expected a non-negative number",
    ),
    ({"type": "push", "manipulator": "paddle", "pose": [1, 1, 0]}, "x.distance: .* got None"),
    (
        {"type": "place", "object": "A", "pose": [1e300, 1, 0]},
        r"x.pose: x = 1e\+300 in is more than 100 table sizes from the table",
    ),
    (
        {"type": "push", "manipulator": "paddle", "pose": [1, -1e9, 0], "distance": 1},
        r"x.pose: y = -1000000000.0 in is more than 100 table sizes",
    ),
]


@pytest.mark.parametrize("data, message", BAD_ACTIONS)
def test_action_from_json_names_the_place_of_each_error(data, message):
    problem = tiny("block-and-fixture")
    with pytest.raises(PlanFileError, match=message):
        action_from_json(data, problem.units, problem, "x")


# -- documents and files -------------------------------------------------------------------
def test_plan_document_records_problem_units_and_search():
    problem = tiny("millimetres")
    doc = document(problem, ACTIONS[:2], particles=5)
    assert doc["format"] == PLAN_FORMAT
    assert doc["problem"] == {
        "name": "millimetres",
        "hash": problem_hash(problem),
        "source": "catalogue:millimetres",
    }
    assert doc["units"] == {"length": "mm", "angle": "deg"}
    assert (doc["status"], doc["semantics"], doc["seed"], doc["particles"]) == (
        "solved",
        "particles",
        3,
        5,
    )
    assert doc["search"] == {"expanded": 2, "elapsed": 0.1}
    assert doc["actions"][0]["pose"] == pytest.approx([129.2352, 23.1648, 0.0])


def test_only_a_solved_plan_document_holds_actions():
    problem = tiny("block-and-fixture")
    assert "actions" not in document(problem, ACTIONS, status="timeout")
    assert "actions" not in document(problem, None, status="solved")


def test_atomic_writes_create_folders_and_leave_no_temporary_files(tmp_path):
    target = tmp_path / "deep" / "er" / "plan.json"
    assert write_json_atomic(target, {"a": 1}) == target
    assert json.loads(target.read_text()) == {"a": 1} and target.read_text().endswith("\n")
    write_text_atomic(target, "replaced\n")
    assert target.read_text() == "replaced\n"
    assert os.listdir(target.parent) == ["plan.json"]


def test_a_failed_atomic_write_keeps_the_old_file(tmp_path, monkeypatch):
    target = write_text_atomic(tmp_path / "plan.json", "old\n")

    def broken_replace(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk full"):
        write_text_atomic(target, "new\n")
    assert target.read_text() == "old\n"
    assert os.listdir(tmp_path) == ["plan.json"]


@pytest.mark.parametrize("name", ["block-and-fixture", "millimetres"])
def test_read_plan_returns_the_written_actions_in_inches(tmp_path, name):
    problem = tiny(name)
    actions = ACTIONS if name == "block-and-fixture" else ACTIONS[:2]
    path = write(tmp_path, document(problem, actions))
    got, doc = read_plan(path, problem)
    assert_same_actions(got, actions)
    assert doc["problem"]["name"] == name
    # Also from a str path.
    assert_same_actions(read_plan(str(path), problem)[0], actions)


def _edited(tmp_path, problem, edit) -> Path:
    doc = document(problem)
    edit(doc)
    return write(tmp_path, doc)


BAD_PLANS = {
    "format": (lambda d: d.update(format="other/1"), "format: expected 'arrange-up-plan/1'"),
    "status": (lambda d: d.update(status="timeout"), "status: the plan is 'timeout'"),
    "no actions": (lambda d: d.pop("actions"), "actions: missing; a solved plan lists its"),
    "units": (lambda d: d.update(units={"length": "ft"}), "units: unknown length unit 'ft'"),
    "units type": (lambda d: d.update(units=["mm"]), "units: "),
    "actions type": (lambda d: d.update(actions={"0": {}}), "actions: expected a list"),
    "action": (
        lambda d: d["actions"][1].update(manipulator="bar"),
        r"actions\[1\]\.manipulator: 'bar' is a fixture",
    ),
}


@pytest.mark.parametrize("case", BAD_PLANS)
def test_read_plan_errors_name_the_file_and_the_place(tmp_path, case):
    problem = tiny("block-and-fixture")
    edit, message = BAD_PLANS[case]
    path = _edited(tmp_path, problem, edit)
    with pytest.raises(PlanFileError, match=message) as error:
        read_plan(path, problem)
    assert str(error.value).startswith(f"{path}: ")


@pytest.mark.parametrize("status", ["exhausted", "unsolvable"])
def test_an_unsolved_plan_file_old_or_new_reads_as_its_status(tmp_path, status):
    # Files written before "exhausted" existed say "unsolvable" for an exhausted search: the
    # status still parses, and reading the plan refuses it as any unsolved plan, by its status.
    problem = tiny("block-and-fixture")
    path = write(tmp_path, document(problem, None, status=status))
    assert SearchStatus(json.loads(path.read_text())["status"]) == status
    with pytest.raises(PlanFileError, match=f"status: the plan is '{status}', not 'solved'"):
        read_plan(path, problem)


def test_read_plan_of_a_missing_file_or_not_json(tmp_path):
    problem = tiny("block-and-fixture")
    missing = tmp_path / "missing.json"
    with pytest.raises(PlanFileError, match=f"^{re.escape(str(missing))}: cannot read plan file"):
        read_plan(missing, problem)
    broken = tmp_path / "broken.json"
    broken.write_text('{"format":\n  oops}\n')
    with pytest.raises(PlanFileError, match=f"^{re.escape(str(broken))}:2:3: not JSON"):
        read_plan(broken, problem)
    listed = tmp_path / "list.json"
    listed.write_text("[1, 2]\n")
    with pytest.raises(PlanFileError, match=r"format: expected .* got \[1, 2\]"):
        read_plan(listed, problem)


def test_plan_problem_mismatch_warns_only_for_other_content():
    one, mm = tiny("one-block"), tiny("millimetres")
    doc = document(one, ACTIONS[:2])
    assert plan_problem_mismatches(doc, one) == []
    (warning,) = plan_problem_mismatches(doc, mm)
    assert "planned for problem 'one-block'" in warning and "'millimetres'" in warning
    assert problem_hash(one) in warning and problem_hash(mm) in warning
    # The same content in other units is the same problem.
    renamed = variant("millimetres", "name: millimetres", "name: one-block")
    assert plan_problem_mismatches(doc, renamed) == []
    # Another controller is named as such; a file naming no controller was made by the servo.
    servo_doc = document(servo(one), ACTIONS[:2])
    (warning,) = plan_problem_mismatches(servo_doc, one)
    assert "planned under the servo controller" in warning
    legacy = {k: v for k, v in servo_doc.items() if k != "controller"}
    assert plan_problem_mismatches(legacy, servo(one)) == []
    (warning,) = plan_problem_mismatches(legacy, one)
    assert "planned under the servo controller" in warning
    # Nothing recorded: nothing to compare.
    assert plan_problem_mismatches({"format": PLAN_FORMAT}, mm) == []
    assert plan_problem_mismatches([], mm) == []  # type: ignore[arg-type]


def test_plan_problem_mismatches_reports_another_problem_under_another_controller():
    one, mm = tiny("one-block"), tiny("millimetres")
    # Planned for another problem and under another controller: both are said, each in the
    # words it has alone.
    other, controller = plan_problem_mismatches(document(one, ACTIONS[:2]), servo(mm))
    assert other == (
        "it was planned for problem 'one-block' with other content than 'millimetres' "
        f"({problem_hash(one)} vs {problem_hash(servo(mm))})"
    )
    assert controller == (
        "it was planned under the compliant controller; problem 'millimetres' uses the servo one"
    )
    legacy = {k: v for k, v in document(servo(one), ACTIONS[:2]).items() if k != "controller"}
    legacy_other, legacy_controller = plan_problem_mismatches(legacy, mm)
    assert "planned for problem 'one-block'" in legacy_other
    assert legacy_controller.startswith("it was planned under the servo controller; problem")
    assert "(it names no controller: it was made when the servo was every" in legacy_controller
    # A malformed record of the problem does not hide the controller.
    malformed = {**document(servo(one), ACTIONS[:2]), "problem": "one-block"}
    record, controller = plan_problem_mismatches(malformed, one)
    assert record == "its 'problem' is the string 'one-block', not an object naming the problem"
    assert "planned under the servo controller" in controller


def test_another_controller_alone_is_not_another_problem():
    # The hash covers the controller, so a plan of the same problem under another controller
    # has another hash; judged under the controller it records (tuned, in the plan's units),
    # the content is the same and only the controller is said.
    tuned = variant(
        "millimetres",
        "name: millimetres",
        "name: one-block\ncontroller: {kind: compliant, kp: 200, speed: 50.8, force: 254}",
    )
    doc = document(tuned, ACTIONS[:2])
    assert doc["units"]["length"] == "mm" and doc["controller"]["speed"] == 50.8
    one = tiny("one-block")
    assert problem_hash(tuned) != problem_hash(servo(one))
    (warning,) = plan_problem_mismatches(doc, servo(one))
    assert warning.startswith("it was planned under the compliant controller")
    # ... while the same kind with other gains is other content, as it always was
    (warning,) = plan_problem_mismatches(doc, one)
    assert "planned for problem 'one-block' with other content than 'one-block'" in warning
    # A controller the plan names but this version cannot read: judged by the name alone.
    unknown = {**doc, "controller": {"kind": "magic"}}
    (warning,) = plan_problem_mismatches(unknown, one)
    assert warning.startswith("it was planned under the magic controller")
    assert len(plan_problem_mismatches(unknown, tiny("millimetres"))) == 2


def test_an_atomic_write_gives_the_file_the_umask_permissions(tmp_path):
    # the temporary file is private (0o600); the file written must not stay so
    previous = os.umask(0o022)
    try:
        written = write_text_atomic(tmp_path / "plan.json", "{}\n")
    finally:
        os.umask(previous)
    assert stat.S_IMODE(written.stat().st_mode) == 0o644
    assert [p.name for p in tmp_path.iterdir()] == ["plan.json"]  # no temporary file left


def test_a_plan_file_naming_a_key_twice_is_refused_at_the_second_copy(tmp_path):
    # json.loads keeps the last copy: a second "actions": [] ran the empty plan
    problem = tiny("block-and-fixture")
    text = json.dumps(document(problem), indent=2)
    path = tmp_path / "twice.json"
    path.write_text(text[: text.rindex("}")] + ',\n  "actions": []\n}\n')
    line = path.read_text().count("\n") - 1
    with pytest.raises(PlanFileError, match=rf'^{re.escape(str(path))}:{line}:3: key "actions"'):
        read_plan(path, problem)


def test_a_plan_file_nested_too_deeply_is_refused_with_line_and_column(tmp_path):
    path = tmp_path / "deep.json"
    path.write_text('{"format":\n  ' + "[" * 100 + "]" * 100 + "}\n")
    with pytest.raises(PlanFileError, match=rf"^{re.escape(str(path))}:2:34: nested too deeply"):
        read_plan(path, tiny("block-and-fixture"))


def test_an_atomic_write_writes_through_a_symlink_and_keeps_it(tmp_path):
    target = tmp_path / "real.json"
    target.write_text("old\n")
    link = tmp_path / "link.json"
    link.symlink_to(target)
    write_text_atomic(link, "new\n")
    assert link.is_symlink() and target.read_text() == "new\n"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_an_atomic_write_writes_through_a_fifo_and_keeps_it(tmp_path):
    import threading

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_text()))
    reader.start()
    write_text_atomic(fifo, "through\n")
    reader.join(timeout=10)
    assert received == ["through\n"]
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)  # not replaced by a regular file


def test_a_plan_file_too_large_or_with_too_many_actions_is_refused(tmp_path):
    from arrange_up.io.planfile import MAX_PLAN_ACTIONS

    problem = tiny("block-and-fixture")
    zero = Path("/dev/zero")
    if zero.exists():  # endless: read up to the limit, then refused
        with pytest.raises(PlanFileError, match=r"^/dev/zero: larger than 16 MiB"):
            read_plan(zero, problem)
    many = document(problem, (ACTIONS[2],) * (MAX_PLAN_ACTIONS + 1))
    path = write(tmp_path, many)
    with pytest.raises(PlanFileError, match=rf"actions: {MAX_PLAN_ACTIONS + 1} actions; a plan"):
        read_plan(path, problem)


def test_a_pose_off_the_table_but_within_reach_is_read():
    problem = tiny("block-and-fixture")
    width, depth = problem.table.size
    far = 99 * max(width, depth)
    for pose in ([-far, 1, 0], [1, depth + far, 0]):
        action = action_from_json(
            {"type": "place", "object": "A", "pose": pose}, problem.units, problem, "x"
        )
        assert action == Place("A", (pose[0], pose[1], 0.0))
