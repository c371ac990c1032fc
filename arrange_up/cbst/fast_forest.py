"""A random forest as flat numpy arrays, evaluated for all trees at once.

scikit-learn's ``RandomForestRegressor.predict`` costs milliseconds per call whatever the
batch size (it dispatches one job per tree), and the planner asks for a handful of rows
thousands of times. :class:`FastForest` copies the fitted trees' arrays (children, split
feature, threshold, leaf values) into single concatenated arrays and walks every
(row, tree) pair down one level per numpy step, so a call costs tens of microseconds.

Exactness: scikit-learn casts inputs to float32 before comparing them with the (float64)
thresholds; so does :meth:`FastForest.predict`, so both take the same path in every tree and
the predictions agree up to the order of summation (~1e-15).

Leaves point to themselves (threshold ``+inf``: "go left" = stay), so the walk needs no
branches and simply runs ``depth`` steps.

Storage: :meth:`arrays` / :meth:`from_arrays` give plain numeric arrays for ``numpy.savez``
(read back with ``allow_pickle=False``): a model file can never run code when loaded.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

__all__ = ["FastForest"]

_ARRAY_NAMES = ("left", "right", "feature", "threshold", "value", "roots")


class FastForest:
    """An ensemble of regression trees, averaged (a random forest's prediction)."""

    def __init__(
        self,
        left: np.ndarray,
        right: np.ndarray,
        feature: np.ndarray,
        threshold: np.ndarray,
        value: np.ndarray,
        roots: np.ndarray,
        depth: int,
        n_features: int,
    ) -> None:
        self.left = np.ascontiguousarray(left, dtype=np.int64)
        self.right = np.ascontiguousarray(right, dtype=np.int64)
        self.feature = np.ascontiguousarray(feature, dtype=np.int64)
        self.threshold = np.ascontiguousarray(threshold, dtype=np.float64)
        self.value = np.ascontiguousarray(value, dtype=np.float64)
        self.roots = np.ascontiguousarray(roots, dtype=np.int64)
        self.depth = int(depth)
        self.n_features = int(n_features)
        n = len(self.left)
        if not (
            len(self.right) == len(self.feature) == len(self.threshold) == len(self.value) == n
        ):
            raise ValueError("forest arrays must all have one entry per node")
        if self.value.ndim != 2:
            raise ValueError("value must be (nodes, outputs)")
        for name in ("left", "right", "roots"):
            arr = getattr(self, name)
            if arr.size and (arr.min() < 0 or arr.max() >= n):
                raise ValueError(f"{name} points outside the node arrays")
        if self.feature.size and (self.feature.min() < 0 or self.feature.max() >= self.n_features):
            raise ValueError("feature indices outside the feature range")

    # -- construction ------------------------------------------------------------------------
    @classmethod
    def from_sklearn(cls, forest) -> FastForest:
        """Copy a fitted ``RandomForestRegressor`` (or any fitted ensemble of sklearn regression
        trees exposing ``estimators_`` and averaging them)."""
        lefts, rights, feats, thrs, vals, roots = [], [], [], [], [], []
        offset = 0
        depth = 0
        for est in forest.estimators_:
            tree = est.tree_
            n = tree.node_count
            left = tree.children_left.astype(np.int64)
            right = tree.children_right.astype(np.int64)
            leaf = left < 0
            idx = np.arange(n, dtype=np.int64)
            left = np.where(leaf, idx, left) + offset
            right = np.where(leaf, idx, right) + offset
            feat = np.where(leaf, 0, tree.feature).astype(np.int64)
            thr = np.where(leaf, np.inf, tree.threshold).astype(np.float64)
            val = tree.value[:, :, 0].astype(np.float64)  # (nodes, outputs)
            lefts.append(left)
            rights.append(right)
            feats.append(feat)
            thrs.append(thr)
            vals.append(val)
            roots.append(offset)
            offset += n
            depth = max(depth, int(tree.max_depth))
        return cls(
            np.concatenate(lefts),
            np.concatenate(rights),
            np.concatenate(feats),
            np.concatenate(thrs),
            np.concatenate(vals),
            np.asarray(roots),
            depth,
            int(forest.n_features_in_),
        )

    # -- properties --------------------------------------------------------------------------
    @property
    def n_trees(self) -> int:
        return len(self.roots)

    @property
    def n_nodes(self) -> int:
        return len(self.left)

    @property
    def n_outputs(self) -> int:
        return self.value.shape[1]

    # -- evaluation --------------------------------------------------------------------------
    def leaves(self, X: np.ndarray) -> np.ndarray:
        """The leaf reached in every tree by every row: ``(rows, trees)`` node indices."""
        X = np.asarray(X, dtype=np.float64)
        if X.ndim != 2 or X.shape[1] != self.n_features:
            raise ValueError(f"expected rows of {self.n_features} features, got shape {X.shape}")
        # Compare as scikit-learn does: inputs rounded to float32 first.
        flat = X.astype(np.float32).astype(np.float64).ravel()
        base = (np.arange(len(X), dtype=np.int64) * self.n_features)[:, None]
        node = np.broadcast_to(self.roots, (len(X), self.n_trees)).copy()
        left, right, feature, threshold = self.left, self.right, self.feature, self.threshold
        for _ in range(self.depth):
            go_left = flat[base + feature[node]] <= threshold[node]
            node = np.where(go_left, left[node], right[node])
        return node

    def predict(self, X: np.ndarray) -> np.ndarray:
        """Average of the trees' predictions: ``(rows, outputs)``."""
        node = self.leaves(X)
        return self.value[node].sum(axis=1) / self.n_trees

    # -- storage -----------------------------------------------------------------------------
    def arrays(self) -> dict[str, np.ndarray]:
        """Plain numeric arrays (compact dtypes) for ``numpy.savez_compressed``."""
        index = np.int32 if self.n_nodes < 2**31 else np.int64
        return {
            "left": self.left.astype(index),
            "right": self.right.astype(index),
            "feature": self.feature.astype(np.int16),
            "threshold": self.threshold,
            "value": self.value,
            "roots": self.roots.astype(index),
            "meta": np.array([self.depth, self.n_features], dtype=np.int64),
        }

    @classmethod
    def from_arrays(cls, arrays: Mapping[str, np.ndarray]) -> FastForest:
        missing = [name for name in (*_ARRAY_NAMES, "meta") if name not in arrays]
        if missing:
            raise ValueError(f"forest arrays missing: {', '.join(missing)}")
        meta = np.asarray(arrays["meta"])
        return cls(
            *(np.asarray(arrays[name]) for name in _ARRAY_NAMES),
            depth=int(meta[0]),
            n_features=int(meta[1]),
        )
