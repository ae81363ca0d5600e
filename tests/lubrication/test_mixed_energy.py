"""Energy of thermal mixed films (issue 4): the heat the solver reports (paper Eq. 12) against the
friction work it comes from, computed here from the solution's fields, and the derivative of the
loss where deterministic asperity contact switches on.

The friction work is built from what a solution reports (p, h, ρ, η_s, the contact indicator, the
statistical asperity pressure) and the contact's surface velocities, by quadratures and formulas
written here: Couette work |us| ∫ τ dx with τ = η_s |us|/h, the rolling friction's work
Fr (u1 + u2) = ur ∫ h dp (the continuum identity of the Poiseuille heat, derived in
``_rolling_work``), the boundary friction μb ∫ p dx over the contact. Contacts and roughness as in
tests/lubrication/test_mixed_thermal.py (REFERENCE §2-§3, §6).
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import gear_contact, greenwood_tripp_pressure
from scipy import integrate

import jaxgear as jg
from jaxgear.lubrication.roughness import Surfaces, ground

LUB = jg.presets.mil_l_23699()
STAT_THERMAL = jg.EHLModel(n_nodes=257, mixed="statistical", thermal=True)
DET_THERMAL = jg.EHLModel(n_nodes=129, mixed="deterministic", thermal=True)


def _flow_factor(h, sigma):
    """Patir and Cheng's pressure flow factor of isotropic roughness, 1 − 0.90 exp(−0.56 λ⁺),
    λ⁺ = ½(λ + √(λ² + 0.1²)) the floor that ``EHLModel``'s statistical film states."""
    lam = h / sigma
    lam = 0.5 * (lam + np.sqrt(lam**2 + 0.01))
    return 1.0 - 0.90 * np.exp(-0.56 * lam)


def _fields(sol, c, sigma=None):
    """The fields of a solution; ``sigma`` (m) for a statistical film: its flow carries the
    average gap (``gap``) with Patir and Cheng's factor."""
    f = {k: np.asarray(getattr(sol, k)) for k in ("x", "h", "gap", "density", "shear_viscosity")}
    f["factor"] = np.ones_like(f["h"]) if sigma is None else _flow_factor(f["h"], sigma)
    f["p_fluid"] = np.asarray(sol.fluid_pressure)
    f["p"] = np.asarray(sol.p)
    f["contact"] = np.asarray(sol.contact)
    f["u1"], f["u2"] = float(c.u1), float(c.u2)
    f["b"] = float(sol.hertz_half_width)
    return f


def _mass_flux(f):
    """Mass flux (kg/(m s)) on the faces i+½ (i = 1 … N−2) that the discrete Reynolds equation
    conserves: the second-order upwind Couette flux ur (3ρh_i − ρh_{i−1})/2 minus the Poiseuille
    flux with ε = φx ρh³/(12η*) averaged to the face (η* = η_s: the paper's Eyring law is one law
    for the stress and the flow; h the gap that carries the flow, φx its flow factor). Returns
    (face positions, flux)."""
    x, h, rho, eta = f["x"], f["gap"], f["density"], f["shear_viscosity"]
    ur = 0.5 * (f["u1"] + f["u2"])
    eps = f["factor"] * rho * np.maximum(h, 0.0) ** 3 / (12.0 * eta)
    eps_face = 0.5 * (eps[1:] + eps[:-1])
    dpdx = np.diff(f["p_fluid"]) / (x[1] - x[0])
    rho_h = rho * h
    couette = ur * (1.5 * rho_h[1:-1] - 0.5 * rho_h[:-2])
    return 0.5 * (x[1:-1] + x[2:]), couette - eps_face[1:] * dpdx[1:]


def _couette_work(f, fill, where=None):
    """|us| ∫ τ dx, τ = (1 − contact) fill η_s |us|/h (paper Eq. 12's sliding part is τ |us|; h
    the gap), by Simpson's rule (the solver sums by the trapezoid rule), W/m."""
    us = abs(f["u1"] - f["u2"])
    h = f["gap"]
    open_ = h > 0.0
    tau = np.where(open_, (1.0 - f["contact"]) * fill * f["shear_viscosity"] * us, 0.0)
    tau = tau / np.where(open_, h, 1.0)
    if where is not None:
        tau = np.where(where, tau, 0.0)
    return us * integrate.simpson(tau, x=f["x"])


