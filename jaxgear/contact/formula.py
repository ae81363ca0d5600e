"""The closed-form friction rungs: constant μ, the regression formula, the closed-form mixed EHL.

Each gives ``ContactForces`` for the loaded contacts of a mesh cycle from closed forms, with no
solver state: cheap, iso-thermal and quasi-steady.
"""

from __future__ import annotations

import jax.numpy as jnp

from ..gear.mesh import MeshCycle
from ..gear.pair import GearPair
from ..lubrication.ehl_formula import ehl_formula_contact
from ..lubrication.friction_models import XuFriction, smooth_sign
from ..material import reduced_modulus
from .base import LOADED_SHARE, SIGN_SLIDE_TO_ROLL, ContactForces, safe_sqrt


def formula_contact_forces(
    pair: GearPair,
    lubricant,
    surfaces,
    mesh: MeshCycle,
    fidelity,
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
        ph = safe_sqrt(w * e_red / (2.0 * jnp.pi * radius))
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
    fidelity,
    load,
    u1,
    u2,
    inlet_temperature,
) -> ContactForces:
    """The "ehl_formula" rung: each loaded contact by the closed-form mixed EHL model of
    ``lubrication/ehl_formula.py`` (sliding and rolling loss, damping cm), iso-thermal and
    quasi-steady, with the EHL rungs' shear law, μb and Greenwood-Tripp constants."""
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
        limiting_shear=(
            fidelity.limiting_shear_coefficient if fidelity.contact.limiting_shear else None
        ),
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
        friction_coefficient=jnp.where(on, safe_sqrt(fs * fs + fr * fr) / safe_load, 0.0),
        converged=jnp.asarray(True),
        failed=jnp.asarray(0, dtype=jnp.int32),
    )
