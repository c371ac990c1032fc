"""Integers and numbers given by a caller or read from a file, checked one way everywhere (the
lowest room: every other may import it).

``bool`` is a subclass of ``int`` in Python, so ``isinstance(True, int)`` holds; a count,
seed or size given as ``True`` is a mistake, and every check here refuses booleans.
"""

from __future__ import annotations

from typing import Any, TypeGuard

__all__ = ["check_count", "is_integer", "is_number"]


def is_integer(value: object) -> TypeGuard[int]:
    """True for an ``int`` that is not a ``bool``."""
    return isinstance(value, int) and not isinstance(value, bool)


def is_number(value: object) -> TypeGuard[float]:
    """True for an ``int`` or ``float`` that is not a ``bool`` (NaN and infinities included)."""
    return isinstance(value, int | float) and not isinstance(value, bool)


def check_count(name: str, value: Any, minimum: int | None = 1, maximum: int | None = None) -> None:
    """Raise ``ValueError`` unless ``value`` is an integer (not a ``bool``) of at least
    ``minimum`` (``None``: any integer). The message names ``name`` and what was expected:
    ``"{name} must be a positive integer, got {value!r}"`` for a minimum of 1,
    ``"... a non-negative integer ..."`` for 0, ``"... an integer ..."`` for ``None`` and
    ``"... an integer of at least {minimum} ..."`` otherwise; with a ``maximum``, a larger
    integer gives ``"{name} must be at most {maximum:,}, got {value!r}"``."""
    if is_integer(value) and (minimum is None or value >= minimum):
        if maximum is not None and value > maximum:
            raise ValueError(f"{name} must be at most {maximum:,}, got {value!r}")
        return
    expected = {None: "an integer", 0: "a non-negative integer", 1: "a positive integer"}.get(
        minimum, f"an integer of at least {minimum}"
    )
    raise ValueError(f"{name} must be {expected}, got {value!r}")
