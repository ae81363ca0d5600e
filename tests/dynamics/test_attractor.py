"""Steady response where no stable periodic orbit exists: the attractor reached by time integration
(``jaxgear.dynamics.attractor_response``) and the coupled model's means over it (status 6).

The calibrated pair has parametric instability bands of its undamped mesh (REFERENCE §1: no LOA mesh
damping): a flip (period-doubling) band near 800 rpm, Neimark-Sacker bands near 1950 and 3900 rpm,
and the contact-loss band of its 3500 rpm mode (benchmarks/RESULTS.md, dynamics). The checks below
use what the attractor did not produce: the periodic orbit where it is stable, and the moment
balance, which fixes the long-time mean mesh force at T1/rb1 in a frictionless mesh.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
from jaxgear.dynamics import DynamicsOptions, attractor_response, dynamic_response
from jaxgear.tribodynamics import (
    STATUS_ATTRACTOR,
    STATUS_DYNAMICS,
    STATUS_NAMES,
    finish,
    first_pass,
)

PAIR = jg.presets.li2015_pair_calibrated()
OPTS = DynamicsOptions(n_positions=32)
MESH = jg.mesh_cycle(PAIR, torque=700.0, n_positions=32)
T1_OVER_RB1 = float(MESH.total_load)


class _Handover(eqx.Module):
    """The end of a point's attractor record, handed to the next point of a continuation."""

    attractor: jax.Array
    on_attractor: jax.Array


def cold_start(n_positions):
    del n_positions
    return _Handover(jnp.zeros(13), jnp.zeros(()))


def _two_passes(pair, lub, surf, op, fid, handover):
    """One point of a continuation sweep as jg.sweep runs it: the fixed point (first pass), then
    the attractor (second pass, ``finish``) from the previous point's record."""
    _, _, pending = first_pass(pair, lub, surf, op, fid)
    result, (state, flag) = finish(
        pair, lub, surf, op, fid, pending, (handover.attractor, handover.on_attractor)
    )
    return result, _Handover(state, flag)


# one point of a continuation sweep (what jg.sweep runs), compiled once for cold and warm starts
_STEP = eqx.filter_jit(_two_passes)


def _op(rpm):
    return jg.OperatingPoint(torque=700.0, speed_rpm=rpm, inlet_temperature=363.15)


def _orbit(rpm):
    return dynamic_response(PAIR, _op(rpm), mesh=MESH, options=OPTS)


def _attractor(rpm, initial_state, settle, record):
    return attractor_response(
        PAIR,
        _op(rpm),
        mesh=MESH,
        options=OPTS,
        initial_state=initial_state,
        settle_periods=settle,
        record_periods=record,
    )


def test_a_stable_orbit_is_its_own_attractor():
    orbit = _orbit(1500.0)
    assert int(orbit.status) == 0
    att = _attractor(1500.0, orbit.initial_state, 1000, 8)
    assert int(att.period) == 1 and bool(att.finite)
    # The record (RK4) and the shooting (Tsit5) integrate the same equations at about the same
    # step, so the record sits on the orbit up to the two integrators' difference: measured
    # 1.1e-6 of the largest εd, DTE RMS 5.5e-6 (the kick decays over the 1000 settling cycles).
    dte = np.asarray(att.dynamic_te)
    scale = np.abs(np.asarray(orbit.dynamic_te)).max()
    assert np.abs(dte - np.asarray(orbit.dynamic_te)[None]).max() < 1e-5 * scale
    assert float(att.dte_rms) == pytest.approx(float(orbit.dte_rms), rel=1e-5)


def test_a_wrong_load_torque_is_rebalanced_to_nominal_mean_speed():
    """Started with the load torque 2 % off, the gears would slow down until the torsional damping
    took up the difference; the settling re-balances s from the exact impulse balance of the rigid
    rotation, so the record runs at the nominal mean speed on the same orbit."""
    orbit = _orbit(1500.0)
    start = orbit.initial_state.at[12].add(0.02)
    att = _attractor(1500.0, start, 1000, 8)
    assert float(att.load_torque_correction) == pytest.approx(
        float(orbit.initial_state[12]), abs=1e-6
    )
    # measured 1.3e-10: the rigid speed offset built in the first block decays through ct
    assert abs(float(att.speed_error)) < 1e-6
    assert int(att.period) == 1
    assert float(att.dte_rms) == pytest.approx(float(orbit.dte_rms), rel=1e-5)


