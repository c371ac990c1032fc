"""Training the learned PREDICT of CBST: a multi-output random forest (thesis §3.2).

* :class:`~arrange_up.cbst.estimator.CBSTRegressor` (its own module, which imports
  scikit-learn) is the estimator that training fits; ``CBSTRegressor`` is also found here.
  Planning predicts with a :class:`~arrange_up.cbst.trained.TrainedModel` read back by
  :func:`~arrange_up.cbst.store.load_model`, never importing scikit-learn.
* :func:`tune` grid-searches the hyperparameters with 8-fold cross-validation, as the thesis
  did, and refits; :func:`cross_validate` gives per-target out-of-fold RMSE and R^2. Rows
  of one example (the blocks of one belief) never straddle a fold (``GroupKFold``). The
  unbiased figure is the score on a fresh test set generated with another seed
  (:func:`train_cbst`; :func:`rescore_model` measures both again for a saved model).
* :func:`train_cbst` is the whole pipeline behind ``arrange-up train-cbst``: generate (or
  resume) the data and a fresh test set under a given controller, tune, score, save
  (:func:`~arrange_up.cbst.store.save_model`).

Imports go one way: this module uses :mod:`~arrange_up.cbst.choice` (the card's controller
record) and :mod:`~arrange_up.cbst.store`; neither imports it.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import time
from collections.abc import Mapping
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from arrange_up import __version__
from arrange_up.cbst.choice import controller_record
from arrange_up.cbst.data import (
    DEFAULT_GENERATION,
    Dataset,
    GenerationSettings,
    TrainingProgress,
    generate_dataset,
    load_dataset,
)
from arrange_up.cbst.features import (
    BUCKLE_LIMIT,
    FEATURE_NAMES,
    TARGET_NAMES,
    TARGET_UNITS,
    THESIS_TEST_RMSE,
)
from arrange_up.cbst.store import SHIPPED_MODELS, load_model, save_model
from arrange_up.model.problem import Controller
from arrange_up.parallel import available_cores

if TYPE_CHECKING:
    from arrange_up.cbst.estimator import CBSTRegressor

__all__ = [
    "DEFAULT_GRID",
    "DY_RESIDUAL",
    "CBSTRegressor",
    "cross_validate",
    "rescore_model",
    "train_cbst",
    "tune",
]


def __getattr__(name: str) -> Any:
    # The estimator is found here too, imported (with scikit-learn, slow to import) only by
    # those who use it.
    if name == "CBSTRegressor":
        from arrange_up.cbst.estimator import CBSTRegressor

        return CBSTRegressor
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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
    # Here: scikit-learn (and the estimator, which imports it) is slow to import, and only
    # training needs it.
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
    # Here: scikit-learn (and the estimator, which imports it) is slow to import, and only
    # training needs it.
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


def _coverage(
    predicted: np.ndarray,
    outcomes: list[np.ndarray],
    depths: np.ndarray,
    allowance: Mapping[str, float],
) -> dict[str, float]:
    """Per target, the share of all rollouts of the rows whose deviation lies inside the box
    the semantics builds from ``predicted`` (clipped at 0, as it does): ``x_max - u <= dx``,
    ``|v - v_c| <= dy``, ``|θ| <= dth``, and for ``slip`` the box's upper end,
    ``u - x_max <= max(slip, allowance of the row's depth)``; ``box``: all four at once."""
    inside: dict[str, list[np.ndarray]] = {name: [] for name in (*TARGET_NAMES, "box")}
    for row, each, depth in zip(np.maximum(predicted, 0.0), outcomes, depths, strict=True):
        limits = row.copy()
        limits[3] = max(row[3], float(allowance.get(str(int(depth)), 0.0)))
        within = each <= limits
        for k, name in enumerate(TARGET_NAMES):
            inside[name].append(within[:, k])
        inside["box"].append(within.all(axis=1))
    return {
        name: float(np.concatenate(flags).mean()) if flags else math.nan
        for name, flags in inside.items()
    }


def _test_scores(
    model: CBSTRegressor, test: Dataset, seed: int, path: Path, allowance: Mapping[str, float]
) -> dict[str, Any]:
    """The scores of ``model`` on the fresh test set ``test`` (generated with ``seed``): RMSE
    and R^2 per target, and, when the test set kept its rollouts' outcomes, the coverage of
    the predicted boxes (:func:`_coverage`, with the card's overshoot ``allowance``)."""
    predicted = model.predict(test.X)
    scores = _scores(test.y, predicted)
    coverage = {}
    if test.outcomes is not None:
        depths = _row_depths(test.X, test.groups)
        coverage["test_coverage"] = _coverage(predicted, test.outcomes, depths, allowance)
    return {
        "test_rmse": scores["rmse"],
        "test_r2": scores["r2"],
        **coverage,
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
            "on a fresh test set generated with another seed (scores.test); test_coverage: "
            "the share of that set's rollouts ending inside the predicted box, per target "
            "and for the whole box"
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
    progress: TrainingProgress | None = None,
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
        outcomes=True,
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
    allowance = _overshoot_allowance(dataset.overshoot, depths)
    import sklearn  # here: importing scikit-learn is slow, and only training needs it

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
        "overshoot_allowance": allowance,
        "buckled_rows": int(np.sum(dataset.overshoot > BUCKLE_LIMIT)),
        "buckle_limit": BUCKLE_LIMIT,
        "model": {
            "type": "RandomForestRegressor (multi-output) via CBSTRegressor",
            "n_estimators": n_estimators,
            "params": {k: _jsonable(v) for k, v in model.get_params().items()},
            "selection": "GridSearchCV, scoring mean R^2, GroupKFold by example",
            **report,
        },
        "scores": _score_card(report, _test_scores(model, test, test_seed, test_data, allowance)),
        "training_seconds": round(time.monotonic() - started, 1),
    }
    save_model(model, card, out, name)
    return json.loads((out / f"{name}.json").read_text(encoding="utf-8"))


def _relabel(progress: TrainingProgress, stage: str, _stage: str, done: int, total: int) -> None:
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
    progress: TrainingProgress | None = None,
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
            outcomes=path is test_data_path,
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
        _test_scores(
            model, test, test_seed, Path(test_data_path), card.get("overshoot_allowance", {})
        ),
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
