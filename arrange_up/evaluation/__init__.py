"""Reliability: noisy open-loop rollouts of a plan (:mod:`~arrange_up.evaluation.rollouts`),
their outcomes (:mod:`~arrange_up.evaluation.outcomes`), the resumable record files
(:mod:`~arrange_up.evaluation.records`), a Wilson interval and the failure breakdown
(:mod:`~arrange_up.evaluation.reliability`), gathered by :func:`evaluate_plan`
(:mod:`~arrange_up.evaluation.evaluate`)."""

from arrange_up.evaluation import evaluate, outcomes, records, reliability, rollouts
from arrange_up.evaluation.evaluate import *  # noqa: F403
from arrange_up.evaluation.outcomes import *  # noqa: F403
from arrange_up.evaluation.records import *  # noqa: F403
from arrange_up.evaluation.reliability import *  # noqa: F403
from arrange_up.evaluation.rollouts import *  # noqa: F403

#: Every public name of the evaluation room's modules.
__all__ = [
    *outcomes.__all__,
    *reliability.__all__,
    *records.__all__,
    *rollouts.__all__,
    *evaluate.__all__,
]
