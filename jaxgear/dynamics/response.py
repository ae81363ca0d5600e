"""Periodic steady-state response of the 6-DOF gear model over one mesh cycle, DTE and speed sweeps.

The steady state is found by shooting: Newton on the periodicity of the Poincaré map over one mesh
period (a fixed-step diffrax solve, differentiated forward with ``jax.jacfwd``), with the load-torque
correction s as a 13th unknown and a gauge on the free rigid-body rotation as the 13th equation:

    R(z0, s) = [ z(Tm; z0, s) − z0 ,  r1φ1(0) + r2φ2(0) ] = 0.

Periodicity of the rotations themselves (not only of their speeds) makes the mean speed exactly nominal,
so s is the mean moment balance including friction and damping. Gradients of anything computed from the
orbit use the implicit function theorem on R = 0 (``lax.custom_root``), never the Newton iterations.
"""

from __future__ import annotations

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, Bool, Float, Int

from .._validation import (
    check_instance,
    check_integer,
    check_non_negative,
    check_positive,
    is_concrete,
)
from ..gear.pair import GearPair
from ..operating import OperatingPoint
from .model import (
    LENGTH_SCALE,
    DynamicsOptions,
    GearDynamics,
    MeshInterface,
    build_dynamics,
)

#: Mesh harmonics in the DTE RMS (REFERENCE §7 R1).
N_HARMONICS = 10

STATUS_CONVERGED = 0
STATUS_NOT_CONVERGED = 1
STATUS_NOT_FINITE = 2
STATUS_UNSTABLE = 3

#: Members redone together by the fallback (fixed gather size).
FALLBACK_CHUNK = 16

#: Floquet multipliers up to 1 + this count as stable (the free rigid rotation has exactly 1).
STABILITY_TOL = 1e-6


class DynamicResponse(eqx.Module):
    """Periodic steady state over one mesh cycle, at the M positions of the mesh cycle (τ_i = i/M).

    Attributes (SI; leading batch axis in sweeps):
        speed_rpm: gear 1 speed, rpm. torque: T1, N m. load_torque: T2 from the mean moment balance, N m.
        mesh_fraction: τ_i [M]. time: t_i = τ_i Tm, s [M].
        displacement: [M, 6] deviations (φ1 rad, y1 m, x1 m, φ2 rad, y2 m, x2 m) from nominal rotation.
        velocity: [M, 6] their time derivatives (rad/s, m/s).
        dynamic_te: εd = r1φ1 + y1 − r2φ2 − y2 (m) [M] (equals the static TE in static equilibrium).
        mesh_force: Fm = km⟨d⟩ − km_b⟨d_b⟩, the drive and back flanks' forces (N) [M] (their
            moment about each centre is rb·Fm; GearDynamics.flank_forces).
        tooth_force: dynamic tooth force per pair W_T = W_sT (r1/T1) km δ (paper Eq. 2), N [M, 2].
        surface_velocity: uj = Rj(Ωj + φj') − xj' per [position, pair, gear] (paper Eq. 3), m/s [M, 2, 2].
        contact_loss: 1.0 where the drive flanks separate (δ ≤ 0) [M]; back_contact: 1.0 on the back side.
        contact_lost: any contact loss over the cycle.
        dte_harmonics: amplitudes εd,q of mesh harmonics q = 1..10, m [10].
        dte_rms: √(Σq εd,q²), m (REFERENCE §7 R1).
        converged: Newton met ``newton_tol``; stable: all Floquet multipliers |μ| ≤ 1 + 1e-6 (an
        unstable periodic orbit is a solution that the real gears would leave);
        floquet_multiplier: the largest |μ|; status: 0 converged and stable, 1 Newton did not
        converge, 2 not finite, 3 converged to an unstable orbit; newton_iterations,
        periodicity_residual: max |z(Tm) − z(0)| / max |z| of the returned orbit (dimensionless).
        initial_state: the shooting unknowns [13] (scaled state at τ = 0 and s), reusable as a guess.
        back_force: the back flanks' force alone (≤ 0, N) [M]: part of ``mesh_force``, apart
            from a mesh damper's pull on separating drive flanks (``GearDynamics._contact_force``).
        mesh_damping_power: mean power the mesh damper along the line of action dissipates over
            the cycle, W (``GearPair.mesh_damping_ratio``; 0 without it): ⟨(f − f_el) d'⟩ over
            both flank pairs, f_el the elastic force alone, from DAMPER_SAMPLES samples per
            mesh position. Not part of the mesh friction loss Φ̄.
    """

    speed_rpm: Float[Array, ""]
    torque: Float[Array, ""]
    load_torque: Float[Array, ""]
    mesh_fraction: Float[Array, " M"]
    time: Float[Array, " M"]
    displacement: Float[Array, "M 6"]
    velocity: Float[Array, "M 6"]
    dynamic_te: Float[Array, " M"]
    mesh_force: Float[Array, " M"]
    tooth_force: Float[Array, "M 2"]
    surface_velocity: Float[Array, "M 2 2"]
    contact_loss: Float[Array, " M"]
    back_contact: Float[Array, " M"]
    contact_lost: Bool[Array, ""]
    dte_harmonics: Float[Array, " 10"]
    dte_rms: Float[Array, ""]
    converged: Bool[Array, ""]
    stable: Bool[Array, ""]
    floquet_multiplier: Float[Array, ""]
    status: Int[Array, ""]
    newton_iterations: Int[Array, ""]
    periodicity_residual: Float[Array, ""]
    initial_state: Float[Array, " 13"]
    back_force: Float[Array, " M"]
    mesh_damping_power: Float[Array, ""]


