"""The learned PREDICT of CBST: a multi-output random forest (thesis §3.2).

* :class:`~arrange_up.cbst.estimator.CBSTRegressor` (its own module, which imports
  scikit-learn) is the estimator that training fits; ``CBSTRegressor`` is also found here.
* :class:`TrainedModel` is a fitted model as stored: the trees as a :class:`FastForest` and
  the residual pairs. :func:`load_model` returns one, so that planning never imports
  scikit-learn (about a second, a tenth of a CBST blocks-9 search).
* :func:`tune` grid-searches the hyperparameters with 8-fold cross-validation, as the thesis
  did, and refits; :func:`cross_validate` gives per-target out-of-fold RMSE and R^2. Rows
  of one example (the blocks of one belief) never straddle a fold (``GroupKFold``). The
  unbiased figure is the score on a fresh test set generated with another seed
  (:func:`train_cbst`; :func:`rescore_model` measures both again for a saved model).
* :func:`save_model` writes ``NAME.npz`` (the trees' arrays, numbers only) and ``NAME.json``
  (the model card); :func:`load_model` reads them back (a :class:`TrainedModel`) with
  ``allow_pickle=False`` after checking the arrays' SHA-256 against the card. No model file
  is ever pickled.
* :func:`train_cbst` is the whole pipeline behind ``arrange-up train-cbst``: generate (or
  resume) the data and a fresh test set under a given controller, tune, score, save.

Shipped models live in the repository's ``semantics/cbst/`` (an installed wheel carries it as
``arrange_up/_shipped/semantics/cbst``), one per controller kind (:data:`SHIPPED_MODELS`);
``load_model("default", controller)`` finds the one for ``controller`` in either.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import replace
from functools import lru_cache, partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from arrange_up import __version__
from arrange_up.cbst.data import (
    DEFAULT_GENERATION,
    Dataset,
    GenerationSettings,
    generate_dataset,
    load_dataset,
)
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
from arrange_up.model.problem import DEFAULT_CONTROLLER, Controller, ControllerKind
from arrange_up.parallel import available_cores

if TYPE_CHECKING:
    from arrange_up.cbst.estimator import CBSTRegressor

__all__ = [
    "CARD_FORMAT",
    "DEFAULT_GRID",
    "DEFAULT_MODEL",
    "SHIPPED_MODELS",
    "DY_RESIDUAL",
    "CBSTRegressor",
    "TrainedModel",
    "check_residual",
    "cross_validate",
    "load_model",
    "model_dir",
    "predict_rows",
    "rescore_model",
    "save_model",
    "shipped_name",
    "train_cbst",
    "tune",
]

CARD_FORMAT = "arrange-up-cbst-model/1"


def __getattr__(name: str) -> Any:
    # The estimator is found here too, imported (with scikit-learn) only by those who use it.
    if name == "CBSTRegressor":
        from arrange_up.cbst.estimator import CBSTRegressor

        return CBSTRegressor
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


#: The name of the shipped model for the problem's controller.
DEFAULT_MODEL = "default"

#: The shipped model trained under each controller kind (``semantics/cbst/NAME.json``).
SHIPPED_MODELS: dict[ControllerKind, str] = {
    ControllerKind.COMPLIANT: "compliant",
    ControllerKind.SERVO: "servo",
}

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
# The stored model
# ----------------------------------------------------------------------------------------------
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


# ----------------------------------------------------------------------------------------------
# The thesis's training procedure
# ----------------------------------------------------------------------------------------------
def _scores(y_true: np.ndarray, y_pred: np.ndarray) -> dict[str, dict[str, float]]:
    """Per target: ``rmse`` and ``r2`` (the coefficient of determination, 1 - SSE/SST: the
    share of the target's variance the predictions explain; 0 for predicting the mean)."""
    y_true, y_pred = np.asarray(y_true, dtype=float), np.asarray(y_pred, dtype=float)
    sse = np.sum((y_true - y_pred) ** 2, axis=0)
    sst = np.sum((y_true - y_true.mean(axis=0)) ** 2, axis=0)
    rmse = np.sqrt(sse / len(y_true))
    r2 = np.where(sst > 0.0, 1.0 - sse / np.where(sst > 0.0, sst, 1.0), 0.0)
    return {
        "rmse": {name: float(v) for name, v in zip(TARGET_NAMES, rmse, strict=True)},
        "r2": {name: float(v) for name, v in zip(TARGET_NAMES, r2, strict=True)},
    }


def cross_validate(
    params: Mapping[str, Any],
    X: np.ndarray,
    y: np.ndarray,
    groups: np.ndarray,
    *,
    cv: int = 8,
    workers: int = 1,
) -> dict[str, dict[str, float]]:
    """Per-target RMSE and R^2 (:func:`_scores`) of the out-of-fold predictions of a
    :class:`CBSTRegressor` with ``params``, refitted on each of ``cv`` folds made by example
    (``GroupKFold`` on ``groups``: the rows of one example never straddle a fold)."""
    from joblib import parallel_config
    from sklearn.model_selection import GroupKFold, cross_val_predict

    from arrange_up.cbst.estimator import CBSTRegressor

    # Threads, not joblib's loky processes: the data generation leaves the process's shared
    # loky executor (arrange_up.parallel) running, and joblib.Parallel cannot take that one
    # over (AttributeError: _temp_folder_manager). Tree building releases the GIL.
    with parallel_config(backend="threading"):
        oof = cross_val_predict(
            CBSTRegressor(**params),
            X,
            y,
            groups=groups,
            cv=GroupKFold(n_splits=cv),
            n_jobs=workers,
        )
    return _scores(y, oof)


def tune(
    X: np.ndarray,
    y: np.ndarray,
    groups: np.ndarray,
    *,
    param_grid: Mapping[str, list[Any]] | None = None,
    n_estimators: int = 100,
    cv: int = 8,
    seed: int = 0,
    workers: int = 1,
) -> tuple[CBSTRegressor, dict[str, Any]]:
    """Grid search with ``cv``-fold cross-validation by example (``GroupKFold``) on all of
    ``X``, then refit on all of it.

    Selection uses the mean R^2 over the outputs (scale-free: the angle target is in degrees
    and would dominate a mean squared error). Returns the refitted model and a report with
    the grid, the best parameters, their mean CV R^2 (``selection_r2``) and per-target CV
    RMSE and R^2 (``cv_rmse``, ``cv_r2``: out-of-fold predictions of the best parameters;
    the parameters were chosen on the same folds, so a fresh test set is the unbiased
    figure, see :func:`train_cbst`).
    """
    from joblib import parallel_config
    from sklearn.model_selection import GridSearchCV, GroupKFold

    from arrange_up.cbst.estimator import CBSTRegressor

    grid = dict(param_grid or DEFAULT_GRID)
    base = CBSTRegressor(n_estimators=n_estimators, random_state=seed, n_jobs=1)
    folds = GroupKFold(n_splits=cv)
    search = GridSearchCV(base, grid, scoring="r2", cv=folds, n_jobs=workers, refit=True)
    started = time.monotonic()
    with parallel_config(backend="threading"):  # see cross_validate
        search.fit(X, y, groups=groups)
    best: CBSTRegressor = search.best_estimator_
    cv_scores = cross_validate(best.get_params(), X, y, groups, cv=cv, workers=workers)
    report = {
        "best_params": {k: _jsonable(v) for k, v in search.best_params_.items()},
        "grid": {k: [_jsonable(v) for v in vs] for k, vs in grid.items()},
        "cv_folds": cv,
        "selection_r2": float(search.best_score_),
        "cv_rmse": cv_scores["rmse"],
        "cv_r2": cv_scores["r2"],
        "rows": int(len(X)),
        "examples": int(len(np.unique(groups))),
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
    model: CBSTRegressor | TrainedModel, card: Mapping[str, Any], directory: str | Path, name: str
) -> Path:
    """Write ``NAME.npz`` (arrays only) and ``NAME.json`` (the card, with the arrays'
    SHA-256 and size added) into ``directory``; returns the card's path. ``ValueError`` for a
    model not fitted."""
    if getattr(model, "forest_", None) is None:
        raise ValueError(f"{type(model).__name__} is not fitted: it has no trees to save")
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


def shipped_name(name_or_path: str | Path, controller: Controller | None = None) -> str | Path:
    """``name_or_path`` with :data:`DEFAULT_MODEL` replaced by the shipped model of
    ``controller``'s kind (``None``: the problems' default controller)."""
    if str(name_or_path) != DEFAULT_MODEL:
        return name_or_path
    return SHIPPED_MODELS[(controller or DEFAULT_CONTROLLER).kind]


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
        f"(shipped: {', '.join(names) or 'none'}; {DEFAULT_MODEL!r}: the one of the "
        "problem's controller)"
    )


