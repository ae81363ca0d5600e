"""The EHL rungs of the coupled model: every tooth-pair contact of a mesh cycle solved by EHL.

Per [position, pair slot] the contact is a line contact with the dynamic (or quasi-static) tooth
force W_T per face width, the surface velocities and the involute curvature; ``solve_ehl`` is mapped
over all of them (one after the other: see ``ehl_contact_forces``). Slots that carry no load (out of
contact, or unloaded by tip relief) are solved at a benign stand-in load and their outputs are
masked to zero. Per-unit-width EHL outputs are multiplied by the face width: friction forces Fs, Fr
(N), damping cm (N s/m, paper Eq. 13), power losses (W).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from ..lubrication.ehl import EHLModel, LineContact, solve_ehl
from ..lubrication.passage import solve_ehl_passage
from ..material import reduced_modulus
from .base import LOADED_SHARE, ContactForces
from .coefficients import fill_nearest, patch_failed, safe_norm


def _sequential(fn):
    """Like ``jax.vmap(fn)`` over the leading axis, but one element after the other."""
    return lambda *args: jax.lax.map(lambda a: fn(*a), args)


def ehl_model_of(fidelity) -> EHLModel:
    """The EHL solver configuration a Fidelity asks for."""
    return EHLModel(
        n_nodes=fidelity.n_nodes,
        thermal=fidelity.thermal,
        mixed=fidelity.mixed_model,
        boundary_friction=fidelity.boundary_friction,
        shear=fidelity.shear,
        asperity_density_product=fidelity.asperity_density_product,
        asperity_slope_ratio=fidelity.asperity_slope_ratio,
        limiting_shear_coefficient=(
            fidelity.limiting_shear_coefficient if fidelity.contact.limiting_shear else None
        ),
    )


def ehl_contact_forces(
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
    """Solve all contacts of a mesh cycle by EHL and return ``ContactForces`` [M, 2] (and the raw
    solutions, for warm starts and fields).

    Args:
        load: tooth force W_T per [position, slot], N. u1, u2: surface velocities, m/s.
        initial: EHLSolution batch [M, 2, ...] to warm-start from (e.g. the previous fixed-point
            iteration), or None for cold solves. Unused by the transient rung (its passage
            warm-starts each position from the one before).
        period: the mesh period, s; needed by ``fidelity.transient`` (the time between positions
            is period / M).
    """
    model = ehl_model_of(fidelity)
    rough = surfaces if fidelity.friction == "ehl_mixed" else None
    width = pair.face_width
    total = mesh.total_load
    loaded = load > LOADED_SHARE * total
    stand_in = 0.5 * total
    w = jnp.where(loaded, load, stand_in) / width
    um = 0.5 * (u1 + u2)
    ok_u = um > 0
    u1s = jnp.where(ok_u, u1, 1.0)
    u2s = jnp.where(ok_u, u2, 1.0)
    e_red = reduced_modulus(*pair.materials)
    shape = load.shape

    def one(r, wpw, a, b, init):
        contact = LineContact(
            reduced_radius=r,
            load_per_width=wpw,
            u1=a,
            u2=b,
            e_reduced=e_red,
            inlet_temperature=inlet_temperature,
        )
        return solve_ehl(
            contact, lubricant, model, rough, initial=init, solids=tuple(pair.materials)
        )

    flat = lambda x: jnp.reshape(x, (-1,))
    # The contacts are solved one after the other (lax.map), not vmapped: each solve has cold-start
    # fallbacks (and thermal/asperity outer steps) behind lax.cond, and under vmap a cond becomes a
    # select that executes every branch for every contact: one after the other is 18×
    # (quasi-static) to 135× (tribo-dynamic) faster on a CPU (smooth EHL, 129 nodes, 64
    # contacts), with identical results.
    batch = _sequential
    if fidelity.transient:
        sols = _engagement_passage(
            mesh.reduced_radius,
            w,
            u1s,
            u2s,
            loaded & ok_u,
            period,
            e_red,
            inlet_temperature,
            lubricant,
            model,
            rough,
            tuple(pair.materials),
        )
    else:
        if initial is None:
            sols = batch(lambda r, wpw, a, b: one(r, wpw, a, b, None))(
                flat(mesh.reduced_radius), flat(w), flat(u1s), flat(u2s)
            )
        else:
            init_flat = jax.tree_util.tree_map(
                lambda x: jnp.reshape(x, (-1, *x.shape[2:])), initial
            )
            sols = batch(one)(flat(mesh.reduced_radius), flat(w), flat(u1s), flat(u2s), init_flat)
        sols = jax.tree_util.tree_map(lambda x: jnp.reshape(x, (*shape, *x.shape[1:])), sols)
    in_use = loaded & ok_u
    mask = in_use.astype(load.dtype)
    outputs = (
        sols.friction_sliding,
        sols.friction_rolling,
        sols.damping,
        sols.power_loss_sliding,
        sols.power_loss_rolling,
    )
    finite = jnp.all(jnp.stack([jnp.isfinite(a) for a in outputs]), axis=0)
    good = in_use & sols.converged & finite
    failed = in_use & ~good
    fs, fr, cm, ps, pr = patch_failed(outputs, good, failed, w, u1s, u2s)
    take = lambda a: a * width * mask
    fs, fr = take(fs), take(fr)
    forces = ContactForces(
        friction_sliding=fs,
        friction_rolling=fr,
        damping=take(cm),
        power_sliding=take(ps),
        # (the sliding loss includes the asperity (boundary) friction of mixed lubrication)
        power_rolling=take(pr),
        friction_coefficient=safe_norm(fs, fr) / jnp.where(loaded, load, 1.0) * mask,
        converged=~jnp.any(failed),
        failed=jnp.sum(failed.astype(jnp.int32)),
    )
    return forces, sols


def _engagement_passage(
    radius, w, u1, u2, valid, period, e_red, inlet_temperature, lubricant, model, rough, solids
):
    """The transient rung: one tooth pair marched through its whole engagement.

    In the periodic steady state every tooth pair has the same history, and one pair's engagement is
    slot 0 over a mesh period followed by slot 1 over the next (MeshCycle). The 2M states are marched
    in that order by ``solve_ehl_passage`` (squeeze term ∂(ρh)/∂t by the model's
    ``time_scheme``, backward Euler by default, with Δt = period / M, surface temperatures with memory when thermal), and the solutions are put back
    on the [M, 2] table. States out of contact are masked out by the caller; here they carry the
    nearest loaded state before them (the first loaded one before entry), so the march never jumps
    through a stand-in load and back, which would be a spurious squeeze.
    """
    if period is None:
        raise ValueError("period (the mesh period, s) is needed by Fidelity.transient = True")
    if rough is not None and model.mixed == "deterministic":
        raise ValueError(
            "Fidelity.transient = True with mixed_model = 'deterministic' is not valid; valid: "
            "mixed_model = 'statistical'. Between two mesh positions the roughness moves by "
            "u·period/M, about a third of the Hertz width, far more than the grid cell the moving "
            "profiles need (EHL_NOTES: Δt ≤ Δx/u); march one contact with solve_ehl_passage and "
            "grid_time_step instead"
        )
    m = w.shape[0]
    # [M, 2] → one engagement of 2M states: slot 0's positions, then slot 1's.
    seq = lambda a: jnp.reshape(jnp.swapaxes(a, 0, 1), (-1,))
    ok = seq(valid)
    fill = lambda a: fill_nearest(seq(a), ok, causal=True)
    contacts = LineContact(
        reduced_radius=fill(radius),
        load_per_width=fill(w),
        u1=fill(u1),
        u2=fill(u2),
        e_reduced=jnp.broadcast_to(e_red, (2 * m,)),
        inlet_temperature=jnp.broadcast_to(inlet_temperature, (2 * m,)),
    )
    times = jnp.arange(2 * m) * (period / m)
    sols = solve_ehl_passage(contacts, lubricant, model, rough, times=times, solids=solids)
    # back to [M, 2, ...]
    return jax.tree_util.tree_map(
        lambda x: jnp.swapaxes(jnp.reshape(x, (2, m, *x.shape[1:])), 0, 1), sols
    )
