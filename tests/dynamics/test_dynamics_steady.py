"""Periodic steady state: periodicity, independence of the start, jumps with backlash, gradients,
bad input."""

from __future__ import annotations

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import synthetic_mesh

import jaxgear as jg
from jaxgear.gear.pair import Bearings


def test_periodic_and_independent_of_initial_state():
    pair = jg.presets.li2015_pair()
    mesh = synthetic_mesh(pair, 700.0, km_amp=0.2, e_amp=4e-6, e_harm=1)
    op = jg.OperatingPoint(torque=700.0, speed_rpm=1900.0)
    ref = jg.dynamic_response(pair, op, mesh=mesh)
    assert bool(ref.converged) and bool(ref.stable) and int(ref.status) == 0
    assert not bool(ref.contact_lost)  # away from any jump region
    # Periodicity residual of the returned orbit (independent re-integration from its start).
    print("periodicity residual", float(ref.periodicity_residual))
    assert float(ref.periodicity_residual) < 1e-9
    # Start Newton far from the orbit: ±10 µm and ±1e4 µm/period on every state, 20 % off in T2.
    rng = np.random.default_rng(0)
    w0 = np.asarray(ref.initial_state)
    for _ in range(2):
        guess = w0 + np.concatenate([rng.uniform(-10, 10, 6), rng.uniform(-1e4, 1e4, 6), [0.2]])
        other = jg.dynamic_response(pair, op, mesh=mesh, initial_state=guess)
        assert bool(other.converged)
        # Same orbit to the Newton tolerance (1e-9 of the state scale): 1e-6 relative on the DTE.
        np.testing.assert_allclose(other.dynamic_te, ref.dynamic_te, rtol=1e-6)
        np.testing.assert_allclose(other.load_torque, ref.load_torque, rtol=1e-9)


def test_static_limit_equals_static_transmission_error():
    """Very low speed: inertia no longer matters, εd(t) → static TE(t) of the mesh cycle."""
    pair = jg.presets.li2015_pair()
    mesh = synthetic_mesh(pair, 700.0, km_amp=0.2, e_amp=4e-6)
    res = jg.dynamic_response(pair, jg.OperatingPoint(torque=700.0, speed_rpm=10.0), mesh=mesh)
    # εd = r1φ1 + y1 − r2φ2 − y2 includes the bearing deflections, so statically it is e + W/km: the
    # static TE of the mesh cycle, whatever the bearing stiffness.
    te = np.asarray(mesh.static_te)
    # 10 rpm: mesh frequency 8 Hz vs first mode ≈ 2.2 kHz, dynamic amplification ~ (8/2200)^2 ~ 1e-5.
    np.testing.assert_allclose(res.dynamic_te, te, rtol=1e-4)


def _jump_case():
    """Light load (static mesh deflection 9.5 µm) and a 5 µm TE excitation near the first mesh mode:
    the teeth separate near resonance. Bearing damping raised (cy 8000 N s/m, ct 15 N m s/rad) so the
    periodic orbits stay stable (with the paper's lighter damping this case goes on to period doubling,
    which the result flags as status 8, UNSTABLE)."""
    base = jg.presets.li2015_pair()
    pair = eqx.tree_at(lambda p: p.bearings, base, Bearings(cy=8000.0, ct=15.0))
    torque = 150.0
    mesh = synthetic_mesh(pair, torque, km_mean=3.0e8, e_amp=5e-6)
    res_rpm = float(jg.natural_frequencies(pair, 3.0e8)[1]) * 60 / pair.teeth[0]
    return pair, torque, mesh, res_rpm