#: Samples per mesh position at which a periodic orbit's mesh damper power is averaged: on the
#: calibrated pair (ζ 0.02-0.05, 1700 and 3350 rpm, M = 32 and 64) one sample a position read it
#: 1.5-11 % low (the compression rate's peaks where tooth pairs enter), 4 within 0.1 % of 16.
DAMPER_SAMPLES = 4


def _solver(options: DynamicsOptions):
    return diffrax.Tsit5() if options.solver is None else options.solver


def _integrate(dyn: GearDynamics, z0, s, options: DynamicsOptions, ts=None):
    """One mesh period from z0; returns z(1) or z at the fractions ``ts``."""
    saveat = diffrax.SaveAt(t1=True) if ts is None else diffrax.SaveAt(ts=ts)
    sol = diffrax.diffeqsolve(
        diffrax.ODETerm(dyn),
        _solver(options),
        t0=0.0,
        t1=1.0,
        dt0=dyn.step,
        y0=z0,
        args=s,
        stepsize_controller=diffrax.ConstantStepSize(),
        saveat=saveat,
        max_steps=options.max_steps_per_period + 2,
        adjoint=diffrax.ForwardMode(),
        throw=False,
    )
    ok = sol.result == diffrax.RESULTS.successful
    ys = jnp.where(ok, sol.ys, jnp.nan)  # too many steps needed: reported as not finite
    return ys[-1] if ts is None else ys


def _residual(dyn: GearDynamics, w, options: DynamicsOptions):
    """R(w) = [z(Tm) − z0, r1φ1(0) + r2φ2(0)] (scaled), w = [z0, s]."""
    z0, s = w[:12], w[12]
    z1 = _integrate(dyn, z0, s, options)
    return jnp.concatenate([z1 - z0, (z0[0] + z0[3])[None]])


def static_guess(dyn: GearDynamics) -> Float[Array, " 13"]:
    """Shooting unknowns of the static equilibrium at τ = 0 (frictionless, in contact, at rest)."""
    tab = dyn.tables(0.0)
    km, e = tab[0], tab[1]
    force = dyn.torque / dyn.base_radius[0]
    y1 = -force / dyn.ky[0]
    y2 = force / dyn.ky[1]
    rel = e + force / km - y1 + y2  # r1φ1 − r2φ2 with the mesh deflection at F/km
    q = jnp.stack([0.5 * rel, y1, 0.0, -0.5 * rel, y2, 0.0]) / LENGTH_SCALE
    return jnp.concatenate([q, jnp.zeros(6), jnp.zeros(1)])


def _scaled_norm(r, w):
    return jnp.max(jnp.abs(r), axis=-1) / (1.0 + jnp.max(jnp.abs(w[..., :12]), axis=-1))


