"""Statistical asperity contact (Greenwood-Williamson / Greenwood-Tripp) for mixed EHL.

For two rough surfaces of composite roughness σ with Gaussian summit heights, the nominal pressure
carried by asperity contact at a mean separation h is (Greenwood & Tripp 1970, in the form of
Johnson, Greenwood & Poon 1972):

    p_a(h) = K′ E′ F_{5/2}(h/σ),   K′ = (8√2/15) π (nβσ)² √(σ/β),

and the real-contact area ratio A_r/A = π² (nβσ)² F_2(h/σ), with n the summit density, β the summit
radius and F_n(λ) = (2π)^(−½) ∫_λ^∞ (s − λ)^n e^(−s²/2) ds. F_n is evaluated by Gauss-Legendre
quadrature (no curve fit), so it is smooth and differentiable in λ for any sign of λ.

Both are evaluated at the separation d of the surfaces' mean planes, which goes negative where the
asperities carry most of the load. The film that carries the flow is the average gap (the expected
gap between a flat and a Gaussian composite surface of standard deviation σ),

    h_T(d) = σ [λ Φ(λ) + φ(λ)],   λ = d/σ,   dh_T/dd = Φ(λ),

(Φ, φ the standard normal distribution and density; h_T = σ F_1(−λ)), and its Poiseuille flow
carries Patir & Cheng's (1978) pressure flow factor for isotropic roughness (γ = 1),
φx = 1 − 0.90 exp(−0.56 λ). Patir and Cheng fitted it for λ ≥ 0.5; below, λ is replaced by a
smooth positive floor of width 0.1 (``smooth_positive``), so φx falls smoothly to 0.1 at λ → −∞,
where the average gap has closed anyway.
"""

from __future__ import annotations

import functools
import math

import jax
import jax.numpy as jnp
import numpy as np
from jax.scipy.special import erfc

from .reynolds import smooth_positive

_RULES = {q: np.polynomial.legendre.leggauss(q) for q in (48, 160)}
_FAR = 12.0  # λ above which F_n is taken as 0 (F_{5/2}(12) ≈ 1e-36)


def gt_integral(order: float, lam, points: int = 160):
    """F_n(λ) = (2π)^(−½) ∫_λ^∞ (s − λ)^n exp(−s²/2) ds, any λ (array), n > −1, by
    Gauss-Legendre quadrature of ``points`` (160: to ~1e-11 relative for n = 5/2 on
    λ ∈ [−6, 6]; 48: to ~1e-7, what the EHL solver's residual uses).

    Its derivative is the closed form dF_n/dλ = −n F_{n−1} (n ≥ 1), by the same quadrature: one
    pass of exponentials gives a value and its slope, so a Jacobian's directional derivatives cost
    a product each instead of a differentiated quadrature."""
    if order >= 1.0:
        return _gt_smooth(float(order), points, jnp.asarray(lam))
    return _gt_quadrature((order,), points, jnp.asarray(lam))[0]


def _gt_quadrature(orders, points, lam):
    """(F_n(λ) for n in ``orders``), from one evaluation of the integrand's exponential.

    On [0, span] the quadrature points are t = u·span (u the rule's points mapped to [0, 1]), so
    tⁿ = uⁿ spanⁿ: the powers are constants times one power of the span, not a power per point."""
    nodes, weights = _RULES[points]
    u = 0.5 * (nodes + 1.0)
    # beyond λ = 12, F_n < 1e-33: zero. Why cut: the integrand's exp(−(λ + t)²/2) would pass
    # through the subnormal range (λ + t ≈ 38) at the thick inlet films of an EHL grid, and
    # arithmetic on subnormals is ~100 × slower on x86 (it slowed a 257-node solve 20×)
    far = lam > _FAR
    lam = jnp.where(far, _FAR, lam)
    span = 9.0 + jnp.maximum(-lam, 0.0)  # the Gaussian tail beyond λ + span is < 1e-18
    g = jnp.exp(-0.5 * (lam[..., None] + u * span[..., None]) ** 2)
    out = []
    for n in orders:
        w = jnp.asarray(0.5 * weights * u**n / math.sqrt(2.0 * math.pi))
        out.append(jnp.where(far, 0.0, span ** (n + 1.0) * jnp.sum(w * g, axis=-1)))
    return out