def load_model(
    name_or_path: str | Path = DEFAULT_MODEL, controller: Controller | None = None
) -> TrainedModel:
    """A fitted :class:`TrainedModel` from a shipped name (``"default"``: the shipped model of
    ``controller``, see :func:`shipped_name`) or a card/arrays path. The card is attached as
    ``model.card_``, its path as ``model.card_path_`` and the validity domain as
    ``model.domain_``. Cached per resolved path. Whether the model suits a problem's
    controller is :func:`arrange_up.cbst.choice.model_for`'s check.

    Raises ``LookupError`` for an unknown name and one ``ValueError`` naming the file for a
    model that is not sound: a card that is not one, an arrays file not beside the card (a
    plain file name in the card's folder), larger than the card says or than
    :data:`MAX_ARRAYS_BYTES`, with another checksum, with unknown or missing arrays or one
    unpacking beyond :data:`MAX_ARRAY_BYTES`; arrays whose shapes, node and tree counts, feature
    count or depth differ from the card or the trees, trees that are not trees, non-finite
    thresholds or values; non-finite or non-positive sizes and domain in the card.
    """
    card_path = _resolve(shipped_name(name_or_path, controller)).resolve()
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
def _load_cached(card_path: str, _mtime: int, _size: int) -> TrainedModel:
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
        params = card.get("model", {}).get("params") or {}
        model = TrainedModel(forest, params.get("residual"))
        model.card_ = card
        model.card_path_ = path
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


