"""The shared file helpers (``arrange_up.io.files``): where UTF-8 breaks, and exclusive locks."""

from __future__ import annotations

from pathlib import Path

from arrange_up.io.files import lock_exclusively, undecodable_place


def test_the_place_of_the_first_byte_that_is_not_utf8() -> None:
    data = "ab\ncdé\nx".encode() + b"\xff tail"
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as error:
        assert undecodable_place(data, error) == (3, 2)
    else:  # pragma: no cover
        raise AssertionError("the bytes decoded")


def test_a_second_exclusive_lock_on_a_file_is_refused_until_the_first_closes(
    tmp_path: Path,
) -> None:
    path = tmp_path / "records.jsonl"
    with open(path, "a+b") as first:
        assert lock_exclusively(first)
        with open(path, "a+b") as second:
            assert not lock_exclusively(second)
    with open(path, "a+b") as third:
        assert lock_exclusively(third)
