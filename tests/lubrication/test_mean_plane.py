"""Mixed lubrication on the mean plane: the statistical film's average gap and flow factor against
closed forms, and the statistical film at both of its limits.

- The average gap h_T(d) = σ[λΦ(λ) + φ(λ)] against the expectation E[(d − z)⁺] of a Gaussian
  height z, integrated here by quadrature; its limits and its inverse.
- Full film (λ ≳ 3): the statistical film is the smooth film.
- Rolling speed → 0: the load goes to the asperities, the friction to μb, and the pressure to the
  dry rough line contact of Greenwood and Tripp, solved here independently (``_dry_rough_contact``:
  numpy, log-kernel panels, F_{5/2} by scipy quadrature).
- The implicit derivatives with respect to the roughness scale, nβσ and the load against central
  differences across the transition.

Contacts of REFERENCE §2-§3 (``helpers.gear_contact``), Mil-L-23699 at 90 °C.
"""

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import gear_contact, greenwood_tripp_constant
from scipy import integrate, interpolate, optimize

import jaxgear as jg
from jaxgear.lubrication import asperity
from jaxgear.lubrication.roughness import ground, polished

LUB = jg.presets.mil_l_23699()
STAT = jg.EHLModel(n_nodes=129, mixed="statistical")
SMOOTH = jg.EHLModel(n_nodes=129)


# --------------------------------------------------------------------------------------------------
# The average gap and the flow factor
# --------------------------------------------------------------------------------------------------
def _expected_gap(d, sigma):
    """E[(d − z)⁺], z ~ N(0, σ²), by adaptive quadrature, m."""
    value, _ = integrate.quad(
        lambda z: (d - z) * math.exp(-0.5 * (z / sigma) ** 2) / (sigma * math.sqrt(2 * math.pi)),
        d - 40.0 * sigma,
        d,
        epsabs=0.0,
        epsrel=1e-12,
    )
    return value


def test_average_gap_is_the_expected_gap_of_a_gaussian_surface():
    sigma = 0.4e-6
    d = np.linspace(-6.0, 8.0, 57) * sigma
    h = np.asarray(asperity.average_gap(jnp.asarray(d), sigma))
    expected = np.array([_expected_gap(v, sigma) for v in d])
    # relative 1e-10: quadrature against erfc, both near machine precision where h_T > 1e-9 σ
    np.testing.assert_allclose(h, expected, rtol=1e-10)
    # h_T(0) = σ/√(2π) (1e-15: one erfc and one exp)
    assert float(asperity.average_gap(0.0, sigma)) == pytest.approx(
        sigma / math.sqrt(2 * math.pi), rel=1e-14
    )


def test_average_gap_tends_to_the_separation_and_its_inverse_is_exact():
    sigma = 1.0e-6
    lam = np.linspace(4.0, 12.0, 33)
    h = np.asarray(asperity.average_gap(jnp.asarray(lam * sigma), sigma))
    # h_T − d = σ[φ(λ) − λ(1 − Φ(λ))] ≈ σ φ(λ)/λ² (the Mills ratio's expansion): relative
    # difference below φ(λ)/λ³, which is 2.1e-6 at λ = 4 and < 1e-6 from λ = 4.2 on
    rel = (h - lam * sigma) / (lam * sigma)
    bound = np.exp(-0.5 * lam**2) / math.sqrt(2 * math.pi) / lam**3
    eps = 1e-15  # rounding of h_T − d (a few ulp of d) where the difference is below it
    assert np.all(rel > -eps)
    assert np.all(rel < bound + eps)
    assert np.all(rel[lam >= 4.2] < 1e-6)
    # the round trip d → h_T → d over boundary, mixed and full film (1e-12 σ: Newton to rounding)
    d = jnp.linspace(-7.0, 10.0, 69) * sigma
    back = asperity.separation_of_gap(asperity.average_gap(d, sigma), sigma)
    np.testing.assert_allclose(np.asarray(back), np.asarray(d), rtol=0, atol=1e-12 * sigma)


