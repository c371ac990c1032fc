"""CBST's learned model: the estimator contract, the fast forest, storage, the shipped model."""

from __future__ import annotations

import json
import time
import zipfile

import numpy as np
import pytest
from sklearn.ensemble import RandomForestRegressor
from sklearn.utils.estimator_checks import check_estimator

from arrange_up.cbst.fast_forest import FastForest
from arrange_up.cbst.features import FEATURE_NAMES, TARGET_NAMES, THESIS_TEST_RMSE, Domain
from arrange_up.cbst.model import CBSTRegressor, tune
from arrange_up.cbst.store import load_model, save_model

# Checks scikit-learn itself skips in this environment (not applicable here):
#  * check_array_api_input: needs SCIPY_ARRAY_API=1 and an array-API library; the model is
#    numpy-only by design.
#  * check_regressor_data_not_an_array: needs pandas, which arrange-up does not depend on.
ENVIRONMENT_SKIPS = {"check_array_api_input", "check_regressor_data_not_an_array"}


def _data(rows: int = 600, seed: int = 0):
    rng = np.random.default_rng(seed)
    X = rng.uniform(0.0, 1.0, size=(rows, len(FEATURE_NAMES)))
    X[:, 11] = rng.integers(0, 4, size=rows)
    y = np.stack(
        [X[:, 0] + X[:, 3], X[:, 4] ** 2, 10 * X[:, 5] + X[:, 11], np.maximum(X[:, 9] - 0.8, 0)],
        axis=1,
    ) + rng.normal(0, 0.01, size=(rows, 4))
    return X, y


@pytest.mark.filterwarnings("ignore::sklearn.exceptions.SkipTestWarning")
def test_check_estimator():
    results = check_estimator(CBSTRegressor(n_estimators=5, random_state=0), on_fail=None)
    failed = [r["check_name"] for r in results if r["status"] == "failed"]
    skipped = {r["check_name"] for r in results if r["status"] == "skipped"}
    assert not failed
    assert skipped <= ENVIRONMENT_SKIPS
    assert len(results) - len(skipped) >= 45


def test_fit_returns_self_and_validates():
    X, y = _data(100)
    model = CBSTRegressor(n_estimators=3, random_state=0)
    assert model.fit(X, y) is model
    assert model.n_features_in_ == 12 and model.n_outputs_ == 4
    assert model.predict(X).shape == (100, 4)
    assert model.fit(X, y[:, 0]).predict(X).shape == (100,)
    with pytest.raises(ValueError):
        model.predict(X[:, :5])


def test_fast_forest_equals_sklearn_and_is_much_faster():
    X, y = _data(800)
    forest = RandomForestRegressor(n_estimators=100, random_state=0).fit(X, y)
    fast = FastForest.from_sklearn(forest)
    Xq = np.random.default_rng(1).uniform(-0.2, 1.2, size=(300, 12))
    Xq[:7] = X[:7]  # rows equal to training values sit exactly on split points' neighbours
    assert np.max(np.abs(fast.predict(Xq) - forest.predict(Xq))) < 1e-9
    row = Xq[:1]
    assert np.max(np.abs(fast.predict(row) - forest.predict(row))) < 1e-9

    def best(fn, repeat=15):
        times = []
        for _ in range(repeat):
            t = time.perf_counter()
            fn(row)
            times.append(time.perf_counter() - t)
        return min(times)

    sk, ff = best(forest.predict), best(fast.predict)
    assert sk / ff >= 10.0, f"sklearn {sk * 1e3:.2f} ms vs fast {ff * 1e3:.3f} ms"