def test_flip_band_settles_on_a_period_two_rattle_with_the_moment_balance():
    orbit = _orbit(800.0)
    # the period-1 orbit exists but is unstable (largest |Floquet multiplier| 1.11, a real −1.11)
    assert int(orbit.status) == jg.Status.UNSTABLE and float(orbit.floquet_multiplier) > 1.05
    att = _attractor(800.0, orbit.initial_state, 2000, 32)
    assert int(att.period) == 2
    assert float(att.contact_loss) > 0.1  # the teeth separate: a rattle, not a small oscillation
    assert float(att.dte_rms_total) > 5.0 * float(jnp.std(orbit.dynamic_te))
    # Frictionless mesh: over whole periods J1 φ1'' and ct1 φ1' average to zero, so the mean mesh
    # force is T1/rb1 exactly; the record samples it at 32 positions per cycle (the impacts make
    # that quadrature the error): measured 3e-4.
    assert float(jnp.mean(att.mesh_force)) == pytest.approx(T1_OVER_RB1, rel=2e-3)


def test_chaotic_rattle_keeps_the_moment_balance_over_the_record():
    orbit = _orbit(3450.0)
    assert int(orbit.status) != 0
    att = _attractor(3450.0, orbit.initial_state, 2000, 256)
    assert int(att.period) == 0 and bool(att.finite)
    assert float(att.contact_loss) > 0.05
    # Not periodic: the record's mean misses T1/rb1 by the start and end momenta of its window,
    # (J1 Δφ1' + ct1 Δφ1)/(rb1 × 256 Tm): measured +0.4 % (4-11 % over 32 cycles).
    assert float(jnp.mean(att.mesh_force)) == pytest.approx(T1_OVER_RB1, rel=0.02)


@pytest.fixture(scope="module")
def at_3450():
    """The coupled model at 3450 rpm (default fidelity): result and WarmStart."""
    lub, surf, fid = jg.presets.mil_l_23699(), jg.presets.ground(), jg.Fidelity()
    return _STEP(PAIR, lub, surf, _op(3450.0), fid, cold_start(fid.n_positions))


def test_simulate_reports_means_over_the_attractor_where_no_orbit_is_stable(at_3450):
    res = at_3450[0]
    assert int(res.status) == STATUS_ATTRACTOR, STATUS_NAMES[int(res.status)]
    assert not bool(res.converged)
    values = [res.power_loss, res.efficiency, res.dte_rms, res.tooth_force, res.power_loss_position]
    assert all(bool(jnp.all(jnp.isfinite(v))) for v in values)
    # the mean tooth load carries the torque (friction moments ~1 % of it; window: above):
    # measured −0.4 %
    assert float(res.tooth_force.sum(1).mean()) == pytest.approx(T1_OVER_RB1, rel=0.03)
    assert 0.0 < float(res.power_loss) < 0.01 * 700.0 * float(_op(3450.0).omega1)