def _test_scores(model: CBSTRegressor, test: Dataset, seed: int, path: Path) -> dict[str, Any]:
    """The scores of ``model`` on the fresh test set ``test`` (generated with ``seed``)."""
    scores = _scores(test.y, model.predict(test.X))
    return {
        "test_rmse": scores["rmse"],
        "test_r2": scores["r2"],
        "test": {
            "examples": test.examples,
            "invalid_examples": test.invalid,
            "rows": int(len(test.X)),
            "rollouts_per_example": test.rollouts,
            "seed": seed,
            "file": path.name,
        },
    }


def _score_card(cv_scores: Mapping[str, Any], test_scores: Mapping[str, Any]) -> dict:
    return {
        "method": (
            f"cv_*: {cv_scores['cv_folds']}-fold GroupKFold (by example) over the training "
            "data, out-of-fold predictions of the card's hyperparameters; test_*: the model "
            "on a fresh test set generated with another seed (scores.test)"
        ),
        "cv_folds": cv_scores["cv_folds"],
        "cv_rmse": cv_scores["cv_rmse"],
        "cv_r2": cv_scores["cv_r2"],
        **test_scores,
        "thesis_test_rmse": THESIS_TEST_RMSE,
        "units": dict(zip(TARGET_NAMES, TARGET_UNITS, strict=True)),
    }


def _fresh_seed(seed: int, test_seed: int) -> None:
    if test_seed == seed:
        raise ValueError(
            "the test set must be generated with another seed than the training data "
            f"(both {seed}): give test_seed (--test-seed) another value than seed (--seed), "
            "so that the test set is fresh"
        )


