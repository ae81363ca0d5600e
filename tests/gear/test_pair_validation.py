"""Bad input to GearPair, TipRelief, Bearings, Material and mesh_cycle: ValueError naming the field,
the value and the valid range."""

import math

import pytest

import jaxgear as jg

BASE = dict(teeth=(23, 47), module=4e-3, pressure_angle=math.radians(25), face_width=0.03)


def _pair(**kw):
    return jg.GearPair(**{**BASE, **kw})


def test_issue_example_constructs():
    pair = _pair()
    assert pair.teeth == (23, 47)
    # Textbook contact ratio of the unshifted pair, written out here:
    # [√(ra1² − rb1²) + √(ra2² − rb2²) − a sin α] / (π m cos α).
    m, a = 4e-3, math.radians(25)
    rb = [m * z / 2 * math.cos(a) for z in (23, 47)]
    ra = [m * (z / 2 + 1) for z in (23, 47)]
    path = sum(math.sqrt(r**2 - b**2) for r, b in zip(ra, rb)) - m * 35 * math.sin(a)
    assert float(jg.gear_geometry(pair).contact_ratio) == pytest.approx(
        path / (math.pi * m * math.cos(a)), rel=1e-12
    )


@pytest.mark.parametrize(
    "kw, field",
    [
        (dict(module=0.0), "module"),
        (dict(module=-3e-3), "module"),
        (dict(face_width=0.0), "face_width"),
        (dict(face_width=-0.01), "face_width"),
        (dict(module=float("nan")), "module"),
        (dict(face_width=float("inf")), "face_width"),
        (dict(pressure_angle=float("nan")), "pressure_angle"),
        (dict(pressure_angle=math.radians(60)), "pressure_angle"),
        (dict(backlash=-1e-4), "backlash"),
        (dict(blank_mass=(0.0, 1.0)), "blank_mass"),
        (dict(blank_inertia=(1e-3, -1e-3)), "blank_inertia"),
        (dict(profile_shift=(float("nan"), 0.0)), "profile_shift"),
        (dict(teeth=(23.5, 47)), "teeth[0]"),
        (dict(teeth=(3, 47)), "teeth[0]"),
    ],
)
def test_bad_scalar_inputs_name_the_field(kw, field):
    with pytest.raises(ValueError) as err:
        _pair(**kw)
    msg = str(err.value)
    assert field in msg
    assert "valid" in msg or "must" in msg


def test_undercut_is_rejected_with_the_minimum():
    # 20° full-depth teeth undercut below z = 2/sin²20° ≈ 17.1.
    with pytest.raises(ValueError, match=r"teeth\[0\] = 12 undercuts.*teeth\[0\] >= 18"):
        jg.GearPair(teeth=(12, 40), module=3e-3, pressure_angle=math.radians(20), face_width=0.02)
    # A positive profile shift removes the undercut.
    jg.GearPair(
        teeth=(12, 40),
        module=3e-3,
        pressure_angle=math.radians(20),
        face_width=0.02,
        profile_shift=(0.4, 0.0),
    )


def test_contact_ratio_below_one_is_rejected():
    # Short teeth (addendum 0.3 m) give a contact ratio well below 1.
    with pytest.raises(ValueError, match=r"contact ratio = 0\.\d+ .*valid range: \[1, 2\)"):
        jg.GearPair(
            teeth=(30, 30),
            module=3e-3,
            pressure_angle=math.radians(20),
            face_width=0.02,
            addendum_coefficient=0.3,
        )


def test_contact_ratio_two_or_more_is_rejected():
    with pytest.raises(ValueError, match="contact ratio"):
        jg.GearPair(
            teeth=(80, 80),
            module=2e-3,
            pressure_angle=math.radians(14.5),
            face_width=0.02,
            addendum_coefficient=1.4,
            dedendum_coefficient=1.7,
        )


def test_relief_start_outside_path_is_rejected():
    with pytest.raises(
        ValueError, match=r"tip_relief\.start_roll_angle\[0\] = 5 deg .*valid range"
    ):
        jg.presets.li2015_pair(tip_relief=10e-6, relief_start_deg=5.0)
    with pytest.raises(ValueError, match=r"tip_relief\.start_roll_angle\[0\] = 30 deg"):
        jg.presets.li2015_pair(tip_relief=10e-6, relief_start_deg=30.0)


def test_relief_and_bearings_and_material_validation():
    with pytest.raises(ValueError, match=r"TipRelief\.amount"):
        jg.TipRelief(amount=-1e-6, start_roll_angle=0.36)
    with pytest.raises(ValueError, match=r"TipRelief\.shape = 'cubic'.*valid choices"):
        jg.TipRelief(amount=1e-6, start_roll_angle=0.36, shape="cubic")
    with pytest.raises(ValueError, match=r"Bearings\.ky"):
        jg.Bearings(ky=0.0)
    with pytest.raises(ValueError, match=r"Bearings\.cy"):
        jg.Bearings(cy=-1.0)
    with pytest.raises(ValueError, match=r"Material\.poisson_ratio = 0\.6.*valid range"):
        jg.Material(
            youngs_modulus=2e11,
            poisson_ratio=0.6,
            density=7800.0,
            thermal_conductivity=45.0,
            specific_heat=470.0,
        )


def test_mesh_cycle_bad_input():
    pair = jg.presets.li2015_pair()
    with pytest.raises(ValueError, match=r"torque = -5 N m is out of range"):
        jg.mesh_cycle(pair, -5.0)
    with pytest.raises(ValueError, match="n_positions"):
        jg.mesh_cycle(pair, 700.0, 2)
    with pytest.raises(ValueError, match="stiffness = 'fem'"):
        jg.mesh_cycle(pair, 700.0, 16, stiffness="fem")