def test_a_continuation_sweep_carries_the_attractor_to_the_next_speed(at_3450):
    """The paper's stepwise speed increase: a point with no stable orbit hands the end of its
    record to the next (the handover of ``tribodynamics.finish``), which settles from it for ATTRACTOR_WARM_SETTLE
    cycles instead of ``settle_periods`` from a kicked orbit. Checked against what it did not
    produce: the same speed settled cold; at the default fidelity the 3475 rpm attractor is not
    periodic, so the two records are different windows of one attractor (measured: Φ̄ −0.2 %,
    DTE RMS −1.8 %). And ``jg.sweep(mode="continuation")`` does hand it on: its second point is
    the warm-started one, not the cold one.
    """
    from jaxgear.tribodynamics import ATTRACTOR_WARM_SETTLE

    lub, surf, fid = jg.presets.mil_l_23699(), jg.presets.ground(), jg.Fidelity()
    assert ATTRACTOR_WARM_SETTLE < fid.settle_periods
    first, warm = at_3450
    assert int(first.status) == STATUS_ATTRACTOR and float(warm.on_attractor) == 1.0
    assert bool(jnp.all(jnp.isfinite(warm.attractor))) and float(jnp.abs(warm.attractor).max()) > 0
    carried, handed = _STEP(PAIR, lub, surf, _op(3475.0), fid, warm)
    cold, _ = _STEP(PAIR, lub, surf, _op(3475.0), fid, cold_start(fid.n_positions))
    assert int(carried.status) == int(cold.status) == STATUS_ATTRACTOR
    assert float(handed.on_attractor) == 1.0
    # bounds: the spread of 256-cycle means over windows of one non-periodic attractor (measured
    # ±1 % for Φ̄ at 1950, 3450 and 3900 rpm, about twice that for the DTE RMS), not the
    # 10-30 % by which the attractor moves Φ̄ from the unstable orbit's
    assert float(carried.power_loss) == pytest.approx(float(cold.power_loss), rel=0.015)
    assert float(carried.dte_rms) == pytest.approx(float(cold.dte_rms), rel=0.03)
    swept = jg.sweep(
        PAIR, lub, surf, _op(3450.0), speeds_rpm=[3450.0, 3475.0], fidelity=fid, mode="continuation"
    )
    assert [int(v) for v in swept.status] == [STATUS_ATTRACTOR, STATUS_ATTRACTOR]
    # the same compiled physics in a scan: equal to rounding where the handover took place
    assert float(swept.power_loss[0]) == pytest.approx(float(first.power_loss), rel=1e-9)
    assert float(swept.power_loss[1]) == pytest.approx(float(carried.power_loss), rel=1e-9)
    assert float(swept.dte_rms[1]) == pytest.approx(float(carried.dte_rms), rel=1e-9)


@pytest.mark.slow
def test_attractor_switch_off_reports_the_unstable_orbit_flagged_slow():
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    op = _op(3450.0)
    on = jg.simulate(PAIR, lub, surf, op, jg.Fidelity())
    off = jg.simulate(PAIR, lub, surf, op, jg.Fidelity(attractor_periods=0))
    assert int(off.status) == STATUS_DYNAMICS and int(on.status) == STATUS_ATTRACTOR
    # measured: DTE RMS 44.3 µm on the unstable orbit, 33.7 µm over the attractor
    assert float(on.dte_rms) < 0.9 * float(off.dte_rms)


@pytest.mark.parametrize(
    "field, value", [("attractor_periods", 1), ("attractor_periods", -1), ("settle_periods", -5)]
)
def test_bad_attractor_settings_raise_naming_the_field(field, value):
    with pytest.raises(ValueError, match=f"Fidelity.{field}"):
        jg.Fidelity(**{field: value})


def test_attractor_response_bad_input_raises_naming_the_field():
    orbit_guess = jnp.zeros(13)
    with pytest.raises(ValueError, match="record_periods"):
        attractor_response(PAIR, _op(1500.0), initial_state=orbit_guess, record_periods=1)
    with pytest.raises(ValueError, match="settle_periods"):
        attractor_response(PAIR, _op(1500.0), settle_periods=-1)
    with pytest.raises(ValueError, match="kick"):
        attractor_response(PAIR, _op(1500.0), kick=-1.0)


@pytest.mark.slow
def test_sweep_sends_only_points_without_a_stable_orbit_to_the_attractor_slow():
    """(slow: ~1 min, a vmapped program of its own; the default run keeps the ``simulate`` test
    above, and the lazy cond is tested on its own in test_lazy_cond.py.) A vmapped sweep (where a plain ``lax.cond`` would run the attractor for every point) with
    one fixed-point iteration: at 2000 rpm the orbit is stable and the unconverged fixed point
    stays status 1; at 3450 rpm the shooting's orbit is unstable, so the fixed point cannot settle
    and the attractor takes over (status 6) whatever the fixed point's own state."""
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    fid = jg.Fidelity(max_fixed_point_iterations=1)
    res = jg.sweep(PAIR, lub, surf, _op(2000.0), speeds_rpm=[2000.0, 3450.0], fidelity=fid)
    assert [int(s) for s in res.status] == [1, STATUS_ATTRACTOR]
    assert list(res.on_attractor) == [False, True] and list(res.failed) == [True, False]
    assert np.all(np.isfinite(np.asarray(res.power_loss)))
    # the attractor's mean tooth load carries the torque (window bias: above), measured −0.4 %
    assert float(np.asarray(res.tooth_force)[1].sum(1).mean()) == pytest.approx(
        T1_OVER_RB1, rel=0.03
    )
    # the mixed batch runs the attractor for its one unstable point alone (mixed="map"), as a
    # single simulate does: the same record and means (batched and unbatched rounding only)
    one = jg.simulate(PAIR, lub, surf, _op(3450.0), fid)
    assert int(one.status) == STATUS_ATTRACTOR
    assert float(res.power_loss[1]) == pytest.approx(float(one.power_loss), rel=1e-8)
    assert float(res.dte_rms[1]) == pytest.approx(float(one.dte_rms), rel=1e-8)


