"""Registration of arrange-up's engines with unified-planning, without importing unified-planning.

unified-planning (1.3) has no entry points: its factory knows an engine from the module-level
table ``DEFAULT_ENGINES`` (name -> module and class names), read when a factory is made, or from
``Factory.add_engine(name, module, class)`` on a factory that exists; either way the factory
imports the module and takes the class from it. arrange-up's engine classes are defined in
:mod:`arrange_up.up.planner_engine`, :mod:`~arrange_up.up.validator_engine` and
:mod:`~arrange_up.up.repairer_engine`, which import unified-planning; this module only names them
(:data:`ENGINES`) and, through :func:`register`, tells unified-planning where they are.

``import arrange_up`` calls :func:`register`. That must not import unified-planning, whose
start-up cost dwarfs the rest of ``import arrange_up`` (figures and the commands that measure
them: ``docs/design/up.md``), so when unified-planning has not loaded its factory yet,
registration waits for it with an import hook. That hook is the one piece of import-system
machinery in the package, and it lives here.

Programs that never import ``arrange_up``, such as unified-planning's own ``up`` command, can
find the engines only through a unified-planning configuration file: :func:`up_ini` gives its
sections, and ``python -m arrange_up.up`` prints or installs them (:mod:`arrange_up.up.__main__`).
"""

from __future__ import annotations

import sys
from typing import Any

__all__ = [
    "ENGINES",
    "ENGINE_CLASS",
    "ENGINE_MODULE",
    "ENGINE_NAME",
    "REPAIRER_CLASS",
    "REPAIRER_MODULE",
    "REPAIRER_NAME",
    "VALIDATOR_CLASS",
    "VALIDATOR_MODULE",
    "VALIDATOR_NAME",
    "register",
    "up_ini",
]

# Each engine's name in unified-planning's factory, and the module (one per engine; each imports
# unified-planning) and class that define it.
ENGINE_NAME = "arrange-up"
ENGINE_MODULE = "arrange_up.up.planner_engine"
ENGINE_CLASS = "ArrangeUpPlanner"
VALIDATOR_NAME = "arrange-up-reliability"
VALIDATOR_MODULE = "arrange_up.up.validator_engine"
VALIDATOR_CLASS = "ArrangeUpReliability"
REPAIRER_NAME = "arrange-up-fixtures"
REPAIRER_MODULE = "arrange_up.up.repairer_engine"
REPAIRER_CLASS = "ArrangeUpFixtureRepairer"
#: Every engine the package registers: (name in unified-planning's factory, module, class).
ENGINES: tuple[tuple[str, str, str], ...] = (
    (ENGINE_NAME, ENGINE_MODULE, ENGINE_CLASS),
    (VALIDATOR_NAME, VALIDATOR_MODULE, VALIDATOR_CLASS),
    (REPAIRER_NAME, REPAIRER_MODULE, REPAIRER_CLASS),
)

_FACTORY_MODULE = "unified_planning.engines.factory"
_ENVIRONMENT_MODULE = "unified_planning.environment"


def register(environment: Any = None) -> None:
    """Make arrange-up's engines (:data:`ENGINES`) known to unified-planning; idempotent, and
    never imports unified-planning.

    * unified-planning's factory module is loaded: the engines join its default engine table
      and preference list (so every environment made later has them) and the factory of
      ``environment``, or of unified-planning's global environment if that exists.
    * It is not (and no ``environment`` is given): an import hook is installed that adds the
      engines to the default table as soon as unified-planning has executed its factory module,
      before any factory exists, so the global environment has them from the start.
    """
    factory_module = sys.modules.get(_FACTORY_MODULE)
    if factory_module is None and environment is None:
        if not any(isinstance(finder, _FactoryHook) for finder in sys.meta_path):
            sys.meta_path.insert(0, _FactoryHook())
        return
    if factory_module is not None:
        _add_to_defaults(factory_module)
    if environment is None:
        environment = getattr(sys.modules.get(_ENVIRONMENT_MODULE), "GLOBAL_ENVIRONMENT", None)
    if environment is not None:
        for name, module_name, class_name in ENGINES:
            if name not in environment.factory.engines:
                environment.factory.add_engine(name, module_name, class_name)


def up_ini() -> str:
    """The ``[engine NAME]`` sections of a unified-planning configuration file (``up.ini``) that
    name arrange-up's engines (:data:`ENGINES`), for programs that never import ``arrange_up``.

    unified-planning 1.3 reads such a file from every parent directory of the running script
    (``up.ini`` or ``.up.ini``) and from the home directory (``~/up.ini``, ``~/.up.ini``,
    ``~/.uprc``), whenever it makes a factory; every section makes the factory import the
    engine's module, so a file naming arrange-up breaks unified-planning wherever ``arrange_up``
    is not installed."""
    lines = [
        "# arrange-up's unified-planning engines (python -m arrange_up.up prints these lines)",
    ]
    for name, module_name, class_name in ENGINES:
        lines += [
            "",
            f"[engine {name}]",
            f"module_name: {module_name}",
            f"class_name: {class_name}",
        ]
    return "\n".join(lines) + "\n"


def _add_to_defaults(factory_module: Any) -> None:
    """Add the engines to the default tables of unified-planning's factory module, which every
    new ``Factory`` reads (importing the engines' modules then)."""
    defaults = getattr(factory_module, "DEFAULT_ENGINES", None)
    preference = getattr(factory_module, "DEFAULT_ENGINES_PREFERENCE_LIST", None)
    for name, module_name, class_name in ENGINES:
        if isinstance(defaults, dict):
            defaults.setdefault(name, (module_name, class_name))
        if isinstance(preference, list) and name not in preference:
            preference.append(name)


class _FactoryHook:
    """A meta path finder that finds nothing itself: for unified-planning's factory module it
    asks the other finders for the spec and wraps its loader, so that :func:`_add_to_defaults`
    runs right after the module is executed; then it removes itself.

    It implements the finder and loader protocols directly instead of deriving from
    ``importlib.abc``, whose import would cost more than the rest of ``import arrange_up``
    (``docs/design/up.md``)."""

    def find_spec(self, fullname: str, path: Any, target: Any = None) -> Any:
        if fullname != _FACTORY_MODULE:
            return None
        for finder in sys.meta_path:
            if finder is self or not hasattr(finder, "find_spec"):
                continue
            spec = finder.find_spec(fullname, path, target)
            if spec is not None:
                break
        else:
            return None
        if spec.loader is not None and hasattr(spec.loader, "exec_module"):
            spec.loader = _PatchingLoader(spec.loader, self)
        return spec


class _PatchingLoader:
    """The loader of unified-planning's factory module, followed by :func:`_add_to_defaults`."""

    def __init__(self, loader: Any, hook: _FactoryHook) -> None:
        self._loader = loader
        self._hook = hook

    def create_module(self, spec: Any) -> Any:
        return self._loader.create_module(spec)

    def exec_module(self, module: Any) -> None:
        self._loader.exec_module(module)
        if self._hook in sys.meta_path:
            sys.meta_path.remove(self._hook)
        _add_to_defaults(module)

    def __getattr__(self, name: str) -> Any:  # get_source, get_filename, ... of the real loader
        return getattr(self._loader, name)
