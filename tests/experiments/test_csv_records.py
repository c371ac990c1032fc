"""Tests of arrange_up.experiments.csv_records: the experiments' CSVs get the record files'
care (a lock, a cut-off line dropped, other columns and settings refused, a key measured
once)."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.experiments.csv_records import (
    CsvAppender,
    CsvRecordsError,
    done_keys,
    read_csv,
    settings_path,
)
from arrange_up.experiments.planning import Planner, transition_comparison

FIELDS = ["problem", "run", "value"]
KEY = ("problem", "run")
SETTINGS = {"rollouts": 4, "max_nodes": 10, "timeout": None}


def _appender(path: Path, settings=SETTINGS) -> CsvAppender:
    return CsvAppender(path, FIELDS, key=KEY, settings=settings)


def test_a_file_that_is_not_this_csv_is_refused_untouched_even_without_a_final_newline(
    tmp_path: Path,
):
    for text in ("one line of notes", "a,b\n1,2", "\xff\xfe binary"):
        path = tmp_path / "t.csv"
        path.write_text(text, encoding="latin-1")
        with pytest.raises(CsvRecordsError, match="are not this experiment's"), _appender(path):
            pass
        assert path.read_text(encoding="latin-1") == text
    # the start of the header a kill cut off is a CSV begun: it starts afresh
    path.write_text("problem,ru")
    with _appender(path) as write:
        write({"problem": "p", "run": 0, "value": 1.5})
    assert path.read_text().splitlines() == ["problem,run,value", "p,0,1.5"]


def test_rows_are_appended_resumed_and_settings_kept(tmp_path: Path):
    path = tmp_path / "t.csv"
    with _appender(path) as write:
        assert write.done == set()
        write({"problem": "p", "run": 0, "value": 1.5})
    with _appender(path) as write:
        assert write.done == {("p", "0")}
        write({"problem": "p", "run": 1, "value": 2})
    assert [r["run"] for r in read_csv(path)] == ["0", "1"]
    assert settings_path(path).name == "t.settings.json"
    assert settings_path(path).exists()


def test_a_second_writer_is_refused_while_the_first_writes(tmp_path: Path):
    path = tmp_path / "t.csv"
    with _appender(path) as write:
        write({"problem": "p", "run": 0, "value": 1})
        # another process: flock locks are held per open file, across processes
        code = (
            "import sys\n"
            "from arrange_up.experiments.csv_records import CsvAppender, CsvRecordsError\n"
            f"try:\n    CsvAppender({str(path)!r}, {FIELDS!r}, key={KEY!r}).__enter__()\n"
            "except CsvRecordsError as e:\n    print(e); sys.exit(3)\n"
        )
        done = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, check=False
        )
        assert done.returncode == 3, done.stderr
        assert "in use by another run" in done.stdout
    with _appender(path) as write:  # released on exit
        assert write.done == {("p", "0")}


def test_a_key_is_measured_once(tmp_path: Path):
    path = tmp_path / "t.csv"
    with _appender(path) as write:
        write({"problem": "p", "run": 0, "value": 1})
        with pytest.raises(CsvRecordsError, match="already measured"):
            write({"problem": "p", "run": "0", "value": 2})
    assert len(read_csv(path)) == 1


def test_a_cut_off_last_line_is_dropped(tmp_path: Path):
    path = tmp_path / "t.csv"
    with _appender(path) as write:
        write({"problem": "p", "run": 0, "value": 1})
        write({"problem": "p", "run": 1, "value": 2})
    text = path.read_text()
    path.write_text(text[: text.rindex("p,1") + 4])  # killed while writing row 1
    assert [r["run"] for r in read_csv(path)] == ["0"]
    assert done_keys(path, KEY) == {("p", "0")}
    with _appender(path) as write:
        assert write.done == {("p", "0")}
        write({"problem": "p", "run": 1, "value": 2})
    with path.open(newline="") as handle:
        assert list(csv.reader(handle)) == [FIELDS, ["p", "0", "1"], ["p", "1", "2"]]


def test_other_columns_or_settings_are_refused(tmp_path: Path):
    path = tmp_path / "t.csv"
    with _appender(path) as write:
        write({"problem": "p", "run": 0, "value": 1})
    with pytest.raises(CsvRecordsError, match=r"max_nodes: the CSV's 10, this run's 20"):
        with _appender(path, {**SETTINGS, "max_nodes": 20}):
            pass
    with pytest.raises(CsvRecordsError, match="columns"):
        with CsvAppender(path, ["problem", "run"], key=KEY, settings=SETTINGS):
            pass
    assert len(read_csv(path)) == 1  # nothing written by the refused runs


PLANNERS = [Planner("deterministic", "deterministic", 1)]


def test_a_planner_given_twice_is_measured_once(tmp_path: Path):
    measured: list[dict] = []
    path = transition_comparison(
        tmp_path,
        problems=("blocks-1", "blocks-1"),
        planners=PLANNERS * 2,
        runs=1,
        rollouts=0,
        workers=1,
        measured=measured.append,
    )
    assert len(measured) == 1
    assert [(r["problem"], r["planner"], r["run"]) for r in read_csv(path)] == [
        ("blocks-1", "deterministic", "0")
    ]


def test_a_rerun_with_a_cut_off_line_resumes_and_other_settings_exit_2(tmp_path: Path):
    kwargs = {"problems": ("blocks-1",), "planners": PLANNERS, "runs": 2, "workers": 1}
    path = transition_comparison(tmp_path, rollouts=0, **kwargs)
    text = path.read_text()
    path.write_text(text[: len(text) - 5])  # the last row cut off by a kill
    transition_comparison(tmp_path, rollouts=0, **kwargs)
    assert [r["run"] for r in read_csv(path)] == ["0", "1"]
    result = CliRunner().invoke(
        main,
        [
            "experiment",
            "transition-comparison",
            "--problems",
            "blocks-1",
            "--runs",
            "2",
            "--rollouts",
            "3",
            "--output-dir",
            str(tmp_path),
        ],
    )
    assert result.exit_code == 2, result.output
    assert "other settings" in result.output and "rollouts" in result.output
    # refused before any work: no estimate of work that will not be done
    assert "estimate:" not in result.output


def test_a_number_column_holding_a_word_nan_or_inf_is_refused_with_its_line(tmp_path: Path):
    path = tmp_path / "t.csv"
    numbers = {"run": int, "value": float}
    with CsvAppender(path, FIELDS, key=KEY, settings=SETTINGS, numbers=numbers) as write:
        write({"problem": "p", "run": 0, "value": 1.5})
        write({"problem": "p", "run": 1, "value": ""})  # not measured: passes
    good = path.read_bytes()
    for cell in ("many", "nan", "-inf", "Infinity", "1.5x"):
        path.write_bytes(good.replace(b"1.5", cell.encode()))
        with pytest.raises(CsvRecordsError, match=rf"t\.csv:2: column value holds '{cell}'"):
            with CsvAppender(path, FIELDS, key=KEY, settings=SETTINGS, numbers=numbers):
                pass
    path.write_bytes(good.replace(b"p,1,", b"p,1.0,"))
    with pytest.raises(CsvRecordsError, match=r"t\.csv:3: column run holds '1.0', not an integer"):
        with CsvAppender(path, FIELDS, key=KEY, settings=SETTINGS, numbers=numbers):
            pass


def test_bytes_that_are_not_utf8_are_refused_with_their_line(tmp_path: Path):
    path = tmp_path / "t.csv"
    with _appender(path) as write:
        write({"problem": "p", "run": 0, "value": 1})
        write({"problem": "q", "run": 0, "value": 1})
    path.write_bytes(path.read_bytes().replace(b"q,", b"\xffq,"))
    for reading in (
        lambda: read_csv(path),
        lambda: done_keys(path, KEY),
        _appender(path).__enter__,
    ):
        with pytest.raises(CsvRecordsError, match=r"t\.csv:3: byte 0xff is not UTF-8"):
            reading()
    # a kill may cut the last line inside a character: that line is dropped, not refused
    path.write_bytes(path.read_bytes().replace(b"\xffq,", b"q,") + "p,1,\u00e9".encode()[:-1])
    assert len(read_csv(path)) == 2


@pytest.mark.parametrize("cell", ["many", "nan", "-inf"])
def test_experiment_refuses_a_resumed_csv_with_a_bad_number_cell_exit_2(tmp_path: Path, cell: str):
    args = ["experiment", "search-table", "--problems", "blocks-1", "--semantics"]
    args += ["deterministic", "--output-dir", str(tmp_path), "--quiet"]
    assert CliRunner().invoke(main, args).exit_code == 0
    path = tmp_path / "search-table.csv"
    lines = path.read_bytes().split(b"\r\n")
    lines[3] = lines[3].rsplit(b",", 1)[0] + b"," + cell.encode()
    path.write_bytes(b"\r\n".join(lines[:4]) + b"\r\n")
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 2, result.output
    assert f"search-table.csv:4: column seconds holds '{cell}'" in result.output
    assert "Traceback" not in result.output
    path.write_bytes(b"\r\n".join(lines[:3]) + b"\r\n\xff\r\n")
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 2, result.output
    assert "search-table.csv:4: byte 0xff is not UTF-8" in result.output


@pytest.mark.parametrize("header", ["problem,runs,value", "\ufeffproblem,run,value", "p,1,2"])
def test_a_header_without_the_key_columns_is_refused_not_a_key_error(tmp_path: Path, header):
    # a renamed column, a byte-order mark or a lost header row: done_keys (read before the
    # appender checks the columns) raised KeyError, a traceback of `experiment`
    path = tmp_path / "t.csv"
    path.write_text(f"{header}\np,1,2\n", encoding="utf-8")
    refused = r"t\.csv: its columns \(.*\) lack (problem|run|problem, run), expected"
    with pytest.raises(CsvRecordsError, match=refused):
        done_keys(path, KEY)


def test_experiment_refuses_a_resumed_csv_with_a_renamed_key_column_exit_2(tmp_path: Path):
    args = ["experiment", "search-table", "--problems", "blocks-1", "--semantics"]
    args += ["deterministic", "--output-dir", str(tmp_path), "--quiet"]
    assert CliRunner().invoke(main, args).exit_code == 0
    path = tmp_path / "search-table.csv"
    path.write_bytes(path.read_bytes().replace(b"problem", b"problme", 1))
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 2, result.output
    assert "search-table.csv: its columns (" in result.output
    assert "problme" in result.output and ") lack problem, expected" in result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
