"""The thermal tribo-dynamic model: gear dynamics and the lubricated contacts solved together.

REFERENCE §1 (paper): the dynamics, given the mesh interface tables (EHL damping cm and friction forces
F1, F2 per position and tooth pair), give the dynamic tooth forces W_T and surface velocities uj; the
contacts, given W_T and uj, give new tables; the two are iterated to a fixed point. jaxgear solves the
fixed point with optimistix (damped fixed-point iteration) and differentiates the converged solution
implicitly (``optx.ImplicitAdjoint`` with a matrix-free GMRES solve of (I − ∂T/∂x) that stops at the
Krylov step where it has converged, ``_krylov.EarlyExitGMRES``), so gradients never pass through the
iterations. The dynamic periodic orbit is carried in the fixed-point state, so each
iteration's shooting starts from the previous orbit.

The quasi-static variant (``Fidelity(dynamics="quasi_static")``) uses W_T = W_sT and the kinematic surface
velocities and needs no iteration.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx
from jaxtyping import Array, Bool, Float, Int

from ._krylov import EarlyExitGMRES
from ._validation import check_instance, check_non_negative, is_concrete
from .anderson import Anderson
from .dynamics.model import DynamicsOptions, MeshInterface
from .dynamics.attractor import DEFAULT_KICK, record_attractor
from .dynamics.response import dte_harmonic_amplitudes, steady_state
from .fidelity import Fidelity
from .gear.geometry import gear_geometry, mesh_period
from .gear.load_sharing import DEFAULT_CONTACT_SMOOTHING
from .gear.mesh import DEFAULT_EDGE_WIDTH, MeshCycle, _back_mesh, mesh_cycle
from .gear.modification import DEFAULT_RELIEF_SMOOTHING
from .gear.pair import GearPair
from .lubrication.friction_models import XuFriction, smooth_sign
from .lubrication.lubricant import Lubricant
from .lubrication.roughness import Surfaces
from .material import reduced_modulus
from .operating import OperatingPoint
from .power_loss import cycle_mean, efficiency, total_per_position

# Status codes of a simulation (0 is success; the first failure found, in this order, is reported).
STATUS_OK = 0
STATUS_FIXED_POINT = 1  # tribo-dynamic fixed point did not reach its tolerance
STATUS_DYNAMICS = 2  # periodic orbit not converged or unstable
STATUS_CONTACT = 3  # a contact solve did not converge
STATUS_NON_FINITE = 4
# 5 is the sweep's own "chunk raised or non-finite" (sweep.SweepResult)
STATUS_ATTRACTOR = 6  # no stable periodic orbit: means over the attractor reached in time
# Recorded attractor cycles at which the contacts are evaluated (of Fidelity.attractor_periods):
# the closed-form mixed EHL contacts of a cycle cost ~4 ms on 2 cores (64 contacts), the record's
# dynamics ~0.9 ms a cycle, so 64 of 256 cycles keep the contacts at about the dynamics' cost.
ATTRACTOR_CONTACT_CYCLES = 64
# Settling cycles of an attractor continued from the previous speed's (continuation sweeps): the
# attractor moves little between neighbouring speeds (measured: see tests/test_attractor.py).
ATTRACTOR_WARM_SETTLE = 200
STATUS_NAMES = {
    STATUS_OK: "ok",
    STATUS_FIXED_POINT: "tribo-dynamic fixed point not converged",
    STATUS_DYNAMICS: "dynamic periodic orbit not converged or unstable",
    STATUS_CONTACT: "contact solver not converged",
    STATUS_NON_FINITE: "non-finite result",
    STATUS_ATTRACTOR: "no stable periodic orbit: means over the attractor (time integration)",
}

# The friction force of the formula rungs changes sign with the sliding velocity through a smooth
# sign over a slide-to-roll ratio of SIGN_SLIDE_TO_ROLL: real EHL traction grows linearly with slip up
# to ~1-2 % SRR before it saturates, and a discontinuous sign makes the tribo-dynamic fixed point
# chatter between neighbouring states (vibration moves the sign change from one position to the next).
SIGN_SLIDE_TO_ROLL = 0.02


class ContactForces(eqx.Module):
    """What the contacts of one mesh cycle give back, per [position, pair] (SI).

    Attributes:
        friction_sliding: Fs, N (sign along u2 − u1, paper Eq. 15).
        friction_rolling: Fr, N (paper Eq. 15).
        damping: cm, N s/m (paper Eq. 13).
        power_sliding: sliding part of Φn, W.
        power_rolling: rolling part of Φn, W.
        friction_coefficient: (Fs² + Fr²)^½ / W_T where loaded (informative), dimensionless.
        converged: every contact solve converged.
        failed: number of loaded contacts whose solve failed (their outputs are carried over from
            the nearest good contact; see ``contacts._patch_failed``).
    """

    friction_sliding: Float[Array, "M 2"]
    friction_rolling: Float[Array, "M 2"]
    damping: Float[Array, "M 2"]
    power_sliding: Float[Array, "M 2"]
    power_rolling: Float[Array, "M 2"]
    friction_coefficient: Float[Array, "M 2"]
    converged: Bool[Array, ""]
    failed: Int[Array, ""]


def _safe_sqrt(x):
    ok = x > 0
    return jnp.where(ok, jnp.sqrt(jnp.where(ok, x, 1.0)), 0.0)


def formula_contact_forces(
    pair: GearPair,
    lubricant,
    surfaces,
    mesh: MeshCycle,
    fidelity: Fidelity,
    load,
    u1,
    u2,
    inlet_temperature,
) -> ContactForces:
    """Constant-μ and regression-formula rungs: Fs = μ W_T sgn(u2 − u1), no rolling loss, no damping.

    The regression rung uses Xu, Kahraman, Anderson & Maddock (2007) (REFERENCE §9) at the dynamic
    Hertz pressure, slide-to-roll ratio and entraining velocity of each contact, the inlet viscosity
    and the composite roughness. These rungs model the sliding loss only: rolling (Poiseuille) loss and
    EHL damping come from the EHL rungs.
    """
    width = pair.face_width
    loaded = load > 0
    w = jnp.where(loaded, load, 0.0) / width
    e_red = reduced_modulus(*pair.materials)
    radius = mesh.reduced_radius
    us = u1 - u2
    if fidelity.friction == "constant":
        mu = jnp.full_like(load, fidelity.constant_mu)
    else:
        ph = _safe_sqrt(w * e_red / (2.0 * jnp.pi * radius))
        ph_safe = jnp.where(loaded, jnp.maximum(ph, 1e6), 1e9)
        ve = jnp.maximum(u1 + u2, 1e-6)
        eta0 = lubricant.viscosity(jnp.zeros(()), inlet_temperature)
        mu = XuFriction().coefficient(
            ph_safe, 2.0 * us / ve, ve, eta0, radius, surfaces.composite_rq
        )
        mu = jnp.where(loaded, mu, 0.0)
    force = mu * jnp.where(loaded, load, 0.0)
    sign = smooth_sign(u2 - u1, SIGN_SLIDE_TO_ROLL * 0.5 * jnp.abs(u1 + u2) + 1e-9)
    zeros = jnp.zeros_like(force)
    return ContactForces(
        friction_sliding=force * sign,
        friction_rolling=zeros,
        damping=zeros,
        power_sliding=force * sign * (u2 - u1),
        power_rolling=zeros,
        friction_coefficient=mu,
        converged=jnp.asarray(True),
        failed=jnp.asarray(0, dtype=jnp.int32),
    )


def formula_ehl_contact_forces(
    pair: GearPair,
    lubricant,
    surfaces,
    mesh: MeshCycle,
    fidelity: Fidelity,
    load,
    u1,
    u2,
    inlet_temperature,
) -> ContactForces:
    """The "ehl_formula" rung: each loaded contact by the closed-form mixed EHL model of
    ``lubrication/ehl_formula.py`` (sliding and rolling loss, damping cm), iso-thermal and
    quasi-steady, with the EHL rungs' shear law, μb and Greenwood-Tripp constants."""
    from .lubrication.contacts import LOADED_SHARE
    from .lubrication.ehl_formula import ehl_formula_contact

    width = pair.face_width
    # Loaded as on the EHL rungs: a touch below 1e-4 of the total load (the edge of tip relief, down
    # to 1e-289 N) carries nothing; the formulas would give an unbounded film there.
    loaded = load > LOADED_SHARE * mesh.total_load
    w = jnp.where(loaded, load, mesh.total_load) / width  # a finite stand-in where unloaded
    ve = u1 + u2
    ok_u = ve > 0
    c = ehl_formula_contact(
        mesh.reduced_radius,
        w,
        jnp.where(ok_u, u1, 1.0),
        jnp.where(ok_u, u2, 1.0),
        reduced_modulus(*pair.materials),
        lubricant,
        inlet_temperature,
        surfaces.composite_rq,
        boundary_friction=fidelity.boundary_friction,
        shear=fidelity.shear,
        density_product=fidelity.asperity_density_product,
        slope_ratio=fidelity.asperity_slope_ratio,
        sign_width=SIGN_SLIDE_TO_ROLL * 0.5 * jnp.abs(ve) + 1e-9,
        limiting_shear=fidelity.limiting_shear_coefficient,
    )
    on = loaded & ok_u
    per_pair = lambda x: jnp.where(on, x * width, 0.0)
    fs, fr = per_pair(c.friction_sliding), per_pair(c.friction_rolling)
    safe_load = jnp.where(on, load, 1.0)
    return ContactForces(
        friction_sliding=fs,
        friction_rolling=fr,
        damping=per_pair(c.damping),
        power_sliding=per_pair(c.power_sliding),
        power_rolling=per_pair(c.power_rolling),
        friction_coefficient=jnp.where(on, _safe_sqrt(fs * fs + fr * fr) / safe_load, 0.0),
        converged=jnp.asarray(True),
        failed=jnp.asarray(0, dtype=jnp.int32),
    )


