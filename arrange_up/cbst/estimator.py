"""The learned PREDICT of CBST as a scikit-learn estimator: :class:`CBSTRegressor`, which
training and tuning (:mod:`arrange_up.cbst.model`) fit. A stored model is read back without
scikit-learn, as a :class:`~arrange_up.cbst.trained.TrainedModel`.

* :class:`CBSTRegressor` is a scikit-learn estimator (hyperparameters only in ``__init__``,
  ``fit`` validates and returns ``self``, learned state ends in ``_``) wrapping a
  ``RandomForestRegressor``. After ``fit`` it predicts through a :class:`FastForest` copy of
  the trees, which gives the same numbers as the forest (to ~1e-15) many times faster.
"""

from __future__ import annotations

import numpy as np
from sklearn.base import BaseEstimator, MultiOutputMixin, RegressorMixin
from sklearn.utils.validation import check_is_fitted, validate_data

from arrange_up.cbst.fast_forest import FastForest
from arrange_up.cbst.trained import check_residual, predict_rows

__all__ = ["CBSTRegressor"]


class CBSTRegressor(MultiOutputMixin, RegressorMixin, BaseEstimator):
    """Multi-output random-forest regressor with a fast flat-array predictor.

    Parameters are those of :class:`sklearn.ensemble.RandomForestRegressor` that the grid
    search tunes or that make a fit reproducible, plus ``residual``: pairs
    ``(output, feature)`` for which the forest learns ``y[:, output] - X[:, feature]`` and
    ``predict`` adds the feature back. The uncertainty across a push is mostly the prior
    uncertainty carried over plus a drift (``dy ≈ dy_c + drift``), a linear carry-over that
    a forest reproduces poorly near the edge of the data; learning the drift removes that
    bias without changing the targets.

    Attributes
    ----------
    forest_ : FastForest
        The fitted trees as flat arrays; ``predict`` uses it.
    estimator_ : RandomForestRegressor
        The fitted forest.
    n_features_in_ : int
    n_outputs_ : int
    """

    def __init__(
        self,
        n_estimators: int = 100,
        max_depth: int | None = None,
        min_samples_leaf: int = 1,
        max_features: float | str | None = 1.0,
        bootstrap: bool = True,
        residual: tuple[tuple[int, int], ...] | None = None,
        random_state: int | None = None,
        n_jobs: int | None = None,
    ) -> None:
        self.n_estimators = n_estimators
        self.max_depth = max_depth
        self.min_samples_leaf = min_samples_leaf
        self.max_features = max_features
        self.bootstrap = bootstrap
        self.residual = residual
        self.random_state = random_state
        self.n_jobs = n_jobs

    def fit(self, X, y) -> CBSTRegressor:
        from sklearn.ensemble import RandomForestRegressor

        X, y = validate_data(self, X, y, multi_output=True, y_numeric=True)
        y = np.array(y, dtype=np.float64)
        self._single_output = y.ndim == 1
        self.residual_ = check_residual(self.residual, X.shape[1], 1 if y.ndim == 1 else y.shape[1])
        if self.residual_:
            y = y.reshape(len(y), -1)
            for out, feat in self.residual_:
                y[:, out] -= X[:, feat]
            if self._single_output:
                y = y[:, 0]
        forest = RandomForestRegressor(
            n_estimators=self.n_estimators,
            max_depth=self.max_depth,
            min_samples_leaf=self.min_samples_leaf,
            max_features=self.max_features,
            bootstrap=self.bootstrap,
            random_state=self.random_state,
            n_jobs=self.n_jobs,
        )
        forest.fit(X, y)
        self.estimator_ = forest
        self.forest_ = FastForest.from_sklearn(forest)
        self.n_outputs_ = 1 if self._single_output else y.shape[1]
        return self

    def predict(self, X) -> np.ndarray:
        check_is_fitted(self, "forest_")
        X = validate_data(self, X, reset=False)
        out = self.predict_rows(X)
        return out[:, 0] if self._single_output else out

    def predict_rows(self, X: np.ndarray) -> np.ndarray:
        """``predict`` without input validation, for trusted float arrays of the right width;
        always ``(rows, outputs)``."""
        return predict_rows(self.forest_, self.residual_, X)

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.target_tags.multi_output = True
        tags.target_tags.single_output = True
        return tags