def _batch_solve_newton(dyns, w0, options: DynamicsOptions, max_steps: int):
    """Periodic orbits of a batch of systems (leading axis B of ``dyns`` and ``w0`` [B, 13]).

    Newton-Broyden with lazy backtracking: the exact Jacobian (``jacfwd`` through one period, 14
    tangent lanes) is computed at the start, refreshed for the whole batch only when some member
    stalls (two rejected trial points in a row), and updated by Broyden's rank-one rule otherwise, so
    most iterations cost one plain period. Linear cases converge in one exact Newton step.
    A trial point whose residual does not fall below the last accepted one is rejected and the step
    halved. The loop is batch-aware (scalar predicates), so it is not recomputed per member under vmap.

    Returns (w [B, 13], (iterations [B], scaled residual [B], converged [B], max |Floquet| [B])).
    """
    res = jax.vmap(lambda d, w: _residual(d, w, options))
    jac = jax.vmap(jax.jacfwd(lambda d, w: _residual(d, w, options), argnums=1))
    n = w0.shape[-1]
    eye = jnp.eye(n)
    tol = options.newton_tol
    r0 = res(dyns, w0)
    rn0 = jnp.where(jnp.all(jnp.isfinite(r0), -1), _scaled_norm(r0, w0), jnp.inf)
    j0 = jac(dyns, w0)
    bsz = w0.shape[0]

    def cond(c):
        i, active = c[-2], c[-1]
        return jnp.any(active) & (i < max_steps)

    def body(c):
        w, r, rn, jm, lam, fails, iters, i, active = c
        jm_safe = jnp.where(jnp.all(jnp.isfinite(jm), (-2, -1))[:, None, None], jm, eye)
        step = jnp.linalg.solve(jm_safe, -r[..., None])[..., 0]
        w_try = w + lam[:, None] * step
        r_try = res(dyns, w_try)
        finite = jnp.all(jnp.isfinite(r_try), -1)
        rn_try = jnp.where(finite, _scaled_norm(r_try, w_try), jnp.inf)
        accept = active & (rn_try < rn)
        # Broyden's (good) rank-one update on accepted members.
        dw = w_try - w
        dr = r_try - r
        denom = jnp.sum(dw * dw, -1)
        upd = (
            jnp.einsum("bi,bj->bij", dr - jnp.einsum("bij,bj->bi", jm, dw), dw)
            / jnp.where(denom > 0, denom, 1.0)[:, None, None]
        )
        jm = jnp.where(accept[:, None, None] & (denom > 0)[:, None, None], jm + upd, jm)
        w = jnp.where(accept[:, None], w_try, w)
        r = jnp.where(accept[:, None], r_try, r)
        rn = jnp.where(accept, rn_try, rn)
        iters = iters + active.astype(iters.dtype)
        lam = jnp.where(accept, 1.0, jnp.where(active, 0.5 * lam, lam))
        fails = jnp.where(accept, 0, fails + active.astype(fails.dtype))
        done = rn <= tol
        stuck = lam < 1e-4
        active = active & ~done & ~stuck
        # Refresh the exact Jacobian (whole batch, scalar predicate) when a member stalls.
        refresh = jnp.any(active & (fails >= 2))
        jm = jax.lax.cond(refresh, lambda: jac(dyns, w), lambda: jm)
        lam = jnp.where(refresh & active, 1.0, lam)
        fails = jnp.where(refresh, 0, fails)
        return w, r, rn, jm, lam, fails, iters, i + 1, active

    init = (
        w0,
        r0,
        rn0,
        j0,
        jnp.ones(bsz, w0.dtype),
        jnp.zeros(bsz, jnp.int32),
        jnp.ones(bsz, jnp.int32),
        jnp.asarray(0),
        rn0 > tol,
    )
    w, _, rn, _, _, _, iters, _, _ = jax.lax.while_loop(cond, body, init)
    done = rn <= tol
    # Monodromy matrix = ∂z(Tm)/∂z0 = J[:12, :12] + I at the orbit; the free rigid rotation gives 1.
    mono = jac(dyns, w)[:, :12, :12] + jnp.eye(12)
    floquet = jnp.max(jnp.abs(jnp.linalg.eigvals(mono)), axis=-1)
    return w, (iters, rn, done, floquet)


