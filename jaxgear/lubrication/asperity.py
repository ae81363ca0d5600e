"""Statistical asperity contact (Greenwood-Williamson / Greenwood-Tripp) for mixed EHL.

For two rough surfaces of composite roughness σ with Gaussian summit heights, the nominal pressure
carried by asperity contact at a mean separation h is (Greenwood & Tripp 1970, in the form of
Johnson, Greenwood & Poon 1972):

    p_a(h) = K′ E′ F_{5/2}(h/σ),   K′ = (8√2/15) π (nβσ)² √(σ/β),

and the real-contact area ratio A_r/A = π² (nβσ)² F_2(h/σ), with n the summit density, β the summit
radius and F_n(λ) = (2π)^(−½) ∫_λ^∞ (s − λ)^n e^(−s²/2) ds. F_n is evaluated by Gauss-Legendre
quadrature (no curve fit), so it is smooth and differentiable in λ for any sign of λ.
"""

from __future__ import annotations

import math

import jax.numpy as jnp
import numpy as np

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(160)


def gt_integral(order: float, lam):
    """F_n(λ) = (2π)^(−½) ∫_λ^∞ (s − λ)^n exp(−s²/2) ds, any λ (array), n > −1."""
    lam = jnp.asarray(lam)
    span = 9.0 + jnp.maximum(-lam, 0.0)  # the Gaussian tail beyond λ + span is < 1e-18
    t = 0.5 * (_NODES + 1.0) * span[..., None]  # (…, q) quadrature points on [0, span]
    w = 0.5 * _WEIGHTS * span[..., None]
    f = t**order * jnp.exp(-0.5 * (lam[..., None] + t) ** 2)
    return jnp.sum(w * f, axis=-1) / math.sqrt(2.0 * math.pi)


def asperity_constant(density_product, slope_ratio):
    """K′ = (8√2/15) π (nβσ)² √(σ/β)."""
    return 8.0 * math.sqrt(2.0) / 15.0 * math.pi * density_product**2 * jnp.sqrt(slope_ratio)


def asperity_pressure(h, sigma, e_reduced, density_product, slope_ratio):
    """p_a = K′ E′ F_{5/2}(h/σ), Pa (h the mean separation, m; σ composite roughness, m)."""
    k = asperity_constant(density_product, slope_ratio)
    return k * e_reduced * gt_integral(2.5, h / sigma)


def contact_area_ratio(h, sigma, density_product):
    """A_r/A = π² (nβσ)² F_2(h/σ)."""
    return jnp.minimum(math.pi**2 * density_product**2 * gt_integral(2.0, h / sigma), 1.0)
