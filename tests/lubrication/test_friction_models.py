"""Cheap friction models: Xu et al. (2007) regression against the formula written out here, the |SR|
smoothing, gradients, trends, constant friction, helpers and bad input."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
from jaxgear.lubrication import friction_models as fm

B = (-8.916465, 1.03303, 1.036077, -0.354068, 2.812084, -0.100601, 0.752755, -0.390958, 0.620305)
CHECK = dict(  # REFERENCE §9 check point, in SI
    hertz_pressure=1.0e9,
    slide_to_roll=0.4,
    entraining_velocity=5.4,
    inlet_viscosity=6.0e-3,
    reduced_radius=0.0128,
    composite_roughness=0.56e-6,
)


def xu_by_hand(ph_gpa, sr, ve, nu_cp, r_m, s_um):
    """Xu et al. (2007), REFERENCE §9, in the formula's own units (GPa, m/s, cP, m, µm)."""
    lg = math.log10(nu_cp)
    f = B[0] + B[3] * abs(sr) * ph_gpa * lg + B[4] * math.exp(-abs(sr) * ph_gpa * lg)
    f += B[8] * math.exp(s_um)
    return math.exp(f) * ph_gpa ** B[1] * abs(sr) ** B[2] * ve ** B[5] * nu_cp ** B[6] * r_m ** B[7]


def test_xu_check_value():
    mu = float(jg.XuFriction().coefficient(**CHECK))
    expect = xu_by_hand(1.0, 0.4, 5.4, 6.0, 0.0128, 0.56)
    # unit conversions are the only difference: round-off agreement
    assert mu == pytest.approx(expect, rel=1e-12)
    # REFERENCE §9 quotes μ ≈ 0.019 (two digits): within the rounding of that figure
    assert mu == pytest.approx(0.019, abs=0.0005)


def test_xu_other_points_and_sign_of_sr():
    model = jg.XuFriction()
    for ph, sr, ve, nu, r, s in [
        (0.6, 0.1, 2.0, 13.3, 0.0128, 0.8),
        (1.7, -0.9, 20.0, 6.0, 0.02, 0.1),
    ]:
        mu = float(model.coefficient(ph * 1e9, sr, ve, nu * 1e-3, r, s * 1e-6))
        assert mu == pytest.approx(xu_by_hand(ph, sr, ve, nu, r, s), rel=1e-12)
    a = model.coefficient(**{**CHECK, "slide_to_roll": 0.3})
    b = model.coefficient(**{**CHECK, "slide_to_roll": -0.3})
    assert float(a) == float(b)


def test_smooth_abs_exact_away_from_zero_and_differentiable_at_zero():
    w = 0.02
    x = jnp.concatenate([jnp.linspace(-1.0, -w, 50), jnp.linspace(w, 1.0, 50)])
    np.testing.assert_array_equal(np.asarray(fm.smooth_abs(x, w)), np.abs(np.asarray(x)))
    g = jax.grad(lambda s: fm.smooth_abs(s, w))
    assert float(g(0.0)) == 0.0
    assert float(g(0.5)) == 1.0 and float(g(-0.5)) == -1.0
    # C¹ at the joins: one-sided slopes agree
    eps = 1e-7
    assert float(g(w - eps)) == pytest.approx(float(g(w + eps)), abs=1e-5)
    # μ is then finite and differentiable at the pitch point
    model = jg.XuFriction(smoothing=w)
    dmu = jax.grad(lambda sr: model.coefficient(**{**CHECK, "slide_to_roll": sr}))(0.0)
    assert np.isfinite(float(dmu)) and float(dmu) == 0.0


def test_gradients_against_finite_differences():
    model = jg.XuFriction()

    def mu(sr, ph):
        return model.coefficient(**{**CHECK, "slide_to_roll": sr, "hertz_pressure": ph})

    for sr0 in (0.4, -0.25, 0.01):  # 0.01 is inside the smoothing band
        ph0 = 1.2e9
        gsr, gph = jax.grad(mu, argnums=(0, 1))(sr0, ph0)
        hsr, hph = 1e-6, 1e3
        fd_sr = (mu(sr0 + hsr, ph0) - mu(sr0 - hsr, ph0)) / (2 * hsr)
        fd_ph = (mu(sr0, ph0 + hph) - mu(sr0, ph0 - hph)) / (2 * hph)
        assert float(gsr) == pytest.approx(float(fd_sr), rel=1e-6)
        assert float(gph) == pytest.approx(float(fd_ph), rel=1e-6)


