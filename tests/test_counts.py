"""The one integer check (arrange_up.counts): booleans are not counts, and the messages name what
was expected, as the callers' tests and users read them."""

from __future__ import annotations

import pytest

from arrange_up.counts import check_count, is_integer, is_number


@pytest.mark.parametrize(
    ("minimum", "value", "expected"),
    [
        (1, 0, "rollouts must be a positive integer, got 0"),
        (1, True, "rollouts must be a positive integer, got True"),
        (1, 2.0, "rollouts must be a positive integer, got 2.0"),
        (0, -1, "rollouts must be a non-negative integer, got -1"),
        (None, "3", "rollouts must be an integer, got '3'"),
        (5, 4, "rollouts must be an integer of at least 5, got 4"),
    ],
)
def test_a_bad_count_is_refused_naming_what_was_expected(minimum, value, expected):
    with pytest.raises(ValueError) as raised:
        check_count("rollouts", value, minimum=minimum)
    assert str(raised.value) == expected


@pytest.mark.parametrize(("minimum", "value"), [(1, 1), (0, 0), (None, -7), (5, 5)])
def test_a_good_count_passes(minimum, value):
    check_count("rollouts", value, minimum=minimum)


def test_booleans_are_neither_integers_nor_numbers():
    assert is_integer(3) and not is_integer(True) and not is_integer(3.0)
    assert is_number(3) and is_number(2.5) and not is_number(False) and not is_number("1")
