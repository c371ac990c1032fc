"""Problem files larger than ``MAX_PROBLEM_BYTES`` are refused before they are parsed: exit 2
with a message naming the file, its size and the limit, for YAML and PDDL alike (a 50 MB file
once took minutes and gigabytes to check)."""

from __future__ import annotations

import contextlib
import os
import threading
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.io.files import MAX_PROBLEM_BYTES, ProblemFileTooLarge, read_problem_bytes

REPOSITORY = Path(__file__).resolve().parents[2]


def _padded(source: Path, target: Path, comment: bytes) -> int:
    """``source`` followed by comment lines, just over the limit; returns the size."""
    data = source.read_bytes()
    line = comment + b" " + b"x" * 98 + b"\n"
    padding = line * ((MAX_PROBLEM_BYTES - len(data)) // len(line) + 1)
    target.write_bytes(data + padding)
    size = target.stat().st_size
    assert MAX_PROBLEM_BYTES < size < MAX_PROBLEM_BYTES + 2 * len(line)
    return size


@pytest.mark.parametrize(("shipped", "comment"), [("blocks-1.yaml", b"#"), ("blocks-1.pddl", b";")])
def test_check_refuses_a_file_just_over_the_limit_before_parsing_it(
    tmp_path: Path, shipped: str, comment: bytes
) -> None:
    path = tmp_path / f"big{Path(shipped).suffix}"
    size = _padded(REPOSITORY / "domains" / shipped, path, comment)
    started = time.perf_counter()
    result = CliRunner().invoke(main, ["check", str(path)])
    elapsed = time.perf_counter() - started
    assert result.exit_code == 2, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
    assert f"{path}: error: the file is too large: {size:,} bytes" in result.output
    assert f"at most {MAX_PROBLEM_BYTES:,} bytes" in result.output
    assert "Traceback" not in result.output
    # refused without parsing: far less than the seconds a megabyte of YAML takes
    assert elapsed < 1.0


def test_plan_refuses_an_oversized_problem_with_exit_2(tmp_path: Path) -> None:
    path = tmp_path / "big.yaml"
    _padded(REPOSITORY / "domains" / "blocks-1.yaml", path, b"#")
    result = CliRunner().invoke(main, ["plan", str(path)])
    assert result.exit_code == 2, result.output
    assert "too large" in result.output and str(path) in result.output


def test_read_problem_bytes_takes_a_file_at_the_limit_and_refuses_one_byte_more(
    tmp_path: Path,
) -> None:
    path = tmp_path / "p.yaml"
    path.write_bytes(b"a" * 100)
    assert read_problem_bytes(path, limit=100) == b"a" * 100
    with pytest.raises(ProblemFileTooLarge) as raised:
        read_problem_bytes(path, limit=99)
    assert raised.value.size == 100


def test_a_stream_is_read_only_up_to_the_limit(tmp_path: Path) -> None:
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)

    def write() -> None:  # more than the limit; the reader hangs up after limit + 1 bytes
        with contextlib.suppress(BrokenPipeError), open(fifo, "wb") as handle:
            handle.write(b"b" * 1000)

    writer = threading.Thread(target=write)
    writer.start()
    try:
        with pytest.raises(ProblemFileTooLarge, match="more than 100 bytes"):
            read_problem_bytes(fifo, limit=100)
    finally:
        writer.join(timeout=5)
