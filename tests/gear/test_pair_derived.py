"""GearPair's derived quantities, overrides and validated substitution.

Tip/root radii, centre distance, blanks and bore follow the fields they derive from whatever way a
field is substituted; given values (overrides) stay as given; substitution by ``replace`` is
validated and broadcast, and ``jaxgear._inputs.validate`` catches a bad ``eqx.tree_at``.
"""

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
from jaxgear._inputs import validate

ARGS = dict(teeth=(50, 50), module=3e-3, pressure_angle=math.radians(20.0), face_width=0.02)


def test_paper_pair_is_derived_from_its_coefficients():
    pair = jg.presets.li2015_pair()
    assert pair.overrides == ()
    # REFERENCE §2: outside / root diameter 156 / 140 mm, centre distance 150 mm (to round-off).
    np.testing.assert_allclose(pair.tip_radius, 0.078, rtol=1e-15)
    np.testing.assert_allclose(pair.root_radius, 0.070, rtol=1e-15)
    assert float(pair.centre_distance) == pytest.approx(0.150, rel=1e-15)
    cal = jg.presets.li2015_pair_calibrated()
    assert cal.overrides == ("blank_mass", "blank_inertia")
    np.testing.assert_array_equal(cal.blank_mass, [5.316, 5.316])
    np.testing.assert_array_equal(cal.blank_inertia, [0.4540, 0.4540])


@pytest.mark.parametrize("how", ["replace", "tree_at"])
def test_substituted_module_gives_a_consistent_pair(how):
    base = jg.presets.li2015_pair_calibrated()
    m = 2.5e-3
    if how == "replace":
        pair = base.replace(module=m)
    else:
        pair = eqx.tree_at(lambda p: p.module, base, jnp.asarray(m))
    validate(pair)
    # Solid-geometry formulas written out: m (z/2 + 1), m (z/2 − 5/3), m (z1 + z2)/2.
    np.testing.assert_allclose(pair.tip_radius, m * 26, rtol=1e-15)
    np.testing.assert_allclose(pair.root_radius, m * (25 - 5 / 3), rtol=1e-14)
    assert float(pair.centre_distance) == pytest.approx(m * 50, rel=1e-15)
    np.testing.assert_allclose(pair.bore_radius, 0.5 * m * (25 - 5 / 3), rtol=1e-14)
    # Overridden blanks stay as given.
    np.testing.assert_array_equal(pair.blank_mass, base.blank_mass)
    # A geometrically similar pair: same contact ratio and roll angles.
    g0, g1 = jg.gear_geometry(base), jg.gear_geometry(pair)
    assert float(g1.contact_ratio) == pytest.approx(float(g0.contact_ratio), rel=1e-13)
    np.testing.assert_allclose(g1.roll_angle_tip, g0.roll_angle_tip, rtol=1e-13)
    # The default blanks are solid disks of reference radius: ρ π r² b and m r²/2.
    plain = jg.presets.li2015_pair().replace(module=m)
    r = m * 25
    np.testing.assert_allclose(plain.blank_mass, 7850 * math.pi * r**2 * 0.02, rtol=1e-14)
    np.testing.assert_allclose(plain.blank_inertia, 0.5 * plain.blank_mass * r**2, rtol=1e-14)


def test_overrides_stay_as_given_and_can_be_removed():
    pair = jg.GearPair(**ARGS, tip_radius=0.0779, centre_distance=0.1501)
    assert pair.overrides == ("tip_radius", "centre_distance")
    moved = pair.replace(face_width=0.025, pressure_angle=math.radians(20.5))
    np.testing.assert_array_equal(moved.tip_radius, [0.0779, 0.0779])
    assert float(moved.centre_distance) == 0.1501
    derived = moved.replace(tip_radius=None, centre_distance=None)
    assert derived.overrides == ()
    np.testing.assert_allclose(derived.tip_radius, 0.078, rtol=1e-15)
    again = derived.replace(root_radius=(0.0699, 0.0698))
    assert again.overrides == ("root_radius",)
    np.testing.assert_array_equal(again.root_radius, [0.0699, 0.0698])


def test_structure_does_not_depend_on_values_and_fields_are_float64():
    a = jg.presets.li2015_pair()
    b = a.replace(module=2.9e-3, **{"tip_relief.amount": 0.0})
    assert jax.tree_util.tree_structure(a) == jax.tree_util.tree_structure(b)
    leaves = jax.tree_util.tree_leaves(b)
    assert all(getattr(leaf, "dtype", None) == jnp.float64 for leaf in leaves)
    # Whatever the caller passes (NumPy float32, Python int) the float fields are float64.
    pair = jg.GearPair(
        teeth=(50, 50),
        module=np.float32(3e-3),
        pressure_angle=math.radians(20.0),
        face_width=0.02,
        backlash=0,
        bearings=jg.Bearings(ky=1_150_000_000, ct=10),
        material=jg.Material(
            youngs_modulus=207_000_000_000,
            poisson_ratio=0.3,
            density=7850,
            thermal_conductivity=46.7,
            specific_heat=470,
        ),
    )
    assert all(leaf.dtype == jnp.float64 for leaf in jax.tree_util.tree_leaves(pair))

    # A new module never recompiles.
    @eqx.filter_jit
    @eqx.debug.assert_max_traces(max_traces=1)
    def tip(p):
        return p.tip_radius

    for m in (3e-3, 2.9e-3, 3.1e-3):
        tip(a.replace(module=m))


