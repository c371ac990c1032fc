"""Plans with real parameters through unified-planning's ``PDDLWriter``.

unified-planning 1.3's ``PDDLWriter.write_plan`` (which its ``up oneshot-planning --plan FILE``
command calls) writes every action parameter as an object name: an arrange-up plan, whose place
and push actions carry real poses and distances, failed with a bare ``AssertionError``.
:func:`install` wraps the writer's plan method once: a sequential plan with a parameter that is
not an object is written one action per line with its numbers as exact decimals,
``(place a 9.088 0.912 0)``, ``(push paddle 8.0666 1.3222 -90 0.9336)`` (inches and degrees, as
the unified-planning model holds them); every other plan is written by unified-planning's own
code, unchanged. PDDL 2.1 has no syntax for numeric action arguments, so such a file is
arrange-up's extension: unified-planning's ``PDDLReader.parse_plan`` cannot read it back, and
``arrange-up plan PROBLEM -o plan.json`` writes the documented plan file (docs/plan-format.md).

The planner engine's module installs it, so it is in place whenever unified-planning has made
the engine (the ``up`` command included), and nowhere else.
"""

from __future__ import annotations

from decimal import Decimal, localcontext
from fractions import Fraction
from typing import IO, Any

from unified_planning.io import PDDLWriter
from unified_planning.plans import SequentialPlan

__all__ = ["decimal", "install"]

_MARK = "_arrange_up_real_parameters"


def install() -> None:
    """Make ``PDDLWriter`` write sequential plans with real parameters (idempotent)."""
    original = PDDLWriter._write_plan
    if getattr(original, _MARK, False):
        return

    def _write_plan(self: Any, plan: Any, out: IO[str]) -> None:
        if not (isinstance(plan, SequentialPlan) and _has_numbers(plan)):
            original(self, plan, out)
            return
        for instance in plan.actions:
            words = [self._get_mangled_name(instance.action)]
            for parameter in instance.actual_parameters:
                if parameter.is_object_exp():
                    words.append(self._get_mangled_name(parameter.object()))
                else:
                    words.append(decimal(Fraction(parameter.constant_value())))
            out.write(f"({' '.join(words)})\n")

    setattr(_write_plan, _MARK, True)
    PDDLWriter._write_plan = _write_plan


def decimal(value: Fraction) -> str:
    """``value`` as a decimal: exact when it has one of at most 12 places (the model's numbers
    have 9), else rounded to 12 places; no exponent, no trailing zeros."""
    with localcontext() as context:
        context.prec = 60
        quotient = Decimal(value.numerator) / Decimal(value.denominator)
        text = format(quotient.quantize(Decimal(1).scaleb(-12)).normalize(), "f")
    return "0" if text == "-0" else text


def _has_numbers(plan: Any) -> bool:
    return any(
        not parameter.is_object_exp()
        for instance in plan.actions
        for parameter in instance.actual_parameters
    )
