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

import importlib
import inspect
from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol

from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action


class Semantics(Protocol):
    """What the planner needs from a transition semantics.

    Attributes
    ----------
    name
        The name the semantics is registered under.
    particles
        Particles per belief it actually uses.
    simulations
        Physics simulations (or model predictions) run so far: the "transitions simulated"
        statistic.
    refuses_uncertain_contacts
        True when the semantics cannot predict a push whose manipulator may or may not touch a
        part (CBST): the planner then also proposes pushes from manipulator positions that
        miss or wholly cover every part ahead (see :mod:`arrange_up.planning.actions`). False
        for a semantics that predicts every push (``particles``, ``deterministic``); a class
        that subclasses this protocol inherits False.
    simulates_pushes
        True when a push's outcome is simulated in the physics (``particles``,
        ``deterministic``): pressing parts already at their goal into a wall again then gives
        a new, slightly perturbed belief each time under the compliant controller, so the
        planner does not propose it. False for a learned prediction (CBST), which is a function
        of the belief (a repeat is a duplicate) and which needs such pushes to narrow intervals
        until later contacts are certain. A class that subclasses this protocol inherits True.
    place_rings
        True when the planner may place a part on rings farther out where its place grid has
        none clear, a push then bringing it in (:mod:`arrange_up.planning.generators.places`).
        False for CBST with a simulated fallback: its boxes, rebuilt from a few simulations,
        do not hold the spread of the longer pushes a ring's place needs (docs/cbst.md). A
        class that subclasses this protocol inherits True.

    A semantics may also say why it refused transitions: ``reasons``, a
    :class:`collections.Counter` of short human-readable sentences, one count per ``None``
    that :meth:`apply` returned (CBST's "the push is not axis-aligned", the particle
    semantics' "a push left A off the table", ...). The planner adds up the reasons counted
    while computing the children the search asked for, in this process or in a worker
    (:mod:`arrange_up.planning.successors`), and names the most frequent when a search ends
    unsolved (:attr:`arrange_up.planning.planner.PlanResult.refusals`). It is optional: without
    it the planner says only that the semantics gave no prediction.
    """

    name: str
    particles: int
    simulations: int
    refuses_uncertain_contacts: bool = False
    simulates_pushes: bool = True
    place_rings: bool = True

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
    """Register a semantics class by import path.

    The module is imported only when the semantics is first made, so naming a semantics costs
    nothing until it is used (``cbst`` needs scikit-learn, ``particles`` pymunk).
    """
    _REGISTRY[name] = (module, attribute)


def available() -> tuple[str, ...]:
    """Names of the registered semantics."""
    return tuple(_REGISTRY)


def _factory(name: str) -> Callable[..., Semantics]:
    """The registered class (or factory) of the named semantics; ``ValueError`` naming the
    registered ones when ``name`` is unknown."""
    if name not in _REGISTRY:
        raise ValueError(f"unknown semantics {name!r}; expected one of {', '.join(_REGISTRY)}")
    module, attribute = _REGISTRY[name]
    return getattr(importlib.import_module(module), attribute)


def simulates_pushes(name: str) -> bool:
    """Whether the named semantics simulates pushes (and so plans with the runner's workers),
    read from its class without instantiating it. ``ValueError`` for an unknown name."""
    return bool(_factory(name).simulates_pushes)  # type: ignore[attr-defined]


def make_semantics(
    name: str,
    problem: ArrangementProblem,
    *,
    particles: int = 50,
    seed: int = 0,
    workers: int = 1,
    model: str | Path | None = None,
) -> Semantics:
    """Instantiate the named semantics for ``problem``.

    ``model`` selects the learned model of a semantics that has one (``cbst``: a shipped name
    or a model card's path, see :func:`arrange_up.cbst.store.load_model`); ``None`` leaves the
    semantics' default.

    Raises ``ValueError`` naming the registered semantics when ``name`` is unknown, and when a
    ``model`` is given to a semantics without one.
    """
    factory = _factory(name)
    if model is None:
        return factory(problem, particles=particles, seed=seed, workers=workers)
    if "model" not in inspect.signature(factory).parameters:
        raise ValueError(
            f"the {name} semantics has no learned model to select (a model, such as one "
            "train-cbst makes, is for the cbst semantics)"
        )
    return factory(problem, particles=particles, seed=seed, workers=workers, model=model)
