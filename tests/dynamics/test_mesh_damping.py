"""A viscous mesh damping along the line of action (``GearPair.mesh_damping_ratio``): the decay
rate of the linearised mesh mode against the single-degree-of-freedom closed form, a damper that
acts only while the flanks touch, nothing at ζ = 0, gradients, the dissipated power, bad input."""

from __future__ import annotations

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import synthetic_mesh, unequal_pair

import jaxgear as jg
from jaxgear.dynamics.model import DynamicsOptions, MeshInterface, build_dynamics
from jaxgear.gear.pair import Bearings

M = 64


def _pair(zeta, bearings=None, backlash=0.14e-3):
    """The dynamics tests' unequal gears (50/50 teeth), with the paper's bearings unless given."""
    return unequal_pair(backlash, (50, 50), bearings or Bearings(), zeta)


def _dynamics(pair, km=3.3e8, torque=600.0, speed=2000.0, **mesh_kw):
    mesh = synthetic_mesh(pair, torque, m=M, km_mean=km, **mesh_kw)
    op = jg.OperatingPoint(torque=torque, speed_rpm=speed)
    return build_dynamics(pair, op, mesh, MeshInterface.zeros(M), DynamicsOptions())


@pytest.mark.parametrize("zeta", [0.02, 0.1, 0.3])
def test_the_mesh_mode_decays_at_the_stated_damping_ratio(zeta):
    # Rigid bearings (k 1e16 N/m against km 3.3e8) and no other dampers leave the mesh mode a
    # single degree of freedom me d'' + c d' + km d = 0, me = me1 me2/(me1 + me2), mej = Jj/rbj²:
    # its eigenvalues are ωn(−ζ ± i√(1 − ζ²)), ωn = √(km/me). Read from the Jacobian of the
    # vector field in contact (constant km, no excitation). Tolerance 1e-6: the bearings'
    # compliance shifts the mode by O(km/k) = 3e-8 (measured 2-3e-8 in ωn and ζ; with k = 1e14
    # both were 100× larger, so the remainder is that compliance, not the damper).
    stiff = Bearings(ky=1e16, cy=0.0, kx=1e16, cx=0.0, ct=0.0)
    pair = _pair(zeta, stiff)
    km = 3.3e8
    dyn = _dynamics(pair, km=km)
    rb = np.asarray(dyn.base_radius)
    me = np.asarray(pair.blank_inertia) / rb**2
    me = me[0] * me[1] / (me[0] + me[1])
    wn = math.sqrt(km / me)
    # in contact: the drive flanks compressed by 20 µm, everything at rest
    z = jnp.zeros(12).at[0].set(20.0)
    jac = np.asarray(jax.jacfwd(lambda z: dyn(0.3, z, 0.0))(z))
    lam = np.linalg.eigvals(jac) / float(dyn.mesh_period)  # d/dτ → d/dt
    mode = lam[np.argmin(np.abs(np.abs(lam) - wn))]
    print(f"ζ {zeta}: measured {-mode.real / abs(mode):.8f}, ωn {abs(mode) / wn - 1:.2e} off")
    assert abs(abs(mode) / wn - 1) < 1e-6
    assert abs(-mode.real / abs(mode) - zeta) < 1e-6 * zeta