def test_save_load_round_trip_without_pickle(tmp_path):
    X, y = _data(200)
    model = CBSTRegressor(n_estimators=4, random_state=0).fit(X, y)
    card = {
        "block_size": 1.0,
        "paddle_size": [2.5, 0.15],
        "domain": Domain().as_dict(),
        "overshoot_allowance": {"1": 0.01},
        "model": {"params": model.get_params()},
    }
    card_path = save_model(model, card, tmp_path, "tiny")
    arrays = tmp_path / "tiny.npz"
    with zipfile.ZipFile(arrays) as zf:  # only .npy arrays, none of dtype object
        assert all(n.endswith(".npy") for n in zf.namelist())
    with np.load(arrays, allow_pickle=False) as data:
        assert all(data[k].dtype != object for k in data.files)
    loaded = load_model(card_path)
    assert loaded.predict(X).shape == (200, 4)
    assert np.array_equal(loaded.predict(X), model.predict(X))
    assert not hasattr(loaded, "estimator_")
    # A tampered arrays file is refused.
    raw = bytearray(arrays.read_bytes())
    raw[-10] ^= 0xFF
    arrays.write_bytes(bytes(raw))
    card_path.write_text(card_path.read_text())  # new mtime: bypass the load cache
    with pytest.raises(ValueError, match="checksum"):
        load_model(str(card_path))


def test_unknown_model_name():
    with pytest.raises(LookupError, match="unknown CBST model"):
        load_model("no-such-model")


def test_tune_reports_cv_rmse_and_r2_of_every_target():
    X, y = _data(240)
    groups = np.repeat(np.arange(120), 2)
    model, report = tune(
        X, y, groups, param_grid={"min_samples_leaf": [1, 4]}, n_estimators=5, cv=8, seed=0
    )
    assert report["cv_folds"] == 8 and report["examples"] == 120 and report["rows"] == 240
    assert set(report["cv_rmse"]) == set(report["cv_r2"]) == set(TARGET_NAMES)
    # dth is mostly one feature: out-of-fold predictions explain nearly all its variance
    assert report["cv_r2"]["dth"] > 0.9 and report["cv_r2"]["dx"] > 0.0
    assert report["best_params"]["min_samples_leaf"] in (1, 4)
    assert isinstance(model, CBSTRegressor)


def test_scores_are_rmse_and_the_coefficient_of_determination():
    from arrange_up.cbst.model import _scores

    y = np.array([[0.0, 1.0, 2.0, 0.0], [2.0, 1.0, 4.0, 0.0]])
    mean = np.repeat(y.mean(axis=0, keepdims=True), 2, axis=0)
    perfect, flat = _scores(y, y), _scores(y, mean)
    assert perfect["r2"]["dx"] == 1.0 and perfect["rmse"]["dth"] == 0.0
    assert flat["r2"]["dx"] == 0.0 and flat["rmse"]["dx"] == 1.0
    assert flat["r2"]["slip"] == 0.0  # a constant target: nothing to explain


@pytest.mark.parametrize("name", ["servo", "compliant"])
def test_shipped_models_and_cards(name):
    model = load_model(name)
    card = model.card_
    assert card["controller"]["kind"] == name
    assert card["features"] == list(FEATURE_NAMES) and card["targets"] == list(TARGET_NAMES)
    scores = card["scores"]
    assert scores["thesis_test_rmse"] == THESIS_TEST_RMSE and scores["cv_folds"] == 8
    for key in ("cv_rmse", "cv_r2", "test_rmse", "test_r2"):
        assert set(scores[key]) == set(TARGET_NAMES), key
    assert scores["test"]["seed"] != card["data"]["seed"]
    assert scores["test"]["rollouts_per_example"] == card["data"]["rollouts_per_example"]
    for key in ("examples", "rows", "rollouts_per_example", "seed"):
        assert key in card["data"]
    json.dumps(card)  # plain JSON
    # A typical row: a placed block (+-0.2 in, 15 deg) pushed alone against the wall.
    row = np.array([[0.05, 0.05, 3.0, 0.2, 0.2, 15.0, 0, 0, 0, 0.3, 0, 0]])
    assert model.domain_.contains(row).all()
    dx, dy, dth, slip = model.predict(row)[0]
    assert 0 <= dx < 0.2 and 0.1 < dy < 0.6 and 0 <= dth < 15 and slip < 0.1