def _rolling_work(f):
    """The work of the rolling friction, W/m: for a steady film ∫ φx h³ p′²/(12η*) dx (the
    Poiseuille heat; h the gap, φx its flow factor) = ur ∫ h dp − q ∮ dp/ρ. Why: with the mass
    flux q = ρ h ur − φx ρh³ p′/(12η*) constant where p > 0 and g = ∫ dp/ρ along x,
    ∫ (φx h³ p′/(12η*)) p′ dx = ∫ (ρ h ur − q) g′ dx =
    ur ∫ h dp − q g(outlet); at p = 0 (inlet, cavitation) the boundary terms vanish. g(outlet) is
    0 for ρ = ρ(p) and small for a thermal film (ρ also follows T). ur ∫ h dp = Fr (u1 + u2), Fr of
    paper Eq. 15. Face sums of the fields; q from the discrete flux in the Hertz zone."""
    h, rho, p = f["gap"], f["density"], f["p_fluid"]
    ur = 0.5 * (f["u1"] + f["u2"])
    dp = np.diff(p)
    h_dp = np.sum(0.5 * (h[1:] + h[:-1]) * dp)
    g_outlet = np.sum(dp / (0.5 * (rho[1:] + rho[:-1])))
    xf, flux = _mass_flux(f)
    q = np.median(flux[np.abs(xf) < 0.5 * f["b"]])
    return ur * h_dp - q * g_outlet, ur * h_dp


@pytest.fixture(scope="module")
def statistical_film():
    # 500 rpm, the full ground roughness: λ ≈ 0.1, deep mixed (13 % of the load on the asperities)
    c = gear_contact(rpm=500.0)
    surf = ground()
    sol = jg.solve_ehl(c, LUB, STAT_THERMAL, surf)
    assert bool(sol.converged), (float(sol.residual), float(sol.thermal_residual))
    return sol, c, surf


@pytest.fixture(scope="module")
def deterministic_film():
    # speed E, the full ground roughness in the film (unified Reynolds), 129 nodes: converges, a
    # film ~185 K hot, 15 % of the load on contact nodes
    c = gear_contact(rpm=3500.0)
    sol = jg.solve_ehl(c, LUB, DET_THERMAL, ground())
    assert bool(sol.converged), (float(sol.residual), float(sol.thermal_residual))
    return sol, c


# --------------------------------------------------------------------------------------------------
# Statistical (Greenwood-Tripp) thermal mixed film
# --------------------------------------------------------------------------------------------------
def test_a_warm_statistical_thermal_solve_reaches_the_cold_solves_film_on_257_nodes(
    statistical_film,
):
    # A warm solve (what every fixed-point iteration and passage step after the first runs) from
    # the 500 rpm film at 510 rpm ends where a cold solve at 510 rpm does: the same discrete
    # film, so its loss equals the cold one's to the solvers' tolerances (measured 5e-16
    # relative), and its temperature check passes. A temperature iteration that ran its first
    # solve as its first step failed this on 257 nodes (not on 65): the warm solve ended
    # unconverged, 0.47 K off its temperature tolerance, its loss 0.05 % off.
    sol, _, surf = statistical_film
    c = gear_contact(rpm=510.0)
    warm = jg.solve_ehl(c, LUB, STAT_THERMAL, surf, initial=sol)
    cold = jg.solve_ehl(c, LUB, STAT_THERMAL, surf)
    assert bool(warm.converged), (float(warm.residual), float(warm.thermal_residual))
    assert bool(cold.converged)
    assert float(warm.thermal_residual) < 0.01 * float(jnp.max(warm.temperature) - 363.15)
    np.testing.assert_allclose(float(warm.power_loss), float(cold.power_loss), rtol=1e-6)
    assert int(warm.iterations) < int(cold.iterations)


