"""The learned PREDICT of CBST: a multi-output random forest (thesis §3.2).

* :class:`CBSTRegressor` is a scikit-learn estimator (hyperparameters only in ``__init__``,
  ``fit`` validates and returns ``self``, learned state ends in ``_``) wrapping a
  ``RandomForestRegressor``. After ``fit`` it predicts through a :class:`FastForest` copy of
  the trees, which gives the same numbers as the forest (to ~1e-15) many times faster.
* :func:`tune` is the thesis's procedure: hold out 10 % of the data, grid-search the
  hyperparameters with 8-fold cross-validation on the other 90 %, refit, and score on the
  held-out part. Rows of one example (the blocks of one belief) never straddle a split:
  the hold-out and the folds are made by example (``GroupShuffleSplit``/``GroupKFold``).
* :func:`save_model` writes ``NAME.npz`` (the trees' arrays, numbers only) and ``NAME.json``
  (the model card); :func:`load_model` reads them back with ``allow_pickle=False`` after
  checking the arrays' SHA-256 against the card. No model file is ever pickled.
* :func:`train_cbst` is the whole pipeline behind ``arrange-up train-cbst``: generate (or
  resume) the data, tune, evaluate, save.

Shipped models live in the repository's ``semantics/cbst/`` (an installed wheel carries it as
``arrange_up/_shipped/semantics/cbst``); ``load_model("default")`` finds either.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
import math
import time
from collections.abc import Callable, Mapping
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import sklearn
from sklearn.base import BaseEstimator, MultiOutputMixin, RegressorMixin
from sklearn.utils.validation import check_is_fitted, validate_data

from arrange_up import __version__
from arrange_up.cbst.data import DEFAULT_GENERATION, generate_dataset, load_dataset
from arrange_up.cbst.fast_forest import FastForest
from arrange_up.cbst.features import (
    BUCKLE_LIMIT,
    FEATURE_NAMES,
    TARGET_NAMES,
    TARGET_UNITS,
    THESIS_TEST_RMSE,
    Domain,
)
from arrange_up.io.resources import shipped_dir
from arrange_up.parallel import available_cores

__all__ = [
    "CARD_FORMAT",
    "DEFAULT_GRID",
    "DY_RESIDUAL",
    "CBSTRegressor",
    "load_model",
    "model_dir",
    "save_model",
    "train_cbst",
    "tune",
]

CARD_FORMAT = "arrange-up-cbst-model/1"

#: Output ``dy`` (1) learned as a residual over the feature ``dy_c`` (4): see
#: :class:`CBSTRegressor`'s ``residual``.
DY_RESIDUAL: tuple[tuple[int, int], ...] = ((1, 4),)

#: The hyperparameter grid searched by default (kept small: 2 cores, see the model card).
#: Leaves of 1, 3 and 6 samples lost to 12 and 24 in earlier searches on the shipped data;
#: beyond the grid, 96 and 192 lost to 48 (mean CV R^2 0.110 and 0.105 against 0.118).
DEFAULT_GRID: dict[str, list[Any]] = {
    "max_features": [1.0, 0.5],
    "min_samples_leaf": [12, 24, 48],
    "residual": [None, DY_RESIDUAL],
}

ProgressCallback = Callable[[str, int, int], None]


# ----------------------------------------------------------------------------------------------
# The estimator
# ----------------------------------------------------------------------------------------------
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
        The fitted forest (absent on a model read by :func:`load_model`).
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
        self.residual_ = self._check_residual(X.shape[1], 1 if y.ndim == 1 else y.shape[1])
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
        """``predict`` without input validation, for trusted float arrays of the right width
        (the semantics' hot path); always ``(rows, outputs)``."""
        out = self.forest_.predict(X)
        for o, f in self.residual_:
            out[:, o] += X[:, f]
        return out

    def _check_residual(self, n_features: int, n_outputs: int) -> tuple[tuple[int, int], ...]:
        pairs = tuple((int(o), int(f)) for o, f in (self.residual or ()))
        for o, f in pairs:
            if not (0 <= o < n_outputs and 0 <= f < n_features):
                raise ValueError(
                    f"residual pair {(o, f)} out of range for {n_outputs} outputs and "
                    f"{n_features} features"
                )
        return pairs

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.target_tags.multi_output = True
        tags.target_tags.single_output = True
        return tags

    # -- built from stored arrays ----------------------------------------------------------
    @classmethod
    def from_forest(
        cls, forest: FastForest, params: Mapping[str, Any] | None = None
    ) -> CBSTRegressor:
        """A fitted regressor around stored arrays (no ``estimator_``)."""
        kept = {k: v for k, v in (params or {}).items() if k in cls._param_names()}
        if kept.get("residual") is not None:  # JSON lists -> tuples
            kept["residual"] = tuple(tuple(int(v) for v in pair) for pair in kept["residual"])
        model = cls(**kept)
        model.residual_ = model._check_residual(forest.n_features, forest.n_outputs)
        model.forest_ = forest
        model.n_features_in_ = forest.n_features
        model.n_outputs_ = forest.n_outputs
        model._single_output = False
        return model

    @classmethod
    def _param_names(cls) -> list[str]:
        return cls._get_param_names()


# ----------------------------------------------------------------------------------------------
# The thesis's training procedure
# ----------------------------------------------------------------------------------------------
def _rmse(y_true: np.ndarray, y_pred: np.ndarray) -> dict[str, float]:
    err = np.sqrt(np.mean((np.asarray(y_true) - np.asarray(y_pred)) ** 2, axis=0))
    return {name: float(v) for name, v in zip(TARGET_NAMES, err, strict=True)}


def tune(
    X: np.ndarray,
    y: np.ndarray,
    groups: np.ndarray,
    *,
    param_grid: Mapping[str, list[Any]] | None = None,
    n_estimators: int = 100,
    cv: int = 8,
    test_fraction: float = 0.1,
    seed: int = 0,
    workers: int = 1,
) -> tuple[CBSTRegressor, dict[str, Any]]:
    """Grid search with ``cv``-fold CV on ``1 - test_fraction`` of the examples, refit on
    them, score on the held-out examples.

    Selection uses the mean R^2 over the three outputs (scale-free: the angle target is in
    degrees and would dominate a mean squared error). Returns the refitted model and a report
    with the best parameters, per-output CV RMSE (out-of-fold predictions of the best
    parameters) and test RMSE.
    """
    from joblib import parallel_config
    from sklearn.model_selection import (
        GridSearchCV,
        GroupKFold,
        GroupShuffleSplit,
        cross_val_predict,
    )

    grid = dict(param_grid or DEFAULT_GRID)
    split = GroupShuffleSplit(n_splits=1, test_size=test_fraction, random_state=seed)
    train_idx, test_idx = next(split.split(X, y, groups))
    X_train, y_train, g_train = X[train_idx], y[train_idx], groups[train_idx]
    X_test, y_test = X[test_idx], y[test_idx]
    base = CBSTRegressor(n_estimators=n_estimators, random_state=seed, n_jobs=1)
    folds = GroupKFold(n_splits=cv)
    search = GridSearchCV(base, grid, scoring="r2", cv=folds, n_jobs=workers, refit=True)
    started = time.monotonic()
    # Threads, not joblib's loky processes: the data generation leaves the process's shared
    # loky executor (arrange_up.parallel) running, and joblib.Parallel cannot take that one
    # over (AttributeError: _temp_folder_manager). Tree building releases the GIL.
    with parallel_config(backend="threading"):
        search.fit(X_train, y_train, groups=g_train)
        oof = cross_val_predict(
            CBSTRegressor(**search.best_estimator_.get_params()),
            X_train,
            y_train,
            groups=g_train,
            cv=folds,
            n_jobs=workers,
        )
    best: CBSTRegressor = search.best_estimator_
    report = {
        "best_params": {k: _jsonable(v) for k, v in search.best_params_.items()},
        "grid": {k: [_jsonable(v) for v in vs] for k, vs in grid.items()},
        "cv_folds": cv,
        "cv_r2": float(search.best_score_),
        "cv_rmse": _rmse(y_train, oof),
        "test_rmse": _rmse(y_test, best.predict(X_test)),
        "train_rows": int(len(train_idx)),
        "test_rows": int(len(test_idx)),
        "train_examples": int(len(np.unique(g_train))),
        "test_examples": int(len(np.unique(groups[test_idx]))),
        "search_seconds": time.monotonic() - started,
    }
    return best, report


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    return value


# ----------------------------------------------------------------------------------------------
# Storage
# ----------------------------------------------------------------------------------------------
def model_dir() -> Path:
    """The folder of shipped models: the wheel's ``_shipped/semantics/cbst`` if present, else
    the checkout's ``semantics/cbst``."""
    return shipped_dir("semantics/cbst", "CBST models")


def save_model(
    model: CBSTRegressor, card: Mapping[str, Any], directory: str | Path, name: str
) -> Path:
    """Write ``NAME.npz`` (arrays only) and ``NAME.json`` (the card, with the arrays'
    SHA-256 and size added) into ``directory``; returns the card's path."""
    check_is_fitted(model, "forest_")
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    arrays_path = directory / f"{name}.npz"
    np.savez_compressed(arrays_path, **model.forest_.arrays())
    digest = hashlib.sha256(arrays_path.read_bytes()).hexdigest()
    card = dict(card)
    card["format"] = CARD_FORMAT
    card["name"] = name
    card["arrays"] = {
        "file": arrays_path.name,
        "sha256": digest,
        "bytes": arrays_path.stat().st_size,
        "trees": model.forest_.n_trees,
        "nodes": model.forest_.n_nodes,
        "depth": model.forest_.depth,
    }
    card_path = directory / f"{name}.json"
    card_path.write_text(json.dumps(card, indent=2, sort_keys=False) + "\n", encoding="utf-8")
    return card_path


def _resolve(name_or_path: str | Path) -> Path:
    """The card of a model given by shipped name, by card path or by ``.npz`` path."""
    text = str(name_or_path)
    path = Path(text).expanduser()
    if path.suffix == ".npz":
        path = path.with_suffix(".json")
    if path.suffix == ".json" and path.is_file():
        return path
    if path.is_dir() and (path / "default.json").is_file():
        return path / "default.json"
    shipped = model_dir() / f"{text}.json"
    if shipped.is_file():
        return shipped
    names = sorted(p.stem for p in model_dir().glob("*.json"))
    raise LookupError(
        f"unknown CBST model {text!r}: no such card file and no shipped model of that name "
        f"(shipped: {', '.join(names) or 'none'})"
    )


def load_model(name_or_path: str | Path = "default") -> CBSTRegressor:
    """A fitted :class:`CBSTRegressor` from a shipped name (``"default"``) or a card/arrays
    path. The card is attached as ``model.card_`` and the validity domain as
    ``model.domain_``. Cached per resolved path.

    Raises ``LookupError`` for an unknown name and one ``ValueError`` naming the file for a
    model that is not sound: a card that is not one, an arrays file not beside the card (a
    plain file name in the card's folder), larger than the card says or than
    :data:`MAX_ARRAYS_BYTES`, with another checksum, with unknown or missing arrays or one
    unpacking beyond :data:`MAX_ARRAY_BYTES`; arrays whose shapes, node and tree counts, feature
    count or depth differ from the card or the trees, trees that are not trees, non-finite
    thresholds or values; non-finite or non-positive sizes and domain in the card.
    """
    card_path = _resolve(name_or_path).resolve()
    stat = card_path.stat()
    return _load_cached(str(card_path), stat.st_mtime_ns, stat.st_size)


#: The largest arrays file loading reads, and the largest array in it once unpacked (the
#: shipped model: 0.23 MB packed): a model file can never exhaust memory.
MAX_ARRAYS_BYTES = 1 << 28
MAX_ARRAY_BYTES = 1 << 28
#: The arrays of a stored :class:`FastForest`, and the dtype kind each must have.
_ARRAY_KINDS = {
    "left": "iu",
    "right": "iu",
    "feature": "iu",
    "threshold": "f",
    "value": "f",
    "roots": "iu",
    "meta": "iu",
}


@lru_cache(maxsize=8)
def _load_cached(card_path: str, _mtime: int, _size: int) -> CBSTRegressor:
    path = Path(card_path)
    try:
        card = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as error:
        raise ValueError(f"{path}: not a CBST model card: {error}") from None
    if not isinstance(card, dict) or card.get("format") != CARD_FORMAT:
        found = card.get("format") if isinstance(card, dict) else type(card).__name__
        raise ValueError(f"{path}: not a CBST model card (format {found!r})")
    try:
        arrays_path, arrays = _read_arrays(path, card)
        forest = _checked_forest(arrays, card, arrays_path)
        params = card.get("model", {}).get("params")
        model = CBSTRegressor.from_forest(forest, params)
        model.card_ = card
        model.domain_ = _checked_card_numbers(card)
    except _ModelError as error:
        raise ValueError(f"{error.where or path}: {error}") from None
    except (KeyError, TypeError, ValueError, AttributeError) as error:
        raise ValueError(f"{path}: not a valid CBST model card: {error!r}") from None
    return model


class _ModelError(ValueError):
    """What is wrong with a stored model; ``where`` is the file it is in (default: the card)."""

    def __init__(self, message: str, where: Path | None = None) -> None:
        super().__init__(message)
        self.where = where


def _read_arrays(card_path: Path, card: dict) -> tuple[Path, dict[str, np.ndarray]]:
    """The arrays the card names, read after checking that the file is beside the card, no
    larger than the card says (and :data:`MAX_ARRAYS_BYTES`), has the card's checksum and holds
    only the forest's arrays, each at most :data:`MAX_ARRAY_BYTES` unpacked."""
    import zipfile

    entry = card.get("arrays")
    if not isinstance(entry, dict) or not isinstance(entry.get("file"), str):
        raise _ModelError("the card names no arrays file (arrays.file)")
    name = entry["file"]
    if Path(name).name != name or name in ("", ".", ".."):
        raise _ModelError(
            f"arrays.file {name!r} is not a file name beside the card; a model's arrays file "
            "lives in the card's folder"
        )
    arrays_path = card_path.parent / name
    if arrays_path.is_symlink() or not arrays_path.is_file():
        raise _ModelError("no such arrays file beside the card (a regular file)", arrays_path)
    size = arrays_path.stat().st_size
    if size != entry.get("bytes") or size > MAX_ARRAYS_BYTES:
        raise _ModelError(
            f"{size} bytes; the card says {entry.get('bytes')!r} (at most {MAX_ARRAYS_BYTES})",
            arrays_path,
        )
    raw = arrays_path.read_bytes()
    if hashlib.sha256(raw).hexdigest() != entry.get("sha256"):
        raise _ModelError("checksum does not match the model card", arrays_path)
    try:
        with zipfile.ZipFile(arrays_path) as archive:
            members = {info.filename: info.file_size for info in archive.infolist()}
    except zipfile.BadZipFile as error:
        raise _ModelError(f"not a .npz archive: {error}", arrays_path) from None
    names = {m[: -len(".npy")] if m.endswith(".npy") else m: n for m, n in members.items()}
    unknown = sorted(set(names) - set(_ARRAY_KINDS))
    missing = sorted(set(_ARRAY_KINDS) - set(names))
    if unknown or missing:
        raise _ModelError(
            f"arrays {', '.join(unknown) or 'none'} are unknown and "
            f"{', '.join(missing) or 'none'} missing; expected exactly "
            f"{', '.join(_ARRAY_KINDS)}",
            arrays_path,
        )
    large = sorted(k for k, n in names.items() if n > MAX_ARRAY_BYTES)
    if large:
        raise _ModelError(
            f"arrays {', '.join(large)} unpack to more than {MAX_ARRAY_BYTES} bytes", arrays_path
        )
    try:
        with np.load(arrays_path, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
    except ValueError as error:
        raise _ModelError(f"unreadable arrays: {error}", arrays_path) from None
    for key, kinds in _ARRAY_KINDS.items():
        if arrays[key].dtype.kind not in kinds:
            raise _ModelError(f"array {key} has dtype {arrays[key].dtype}", arrays_path)
    return arrays_path, arrays


def _checked_forest(arrays: dict[str, np.ndarray], card: dict, where: Path) -> FastForest:
    """The forest of ``arrays`` once its structure matches the card: shapes, node and tree
    counts, the feature count, trees whose children come after their parent within the tree
    (so the walk ends), the recorded depth equal to the trees' real depth, finite values."""
    entry = card["arrays"]

    def refuse(message: str) -> None:
        raise _ModelError(message, where)

    left, right, feature, threshold, value, roots, meta = (
        arrays[k] for k in ("left", "right", "feature", "threshold", "value", "roots", "meta")
    )
    n = left.shape[0] if left.ndim == 1 else -1
    if any(a.ndim != 1 or a.shape[0] != n for a in (left, right, feature, threshold)):
        refuse("left, right, feature and threshold must be 1-D with one entry per node")
    if n != entry.get("nodes") or n < 1:
        refuse(f"{n} nodes; the card says {entry.get('nodes')!r}")
    if value.shape != (n, len(TARGET_NAMES)):
        refuse(f"value has shape {value.shape}; expected ({n}, {len(TARGET_NAMES)})")
    if meta.shape != (2,):
        refuse(f"meta has shape {meta.shape}; expected (2,): depth and feature count")
    depth, n_features = int(meta[0]), int(meta[1])
    named = card.get("features", list(FEATURE_NAMES))
    if named != list(FEATURE_NAMES) or n_features != len(FEATURE_NAMES):
        refuse(
            f"{n_features} features; arrange-up's CBST features are the "
            f"{len(FEATURE_NAMES)} of {', '.join(FEATURE_NAMES)} (the card's 'features')"
        )
    if roots.ndim != 1 or roots.shape[0] != entry.get("trees") or roots.shape[0] < 1:
        refuse(f"roots has shape {roots.shape}; the card says {entry.get('trees')!r} trees")
    if roots[0] != 0 or np.any(np.diff(roots) <= 0) or roots[-1] >= n:
        refuse("roots must start at 0 and increase within the node arrays")
    index = np.arange(n)
    tree = np.searchsorted(roots, index, side="right") - 1
    end = np.append(roots[1:], n)[tree]
    leaf = left == index
    if np.any(leaf & ((right != index) | (threshold != np.inf))):
        refuse("a leaf (left child itself) must have itself as right child and threshold +inf")
    inner = ~leaf
    for name, child in (("left", left), ("right", right)):
        if np.any(inner & ((child <= index) | (child >= end))):
            refuse(f"a {name} child lies outside its tree or before its parent")
    if np.any(inner & ((feature < 0) | (feature >= n_features))):
        refuse("a split feature lies outside the feature range")
    if not np.all(np.isfinite(threshold[inner])) or not np.all(np.isfinite(value)):
        refuse("thresholds of splits and leaf values must be finite numbers")
    # the walk runs `depth` steps: the recorded depth must be the trees' depth
    reached = np.zeros(n, dtype=bool)
    reached[roots] = True
    frontier = roots
    real = 0
    while True:
        frontier = frontier[inner[frontier]]
        if not frontier.size:
            break
        real += 1
        children = np.concatenate([left[frontier], right[frontier]])
        if np.any(reached[children]) or len(np.unique(children)) != len(children):
            refuse("a node is the child of two nodes")
        reached[children] = True
        frontier = children
    if not reached.all():
        refuse("some nodes are in no tree")
    if depth != real or depth != entry.get("depth"):
        refuse(
            f"depth {depth} recorded; the trees are {real} deep (the card says "
            f"{entry.get('depth')!r})"
        )
    return FastForest.from_arrays(arrays)


def _checked_card_numbers(card: dict) -> Domain:
    """The card's validity domain, once it and the sizes the semantics reads are finite and
    positive where they must be."""

    def finite(name: str, values: Any, positive: bool = False) -> None:
        values = np.asarray(values, dtype=float)
        if not np.all(np.isfinite(values)) or (positive and not np.all(values > 0)):
            raise _ModelError(
                f"{name} must be {'positive' if positive else 'finite'} numbers, got {values}"
            )

    finite("block_size", card["block_size"], positive=True)
    paddle = np.asarray(card["paddle_size"], dtype=float)
    if paddle.shape != (2,):
        raise _ModelError(f"paddle_size must be [length, thickness], got {card['paddle_size']}")
    finite("paddle_size", paddle, positive=True)
    allowance = card["overshoot_allowance"]
    if not isinstance(allowance, dict) or not all(str(k).isdigit() for k in allowance):
        raise _ModelError("overshoot_allowance must map depths to inches")
    finite("overshoot_allowance", list(allowance.values()) or [0.0])
    domain = Domain.from_dict(card["domain"])
    finite("domain.block_half", domain.block_half, positive=True)
    finite("domain.paddle_half", domain.paddle_half, positive=True)
    finite("domain.paddle_offset", domain.paddle_offset, positive=True)
    finite("domain.tolerance", domain.tolerance)
    if len(domain.block_half) != 3 or len(domain.paddle_half) != 3:
        raise _ModelError("domain half-widths must be (x, y, theta)")
    return domain


# ----------------------------------------------------------------------------------------------
# The pipeline
# ----------------------------------------------------------------------------------------------
def _overshoot_allowance(overshoot: np.ndarray, depths: np.ndarray) -> dict[str, float]:
    """Per depth, the 99th percentile of the overshoot of ``x_max`` in trains that did not
    buckle (overshoot at most ``BUCKLE_LIMIT``), rounded up to 1e-3 in: the physics lets
    contacts interpenetrate by its collision slop, so a flush train ends a little beyond
    ``x_max``. (Larger overshoots are the predicted ``slip``'s business.)"""
    out = {}
    for k in sorted(set(int(d) for d in depths)):
        rows = overshoot[(depths == k) & (overshoot <= BUCKLE_LIMIT)]
        worst = float(np.percentile(rows, 99.0)) if len(rows) else 0.0
        out[str(k)] = math.ceil(max(0.0, worst) * 1000.0) / 1000.0
    return out


def _row_depths(X: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """Depth of each row (1 = next to the wall): rows of an example are stored paddle side
    first, so depth counts down to 1 within each group."""
    depths = np.empty(len(X), dtype=int)
    start = 0
    while start < len(X):
        stop = start
        while stop < len(X) and groups[stop] == groups[start]:
            stop += 1
        depths[start:stop] = np.arange(stop - start, 0, -1)
        start = stop
    return depths


def train_cbst(
    examples: int = 1800,
    rollouts_per_example: int = 1000,
    seed: int = 0,
    workers: int | None = 1,
    output_dir: str | Path | None = None,
    *,
    backend: str = "local",
    scheduler: str | None = None,
    name: str = "default",
    data_path: str | Path | None = None,
    param_grid: Mapping[str, list[Any]] | None = None,
    n_estimators: int = 100,
    progress: ProgressCallback | None = None,
) -> dict[str, Any]:
    """Generate (or resume) the training data, tune and evaluate the model as the thesis
    does, and save ``NAME.npz`` + ``NAME.json`` into ``output_dir``.

    Parameters
    ----------
    examples, rollouts_per_example
        Data set size: beliefs, and simulated pushes per belief (thesis: 1800 x 1000).
    seed
        Seeds the data (example ``i`` depends only on ``(seed, i)``), the split and the forest.
    workers
        Processes for data generation and for the grid search (``None``: every core).
    backend, scheduler
        Where the data is generated (:func:`arrange_up.parallel.get_runner`): ``"local"``
        processes, or ``"dask"`` (a local cluster, or the one at ``scheduler``). The grid
        search always runs locally with ``workers`` processes.
    output_dir
        Where to write the model (default ``./cbst-model``; the shipped model lives in the
        repository's ``semantics/cbst``).
    data_path
        The resumable ``.jsonl`` data file (default ``OUTPUT_DIR/NAME.data.jsonl``); rerunning
        with the same arguments skips the examples already in it.
    progress
        ``progress(stage, done, total)`` with stage ``"data"``, then ``"fit"`` (0/1, 1/1).

    Returns the model card (also written as ``NAME.json``).
    """
    workers = available_cores() if workers is None else workers
    if examples < 10:
        raise ValueError("examples must be at least 10 (8-fold CV on 90% of them)")
    out = Path(output_dir) if output_dir is not None else Path("cbst-model")
    data = Path(data_path) if data_path is not None else out / f"{name}.data.jsonl"
    started = time.monotonic()
    summary = generate_dataset(
        data,
        examples=examples,
        rollouts=rollouts_per_example,
        seed=seed,
        workers=workers,
        backend=backend,
        scheduler=scheduler,
        progress=progress,
    )
    dataset = load_dataset(data, examples=examples, seed=seed, rollouts=rollouts_per_example)
    if progress is not None:
        progress("fit", 0, 1)
    model, report = tune(
        dataset.X,
        dataset.y,
        dataset.groups,
        param_grid=param_grid,
        n_estimators=n_estimators,
        seed=seed,
        workers=workers,
    )
    if progress is not None:
        progress("fit", 1, 1)
    depths = _row_depths(dataset.X, dataset.groups)
    settings = DEFAULT_GENERATION
    card: dict[str, Any] = {
        "description": (
            "Learned PREDICT of CBST (thesis §3.2): multi-output random forest mapping "
            "(prev, cur, next) interval beliefs of a push toward a wall to the uncertainty of "
            "cur after the push. See docs/cbst.md."
        ),
        "created": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "arrange_up_version": __version__,
        "sklearn_version": sklearn.__version__,
        "data": {
            "examples": dataset.examples,
            "invalid_examples": dataset.invalid,
            "rows": int(len(dataset.X)),
            "rollouts_per_example": rollouts_per_example,
            "seed": seed,
            "failed_rollouts": dataset.failed_rollouts,
            "generation_cpu_seconds": round(dataset.example_seconds, 1),
            "generation_wall_seconds_this_run": round(summary["seconds"], 1),
            "examples_computed_this_run": summary["computed"],
            "workers": workers,
            "backend": backend,
            "file": data.name,
            "settings": settings.as_dict(),
            "settings_digest": settings.digest(),
        },
        "features": list(FEATURE_NAMES),
        "feature_units": "inches; dth_* in degrees; ct = 2*[prev is object] + [next is object]",
        "targets": list(TARGET_NAMES),
        "target_units": list(TARGET_UNITS),
        "block_size": settings.block_size,
        "paddle_size": list(settings.paddle_size),
        "domain": settings.domain.as_dict(),
        "overshoot_allowance": _overshoot_allowance(dataset.overshoot, depths),
        "buckled_rows": int(np.sum(dataset.overshoot > BUCKLE_LIMIT)),
        "buckle_limit": BUCKLE_LIMIT,
        "model": {
            "type": "RandomForestRegressor (multi-output) via CBSTRegressor",
            "n_estimators": n_estimators,
            "params": {k: _jsonable(v) for k, v in model.get_params().items()},
            "selection": "GridSearchCV, scoring mean R^2, GroupKFold by example",
            **report,
        },
        "scores": {
            "cv_rmse": report["cv_rmse"],
            "test_rmse": report["test_rmse"],
            "thesis_test_rmse": THESIS_TEST_RMSE,
            "units": dict(zip(TARGET_NAMES, TARGET_UNITS, strict=True)),
        },
        "training_seconds": round(time.monotonic() - started, 1),
    }
    save_model(model, card, out, name)
    return json.loads((out / f"{name}.json").read_text(encoding="utf-8"))