def test_trends_follow_the_formula_exponents():
    model = jg.XuFriction()
    # b6 < 0: μ falls with entraining speed
    ve = jnp.linspace(1.0, 40.0, 30)
    mu_v = np.asarray(model.coefficient(**{**CHECK, "entraining_velocity": ve}))
    assert np.all(np.diff(mu_v) < 0)
    assert mu_v[-1] / mu_v[0] == pytest.approx(40.0 ** B[5], rel=1e-12)  # pure power law in Ve
    # load: d ln μ/d Ph = b2/Ph + |SR| lg ν0 (b4 − b5 e^(−|SR| Ph lg ν0)) > 0 over 0.3-1.5 GPa here
    ph = np.linspace(0.3, 1.5, 25)
    lg = math.log10(6.0)
    assert np.all(B[1] / ph + 0.4 * lg * (B[3] - B[4] * np.exp(-0.4 * ph * lg)) > 0)
    mu_p = np.asarray(model.coefficient(**{**CHECK, "hertz_pressure": jnp.asarray(ph) * 1e9}))
    assert np.all(np.diff(mu_p) > 0)
    # μ rises with roughness (b9 > 0) and falls with radius (b8 < 0)
    mu_s = np.asarray(
        model.coefficient(**{**CHECK, "composite_roughness": jnp.array([0.1e-6, 1e-6])})
    )
    assert mu_s[1] > mu_s[0]
    mu_r = np.asarray(model.coefficient(**{**CHECK, "reduced_radius": jnp.array([0.005, 0.05])}))
    assert mu_r[1] < mu_r[0]


def test_constant_friction():
    model = jg.ConstantFriction(0.07)
    mu = model.coefficient(**{**CHECK, "slide_to_roll": jnp.linspace(-1, 1, 7)})
    assert mu.shape == (7,)
    np.testing.assert_array_equal(np.asarray(mu), 0.07)
    assert isinstance(model, jg.FrictionModel) and isinstance(jg.XuFriction(), jg.FrictionModel)
    # traced mu: gradient of the sliding loss w.r.t. μ is w'|us|
    g = jax.grad(lambda m: fm.sliding_power_loss(jg.ConstantFriction(m).mu, 5e5, -2.0))(0.05)
    assert float(g) == pytest.approx(5e5 * 2.0, rel=1e-15)


def test_power_loss_and_force_helpers():
    assert float(fm.sliding_power_loss(0.05, 4.966e5, -1.5)) == pytest.approx(0.05 * 4.966e5 * 1.5)
    assert float(fm.sliding_power_loss(0.05, 4.966e5, 0.0)) == 0.0
    assert float(fm.friction_force(0.05, 9932.0)) == pytest.approx(496.6)
    assert float(fm.friction_force(0.05, 9932.0, 2.0)) == pytest.approx(-496.6)
    assert float(fm.friction_force(0.05, 9932.0, -2.0)) == pytest.approx(496.6)


def test_vmap_and_jit_equal_eager():
    model = jg.XuFriction()
    srs = jnp.linspace(-0.8, 0.8, 9)
    f = lambda sr: model.coefficient(**{**CHECK, "slide_to_roll": sr})
    np.testing.assert_allclose(
        np.asarray(jax.vmap(jax.jit(f))(srs)), np.asarray(f(srs)), rtol=1e-14
    )


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("hertz_pressure", -1e9),
        ("entraining_velocity", 0.0),
        ("inlet_viscosity", 0.0),
        ("reduced_radius", -0.01),
        ("composite_roughness", -1e-7),
        ("slide_to_roll", float("nan")),
    ],
)
def test_bad_inputs_raise(field, value):
    with pytest.raises(ValueError, match=field):
        jg.XuFriction().coefficient(**{**CHECK, field: value})
    with pytest.raises(ValueError, match=field):
        jg.ConstantFriction(0.05).coefficient(**{**CHECK, field: value})


def test_bad_model_parameters_raise():
    with pytest.raises(ValueError, match="mu"):
        jg.ConstantFriction(-0.1)
    with pytest.raises(ValueError, match="smoothing"):
        jg.XuFriction(smoothing=0.0)
    with pytest.raises(ValueError, match="coefficients"):
        jg.XuFriction(coefficients=(1.0, 2.0))