def test_two_stable_orbits_coexist_in_the_jump_region():
    """Cheap sibling of the sweep test: at one speed in the hysteresis band, the orbit reached from
    the static equilibrium (small, in contact) and the one continued down from above the band (large,
    losing contact) are both converged, stable and distinct."""
    pair, torque, mesh, res_rpm = _jump_case()
    target = 0.90 * res_rpm
    low = jg.dynamic_response(pair, jg.OperatingPoint(torque=torque, speed_rpm=target), mesh=mesh)
    guess = None
    prev = None
    for frac in (0.93, 0.92, 0.91, 0.90):  # stepwise down, carrying the state (dq/dt kept)
        sp = frac * res_rpm
        if guess is not None:
            guess = np.asarray(guess).copy()
            guess[6:12] *= prev / sp
        high = jg.dynamic_response(
            pair, jg.OperatingPoint(torque=torque, speed_rpm=sp), mesh=mesh, initial_state=guess
        )
        guess, prev = high.initial_state, sp
    for r in (low, high):
        assert bool(r.converged) and bool(r.stable) and float(r.periodicity_residual) < 1e-8
    assert not bool(low.contact_lost) and bool(high.contact_lost)
    assert float(high.dte_rms) > 1.1 * float(low.dte_rms)


@pytest.mark.slow
def test_up_and_down_sweeps_show_the_contact_loss_jump():
    pair, torque, mesh, res_rpm = _jump_case()
    speeds = np.arange(0.84, 0.98, 0.005) * res_rpm
    op = jg.OperatingPoint(torque=torque, speed_rpm=1000.0)
    up, down = jg.dynamic_response_sweep(pair, op, speeds, mode="up_down", mesh=mesh)
    for branch in (up, down):
        assert bool(jnp.all(branch.converged)) and bool(jnp.all(branch.stable))
        assert float(jnp.max(branch.periodicity_residual)) < 1e-8
    a_up, a_down = np.asarray(up.dte_rms), np.asarray(down.dte_rms)
    # Softening (contact loss lowers the mean stiffness): going down, the large-amplitude branch is
    # followed below the speed where going up jumps onto it; the two differ by > 10 % there.
    gap = np.abs(a_up - a_down) / np.maximum(a_up, a_down)
    assert gap.max() > 0.1
    band = gap > 0.02
    # In the hysteresis band the higher branch loses contact (the lower one only starts to at the
    # band's edge, where it jumps up).
    hi_lost = np.where(a_up > a_down, np.asarray(up.contact_lost), np.asarray(down.contact_lost))
    assert np.all(hi_lost[band])
    # Each sweep jumps: a > 8 % step between neighbouring speeds 0.5 % apart.
    assert np.max(np.abs(np.diff(a_up)) / a_up[:-1]) > 0.08
    assert np.max(np.abs(np.diff(a_down)) / a_down[1:]) > 0.08
    # Outside the band both sweeps find the same orbit.
    np.testing.assert_allclose(a_up[~band], a_down[~band], rtol=1e-5)


@pytest.mark.slow
def test_parallel_sweep_equals_loop_of_single_speeds():
    pair = jg.presets.li2015_pair()
    mesh = synthetic_mesh(pair, 700.0, km_amp=0.2, e_amp=4e-6)
    op = jg.OperatingPoint(torque=700.0, speed_rpm=1000.0)
    speeds = np.array([800.0, 2100.0, 3900.0])
    sweep = jg.dynamic_response_sweep(pair, op, speeds, mesh=mesh)
    for i, sp in enumerate(speeds):
        one = jg.dynamic_response(pair, jg.OperatingPoint(torque=700.0, speed_rpm=sp), mesh=mesh)
        np.testing.assert_allclose(sweep.dte_rms[i], one.dte_rms, rtol=1e-8)
        np.testing.assert_allclose(sweep.tooth_force[i], one.tooth_force, rtol=1e-8, atol=1e-6)