@pytest.mark.slow
def test_ehl_rung_attractor_means_follow_exact_ehl_solves_slow():
    """On the EHL rungs the attractor's contacts come from the closed-form mixed EHL contact scaled
    to the rung's level on the orbit (``tribodynamics.second_pass.attractor_means``). Checked against what it
    stands in for: the rung's own EHL solves at every recorded load and velocity of the same record
    (rebuilt here from the returned WarmStart: the record is deterministic)."""
    from jaxgear.dynamics.attractor import DEFAULT_KICK, record_attractor
    from jaxgear.dynamics.model import build_dynamics
    from jaxgear.tribodynamics import simulate_with_state
    from jaxgear.tribodynamics.fixed_point import cycle_contacts, dynamics_options

    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    op = _op(3450.0)
    fid = jg.Fidelity(friction="ehl_mixed", n_positions=24, n_nodes=65, attractor_periods=64)
    res, warm = simulate_with_state(PAIR, lub, surf, op, fid)
    assert int(res.status) == STATUS_ATTRACTOR, STATUS_NAMES[int(res.status)]
    # the teeth separate at 3450 rpm but do not strike the back flanks: all of Φ̄ is the drive
    # flanks', which the exact solves below recompute
    assert float(res.back_contact_share) == 0.0
    assert float(res.power_loss_back) == 0.0

    mesh = jg.mesh_cycle(PAIR, op.torque, fid.n_positions, stiffness=fid.stiffness)
    options = dynamics_options(fid)
    dyn = build_dynamics(PAIR, op, mesh, warm.interface, options)
    rec = record_attractor(
        dyn, mesh, warm.orbit, options, fid.settle_periods, fid.attractor_periods, DEFAULT_KICK
    )
    # the record the result was averaged over (all 64 cycles: stride 1)
    assert np.asarray(rec.tooth_force).mean(0) == pytest.approx(np.asarray(res.tooth_force))

    def exact(wu):
        return cycle_contacts(PAIR, lub, surf, op, fid, mesh, wu[0], wu[1])[0]

    per_cycle = jax.jit(lambda w, u: jax.lax.map(exact, (w, u)))(
        rec.tooth_force, rec.surface_velocity
    )
    # A few exact solves fail at the impact loads of the rattle (measured: at most 8 of a cycle's
    # 48 contacts); they are carried over from the nearest good contact, as in the coupled model.
    assert int(jnp.max(per_cycle.failed)) <= 12
    m = fid.n_positions
    sliding = float(jnp.sum(per_cycle.power_sliding)) / (64 * m)
    rolling = float(jnp.sum(per_cycle.power_rolling)) / (64 * m)
    # measured (2026-11-25): sliding +2.8 %, rolling −1.1 %, total +2.4 % (304 W exact); bounds
    # twice that: the proxy's error grows with the distance of the rattle's loads from the orbit's
    assert float(res.power_loss_sliding) == pytest.approx(sliding, rel=0.06)
    assert float(res.power_loss_rolling) == pytest.approx(rolling, rel=0.05)
    assert float(res.power_loss) == pytest.approx(sliding + rolling, rel=0.05)