def contact_forces(
    pair,
    lubricant,
    surfaces,
    mesh,
    fidelity,
    load,
    u1,
    u2,
    inlet_temperature,
    initial=None,
    period=None,
):
    """Dispatch on ``fidelity.friction`` (a static choice: unused rungs are never traced).

    Returns (ContactForces, contact state): the contact state is the batch of EHL solutions on the EHL
    rungs (a warm start for the next evaluation, and the fields), None on the formula rungs.
    """
    if fidelity.friction in ("constant", "regression", "ehl_formula"):
        closed_form = (
            formula_ehl_contact_forces
            if fidelity.friction == "ehl_formula"
            else formula_contact_forces
        )
        forces = closed_form(
            pair, lubricant, surfaces, mesh, fidelity, load, u1, u2, inlet_temperature
        )
        return forces, None
    from .lubrication.contacts import ehl_contact_forces

    return ehl_contact_forces(
        pair, lubricant, surfaces, mesh, fidelity, load, u1, u2, inlet_temperature, initial, period
    )


def interface_from_forces(forces: ContactForces) -> MeshInterface:
    """Paper Eq. 14-15 without the cm term (the dynamics adds cm times the vibratory sliding speed):
    F1 = Fs − Fr, F2 = Fs + Fr."""
    return MeshInterface(
        damping=forces.damping,
        friction_1=forces.friction_sliding - forces.friction_rolling,
        friction_2=forces.friction_sliding + forces.friction_rolling,
    )