def test_statistical_thermal_heat_equals_friction_work(statistical_film):
    sol, c, surf = statistical_film
    f = _fields(sol, c, float(surf.composite_rq))
    x, b = f["x"], f["b"]
    us = abs(f["u1"] - f["u2"])
    mu_b = float(STAT_THERMAL.boundary_friction)
    assert float(sol.temperature.max() - c.inlet_temperature) > 1.0  # a thermal film

    # the discrete Reynolds equation conserves mass: the flux through the pressurised film is one
    # value (measured spread 2.5e-8 relative over −1.5 b … 0.8 b; bound 1e-6: the solver's ε takes
    # the floored film ½(h + √(h² + f²)), f = 1e-3 × the Moes film, ~1e-6 of ε at this film, and
    # the Newton residual is < 1e-12)
    xf, flux = _mass_flux(f)
    film = (xf > -1.5 * b) & (xf < 0.8 * b)
    q = np.median(flux[film])
    assert q > 0.0
    assert np.max(np.abs(flux[film] / q - 1.0)) < 1e-6

    # sliding: Couette work of the fluid, the cavitated outlet filled as streaks carrying q
    # (fill = q/(ur ρ h) ≤ 1 downstream of x = 0, EHLSolution's definition), against the fluid
    # sliding heat. Measured 3.0e-6 apart (Simpson against the solver's trapezoid sum); bound
    # 1e-3, the O(Δx²) quadrature error of an integrand with kinks at the inlet and outlet menisci
    ur = 0.5 * (f["u1"] + f["u2"])
    fill = np.where(x > 0.0, np.clip(q / (ur * f["density"] * f["gap"]), 0.0, 1.0), 1.0)
    fluid_heat = float(sol.power_loss_sliding - sol.power_loss_asperity)
    couette = _couette_work(f, fill)
    assert couette == pytest.approx(fluid_heat, rel=1e-3)
    # friction force × sliding speed is the same heat (both from one η_s; 1e-9: summation only)
    fluid_force = float(sol.friction_sliding - sol.friction_asperity)
    assert abs(fluid_force) * us == pytest.approx(fluid_heat, rel=1e-9)

    # asperity (boundary) friction μb ∫ p_a dx over the film, by Simpson (measured 4e-6 from the
    # solver's sum; bound 1e-3 as above), and its heat μb p_a |us|
    asperity_load = integrate.simpson(np.asarray(sol.asperity_pressure), x=x)
    assert float(sol.contact_load) == pytest.approx(asperity_load, rel=1e-3)
    assert abs(float(sol.friction_asperity)) == pytest.approx(mu_b * asperity_load, rel=1e-3)
    assert float(sol.power_loss_asperity) == pytest.approx(mu_b * asperity_load * us, rel=1e-3)
    # the asperity pressure is Greenwood-Tripp's at the mean-plane separation the film reports (one
    # Newton system: the library's 160-point Gauss-Legendre F_{5/2} against scipy's adaptive
    # quadrature; bound 1e-6 ph)
    hertz = np.abs(x) < b
    expected = greenwood_tripp_pressure(
        f["h"][hertz],
        float(surf.composite_rq),
        float(c.e_reduced),
        STAT_THERMAL.asperity_density_product,
        STAT_THERMAL.asperity_slope_ratio,
    )
    gap = np.max(np.abs(np.asarray(sol.asperity_pressure)[hertz] - expected))
    assert gap < 1e-6 * float(sol.hertz_pressure), gap / float(sol.hertz_pressure)

    # rolling: the Poiseuille heat (Eq. 12) against the work of the rolling friction (see
    # ``_rolling_work``). Measured +1.6 % on 257 nodes: the discrete identity is off by the upwind
    # wedge's half-cell shift of the film against the steep inlet rise and outlet spike; bound 5 %
    rolling_work, hdp = _rolling_work(f)
    assert hdp == pytest.approx(2.0 * ur * float(sol.friction_rolling), rel=1e-9)  # Fr of Eq. 15
    assert rolling_work == pytest.approx(float(sol.power_loss_rolling), rel=0.05)
    # and Eq. 12's rolling part coded at the nodes (central differences, Simpson) against the
    # solver's face sum: measured −2.5 %, the same steep cells; bound 10 %
    dpdx = np.gradient(f["p_fluid"], x)
    q_roll = f["factor"] * f["gap"] ** 3 / (12.0 * f["shear_viscosity"]) * dpdx**2
    roll_nodes = integrate.simpson(q_roll, x=x)
    assert roll_nodes == pytest.approx(float(sol.power_loss_rolling), rel=0.10)

    # the whole loss: heat against the friction forces' work, Fs us + Fr (u1 + u2) with the
    # boundary friction (the rolling part is 1.5 % of the loss: 5 % of it is < 1e-3; measured
    # 2.4e-4)
    work = couette + mu_b * asperity_load * us + rolling_work
    assert work == pytest.approx(float(sol.power_loss), rel=2e-3)
    assert float(sol.power_loss) == pytest.approx(
        integrate.simpson(np.asarray(sol.heat_flux), x=x), rel=1e-3
    )


