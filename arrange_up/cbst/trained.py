"""A fitted CBST model as planning uses it (thesis §3.2): the trees as a
:class:`~arrange_up.cbst.fast_forest.FastForest` and the residual pairs, predicting without
scikit-learn. Training (:mod:`arrange_up.cbst.model`) fits a
:class:`~arrange_up.cbst.estimator.CBSTRegressor`, which predicts with the same
:func:`predict_rows`; :mod:`arrange_up.cbst.store` writes and reads models.
"""

from __future__ import annotations

import numpy as np

from arrange_up.cbst.fast_forest import FastForest

__all__ = ["TrainedModel", "check_residual", "predict_rows"]


def check_residual(residual, n_features: int, n_outputs: int) -> tuple[tuple[int, int], ...]:
    """``residual``'s ``(output, feature)`` pairs as ints; ``ValueError`` for one out of range."""
    pairs = tuple((int(o), int(f)) for o, f in (residual or ()))
    for o, f in pairs:
        if not (0 <= o < n_outputs and 0 <= f < n_features):
            raise ValueError(
                f"residual pair {(o, f)} out of range for {n_outputs} outputs and "
                f"{n_features} features"
            )
    return pairs


def predict_rows(
    forest: FastForest, residual: tuple[tuple[int, int], ...], X: np.ndarray
) -> np.ndarray:
    """The forest's predictions for trusted float rows ``X`` of the right width, with each
    residual pair's feature added back to its output; always ``(rows, outputs)``."""
    out = forest.predict(X)
    for o, f in residual:
        out[:, o] += X[:, f]
    return out


class TrainedModel:
    """A fitted CBST model as :func:`load_model` reads it: the trees as a :class:`FastForest`
    (``forest_``) and the residual pairs (``residual_``, see
    :class:`~arrange_up.cbst.estimator.CBSTRegressor`), predicting without scikit-learn
    (importing it would cost every planning run about a second). :func:`load_model` attaches
    ``card_``, ``card_path_`` and ``domain_``.
    """

    def __init__(self, forest: FastForest, residual=None) -> None:
        self.forest_ = forest
        self.residual_ = check_residual(residual, forest.n_features, forest.n_outputs)
        self.n_features_in_ = forest.n_features
        self.n_outputs_ = forest.n_outputs

    def predict(self, X) -> np.ndarray:
        """``(rows, outputs)`` predictions of the rows ``X``; ``ValueError`` unless ``X`` is
        a finite 2-D array of ``n_features_in_`` columns."""
        X = np.asarray(X, dtype=np.float64)
        if X.ndim != 2 or X.shape[1] != self.n_features_in_ or not np.isfinite(X).all():
            raise ValueError(
                f"expected finite rows of {self.n_features_in_} features, got shape {X.shape}"
            )
        return self.predict_rows(X)

    def predict_rows(self, X: np.ndarray) -> np.ndarray:
        """:meth:`predict` without input validation (the semantics' hot path)."""
        return predict_rows(self.forest_, self.residual_, X)