def _transient(dyn: GearDynamics, w, options: DynamicsOptions):
    """Integrate ``options.transient_periods`` mesh periods from w (transients decay), re-gauged."""
    n = options.transient_periods
    sol = diffrax.diffeqsolve(
        diffrax.ODETerm(dyn),
        _solver(options),
        t0=0.0,
        t1=float(n),
        dt0=dyn.step,
        y0=w[:12],
        args=w[12],
        stepsize_controller=diffrax.ConstantStepSize(),
        saveat=diffrax.SaveAt(t1=True),
        max_steps=(options.max_steps_per_period + 2) * n,
        adjoint=diffrax.ForwardMode(),
        throw=False,
    )
    z = jnp.where(sol.result == diffrax.RESULTS.successful, sol.ys[-1], jnp.nan)
    rigid = 0.5 * (z[0] + z[3])
    z = z.at[0].add(-rigid).at[3].add(-rigid)
    return jnp.concatenate([z, w[12:]])


def _acceptable(aux):
    _, _, done, floquet = aux
    return done & (floquet <= 1.0 + STABILITY_TOL)


def _index(tree, i):
    return jax.tree_util.tree_map(lambda a: a[i], tree)


def _batch_solve(dyns, w0, options: DynamicsOptions, fallback_from=None, retry_unstable=True):
    """Batched periodic orbits with a per-member fallback and implicit differentiation.

    Members whose Newton fails or ends on an unstable orbit are redone, gathered in chunks (a loop
    with a scalar predicate, so it costs nothing when unused): transients are let decay from
    ``fallback_from`` (default ``w0``) for ``options.transient_periods`` periods, then Newton again.
    ``retry_unstable`` (traced bool) = False redoes only members whose Newton failed, not those that
    converged to an unstable orbit (a continuation inside a band without a stable orbit).
    The result is then passed through ``lax.custom_root`` per member, so derivatives come from the
    implicit function theorem on R = 0 and never from the iterations.
    """
    dyns_c = jax.lax.stop_gradient(dyns)
    w, aux = _batch_solve_newton(
        dyns_c,
        jax.lax.stop_gradient(w0),
        options,
        min(options.newton_batch_steps, options.newton_max_steps),
    )
    start = w0 if fallback_from is None else fallback_from
    start = jax.lax.stop_gradient(start)
    bsz = w.shape[0]
    chunk = min(bsz, FALLBACK_CHUNK)

    if bsz <= 2:
        # Few members (one speed, continuation): redo them one at a time with a scalar cond. (The
        # gathered-chunk loop below costs ~0.1 s per call on CPU even when it does not iterate.)
        def redo(i, carry):
            w, aux = carry
            aux_i = _index(aux, i)
            ok = aux_i[2] & (~retry_unstable | _acceptable(aux_i))

            def again():
                dyn_i = _index(dyns_c, i)
                w_t = _transient(dyn_i, start[i], options)
                dyn_1 = jax.tree_util.tree_map(lambda a: a[None], dyn_i)
                w1, aux1 = _batch_solve_newton(dyn_1, w_t[None], options, options.newton_max_steps)
                # keep the new attempt only if it is better (acceptable, or at least converged)
                better = _acceptable(_index(aux1, 0)) | (aux1[2][0] & ~aux[2][i])
                w_new = jnp.where(better, w1[0], w[i])
                aux_new = jax.tree_util.tree_map(
                    lambda a, b: a.at[i].set(jnp.where(better, b[0], a[i])), aux, aux1
                )
                return w.at[i].set(w_new), aux_new

            return jax.lax.cond(ok, lambda: (w, aux), again)

        w, aux = jax.lax.fori_loop(0, bsz, redo, (w, aux))
    else:
        # Redo the members that need it in chunks of up to ``chunk`` (gathered with a fixed size, so the
        # cost scales with the number of failures, not with the batch): transient decay, then Newton.
        def pending(carry):
            _, aux, tried = carry
            need = ~aux[2] | (retry_unstable & ~jax.vmap(_acceptable)(aux))
            return need & ~tried

        def cond(carry):
            return jnp.any(pending(carry))

        def body(carry):
            w, aux, tried = carry
            idx = jnp.nonzero(pending(carry), size=chunk, fill_value=bsz)[0]
            valid = idx < bsz
            safe = jnp.where(valid, idx, 0)
            dyn_k = _index(dyns_c, safe)
            w_t = jax.vmap(lambda d, x: _transient(d, x, options))(dyn_k, start[safe])
            w1, aux1 = _batch_solve_newton(dyn_k, w_t, options, options.newton_max_steps)
            # Keep a new attempt only if it is better: acceptable, or at least converged.
            better = valid & (jax.vmap(_acceptable)(aux1) | (aux1[2] & ~aux[2][safe]))
            tgt = jnp.where(better, safe, bsz)  # out-of-range index: dropped by the scatter
            w = w.at[tgt].set(w1, mode="drop")
            aux = jax.tree_util.tree_map(lambda a, b: a.at[tgt].set(b, mode="drop"), aux, aux1)
            tried = tried.at[jnp.where(valid, safe, bsz)].set(True, mode="drop")
            return w, aux, tried

        w, aux, _ = jax.lax.while_loop(cond, body, (w, aux, jnp.zeros(bsz, bool)))

    def attach(dyn, w_star):
        def identity_solve(f, x):
            return x

        def tangent_solve(g, y):
            return jnp.linalg.solve(jax.jacfwd(g)(y), y)

        return jax.lax.custom_root(
            lambda w: _residual(dyn, w, options), w_star, identity_solve, tangent_solve
        )

    w = jax.vmap(attach)(dyns, w)
    return w, aux