@functools.partial(jax.custom_jvp, nondiff_argnums=(0, 1))
def _gt_smooth(order, points, lam):
    return _gt_quadrature((order,), points, lam)[0]


@_gt_smooth.defjvp
def _gt_smooth_jvp(order, points, primals, tangents):
    (lam,), (dlam,) = primals, tangents
    if order >= 2.0:  # F_{n−1} has its own closed-form derivative (second derivatives)
        value, lower = _gt_quadrature((order,), points, lam)[0], _gt_smooth(order - 1.0, points, lam)
    else:
        value, lower = _gt_quadrature((order, order - 1.0), points, lam)
    return value, -order * lower * dlam


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


def normal_cdf(lam):
    """Φ(λ), the standard normal distribution function (by erfc: accurate in both tails)."""
    return 0.5 * erfc(-lam / math.sqrt(2.0))


def normal_pdf(lam):
    """φ(λ), the standard normal density."""
    return jnp.exp(-0.5 * lam * lam) / math.sqrt(2.0 * math.pi)


def average_gap(d, sigma):
    """h_T(d) = σ [λΦ(λ) + φ(λ)], λ = d/σ: the average gap, m, at the mean-plane separation d
    (m, any sign) of surfaces of composite roughness σ (m, > 0). h_T(0) = σ/√(2π); h_T → d for
    d ≫ σ (relative difference ≈ φ(λ)/λ³); h_T → 0 for d ≪ −σ."""
    lam = d / sigma
    # outside |λ| ≤ 12 the gap is d or 0 to 1e-33 of σ (and Φ, φ there would pass through the
    # subnormal range, slow on x86: see ``gt_integral``)
    inner = jnp.clip(lam, -_FAR, _FAR)
    gap = sigma * (inner * normal_cdf(inner) + normal_pdf(inner))
    return jnp.where(lam > _FAR, d, jnp.where(lam < -_FAR, 0.0, gap))


_INVERSE_ITERATIONS = 40


def separation_of_gap(h, sigma):
    """The mean-plane separation d, m, whose average gap ``average_gap(d, σ)`` is h (m, > 0).

    Newton on ln h_T(λ) (concave in λ: after the first step the iterates rise to the root
    monotonically), then one last step outside the stopped iterations, so that derivatives are
    those of the implicit function (dd/dh = 1/Φ(λ))."""
    g = h / sigma
    log_g = jnp.log(g)

    def f(lam):
        return jnp.log(lam * normal_cdf(lam) + normal_pdf(lam)) - log_g

    def slope(lam):
        return normal_cdf(lam) / (lam * normal_cdf(lam) + normal_pdf(lam))

    # start: the film itself where it is thick; the Gaussian tail's λ where it is thin
    thin = -jnp.sqrt(
        2.0 * jnp.maximum(-jnp.log(jnp.minimum(g, 0.3) * math.sqrt(2.0 * math.pi)), 0.0)
    )
    lam = jax.lax.stop_gradient(jnp.where(g > 0.4, g, thin))

    def step(_, lam):
        return lam - f(lam) / slope(lam)

    lam = jax.lax.stop_gradient(jax.lax.fori_loop(0, _INVERSE_ITERATIONS, step, lam))
    return sigma * (lam - f(lam) / slope(lam))


#: Patir & Cheng (1978) pressure flow factor of isotropic roughness (γ = 1): φx = 1 − C e^(−r λ).
PATIR_CHENG_PRESSURE = (0.90, 0.56)
_FLOW_FACTOR_FLOOR = 0.1  # width of the smooth floor on λ below Patir and Cheng's fitted range


def pressure_flow_factor(d, sigma):
    """φx(λ) = 1 − 0.90 exp(−0.56 λ⁺), λ = d/σ, λ⁺ a smooth positive floor of λ (width 0.1):
    Patir & Cheng's pressure flow factor of isotropic roughness, in (0.1, 1]."""
    c, r = PATIR_CHENG_PRESSURE
    lam = smooth_positive(d / sigma, _FLOW_FACTOR_FLOOR)
    return 1.0 - c * jnp.exp(-r * lam)
