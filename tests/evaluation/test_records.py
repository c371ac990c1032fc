"""Tests of arrange_up.evaluation.records: each resumed rollout line is checked against the plan
before it counts."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.evaluation.records import RECORD_FORMAT, RecordFile, RecordFileError
from arrange_up.io.domains import load
from arrange_up.model.world import Place
from arrange_up.parallel import SERIAL

HEADER = {
    "format": RECORD_FORMAT,
    "problem": {"name": "p", "hash": "sha256:p"},
    "plan": {"hash": "sha256:l", "actions": 3},
    "seed": 0,
    "physics": "0123456789abcdef",
}
GOOD = [
    {"rollout": 0, "success": True},
    {"rollout": 1, "success": False, "failure": {"kind": "action_failed", "action": 2}},
    {
        "rollout": 2,
        "success": False,
        "failure": {
            "kind": "goal_missed",
            "misses": [{"part": "A", "dimensions": ["x"], "excess": [0.1, 0, 0]}],
        },
    },
]


def _failed(failure: object) -> dict:
    return {"rollout": 3, "success": False, "failure": failure}


def _write(path: Path, *lines: object) -> None:
    text = [json.dumps(HEADER)] + [
        line if isinstance(line, str) else json.dumps(line) for line in lines
    ]
    path.write_text("\n".join(text) + "\n", encoding="utf-8")


def test_good_lines_are_read(tmp_path: Path):
    path = tmp_path / "r.jsonl"
    _write(path, *GOOD)
    file = RecordFile(path, HEADER)
    file.close()
    assert sorted(file.records) == [0, 1, 2]
    assert file.records[1].failure.action == 2


@pytest.mark.parametrize(
    ("line", "says"),
    [
        (_failed({"kind": "off_table", "action": 3}), "action"),
        (_failed({"kind": "off_table", "action": -1}), "action"),
        (_failed({"kind": "not_at_rest"}), "action"),
        (
            {"rollout": 3, "success": False, "failure": {"kind": "goal_missed", "action": 0}},
            "names no action",
        ),
        ({"rollout": 3, "success": False, "failure": {"kind": "crashed"}}, "unknown failure kind"),
        ({"rollout": 3, "success": False, "failure": 5}, "failure"),
        ({"rollout": 3, "success": False, "failure": "goal_missed"}, "failure"),
        (
            {
                "rollout": 3,
                "success": False,
                "failure": {
                    "kind": "goal_missed",
                    "misses": [{"part": "A", "dimensions": ["x"], "excess": ["far", 0, 0]}],
                },
            },
            "three finite numbers",
        ),
        (
            {
                "rollout": 3,
                "success": False,
                "failure": {"kind": "off_table", "action": 0, "objects": 5},
            },
            "objects",
        ),
        ({"rollout": "3", "success": True}, "rollout"),
        ({"rollout": 3, "success": "yes"}, "success"),
        ([3, True], "JSON object"),
        ("{not json", "not a rollout record"),
    ],
)
def test_a_bad_line_is_refused_with_its_file_and_line(tmp_path: Path, line, says):
    path = tmp_path / "r.jsonl"
    _write(path, *GOOD, line, {"rollout": 4, "success": True})
    with pytest.raises(RecordFileError) as caught:
        RecordFile(path, HEADER)
    message = str(caught.value)
    assert message.startswith(f"{path}:5: ")  # the header is line 1, the bad line line 5
    assert says in message


def test_a_resumed_evaluation_refuses_an_edited_line(tmp_path: Path):
    problem = load("blocks-1")
    actions = [Place("A", (9.5, 0.5, 0.0))]
    record = tmp_path / "b1.jsonl"
    first = evaluate_plan(problem, actions, rollouts=3, seed=0, runner=SERIAL, record=record)
    lines = record.read_text().splitlines()
    edited = json.loads(lines[2])
    edited.update(success=False, failure={"kind": "action_failed", "action": 7})
    record.write_text("\n".join([*lines[:2], json.dumps(edited), *lines[3:]]) + "\n")
    with pytest.raises(RecordFileError, match=rf"{record.name}:3: .*action.*got 7"):
        evaluate_plan(problem, actions, rollouts=3, seed=0, runner=SERIAL, record=record)
    record.write_text("\n".join(lines) + "\n")  # as written: resumed, identical
    again = evaluate_plan(problem, actions, rollouts=3, seed=0, runner=SERIAL, record=record)
    assert again == first and again.resumed == 3


def test_a_rollout_recorded_twice_is_read_once_or_refused_when_the_copies_differ(tmp_path):
    path = tmp_path / "r.jsonl"
    _write(path, *GOOD, GOOD[0])  # the same line again (a copy): harmless
    file = RecordFile(path, HEADER)
    file.close()
    assert sorted(file.records) == [0, 1, 2]
    _write(path, *GOOD, {"rollout": 1, "success": True})  # another outcome: refused
    with pytest.raises(RecordFileError, match=r":5: rollout 1 is recorded twice with different"):
        RecordFile(path, HEADER)
