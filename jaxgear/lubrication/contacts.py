"""The EHL rungs of the coupled model: every tooth-pair contact of a mesh cycle solved by EHL.

Per [position, pair slot] the contact is a line contact with the dynamic (or quasi-static) tooth force
W_T per face width, the surface velocities and the involute curvature; ``solve_ehl`` is mapped over
all of them (one after the other: see ``ehl_contact_forces``). Slots that carry no load (out of contact, or unloaded by tip relief) are solved at a
benign stand-in load and their outputs are masked to zero. Per-unit-width EHL outputs are multiplied
by the face width: friction forces Fs, Fr (N), damping cm (N s/m, paper Eq. 13), power losses (W).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from ..material import reduced_modulus
from .ehl import EHLModel, LineContact, solve_ehl

# A slot counts as loaded above this share of the total load (below it the contact is a few-newton
# touch at the edge of relief, where EHL has no meaning and contributes nothing measurable).
LOADED_SHARE = 1e-4


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
    )


def ehl_contact_forces(
    pair, lubricant, surfaces, mesh, fidelity, load, u1, u2, inlet_temperature, initial=None
):
    """Solve all contacts of a mesh cycle by EHL and return ``ContactForces`` [M, 2] (and the raw
    solutions, for warm starts and fields).

    Args:
        load: tooth force W_T per [position, slot], N. u1, u2: surface velocities, m/s.
        initial: EHLSolution batch [M, 2, ...] to warm-start from (e.g. the previous fixed-point
            iteration), or None for cold solves.
    """
    from ..tribodynamics import ContactForces

    if fidelity.transient:
        raise ValueError(
            "Fidelity.transient = True is not valid in the coupled model yet; valid: False. The "
            "transient passage exists per contact (jaxgear.lubrication.passage.solve_ehl_passage) "
            "but is not wired into the tribo-dynamic fixed point"
        )
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
    # select that executes every branch for every contact. Measured on this 2-core CPU (smooth EHL,
    # 129 nodes, 64 contacts, benchmarks/RESULTS.md): quasi-static 10.9 s -> 0.61 s per
    # evaluation, tribo-dynamic 108 s -> 0.8 s, identical results.
    batch = _sequential
    if initial is None:
        sols = batch(lambda r, wpw, a, b: one(r, wpw, a, b, None))(
            flat(mesh.reduced_radius), flat(w), flat(u1s), flat(u2s)
        )
    else:
        init_flat = jax.tree_util.tree_map(lambda x: jnp.reshape(x, (-1, *x.shape[2:])), initial)
        sols = batch(one)(flat(mesh.reduced_radius), flat(w), flat(u1s), flat(u2s), init_flat)
    sols = jax.tree_util.tree_map(lambda x: jnp.reshape(x, (*shape, *x.shape[1:])), sols)
    mask = (loaded & ok_u).astype(load.dtype)
    fs = sols.friction_sliding * width * mask
    fr = sols.friction_rolling * width * mask
    forces = ContactForces(
        friction_sliding=fs,
        friction_rolling=fr,
        damping=sols.damping * width * mask,
        power_sliding=sols.power_loss_sliding * width * mask,
        # (the sliding loss includes the asperity (boundary) friction of mixed lubrication)
        power_rolling=sols.power_loss_rolling * width * mask,
        friction_coefficient=jnp.sqrt(fs**2 + fr**2) / jnp.where(loaded, load, 1.0) * mask,
        converged=jnp.all(jnp.where(mask > 0, sols.converged, True)),
    )
    return forces, sols