def test_average_gap_derivatives():
    sigma = 0.5e-6
    d = jnp.linspace(-4.0, 5.0, 19) * sigma
    # dh_T/dd = Φ(λ): against the normal distribution function from scipy's erf (1e-12)
    slope = jax.vmap(jax.grad(lambda v: asperity.average_gap(v, sigma)))(d)
    phi = 0.5 * (1.0 + np.array([math.erf(float(v) / sigma / math.sqrt(2)) for v in d]))
    np.testing.assert_allclose(np.asarray(slope), phi, rtol=1e-12)
    # the inverse's derivative is 1/Φ (the implicit function; not the stopped Newton's)
    h = asperity.average_gap(d, sigma)
    inverse = jax.vmap(jax.grad(lambda v: asperity.separation_of_gap(v, sigma)))(h)
    np.testing.assert_allclose(np.asarray(inverse), 1.0 / phi, rtol=1e-10)


def test_pressure_flow_factor_is_patir_and_chengs():
    sigma = 1.0
    lam = jnp.asarray([0.5, 1.0, 2.0, 3.0, 6.0])
    # in their fitted range (λ ≥ 0.5) the floor ½(λ + √(λ² + 0.01)) moves λ by ≈ 0.0025/λ: the
    # factor is 1 − 0.90 e^(−0.56 λ) within 1 % at λ = 0.5 and 2e-3 from λ = 1 on (Patir and
    # Cheng's fit is good to a few per cent)
    phi = np.asarray(asperity.pressure_flow_factor(lam, sigma))
    expected = 1.0 - 0.90 * np.exp(-0.56 * np.asarray(lam))
    np.testing.assert_allclose(phi[0], expected[0], rtol=1e-2)
    np.testing.assert_allclose(phi[1:], expected[1:], rtol=2e-3)
    # below it, smooth and bounded: in (0.1, 1], increasing
    low = np.asarray(asperity.pressure_flow_factor(jnp.linspace(-8.0, 0.5, 35), sigma))
    assert np.all((low > 0.1) & (low <= 1.0))
    assert np.all(np.diff(low) > 0.0)


# --------------------------------------------------------------------------------------------------
# Full film: the smooth film
# --------------------------------------------------------------------------------------------------
def test_full_film_limit_is_the_smooth_film():
    # Polished at 3500 rpm: the smooth central film is 3.1 σ, no asperity contact. The power loss
    # is the smooth solver's within 0.5 % (measured −0.41 %), the sliding part within 0.1 %
    # (−0.05 %). The film and the rolling loss still feel Patir and Cheng's flow factor, which is
    # 0.83 at λ = 3 (isotropic roughness halves its distance from 1 every 1.24 σ): the inlet's
    # Poiseuille backflow is smaller, the film thicker. Measured h_c +1.5 %, h_min +3.5 %, rolling
    # loss −2.2 %; bound 5 %. At 0.3 × that roughness (λ = 10, φx = 0.997) everything is the
    # smooth film's within 0.1 % (measured ≤ 5e-4, h_min).
    c = gear_contact(rpm=3500.0)
    smooth = jg.solve_ehl(c, LUB, SMOOTH)
    assert bool(smooth.converged)
    bounds = {
        1.0: dict(
            power_loss=5e-3,
            power_loss_sliding=1e-3,
            friction_sliding=1e-3,
            power_loss_rolling=0.05,
            friction_rolling=0.05,
            h_central=0.05,
            h_min=0.05,
        ),
        0.3: dict(
            power_loss=1e-3,
            power_loss_sliding=1e-3,
            friction_sliding=1e-3,
            power_loss_rolling=1e-3,
            friction_rolling=1e-3,
            h_central=1e-3,
            h_min=1e-3,
        ),
    }
    for scale, fields in bounds.items():
        surf = polished(scale)
        rough = jg.solve_ehl(c, LUB, STAT, surf)
        assert bool(rough.converged)
        assert float(smooth.h_central) / float(surf.composite_rq) > 3.0
        assert float(rough.contact_load_share) < 1e-4
        for field, rel in fields.items():
            a, b = float(getattr(rough, field)), float(getattr(smooth, field))
            assert a == pytest.approx(b, rel=rel), (scale, field, a, b)


# --------------------------------------------------------------------------------------------------
# Rolling speed → 0: boundary lubrication and the dry rough contact
# --------------------------------------------------------------------------------------------------
_F52 = None


