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
from .friction_models import smooth_sign

# A slot counts as loaded above this share of the total load (below it the contact is a few-newton
# touch at the edge of relief, where EHL has no meaning and contributes nothing measurable).
LOADED_SHARE = 1e-4

# Largest load exponent of a frozen coefficient (``frozen_contact_forces``). The EHL damping of
# Eq. 13 peaks near the pitch point, where it grows like W^4-4.6 (measured: mixed EHL, 2500 rpm,
# 24 × 65); friction and loss coefficients have exponents within ±0.5.
_MAX_EXPONENT = 5.0


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
    from ..contact.base import ContactForces

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
    fs, fr, cm, ps, pr = _patch_failed(outputs, good, failed, w, u1s, u2s)
    take = lambda a: a * width * mask
    fs, fr = take(fs), take(fr)
    forces = ContactForces(
        friction_sliding=fs,
        friction_rolling=fr,
        damping=take(cm),
        power_sliding=take(ps),
        # (the sliding loss includes the asperity (boundary) friction of mixed lubrication)
        power_rolling=take(pr),
        friction_coefficient=_safe_norm(fs, fr) / jnp.where(loaded, load, 1.0) * mask,
        converged=~jnp.any(failed),
        failed=jnp.sum(failed.astype(jnp.int32)),
    )
    return forces, sols


def frozen_contact_forces(
    reference, reference_load, reference_velocity, load, velocity, total_load, load_tangent=None
):
    """``Fidelity.coupling = "frozen"``: the contact forces at the dynamic ``load`` [M, 2] and
    ``velocity`` [M, 2, 2] from the ``reference`` ContactForces solved once at ``reference_load``
    and ``reference_velocity`` (the quasi-static state), through ``contact_coefficients``.

    ``load_tangent``: the derivative of the reference outputs along a uniform scaling of the loads,
    W ∂F/∂W (a ContactForces of tangents, from ``jax.jvp``). With it each coefficient follows a power
    law in the load, c (W/W0)^b with b = ∂ln c/∂ln W at the reference (clipped to [−5, 5]), which
    carries the fall of the friction coefficient with load that a constant coefficient misses; without
    it the coefficients are constant.

    Slots unloaded in the reference (before or after the static contact, or unloaded by tip relief)
    take the coefficients of the nearest loaded one along the engagement, so a contact that the
    vibration loads where the static mesh does not still carries friction; slots unloaded now carry
    none. ``converged`` and ``failed`` are the reference's.
    """
    from ..contact.base import ContactForces

    def in_use(w, u):
        return (w > LOADED_SHARE * total_load) & (u[..., 0] + u[..., 1] > 0)

    def outputs(forces):
        return (
            forces.friction_sliding,
            forces.friction_rolling,
            forces.damping,
            forces.power_sliding,
            forces.power_rolling,
        )

    u1r, u2r = reference_velocity[..., 0], reference_velocity[..., 1]
    good = in_use(reference_load, reference_velocity)
    coefficients = contact_coefficients(outputs(reference), good, reference_load, u1r, u2r)
    mask = in_use(load, velocity).astype(load.dtype)
    safe_load = jnp.where(mask > 0, load, 1.0)
    if load_tangent is not None:
        tangents = contact_coefficients(outputs(load_tangent), good, reference_load, u1r, u2r)
        w0 = fill_engagement(reference_load, good)
        ratio = safe_load / jnp.where(w0 > 0, w0, 1.0)
        # scales ∝ W except the damping's (1): ∂ln c/∂ln W = (W ∂F/∂W)/(c · scale) − 1
        own = (1.0, 1.0, 0.0, 1.0, 1.0)
        powered = []
        for c, t, k in zip(coefficients, tangents, own):
            nonzero = jnp.abs(c) > 0
            b = jnp.where(nonzero, t / jnp.where(nonzero, c, 1.0) - k, 0.0)
            powered.append(c * ratio ** jnp.clip(b, -_MAX_EXPONENT, _MAX_EXPONENT))
        coefficients = tuple(powered)
    fs, fr, cm, ps, pr = (
        a * mask
        for a in scale_coefficients(coefficients, safe_load, velocity[..., 0], velocity[..., 1])
    )
    return ContactForces(
        friction_sliding=fs,
        friction_rolling=fr,
        damping=cm,
        power_sliding=ps,
        power_rolling=pr,
        friction_coefficient=_safe_norm(fs, fr) / safe_load * mask,
        converged=reference.converged,
        failed=reference.failed,
    )


def _safe_norm(a, b):
    """sqrt(a² + b²) with a finite derivative where both are zero (the masked slots): a plain sqrt
    gives a NaN tangent there, which poisons the implicit fixed-point solve of the tribo-dynamic
    rung (its linear system takes every leaf of the state, this one included)."""
    sq = a**2 + b**2
    positive = sq > 0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, sq, 1.0)), 0.0)


