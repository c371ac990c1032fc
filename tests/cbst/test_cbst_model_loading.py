"""Loading a CBST model checks its arrays against its card, and a model train-cbst made is
usable by the planner and the unified-planning engine."""

from __future__ import annotations

import dataclasses
import hashlib
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import arrange_up.cbst.store as store
from arrange_up.cbst.features import FEATURE_NAMES, Domain
from arrange_up.cbst.model import CBSTRegressor
from arrange_up.cbst.store import load_model, model_dir, save_model
from arrange_up.io.domains import load as load_domain
from arrange_up.model.problem import Controller, ControllerKind
from arrange_up.planning.planner import plan
from arrange_up.transitions import make_semantics


def load(name: str):
    """A shipped problem under the servo controller, the one the model of one's own (a copy
    of the shipped servo model) was trained under."""
    return dataclasses.replace(load_domain(name), controller=Controller(kind=ControllerKind.SERVO))


@pytest.fixture(scope="module")
def tiny():
    rng = np.random.default_rng(0)
    X = rng.uniform(0.0, 1.0, size=(200, len(FEATURE_NAMES)))
    y = np.stack([X[:, 0], X[:, 1] ** 2, X[:, 2], X[:, 3]], axis=1)
    return CBSTRegressor(n_estimators=3, random_state=0).fit(X, y)


CARD = {
    "block_size": 1.0,
    "paddle_size": [2.5, 0.15],
    "domain": Domain().as_dict(),
    "overshoot_allowance": {"1": 0.01},
    "features": list(FEATURE_NAMES),
}


def _saved(tiny, folder: Path, edit=None, card_edit=None) -> Path:
    """The tiny model saved into ``folder``, its arrays edited by ``edit`` and its card by
    ``card_edit``, with the card's checksum and size made to match (a consistent tampering,
    which the checksum alone cannot catch)."""
    card_path = save_model(tiny, CARD, folder, "tiny")
    arrays_path = folder / "tiny.npz"
    if edit is not None:
        with np.load(arrays_path) as data:
            arrays = {k: data[k].copy() for k in data.files}
        edit(arrays)
        np.savez_compressed(arrays_path, **arrays)
    card = json.loads(card_path.read_text())
    raw = arrays_path.read_bytes()
    card["arrays"].update(sha256=hashlib.sha256(raw).hexdigest(), bytes=len(raw))
    if card_edit is not None:
        card_edit(card)
    card_path.write_text(json.dumps(card))
    return card_path


def test_a_sound_model_loads(tiny, tmp_path):
    model = load_model(_saved(tiny, tmp_path))
    assert model.forest_.depth == tiny.forest_.depth


def _set(key, index, value):
    def edit(arrays):
        arrays[key][index] = value

    return edit


def _internal(arrays, k: int = 0) -> int:
    """The index of the ``k``-th split node (not a leaf)."""
    return int(np.flatnonzero(arrays["left"] != np.arange(len(arrays["left"])))[k])


@pytest.mark.parametrize(
    ("edit", "card_edit", "says"),
    [
        (_set("meta", 0, 10**12), None, "depth 1000000000000 recorded"),
        (_set("meta", 1, 11), None, "11 features"),
        (_set("value", (0, 0), np.nan), None, "finite"),
        (lambda a: a["threshold"].__setitem__(_internal(a), np.nan), None, "finite"),
        (lambda a: a["left"].__setitem__(_internal(a, 1), 0), None, "before its parent"),
        (lambda a: a.__setitem__("extra", np.zeros(3)), None, "extra are unknown"),
        (lambda a: a.__setitem__("value", a["value"][:, :3]), None, "value has shape"),
        (lambda a: a.__setitem__("roots", a["roots"][:2]), None, "trees"),
        (None, lambda c: c["arrays"].update(depth=99), "the card says 99"),
        (None, lambda c: c["arrays"].update(nodes=1), "the card says 1"),
        (None, lambda c: c["arrays"].update(file="/dev/zero"), "not a file name beside"),
        (None, lambda c: c["arrays"].update(file="../x.npz"), "not a file name beside"),
        (None, lambda c: c.update(block_size=float("nan")), "block_size"),
        (None, lambda c: c["domain"].update(paddle_offset=float("nan")), "paddle_offset"),
        (None, lambda c: c["arrays"].update(bytes=10), "the card says 10"),
        (None, lambda c: c.pop("domain"), "not a valid CBST model card"),
    ],
)
def test_an_unsound_model_is_one_value_error_naming_the_file(tiny, tmp_path, edit, card_edit, says):
    card_path = _saved(tiny, tmp_path, edit, card_edit)
    with pytest.raises(ValueError) as caught:
        load_model(card_path)
    message = str(caught.value)
    assert message.startswith(str(tmp_path)), message
    assert says in message


