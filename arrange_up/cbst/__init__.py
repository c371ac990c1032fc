"""CBST: composable learned belief-state transitions with contact graphs (thesis §3.2).

* :mod:`~arrange_up.cbst.frame`: the canonical "push toward +u" frame (one implementation for
  the four axis directions).
* :mod:`~arrange_up.cbst.contact_graph`: MAKECG, maximal paths and the predictability rules.
* :mod:`~arrange_up.cbst.features`: PREDICT's features, targets and validity domain.
* :mod:`~arrange_up.cbst.data`: the seeded, parallel, resumable training-data generator.
* :mod:`~arrange_up.cbst.fast_forest`: a random forest as flat arrays, evaluated vectorised.
* :mod:`~arrange_up.cbst.trained`: a fitted model as planning uses it
  (:class:`~arrange_up.cbst.trained.TrainedModel`), predicting without scikit-learn.
* :mod:`~arrange_up.cbst.store`: the shipped models, :func:`load_model` and
  :func:`~arrange_up.cbst.store.save_model` (the arrays and the model card).
* :mod:`~arrange_up.cbst.model`: tuning, cross-validation and :func:`train_cbst`.
* :mod:`~arrange_up.cbst.estimator`: :class:`CBSTRegressor`, the scikit-learn estimator that
  training fits (imported on first use: planning never needs scikit-learn).
* :mod:`~arrange_up.cbst.choice`: which model a problem plans with (the one trained under its
  controller).

The semantics itself is :class:`arrange_up.transitions.cbst.CBSTSemantics`
(``plan(problem, semantics="cbst")``); see ``docs/cbst.md``.
"""

from typing import Any

from arrange_up.cbst.data import generate_dataset
from arrange_up.cbst.model import train_cbst
from arrange_up.cbst.store import load_model

__all__ = ["CBSTRegressor", "generate_dataset", "load_model", "train_cbst"]


def __getattr__(name: str) -> Any:
    # The estimator imports scikit-learn (about a second): only for those who use it.
    if name == "CBSTRegressor":
        from arrange_up.cbst.estimator import CBSTRegressor

        return CBSTRegressor
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