def _attractor_efficiency():
    """Ψ(tip relief, torque) of the calibrated pair at 2500 rpm, tribo-dynamic with the attractor
    branch (constant μ, smooth backlash, 24 positions), jitted, and the point x0."""
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    fid = jg.Fidelity(
        friction="constant",
        constant_mu=0.05,
        backlash="smooth",
        n_positions=24,
        fixed_point_tolerance=1e-10,
    )
    assert fid.attractor_periods > 0

    @jax.jit
    def eff(x):
        pair = jg.presets.li2015_pair_calibrated(tip_relief=x[0])
        op = jg.OperatingPoint(torque=x[1], speed_rpm=2500.0, inlet_temperature=363.15)
        return jg.simulate(pair, lub, surf, op, fid).efficiency

    return eff, jnp.asarray([10e-6, 700.0])


def test_forward_mode_through_the_attractor_branch_lowers():
    # Regression: the attractor branch closed over DynamicsOptions arrays made in the simulate
    # trace; the JVP rule of the lazy cond re-traces the branch, so jax.jacfwd of simulate (what
    # optimise_tip_relief uses) failed to lower with "No constant handler for type
    # DynamicJaxprTracer" at every tribo-dynamic fidelity with attractor_periods > 0. Lowering
    # alone shows it (~24 s); compiling and running the derivative is the slow test below
    # (~150 s more, nearly all compilation)
    eff, x0 = _attractor_efficiency()
    lowered = jax.jit(jax.jacfwd(eff)).lower(x0)
    assert lowered.out_info.shape == (2,)


@pytest.mark.slow
def test_forward_mode_gradient_with_the_attractor_branch_matches_central_differences():
    # the implicit derivative of the fixed point (solved by _krylov.EarlyExitGMRES) through the
    # attractor branch against central differences (measured 2026-11-28: 1e-9 and 5e-7 apart);
    # the slow tests of tests/tribodynamics/test_tribodynamics.py do so at the EHL rungs
    eff, x0 = _attractor_efficiency()
    g = jax.jit(jax.jacfwd(eff))(x0)
    steps = (1e-8, 0.5)  # 1e-3 and 7e-4 of the values
    fd = [(eff(x0.at[i].add(h)) - eff(x0.at[i].add(-h))) / (2.0 * h) for i, h in enumerate(steps)]
    # central differences in float64 with the fixed point converged to 1e-10 and the orbit's
    # Newton to 1e-9: truncation O(h²) and noise 1e-10/h leave ~1e-5 relative; 1e-3 as the slow
    # gradient tests (a wrong tangent, e.g. an unconverged implicit solve, is off by far more)
    assert np.all(np.isfinite(np.asarray(g)))
    assert float(g[0]) == pytest.approx(float(fd[0]), rel=1e-3)
    assert float(g[1]) == pytest.approx(float(fd[1]), rel=1e-3)


def test_a_mean_over_the_attractor_reports_nan_derivatives_not_a_part_of_them(at_3450):
    """At status 6 the attractor branch cuts its operand from the trace, so before the marker a
    ``jax.jvp`` of Ψ there was the part that does not pass through the dynamics (T1 ω1 in Ψ),
    a finite number that is neither the derivative nor zero. The marker makes every floating
    field's tangent NaN where the flag holds, leaves it unchanged elsewhere, and leaves the values
    alone (checked on the real status-6 result's fields; the slow test below runs it through
    ``simulate``)."""
    from jaxgear.tribodynamics.result import without_derivative_where

    res = at_3450[0]
    assert int(res.status) == STATUS_ATTRACTOR

    def marked(t, flag):
        scaled = jax.tree_util.tree_map(lambda a: a * t if eqx.is_inexact_array(a) else a, res)
        return without_derivative_where(scaled, flag)

    one = (jnp.asarray(1.0),)
    values, tangents = jax.jvp(lambda t: marked(t, res.status == STATUS_ATTRACTOR), one, one)
    _, kept = jax.jvp(lambda t: marked(t, jnp.asarray(False)), one, one)
    floats = [
        name for name in type(res).__dataclass_fields__ if eqx.is_inexact_array(getattr(res, name))
    ]
    assert "efficiency" in floats and "power_loss" in floats
    for name in floats:
        assert bool(jnp.all(getattr(values, name) == getattr(res, name))), name
        assert bool(jnp.all(jnp.isnan(getattr(tangents, name)))), name
        # unflagged, the tangent of a · t at t = 1 is a itself, NaN-free where a is
        assert bool(jnp.array_equal(getattr(kept, name), getattr(res, name))), name
    assert int(values.status) == STATUS_ATTRACTOR