def train_cbst(
    examples: int = 1800,
    rollouts_per_example: int = 1000,
    seed: int = 0,
    workers: int | None = 1,
    output_dir: str | Path | None = None,
    *,
    controller: Controller | None = None,
    settings: GenerationSettings | None = None,
    test_examples: int = 200,
    test_seed: int = 1,
    backend: str = "local",
    scheduler: str | None = None,
    name: str | None = None,
    data_path: str | Path | None = None,
    test_data_path: str | Path | None = None,
    param_grid: Mapping[str, list[Any]] | None = None,
    n_estimators: int = 100,
    progress: ProgressCallback | None = None,
) -> dict[str, Any]:
    """Generate (or resume) the training data and a fresh test set, tune the model by
    cross-validation, score it, and save ``NAME.npz`` + ``NAME.json`` into ``output_dir``.

    Parameters
    ----------
    examples, rollouts_per_example
        Data set size: beliefs, and simulated pushes per belief (thesis: 1800 x 1000).
    seed
        Seeds the data (example ``i`` depends only on ``(seed, i)``) and the forest.
    workers
        Processes for data generation and for the grid search (``None``: every core).
    controller, settings
        The physics of the rollouts: ``settings`` (default
        :data:`~arrange_up.cbst.data.DEFAULT_GENERATION`) with its controller replaced by
        ``controller`` when given (default: the settings', the compliant controller at its
        defaults). The card names the controller; a model plans only problems with it.
    test_examples, test_seed
        The fresh test set: examples of the same distribution and rollouts, generated with
        ``test_seed`` (which must differ from ``seed``).
    backend, scheduler
        Where the data is generated (:func:`arrange_up.parallel.get_runner`): ``"local"``
        processes, or ``"dask"`` (a local cluster, or the one at ``scheduler``). The grid
        search always runs locally with ``workers`` threads.
    output_dir
        Where to write the model (default ``./cbst-model``; the shipped models live in the
        repository's ``semantics/cbst``).
    name
        The model's name (default: the controller kind's shipped name, ``compliant`` or
        ``servo``).
    data_path, test_data_path
        The resumable ``.jsonl`` data files (default ``OUTPUT_DIR/NAME.data.jsonl`` and
        ``OUTPUT_DIR/NAME.test.jsonl``); rerunning with the same arguments skips the
        examples already in them.
    progress
        ``progress(stage, done, total)`` with stage ``"data"``, ``"test data"``, then
        ``"fit"`` (0/1, 1/1).

    Returns the model card (also written as ``NAME.json``).
    """
    workers = available_cores() if workers is None else workers
    if examples < 10:
        raise ValueError("examples must be at least 10 (8-fold CV by example)")
    if test_examples < 1:
        raise ValueError("test_examples must be at least 1")
    _fresh_seed(seed, test_seed)
    settings = settings or DEFAULT_GENERATION
    if controller is not None:
        settings = replace(settings, controller=controller)
    name = name or SHIPPED_MODELS[settings.controller.kind]
    out = Path(output_dir) if output_dir is not None else Path("cbst-model")
    data = Path(data_path) if data_path is not None else out / f"{name}.data.jsonl"
    test_data = Path(test_data_path) if test_data_path is not None else out / f"{name}.test.jsonl"
    if data.resolve() == test_data.resolve():
        raise ValueError(f"{data}: the training data and the test set need separate files")
    started = time.monotonic()
    parallel = {"workers": workers, "backend": backend, "scheduler": scheduler}
    summary = generate_dataset(
        data,
        examples=examples,
        rollouts=rollouts_per_example,
        seed=seed,
        settings=settings,
        progress=progress,
        **parallel,
    )
    test_summary = generate_dataset(
        test_data,
        examples=test_examples,
        rollouts=rollouts_per_example,
        seed=test_seed,
        settings=settings,
        progress=None if progress is None else partial(_relabel, progress, "test data"),
        **parallel,
    )
    dataset = load_dataset(
        data, examples=examples, seed=seed, rollouts=rollouts_per_example, settings=settings
    )
    test = load_dataset(
        test_data,
        examples=test_examples,
        seed=test_seed,
        rollouts=rollouts_per_example,
        settings=settings,
    )
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
    import sklearn

    # Lazy: choice imports this module (it loads the models it checks).
    from arrange_up.cbst.choice import controller_record

    card: dict[str, Any] = {
        "description": (
            "Learned PREDICT of CBST (thesis §3.2): multi-output random forest mapping "
            "(prev, cur, next) interval beliefs of a push toward a wall to the uncertainty of "
            f"cur after the push, trained under the {settings.controller.kind} controller. "
            "See docs/cbst.md."
        ),
        "controller": controller_record(settings.controller),
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
            "test_generation_cpu_seconds": round(test.example_seconds, 1),
            "test_generation_wall_seconds_this_run": round(test_summary["seconds"], 1),
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
        "scores": _score_card(report, _test_scores(model, test, test_seed, test_data)),
        "training_seconds": round(time.monotonic() - started, 1),
    }
    save_model(model, card, out, name)
    return json.loads((out / f"{name}.json").read_text(encoding="utf-8"))


