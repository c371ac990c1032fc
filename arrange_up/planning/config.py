"""The configuration of a planning run, as one frozen value.

:class:`PlanConfig` gathers every choice :func:`arrange_up.planning.planner.plan` makes besides
the problem: the semantics and its particles, the seed, the learned model, the search
(:class:`SearchConfig`), where successors are computed (:class:`~arrange_up.parallel.RunnerConfig`)
and the validation rollouts. The command line, the unified-planning engine, the repair and the
experiments build one and pass it down; its checks are written here once, so a bad option fails
with the same message wherever it came from, before anything is built.

``PlanConfig.of(semantics="deterministic", max_nodes=100)`` builds one from the flat option
names :func:`~arrange_up.planning.planner.plan` also accepts as keywords.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from arrange_up.counts import check_count
from arrange_up.parallel import RunnerConfig
from arrange_up.planning.heuristics import check_heuristic
from arrange_up.planning.validation import check_validate
from arrange_up.transitions import available

#: Receives a planning run's statistics (``SearchSnapshot.to_json()`` of
#: :mod:`arrange_up.planning.planner`) every :data:`arrange_up.search.PROGRESS_INTERVAL` seconds.
ProgressCallback = Callable[[dict[str, Any]], None]

DEFAULT_MAX_NODES = 5000
"""The thesis's node limit (§3.3)."""
DEFAULT_WEIGHT = 2.0
"""Weighted A* by default: with the (already inadmissible) per-dimension count, A* spends most
of its nodes on plateaus of equal f, and weight 2 solves within the node limit problems A* does
not, for plans an action or two longer (figures in docs/design/planning.md). ``weight=1`` gives
the thesis's A*."""


@dataclass(frozen=True)
class SearchConfig:
    """How the belief space is searched.

    Fields:

    weight
        ``f = g + weight * h``; 1 is A*, the default 2 weighted A* (see :data:`DEFAULT_WEIGHT`).
    heuristic
        One of :data:`arrange_up.planning.heuristics.HEURISTICS` (default: the thesis's
        inadmissible per-dimension count with the part-ordering filter, its fastest
        configuration).
    dominance
        Prune beliefs dominated by an already reached belief (thesis §2.1.2, in its form: a
        dominated belief is pruned whatever its path cost), with a 0.01 in / 0.01 rad
        tolerance (see :class:`~arrange_up.belief.states.IntervalDominanceIndex`).
    max_nodes
        Limit on expanded nodes; None: the problem's ``planning.max_nodes`` or
        :data:`DEFAULT_MAX_NODES` (:meth:`node_limit`).
    timeout
        Wall-clock seconds for the whole run, validation included: the search returns status
        ``timeout`` when it runs out; a plan found before it is returned with the validation
        rollouts that fitted. None: no limit.
    deferred
        Deferred evaluation: a successor is simulated only when it is taken off the open list,
        not when generated. Most generated successors are never expanded, and simulating them
        is where the time goes.
    tie_break
        Break ties among equally good nodes at random from the seed (gives different but
        equally good plans for different seeds, e.g. for plan repair); default first-in
        first-out.
    agenda
        Search by the goal agenda first (:mod:`arrange_up.planning.agenda`): one part at a
        time from the belief the last one reached, then, where it fails, the whole goal in the
        node limit and time left. False: the whole goal's search alone.
    ordering_filter
        Let the heuristic's part-ordering filter cut beliefs as dead ends; a search it leaves
        with nothing to search runs again without it (``exhausted`` must mean the space was
        searched).
    variety
        Deliberate variety for nominal plans (plan repair, thesis ch. 4): every push the action
        generator proposes is, with probability
        :data:`~arrange_up.planning.task.VARIETY_SPLIT`, offered cut short to a random 40-80% of
        its distance instead of whole. The draws derive from the seed and the belief, so a run
        is reproducible, and different seeds search different action sets. Plans stay valid
        plans of the unchanged problem.
    """

    weight: float = DEFAULT_WEIGHT
    heuristic: str = "inadmissible"
    dominance: bool = True
    max_nodes: int | None = None
    timeout: float | None = None
    deferred: bool = True
    tie_break: bool = False
    variety: bool = False
    agenda: bool = True
    ordering_filter: bool = True

    def __post_init__(self) -> None:
        check_heuristic(self.heuristic)
        if self.max_nodes is not None:
            check_count("max_nodes", self.max_nodes, minimum=1)

    def node_limit(self, planning_max_nodes: int | None) -> int:
        """The node limit of a search: :attr:`max_nodes`, else the problem's own
        (``planning_max_nodes``), else :data:`DEFAULT_MAX_NODES`."""
        if self.max_nodes is not None:
            return self.max_nodes
        return planning_max_nodes or DEFAULT_MAX_NODES


