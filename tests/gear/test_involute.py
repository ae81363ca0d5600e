"""The array formulas of gear/involute.py against a textbook example and closed forms."""

import math

import jax
import numpy as np
import pytest

from jaxgear.gear import involute as inv


def test_inverse_involute_round_trip_and_implicit_derivative():
    alpha = np.radians(np.linspace(5.0, 50.0, 46))
    value = np.asarray(inv.involute(alpha))
    np.testing.assert_allclose(inv.inverse_involute(value), alpha, rtol=1e-14)
    # dα/d inv = 1/tan² α (the implicit derivative), in both modes.
    expected = 1.0 / np.tan(alpha) ** 2
    np.testing.assert_allclose(
        jax.vmap(jax.grad(inv.inverse_involute))(value), expected, rtol=1e-12
    )
    np.testing.assert_allclose(
        jax.vmap(jax.jacfwd(inv.inverse_involute))(value), expected, rtol=1e-12
    )


def test_shifted_pair_textbook_example():
    # KHK Gear Technical Reference, profile-shifted spur gears: m 3 mm, α 20°, z 12/24,
    # x 0.6/0.36 give inv α_w = 0.034316, α_w = 26.0886° and a = 56.4999 mm (the quoted digits
    # set the tolerances).
    teeth, shift, alpha = (12, 24), np.array([0.6, 0.36]), math.radians(20.0)
    alpha_w = float(inv.working_pressure_angle(alpha, teeth, shift))
    assert float(inv.involute(alpha_w)) == pytest.approx(0.034316, abs=1e-6)
    assert math.degrees(alpha_w) == pytest.approx(26.0886, abs=1e-4)
    a_w = float(inv.zero_backlash_centre_distance(3e-3, teeth, alpha, shift))
    assert a_w * 1e3 == pytest.approx(56.4999, abs=1e-4)
    # The same centre distance from the base radii: a_w cos α_w = rb1 + rb2.
    rb = np.asarray(inv.base_radius(3e-3, np.array(teeth), alpha))
    assert float(inv.operating_pressure_angle(rb, a_w)) == pytest.approx(alpha_w, rel=1e-12)


def test_unshifted_pair_closed_forms():
    alpha, m, z = math.radians(20.0), 3e-3, np.array([50, 50])
    a_w = float(inv.zero_backlash_centre_distance(m, z, alpha, np.zeros(2)))
    assert a_w == pytest.approx(m * 100 / 2, rel=1e-15)
    np.testing.assert_allclose(inv.tip_radius(m, z, 1.0, 0.0), 0.078, rtol=1e-15)
    np.testing.assert_allclose(inv.root_radius(m, z, 5.0 / 3.0, 0.0), 0.070, rtol=1e-15)
    np.testing.assert_allclose(
        inv.base_pitch(inv.base_radius(m, z, alpha), z), math.pi * m * math.cos(alpha), rtol=1e-15
    )
    # Roll angle and its guard below the base circle: value 0 and a finite derivative.
    rb = float(inv.base_radius(m, 50, alpha))
    assert float(inv.roll_angle(0.078, rb)) == pytest.approx(math.sqrt(0.078**2 - rb**2) / rb)
    assert float(inv.roll_angle(0.070, rb)) == 0.0
    assert float(jax.grad(inv.roll_angle)(0.070, rb)) == 0.0
    # Tooth thickness at the reference circle: half the pitch, unshifted.
    assert float(inv.reference_tooth_thickness(m, alpha, 0.0)) == pytest.approx(math.pi * m / 2)
    # Undercut limit of 20° full-depth teeth: 2/sin² 20° = 17.1.
    assert float(inv.undercut_limit(alpha, 1.0, 0.0)) == pytest.approx(17.097, abs=1e-3)
