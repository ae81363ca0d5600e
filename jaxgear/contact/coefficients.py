"""Contact outputs as coefficients of their load and velocity scales: how a failed contact borrows
its neighbour's friction, and how the frozen coupling carries contacts to other loads."""

from __future__ import annotations

import jax
import jax.numpy as jnp

from ..lubrication.friction_models import smooth_sign
from .base import SIGN_SLIDE_TO_ROLL, safe_sqrt


def safe_norm(a, b):
    """sqrt(a² + b²) with a finite derivative where both are zero (the masked slots): a plain sqrt
    gives a NaN tangent there, which poisons the implicit fixed-point solve of the tribo-dynamic
    rung (its linear system takes every leaf of the state, this one included)."""
    return safe_sqrt(a**2 + b**2)


def patch_failed(outputs, good, failed, w, u1, u2):
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
    filled = unseq(fill_nearest(seq(values), seq(good)))
    return jnp.where(jnp.any(good), filled, 0.0)


def scale_coefficients(coefficients, w, u1, u2):
    """``contact_coefficients`` back to outputs at the load ``w`` and velocities u1, u2."""
    return tuple(c * sc for c, sc in zip(coefficients, coefficient_scales(w, u1, u2)))


def fill_nearest(values, valid, causal=False):
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