@dataclass(frozen=True)
class PlanConfig:
    """Everything a planning run is configured by (see :func:`~arrange_up.planning.planner.plan`).

    Fields:

    semantics
        The belief transition, by name (see :mod:`arrange_up.transitions`).
    particles
        Particles per belief, for particle semantics (``deterministic`` always uses one).
    seed
        Makes the run reproducible: initial particles, per-particle noise and (with
        ``search.tie_break``) the order among equally good nodes all derive from it.
    model
        The learned model of a semantics that has one (``cbst``: a shipped name or the card
        of a model ``arrange-up train-cbst`` made); None: the shipped default.
    validate
        Rollouts that check a found plan on fresh initial states and noise
        (:mod:`arrange_up.planning.validation`); None: the semantics' default
        (:func:`~arrange_up.planning.validation.default_validation`); 0 turns it off.
    search
        How the belief space is searched.
    runner
        Where successor beliefs (and validation rollouts) are computed. A semantics that
        simulates no pushes (``cbst``) computes them in this process whatever it says.
    """

    semantics: str = "particles"
    particles: int = 50
    seed: int = 0
    model: str | Path | None = None
    validate: int | None = None
    search: SearchConfig = field(default_factory=SearchConfig)
    runner: RunnerConfig = field(default_factory=RunnerConfig)

    def __post_init__(self) -> None:
        if self.semantics not in available():
            raise ValueError(
                f"unknown semantics {self.semantics!r}; expected one of {', '.join(available())}"
            )
        check_count("particles", self.particles, minimum=1)
        check_count("seed", self.seed, minimum=0)
        check_validate(self.validate)
        if self.model is not None and not isinstance(self.model, str | Path):
            raise ValueError(
                f"model must be a shipped model name or a card path, got {self.model!r}"
            )

    @classmethod
    def of(cls, base: PlanConfig | None = None, **options: Any) -> PlanConfig:
        """``base`` (default: the defaults) with the flat ``options`` replaced: the names of
        this class's own fields, of :class:`SearchConfig`'s and of
        :class:`~arrange_up.parallel.RunnerConfig`'s. ``TypeError`` for any other name."""
        base = cls() if base is None else base
        own, search, runner = {}, {}, {}
        for name, value in options.items():
            if name in _OWN:
                own[name] = value
            elif name in _SEARCH:
                search[name] = value
            elif name in _RUNNER:
                runner[name] = value
            else:
                raise TypeError(f"unknown planning option {name!r}")
        if search:
            own["search"] = dataclasses.replace(base.search, **search)
        if runner:
            own["runner"] = dataclasses.replace(base.runner, **runner)
        return dataclasses.replace(base, **own) if own else base


_OWN = frozenset(f.name for f in dataclasses.fields(PlanConfig)) - {"search", "runner"}
_SEARCH = frozenset(f.name for f in dataclasses.fields(SearchConfig))
_RUNNER = frozenset(f.name for f in dataclasses.fields(RunnerConfig))