class SimulationResult(eqx.Module):
    """The tribo-dynamic (or quasi-static) solution over one mesh cycle (SI; M positions, 2 pair slots).

    Attributes:
        power_loss: Φ̄, cycle-mean mesh power loss, W (paper Eq. 17).
        power_loss_sliding, power_loss_rolling: its sliding and rolling parts, W.
        efficiency: Ψ = 1 − Φ̄/(T1 ω1).
        dte_rms: RMS dynamic transmission error over the first 10 mesh harmonics, m (REFERENCE §7 R1);
            quasi-static: of the static TE.
        power_loss_position: Φ(t_i), W [M]; power_loss_pair: Φn(t_i), W [M, 2] (and its sliding and
            rolling parts power_sliding_pair, power_rolling_pair).
        tooth_force: W_T per pair, N [M, 2]; surface_velocity: uj per [position, pair, gear], m/s.
        hertz_pressure: Hertz pressure of W_T per pair, Pa [M, 2].
        friction_coefficient: per pair [M, 2]; damping: cm per pair, N s/m [M, 2].
        dynamic_te: εd(t_i), m [M]; roll_angle: gear 1 roll angle of slot 0, rad [M].
        converged: everything converged; status: 0 ok, else the first failure (see STATUS_NAMES);
            6 (STATUS_ATTRACTOR): the fixed point has no stable periodic orbit, and the values are
            means over the attractor the gears settle on (``Fidelity.attractor_periods``);
        fixed_point_residual: |T(y) − y| of the friction table F1 relative to its maximum, in the
            last fixed-point evaluation;
        fixed_point_iterations: iterations used (0 for quasi-static).
        failed_contacts: loaded contacts of the cycle whose EHL solve failed (status 3); their
            outputs are carried over from the nearest good contact of the engagement, never used as
            they came out.
        power_loss_back: the back flanks' part of Φ̄ (and of its sliding and rolling parts and
            Φ(t)), W: where rattling teeth strike the back flanks, on the attractor (status 6) or
            on a periodic orbit, their contacts on the mirrored line of action
            (``_back_flank_power``); 0 elsewhere.
        back_contact_share: share of the mesh cycle with back-flank contact (the mesh deflection
            past the backlash, negative tooth forces; on status 6 over every recorded cycle of the
            attractor). 0 when quasi-static.
        mesh_damping_power: mean power the viscous mesh damper along the line of action
            dissipates, W (``GearPair.mesh_damping_ratio``; 0 without it, and when quasi-static):
            vibration energy turned into heat in the mesh, not friction, so not part of Φ̄ or Ψ
            (the paper's loss is the friction's; neither are the bearings' and torsional
            dampers'). On status 6 the attractor record's mean.
    """

    power_loss: Float[Array, ""]
    power_loss_sliding: Float[Array, ""]
    power_loss_rolling: Float[Array, ""]
    efficiency: Float[Array, ""]
    dte_rms: Float[Array, ""]
    power_loss_position: Float[Array, " M"]
    power_loss_pair: Float[Array, "M 2"]
    power_sliding_pair: Float[Array, "M 2"]
    power_rolling_pair: Float[Array, "M 2"]
    tooth_force: Float[Array, "M 2"]
    surface_velocity: Float[Array, "M 2 2"]
    hertz_pressure: Float[Array, "M 2"]
    friction_coefficient: Float[Array, "M 2"]
    damping: Float[Array, "M 2"]
    dynamic_te: Float[Array, " M"]
    roll_angle: Float[Array, " M"]
    converged: Bool[Array, ""]
    status: Int[Array, ""]
    fixed_point_residual: Float[Array, ""]
    fixed_point_iterations: Int[Array, ""]
    failed_contacts: Int[Array, ""]
    power_loss_back: Float[Array, ""]
    back_contact_share: Float[Array, ""]
    mesh_damping_power: Float[Array, ""]


def kinematic_velocities(pair: GearPair, mesh: MeshCycle, omega1):
    """Kinematic surface velocities uj = ρj ωj per [position, pair, gear], m/s."""
    omega = jnp.stack([omega1, omega1 * pair.teeth[0] / pair.teeth[1]])
    return mesh.radius_of_curvature * omega


def _hertz(pair, mesh, load):
    w = jnp.maximum(load, 0.0) / pair.face_width
    return _safe_sqrt(w * reduced_modulus(*pair.materials) / (2.0 * jnp.pi * mesh.reduced_radius))


def _dynamics_options(fidelity: Fidelity) -> DynamicsOptions:
    return DynamicsOptions(
        steps_per_period=fidelity.steps_per_period,
        n_positions=fidelity.n_positions,
        backlash=fidelity.backlash,
        back_flank=fidelity.back_flank,
    )


def _back_contact_share(load):
    """Share of the positions of one cycle's tooth forces ``load`` [..., M, 2] whose mesh force
    (their sum) is negative: back-flank contact."""
    return jnp.mean((jnp.sum(load, axis=-1) < 0.0).astype(load.dtype))


def _back_flank_power(pair, op, fidelity, mesh, mesh_force, contacts):
    """The back flanks' power loss per position [M] (sliding, rolling), W: the means over the
    cycles of ``mesh_force`` [C, M] (the back flanks' force, ≤ 0) of the back-flank contacts
    where it is negative.

    The back contacts stand where the mirror image of the drive mesh puts them
    (``gear.mesh.back_flank_mesh``); the negative mesh force is shared among them by their
    quasi-static load shares and solved by ``contacts(w, u, mesh)`` (the rung's contacts on the
    attractor) at the kinematic surface velocities of their radii of curvature (the vibration's
    velocities, which move the drive flanks' Φ̄ by < 0.4 %, are left out). Their friction does not
    act on the dynamics."""
    back_mesh = _back_mesh(
        pair,
        op.torque,
        mesh.mesh_fraction,
        fidelity.stiffness,
        DEFAULT_EDGE_WIDTH,
        DEFAULT_RELIEF_SMOOTHING,
        DEFAULT_CONTACT_SMOOTHING,
    )
    u = kinematic_velocities(pair, back_mesh, op.omega1)

    def one(fm):
        w = back_mesh.load_share * jnp.maximum(-fm, 0.0)[:, None]
        c = contacts(w, u, back_mesh)
        return total_per_position(c.power_sliding), total_per_position(c.power_rolling)

    sliding, rolling = jax.vmap(one)(mesh_force)
    return jnp.mean(sliding, axis=0), jnp.mean(rolling, axis=0)


