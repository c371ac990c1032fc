"""Tests of units (``arrange_up.model.units``): conversion to and from inches and radians."""

from __future__ import annotations

import math

import pytest

from arrange_up.model.units import Units


def test_defaults_are_inches_and_degrees() -> None:
    units = Units()
    assert (units.length, units.angle) == ("in", "deg")
    assert units.length_in(2.0) == 2.0
    assert units.angle_in(180.0) == pytest.approx(math.pi)


def test_unknown_units_are_refused() -> None:
    with pytest.raises(ValueError, match="unknown length unit 'ft'"):
        Units(length="ft")
    with pytest.raises(ValueError, match="unknown angle unit 'grad'"):
        Units(angle="grad")


def test_lengths_poses_and_angles_convert_both_ways() -> None:
    units = Units(length="cm", angle="rad")
    assert units.length_in(2.54) == pytest.approx(1.0)
    assert units.pose_in((2.54, 5.08, 0.5)) == pytest.approx((1.0, 2.0, 0.5))
    pose = (3.0, -1.5, 0.25)
    assert units.pose_out(units.pose_in(pose)) == pytest.approx(pose)
    assert Units(length="mm").length_out(1.0) == pytest.approx(25.4)
    assert Units(length="m").length_factor == pytest.approx(100 / 2.54)


def test_densities_convert_with_the_square_of_the_length_factor() -> None:
    units = Units(length="cm")
    # 1 mass unit per square centimetre is 2.54**2 per square inch.
    assert units.density_in(1.0) == pytest.approx(2.54**2)
    assert units.density_out(units.density_in(0.3)) == pytest.approx(0.3)
