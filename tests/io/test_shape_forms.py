"""Tests of the shape forms (``arrange_up.io.shape_forms``) shared by the YAML reader and the
shape catalogue."""

from __future__ import annotations

import pytest

from arrange_up.geometry import shapes as geometry
from arrange_up.io.shape_catalogue import build_shape
from arrange_up.io.shape_forms import box_shape, ccw_polygon, centred_shape, convex_decomposition
from arrange_up.io.yaml_problem import load_problem_text

L_SHAPE = ((0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0))


def test_a_box_is_centred_and_remembers_its_size() -> None:
    shape = box_shape(2.0, 1.0, "slab")
    assert shape.box == (2.0, 1.0) and shape.name == "slab"
    assert shape.extent == pytest.approx((-1.0, -0.5, 1.0, 0.5))


def test_a_polygon_is_decomposed_counter_clockwise_and_centred_on_its_centroid() -> None:
    parts = convex_decomposition(L_SHAPE[::-1])  # clockwise input
    assert len(parts) >= 2
    assert all(geometry.is_convex(p) and ccw_polygon(p) == p for p in parts)
    shape = centred_shape(parts, "ell")
    assert shape.area == pytest.approx(3.0)
    assert geometry.parts_centroid(shape.parts) == pytest.approx((0.0, 0.0), abs=1e-12)


def test_the_yaml_reader_and_the_catalogue_build_the_same_shape() -> None:
    points = [list(p) for p in L_SHAPE]
    problem = load_problem_text(
        f"""\
name: ell
table: {{size: [10, 5]}}
shapes:
  ell: {{polygon: {points}}}
objects:
  A: {{kind: part, shape: ell}}
goal: {{tolerance: [0.2, 0.2], poses: {{A: [5, 2, 0]}}}}
"""
    )
    assert problem.object("A").shape == build_shape("polygon", points, "ell")