def _safe_abs_complex(c):
    mag2 = jnp.real(c) ** 2 + jnp.imag(c) ** 2
    ok = mag2 > 0.0
    return jnp.where(ok, jnp.sqrt(jnp.where(ok, mag2, 1.0)), 0.0)


def dte_harmonic_amplitudes(dte, n_harmonics: int = N_HARMONICS):
    """Amplitudes (m) of mesh harmonics 1..n of one period of εd sampled at M uniform points."""
    m = dte.shape[-1]
    if m < 2 * n_harmonics + 1:
        raise ValueError(f"need at least {2 * n_harmonics + 1} samples per period; got {m}")
    c = jnp.fft.rfft(dte, axis=-1) / m
    return 2.0 * _safe_abs_complex(c[..., 1 : n_harmonics + 1])


def _kinematics(dyn: GearDynamics, mesh, zs):
    """Physical response at the mesh positions from scaled states ``zs`` [..., M, 12]: displacement
    and velocity [..., M, 6], DTE εd and mesh deflection d [..., M], mesh force Fm [..., M], tooth
    forces W_T [..., M, 2] (paper Eq. 2) and surface velocities uj [..., M, 2, 2] (paper Eq. 3); d is
    the drive flanks' compression and the back flanks' (``GearDynamics.flank_compressions``) [..., M]
    each."""
    q, v = dyn.physical(zs)
    rb = dyn.base_radius
    rot_scale = jnp.stack([1 / rb[0], 1.0, 1.0, 1 / rb[1], 1.0, 1.0])
    displacement = q * rot_scale
    velocity = v * rot_scale
    dte = dyn.mesh_deflection(q, 0.0)
    tau = mesh.mesh_fraction
    d, d_back = dyn.flank_compressions(tau, q)
    f_drive, f_back = dyn.flank_forces(tau, q, v)
    fm = f_drive + f_back
    tooth = mesh.normal_load / mesh.total_load * fm[..., None]
    arms = mesh.radius_of_curvature  # [M, pair, gear]
    speed = dyn.omega + velocity[..., jnp.array([0, 3])]  # θj' [..., M, gear]
    dx = velocity[..., jnp.array([2, 5])]  # xj' [..., M, gear]
    surf = arms * speed[..., None, :] - dx[..., None, :]
    return displacement, velocity, dte, (d, d_back), (fm, f_back), tooth, surf


