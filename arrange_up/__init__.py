"""arrange-up: conformant planning for robot tabletop manipulation.

Importing this package is cheap: heavy libraries (unified-planning, pymunk, matplotlib) are
imported only by the modules that need them. Importing it also registers arrange-up's engines
with unified-planning (:mod:`arrange_up.up.registration`, without importing unified-planning),
so ``OneshotPlanner(name="arrange-up")`` works in any program that has imported ``arrange_up``,
before or after unified-planning.

Entry points for library users::

    import arrange_up
    problem = arrange_up.load("blocks-4")          # a shipped name, a .yaml or a .pddl path
    result = arrange_up.plan(problem, semantics="particles", particles=50, seed=0)
    config = arrange_up.PlanConfig(particles=25, search=arrange_up.SearchConfig(max_nodes=500))
    result = arrange_up.plan(problem, config)       # the same options as one frozen value
    up_problem = arrange_up.to_up(problem)          # a unified_planning.model.Problem
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from arrange_up.up.registration import register as _register_up_engines

__version__ = "0.1.0"
__all__ = ["PlanConfig", "SearchConfig", "load", "plan", "to_up", "__version__"]

if TYPE_CHECKING:  # pragma: no cover
    from arrange_up.io.domains import load
    from arrange_up.planning.config import PlanConfig, SearchConfig
    from arrange_up.planning.planner import plan
    from arrange_up.up.compile import to_up

_LAZY = {
    "PlanConfig": ("arrange_up.planning.config", "PlanConfig"),
    "SearchConfig": ("arrange_up.planning.config", "SearchConfig"),
    "load": ("arrange_up.io.domains", "load"),
    "plan": ("arrange_up.planning.planner", "plan"),
    "to_up": ("arrange_up.up.compile", "to_up"),
}


def __getattr__(name: str) -> Any:
    # The public functions live in modules that import numpy or unified-planning (start-up
    # cost in docs/design/up.md); ``import arrange_up`` must stay cheap, so load them on first use.
    if name in _LAZY:
        module, attribute = _LAZY[name]
        value = getattr(importlib.import_module(module), attribute)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'arrange_up' has no attribute {name!r}")


_register_up_engines()