def test_residual_learns_the_carry_over_without_edge_bias():
    # y = feature 4 + a small drift: a forest on y is biased at the edge of the data, a
    # forest on the residual is not; the prediction adds the feature back.
    X, _ = _data(400)
    y = np.stack([X[:, 0], X[:, 4] + 0.05 * X[:, 5]], axis=1)
    edge = X[np.argsort(X[:, 4])[:20]]
    plain = CBSTRegressor(n_estimators=20, min_samples_leaf=12, random_state=0).fit(X, y)
    resid = CBSTRegressor(
        n_estimators=20, min_samples_leaf=12, residual=((1, 4),), random_state=0
    ).fit(X, y)
    truth = edge[:, 4] + 0.05 * edge[:, 5]
    err_plain = np.abs(plain.predict(edge)[:, 1] - truth).mean()
    err_resid = np.abs(resid.predict(edge)[:, 1] - truth).mean()
    assert err_resid < 0.5 * err_plain
    with pytest.raises(ValueError, match="residual"):
        CBSTRegressor(n_estimators=2, residual=((5, 0),)).fit(X, y)


def test_load_by_name_from_an_installed_wheel_layout(tmp_path, monkeypatch):
    """A wheel carries semantics/ as arrange_up/_shipped/semantics/: found there first."""
    import shutil

    from arrange_up.cbst import store
    from arrange_up.io import resources

    shipped = tmp_path / "_shipped" / "semantics" / "cbst"
    shipped.mkdir(parents=True)
    source = store.model_dir()  # the checkout's, or the installed wheel's
    for suffix in (".json", ".npz"):
        shutil.copy(source / f"servo{suffix}", shipped / f"wheel-only{suffix}")
    card = json.loads((shipped / "wheel-only.json").read_text())
    card["arrays"]["file"] = "wheel-only.npz"
    (shipped / "wheel-only.json").write_text(json.dumps(card))
    monkeypatch.setattr(resources, "WHEEL_DIR", tmp_path / "_shipped")
    assert store.model_dir() == shipped
    model = load_model("wheel-only")
    assert model.card_["arrays"]["file"] == "wheel-only.npz"


def test_train_cbst_end_to_end_in_one_process(tmp_path):
    """Data through the local worker pool, then the grid search, in one process (the two
    must not fight over loky's shared executor), then a loadable model and card."""
    from arrange_up.cbst.model import train_cbst

    stages = []
    card = train_cbst(
        examples=16,
        rollouts_per_example=3,
        seed=5,
        workers=2,
        output_dir=tmp_path,
        test_examples=4,
        param_grid={"min_samples_leaf": [2, 4]},
        n_estimators=4,
        progress=lambda stage, done, total: stages.append((stage, done, total)),
    )
    assert ("data", 16, 16) in stages and ("test data", 4, 4) in stages
    assert stages[-1] == ("fit", 1, 1)
    assert card["data"]["examples"] == 16 and card["scores"]["cv_folds"] == 8
    assert card["scores"]["test"]["examples"] == 4 and card["scores"]["test"]["seed"] == 1
    assert (tmp_path / "compliant.data.jsonl").exists()
    assert (tmp_path / "compliant.test.jsonl").exists()
    coverage = card["scores"]["test_coverage"]
    assert set(coverage) == {"dx", "dy", "dth", "slip", "box"}
    assert all(0.0 <= share <= 1.0 for share in coverage.values())
    assert coverage["box"] <= min(coverage[name] for name in ("dx", "dy", "dth", "slip"))
    model = load_model(tmp_path / "compliant.json")
    assert model.predict(np.zeros((1, 12))).shape == (1, 4)


def test_coverage_counts_rollouts_inside_the_predicted_box():
    from arrange_up.cbst.model import _coverage

    predicted = np.array([[0.1, 0.2, 5.0, -0.3], [0.0, 0.1, 1.0, 0.05]])
    outcomes = [
        # inside; dx beyond; slip beyond the depth-1 allowance 0.01 (slip predicted < 0)
        np.array([[0.05, 0.1, 4.0, 0.0], [0.2, 0.1, 4.0, 0.0], [0.0, 0.0, 0.0, 0.02]]),
        # inside (slip 0.05 predicted); dth beyond
        np.array([[0.0, 0.1, 1.0, 0.05], [0.0, 0.0, 2.0, 0.0]]),
    ]
    coverage = _coverage(predicted, outcomes, np.array([1, 2]), {"1": 0.01, "2": 0.0})
    assert coverage["dx"] == pytest.approx(4 / 5) and coverage["dy"] == 1.0
    assert coverage["dth"] == pytest.approx(4 / 5) and coverage["slip"] == pytest.approx(4 / 5)
    assert coverage["box"] == pytest.approx(2 / 5)