def _assemble(
    pair, op, mesh, forces, load, velocity, dte, status, residual, iterations, back=None, damper=0.0
):
    """The SimulationResult; ``back``: (back_contact_share, (sliding, rolling) back-flank power
    per position) of the orbit or the attractor, or None (quasi-static: no back contact);
    ``damper``: the mesh damper's mean power (W)."""
    none = jnp.zeros(mesh.n_positions, dtype=load.dtype)
    back_contact, (back_sliding, back_rolling) = (None, (none, none)) if back is None else back
    power_pair = forces.power_sliding + forces.power_rolling
    sliding = cycle_mean(total_per_position(forces.power_sliding) + back_sliding)
    rolling = cycle_mean(total_per_position(forces.power_rolling) + back_rolling)
    loss = sliding + rolling
    dte_rms = jnp.sqrt(jnp.sum(dte_harmonic_amplitudes(dte) ** 2))
    # the tooth forces and the mesh too: a contact solver reads a NaN load as no contact (NaN > 0 is
    # false), so a NaN position would otherwise drop out of Φ̄ silently
    values = jnp.stack(
        [loss, dte_rms, jnp.sum(power_pair), jnp.sum(load), jnp.sum(mesh.mesh_stiffness)]
    )
    status = jnp.where(jnp.all(jnp.isfinite(values)), status, STATUS_NON_FINITE)
    return SimulationResult(
        power_loss=loss,
        power_loss_sliding=sliding,
        power_loss_rolling=rolling,
        efficiency=efficiency(loss, op.torque, op.omega1),
        dte_rms=dte_rms,
        power_loss_position=total_per_position(power_pair) + back_sliding + back_rolling,
        power_loss_pair=power_pair,
        power_sliding_pair=forces.power_sliding,
        power_rolling_pair=forces.power_rolling,
        tooth_force=load,
        surface_velocity=velocity,
        hertz_pressure=_hertz(pair, mesh, load),
        friction_coefficient=forces.friction_coefficient,
        damping=forces.damping,
        dynamic_te=dte,
        roll_angle=mesh.roll_angle,
        converged=status == STATUS_OK,
        status=jnp.asarray(status, dtype=jnp.int32),
        fixed_point_residual=jnp.asarray(residual, dtype=loss.dtype),
        fixed_point_iterations=jnp.asarray(iterations, dtype=jnp.int32),
        failed_contacts=jnp.asarray(forces.failed, dtype=jnp.int32),
        power_loss_back=cycle_mean(back_sliding + back_rolling),
        back_contact_share=(
            _back_contact_share(load) if back_contact is None else jnp.asarray(back_contact)
        ).astype(loss.dtype),
        mesh_damping_power=jnp.asarray(damper, dtype=loss.dtype),
    )


def _quasi_static(pair, lubricant, surfaces, op, fidelity, mesh):
    velocity = kinematic_velocities(pair, mesh, op.omega1)
    load = mesh.normal_load
    forces, _ = contact_forces(
        pair,
        lubricant,
        surfaces,
        mesh,
        fidelity,
        load,
        velocity[..., 0],
        velocity[..., 1],
        op.inlet_temperature,
        period=mesh_period(pair, op.speed_rpm),
    )
    status = jnp.where(forces.converged, STATUS_OK, STATUS_CONTACT)
    return _assemble(pair, op, mesh, forces, load, velocity, mesh.static_te, status, 0.0, 0)


def _cycle_contacts(pair, lubricant, surfaces, op, fidelity, mesh, load, velocity, initial=None):
    """The contacts of the cycle at tooth forces ``load`` [M, 2] and surface velocities ``velocity``
    [M, 2, 2] (``contact_forces``)."""
    return contact_forces(
        pair,
        lubricant,
        surfaces,
        mesh,
        fidelity,
        load,
        velocity[..., 0],
        velocity[..., 1],
        op.inlet_temperature,
        initial,
        period=mesh_period(pair, op.speed_rpm),
    )