def test_the_damper_acts_only_while_the_flanks_touch():
    pair = _pair(0.1)
    dyn = _dynamics(pair, e_amp=2e-6, e_harm=2)
    c = float(dyn.mesh_damping)
    assert c > 0.0
    tau = 0.17
    km = float(dyn.tables(tau)[0])
    ell = float(dyn.half_clearance)

    def drive(q, v):
        return float(dyn.flank_forces(tau, jnp.asarray(q), jnp.asarray(v))[0])

    def back(q, v):
        return float(dyn.flank_forces(tau, jnp.asarray(q), jnp.asarray(v))[1])

    q_in = np.array([20e-6, 0, 0, 0, 0, 0])
    d, _ = dyn.flank_compressions(tau, jnp.asarray(q_in))
    rate, _ = dyn.flank_rates(tau, jnp.zeros(6))  # the excitation's own rate
    closing = np.array([0.01, 0, 0, 0, 0, 0])
    np.testing.assert_allclose(
        drive(q_in, closing), km * float(d) + c * (0.01 + float(rate)), rtol=1e-12
    )
    # separating faster than the spring relaxes (0.5 µm compressed, km d ≈ 165 N, against the
    # damper's ≈ 340 N at 0.1 m/s): a Kelvin-Voigt contact pulls (GearDynamics._contact_force)
    e = float(dyn.tables(tau)[1])
    q_light = np.array([e + 0.5e-6, 0, 0, 0, 0, 0])
    rate_sep, _ = dyn.flank_rates(tau, jnp.asarray(-10.0 * closing))
    np.testing.assert_allclose(
        drive(q_light, -10.0 * closing), km * 0.5e-6 + c * float(rate_sep), rtol=1e-9
    )
    assert drive(q_light, -10.0 * closing) < 0.0
    # that pull is the drive flanks', not a back-flank contact (the back loss and share read the
    # back flanks' own force, DynamicResponse.back_force)
    assert back(q_light, -10.0 * closing) == 0.0
    # apart, moving together: no force before they touch
    q_apart = np.array([-ell, 0, 0, 0, 0, 0])
    assert drive(q_apart, closing) == 0.0
    assert back(q_apart, -closing) == 0.0
    # the back flanks: compressed by 20 µm beyond the clearance, closing further (moving back)
    q_back = np.array([-2 * ell - 20e-6, 0, 0, 0, 0, 0])
    _, d_b = dyn.flank_compressions(tau, jnp.asarray(q_back))
    _, rate_b = dyn.flank_rates(tau, jnp.asarray(-closing))
    km_b = float(dyn.back_tables(dyn.back_phase - tau)[0])
    assert float(d_b) > 0.0
    np.testing.assert_allclose(
        back(q_back, -closing), -(km_b * float(d_b) + c * float(rate_b)), rtol=1e-12
    )
    # apart by 0.5 µm on the back side, closing fast: nothing before they touch
    _, e_b = dyn.back_tables(dyn.back_phase - tau)
    q_back_apart = np.array([-2 * ell - float(e_b) + 0.5e-6, 0, 0, 0, 0, 0])
    assert back(q_back_apart, -10.0 * closing) == 0.0


def test_the_excitation_rate_is_the_tables_derivative():
    # The damper acts on d' = ε' − e'(t); e'(τ) is the spline's exact derivative, checked against
    # the analytic e(τ) = e_amp sin 4πτ of the table it interpolates (64 points: the cubic
    # spline's derivative error, O(h³) of a 2-harmonic sine, ~1e-4 of the amplitude).
    pair = _pair(0.05)
    e_amp = 2e-6
    dyn = _dynamics(pair, e_amp=e_amp, e_harm=2)
    tau = jnp.linspace(0.0, 1.0, 97)
    got = np.asarray(dyn.tables.slope(tau, 1))
    want = e_amp * 4 * np.pi * np.cos(4 * np.pi * np.asarray(tau))
    assert np.max(np.abs(got - want)) < 2e-4 * e_amp * 4 * np.pi
    # and against a central difference of the spline itself (its own consistency, to 1e-7)
    h = 1e-6
    fd = (np.asarray(dyn.tables(tau + h))[:, 1] - np.asarray(dyn.tables(tau - h))[:, 1]) / (2 * h)
    assert np.max(np.abs(got - fd)) < 1e-7 * e_amp * 4 * np.pi


def test_zero_damping_leaves_the_forces_as_they_were():
    pair = _pair(0.0)
    dyn = _dynamics(pair, e_amp=2e-6, e_harm=2)
    q = jnp.asarray([20e-6, 1e-6, -1e-6, 0, 0, 0])
    v = jnp.asarray([0.3, -0.1, 0.2, 0.1, 0.05, -0.02])
    for got, want in zip(dyn.flank_forces(0.4, q, v), dyn.flank_forces(0.4, q)):
        assert float(got) == float(want)


