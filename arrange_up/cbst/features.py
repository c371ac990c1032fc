"""PREDICT's inputs and outputs (thesis §3.2, "Learning a quantitative model for pushing").

All in the canonical frame (push toward ``+u``; the thesis's ``x`` is ``u`` and its ``y`` is
``v``). Lengths are in inches and angles in **degrees** (the thesis's units, so its RMSEs
compare directly with ours).

Feature vector (12 numbers), exactly the thesis's
``<Δq_p, Δq_c, Δq_n, q_p.y - q_c.y, q_n.y - q_c.y, ct>``:

====  =====================  ==============================================================
 #    name                   meaning
====  =====================  ==============================================================
0-2   dx_p, dy_p, dth_p      half-widths of the previous node: the paddle's pose uncertainty
                             when the current object is first in the train, else the
                             previous object's
3-5   dx_c, dy_c, dth_c      half-widths of the current object
6-8   dx_n, dy_n, dth_n      half-widths of the next object; ``0, 0, 0`` for the wall
9     y_p - y_c              offset across the push of the previous node's centre (the
                             paddle's commanded centre for the first object)
10    y_n - y_c              offset of the next object's centre; ``0`` for the wall
11    ct                     contact type (below)
====  =====================  ==============================================================

``ct`` (our encoding; the thesis names the feature without giving one) =
``2 * [previous is an object] + [next is an object]``:

* 0: paddle | current | wall      * 1: paddle | current | object
* 2: object | current | wall      * 3: object | current | object

The features are always computed from the belief **before** the push (the prior of all three
nodes), exactly as in the training data; the composition from the wall back toward the
paddle only enters through the position ``x_max`` of the targets.

Targets (4 numbers): three are the thesis's definitions over K rollouts ``i``:

* ``dx = x_max - min_i u_i``, where ``x_max = wall - (depth - 1/2) * d`` is the largest
  possible ``u`` of the object, all objects ahead of it flush and as far forward as possible
  (``depth`` = 1 for the object touching the wall, ``d`` the block width). The predicted
  interval is ``[x_max - dx, x_max]``: centre ``x_max - dx/2``, half-width ``dx/2``.
* ``dy = max_i |v_i - v|`` about the unchanged centre ``v``: the predicted half-width.
* ``dth = max_i |theta_i|`` (degrees, wrapped into the block's symmetry period around 0):
  the predicted half-width about the centre angle 0.
* ``slip = max(0, max_i u_i - x_max)`` (inches): **our addition**, not in the thesis. A train
  pushed off-centre can buckle: blocks squeeze out sideways and one may end beyond ``x_max``
  (how far, and how often: ``docs/cbst.md``, "PREDICT"), which the thesis's three targets
  cannot express, and a prediction that ignored it would claim a box the train has left. The
  semantics declines to predict when the predicted slip exceeds :data:`BUCKLE_LIMIT`, and
  otherwise widens the interval's upper end to ``x_max + max(slip, allowance)``, the allowance
  being the contact slop of the physics measured in the data (model card).

With ``GenerationSettings.quantile`` ``q`` below 1 (:mod:`.data`), every maximum over the
rollouts above is their ``q`` quantile instead (``dx``: of ``x_max - u_i``), so that a target
does not widen as the rollouts per example grow.

Validity domain: the model answers only for inputs inside the ranges it was trained on
(:class:`Domain`); outside them the semantics declines to predict.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from arrange_up.geometry.shapes import HalfWidths

__all__ = [
    "FEATURE_NAMES",
    "TARGET_NAMES",
    "THESIS_TEST_RMSE",
    "BUCKLE_LIMIT",
    "Domain",
    "contact_type",
    "feature_row",
]

FEATURE_NAMES: tuple[str, ...] = (
    "dx_p",
    "dy_p",
    "dth_p",
    "dx_c",
    "dy_c",
    "dth_c",
    "dx_n",
    "dy_n",
    "dth_n",
    "y_p-y_c",
    "y_n-y_c",
    "ct",
)
TARGET_NAMES: tuple[str, ...] = ("dx", "dy", "dth", "slip")
#: Units of the targets, in :data:`TARGET_NAMES` order.
TARGET_UNITS: tuple[str, ...] = ("in", "in", "deg", "in")
#: Predicted ``slip`` (inches) above which a train may buckle: no prediction.
BUCKLE_LIMIT = 0.1
#: The thesis's held-out test RMSE (§3.2), per target.
THESIS_TEST_RMSE: dict[str, float] = {"dx": 0.509, "dy": 0.079, "dth": 2.799}


def contact_type(prev_is_object: bool, next_is_object: bool) -> int:
    """``ct = 2 * [previous is an object] + [next is an object]`` (module docstring)."""
    return 2 * int(bool(prev_is_object)) + int(bool(next_is_object))


def feature_row(
    prev_half: HalfWidths,
    prev_v: float,
    prev_is_object: bool,
    cur_half: HalfWidths,
    cur_v: float,
    next_half: HalfWidths | None,
    next_v: float | None,
) -> list[float]:
    """The 12 features of one object (angles of the half-widths in radians here, degrees in
    the row). ``next_half is None`` means the next node is the wall."""
    deg = math.degrees
    wall = next_half is None
    nh = (0.0, 0.0, 0.0) if wall else next_half
    return [
        float(prev_half[0]),
        float(prev_half[1]),
        deg(prev_half[2]),
        float(cur_half[0]),
        float(cur_half[1]),
        deg(cur_half[2]),
        float(nh[0]),
        float(nh[1]),
        deg(nh[2]),
        float(prev_v - cur_v),
        0.0 if wall else float(next_v - cur_v),  # type: ignore[operator]
        float(contact_type(prev_is_object, not wall)),
    ]


@dataclass(frozen=True)
class Domain:
    """The input ranges the training data covers (inches, degrees); see :mod:`.data`.

    ``block_half``: largest half-widths of an object's belief; ``paddle_half``: of the
    paddle's pose uncertainty; ``paddle_offset``: largest ``|y_p - y_c|`` for the paddle.
    Offsets between objects are bounded by the certain-contact rule of
    :mod:`.contact_graph` (``MIN_OVERLAP``), which the data generator enforces as well.
    """

    block_half: tuple[float, float, float] = (0.4, 0.4, 15.0)
    paddle_half: tuple[float, float, float] = (0.1, 0.1, 5.0)
    paddle_offset: float = 1.5
    tolerance: float = 1e-6

    def contains(self, rows: np.ndarray) -> np.ndarray:
        """Per row of features: True if inside the domain."""
        rows = np.atleast_2d(np.asarray(rows, dtype=float))
        tol = self.tolerance
        block = np.asarray(self.block_half)
        paddle = np.asarray(self.paddle_half)
        prev_is_object = rows[:, 11] >= 2
        prev_limit = np.where(prev_is_object[:, None], block, paddle)
        ok = np.all(rows[:, 0:3] >= -tol, axis=1) & np.all(rows[:, 0:3] <= prev_limit + tol, axis=1)
        ok &= np.all(rows[:, 3:9] >= -tol, axis=1)
        ok &= np.all(rows[:, 3:6] <= block + tol, axis=1)
        ok &= np.all(rows[:, 6:9] <= block + tol, axis=1)
        ok &= prev_is_object | (np.abs(rows[:, 9]) <= self.paddle_offset + tol)
        ok &= np.all(np.isfinite(rows), axis=1)
        return ok

    def as_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> Domain:
        return cls(
            block_half=tuple(data["block_half"]),  # type: ignore[arg-type]
            paddle_half=tuple(data["paddle_half"]),  # type: ignore[arg-type]
            paddle_offset=float(data["paddle_offset"]),
            tolerance=float(data.get("tolerance", 1e-6)),
        )