def _tribo_dynamic(pair, lubricant, surfaces, op, fidelity, mesh, warm):
    options = _dynamics_options(fidelity)
    m = mesh.n_positions

    def contacts_at(load, velocity, initial=None):
        """The contacts of the cycle at tooth forces ``load`` and surface velocities ``velocity``."""
        return _cycle_contacts(
            pair, lubricant, surfaces, op, fidelity, mesh, load, velocity, initial
        )

    def respond(interface, guess):
        return steady_state(pair, op, mesh, interface, options, guess)

    # Plain iteration damps inside the map; Anderson damps in its mixing (same fixed point).
    beta = fidelity.relaxation if fidelity.anderson_memory == 0 else 1.0

    # The fixed-point state carries, beside the interface tables, the orbit (a warm start for the next
    # shooting) and what the result needs (tooth forces, velocities, DTE, contact forces), so the
    # dynamics and the contacts are traced once, inside the iteration.
    def step(state, _):
        interface = state["interface"]
        # Before the first orbit exists, shoot from the static equilibrium (NaN guess).
        guess = jnp.where(state["started"] > 0.5, state["guess"], jnp.nan)
        resp = respond(interface, guess)
        # A shooting that diverged (NaN orbit) must not poison the tables: the contacts keep the
        # last finite loads and velocities, and the next iteration shoots cold. (Seen at 3400 rpm at
        # the paper fidelity, where NaN contact outputs made the shooting diverge; those are now
        # kept finite at their source, contacts.ehl_contact_forces. This is the second guard.)
        finite = (
            jnp.all(jnp.isfinite(resp.initial_state))
            & jnp.all(jnp.isfinite(resp.tooth_force))
            & jnp.all(jnp.isfinite(resp.surface_velocity))
            & jnp.all(jnp.isfinite(resp.dynamic_te))
        )
        load = jnp.where(finite, resp.tooth_force, state["load"])
        u = jnp.where(finite, resp.surface_velocity, state["velocity"])
        if fidelity.coupling == "frozen":
            from .lubrication.contacts import frozen_contact_forces

            # the contacts of the quasi-static state, scaled to this iteration's loads and speeds
            forces = frozen_contact_forces(
                forces0, mesh.normal_load, velocity0, load, u, mesh.total_load, tangent0
            )
            contacts = state["contacts"]
        else:
            forces, contacts = contacts_at(load, u, jax.lax.stop_gradient(state["contacts"]))
        # The EHL solutions ride along only as the next iteration's warm start: a converged solve
        # does not depend on where it started, so they carry no derivative (and the implicit
        # fixed-point system is not asked to solve for thousands of film nodes).
        contacts = jax.lax.stop_gradient(contacts)
        new = interface_from_forces(forces)
        relaxed = jax.tree_util.tree_map(lambda a, b: (1.0 - beta) * a + beta * b, interface, new)
        return {
            "interface": relaxed,
            "guess": jnp.where(finite, resp.initial_state, state["guess"]),
            "load": load,
            "velocity": u,
            "dte": jnp.where(finite, resp.dynamic_te, state["dte"]),
            "damper": jnp.where(finite, resp.mesh_damping_power, state["damper"]),
            "back_force": jnp.where(finite, resp.back_force, state["back_force"]),
            "forces": forces,
            "dynamics_ok": jnp.where(finite & (resp.status == 0), 1.0, 0.0),
            "started": jnp.where(finite, 1.0, 0.0) * jnp.ones_like(state["started"]),
            "previous": interface.friction_1,
            "contacts": contacts,
        }

    zeros = jnp.zeros((m, 2), dtype=op.torque.dtype)
    if warm is None:
        warm = cold_start(m, zeros.dtype)
    # continuation: the neighbouring point's converged interface and orbit (a cold WarmStart has
    # zero tables and started = 0, which makes this the cold path, traced the same way)
    interface0, guess0, started0 = warm.interface, warm.orbit, warm.started
    velocity0 = kinematic_velocities(pair, mesh, op.omega1)

    # EHL rungs: cold solves at the quasi-static state, then every iteration warm-starts from the last
    # (one cold and one warm trace of the solver); formula rungs carry no contact state. Frozen
    # coupling: these are the only contact solves (``step`` scales them).
    def quasi_static_contacts(load_scale):
        return contacts_at(mesh.normal_load * load_scale, velocity0)

    one = jnp.ones((), dtype=zeros.dtype)
    tangent0 = None
    if fidelity.coupling == "frozen":
        # the outputs' response to the load, W ∂F/∂W, by forward mode through the converged solves
        # (implicit derivatives: no extra Newton iterations). Measured on the calibrated pair at
        # 1750 rpm (resonance, dynamic loads 0.1-2.2 × static), 32 × 129, iso-thermal transient
        # mixed EHL: Φ̄ 182.3 W with constant coefficients, 172.7 W with this power law, 162.3 W
        # with the full fixed point. It costs 26 % more than the contact solves alone at 32 × 129,
        # 85 % at 24 × 65 (the forward-mode pass through the marches).
        (forces0, contacts0), (tangent0, _) = jax.jvp(quasi_static_contacts, (one,), (one,))
    else:
        forces0, contacts0 = quasi_static_contacts(one)
    state0 = {
        "interface": interface0,
        "guess": guess0,
        "load": mesh.normal_load,
        "velocity": velocity0,
        "dte": mesh.static_te,
        "damper": jnp.zeros((), dtype=zeros.dtype),
        "back_force": jnp.zeros(m, dtype=zeros.dtype),
        "forces": forces0,
        "contacts": jax.lax.stop_gradient(contacts0),
        "dynamics_ok": jnp.asarray(1.0, dtype=zeros.dtype),
        "started": jnp.asarray(started0, dtype=zeros.dtype),
        "previous": zeros,
    }
    if fidelity.anderson_memory > 0:
        # Anderson mixing of the interface tables and the orbit; the carried outputs follow T.
        solver = Anderson(
            rtol=fidelity.fixed_point_rtol,
            atol=fidelity.fixed_point_rtol * 1e-3,
            memory=fidelity.anderson_memory,
            beta=fidelity.relaxation,
            core=lambda st: (st["interface"], st["guess"]),
            replace_core=lambda st, c: {**st, "interface": c[0], "guess": c[1]},
            # Converged means the interface tables settled, each relative to its largest entry
            # (Anderson.measure). The orbit is mixed too but only warm-starts the shooting, whose
            # own convergence is checked (dynamics_ok). An element-wise test failed point E at the
            # paper fidelity after 40 iterations with the friction table settled to 7e-9 of its
            # maximum: entries crossing zero at the pitch point cannot meet an absolute 1e-7 N.
            measure=lambda st: st["interface"],
        )
    else:
        solver = optx.FixedPointIteration(
            rtol=fidelity.fixed_point_rtol,
            atol=fidelity.fixed_point_rtol * 1e-3,
            norm=optx.max_norm,
        )
    # One JVP of ``step`` per Krylov vector and direction. T contracts strongly where the fixed point
    # converges in a few iterations, and then a few vectors solve the system (5 at 2500 rpm, fast());
    # lineax's GMRES(20) spent two whole cycles (41 JVPs) there: the gradient cost 6.4× the forward
    # instead of 3.0× (benchmarks/RESULTS.md, end_to_end).
    adjoint = optx.ImplicitAdjoint(linear_solver=EarlyExitGMRES(rtol=1e-10, atol=0.0))
    sol = optx.fixed_point(
        step,
        solver,
        state0,
        max_steps=fidelity.max_fixed_point_iterations,
        adjoint=adjoint,
        throw=False,
    )
    state = sol.value
    forces = state["forces"]
    # |T(y) − y| of the friction table relative to its maximum (T(y): the tables of the last
    # evaluation's forces; y: the tables it was evaluated at). Not the mixed iterate's change, which
    # Anderson can make small while T(y) − y stays large.
    new = interface_from_forces(forces).friction_1
    scale = jnp.maximum(jnp.max(jnp.abs(new)), 1e-12)
    residual = jax.lax.stop_gradient(jnp.max(jnp.abs(new - state["previous"])) / scale)
    fp_ok = sol.result == optx.RESULTS.successful
    status = jnp.where(
        ~fp_ok,
        STATUS_FIXED_POINT,
        jnp.where(
            state["dynamics_ok"] < 0.5,
            STATUS_DYNAMICS,
            jnp.where(forces.converged, STATUS_OK, STATUS_CONTACT),
        ),
    )
    load, velocity, dte = state["load"], state["velocity"], state["dte"]
    damper = state["damper"]
    attractor, on_attractor = jnp.zeros(13, dtype=zeros.dtype), jnp.zeros((), dtype=zeros.dtype)
    if fidelity.attractor_periods > 0:
        warm_attractor = (warm.attractor, warm.on_attractor)
        (forces, load, velocity, dte, damper), status, (attractor, on_attractor), *back = (
            _attractor_means(
                pair, lubricant, surfaces, op, fidelity, mesh, state, status, warm_attractor
            )
        )
    else:
        back = _orbit_back(pair, lubricant, surfaces, op, fidelity, mesh, state)
    its = sol.stats["num_steps"]
    result = _assemble(
        pair, op, mesh, forces, load, velocity, dte, status, residual, its, back, damper
    )
    if fidelity.attractor_periods > 0:
        result = _without_derivative_where(result, result.status == STATUS_ATTRACTOR)
    return result, WarmStart(
        interface=state["interface"],
        orbit=state["guess"],
        started=state["started"],
        attractor=attractor,
        on_attractor=on_attractor,
    )