@pytest.mark.parametrize("bad", [-0.1, 1.0, 2.0, float("nan")])
def test_bad_damping_ratio_names_the_field(bad):
    with pytest.raises(ValueError, match=r"mesh_damping_ratio = .*valid range: \[0, 1\)"):
        _pair(bad)


def test_damping_ratio_from_config():
    from jaxgear.cli.config import gear_pair_from_config

    pair = gear_pair_from_config({"gear": {"mesh_damping_ratio": 0.05}})
    assert float(pair.mesh_damping_ratio) == 0.05
    assert float(gear_pair_from_config({}).mesh_damping_ratio) == 0.0
    with pytest.raises(ValueError, match="mesh_damping_ratio"):
        gear_pair_from_config({"gear": {"mesh_damping_ratio": 1.5}})


def test_damping_ratio_is_traced():
    # a design variable like the others: changing it does not change the pytree's structure
    a, b = _pair(0.0), _pair(0.05)
    assert jax.tree_util.tree_structure(a) == jax.tree_util.tree_structure(b)
    c = eqx.tree_at(lambda p: p.mesh_damping_ratio, a, jnp.asarray(0.05))
    assert float(c.mesh_damping_ratio) == 0.05


def test_an_attractor_record_of_a_stable_orbit_dissipates_what_the_orbit_does():
    # Two quadratures of the damper's power, apart: the periodic orbit's mean over 4 samples a
    # position of its Tsit5 solution, and the attractor record's sum over every RK4 step of 256
    # cycles, started off the (stable) orbit and settled back onto it. Tolerance 1e-3: the two
    # integrators' orbits differ by ~1e-6 of the DTE (AttractorRecord), the sampling by < 1e-3
    # (DAMPER_SAMPLES).
    from jaxgear.dynamics import attractor_response

    pair = _pair(0.05, Bearings())
    torque = 600.0
    mesh = synthetic_mesh(pair, torque, m=M, km_mean=3.3e8, km_amp=0.15, e_amp=3e-6, e_harm=2)
    op = jg.OperatingPoint(torque=torque, speed_rpm=3000.0)
    orbit = jg.dynamic_response(pair, op, mesh=mesh)
    assert int(orbit.status) == 0
    rec = attractor_response(
        pair, op, mesh=mesh, initial_state=orbit.initial_state, settle_periods=500
    )
    p_orbit, p_rec = float(orbit.mesh_damping_power), float(rec.mesh_damping_power)
    print(f"damper power: orbit {p_orbit:.4f} W, record {p_rec:.4f} W")
    assert p_orbit > 1.0
    assert abs(p_rec / p_orbit - 1) < 1e-3


def test_the_coupled_model_reports_the_damper_power_of_its_orbit():
    # SimulationResult.mesh_damping_power is the converged orbit's (the dynamics re-run here
    # apart, on the fixed point's final tables and orbit, to 1e-6), not part of Φ̄, and 0 with
    # ζ = 0 or quasi-static.
    from jaxgear.tribodynamics import simulate_with_state
    from jaxgear.tribodynamics.fixed_point import dynamics_options

    base = jg.presets.li2015_pair_calibrated()
    pair = eqx.tree_at(lambda p: p.mesh_damping_ratio, base, jnp.asarray(0.05))
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    op = jg.OperatingPoint(torque=700.0, speed_rpm=2500.0, inlet_temperature=363.15)
    fid = jg.Fidelity.fast(friction="constant", n_positions=24)
    res, warm = eqx.filter_jit(simulate_with_state)(pair, lub, surf, op, fid)
    assert int(res.status) == 0
    mesh = jg.mesh_cycle(pair, op.torque, fid.n_positions)
    orbit = jg.dynamic_response(
        pair,
        op,
        mesh=mesh,
        interface=warm.interface,
        options=dynamics_options(fid),
        initial_state=warm.orbit,
    )
    power = float(res.mesh_damping_power)
    print(f"damper {power:.3f} W, friction loss {float(res.power_loss):.3f} W")
    assert power > 1.0
    assert abs(power / float(orbit.mesh_damping_power) - 1) < 1e-6
    undamped = jg.simulate(base, lub, surf, op, fid)
    assert float(undamped.mesh_damping_power) == 0.0
    static = jg.simulate(pair, lub, surf, op, fid.replace(dynamics="quasi_static"))
    assert float(static.mesh_damping_power) == 0.0


