"""Belief-state transition semantics, by name.

A semantics maps ``(belief, action)`` to the resulting belief, or to ``None`` when it cannot
predict the outcome or the outcome is not acceptable (a part pushed off the table, a
simulation that never came to rest). The registry lets the planner, the unified-planning
engine, the CLI and the experiments refer to semantics by name:

* ``deterministic``: one particle at the nominal initial poses, no noise, every domain
  parameter at the middle of its range (the thesis's nominal planner).
* ``particles``: the particle belief-state transition of thesis §3.1.

New semantics register themselves with :func:`register`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action


class Semantics(Protocol):
    """What the planner needs from a transition semantics.

    A semantics may also set ``refuses_uncertain_contacts = True`` (read with ``getattr``,
    default False) when it cannot predict a push whose manipulator may or may not touch a part
    (CBST does so): the planner then also proposes pushes from manipulator positions that miss
    or wholly cover every part ahead (see :mod:`arrange_up.planning.actions`).
    """

    name: str
    particles: int
    simulations: int  # physics simulations run so far (the "transitions simulated" statistic)

    def initial_belief(self) -> Any: ...

    def apply(self, belief: Any, action: Action) -> Any | None: ...

    def close(self) -> None: ...


SemanticsFactory = Callable[..., Semantics]
_REGISTRY: dict[str, tuple[str, str]] = {
    "deterministic": ("arrange_up.transitions.particles", "DeterministicSemantics"),
    "particles": ("arrange_up.transitions.particles", "ParticleSemantics"),
    "cbst": ("arrange_up.transitions.cbst", "CBSTSemantics"),
}


def register(name: str, module: str, attribute: str) -> None:
    """Register a semantics class by import path (imported only when first used)."""
    _REGISTRY[name] = (module, attribute)


def available() -> tuple[str, ...]:
    """Names of the registered semantics."""
    return tuple(_REGISTRY)


def make_semantics(
    name: str,
    problem: ArrangementProblem,
    *,
    particles: int = 50,
    seed: int = 0,
    workers: int = 1,
) -> Semantics:
    """Instantiate the named semantics for ``problem``.

    Raises ``ValueError`` naming the registered semantics when ``name`` is unknown.
    """
    import importlib

    if name not in _REGISTRY:
        raise ValueError(f"unknown semantics {name!r}; expected one of {', '.join(_REGISTRY)}")
    module, attribute = _REGISTRY[name]
    factory = getattr(importlib.import_module(module), attribute)
    return factory(problem, particles=particles, seed=seed, workers=workers)