@pytest.mark.slow
def test_simulate_derivative_is_nan_on_the_attractor_and_finite_on_a_stable_orbit():
    # end to end: jax.jvp of Ψ in the torque through simulate at 3450 rpm (status 6 at the
    # default fidelity) is NaN; at 2500 rpm (a stable orbit) it is finite (its value against
    # central differences: the slow gradient test above). ~3 min, nearly all compilation
    lub, surf, fid = jg.presets.mil_l_23699(), jg.presets.ground(), jg.Fidelity()

    def eff(torque, rpm):
        op = jg.OperatingPoint(torque=torque, speed_rpm=rpm, inlet_temperature=363.15)
        res = jg.simulate(PAIR, lub, surf, op, fid)
        return res.efficiency, res.status

    for rpm, expect_nan in ((3450.0, True), (2500.0, False)):
        (value, status), (tangent, _) = jax.jvp(
            lambda t, rpm=rpm: eff(t, jnp.asarray(rpm)),
            (jnp.asarray(700.0),),
            (jnp.asarray(1.0),),
        )
        assert bool(jnp.isfinite(value))
        assert (int(status) == STATUS_ATTRACTOR) == expect_nan, (rpm, int(status))
        assert bool(jnp.isnan(tangent)) == expect_nan, (rpm, float(tangent))


def test_back_flank_strikes_are_counted_from_the_record_not_the_mean_loads(at_3450):
    """Rattling teeth that cross the backlash strike the back flanks (negative tooth forces). The
    share of the cycle they take (``back_contact_share``) and their loss (``power_loss_back``,
    part of Φ̄) come from the attractor's recorded cycles. At 3850 rpm (default fidelity) the
    attractor strikes back (the frictionless dynamics alone: 0.32 of the record at 3900 rpm,
    benchmarks/attractor.py; docs/limitations.md, back-flank contact), while the mean tooth
    forces the result reports are positive at every position (the strikes average out), so a
    share or a loss from them would read 0. At 3450 rpm the teeth separate but do not strike
    back, and a stable orbit (2500 rpm) and the quasi-static cycle carry none."""
    lub, surf, fid = jg.presets.mil_l_23699(), jg.presets.ground(), jg.Fidelity()
    res, _ = _STEP(PAIR, lub, surf, _op(3850.0), fid, cold_start(fid.n_positions))
    assert int(res.status) == STATUS_ATTRACTOR
    mean_force = np.asarray(res.tooth_force).sum(axis=1)
    assert mean_force.min() > 0.0
    # measured 0.297 (0.209 before the back flanks had their own stiffness and line of action;
    # fast(), in a continuation sweep: 0.13-0.47 over 3850-4050 rpm); the bounds say "strikes a
    # real share of the cycle", not a value (it moves with the attractor's window)
    assert 0.05 < float(res.back_contact_share) < 0.5
    # Φ̄ is the drive flanks' cycle mean plus the back flanks' (measured: 222.9 W, 22 % of Φ̄);
    # the drive part is the per-pair table's mean, to round-off
    drive = float(jnp.mean(jnp.sum(res.power_loss_pair, axis=1)))
    back = float(res.power_loss_back)
    assert back > 0.02 * float(res.power_loss)
    assert float(res.power_loss) == pytest.approx(drive + back, rel=1e-12)
    assert float(jnp.mean(res.power_loss_position)) == pytest.approx(drive + back, rel=1e-12)
    assert float(at_3450[0].back_contact_share) == 0.0
    assert float(at_3450[0].power_loss_back) == 0.0
    stable, _ = _STEP(PAIR, lub, surf, _op(2500.0), fid, cold_start(fid.n_positions))
    assert int(stable.status) == 0
    assert float(stable.back_contact_share) == 0.0
    assert float(stable.power_loss_back) == 0.0
    qs = jg.simulate(PAIR, lub, surf, _op(3850.0), fid.replace(dynamics="quasi_static"))
    assert float(qs.back_contact_share) == 0.0
    assert float(qs.power_loss_back) == 0.0