def test_a_damped_sweep_keeps_the_damper_power_apart():
    # the damping ratio is a sweepable input; its power is a CSV column of its own
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    op = jg.OperatingPoint(torque=700.0, speed_rpm=2500.0, inlet_temperature=363.15)
    fid = jg.Fidelity.fast(friction="constant", n_positions=24)
    res = jg.sweep(
        jg.presets.li2015_pair_calibrated(),
        lub,
        surf,
        op,
        speeds_rpm=[2500.0, 2500.0],
        fidelity=fid,
        mode="parallel",
        mesh_damping_ratio=[0.0, 0.05],
    )
    assert np.all(res.converged)
    assert float(res.mesh_damping_power[0]) == 0.0
    assert float(res.mesh_damping_power[1]) > 1.0
    with pytest.raises(ValueError, match="mesh_damping_ratio"):
        jg.sweep(
            jg.presets.li2015_pair_calibrated(),
            lub,
            surf,
            op,
            speeds_rpm=[2500.0],
            fidelity=fid,
            mesh_damping_ratio=[1.5],
        )


def test_gradients_of_the_orbit_wrt_the_damping_ratio_match_central_differences():
    # ζ is a traced design variable: the DTE RMS and the damper's power of the periodic orbit
    # (implicit through the shooting) against central differences; jax.jacfwd of one scalar, the
    # case a clipped damper force once got wrong (GearDynamics._contact_force). 1e-3 relative:
    # the central differences' truncation at 2 % steps (~1e-4) and the Newton tolerance (1e-9).
    base = jg.presets.li2015_pair()

    @eqx.filter_jit
    def orbit(zeta):
        pair = eqx.tree_at(lambda p: p.mesh_damping_ratio, base, zeta)
        res = jg.dynamic_response(pair, jg.OperatingPoint(torque=700.0, speed_rpm=1500.0))
        return jnp.stack([res.dte_rms, res.mesh_damping_power]), res.converged

    z0, h = jnp.asarray(0.05), 1e-3
    value, ok = orbit(z0)
    assert bool(ok)
    grad = jax.jacfwd(lambda z: orbit(z)[0])(z0)
    fd = (orbit(z0 + h)[0] - orbit(z0 - h)[0]) / (2 * h)
    for name, g, f, v in zip(("DTE RMS", "damper power"), grad, fd, value):
        print(f"d {name}/dζ: implicit {float(g):.6e}, central FD {float(f):.6e}")
        assert abs(float(f)) * 0.05 > 1e-3 * abs(float(v))  # a real dependence, not noise
        assert abs(float(g) / float(f) - 1) < 1e-3


@pytest.mark.slow
def test_gradient_of_the_efficiency_wrt_the_damping_ratio_matches_central_differences():
    # Through the tribo-dynamic fixed point (the regression rung, smooth backlash: the damper
    # weighted by σ(d/w)). 1e-3 relative: truncation at 2 % steps, fixed point to 1e-10.
    base = jg.presets.li2015_pair()
    fid = jg.Fidelity(
        friction="regression",
        backlash="smooth",
        fixed_point_tolerance=1e-10,
        max_fixed_point_iterations=40,
    )
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    op = jg.OperatingPoint(torque=700.0, speed_rpm=2500.0, inlet_temperature=363.15)

    def efficiency(zeta):
        pair = eqx.tree_at(lambda p: p.mesh_damping_ratio, base, zeta)
        return jg.simulate(pair, lub, surf, op, fid).efficiency

    z0, h = jnp.asarray(0.05), 1e-3
    g = jax.jacfwd(efficiency)(z0)
    f = (efficiency(z0 + h) - efficiency(z0 - h)) / (2 * h)
    print(f"dΨ/dζ: implicit {float(g):.6e}, central FD {float(f):.6e}")
    assert abs(float(f)) > 1e-6  # measured 2.6e-3 per unit ζ: a real dependence
    assert abs(float(g) / float(f) - 1) < 1e-3