def _f52(lam):
    """F_{5/2}(λ) by a cubic spline through scipy quadratures on λ ∈ [−8, 6] (0 above)."""
    global _F52
    if _F52 is None:
        grid = np.linspace(-8.0, 6.0, 281)

        def f(v):
            value, _ = integrate.quad(lambda s: (s - v) ** 2.5 * math.exp(-0.5 * s * s), v, v + 40)
            return value / math.sqrt(2 * math.pi)

        _F52 = interpolate.CubicSpline(grid, [f(v) for v in grid])
    lam = np.asarray(lam)
    return np.where(lam < 6.0, _F52(np.minimum(lam, 6.0)), 0.0)


def _dry_rough_contact(contact, sigma, model, x):
    """Pressure (Pa) at ``x`` (m) of the dry line contact of rough elastic cylinders, the
    asperities Greenwood-Tripp's: p = K′E′F_{5/2}(d/σ), d = d0 + x²/2R + v(p), v the elastic
    half-plane's displacement −(4/πE′)∫ p(s) ln|x − s| ds (up to a constant in d0), ∫ p dx = w.
    Piecewise-constant pressure panels on ``x``, solved by scipy's root finder (hybr)."""
    r, w, e = (
        float(contact.reduced_radius),
        float(contact.load_per_width),
        float(contact.e_reduced),
    )
    k = greenwood_tripp_constant(model.asperity_density_product, model.asperity_slope_ratio) * e
    dx = x[1] - x[0]

    def panel(t):  # ∫ ln|t| dt antiderivative
        return np.where(t == 0.0, 0.0, t * np.log(np.abs(np.where(t == 0.0, 1.0, t))) - t)

    t = x[:, None] - x[None, :]
    kernel = panel(t + 0.5 * dx) - panel(t - 0.5 * dx)
    compliance = -4.0 / (math.pi * e) * kernel

    def pressure(d):
        return k * _f52(d / sigma)

    def residual(z):
        d, d0 = z[:-1], z[-1]
        p = pressure(d)
        film = d0 + x**2 / (2 * r) + compliance @ p
        return np.concatenate([(d - film) / sigma, [np.sum(p) * dx / w - 1.0]])

    hertz = float(contact.hertz_half_width)
    d_start = np.maximum(x**2 - hertz**2, 0.0) / (2 * r) - 1.5 * sigma
    d0 = -1.5 * sigma - float(compliance[len(x) // 2] @ pressure(d_start))
    sol = optimize.root(residual, np.concatenate([d_start, [d0]]), method="hybr", tol=1e-12)
    assert sol.success, sol.message
    return pressure(sol.x[:-1])


def test_boundary_limit_load_on_the_asperities_and_friction_to_boundary_friction():
    # 0.3 rpm (ur = 0.8 mm/s), 3 × the ground roughness: the entrained flux can no longer carry
    # the load. Asperity share ≥ 0.9 and μ within 15 % of μb (the bounds; measured 0.992
    # and μ = 0.0992 against μb = 0.1)
    c = gear_contact(rpm=0.3)
    sol = jg.solve_ehl(c, LUB, STAT, ground(3.0))
    assert bool(sol.converged)
    assert float(sol.contact_load_share) >= 0.9
    mu = abs(float(sol.friction_sliding)) / float(c.load_per_width)
    assert mu == pytest.approx(float(STAT.boundary_friction), rel=0.15)


def test_rolling_speed_to_zero_tends_to_the_dry_rough_contact():
    c_slow = gear_contact(rpm=0.3)
    surf = ground(3.0)
    sigma = float(surf.composite_rq)
    sols = [jg.solve_ehl(gear_contact(rpm=rpm), LUB, STAT, surf) for rpm in (300.0, 30.0, 3.0, 0.3)]
    assert all(bool(s.converged) for s in sols)
    # the asperities take the load over as the entrained flux falls (measured 0.31, 0.60, 0.89,
    # 0.99: at 300 rpm, where the smooth film would be 0.007 σ, the average gap the asperities
    # hold open, 0.15 σ, still carries the fluid's 69 %)
    shares = [float(s.contact_load_share) for s in sols]
    assert shares == sorted(shares) and shares[-1] > 0.98, shares
    sols = sols[1:]
    x = np.asarray(sols[-1].x)
    dry = _dry_rough_contact(c_slow, sigma, STAT, x)
    ph = float(sols[-1].hertz_pressure)
    gaps = [
        float(np.max(np.abs(np.interp(x, np.asarray(s.x), np.asarray(s.p)) - dry))) / ph
        for s in sols
    ]
    # the difference shrinks as the speed falls (measured 0.15, 0.096, 0.006 ph at 30, 3, 0.3 rpm)
    # and at 0.3 rpm the film's pressure is the dry contact's within 3 % of ph (measured 0.6 %: the
    # fluid still carries 0.85 % of the load; the two discretisations differ by O(Δx²))
    assert gaps[0] > gaps[1] > gaps[2], gaps
    assert gaps[2] < 0.03, gaps
    # the dry rough contact is lower (and so wider) than Hertz's, the asperities' compliance
    # spreading the load (measured peak 0.79 ph)
    assert float(np.max(dry)) < 0.9 * ph


def test_transient_engagement_in_deep_contact_converges_at_every_step():
    # 3 × ground at 300 rpm: the mean planes overlap (d < 0) over the whole engagement. Each time
    # step starts from the last; its central film must be carried as the average gap (positive
    # however deep the contact), not as the mean-plane separation, which a ratio of film
    # estimates cannot move to the next contact. Carried as the separation, every step's start
    # was wrong and the engagement ended with status 3 (a contact not converged) at 300 and
    # 600 rpm, on 65 and 129 nodes; carried as the gap, status 0.
    fid = jg.Fidelity.paper(dynamics="quasi_static", thermal=False, n_positions=24, n_nodes=65)
    op = jg.OperatingPoint(torque=700.0, speed_rpm=300.0, inlet_temperature=363.15)
    res = jg.simulate(jg.presets.li2015_pair_calibrated(), LUB, ground(3.0), op, fidelity=fid)
    assert int(res.status) == 0, res.status
    assert math.isfinite(float(res.power_loss)) and float(res.power_loss) > 0.0


# --------------------------------------------------------------------------------------------------
# Derivatives across the transition
# --------------------------------------------------------------------------------------------------
def _loss_and_share(theta, rpm, surfaces):
    """(power loss W/m, asperity load share, converged) of the statistical film at the pitch
    contact, θ = (roughness scale, nβσ, load per width N/m)."""
    c = gear_contact(rpm=1.0)
    c = eqx.tree_at(lambda k: (k.load_per_width, k.u1, k.u2), c, (theta[2], c.u1 * rpm, c.u2 * rpm))
    surf = eqx.tree_at(lambda s: s.scale, surfaces, theta[0])
    model = eqx.tree_at(lambda m: m.asperity_density_product, STAT, theta[1])
    sol = jg.solve_ehl(c, LUB, model, surf)
    return jnp.stack([sol.power_loss, sol.contact_load_share, sol.converged.astype(float)])


_values = eqx.filter_jit(_loss_and_share)
_tangents = eqx.filter_jit(
    lambda theta, e, rpm, surfaces: jax.jvp(
        lambda t: _loss_and_share(t, rpm, surfaces), (theta,), (e,)
    )
)


@pytest.mark.parametrize(
    "rpm, surfaces",
    [(300.0, ground(2.0)), (2000.0, ground()), (3500.0, polished())],
    ids=["boundary-side", "mixed", "full-film"],
)
def test_derivatives_against_central_differences_across_the_transition(rpm, surfaces):
    # forward mode through the implicit rule of the Newton system (the asperity pressure inside it)
    # against central differences of converged solves. Steps 1e-4 relative: truncation O(1e-8)
    # against the solve's ~1e-12 residual over a 2e-4 span; bound 1e-4 relative to the
    # derivative's size (or 1e-6 of the value where a derivative is nearly zero)
    w = float(gear_contact().load_per_width)
    theta = np.array([1.0, float(STAT.asperity_density_product), w])
    speed = jnp.asarray(rpm)
    value = np.asarray(_values(jnp.asarray(theta), speed, surfaces))
    assert value[2] == 1.0
    for i in range(3):
        e = np.zeros(3)
        e[i] = 1.0
        _, tangent = _tangents(jnp.asarray(theta), jnp.asarray(e), speed, surfaces)
        step = 1e-4 * theta[i]
        up = np.asarray(_values(jnp.asarray(theta + step * e), speed, surfaces))
        down = np.asarray(_values(jnp.asarray(theta - step * e), speed, surfaces))
        assert up[2] == 1.0 and down[2] == 1.0
        central = (up - down) / (2 * step)
        for k in range(2):
            scale = max(abs(central[k]), 1e-6 * abs(value[k]) / theta[i])
            assert abs(float(tangent[k]) - central[k]) <= 1e-4 * scale, (i, k, tangent, central)
