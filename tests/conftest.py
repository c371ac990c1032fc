"""Shared fixtures: the catalogue of tiny problems (``tests/catalogue.py``) by name.

* ``tiny``: the loader function itself, ``tiny("one-block")``.
* ``problem``: one catalogue problem, chosen by indirect parametrisation::

      @pytest.mark.parametrize("problem", ["one-block", "l-part"], indirect=True)
      def test_something(problem): ...
"""

from __future__ import annotations

from collections.abc import Callable

import pytest
from catalogue import tiny as _tiny

from arrange_up.model.problem import ArrangementProblem


@pytest.fixture(scope="session")
def tiny() -> Callable[[str], ArrangementProblem]:
    """Load a catalogue problem by name (each is loaded once per session)."""
    return _tiny


@pytest.fixture
def problem(request: pytest.FixtureRequest) -> ArrangementProblem:
    """The catalogue problem named by the test's indirect parameter."""
    name = getattr(request, "param", None)
    if name is None:
        raise pytest.UsageError(
            "the 'problem' fixture needs a catalogue name: "
            '@pytest.mark.parametrize("problem", ["one-block"], indirect=True)'
        )
    return _tiny(name)