# --------------------------------------------------------------------------------------------------
# Deterministic rough (unified Reynolds) thermal film
# --------------------------------------------------------------------------------------------------
def test_deterministic_thermal_heat_equals_friction_work(deterministic_film):
    sol, c = deterministic_film
    f = _fields(sol, c)
    x = f["x"]
    us = abs(f["u1"] - f["u2"])
    mu_b = float(DET_THERMAL.boundary_friction)
    assert float(sol.temperature.max() - c.inlet_temperature) > 10.0
    assert float(sol.contact_load_share) > 0.01

    # contact nodes: the film below 1.5 × the threshold (``EHLModel.contact_threshold`` × the Moes
    # film; the indicator's midpoint). The smooth indicator differs from this set only at films
    # within [1, 2] × the threshold, where no node stands here (asserted); so μb ∫ p over them
    # (trapezoid, N/m) is the boundary friction to rounding (bound 1e-9)
    threshold = DET_THERMAL.contact_threshold * float(sol.moes_film)
    in_band = (f["h"] > threshold) & (f["h"] < 2.0 * threshold)
    assert not np.any(in_band)
    closed = f["h"] < 1.5 * threshold
    assert np.sum(closed) >= 3
    contact_load = np.trapezoid(np.where(closed, f["p"], 0.0), x)
    assert float(sol.contact_load) == pytest.approx(contact_load, rel=1e-9)
    assert abs(float(sol.friction_asperity)) == pytest.approx(mu_b * contact_load, rel=1e-9)
    assert float(sol.power_loss_asperity) == pytest.approx(mu_b * contact_load * us, rel=1e-9)
    # (Simpson's rule would put the contact load 28 % higher: each contact spot is one node, so
    # on 129 nodes the boundary friction is known only to that quadrature's spread)

    # sliding: the Couette work over the full film upstream of the centre (x ≤ 0, where no outlet
    # fill applies) against the solver's sliding heat flux there; the heat flux is sampled as the
    # solver sums it (trapezoid: the integrand jumps at the one-node contact spots, where Simpson
    # and the trapezoid differ by 1.2 %), so only the integrand is compared. Measured 3.9e-6: the
    # solver's film floor h_eff = ½(h + √(h² + f²)), f = 1e-3 × the Moes film (0.3 nm), against h
    # at the thinnest open nodes (10 nm: f²/4h² = 2e-4 there); bound 2e-5
    upstream = x <= 0.0
    us_tau = np.where(f["h"] > 0.0, (1.0 - f["contact"]) * f["shear_viscosity"] * us**2, 0.0)
    us_tau = us_tau / np.where(f["h"] > 0.0, f["h"], 1.0)
    heat = np.asarray(sol.heat_flux_sliding)
    np.testing.assert_allclose(
        np.trapezoid(np.where(upstream, us_tau, 0.0), x),
        np.trapezoid(np.where(upstream, heat, 0.0), x),
        rtol=2e-5,
    )
    # over the whole film, friction force × sliding speed is the fluid sliding heat (1e-9)
    fluid_heat = float(sol.power_loss_sliding - sol.power_loss_asperity)
    assert abs(float(sol.friction_sliding - sol.friction_asperity)) * us == pytest.approx(
        fluid_heat, rel=1e-9
    )
    # rolling: Eq. 12's Poiseuille heat on the cell faces (the flow coefficient h³/(12η*) of the
    # open nodes averaged to the face, the face pressure difference), coded from the fields,
    # against the solver's: bound 2e-5 (the film floor, as above)
    flow = np.where(f["h"] > 0.0, (1.0 - f["contact"]) * f["h"] ** 3, 0.0)
    flow = flow / (12.0 * f["shear_viscosity"])
    dx = x[1] - x[0]
    faces = 0.5 * (flow[1:] + flow[:-1]) * (np.diff(f["p_fluid"]) / dx) ** 2
    assert np.sum(faces) * dx == pytest.approx(float(sol.power_loss_rolling), rel=2e-5)
    assert float(sol.power_loss) == pytest.approx(
        float(sol.power_loss_sliding + sol.power_loss_rolling), rel=1e-12
    )