def test_an_array_unpacking_beyond_the_limit_is_refused(tiny, tmp_path, monkeypatch):
    card_path = _saved(tiny, tmp_path)
    monkeypatch.setattr(store, "MAX_ARRAY_BYTES", 64)
    with pytest.raises(ValueError, match=r"tiny\.npz: arrays .* unpack to more than 64 bytes"):
        load_model(card_path)


def test_an_arrays_file_that_is_a_link_elsewhere_is_refused(tiny, tmp_path):
    card_path = _saved(tiny, tmp_path / "a")
    target = tmp_path / "a" / "tiny.npz"
    moved = tmp_path / "elsewhere.npz"
    shutil.move(target, moved)
    target.symlink_to(moved)
    with pytest.raises(ValueError, match="no such arrays file beside the card"):
        load_model(card_path)


# -- a model of one's own, for the planner and the engine ----------------------------------------
@pytest.fixture(scope="module")
def own_model(tmp_path_factory) -> Path:
    """The shipped model saved as a model of one's own (as train-cbst writes one)."""
    folder = tmp_path_factory.mktemp("own")
    shipped = load_model("servo")
    card = {k: v for k, v in shipped.card_.items() if k not in ("format", "name", "arrays")}
    return save_model(shipped, card, folder, "mine")


def test_the_planner_plans_with_a_model_of_ones_own(own_model):
    problem = load("blocks-2")
    default = plan(problem, semantics="cbst", seed=0, max_nodes=300)
    mine = plan(problem, semantics="cbst", seed=0, max_nodes=300, model=own_model)
    assert default.solved and mine.actions == default.actions


def test_a_model_is_refused_where_it_cannot_be_used(own_model, tmp_path):
    problem = load("blocks-1")
    with pytest.raises(ValueError, match="no learned model"):
        plan(problem, semantics="particles", particles=2, model=own_model)
    with pytest.raises(ValueError, match="no learned model"):
        make_semantics("deterministic", problem, model=own_model)
    with pytest.raises(LookupError, match="unknown CBST model"):
        plan(problem, semantics="cbst", model=tmp_path / "none.json")
    assert (model_dir() / "servo.json").is_file() and (model_dir() / "compliant.json").is_file()


def test_the_engine_takes_a_model_parameter(own_model, tmp_path):
    from unified_planning.engines import PlanGenerationResultStatus as Status
    from unified_planning.shortcuts import OneshotPlanner

    from arrange_up.up.compile import to_up

    params = {"semantics": "cbst", "seed": 0, "max_nodes": 300, "model": str(own_model)}
    with OneshotPlanner(name="arrange-up", params=params) as planner:
        result = planner.solve(to_up(load("blocks-2")), timeout=120)
    assert result.status is Status.SOLVED_SATISFICING
    bad = _saved_copy_with_depth(own_model, tmp_path)
    with pytest.raises(ValueError, match="depth"):
        OneshotPlanner(name="arrange-up", params={**params, "model": str(bad)})
    with pytest.raises(ValueError, match="cbst"):
        OneshotPlanner(name="arrange-up", params={"semantics": "particles", "model": "default"})


def _saved_copy_with_depth(card_path: Path, folder: Path) -> Path:
    for suffix in (".json", ".npz"):
        shutil.copy(card_path.with_suffix(suffix), folder / f"bad{suffix}")
    with np.load(folder / "bad.npz") as data:
        arrays = {k: data[k].copy() for k in data.files}
    arrays["meta"][0] = 10**9
    np.savez_compressed(folder / "bad.npz", **arrays)
    card = json.loads((folder / "bad.json").read_text())
    raw = (folder / "bad.npz").read_bytes()
    card["arrays"].update(file="bad.npz", sha256=hashlib.sha256(raw).hexdigest(), bytes=len(raw))
    (folder / "bad.json").write_text(json.dumps(card))
    return folder / "bad.json"
