"""Periodic steady-state response of the 6-DOF gear model over one mesh cycle, DTE and speed sweeps.

The steady state is the periodic orbit over one mesh period, found by shooting (``shooting.py``:
Newton-Broyden on the periodicity of the period map, with the load-torque correction s as a 13th
unknown and a gauge on the free rigid-body rotation as the 13th equation,

    R(z0, s) = [ z(Tm; z0, s) − z0 ,  r1φ1(0) + r2φ2(0) ] = 0),

integrated by a fixed-step Runge-Kutta method (``integrate.py``). Periodicity of the rotations
themselves (not only of their speeds) makes the mean speed exactly nominal, so s is the mean moment
balance including friction and damping. Gradients of anything computed from the orbit use the
implicit function theorem on R = 0, never the Newton iterations, in forward and reverse mode.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, Bool, Float, Int

from .._inputs import canonical
from .._validation import check_instance, check_positive, is_concrete
from ..gear.mesh import mesh_cycle
from ..gear.pair import GearPair
from ..operating import OperatingPoint
from ..results import Status
from .integrate import PeriodFlow
from .model import DynamicsOptions, GearDynamics, MeshInterface, build_dynamics
from .shooting import STABILITY_TOL, OrbitStats, periodic_orbit, static_guess

#: Mesh harmonics in the DTE RMS (REFERENCE §7 R1).
N_HARMONICS = 10

# Status codes of a DynamicResponse (``results.Status``).
STATUS_CONVERGED = Status.OK
STATUS_NOT_CONVERGED = Status.DYNAMICS
STATUS_NOT_FINITE = Status.NON_FINITE
STATUS_UNSTABLE = Status.UNSTABLE


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
        floquet_multiplier: the largest |μ|; status (``results.Status``): 0 converged and stable,
        2 Newton did not converge, 4 not finite, 8 converged to an unstable orbit; newton_iterations,
        periodicity_residual: max |z(Tm) − z(0)| / max |z| of the returned orbit (dimensionless).
        initial_state: the shooting unknowns [13] (scaled state at τ = 0 and s), reusable as a guess.
        back_force: the back flanks' force alone (≤ 0, N) [M]: part of ``mesh_force``, apart
            from a mesh damper's pull on separating drive flanks (``GearDynamics._contact_force``).
        mesh_damping_power: mean power the mesh damper along the line of action dissipates over
            the cycle, W (``GearPair.mesh_damping_ratio``; 0 without it): ⟨(f − f_el) d'⟩ over
            both flank pairs, f_el the elastic force alone, integrated along the orbit with the
            state (``integrate.period_flow``). Not part of the mesh friction loss Φ̄.
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


def postprocess(
    dyn: GearDynamics, mesh, op, w, stats: OrbitStats, flow: PeriodFlow
) -> DynamicResponse:
    """The DynamicResponse of the orbit ``w`` [13] with its ``PeriodFlow`` and shooting stats."""
    zs = flow.positions
    resid = jnp.max(jnp.abs(flow.final - w[:12])) / jnp.maximum(jnp.max(jnp.abs(zs)), 1e-30)
    displacement, velocity, dte, (d, d_back), (fm, f_back), tooth, surf = _kinematics(dyn, mesh, zs)
    harm = dte_harmonic_amplitudes(dte)
    rms = jnp.sqrt(jnp.sum(harm**2))
    finite = jnp.all(jnp.isfinite(zs)) & jnp.all(jnp.isfinite(flow.final)) & jnp.isfinite(rms)
    converged = stats.converged & finite
    stable = stats.floquet_multiplier <= 1.0 + STABILITY_TOL
    status = jnp.where(
        finite,
        jnp.where(
            converged, jnp.where(stable, STATUS_CONVERGED, STATUS_UNSTABLE), STATUS_NOT_CONVERGED
        ),
        STATUS_NOT_FINITE,
    )
    tau = mesh.mesh_fraction
    return DynamicResponse(
        speed_rpm=jnp.asarray(op.speed_rpm, float),
        torque=jnp.asarray(op.torque, float),
        load_torque=dyn.load_torque(w[12]),
        mesh_fraction=tau,
        time=tau * dyn.mesh_period,
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
        floquet_multiplier=stats.floquet_multiplier,
        status=status.astype(jnp.int32),
        newton_iterations=stats.iterations.astype(jnp.int32),
        periodicity_residual=resid,
        initial_state=w,
        back_force=f_back,
        mesh_damping_power=flow.damper_power,
    )


def solve_steady_state(dyn: GearDynamics, mesh, op, options, guess, retry_unstable=True):
    """The periodic steady state of ``dyn`` (DynamicResponse), Newton from ``guess`` [13] (NaN:
    from the static equilibrium), the fallback's transient from the static equilibrium."""
    cold = static_guess(dyn)
    w0 = jnp.where(jnp.all(jnp.isfinite(guess)), guess, cold)
    w, stats, flow = periodic_orbit(
        dyn, w0, options, mesh.n_positions, fallback_from=cold, retry_unstable=retry_unstable
    )
    return postprocess(dyn, mesh, op, w, stats, flow)


def steady_state(pair, op, mesh, interface, options, guess, retry_unstable=True):
    """``solve_steady_state`` of the dynamics of ``pair`` at ``op`` with the mesh cycle ``mesh``
    and the interface tables ``interface`` (traceable: no checks)."""
    dyn = build_dynamics(pair, op, mesh, interface, options)
    return solve_steady_state(dyn, mesh, op, options, guess, retry_unstable)


def _check_inputs(pair, op):
    check_instance("pair", pair, GearPair)
    check_instance("op", op, OperatingPoint)
    if is_concrete(op):
        check_positive("OperatingPoint.speed_rpm", op.speed_rpm, "rpm")
        check_positive("OperatingPoint.torque", op.torque, "N m")
    if is_concrete(pair):
        check_positive("blank_mass", pair.blank_mass, "kg")
        check_positive("blank_inertia", pair.blank_inertia, "kg m^2")


def _prepare(pair, op, mesh, interface, options):
    if interface is None:
        m = options.n_positions if mesh is None else mesh.n_positions
        interface = MeshInterface.zeros(m)
    return canonical((pair, op, mesh, interface, options))


def _mesh_and_interface(pair, op, mesh, interface, options):
    if mesh is None:
        mesh = mesh_cycle(pair, torque=op.torque, n_positions=options.n_positions)
    if interface is None:
        interface = MeshInterface.zeros(mesh.n_positions)
    return mesh, interface


@eqx.filter_jit
def _dynamic_response_jit(pair, op, mesh, interface, options, guess):
    mesh, interface = _mesh_and_interface(pair, op, mesh, interface, options)
    return steady_state(pair, op, mesh, interface, options, guess)


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
        DynamicResponse. Differentiable in every traced input, in forward and reverse mode, by
        implicit differentiation of the periodicity condition.
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
    nan = jnp.full(13, jnp.nan)
    return jax.vmap(
        lambda speed: steady_state(pair, _at_speed(op, speed), mesh, interface, options, nan)
    )(speeds)


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
        # this is the jump. Inside a band where the previous speed had no stable orbit either, an
        # unstable orbit is accepted without the (costly, futile) transient retry.
        res = solve_steady_state(
            dyn, mesh, op_n, options, guess, retry_unstable=~have_prev | prev_stable
        )
        # Carry only stable orbits: an unstable one (inside a band without a stable periodic orbit)
        # is not what the gears settle on and may sit far from it.
        ok = res.converged & res.stable
        new_carry = (
            jnp.where(ok, res.initial_state, w_prev),
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
