"""The second pass of the coupled model: what few points need and every program would pay for.

Where the fixed point ends without a stable periodic orbit, the result is the mean over the
attractor the gears settle on, by time integration (``dynamics.attractor``); where the gears strike
the back flanks (on the attractor, or on a periodic orbit), the back flanks' contacts are solved
and their loss counted. Both are costly to compile (a time integration; the back flanks' mesh
cycle and contacts) and rare, so ``simulate`` and ``sweep`` run them as a program of their own
on the points that need them (``finish``), after the fixed point of every point; inside a caller's
own ``jit`` they are traced into the program behind a vmap-lazy branch.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp

from .._solvers.lazy_cond import cond_any_member
from ..contact.base import kinematic_velocities, safe_sqrt
from ..dynamics.attractor import DEFAULT_KICK, record_attractor
from ..dynamics.model import build_dynamics
from ..gear.load_sharing import DEFAULT_CONTACT_SMOOTHING
from ..gear.mesh import DEFAULT_EDGE_WIDTH, _back_mesh
from ..gear.modification import DEFAULT_RELIEF_SMOOTHING
from ..power_loss import total_per_position
from .fixed_point import Pending, cycle_contacts, dynamics_options
from .result import STATUS_ATTRACTOR, assemble, without_derivative_where

# Recorded attractor cycles at which the contacts are evaluated (of Fidelity.attractor_periods):
# the closed-form mixed EHL contacts of a cycle cost ~4 ms on 2 cores (64 contacts), the record's
# dynamics ~0.9 ms a cycle, so 64 of 256 cycles keep the contacts at about the dynamics' cost.
ATTRACTOR_CONTACT_CYCLES = 64
# Settling cycles of an attractor continued from the previous speed's (continuation sweeps): the
# attractor moves little between neighbouring speeds (checked by the attractor tests).
ATTRACTOR_WARM_SETTLE = 200


def back_flank_power(pair, op, fidelity, mesh, mesh_force, contacts):
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


def record_contacts(pair, lubricant, surfaces, op, fidelity, mesh, st):
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
        # and Φ̄ within 13 % over the baseline sweep.
        proxy_fid = fidelity.replace(friction="ehl_formula")
        if fidelity.friction == "ehl_smooth":  # no asperity load on the smooth rung
            surfaces = eqx.tree_at(lambda s: s.scale, surfaces, jnp.zeros_like(surfaces.scale))

        def proxy(w, u, m=mesh):
            return cycle_contacts(pair, lubricant, surfaces, op, proxy_fid, m, w, u)[0]

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
            mu = jnp.where(loaded, safe_sqrt(fs * fs + fr * fr) / jnp.where(loaded, w, 1.0), 0.0)
            return eqx.tree_at(
                lambda f: (*(getattr(f, n) for n in fields), f.friction_coefficient),
                c,
                (*scaled.values(), mu),
            )

    else:

        def each(w, u, m=mesh):
            return cycle_contacts(pair, lubricant, surfaces, op, fidelity, m, w, u)[0]

    return each


def back_flanks(pair, lubricant, surfaces, op, fidelity, mesh, st, force):
    """(sliding, rolling) back-flank power per position [M] of the back flanks' force samples
    ``force`` [C, M] (``back_flank_power``: means over the C cycles), their contacts solved as an
    attractor's (``record_contacts``, from the fixed point's state ``st``); zeros where no sample
    is negative (no periodic orbit of the calibrated pair's baseline strikes the back flanks; a
    light load or a small backlash makes them). A vmap-lazy cond: a sweep none of whose points
    strikes back skips it (run for every member, it costs a parallel sweep at
    ``Fidelity.fast()`` ~12 % more). One call site for the orbit's and the attractor's samples:
    the back flanks' mesh cycle and contacts are traced once."""

    # the fidelity goes in the operand: its constants are arrays of this trace, which a branch
    # must not close over (the lazy cond's JVP rule re-traces its branches)
    def strikes(operand):
        pair, lubricant, surfaces, op, fidelity, mesh, st, force = operand
        each = record_contacts(pair, lubricant, surfaces, op, fidelity, mesh, st)
        return back_flank_power(pair, op, fidelity, mesh, force, each)

    def none(operand):
        force = operand[-1]
        zero = jnp.zeros(force.shape[-1], dtype=force.dtype)
        return zero, zero

    operand = (pair, lubricant, surfaces, op, fidelity, mesh, st, force)
    return cond_any_member(jnp.any(force < 0.0), strikes, none, operand, all_true_path=False)


def orbit_back(pair, lubricant, surfaces, op, fidelity, mesh, st):
    """(back_contact_share, (sliding, rolling) back-flank power per position [M]) of the fixed
    point's periodic orbit ``st``: its back-flank contacts, where the back flanks' force
    (``DynamicResponse.back_force``) is negative (``back_flanks``)."""
    force = st["back_force"][None]  # [1, M]
    power = back_flanks(pair, lubricant, surfaces, op, fidelity, mesh, st, force)
    return jnp.mean((force < 0.0).astype(force.dtype)), power