@pytest.mark.xfail(
    strict=True,
    reason="deterministic films' Poiseuille heat is 3.4x the rolling friction's work (129 nodes, "
    "speed E, thermal: 87.4 against 25.8 kW/m; 2.7x iso-thermal on 257 nodes): the upwind wedge "
    "at one-cell asperity pressure jumps, and the mass those films do not conserve",
)
def test_deterministic_rolling_heat_equals_the_rolling_friction_work(deterministic_film):
    # The steady identity of ``_rolling_work`` holds for any film that solves Reynolds where p > 0;
    # the statistical film meets it within 2.6 % on 257 nodes. Bound 10 %.
    sol, c = deterministic_film
    ur = float(c.rolling_velocity)
    assert 2.0 * ur * float(sol.friction_rolling) == pytest.approx(
        float(sol.power_loss_rolling), rel=0.10
    )


@pytest.mark.xfail(
    strict=True,
    reason="deterministic films do not conserve mass: overlapped nodes (h < 0) held at p = 0 by "
    "the complementarity act as sources; 129 nodes, speed E: the flux through the inlet is "
    "-4.3e-3 kg/(m s) (backflow), through the Hertz zone +1.8e-4",
)
def test_deterministic_film_conserves_mass(deterministic_film):
    # the discrete flux that the Reynolds equation conserves, inlet (x < −1.2 b) against the Hertz
    # zone: one positive value, as in the statistical film (2e-7); bound 1 %
    sol, c = deterministic_film
    f = _fields(sol, c)
    xf, flux = _mass_flux(f)
    inlet = np.median(flux[(xf > -2.0 * f["b"]) & (xf < -1.2 * f["b"])])
    centre = np.median(flux[np.abs(xf) < 0.3 * f["b"]])
    assert inlet > 0.0
    assert inlet == pytest.approx(centre, rel=0.01)


# --------------------------------------------------------------------------------------------------
# The derivative where asperity contact switches on (deterministic film)
# --------------------------------------------------------------------------------------------------
_OUTLET_BUMP_OUTPUTS = ("power_loss", "power_loss_asperity", "friction_sliding", "contact_fraction")


def _outlet_bump_jvp():
    """jit(jvp) of a 129-node iso-thermal deterministic film at 500 rpm with one Gaussian bump
    (1 µm × scale, 1/e half-width 40 µm) on surface 1 at the outlet constriction (x = 0.9 b), as a
    function of the roughness scale. Returns (outputs, their derivatives) with outputs
    ``_OUTLET_BUMP_OUTPUTS`` + (converged, h_min/threshold)."""
    model = jg.EHLModel(n_nodes=129, mixed="deterministic")
    c = gear_contact(rpm=500.0)
    dx, n = 0.5e-6, 8192
    xs = np.arange(n) * dx
    z1 = jnp.asarray(1e-6 * np.exp(-(((xs - 0.5 * n * dx) / 40e-6) ** 2)))
    x0 = 0.9 * float(c.hertz_half_width)

    def outputs(scale):
        surf = Surfaces(
            profile1=z1,
            profile2=jnp.zeros_like(z1),
            dx=dx,
            scale=scale,
            offset=(x0 - 0.5 * n * dx, 0.0),
        )
        s = jg.solve_ehl(c, LUB, model, surf)
        threshold = model.contact_threshold * s.moes_film
        extra = [s.converged.astype(float), jnp.min(s.h) / threshold]
        return jnp.stack([getattr(s, k) for k in _OUTLET_BUMP_OUTPUTS] + extra)

    return jax.jit(lambda s: jax.jvp(outputs, (s,), (jnp.ones_like(s),)))


