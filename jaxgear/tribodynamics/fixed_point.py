"""The first pass of the coupled model: the quasi-static rung, and the tribo-dynamic fixed point.

REFERENCE §1 (paper): the dynamics, given the mesh interface tables (EHL damping cm and friction
forces F1, F2 per position and tooth pair), give the dynamic tooth forces W_T and surface
velocities uj; the contacts, given W_T and uj, give new tables; the two are iterated to a fixed
point. The fixed point is solved with optimistix (Anderson-accelerated, or damped iteration) and
differentiated implicitly (``optx.ImplicitAdjoint`` with a matrix-free GMRES solve of (I − ∂T/∂x)
that stops at the Krylov step where it has converged, ``_solvers.krylov.EarlyExitGMRES``), so gradients
never pass through the iterations, in forward or reverse mode. The dynamic periodic orbit is
carried in the fixed-point state, so each iteration's shooting starts from the previous orbit.

The quasi-static variant uses W_T = W_sT and the kinematic surface velocities and needs no
iteration.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx
from jaxtyping import Array, Float, Int

from .._solvers.anderson import Anderson
from .._solvers.implicit import NaNImplicitAdjoint
from .._solvers.krylov import EarlyExitGMRES
from ..contact.base import ContactForces, interface_from_forces, kinematic_velocities
from ..contact.cycle import contact_forces
from ..contact.frozen import frozen_contact_forces
from ..dynamics.model import DynamicsOptions, MeshInterface
from ..dynamics.response import steady_state
from ..gear.geometry import mesh_period
from ..gear.mesh import MeshCycle
from .result import (
    STATUS_CONTACT,
    STATUS_DYNAMICS,
    STATUS_FIXED_POINT,
    STATUS_OK,
    assemble,
)


def dynamics_options(fidelity) -> DynamicsOptions:
    return DynamicsOptions(
        steps_per_period=fidelity.steps_per_period,
        n_positions=fidelity.n_positions,
        backlash=fidelity.backlash,
        back_flank=fidelity.back_flank,
    )


class WarmStart(eqx.Module):
    """A converged tribo-dynamic state to start a neighbouring point from (continuation sweeps).

    ``started`` is 1 when ``orbit`` is a periodic orbit to shoot from, 0 for a cold start
    (``cold_start``): then the orbit is ignored and the tables are zero."""

    interface: MeshInterface
    orbit: Float[Array, " 13"]
    started: Float[Array, ""]


def cold_start(n_positions: int, dtype=jnp.float64) -> WarmStart:
    """The WarmStart equivalent to no warm start: a continuation sweep's first point runs through the
    same compiled step as the others (one compilation instead of two)."""
    zeros = jnp.zeros((n_positions, 2), dtype=dtype)
    return WarmStart(
        MeshInterface(zeros, zeros, zeros), jnp.zeros(13, dtype=dtype), jnp.zeros((), dtype=dtype)
    )


class Pending(eqx.Module):
    """The first pass's state of one point: what ``result.assemble`` needs, and what the second
    pass (``second_pass.finish``) starts from.

    Attributes:
        mesh: the point's MeshCycle.
        status: the first pass's status (``result.STATUS_*``; 0 on the quasi-static rung's success).
        residual, iterations: the fixed point's residual and iteration count.
        forces: ContactForces of the last evaluation; load, velocity, dte, damper: tooth forces,
            surface velocities, DTE and mesh damper power on the orbit; back_force: the back
            flanks' force along the orbit; interface, guess: the last interface tables and orbit
            (shooting unknowns); dynamics_ok: 1 where the last orbit converged and is stable.
    """

    STATE_KEYS = (
        "forces", "load", "velocity", "dte", "damper", "back_force", "interface", "guess",
        "dynamics_ok",
    )

    mesh: MeshCycle
    status: Int[Array, ""]
    residual: Float[Array, ""]
    iterations: Int[Array, ""]
    forces: ContactForces
    load: Float[Array, "M 2"]
    velocity: Float[Array, "M 2 2"]
    dte: Float[Array, " M"]
    damper: Float[Array, ""]
    back_force: Float[Array, " M"]
    interface: MeshInterface
    guess: Float[Array, " 13"]
    dynamics_ok: Float[Array, ""]

    @property
    def unstable(self):
        """No stable periodic orbit (the orbit the shooting ended on is finite but unstable or
        not converged): the attractor's case."""
        return (self.dynamics_ok < 0.5) & jnp.all(jnp.isfinite(self.guess))

    @property
    def strikes_back(self):
        """The orbit's back flanks carry load somewhere in the cycle."""
        return jnp.any(self.back_force < 0.0)


def cycle_contacts(pair, lubricant, surfaces, op, fidelity, mesh, load, velocity, initial=None):
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


def quasi_static(pair, lubricant, surfaces, op, fidelity, mesh):
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
    return assemble(pair, op, mesh, forces, load, velocity, mesh.static_te, status, 0.0, 0)


def tribo_dynamic_fixed_point(pair, lubricant, surfaces, op, fidelity, mesh, warm):
    """The tribo-dynamic fixed point of the interface tables and the periodic orbit (the first
    pass): returns (Pending, WarmStart). What needs the second pass (the attractor where no stable
    orbit exists, the back flanks' loss where the orbit strikes them) is left to
    ``second_pass.finish``."""
    options = dynamics_options(fidelity)
    m = mesh.n_positions

    def contacts_at(load, velocity, initial=None):
        """The contacts of the cycle at tooth forces ``load`` and surface velocities ``velocity``."""
        return cycle_contacts(
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
        # kept finite at their source, contact.ehl.ehl_contact_forces. This is the second guard.)
        finite = (
            jnp.all(jnp.isfinite(resp.initial_state))
            & jnp.all(jnp.isfinite(resp.tooth_force))
            & jnp.all(jnp.isfinite(resp.surface_velocity))
            & jnp.all(jnp.isfinite(resp.dynamic_te))
        )
        load = jnp.where(finite, resp.tooth_force, state["load"])
        u = jnp.where(finite, resp.surface_velocity, state["velocity"])
        if fidelity.coupling == "frozen":
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
        # (implicit derivatives: no extra Newton iterations). At a resonance (dynamic loads
        # 0.1-2.2 × static) it halves the error of constant coefficients against the full fixed
        # point (Φ̄ 6 % against 12 % off), for 26-85 % more than the contact solves alone (the
        # forward-mode pass through the marches).
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
    # instead of 3.0×.
    # A failed implicit solve (a singular I − ∂T/∂x, a non-finite right-hand side) gives NaN
    # derivatives, never an exception from inside the transformation.
    adjoint = NaNImplicitAdjoint(
        linear_solver=EarlyExitGMRES(rtol=1e-10, atol=0.0, nan_on_failure=True)
    )
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
    pending = Pending(
        mesh=mesh,
        status=jnp.asarray(status, jnp.int32),
        residual=residual,
        iterations=jnp.asarray(sol.stats["num_steps"], jnp.int32),
        **{k: state[k] for k in Pending.STATE_KEYS},
    )
    warm_out = WarmStart(
        interface=state["interface"], orbit=state["guess"], started=state["started"]
    )
    return pending, warm_out


