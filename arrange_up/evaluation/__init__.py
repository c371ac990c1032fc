"""Reliability: noisy open-loop rollouts of a plan (:mod:`~arrange_up.evaluation.rollouts`),
their outcomes (:mod:`~arrange_up.evaluation.outcomes`), the resumable record files
(:mod:`~arrange_up.evaluation.records`), a Wilson interval and the failure breakdown
(:mod:`~arrange_up.evaluation.reliability`), gathered by :func:`evaluate_plan`
(:mod:`~arrange_up.evaluation.evaluate`)."""

from arrange_up.evaluation.evaluate import *  # noqa: F403  (every public name of the evaluation)
