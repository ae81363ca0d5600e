"""Quasi-static load sharing and static transmission error by compatibility of deflections.

At one mesh position the pairs in contact n share one approach d along the LOA (the loaded static
transmission error). Pair n, with stiffness k_n and relief separation e_n, touches only where
d > e_n and then carries W_n = k_n (d − e_n). The total load fixes d:

    Σ_n c_n k_n g(d − e_n) = W,

with c_n the (smooth) contact weight and g(u) = w softplus(u/w) a smooth max(u, 0) of width w (default
0.02 µm, far below the micrometre deflections, so shares match the piecewise-linear model to round-off
wherever no pair sits within a few w of first touch). The root is found by a monotone Newton iteration
(F is increasing and convex in d and the start has F ≥ 0) and differentiated implicitly with
``lax.custom_root``: gradients never pass through the iterations.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
from jax import lax

DEFAULT_CONTACT_SMOOTHING = 2e-8  # m
_NEWTON_STEPS = 60


def _g(u, width):
    return width * jax.nn.softplus(u / width)


def _dg(u, width):
    return jax.nn.sigmoid(u / width)


def solve_approach(stiffness, separation, weight, total_load, width=DEFAULT_CONTACT_SMOOTHING):
    """Loaded static TE d (m) at one position: Σ c k g(d − e) = W.

    Args:
        stiffness: pair stiffness k_n, N/m, shape [P].
        separation: relief separation e_n, m, [P].
        weight: contact weight c_n ∈ [0, 1], [P].
        total_load: W, N.
        width: smoothing width w of the first touch, m.
    """
    kc = weight * stiffness

    def residual(d):
        return jnp.sum(kc * _g(d - separation, width)) - total_load

    def newton(f, d0):
        def step(_, d):
            slope = jnp.sum(kc * _dg(d - separation, width))
            return d - f(d) / jnp.maximum(slope, 1e-30)

        return lax.fori_loop(0, _NEWTON_STEPS, step, d0)

    def tangent_solve(g, y):
        return y / g(1.0)

    # Start right of the root: every loaded pair's g(d0 − e) ≥ d0 − e ≥ W/Σkc.
    d0 = total_load / jnp.maximum(jnp.sum(kc), 1e-30) + jnp.max(jnp.where(kc > 0, separation, 0.0))
    return lax.custom_root(residual, d0, newton, tangent_solve)


def share_load(stiffness, separation, weight, total_load, width=DEFAULT_CONTACT_SMOOTHING):
    """Solve one position: returns (d, pair loads W_n [P], tangent mesh stiffness Σ c k g'(d − e)).

    The tangent mesh stiffness is the stiffness of the loaded pairs, the km of the dynamics.
    """
    d = solve_approach(stiffness, separation, weight, total_load, width)
    kc = weight * stiffness
    loads = kc * _g(d - separation, width)
    km = jnp.sum(kc * _dg(d - separation, width))
    return d, loads, km
