"""Gear geometry against REFERENCE §3 check values and textbook formulas computed here."""

import math

import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
from jaxgear.gear.geometry import kinematics, normal_load, reduced_radius
from jaxgear.material import reduced_modulus


@pytest.fixture(scope="module")
def paper():
    pair = jg.presets.li2015_pair()
    return pair, jg.gear_geometry(pair)


def test_paper_pair_reference_values(paper):
    pair, geo = paper
    # REFERENCE §3 [computed]; tolerances are those of the issue (contact ratio ±0.001, angles ±0.01°).
    assert abs(float(geo.contact_ratio) - 1.7547) < 1e-3
    assert float(geo.base_radius[0]) == pytest.approx(70.4769e-3, abs=1e-7)
    assert float(geo.base_pitch) == pytest.approx(8.8564e-3, abs=1e-7)
    assert float(geo.path_length) == pytest.approx(15.5401e-3, abs=1e-7)
    deg = lambda v: math.degrees(float(v))
    assert deg(geo.roll_angle_start) == pytest.approx(14.537, abs=0.01)
    assert deg(geo.roll_angle_lowest_single) == pytest.approx(19.971, abs=0.01)
    assert deg(geo.roll_angle_pitch) == pytest.approx(20.854, abs=0.01)
    assert deg(geo.roll_angle_highest_single) == pytest.approx(21.737, abs=0.01)
    assert deg(geo.roll_angle_end) == pytest.approx(27.171, abs=0.01)
    # Reduced radius at the pitch point: 12.826 mm (±1 %, the tolerance).
    assert float(reduced_radius(geo, geo.pitch_point)) == pytest.approx(12.826e-3, rel=1e-3)


@pytest.mark.parametrize(
    "torque, ph_ref, b_ref", [(700.0, 1.184e9, 267e-6), (1500.0, 1.733e9, 391e-6)]
)
def test_hertz_at_pitch_one_pair(paper, torque, ph_ref, b_ref):
    pair, geo = paper
    w = normal_load(pair, torque) / pair.face_width
    r = reduced_radius(geo, geo.pitch_point)
    e = reduced_modulus(*pair.materials)
    # REFERENCE §3: 1.184 / 1.733 GPa, 267 / 391 µm; ±1 % (the tolerance).
    assert float(jg.hertz_pressure(w, r, e)) == pytest.approx(ph_ref, rel=0.01)
    assert float(jg.hertz_half_width(w, r, e)) == pytest.approx(b_ref, rel=0.01)


def test_kinematics_paper(paper):
    pair, geo = paper
    omega = 1000.0 * 2 * math.pi / 60
    s = jnp.linspace(geo.path_start, geo.path_end, 7)
    kin = kinematics(pair, geo, s, omega)
    # Unity ratio: ur = 2.686 m/s per 1000 rpm along the whole path (REFERENCE §3).
    np.testing.assert_allclose(kin.rolling_velocity, 2.686, rtol=1e-3)
    # us = ω(2s − T1T2): ±1.627 m/s at the path ends, 0 at the pitch point.
    assert float(kin.sliding_velocity[0]) == pytest.approx(-1.627, abs=2e-3)
    assert float(kin.sliding_velocity[-1]) == pytest.approx(1.627, abs=2e-3)
    kp = kinematics(pair, geo, geo.pitch_point, omega)
    assert abs(float(kp.sliding_velocity)) < 1e-12
    assert float(normal_load(pair, 700.0)) == pytest.approx(9932.0, rel=1e-3)


def _textbook(z1, z2, m, alpha, x1=0.0, x2=0.0, ha=1.0):
    """Independent textbook involute formulas (e.g. Maitra, Handbook of Gear Design)."""
    inv = lambda a: math.tan(a) - a
    inv_w = inv(alpha) + 2 * math.tan(alpha) * (x1 + x2) / (z1 + z2)
    lo, hi = 1e-6, 1.5
    for _ in range(200):  # bisection: a different root finder from the library's Newton
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if inv(mid) < inv_w else (lo, mid)
    alpha_w = 0.5 * (lo + hi)
    a_w = m * (z1 + z2) / 2 * math.cos(alpha) / math.cos(alpha_w)
    rb1, rb2 = m * z1 / 2 * math.cos(alpha), m * z2 / 2 * math.cos(alpha)
    ra1, ra2 = m * (z1 / 2 + ha + x1), m * (z2 / 2 + ha + x2)
    pb = math.pi * m * math.cos(alpha)
    path = math.sqrt(ra1**2 - rb1**2) + math.sqrt(ra2**2 - rb2**2) - a_w * math.sin(alpha_w)
    return dict(a_w=a_w, alpha_w=alpha_w, rb=(rb1, rb2), ra=(ra1, ra2), cr=path / pb, pb=pb)


@pytest.mark.parametrize("shift", [(0.0, 0.0), (0.3, -0.1), (0.25, 0.25)])
def test_non_unity_pair_against_textbook(shift):
    z1, z2, m, alpha = 23, 47, 4e-3, math.radians(25)
    pair = jg.GearPair(
        teeth=(z1, z2), module=m, pressure_angle=alpha, face_width=0.03, profile_shift=shift
    )
    geo = jg.gear_geometry(pair)
    ref = _textbook(z1, z2, m, alpha, *shift)
    assert float(geo.centre_distance) == pytest.approx(ref["a_w"], rel=1e-10)
    assert float(geo.operating_pressure_angle) == pytest.approx(ref["alpha_w"], rel=1e-9)
    np.testing.assert_allclose(geo.base_radius, ref["rb"], rtol=1e-12)
    np.testing.assert_allclose(geo.tip_radius, ref["ra"], rtol=1e-12)
    assert float(geo.contact_ratio) == pytest.approx(ref["cr"], rel=1e-9)
    assert float(geo.base_pitch) == pytest.approx(ref["pb"], rel=1e-12)
    # Pitch point: curvature radii ρj = r_w,j sin α_w, sliding zero there, gear ratio of speeds.
    omega1 = 100.0
    kin = kinematics(pair, geo, geo.pitch_point, omega1)
    assert float(kin.sliding_velocity) == pytest.approx(0.0, abs=1e-12)
    rw1 = ref["rb"][0] / math.cos(ref["alpha_w"])
    assert float(kin.u1) == pytest.approx(omega1 * rw1 * math.sin(ref["alpha_w"]), rel=1e-10)


def test_roll_angle_maps_round_trip(paper):
    _, geo = paper
    from jaxgear.gear.geometry import contact_position, position_from_roll_angle, roll_angles

    s = contact_position(geo, jnp.asarray([0.0, 0.3, 0.9]), 0)
    e1, e2 = roll_angles(geo, s)
    np.testing.assert_allclose(position_from_roll_angle(geo, e1), s, rtol=1e-14)
    # Both roll angles add up to the LOA length over the base radius for unity gears.
    np.testing.assert_allclose(e1 + e2, geo.line_of_action_length / geo.base_radius[0], rtol=1e-14)