def _relabel(progress: ProgressCallback, stage: str, _stage: str, done: int, total: int) -> None:
    progress(stage, done, total)


def rescore_model(
    name_or_path: str | Path,
    *,
    data_path: str | Path,
    test_data_path: str | Path,
    test_examples: int = 200,
    test_seed: int = 1,
    workers: int | None = 1,
    backend: str = "local",
    scheduler: str | None = None,
    write: bool = False,
    progress: ProgressCallback | None = None,
) -> dict[str, Any]:
    """The card ``scores`` of a saved model, measured again: its training data regenerated
    (or resumed) from the card's examples, rollouts, seed and settings into ``data_path``
    for the CV figures (its hyperparameters refitted on 8 folds by example), and a fresh
    test set of ``test_examples`` with ``test_seed`` in ``test_data_path`` for the model's
    own arrays. With ``write`` the card's ``scores`` are replaced (the arrays and their
    checksum are untouched). Returns the new scores.

    For models saved before the cards reported CV R^2 and a fresh test set (the servo
    model); a model :func:`train_cbst` makes has these scores already."""
    workers = available_cores() if workers is None else workers
    model = load_model(name_or_path)
    card = model.card_
    info = card["data"]
    seed, rollouts = int(info["seed"]), int(info["rollouts_per_example"])
    _fresh_seed(seed, test_seed)
    settings = GenerationSettings.from_dict(info["settings"])
    if settings.digest() != info["settings_digest"]:
        raise ValueError(
            f"{model.card_path_}: the card's settings do not give its settings digest "
            f"({settings.digest()} != {info['settings_digest']}): generated by another version"
        )
    parallel = {"workers": workers, "backend": backend, "scheduler": scheduler}
    for path, n, s, stage in (
        (data_path, int(info["examples"]), seed, "data"),
        (test_data_path, test_examples, test_seed, "test data"),
    ):
        generate_dataset(
            path,
            examples=n,
            rollouts=rollouts,
            seed=s,
            settings=settings,
            progress=None if progress is None else partial(_relabel, progress, stage),
            **parallel,
        )
    dataset = load_dataset(
        data_path, examples=int(info["examples"]), seed=seed, rollouts=rollouts, settings=settings
    )
    test = load_dataset(
        test_data_path,
        examples=test_examples,
        seed=test_seed,
        rollouts=rollouts,
        settings=settings,
    )
    if progress is not None:
        progress("fit", 0, 1)
    folds = int(card["model"].get("cv_folds", 8))
    cv_scores = cross_validate(
        card["model"]["params"], dataset.X, dataset.y, dataset.groups, cv=folds, workers=workers
    )
    if progress is not None:
        progress("fit", 1, 1)
    scores = _score_card(
        {"cv_folds": folds, "cv_rmse": cv_scores["rmse"], "cv_r2": cv_scores["r2"]},
        _test_scores(model, test, test_seed, Path(test_data_path)),
    )
    scores["cv_data"] = {
        "examples": dataset.examples,
        "rows": int(len(dataset.X)),
        "file": Path(data_path).name,
    }
    if write:
        card = dict(card)
        card["scores"] = scores
        path = model.card_path_
        path.write_text(json.dumps(card, indent=2) + "\n", encoding="utf-8")
    return scores