def _postprocess(dyn: GearDynamics, mesh, op, w, aux, options: DynamicsOptions) -> DynamicResponse:
    iters, _, newton_ok, floquet = aux
    m = mesh.n_positions
    dense = jnp.arange(DAMPER_SAMPLES * m + 1) / (DAMPER_SAMPLES * m)
    zs_dense = _integrate(dyn, w[:12], w[12], options, ts=dense)
    q_dense, v_dense = dyn.physical(zs_dense[:-1])
    damper = jnp.mean(dyn.damper_power(dense[:-1], q_dense, v_dense))
    ts = dense[::DAMPER_SAMPLES]
    zs = zs_dense[::DAMPER_SAMPLES]
    resid = jnp.max(jnp.abs(zs[-1] - zs[0])) / jnp.maximum(jnp.max(jnp.abs(zs)), 1e-30)
    displacement, velocity, dte, (d, d_back), (fm, f_back), tooth, surf = _kinematics(
        dyn, mesh, zs[:-1]
    )
    harm = dte_harmonic_amplitudes(dte)
    rms = jnp.sqrt(jnp.sum(harm**2))
    finite = jnp.all(jnp.isfinite(zs)) & jnp.isfinite(rms)
    converged = newton_ok & finite
    stable = floquet <= 1.0 + STABILITY_TOL
    status = jnp.where(
        finite,
        jnp.where(
            converged, jnp.where(stable, STATUS_CONVERGED, STATUS_UNSTABLE), STATUS_NOT_CONVERGED
        ),
        STATUS_NOT_FINITE,
    )
    return DynamicResponse(
        speed_rpm=jnp.asarray(op.speed_rpm, float),
        torque=jnp.asarray(op.torque, float),
        load_torque=dyn.load_torque(w[12]),
        mesh_fraction=ts[:-1],
        time=ts[:-1] * dyn.mesh_period,
        displacement=displacement,
        velocity=velocity,
        dynamic_te=dte,
        mesh_force=fm,
        tooth_force=tooth,
        surface_velocity=surf,
        contact_loss=(d < 0.0).astype(float),
        back_contact=(d_back > 0.0).astype(float),
        contact_lost=jnp.any(d < 0.0),
        dte_harmonics=harm,
        dte_rms=rms,
        converged=converged,
        stable=stable,
        floquet_multiplier=floquet,
        status=status.astype(jnp.int32),
        newton_iterations=iters.astype(jnp.int32),
        periodicity_residual=resid,
        initial_state=w,
        back_force=f_back,
        mesh_damping_power=damper,
    )


