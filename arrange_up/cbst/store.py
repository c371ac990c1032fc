"""Where CBST models live and how they are written and read back (thesis §3.2).

* :func:`save_model` writes ``NAME.npz`` (the trees' arrays, numbers only) and ``NAME.json``
  (the model card); :func:`load_model` reads them back (a
  :class:`~arrange_up.cbst.trained.TrainedModel`) with ``allow_pickle=False`` after checking
  the arrays' SHA-256 against the card. No model file is ever pickled, and loading never
  imports scikit-learn (about a second, a tenth of a CBST blocks-9 search).

Shipped models live in the repository's ``semantics/cbst/`` (an installed wheel carries it as
``arrange_up/_shipped/semantics/cbst``), one per controller kind (:data:`SHIPPED_MODELS`);
``load_model("default", controller)`` finds the one for ``controller`` in either.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from arrange_up.cbst.fast_forest import FastForest
from arrange_up.cbst.features import FEATURE_NAMES, TARGET_NAMES, Domain
from arrange_up.cbst.trained import TrainedModel
from arrange_up.io.resources import shipped_dir
from arrange_up.model.problem import DEFAULT_CONTROLLER, Controller, ControllerKind

if TYPE_CHECKING:
    from arrange_up.cbst.estimator import CBSTRegressor

__all__ = [
    "CARD_FORMAT",
    "DEFAULT_MODEL",
    "MAX_ARRAYS_BYTES",
    "MAX_ARRAY_BYTES",
    "SHIPPED_MODELS",
    "load_model",
    "model_dir",
    "save_model",
    "shipped_name",
]

CARD_FORMAT = "arrange-up-cbst-model/1"

#: The name of the shipped model for the problem's controller.
DEFAULT_MODEL = "default"

#: The shipped model trained under each controller kind (``semantics/cbst/NAME.json``).
SHIPPED_MODELS: dict[ControllerKind, str] = {
    ControllerKind.COMPLIANT: "compliant",
    ControllerKind.SERVO: "servo",
}


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


#: The largest arrays file loading reads, and the largest array in it once unpacked (256 MiB,
#: far above any shipped model's): a model file can never exhaust memory.
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