def test_replace_broadcasts_and_reaches_nested_fields():
    pair = jg.presets.li2015_pair()
    out = pair.replace(
        blank_mass=3.0,
        profile_shift=0.1,
        **{"tip_relief.amount": 5e-6, "bearings.ky": 1e9, "materials.1.youngs_modulus": 210e9},
    )
    np.testing.assert_array_equal(out.blank_mass, [3.0, 3.0])
    np.testing.assert_array_equal(out.profile_shift, [0.1, 0.1])
    np.testing.assert_array_equal(out.tip_relief.amount, [5e-6, 5e-6])
    np.testing.assert_array_equal(out.bearings.ky, [1e9, 1e9])
    assert float(out.materials[1].youngs_modulus) == 210e9
    assert float(out.materials[0].youngs_modulus) == 207e9
    assert out.tip_relief.replace(shape="parabolic").shape == ("parabolic", "parabolic")
    with pytest.raises(ValueError, match="no field 'modul'.*valid fields: teeth, module"):
        pair.replace(modul=3e-3)
    # Traced values too (checks skipped, as in the constructor): a_w = m (z1 + z2)/2.
    assert float(jax.grad(lambda m: pair.replace(module=m).centre_distance)(3e-3)) == 50.0


def test_scalar_put_in_by_tree_at_is_a_shape_error_naming_the_field():
    pair = jg.presets.li2015_pair()
    bad = eqx.tree_at(lambda p: p.tip_relief.amount, pair, jnp.asarray(5e-6))
    with pytest.raises(ValueError, match=r"TipRelief\.amount has shape \(\); valid shape: \(2,\)"):
        validate(bad)
    bad = eqx.tree_at(lambda p: p.bearings.ky, pair, jnp.asarray(1e9))
    with pytest.raises(ValueError, match=r"Bearings\.ky has shape \(\); valid shape: \(2,\)"):
        validate(bad)
    bad = eqx.tree_at(lambda p: p.module, pair, jnp.asarray([3e-3, 3e-3]))
    with pytest.raises(ValueError, match=r"module has shape \(2,\); valid shape: \(\)"):
        validate(bad)
    bad = eqx.tree_at(lambda p: p.materials[0].density, pair, jnp.full(2, 7850.0))
    with pytest.raises(ValueError, match=r"Material\.density has shape \(2,\); valid shape: \(\)"):
        validate(bad)


def _raw(pair, where, value):
    return eqx.tree_at(where, pair, jnp.asarray(value))


@pytest.mark.parametrize(
    "changes, where, value, message",
    [
        (
            {"tip_relief.amount": -50e-6},
            lambda p: p.tip_relief.amount,
            [-50e-6, -50e-6],
            r"TipRelief\.amount = \[-5\.e-05 -5\.e-05\] m is out of range",
        ),
        (
            {"tip_relief.start_roll_angle": math.radians(30.0)},
            lambda p: p.tip_relief.start_roll_angle,
            [math.radians(30.0)] * 2,
            r"tip_relief\.start_roll_angle\[0\] = 30 deg is outside the path of contact",
        ),
        ({"face_width": -0.02}, lambda p: p.face_width, -0.02, r"face_width = -0\.02 m"),
        ({"module": 0.0}, lambda p: p.module, 0.0, r"module = 0 m is out of range"),
        (
            {"bearings.ky": -1.0},
            lambda p: p.bearings.ky,
            [-1.0, -1.0],
            r"Bearings\.ky = \[-1\. -1\.\] N/m is out of range",
        ),
        (
            {"materials.0.poisson_ratio": 0.7},
            lambda p: p.materials[0].poisson_ratio,
            0.7,
            r"Material\.poisson_ratio = 0\.7 is out of range",
        ),
    ],
)
def test_invalid_substitution_is_rejected_by_replace_and_validate(changes, where, value, message):
    pair = jg.presets.li2015_pair()
    with pytest.raises(ValueError, match=message) as info:
        pair.replace(**changes)
    assert f"GearPair.replace({next(iter(changes))})" in str(info.value)
    with pytest.raises(ValueError, match=message):
        validate(_raw(pair, where, value))


def test_module_that_makes_the_contact_ratio_below_one_is_rejected():
    # With the tip radius given, a larger module moves the base circles out under the tips.
    pair = jg.presets.li2015_pair().replace(tip_radius=0.078)
    message = r"GearPair\.replace\(module\): contact ratio = 0\.\d+ .*valid range: \[1, 2\)"
    with pytest.raises(ValueError, match=message):
        pair.replace(module=3.1e-3)
    with pytest.raises(ValueError, match=r"contact ratio = 0\.\d+ .*\bmodule\b"):
        validate(_raw(pair, lambda p: p.module, 3.1e-3))


def test_relief_bearings_material_replace():
    relief = jg.TipRelief(amount=10e-6, start_roll_angle=0.365)
    np.testing.assert_array_equal(relief.replace(amount=5e-6).amount, [5e-6, 5e-6])
    with pytest.raises(ValueError, match=r"TipRelief\.replace\(amount\): TipRelief\.amount"):
        relief.replace(amount=-1e-6)
    assert float(jg.Bearings().replace(cy=(1.0, 2.0)).cy[1]) == 2.0
    with pytest.raises(ValueError, match=r"Bearings\.replace\(kx\): Bearings\.kx"):
        jg.Bearings().replace(kx=0.0)
    steel = jg.presets.steel()
    assert float(steel.replace(density=7800).density) == 7800.0
    with pytest.raises(ValueError, match=r"Material\.replace\(density\): Material\.density"):
        steel.replace(density=-1.0)
