"""A resumed ``arrange-up execute --record`` says which episodes it read back from the record
instead of reporting them as run (as ``evaluate --record`` says what it resumed)."""

from __future__ import annotations

import json

from click.testing import CliRunner

from arrange_up.cli import execute as execute_command
from arrange_up.cli import main
from arrange_up.execution.episodes import EpisodeRecord

#: Cheap episodes: the deterministic first plan executed open loop, sensing nothing.
CHEAP = ["--semantics", "deterministic", "--sense", "none", "--max-replans", "0"]
CHEAP += ["--filter-particles", "4"]


def _execute(record, episodes: int, *extra: str):
    args = ["execute", "blocks-2", "--episodes", str(episodes), "--record", str(record)]
    result = CliRunner().invoke(main, [*args, *CHEAP, *extra])
    assert result.exit_code == 0, result.output
    return result


def test_a_resumed_execute_names_the_episodes_read_back_and_lists_only_those_run(tmp_path):
    record = tmp_path / "r.jsonl"
    first = _execute(record, 2)
    assert "resumed from" not in first.output and "resumed 2" not in first.output
    assert first.stderr.count("  episode ") == 2
    again = _execute(record, 3)
    assert f"  resumed 2 episodes from {record}\n" in again.stderr
    run_now = [line for line in again.stderr.splitlines() if line.startswith("  episode ")]
    assert len(run_now) == 1 and run_now[0].startswith("  episode 2: ")
    assert f", 2 resumed from {record}\n" in again.stdout
    # everything read back: no episode line, the summary says all were resumed
    whole = _execute(record, 3)
    assert "  episode " not in whole.stderr
    assert f"  resumed 3 episodes from {record}" in whole.stderr
    assert f", 3 resumed from {record}\n" in whole.stdout
    data = json.loads(_execute(record, 3, "--json").stdout)
    assert data["resumed"] == 3 and data["trials"] == 3


def test_an_interrupted_resumed_execute_says_how_many_were_read_back(tmp_path, monkeypatch):
    record = tmp_path / "r.jsonl"

    def resume_two_run_one_then_ctrl_c(*args, progress, on_resume, **kwargs):
        on_resume((0, 1))
        for i in range(3):
            progress(EpisodeRecord(i, True, None, 3, (), (), "done"))
        raise KeyboardInterrupt

    monkeypatch.setattr(execute_command, "run_episodes", resume_two_run_one_then_ctrl_c)
    args = ["execute", "blocks-2", "--episodes", "5", "--semantics", "deterministic"]
    result = CliRunner().invoke(main, [*args, "--record", str(record)])
    assert result.exit_code == 1
    assert f"interrupted after 3 of 5 episodes (2 of them resumed from {record}; 3 reached" in (
        result.output
    )
    assert result.stderr.count("  episode ") == 1


def _edited_line(record, edit) -> None:
    lines = record.read_text().splitlines()
    lines[1] = edit(lines[1])
    record.write_text("\n".join(lines) + "\n")


def test_a_record_line_with_infinity_or_an_action_past_the_episode_is_refused(tmp_path):
    for name, edit, message in (
        ("inf", lambda line: line.replace('"actions": 6', '"actions": Infinity', 1), "Infinity"),
        (
            "past",
            lambda line: json.dumps(
                {
                    **json.loads(line),
                    "success": False,
                    "failure": {"kind": "action_failed", "action": 99999, "reason": "x"},
                }
            ),
            "failure.action: expected the 0-based index of an action of the 6 executed",
        ),
        ("count", lambda line: line.replace('"actions": 6', '"actions": 99999', 1), "actions:"),
    ):
        record = tmp_path / f"{name}.jsonl"
        _execute(record, 1)
        assert '"actions": 6' in record.read_text()
        _edited_line(record, edit)
        args = ["execute", "blocks-2", "--episodes", "1", "--record", str(record), *CHEAP]
        result = CliRunner().invoke(main, args)
        assert result.exit_code == 2, (name, result.output)
        assert result.exception is None or isinstance(result.exception, SystemExit)
        assert f"{record}:2: not an episode record: " in result.stderr and message in result.stderr


def test_a_record_that_is_not_a_regular_file_is_refused_before_any_work():
    args = ["execute", "blocks-2", "--episodes", "1", "--record", "/dev/null", *CHEAP]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 2, result.output
    assert "/dev/null: not a regular file" in result.stderr
