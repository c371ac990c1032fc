"""Checking a found plan on fresh rollouts, and planning again from the starts it failed on.

A plan the particle search finds is conformant for its particles only: every particle, with
the noise drawn for it, reaches the goal. How far that carries to the problem's whole
uncertainty depends on how well ``P`` particles show it. :func:`validate_plan` measures it the
way evaluation does, on rollouts the search never saw: each draws a fresh initial state from the
problem's initial intervals and fresh noise for every action, and is judged by the evaluation's
rules (:mod:`arrange_up.evaluation.rollouts`). The initial states of the rollouts that failed
are *counterexamples*: :func:`arrange_up.planning.planner.plan` adds them to the search's
initial belief as further particles and searches again, a few rounds at most, so the next plan
must also bring those starts (with noise drawn anew for them) to the goal.

A CBST plan is checked the same way, by default too: its interval beliefs come from learned
predictions and a grazing rule, which are not bounds (docs/cbst.md, "How far the predictions
hold"), so only rollouts say how it does. It has no particles to add counterexamples to, so
its validation is the one round, reported. A deterministic plan (a nominal plan, not a
conformant one) is checked only when asked, in one round as well.

The validation rollouts are an evaluation with a seed of their own, derived from the planning
seed and the round (:func:`validation_seed`), never a small integer: an evaluation a user runs
(seed 0 by default) does not meet the starts the planner was shown, so its figure stays a
fresh test set.

A planning run's time limit holds while it validates: the rollouts stop when it comes, and the
round records how many ran (:attr:`ValidationRound.run`). A plan validated on fewer rollouts
than asked is still returned, with its line saying so; it is never presented as checked on
all of them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from arrange_up.belief.compiled import CompiledProblem
from arrange_up.counts import check_count
from arrange_up.evaluation.evaluate import MAX_ROLLOUTS, evaluate_plan
from arrange_up.evaluation.reliability import wilson_interval
from arrange_up.evaluation.rollouts import rollout_start
from arrange_up.model.world import Action, WorldState
from arrange_up.parallel import SERIAL, RunnerConfig

__all__ = [
    "MIN_VALIDATION_ROLLOUTS",
    "VALIDATION_REPLANS",
    "Validation",
    "ValidationRound",
    "check_validate",
    "choose_round",
    "default_validation",
    "default_validation_rollouts",
    "validate_plan",
    "validation_seed",
    "research_budget",
]

#: Searches after the first that validation may start. Measured on the fresh problems
#: (docs/design/planning-validation.md, "Validated plans"): the rounds that helped needed one
#: or two.
VALIDATION_REPLANS = 3

#: A search after the first may expand at most this many times the nodes the first expanded
#: (at least :data:`MIN_RESEARCH_NODES`, at most the run's node limit): it refines a plan in
#: hand with more particles, so it must not cost what finding a first plan from nothing may;
#: docs/design/agenda.md gives the measurements behind both values.
RESEARCH_NODE_FACTOR = 10
#: The fewest nodes a search after the first may expand.
MIN_RESEARCH_NODES = 1000


def research_budget(first_expanded: int, node_limit: int) -> int:
    """The node limit of a search after the first, whose first search expanded
    ``first_expanded`` nodes in a run limited to ``node_limit``."""
    return min(node_limit, max(MIN_RESEARCH_NODES, RESEARCH_NODE_FACTOR * first_expanded))


#: ``SeedSequence`` key of the validation stream, apart from the planner's other draws.
_VALIDATION_KEY = 0x5A11D


#: The fewest validation rollouts by default: the fewest that a plan failing one rollout in
#: twenty (below the 95 % reliability is judged by) passes with probability under 0.05
#: (0.95 ** 59 = 0.048); 60 rollouts pass it with probability 0.046.
MIN_VALIDATION_ROLLOUTS = 60


def default_validation_rollouts(particles: int) -> int:
    """The validation rollouts for a search of ``particles`` particles when none are asked for:
    twice the particles, so that a user who buys a larger belief also buys a sharper check, and
    at least :data:`MIN_VALIDATION_ROLLOUTS`."""
    return max(2 * particles, MIN_VALIDATION_ROLLOUTS)


def default_validation(semantics: str, particles: int, start: Any = None) -> int:
    """The validation rollouts of a planning run that asks for none: for the conformant
    semantics planning from the problem's initial belief, :func:`default_validation_rollouts`
    of the particles searched (``particles``; CBST's interval belief counts as its two corner
    pseudo-particles), else 0 (the deterministic semantics' nominal plans, and plans from a
    ``start`` belief)."""
    if start is not None:
        return 0
    if semantics == "particles":
        return default_validation_rollouts(particles)
    if semantics == "cbst":
        return default_validation_rollouts(2)
    return 0


def research_on_failure(semantics: str) -> bool:
    """Whether a failed validation searches again with the failed starts as further particles:
    only the ``particles`` semantics has particles to add them to."""
    return semantics == "particles"


def check_validate(validate: Any, start: Any = None) -> None:
    """``ValueError`` unless ``validate`` suits a planning run (from a ``start`` belief when one
    is given): None (the default), or a non-negative integer that is positive only when
    planning from the problem's initial belief (the validation rollouts start from that belief,
    not from a posterior), at most :data:`~arrange_up.evaluation.evaluate.MAX_ROLLOUTS`. Every
    semantics' plan can be checked."""
    if validate is None:
        return
    check_count("validate", validate, minimum=0, maximum=MAX_ROLLOUTS)
    if validate and start is not None:
        raise ValueError(
            "validate checks plans from the problem's initial belief; a start belief takes none"
        )


