"""The frozen coupling (``Fidelity.coupling = "frozen"``): contacts solved once, at the
quasi-static state, and carried to the dynamic loads and velocities as power-law coefficients."""

from __future__ import annotations

import jax.numpy as jnp

from .base import LOADED_SHARE, ContactForces
from .coefficients import contact_coefficients, fill_engagement, safe_norm, scale_coefficients

# Largest load exponent of a frozen coefficient (``frozen_contact_forces``). The EHL damping of
# Eq. 13 peaks near the pitch point, where it grows like W^4-4.6 (measured: mixed EHL, 2500 rpm,
# 24 × 65); friction and loss coefficients have exponents within ±0.5.
_MAX_EXPONENT = 5.0


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
        friction_coefficient=safe_norm(fs, fr) / safe_load * mask,
        converged=reference.converged,
        failed=reference.failed,
    )