@jax.custom_jvp
def _nan_tangent_where(x, flag):
    """``x``, whose tangent is NaN where ``flag`` (a float, 1 or 0) is 1 and passes unchanged
    elsewhere: a derivative that does not exist is reported as NaN, not as zero or a part."""
    del flag
    return x


@_nan_tangent_where.defjvp
def _nan_tangent_where_jvp(primals, tangents):
    x, flag = primals
    tx, _ = tangents
    scale = jnp.where(flag > 0.5, jnp.nan, 1.0).astype(tx.dtype)
    return x, scale * tx


def _without_derivative_where(result: SimulationResult, flag) -> SimulationResult:
    """``result`` with every floating-point field's derivative NaN where ``flag`` holds.

    Used at status 6: the attractor's means are not smooth functions of the design (the operand
    of the attractor branch is cut from the trace), so without this a ``jax.jvp``/``jax.jacfwd``
    of Ψ there would silently be the part that does not pass through the dynamics (Ψ's T1 ω1, the
    mesh geometry), neither zero nor the derivative. Values are unchanged."""
    f = jnp.asarray(flag, dtype=result.power_loss.dtype)

    def mark(leaf):
        if eqx.is_inexact_array(leaf):
            return _nan_tangent_where(leaf, f)
        return leaf

    return jax.tree_util.tree_map(mark, result)


def _record_contacts(pair, lubricant, surfaces, op, fidelity, mesh, st):
    """``each(w, u, m=mesh)``: the rung's contacts at loads the fixed point did not solve (an
    attractor's recorded cycles, the back flanks), given the fixed point's state ``st`` (its
    ``load``, ``velocity`` and ``forces`` on the orbit): the closed-form rungs exactly, the EHL
    rungs by the closed-form mixed EHL contact scaled to the rung's level on the orbit."""

    if fidelity.uses_ehl:
        # The closed-form mixed EHL contact (the "ehl_formula" rung) at each recorded load and
        # velocity, scaled to this rung's level by the ratio of the two models' cycle totals
        # on the orbit, per output (EHL solves at every recorded position would cost 64 × the
        # fixed point's contacts; a forward-mode pass through them for power laws in the load,
        # as the frozen coupling does, cost +80 s of compilation at the paper fidelity).
        # Evaluated exactly, the closed form follows a rattle's loads from zero to impact
        # (power laws from the orbit are extrapolated there, and carry no load to a slot the
        # orbit leaves unloaded); it tracks the EHL solver's forces within 16 % at one contact
        # (tests/test_ehl_formula.py) and Φ̄ within 6.1 % over the baseline sweep.
        proxy_fid = fidelity.replace(friction="ehl_formula")
        if fidelity.friction == "ehl_smooth":  # no asperity load on the smooth rung
            surfaces = eqx.tree_at(lambda s: s.scale, surfaces, jnp.zeros_like(surfaces.scale))

        def proxy(w, u, m=mesh):
            return _cycle_contacts(pair, lubricant, surfaces, op, proxy_fid, m, w, u)[0]

        on_orbit = proxy(st["load"], st["velocity"])
        fields = (
            "friction_sliding",
            "friction_rolling",
            "damping",
            "power_sliding",
            "power_rolling",
        )

        def ratio(name):
            ehl = jnp.sum(jnp.abs(getattr(st["forces"], name)))
            closed = jnp.sum(jnp.abs(getattr(on_orbit, name)))
            return jnp.where(closed > 0, ehl / jnp.where(closed > 0, closed, 1.0), 0.0)

        ratios = {name: ratio(name) for name in fields}

        def each(w, u, m=mesh):
            c = proxy(w, u, m)
            scaled = {name: getattr(c, name) * ratios[name] for name in fields}
            fs, fr = scaled["friction_sliding"], scaled["friction_rolling"]
            loaded = w > 0
            mu = jnp.where(loaded, _safe_sqrt(fs * fs + fr * fr) / jnp.where(loaded, w, 1.0), 0.0)
            return eqx.tree_at(
                lambda f: (*(getattr(f, n) for n in fields), f.friction_coefficient),
                c,
                (*scaled.values(), mu),
            )

    else:

        def each(w, u, m=mesh):
            return _cycle_contacts(pair, lubricant, surfaces, op, fidelity, m, w, u)[0]

    return each