def test_gradient_is_finite_and_continuous_where_asperity_contact_switches_on():
    """The bump closes the film as its scale grows: contact (the smooth indicator,
    ``ehl.core._contact_indicator``: 1 below the threshold film, 0 above twice it) appears between
    scales 0.69 and 0.73. Measured (2026-11-30, jvp; central differences agree):

    - no contact (scale ≤ 0.66, h_min ≥ 5 × threshold): dP/ds = −62 … −8 W/m per unit scale;
    - onset: contact fraction 3e-8 / 3e-6 / 3e-4 / 1.4e-2 / 2.3e-2 at s = 0.69 / 0.70 / 0.71 /
      0.72 / 0.73 (h_min 3.2 / 2.6 / 2.0 / 1.45 / 0.89 × threshold); dP/ds = +67 / +109 / +160 /
      −230 / −156: across the indicator's transition (Δs ≈ 0.02, h_min from 2 to 1 × threshold)
      the derivative swings by ~390 W/m within Δs = 0.01, smoothly (the boundary friction
      switched on by the tanh indicator, peak dP_asp/ds = 1.9e3 W/m at s = 0.72, against 0
      before and −34 after), while P itself moves by < 3 W/m (1014.0 → 1014.6 → 1012.4);
    - in contact (s ≥ 0.74, one node closed, h_min < threshold): dP/ds = −140 … −138.
    """
    jvp = _outlet_bump_jvp()

    def at(s):
        y, dy = jvp(jnp.asarray(s))
        return np.asarray(y), np.asarray(dy)

    def central(s, step=1e-4):
        return (at(s + step)[0] - at(s - step)[0]) / (2.0 * step)

    # (ii) away from the switch on both sides: jvp against central differences. Measured ≤ 2e-7
    # relative; bound 1e-5 (truncation step² f‴/6 ~ 1e-8 relative and the Newton tolerance
    # 1e-9 ph over the step, ~1e-5 of the slope at worst)
    for s in (0.55, 0.78):
        y, dy = at(s)
        assert y[4] == 1.0
        fd = central(s)
        np.testing.assert_allclose(dy[:3], fd[:3], rtol=1e-5, atol=1e-6)
    assert at(0.55)[0][3] < 1e-12 and at(0.55)[0][5] > 10.0  # open film: no contact
    assert at(0.78)[0][3] > 0.01 and at(0.78)[0][5] < 0.0  # closed at the bump

    # (i) through the switch, every 0.0025 of scale: converged, finite derivatives
    scales = np.arange(0.68, 0.7401, 0.0025)
    ys, dys = zip(*(at(s) for s in scales), strict=True)
    ys, dys = np.array(ys), np.array(dys)
    assert np.all(ys[:, 4] == 1.0)
    assert np.all(np.isfinite(dys))
    assert ys[0, 3] < 1e-8 < 0.01 < ys[-1, 3]  # contact switches on inside the sweep
    # (iii) the derivative is that of a continuous loss: integrated across the switch it gives the
    # change of the loss and of its asperity part (no step hidden between samples). Trapezoid on
    # the sweep: its error is Δs²/12 × the change of the slope (~400 W/m over 0.01: ~0.2 W/m);
    # bound 5 % of the asperity part's change (14 W/m) and 0.5 W/m of the loss's
    for k, bound in ((0, 0.5), (1, 0.05 * (ys[-1, 1] - ys[0, 1]))):
        change = ys[-1, k] - ys[0, k]
        assert abs(np.trapezoid(dys[:, k], scales) - change) < bound, (k, change)
    # the steepest slope is finite and of the size the smoothing sets: the boundary friction's
    # heat switched on over Δs ≈ 0.02 (h_min from 2 to 1 × threshold); the tanh indicator's
    # peak is 2× its mean slope over that width; bound 4× (measured 1.9e3 against 14.8/0.02)
    peak = np.max(np.abs(dys[:, 1]))
    assert peak < 4.0 * (ys[-1, 1] - ys[0, 1]) / 0.02
    # and continuous at the steepest point: the slope 1e-6 of scale either side moves by
    # f″ × 2e-6 (f″ ~ 4e4 W/m, ~0.1 W/m); a jump would show here. Bound 1 W/m on the total.
    s_star = scales[np.argmax(np.abs(dys[:, 1]))]
    left, right = at(s_star - 1e-6)[1], at(s_star + 1e-6)[1]
    assert abs(right[0] - left[0]) < 1.0 and abs(right[1] - left[1]) < 1.0
    # at the steepest point jvp and central differences still agree: measured 2e-4 relative, the
    # step² f‴/6 truncation of the tanh's curvature; bound 2e-3
    np.testing.assert_allclose(at(s_star)[1][:3], central(s_star)[:3], rtol=2e-3, atol=1e-3)