def test_gradient_of_dte_rms_wrt_tip_relief_and_torque_matches_central_differences():
    base = jg.presets.li2015_pair()
    speed = 1500.0

    @eqx.filter_jit
    def dte_rms(relief, torque):
        pair = eqx.tree_at(lambda p: p.tip_relief.amount, base, jnp.stack([relief, relief]))
        op = jg.OperatingPoint(torque=torque, speed_rpm=speed)
        res = jg.dynamic_response(pair, op)  # the real mesh cycle, built from relief and torque
        return res.dte_rms, res.converged & ~res.contact_lost

    x0 = (jnp.asarray(10e-6), jnp.asarray(700.0))
    value, ok = dte_rms(*x0)
    assert bool(ok)
    grad = jax.jacfwd(lambda a, t: dte_rms(a, t)[0], argnums=(0, 1))(*x0)
    steps = (2e-7, 7.0)  # 2 % and 1 %: truncation ~1e-4 relative, Newton noise 1e-9/1e-2 ~ 1e-7
    for k, h in enumerate(steps):
        xp = list(x0)
        xm = list(x0)
        xp[k] = x0[k] + h
        xm[k] = x0[k] - h
        fd = (dte_rms(*xp)[0] - dte_rms(*xm)[0]) / (2 * h)
        print(f"gradient {k}: implicit {float(grad[k]):.6e}, central FD {float(fd):.6e}")
        # 1e-3 relative: central-difference truncation error at these steps, measured ~1e-4.
        assert abs(float(grad[k]) / float(fd) - 1) < 1e-3, (k, float(grad[k]), float(fd))
        assert abs(float(fd)) * x0[k] > 1e-3 * float(value)  # a real dependence, not noise


def test_bad_input_raises_value_error_naming_the_field():
    pair = jg.presets.li2015_pair()
    with pytest.raises(ValueError, match="OperatingPoint.speed_rpm"):
        jg.OperatingPoint(torque=700.0, speed_rpm=0.0)
    with pytest.raises(ValueError, match="OperatingPoint.speed_rpm"):
        jg.OperatingPoint(torque=700.0, speed_rpm=-100.0)
    with pytest.raises(ValueError, match="OperatingPoint.torque"):
        jg.OperatingPoint(torque=-1.0, speed_rpm=1000.0)
    with pytest.raises(ValueError, match="inlet_temperature"):
        jg.OperatingPoint(torque=700.0, speed_rpm=1000.0, inlet_temperature=90.0)
    geo = dict(teeth=(50, 50), module=3e-3, pressure_angle=math.radians(20.0), face_width=0.02)
    with pytest.raises(ValueError, match="blank_mass"):
        jg.GearPair(**geo, blank_mass=(0.0, 2.0))
    with pytest.raises(ValueError, match="blank_inertia"):
        jg.GearPair(**geo, blank_inertia=(-1e-3, 1e-3))
    with pytest.raises(ValueError, match="Bearings.cy"):
        Bearings(cy=-1.0)
    with pytest.raises(ValueError, match="Bearings.ct"):
        Bearings(ct=(10.0, -2.0))
    with pytest.raises(ValueError, match="MeshInterface.damping"):
        z = np.zeros((8, 2))
        jg.MeshInterface(damping=z - 1.0, friction_1=z, friction_2=z)
    with pytest.raises(ValueError, match="speeds_rpm"):
        jg.dynamic_response_sweep(
            pair, jg.OperatingPoint(torque=700.0, speed_rpm=1.0), [100.0, 0.0]
        )
    with pytest.raises(ValueError, match="mesh_stiffness"):
        jg.natural_frequencies(pair, -3e8)
    # A pair whose masses were made invalid after construction is still caught at the boundary
    # (blank_mass is derived unless given: a given one is stored in blank_mass_override).
    calibrated = jg.presets.li2015_pair_calibrated()
    bad = eqx.tree_at(lambda p: p.blank_mass_override, calibrated, jnp.asarray([2.0, -2.0]))
    with pytest.raises(ValueError, match="blank_mass"):
        jg.dynamic_response(bad, jg.OperatingPoint(torque=700.0, speed_rpm=1000.0))
    with pytest.raises(ValueError, match="DynamicsOptions.backlash"):
        jg.DynamicsOptions(backlash="soft")