def _orbit_back(pair, lubricant, surfaces, op, fidelity, mesh, st):
    """(back_contact_share, (sliding, rolling) back-flank power per position [M]) of the fixed
    point's periodic orbit ``st``: its back-flank contacts, where the back flanks' force
    (``DynamicResponse.back_force``) is negative, solved as an attractor's (``_record_contacts``,
    ``_back_flank_power``); zeros where it has none (no periodic orbit of the calibrated pair's
    baseline has any; a light load or a small backlash gives them). A vmap-lazy cond: a sweep
    none of whose points strikes back skips it (run for every member, it cost the 149-speed
    parallel sweep at ``Fidelity.fast()`` 12 %: 40.5 against 36.0 s compiled)."""
    from ._lazy_cond import cond_any_member

    force = st["back_force"][None]  # [1, M]

    def strikes(operand):
        pair, lubricant, surfaces, op, mesh, st, force = operand
        each = _record_contacts(pair, lubricant, surfaces, op, fidelity, mesh, st)
        return _back_flank_power(pair, op, fidelity, mesh, force, each)

    def none(operand):
        force = operand[-1]
        zero = jnp.zeros(force.shape[-1], dtype=force.dtype)
        return zero, zero

    operand = (pair, lubricant, surfaces, op, mesh, st, force)
    power = cond_any_member(jnp.any(force < 0.0), strikes, none, operand, all_true_path=False)
    return jnp.mean((force < 0.0).astype(force.dtype)), power