def _patch_failed(outputs, good, failed, w, u1, u2):
    """Per-unit-width outputs (Fs, Fr, cm, Φs, Φr) with each failed contact replaced by its nearest
    good neighbour along the engagement (MeshCycle order: slot 0's positions, then slot 1's), carried
    over as a coefficient and scaled back by this contact's load and velocities.

    A failed contact solve (not converged, or non-finite) can leave any value: seen, a coarse
    (65-node) transient march at 1500 N m whose one failed state near the pitch point gave a rolling
    loss of 3.6e19 W while its neighbours gave 30-40 W. Its own outputs are therefore never used. The
    coefficients carried over are those of ``contact_coefficients`` (Fs/(W s), Fr/W, cm,
    Φs/(W us s), Φr/(W um), with s the sign of us = u2 − u1 smoothed over 2 % slide-to-roll ratio,
    so the sliding friction changes sign with the sliding velocity across the pitch point). The contact stays
    reported: ``converged`` is False (status 3) and ``failed`` counts it. No good contact at all:
    zeros.
    """
    coefficients = contact_coefficients(outputs, good, w, u1, u2)
    filled = scale_coefficients(coefficients, w, u1, u2)
    return tuple(
        jnp.where(failed, f, jnp.where(good, value, 0.0)) for f, value in zip(filled, outputs)
    )


def coefficient_scales(w, u1, u2):
    """What each contact output (Fs, Fr, cm, Φs, Φr) is carried over in proportion to: W s, W, 1,
    W us s, W um (``w`` a load, per width or not; s = us/(us² + (0.02 um)²)^½ the sign of
    us = u2 − u1 smoothed over 2 % slide-to-roll ratio, as the formula rungs' friction). A constant
    μ gives Fs = μ W s and Φs = Fs us = μ W us s: constant coefficients, whatever the velocities."""
    from ..contact.base import SIGN_SLIDE_TO_ROLL

    us = u2 - u1
    um = 0.5 * (u1 + u2)
    sign = smooth_sign(us, SIGN_SLIDE_TO_ROLL * um)
    return (w * sign, w, jnp.ones_like(w), w * us * sign, w * um)


def contact_coefficients(outputs, good, w, u1, u2):
    """The outputs (Fs, Fr, cm, Φs, Φr) per [position, slot] divided by ``coefficient_scales``,
    where ``good``; elsewhere the nearest good contact's along the engagement (zeros if none is).
    An entry whose scale vanishes (the sliding ones at the pitch point) is not good for that
    output: its coefficient comes from the nearest entry whose scale does not."""
    out = []
    for value, sc in zip(outputs, coefficient_scales(w, u1, u2)):
        size = jnp.max(jnp.where(good, jnp.abs(sc), 0.0))
        usable = good & (jnp.abs(sc) > 1e-9 * size)
        sc_safe = jnp.where(usable, sc, 1.0)
        out.append(fill_engagement(jnp.where(usable, value / sc_safe, 0.0), usable))
    return tuple(out)


def fill_engagement(values, good):
    """``values`` [M, 2] with each entry not ``good`` replaced by the nearest good one along the
    engagement (MeshCycle order: slot 0's positions, then slot 1's); zeros if none is good."""
    m = values.shape[0]
    seq = lambda a: jnp.reshape(jnp.swapaxes(a, 0, 1), (-1,))
    unseq = lambda a: jnp.swapaxes(jnp.reshape(a, (2, m)), 0, 1)
    filled = unseq(_fill_nearest(seq(values), seq(good)))
    return jnp.where(jnp.any(good), filled, 0.0)


def scale_coefficients(coefficients, w, u1, u2):
    """``contact_coefficients`` back to outputs at the load ``w`` and velocities u1, u2."""
    return tuple(c * sc for c, sc in zip(coefficients, coefficient_scales(w, u1, u2)))


def _fill_nearest(values, valid, causal=False):
    """Each invalid entry replaced by the nearest valid one along the leading axis (the one before on
    a tie; ``causal``: the one before whenever there is one, else the first valid one); unchanged
    where valid or where none is valid."""
    k = values.shape[0]
    idx = jnp.arange(k)
    before = jax.lax.cummax(jnp.where(valid, idx, -1))
    after = jax.lax.cummin(jnp.where(valid, idx, k), reverse=True)
    use_before = before >= 0
    if not causal:
        use_before = use_before & ((after >= k) | (idx - before <= after - idx))
    src = jnp.clip(jnp.where(use_before, before, after), 0, k - 1)
    return jnp.where(jnp.any(valid), values[src], values)


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
    from .passage import solve_ehl_passage

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
    fill = lambda a: _fill_nearest(seq(a), ok, causal=True)
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
