"""The response by time integration where no stable periodic orbit exists: the attractor.

Where the periodic orbit that the shooting finds is unstable (a parametric instability band, or
the teeth rattling through the backlash), the gears settle on another attractor: a period-doubled
orbit, a torus or a chaotic rattle. It is found as the paper finds every steady state, by
integrating in time (classical RK4 at the shooting's step, re-balancing the load torque so that
the mean speed stays nominal), and recorded at the mesh positions of many cycles. Nothing here
assumes periodicity, and nothing here is differentiated: an aperiodic attractor's averages are not
smooth functions of the inputs.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, Bool, Float, Int

from .._validation import check_integer, check_non_negative
from ..operating import OperatingPoint
from .model import LENGTH_SCALE, DynamicsOptions, GearDynamics, MeshInterface, build_dynamics
from .response import (
    N_HARMONICS,
    _check_inputs,
    _kinematics,
    _mesh_and_interface,
    _prepare,
    _safe_abs_complex,
)
from .shooting import static_guess

MAX_DETECTED_PERIOD = 4
#: A record is p-periodic when successive p-cycle blocks of εd agree to this fraction of its range
#: (the record's RK4 and the shooting's Tsit5 orbits differ by ~1e-6 of it: measured at 1500 rpm).
PERIODICITY_TOL = 1e-4


class AttractorRecord(eqx.Module):
    """The response over K mesh cycles of the attractor reached by time integration.

    Where no stable period-1 orbit exists (a parametric instability band, or rattling through the
    backlash), the gears settle on another attractor: a period-doubled orbit, a torus or a chaotic
    rattle. It is found as the paper finds every steady state, by integrating in time: from a start
    (an unstable orbit, slightly perturbed) through ``settle`` mesh cycles, then recorded at the M
    mesh positions of K cycles. Nothing here assumes periodicity.

    Attributes (SI):
        dynamic_te: εd per recorded cycle and position, m [K, M].
        mesh_force: km δ, N [K, M]; back_force: the back flanks' part of it (≤ 0), N [K, M];
        tooth_force: W_T per pair, N [K, M, 2] (paper Eq. 2);
        surface_velocity: uj per [cycle, position, pair, gear], m/s [K, M, 2, 2] (paper Eq. 3).
        contact_loss: share of the recorded samples with the drive flanks apart (δ ≤ 0).
        dte_harmonics: amplitudes of mesh harmonics 1..10 of the whole record, m [10]; equal to the
            harmonics of the cycle-mean waveform (averaging over cycles keeps exactly the mesh
            harmonics), so ``dte_rms`` is REFERENCE §7 R1's measure, as ``DynamicResponse.dte_rms``.
        dte_rms: √Σq εd,q², m. dte_rms_total: RMS of εd about its mean over the record, m (the
            sub-harmonic and aperiodic parts included).
        period: the smallest p ≤ 4 for which the record repeats every p cycles (to 1e-4 of its
            range), 0 when it does not (quasi-periodic, chaotic, or still settling).
        speed_error: mean speed of the free rigid rotation over the record relative to the
            nominal pitch-line speed (the settling re-balances the load torque to keep it ~0).
        load_torque_correction: s of the record (``DynamicResponse`` and ``GearDynamics.load_torque``).
        finite: the integration stayed finite.
        final_state: scaled state [12] at the end of the record (to continue from).
        mesh_damping_power: mean power the mesh damper dissipates over the record, W
            (``DynamicResponse.mesh_damping_power``), at every RK4 step's start.
    """

    dynamic_te: Float[Array, "K M"]
    mesh_force: Float[Array, "K M"]
    back_force: Float[Array, "K M"]
    tooth_force: Float[Array, "K M 2"]
    surface_velocity: Float[Array, "K M 2 2"]
    contact_loss: Float[Array, ""]
    dte_harmonics: Float[Array, " 10"]
    dte_rms: Float[Array, ""]
    dte_rms_total: Float[Array, ""]
    period: Int[Array, ""]
    speed_error: Float[Array, ""]
    load_torque_correction: Float[Array, ""]
    finite: Bool[Array, ""]
    final_state: Float[Array, " 12"]
    mesh_damping_power: Float[Array, ""]


def _regauge(z):
    """Remove the free rigid rotation (it drifts on an attractor; εd does not see it)."""
    rigid = 0.5 * (z[0] + z[3])
    return z.at[0].add(-rigid).at[3].add(-rigid)


#: Relative perturbation that starts the time integration off an (unstable) orbit.
DEFAULT_KICK = 1e-3


def _rk4_step(dyn: GearDynamics, z, s, t, h):
    """One classical Runge-Kutta step of size ``h`` from τ = ``t`` (mesh periods): (the new
    state, the mesh damper's power at the step's start, W).

    The four stages run in a loop over one evaluation of the vector field (traced once, not four
    times: the field is most of the program), with the arithmetic of the written-out method."""
    c = jnp.asarray([0.0, 0.5, 0.5, 1.0], dtype=z.dtype)

    def stage(i, carry):
        ks, power = carry
        k_prev = ks[jnp.maximum(i - 1, 0)]
        dz, p = dyn.rate_and_damper_power(t + c[i] * h, z + c[i] * h * k_prev, s)
        return ks.at[i].set(dz), jnp.where(i == 0, p, power)

    ks0 = jnp.zeros((4, z.shape[0]), dtype=z.dtype)
    ks, power = jax.lax.fori_loop(0, 4, stage, (ks0, jnp.zeros((), dtype=z.dtype)))
    return z + (h / 6.0) * (ks[0] + 2.0 * ks[1] + 2.0 * ks[2] + ks[3]), power


def _rk4(dyn: GearDynamics, z, s, n_steps):
    """``n_steps`` RK4 steps of ``dyn.step`` from τ = 0 (a whole number of mesh periods when
    n_steps is a multiple of the steps per period). Used for the attractor, whose settling is a
    transient whose details do not matter: about 3.5× cheaper per step on a CPU than a diffrax
    solve per period, and cheap to compile (the shooting's diffrax solve is
    not traced again)."""
    return jax.lax.fori_loop(
        0, n_steps, lambda i, z: _rk4_step(dyn, z, s, i * dyn.step, dyn.step)[0], z
    )


#: Mesh cycles per block of the settling: the load-torque correction is re-balanced after each.
SETTLE_BLOCK = 50


def _settle(dyn: GearDynamics, z, s, options: DynamicsOptions, settle: int):
    """Integrate ``settle`` mesh cycles (rounded up to blocks of ``SETTLE_BLOCK``), re-balancing the
    load-torque correction s after each block so that the mean speed stays nominal, as the shooting
    makes it on a periodic orbit (the mesh tables run on nominal time).

    The mesh force cancels from rb2 × (gear 1's moment equation) + rb1 × (gear 2's): over a block
    of duration Δt, with q0 = rb1 φ1, q3 = rb2 φ2 (drift included),
        Δ[a1 q0' + a2 q3'] + c1 Δq0 + c2 Δq3 = rb2 T1 (s* − s) Δt,
    a1 = rb2 J1/rb1, a2 = rb1 J2/rb2, c1 = rb2 ct1/rb1, c2 = rb1 ct2/rb2, where s* balances the
    block's mean friction moments (no net rigid acceleration or drift): the next block runs at s*.
    Returns (state, s)."""
    rb, j, ct = dyn.base_radius, dyn.inertia, dyn.ct
    a1, a2 = rb[1] * j[0] / rb[0], rb[0] * j[1] / rb[1]
    c1, c2 = rb[1] * ct[0] / rb[0], rb[0] * ct[1] / rb[1]
    impulse = dyn.base_radius[1] * dyn.torque * SETTLE_BLOCK * dyn.mesh_period

    # steps per period: traced (more at low speed, ``build_dynamics``)
    steps = SETTLE_BLOCK * jnp.round(1.0 / dyn.step).astype(jnp.int32)

    def block(carry, _):
        z, s = carry
        z1 = _rk4(dyn, z, s, steps)
        q0, v0 = dyn.physical(z)
        q1, v1 = dyn.physical(z1)
        dq, dv = q1 - q0, v1 - v0
        lhs = a1 * dv[0] + a2 * dv[3] + c1 * dq[0] + c2 * dq[3]
        return (_regauge(z1), s + lhs / impulse), None

    n_blocks = (settle + SETTLE_BLOCK - 1) // SETTLE_BLOCK  # may be traced
    return jax.lax.fori_loop(0, n_blocks, lambda _, carry: block(carry, None)[0], (z, s))


def record_attractor(
    dyn: GearDynamics, mesh, w, options: DynamicsOptions, settle: int, record: int, kick: float
) -> AttractorRecord:
    """``AttractorRecord`` of ``dyn`` from the shooting unknowns ``w`` [13] (state and load-torque
    correction s), perturbed by ``kick`` times the largest displacement (gear 1's coordinates up,
    gear 2's down) so that an unstable orbit is left. ``record`` is static; ``settle`` (cycles,
    rounded up to blocks of SETTLE_BLOCK) and ``kick`` may be traced (a start already on the
    attractor, at a neighbouring speed, needs no kick and a short settling)."""
    m = mesh.n_positions
    z0, s = w[:12], w[12]
    # gear 1 forward, gear 2 back: a change of εd (a uniform shift would move the gears together
    # and leave the relative motion, where the instabilities live, on the orbit)
    pattern = jnp.tile(jnp.array([1.0, 1.0, 1.0, -1.0, -1.0, -1.0]), 2)
    z0 = z0 + kick * (jnp.max(jnp.abs(z0[:6])) + 1.0) * pattern

    z, s = _settle(dyn, z0, s, options, settle)
    # whole RK4 steps between the mesh positions, no longer than the shooting's step; one flat loop
    # over the record's steps (nested loops per cycle and position cost 5× more per step on a CPU)
    per = jnp.ceil(jnp.round(1.0 / dyn.step) / m).astype(jnp.int32)
    h = 1.0 / (m * per)
    n_cycle = m * per

    rows = record * m
    scratch = rows  # where the steps inside a position's interval write (an unconditional update
    # at a computed row stays in place; a masked one copied the whole buffer every step)

    def step(i, carry):
        z, zs, drift, energy = carry
        t = (i % n_cycle) * h
        z, power = _rk4_step(dyn, z, s, t, h)
        energy = energy + power
        end = i % n_cycle == n_cycle - 1
        drift = drift + jnp.where(end, 0.5 * (z[0] + z[3]), 0.0)
        z = jnp.where(end, _regauge(z), z)
        k = (i + 1) // per  # the mesh position this step ends at
        row = jnp.where(((i + 1) % per == 0) & (k < rows), k, scratch)
        return z, jax.lax.dynamic_update_index_in_dim(zs, z, row, 0), drift, energy

    zs0 = jnp.zeros((rows + 1, z.shape[0]), dtype=z.dtype).at[0].set(z)
    zero = jnp.zeros((), dtype=z.dtype)
    z_end, zs, drift, energy = jax.lax.fori_loop(0, record * n_cycle, step, (z, zs0, zero, zero))
    zs = zs[:rows]
    zs = zs.reshape(record, m, -1)  # [K, M, 12]
    # mean rigid speed over the record relative to the nominal pitch-line speed rb1 Ω1
    nominal = dyn.base_radius[0] * dyn.omega[0] * dyn.mesh_period / LENGTH_SCALE  # per cycle
    speed_error = drift / (record * nominal)
    _, _, dte, (d, _), (fm, f_back), tooth, surf = _kinematics(dyn, mesh, zs)
    flat = dte.reshape(-1)
    harm = 2.0 * _safe_abs_complex(jnp.fft.rfft(flat) / flat.shape[0])
    harm = harm[record : record * N_HARMONICS + 1 : record]
    span = jnp.maximum(jnp.max(flat) - jnp.min(flat), 1e-30)
    repeats = jnp.stack(
        [
            jnp.max(jnp.abs(dte[p:] - dte[:-p])) / span <= PERIODICITY_TOL
            for p in range(1, min(MAX_DETECTED_PERIOD, record - 1) + 1)
        ]
    )
    found = jnp.any(repeats)
    finite = jnp.all(jnp.isfinite(zs)) & jnp.all(jnp.isfinite(z_end))
    return AttractorRecord(
        dynamic_te=dte,
        mesh_force=fm,
        back_force=f_back,
        tooth_force=tooth,
        surface_velocity=surf,
        contact_loss=jnp.mean((d < 0.0).astype(dte.dtype)),
        dte_harmonics=harm,
        dte_rms=jnp.sqrt(jnp.sum(harm**2)),
        dte_rms_total=jnp.std(flat),
        period=jnp.where(found, jnp.argmax(repeats) + 1, 0).astype(jnp.int32),
        speed_error=speed_error,
        load_torque_correction=s,
        finite=finite,
        final_state=z_end,
        mesh_damping_power=energy / (record * n_cycle),
    )


@eqx.filter_jit
def _attractor_jit(pair, op, mesh, interface, options, guess, settle, record, kick):
    mesh, interface = _mesh_and_interface(pair, op, mesh, interface, options)
    dyn = build_dynamics(pair, op, mesh, interface, options)
    cold = static_guess(dyn)
    w = jnp.where(jnp.all(jnp.isfinite(guess)), guess, cold)
    return record_attractor(dyn, mesh, w, options, settle, record, kick)


def attractor_response(
    pair,
    op: OperatingPoint,
    *,
    mesh=None,
    interface: MeshInterface | None = None,
    options: DynamicsOptions | None = None,
    initial_state=None,
    settle_periods: int = 2000,
    record_periods: int = 256,
    kick: float = DEFAULT_KICK,
) -> AttractorRecord:
    """The steady response of ``pair`` at ``op`` by time integration, with no periodicity assumed.

    Use it where ``dynamic_response`` reports no stable periodic orbit (status 2 or 8: not converged or unstable): the gears
    then settle elsewhere, and this records where. Weak instabilities (largest Floquet multiplier
    1 + ε) leave the orbit over ~ln(1/kick)/ε cycles, so ``settle_periods`` must exceed that.

    Args:
        pair, op, mesh, interface, options: as ``dynamic_response``.
        initial_state: shooting unknowns [13] to start from (``DynamicResponse.initial_state``: the
            load-torque correction is taken from it); default the static equilibrium with s = 0.
        settle_periods: mesh cycles integrated before recording (≥ 0).
        record_periods: mesh cycles recorded (≥ 2).
        kick: relative perturbation of the start (≥ 0).

    Returns:
        AttractorRecord. Not differentiable in any useful sense (an aperiodic attractor's averages
        are not smooth functions of the inputs).
    """
    options = DynamicsOptions() if options is None else options
    _check_inputs(pair, op)
    check_integer("settle_periods", settle_periods, 0)
    check_integer("record_periods", record_periods, 2)
    check_non_negative("kick", kick, "")
    guess = jnp.full(13, jnp.nan) if initial_state is None else jnp.asarray(initial_state, float)
    pair, op, mesh, interface, options = _prepare(pair, op, mesh, interface, options)
    return _attractor_jit(
        pair, op, mesh, interface, options, guess, settle_periods, record_periods, float(kick)
    )