def _attractor_means(pair, lubricant, surfaces, op, fidelity, mesh, state, status, warm):
    """Where the fixed point ends without a stable periodic orbit (status 2, or 1 when the
    shooting's last orbit was unstable: the fixed point cannot settle on an orbit that does not
    exist): the means over ``fidelity.attractor_periods`` mesh cycles of the attractor the gears
    settle on instead.

    The dynamics run in time with the last interface tables (the cycle's friction and damping; a
    table per mesh phase, so the friction does not follow each cycle's load within the
    integration), from the unstable orbit slightly perturbed, through ``settle_periods`` cycles;
    then the contacts are evaluated at every recorded position of ATTRACTOR_CONTACT_CYCLES cycles
    spread over the record: exactly on the closed-form rungs; on the EHL rungs by the closed-form
    mixed EHL contact scaled to the rung's level on the orbit (below), not by new EHL solves.
    Returned, as one tuple, per position: the means over those cycles of the contact outputs (so
    Φ̄ is the record's mean loss), tooth forces and velocities, and the DTE's mean over the whole
    record (its mesh harmonics are the record's); with them the mesh damper's mean power over the
    record. Then status 6 (STATUS_ATTRACTOR), or the status kept
    where the record is not finite. Last, the share of the whole record's positions in back-flank
    contact (``SimulationResult.back_contact_share``; the orbit's where the record is not finite)
    and the back flanks' power per position over the same cycles (``_back_flank_power``: sliding,
    rolling; zeros where the record is not finite). No derivative passes through the attractor
    (its means are not smooth functions of the design): ``_tribo_dynamic`` makes every derivative
    of a status-6 result NaN (``_without_derivative_where``).

    ``warm``: (state [13], flag) of the previous point's attractor in a continuation sweep; where
    the flag is 1 the record starts from it, with ATTRACTOR_WARM_SETTLE cycles and no kick (the
    paper's stepwise speed increase: the gears carry their motion from speed to speed). Returns,
    besides the means, the (state, flag) to hand to the next point.

    A vmap-lazy cond: a point with a stable orbit pays nothing, in a vmapped sweep too; where a
    batch mixes stable and unstable points, the unstable ones run the branch one by one
    (``cond_any_member(..., mixed="map")``)."""
    from ._lazy_cond import cond_any_member
    from .dynamics.model import build_dynamics

    keys = ("forces", "load", "velocity", "dte", "damper", "back_force", "interface", "guess")
    operand = (pair, lubricant, surfaces, op, mesh, {k: state[k] for k in keys}, status, warm)

    def on_attractor(operand):
        pair, lubricant, surfaces, op, mesh, st, status, warm = jax.lax.stop_gradient(operand)
        # built here, not closed over: its array fields are created in the trace they are used
        # in (closed over from the simulate trace they leaked when the JVP rule of the lazy cond
        # re-traced this branch: jax.jacfwd of simulate failed with "No constant handler")
        options = _dynamics_options(fidelity)
        load, velocity = st["load"], st["velocity"]
        dyn = build_dynamics(pair, op, mesh, st["interface"], options)
        continued = warm[1] > 0.5
        rec = record_attractor(
            dyn,
            mesh,
            jnp.where(continued, warm[0], st["guess"]),
            options,
            jnp.where(
                continued,
                min(ATTRACTOR_WARM_SETTLE, fidelity.settle_periods),
                fidelity.settle_periods,
            ),
            fidelity.attractor_periods,
            jnp.where(continued, 0.0, DEFAULT_KICK),
        )

        each = _record_contacts(pair, lubricant, surfaces, op, fidelity, mesh, st)

        # ATTRACTOR_CONTACT_CYCLES cycles spread over the whole record (the window's length, not
        # the sample count, sets the bias of the mean), one from every block of `stride`, at a
        # position in the block that cycles through 0..stride−1 so that a period-2, -3 or -4
        # attractor is not sampled at one of its phases only
        stride = max(1, fidelity.attractor_periods // ATTRACTOR_CONTACT_CYCLES)
        k = jnp.arange(fidelity.attractor_periods // stride)
        pick = k * stride + k % stride
        loads, speeds = rec.tooth_force[pick], rec.surface_velocity[pick]
        per_cycle = jax.vmap(each)(loads, speeds)
        mean = eqx.tree_at(
            lambda f: (f.converged, f.failed),
            jax.tree_util.tree_map(lambda a: jnp.mean(a, axis=0), per_cycle),
            (jnp.all(per_cycle.converged), jnp.max(per_cycle.failed)),
        )
        new = (
            mean,
            jnp.mean(loads, 0),
            jnp.mean(speeds, 0),
            jnp.mean(rec.dynamic_te, 0),
            rec.mesh_damping_power,
        )
        ok = rec.finite & jnp.all(
            jnp.stack([jnp.all(jnp.isfinite(a)) for a in jax.tree_util.tree_leaves(new)])
        )
        old = (st["forces"], load, velocity, st["dte"], st["damper"])
        picked = jax.tree_util.tree_map(lambda a, b: jnp.where(ok, a, b), new, old)
        end = jnp.concatenate([rec.final_state, rec.load_torque_correction[None]])
        handover = (jnp.where(ok, end, 0.0), jnp.where(ok, 1.0, 0.0).astype(end.dtype))
        status = jnp.where(ok, STATUS_ATTRACTOR, status).astype(status.dtype)
        orbit_share = jnp.mean((st["back_force"] < 0.0).astype(load.dtype))
        back = jnp.where(ok, jnp.mean((rec.back_force < 0.0).astype(load.dtype)), orbit_share)
        back_power = _back_flank_power(pair, op, fidelity, mesh, rec.back_force[pick], each)
        back_power = jax.tree_util.tree_map(
            lambda a: jnp.where(ok & jnp.all(jnp.isfinite(a)), a, 0.0), back_power
        )
        return (picked, status, handover, back, back_power)

    def keep(operand):
        pair, lubricant, surfaces, op, mesh, st, status, warm = operand
        off = (jnp.zeros_like(warm[0]), jnp.zeros_like(warm[1]))
        back = _orbit_back(pair, lubricant, surfaces, op, fidelity, mesh, st)
        kept = (st["forces"], st["load"], st["velocity"], st["dte"], st["damper"])
        return kept, status, off, *back

    unstable = (state["dynamics_ok"] < 0.5) & jnp.all(jnp.isfinite(state["guess"]))
    # The branch is costly to compile (the dynamics in time): traced once, without the all-members
    # path. In a vmapped sweep whose batch mixes stable and unstable points, the unstable ones run
    # it one by one (mixed="map"): the batched select ran the 2000-cycle integration for every
    # point, 615 s for the 149-speed baseline sweep at fast() with 27 points on an attractor.
    return cond_any_member(unstable, on_attractor, keep, operand, all_true_path=False, mixed="map")


class WarmStart(eqx.Module):
    """A converged tribo-dynamic state to start a neighbouring point from (continuation sweeps).

    ``started`` is 1 when ``orbit`` is a periodic orbit to shoot from, 0 for a cold start
    (``cold_start``): then the orbit is ignored and the tables are zero. ``attractor``: the state
    [12] and load-torque correction at the end of the point's attractor record, valid when
    ``on_attractor`` is 1: the next speed, if it has no stable orbit either, continues from it
    (the paper's stepwise speed increase), with ATTRACTOR_WARM_SETTLE settling cycles and no kick."""

    interface: MeshInterface
    orbit: Float[Array, " 13"]
    started: Float[Array, ""]
    attractor: Float[Array, " 13"]
    on_attractor: Float[Array, ""]


def cold_start(n_positions: int, dtype=jnp.float64) -> WarmStart:
    """The WarmStart equivalent to no warm start: a continuation sweep's first point runs through the
    same compiled step as the others (one compilation instead of two)."""
    zeros = jnp.zeros((n_positions, 2), dtype=dtype)
    none, no = jnp.zeros(13, dtype=dtype), jnp.zeros((), dtype=dtype)
    return WarmStart(MeshInterface(zeros, zeros, zeros), none, no, none, no)


def simulate_with_state(pair, lubricant, surfaces, op, fidelity, warm: WarmStart | None = None):
    """``simulate`` that also returns the WarmStart of its converged state (traceable: no checks).

    The quasi-static rung has no state: its WarmStart is zeros, and ``warm`` is ignored.
    """
    mesh = mesh_cycle(pair, op.torque, fidelity.n_positions, stiffness=fidelity.stiffness)
    if fidelity.dynamics == "quasi_static":
        none = cold_start(fidelity.n_positions, op.torque.dtype)
        return _quasi_static(pair, lubricant, surfaces, op, fidelity, mesh), none
    return _tribo_dynamic(pair, lubricant, surfaces, op, fidelity, mesh, warm)


@eqx.filter_jit
def _simulate(pair, lubricant, surfaces, op, fidelity):
    return simulate_with_state(pair, lubricant, surfaces, op, fidelity)[0]


def simulate(
    pair: GearPair,
    lubricant,
    surfaces,
    op: OperatingPoint,
    fidelity: Fidelity | None = None,
) -> SimulationResult:
    """Power loss, efficiency and dynamic response of ``pair`` at ``op``.

    Args:
        pair: GearPair.
        lubricant: Lubricant (inlet viscosity, rheology).
        surfaces: Surfaces (roughness; ``jg.presets.smooth()`` for none).
        op: OperatingPoint (torque N m, speed rpm, inlet temperature K).
        fidelity: Fidelity (default ``Fidelity.fast()``).

    Returns:
        SimulationResult; ``converged``/``status`` report failures, never silent NaN. Differentiable in
        every traced input (forward mode, ``jax.jvp``/``jax.jacfwd``), except where the result
        is a mean over an attractor (status 6, no stable periodic orbit): there every derivative
        is NaN, since the mean over a rattle or a quasi-periodic motion is not a smooth function
        of the design; the value and its status are still reported.
    """
    fidelity = Fidelity.fast() if fidelity is None else fidelity
    check_inputs(pair, lubricant, surfaces, op, fidelity)
    if is_concrete(surfaces):
        check_non_negative("surfaces.composite_rq", surfaces.composite_rq, "m")
    gear_geometry(pair)  # shapes and geometry checks happen at construction; nothing to redo
    return _simulate(pair, lubricant, surfaces, op, fidelity)


def check_inputs(pair, lubricant, surfaces, op, fidelity) -> None:
    """Types of ``simulate``'s (and ``sweep``'s) arguments: a wrong one would fail deep inside the
    trace with an AttributeError naming no argument."""
    check_instance("fidelity", fidelity, Fidelity)
    check_instance("op", op, OperatingPoint)
    check_instance("pair", pair, GearPair)
    check_instance("lubricant", lubricant, Lubricant)
    check_instance(
        "surfaces", surfaces, Surfaces, "a jaxgear.Surfaces (jg.presets.smooth() for none)"
    )
    for name in ("torque", "speed_rpm", "inlet_temperature"):
        shape = jnp.shape(getattr(op, name))
        if shape != ():
            raise ValueError(
                f"op.{name} has shape {shape}; valid: a scalar (use jg.sweep for many points)"
            )