def attractor_means(pair, lubricant, surfaces, op, fidelity, mesh, state, status, warm):
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
    and the back flanks' power per position over the same cycles (``back_flank_power``: sliding,
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
    keys = ("forces", "load", "velocity", "dte", "damper", "back_force", "interface", "guess")
    st = {k: state[k] for k in keys}
    # ATTRACTOR_CONTACT_CYCLES cycles spread over the whole record (the window's length, not
    # the sample count, sets the bias of the mean), one from every block of `stride`
    stride = max(1, fidelity.attractor_periods // ATTRACTOR_CONTACT_CYCLES)
    n_samples = fidelity.attractor_periods // stride
    operand = (pair, lubricant, surfaces, op, fidelity, mesh, st, status, warm)

    def on_attractor(operand):
        pair, lubricant, surfaces, op, fidelity, mesh, st, status, warm = jax.lax.stop_gradient(
            operand
        )
        # built here, not closed over: its array fields are created in the trace they are used
        # in (closed over from the simulate trace they leaked when the JVP rule of the lazy cond
        # re-traced this branch: jax.jacfwd of simulate failed with "No constant handler")
        options = dynamics_options(fidelity)
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

        each = record_contacts(pair, lubricant, surfaces, op, fidelity, mesh, st)

        # the samples (``n_samples``), each at a position in its block that cycles through
        # 0..stride−1 so that a period-2, -3 or -4 attractor is not sampled at one of its phases
        # only
        k = jnp.arange(n_samples)
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
        # the back flanks' force at the same cycles, evaluated after the branch (``back_flanks``)
        samples = jnp.where(ok & jnp.all(jnp.isfinite(rec.back_force)), rec.back_force[pick], 0.0)
        return (picked, status, handover, back, samples)

    def keep(operand):
        pair, lubricant, surfaces, op, fidelity, mesh, st, status, warm = operand
        off = (jnp.zeros_like(warm[0]), jnp.zeros_like(warm[1]))
        force = st["back_force"]
        share = jnp.mean((force < 0.0).astype(force.dtype))
        # the orbit's one cycle in every sample row: the mean over the rows is the orbit's
        samples = jnp.broadcast_to(force, (n_samples, force.shape[0]))
        kept = (st["forces"], st["load"], st["velocity"], st["dte"], st["damper"])
        return kept, status, off, share, samples

    unstable = (state["dynamics_ok"] < 0.5) & jnp.all(jnp.isfinite(state["guess"]))
    # The branch is costly to compile (the dynamics in time): traced once, without the all-members
    # path. In a vmapped sweep whose batch mixes stable and unstable points, the unstable ones run
    # it one by one (mixed="map"): a batched select would run the 2000-cycle integration for
    # every point of the batch.
    picked, status, handover, share, samples = cond_any_member(
        unstable, on_attractor, keep, operand, all_true_path=False, mixed="map"
    )
    power = back_flanks(pair, lubricant, surfaces, op, fidelity, mesh, st, samples)
    power = jax.tree_util.tree_map(lambda a: jnp.where(jnp.isfinite(a), a, 0.0), power)
    return picked, status, handover, share, power


def finish(pair, lubricant, surfaces, op, fidelity, pending: Pending, warm_attractor=None):
    """The SimulationResult of a tribo-dynamic point from its first pass ``pending``: the means
    over the attractor where no stable orbit exists (``fidelity.attractor_periods`` > 0; status
    6, every derivative NaN), the back flanks' loss where the gears strike them. Traceable.

    ``warm_attractor``: (state [13], flag) of the previous point's attractor record in a
    continuation sweep (flag 1: start from it, with ATTRACTOR_WARM_SETTLE settling cycles and no
    kick). Returns (result, the (state, flag) to hand to the next point)."""
    mesh = pending.mesh
    state = {k: getattr(pending, k) for k in Pending.STATE_KEYS}
    if warm_attractor is None:
        warm_attractor = (jnp.zeros(13, pending.guess.dtype), jnp.zeros((), pending.guess.dtype))
    if fidelity.attractor_periods > 0:
        (forces, load, velocity, dte, damper), status, handover, *back = attractor_means(
            pair, lubricant, surfaces, op, fidelity, mesh, state, pending.status, warm_attractor
        )
    else:
        back = orbit_back(pair, lubricant, surfaces, op, fidelity, mesh, state)
        forces, load, velocity, dte, damper = (
            pending.forces,
            pending.load,
            pending.velocity,
            pending.dte,
            pending.damper,
        )
        status = pending.status
        handover = (jnp.zeros_like(warm_attractor[0]), jnp.zeros_like(warm_attractor[1]))
    result = assemble(
        pair,
        op,
        mesh,
        forces,
        load,
        velocity,
        dte,
        status,
        pending.residual,
        pending.iterations,
        back,
        damper,
    )
    if fidelity.attractor_periods > 0:
        result = without_derivative_where(result, result.status == STATUS_ATTRACTOR)
    return result, handover