#: Record periodicities tested by ``AttractorRecord.period`` (period-1 to period-4 orbits).
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
    """One classical Runge-Kutta step of size ``h`` from τ = ``t`` (mesh periods)."""
    k1 = dyn(t, z, s)
    k2 = dyn(t + 0.5 * h, z + 0.5 * h * k1, s)
    k3 = dyn(t + 0.5 * h, z + 0.5 * h * k2, s)
    k4 = dyn(t + h, z + h * k3, s)
    return z + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def _rk4(dyn: GearDynamics, z, s, n_steps):
    """``n_steps`` RK4 steps of ``dyn.step`` from τ = 0 (a whole number of mesh periods when
    n_steps is a multiple of the steps per period). Used for the attractor, whose settling is a
    transient whose details do not matter: about 3.5× cheaper per step on a CPU than a diffrax
    solve per period (measured, 2026-11-24), and cheap to compile (the shooting's diffrax solve is
    not traced again)."""
    return jax.lax.fori_loop(
        0, n_steps, lambda i, z: _rk4_step(dyn, z, s, i * dyn.step, dyn.step), z
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
        q, v = dyn.physical(z)
        energy = energy + dyn.damper_power(t, q, v)
        z = _rk4_step(dyn, z, s, t, h)
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

    Use it where ``dynamic_response`` reports no stable periodic orbit (status 1 or 3): the gears
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


def _check_inputs(pair, op):
    check_instance("pair", pair, GearPair)
    check_instance("op", op, OperatingPoint)
    if is_concrete(op):
        check_positive("OperatingPoint.speed_rpm", op.speed_rpm, "rpm")
        check_positive("OperatingPoint.torque", op.torque, "N m")
    if is_concrete(pair):
        check_positive("blank_mass", pair.blank_mass, "kg")
        check_positive("blank_inertia", pair.blank_inertia, "kg m^2")


def _canonical(tree):
    """Floating leaves as strong-typed default-float arrays, so that equal shapes share one compiled
    function whatever Python or weak types the caller used."""
    ftype = jnp.result_type(float)

    def conv(x):
        if isinstance(x, float) or (eqx.is_array(x) and jnp.issubdtype(x.dtype, jnp.floating)):
            return jnp.asarray(x, dtype=ftype)
        return x

    return jax.tree_util.tree_map(conv, tree)


def _prepare(pair, op, mesh, interface, options):
    if interface is None:
        m = options.n_positions if mesh is None else mesh.n_positions
        interface = MeshInterface.zeros(m)
    return _canonical((pair, op, mesh, interface, options))


def _mesh_and_interface(pair, op, mesh, interface, options):
    if mesh is None:
        from ..gear.mesh import mesh_cycle  # provided by the gear-mesh issue

        mesh = mesh_cycle(pair, torque=op.torque, n_positions=options.n_positions)
    if interface is None:
        interface = MeshInterface.zeros(mesh.n_positions)
    return mesh, interface


def _steady_state(pair, op, mesh, interface, options, guess):
    dyn = build_dynamics(pair, op, mesh, interface, options)
    cold = static_guess(dyn)
    guess = cold if guess is None else jnp.where(jnp.all(jnp.isfinite(guess)), guess, cold)
    batch = jax.tree_util.tree_map(lambda a: a[None], dyn)
    w, aux = _batch_solve(batch, guess[None], options, fallback_from=cold[None])
    return _postprocess(dyn, mesh, op, w[0], _index(aux, 0), options)


@eqx.filter_jit
def _dynamic_response_jit(pair, op, mesh, interface, options, guess):
    mesh, interface = _mesh_and_interface(pair, op, mesh, interface, options)
    return _steady_state(pair, op, mesh, interface, options, guess)


def dynamic_response(
    pair,
    op: OperatingPoint,
    *,
    mesh=None,
    interface: MeshInterface | None = None,
    options: DynamicsOptions | None = None,
    initial_state=None,
) -> DynamicResponse:
    """Periodic steady-state dynamic response of ``pair`` at ``op`` over one mesh cycle.

    Args:
        pair: GearPair (masses, inertias, bearings, backlash 2ℓ).
        op: OperatingPoint (torque T1 in N m on gear 1, speed of gear 1 in rpm).
        mesh: MeshCycle (default ``jg.mesh_cycle(pair, torque=op.torque, n_positions=options.n_positions)``).
        interface: MeshInterface over the mesh's positions (default zeros: dry, frictionless).
        options: DynamicsOptions (backlash model, steps per period, Newton settings).
        initial_state: shooting unknowns [13] to start Newton from (e.g. ``initial_state`` of a
            neighbouring speed); default the static equilibrium.

    Returns:
        DynamicResponse. Differentiable (forward mode: ``jax.jvp``/``jax.jacfwd``) in every traced input
        by implicit differentiation of the periodicity condition.
    """
    options = DynamicsOptions() if options is None else options
    _check_inputs(pair, op)
    # NaN marks "no guess" so that passing a guess or not shares one compiled function.
    guess = jnp.full(13, jnp.nan) if initial_state is None else jnp.asarray(initial_state, float)
    pair, op, mesh, interface, options = _prepare(pair, op, mesh, interface, options)
    return _dynamic_response_jit(pair, op, mesh, interface, options, guess)


def _at_speed(op: OperatingPoint, speed_rpm) -> OperatingPoint:
    return eqx.tree_at(lambda o: o.speed_rpm, op, jnp.asarray(speed_rpm, float))


def _rescale_guess(w, old_speed, new_speed):
    # Velocities in the scaled state are per mesh period: keep dq/dt, rescale dq/dτ.
    factor = old_speed / new_speed
    return w.at[6:12].multiply(factor)


@eqx.filter_jit
def _sweep_parallel(pair, op, speeds, mesh, interface, options):
    mesh, interface = _mesh_and_interface(pair, op, mesh, interface, options)

    def dyn_at(speed):
        return build_dynamics(pair, _at_speed(op, speed), mesh, interface, options)

    dyns = jax.vmap(dyn_at)(speeds)
    guesses = jax.vmap(static_guess)(dyns)
    w, aux = _batch_solve(dyns, guesses, options)

    def post(speed, dyn, w, aux):
        return _postprocess(dyn, mesh, _at_speed(op, speed), w, aux, options)

    return jax.vmap(post)(speeds, dyns, w, aux)


@eqx.filter_jit
def _sweep_continuation(pair, op, speeds, mesh, interface, options):
    mesh, interface = _mesh_and_interface(pair, op, mesh, interface, options)

    def step(carry, speed):
        w_prev, speed_prev, have_prev, prev_stable = carry
        op_n = _at_speed(op, speed)
        dyn = build_dynamics(pair, op_n, mesh, interface, options)
        cold = static_guess(dyn)
        guess = jnp.where(have_prev, _rescale_guess(w_prev, speed_prev, speed), cold)
        # Newton from the previous orbit; if that branch has disappeared (no convergence, or only an
        # unstable orbit is left), the state left by the previous speed decays to the new attractor:
        # this is the jump.
        batch = jax.tree_util.tree_map(lambda a: a[None], dyn)
        # Inside a band where the previous speed had no stable orbit either, an unstable orbit is
        # accepted without the (costly, futile) transient retry.
        w, aux = _batch_solve(batch, guess[None], options, retry_unstable=~have_prev | prev_stable)
        w, aux = w[0], _index(aux, 0)
        res = _postprocess(dyn, mesh, op_n, w, aux, options)
        # Carry only stable orbits: an unstable one (inside a band without a stable periodic orbit)
        # is not what the gears settle on and may sit far from it.
        ok = res.converged & res.stable
        new_carry = (
            jnp.where(ok, w, w_prev),
            jnp.where(ok, speed, speed_prev),
            have_prev | ok,
            res.stable | ~res.converged,
        )
        return new_carry, res

    init = (jnp.zeros(13), speeds[0], jnp.asarray(False), jnp.asarray(True))
    _, out = jax.lax.scan(step, init, speeds)
    return out


def dynamic_response_sweep(
    pair,
    op: OperatingPoint,
    speeds_rpm,
    *,
    mode: str = "parallel",
    mesh=None,
    interface: MeshInterface | None = None,
    options: DynamicsOptions | None = None,
):
    """Steady-state responses over gear 1 speeds ``speeds_rpm`` (rpm), torque ``op.torque``.

    Modes:
        "parallel": every speed independently from the static equilibrium (``vmap``).
        "continuation": speeds in the given order with ``lax.scan``, each Newton started from the
            previous orbit (the paper's stepwise speed change); a lost branch restarts from static
            equilibrium, which is how jumps appear.
        "up_down": continuation up the ascending speeds and back down; returns ``(up, down)``, both
            ordered by ascending speed, so that hysteresis shows as up ≠ down.

    Returns:
        DynamicResponse with a leading speed axis (a pair of them for "up_down").
    """
    options = DynamicsOptions() if options is None else options
    speeds = jnp.asarray(speeds_rpm, dtype=float)
    if speeds.ndim != 1 or speeds.shape[0] < 1:
        raise ValueError(
            f"speeds_rpm has shape {speeds.shape}; valid: a non-empty 1-D array of speeds, rpm"
        )
    check_positive("speeds_rpm", speeds, "rpm")
    _check_inputs(pair, op)
    pair, op, mesh, interface, options = _prepare(pair, op, mesh, interface, options)
    if mode == "parallel":
        return _sweep_parallel(pair, op, speeds, mesh, interface, options)
    if mode == "continuation":
        return _sweep_continuation(pair, op, speeds, mesh, interface, options)
    if mode == "up_down":
        asc = jnp.sort(speeds)
        up = _sweep_continuation(pair, op, asc, mesh, interface, options)
        down = _sweep_continuation(pair, op, asc[::-1], mesh, interface, options)
        down = jax.tree_util.tree_map(lambda a: a[::-1], down)
        return up, down
    raise ValueError(
        f"mode = {mode!r} is not valid; valid choices: 'parallel', 'continuation', 'up_down'"
    )