def validation_seed(seed: int, round_: int) -> int:
    """The evaluation seed of validation round ``round_`` of a planning run with ``seed``: a
    63-bit integer drawn from ``SeedSequence([seed, key, round_])``."""
    state = np.random.SeedSequence([seed, _VALIDATION_KEY, round_]).generate_state(1, np.uint64)
    return int(state[0]) >> 1


@dataclass(frozen=True)
class ValidationRound:
    """One search of a validated planning run: the particles it searched with (the requested
    ones plus the counterexamples of the earlier rounds; None for a semantics without
    particles, which searches once), its status and expanded nodes, and,
    for a found plan, how many validation rollouts ran on it (``run``: all the run asked for
    unless the time limit or a stop came first) and how many of those succeeded
    (``successes``); both ``None`` without a plan."""

    particles: int | None
    status: str
    expanded: int
    successes: int | None
    run: int | None = None

    def to_json(self) -> dict[str, Any]:
        return {
            "particles": self.particles,
            "status": str(self.status),
            "expanded": self.expanded,
            "run": self.run,
            "successes": self.successes,
        }


def choose_round(rounds: tuple[ValidationRound, ...]) -> int:
    """The index of the round whose plan a validated run returns: among the rounds with a plan,
    the highest lower end of the 95 % Wilson interval of its successes on the rollouts run
    (so a round cut short after a few lucky rollouts does not beat one that ran them all),
    then the most rollouts run, then the later (it was searched with more particles). When
    every round ran its rollouts in full this is the most successes, the later on a tie."""
    planned = [i for i, r in enumerate(rounds) if r.successes is not None]

    def key(i: int) -> tuple[float, int, int]:
        run, successes = rounds[i].run or 0, rounds[i].successes or 0
        return (wilson_interval(successes, run)[0] if run else 0.0, run, i)

    return max(planned, key=key)


@dataclass(frozen=True)
class Validation:
    """The validation of a planning run: ``rollouts`` fresh rollouts asked for per found plan,
    the rounds in order, and ``chosen``, the index of the round whose plan was returned
    (:func:`choose_round`). ``stopped_by`` names what cut a round's rollouts short (``"the time
    limit"`` or ``"a stop request"``), ``None`` when none was."""

    rollouts: int
    rounds: tuple[ValidationRound, ...]
    chosen: int
    stopped_by: str | None = None

    @property
    def successes(self) -> int:
        """Validation successes of the returned plan."""
        successes = self.rounds[self.chosen].successes
        assert successes is not None  # a chosen round has a plan
        return successes

    @property
    def run(self) -> int:
        """Validation rollouts run on the returned plan (``rollouts`` unless the time limit or
        a stop came first)."""
        run = self.rounds[self.chosen].run
        assert run is not None  # a chosen round has a plan
        return run

    @property
    def complete(self) -> bool:
        """True iff the returned plan ran every validation rollout asked for."""
        return self.run == self.rollouts

    @property
    def passed(self) -> bool:
        """True iff the returned plan ran every validation rollout and succeeded in each."""
        return self.complete and self.successes == self.rollouts

    def line(self) -> str:
        """One line for the command line: what the returned plan did on fresh rollouts, and
        what the extra searches were."""
        chosen = self.rounds[self.chosen]
        if self.complete:
            text = f"validated on {self.rollouts} fresh rollouts: {self.successes} succeeded"
        elif self.run:
            text = (
                f"validated on {self.run} of {self.rollouts} fresh rollouts (stopped by "
                f"{self.stopped_by}): {self.successes} succeeded"
            )
        else:
            text = f"not validated: {self.stopped_by} came before any of {self.rollouts} rollouts"
        if chosen.particles is not None:
            text += (
                f" (plan of search {self.chosen + 1} of {len(self.rounds)}, "
                f"{chosen.particles} particles)"
            )
        if len(self.rounds) > 1:
            text += "; searches: " + ", ".join(
                f"{r.particles} particles {r.status}"
                + (f" {r.successes}/{r.run}" if r.successes is not None else "")
                for r in self.rounds
            )
        return text

    def to_json(self) -> dict[str, Any]:
        return {
            "rollouts": self.rollouts,
            "run": self.run,
            "successes": self.successes,
            "chosen": self.chosen,
            "rounds": [r.to_json() for r in self.rounds],
            **({"stopped_by": self.stopped_by} if self.stopped_by else {}),
        }


def validate_plan(
    compiled: CompiledProblem,
    actions: tuple[Action, ...],
    *,
    rollouts: int,
    seed: int,
    round_: int,
    runner: RunnerConfig = SERIAL,
    should_stop: Callable[[], bool] | None = None,
) -> tuple[int, int, tuple[WorldState, ...]]:
    """Run ``rollouts`` rollouts of ``actions`` in ``compiled.problem`` with
    :func:`validation_seed` ``(seed, round_)`` (on ``runner``, as
    :func:`~arrange_up.evaluation.evaluate.evaluate_plan` runs them), starting no more once
    ``should_stop()`` returns True; return how many ran, their successes, and the initial
    states of the failed ones, in rollout order."""
    vseed = validation_seed(seed, round_)
    problem = compiled.problem
    reliability = evaluate_plan(
        problem,
        actions,
        rollouts=rollouts,
        seed=vseed,
        runner=runner,
        keep_records=True,
        should_stop=should_stop,
    )
    assert reliability.records is not None  # asked for with keep_records
    failed = tuple(
        rollout_start(problem, vseed, record.index)
        for record in reliability.records
        if not record.success
    )
    return reliability.trials, reliability.successes, failed
