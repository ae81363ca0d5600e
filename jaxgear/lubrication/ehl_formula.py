"""Mixed-lubrication friction from closed-form EHL results: the "ehl_formula" rung of the ladder.

A line contact of the statistical mixed EHL rung (``EHLModel(mixed="statistical")``) without the
Reynolds solve. Each piece is a published closed form, evaluated with the same lubricant, roughness and
shear law as the EHL rungs, and checked against the EHL solver in ``tests/lubrication/test_ehl_formula.py``:

- **Film**: Pan & Hamrock's (1989) central film h_c (REFERENCE §8) of smooth surfaces, and the
  average gap that carries the flow on rough ones, h_T,c = h_c + σ g(h_c/σ). The thickening
  σ g is the statistical film's (``EHLModel(mixed="statistical")``): Patir and Cheng's flow factor
  cuts the inlet's Poiseuille backflow, so more lubricant is entrained. It is not a published
  closed form but a fit to that solver (``ROUGH_FILM_THICKENING``: g(λ) = 0.20/(1 + (λ/2.06)³),
  from the central average gaps of 7 ground contacts at λ = h_c/σ = 0.11-0.81, all 0.18-0.22 σ
  above h_c, and a polished one at λ = 3.1, 0.046 σ above). The separation of the surfaces' mean
  planes there is d_c = h_T⁻¹(h_T,c) (``asperity.separation_of_gap``; negative where the film is
  thin against the roughness). The mean-plane separation is flat over the Hertz zone |x| ≤ b and opened outside it
  by the gap of the dry Hertz line contact, g(X) = (b²/R) ½ (|X| √(X² − 1) − arcosh |X|), X = x/b.
- **Asperity load** (Johnson, Greenwood & Poon 1972 load sharing): the Greenwood-Tripp pressure
  p_a(d) = K′ E′ F_{5/2}(d/σ) of ``asperity.py`` at that separation, integrated, w_a = ∫ p_a dx; the
  fluid carries the rest, with the Hertz pressure shape p_f = (1 − w_a/w) ph √(1 − X²).
- **Sliding traction**: boundary friction μb w_a plus the fluid shear over the non-contact share
  ∫ (1 − A_r/A) η_s (u2 − u1)/h_c dx of the Hertz zone (A_r/A = π²(nβσ)² F_2(d_c/σ)), η_s the
  shear law's viscosity at p_f (paper η* = η/cosh(τm/τ0): τ = τ0 tanh(τm/τ0); exact Eyring
  τ = τ0 asinh(η us/(τ0 h)); Newtonian), so the traction saturates where the paper's model
  saturates it. Damping cm = ∫ (1 − A_r/A) η_s/h_c dx (paper Eq. 13).
- **Rolling traction**: Goksem & Hargreaves (1978), isothermal,
  F_R = 4.318 (G U)^0.658 W′^0.0126 R/α per unit width, with U = η0 um/(E′R), G = αE′,
  W′ = w/(E′R); its power is F_R (u1 + u2) (the steady film's Poiseuille dissipation).

Iso-thermal and quasi-steady. What it leaves out against the EHL rungs: the film's thermal and
transient response, the outlet constriction, the local coupling of asperity and fluid pressure. Its
error against them and its cost are measured in ``benchmarks/fidelity_trade.py``.

SI units throughout; arguments broadcast (a whole mesh cycle at once).
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from .asperity import asperity_pressure, contact_area_ratio, separation_of_gap
from .friction_models import smooth_sign
from .rheology import log_limited_stress

# Gauss-Legendre nodes on [-1, 1]: the Hertz zone (fluid traction, asperity load on the flat film) and
# the opening gap outside it (asperity load).
_ZONE_X, _ZONE_W = np.polynomial.legendre.leggauss(24)
_GAP_T, _GAP_W = np.polynomial.legendre.leggauss(24)

#: Goksem & Hargreaves (1978) isothermal rolling traction, F_R/(R/α) = C (GU)^a W′^b.
ROLLING_TRACTION = (4.318, 0.658, 0.0126)
#: Pan & Hamrock (1989) central film, h_c/R = C W′^a U^b G^c (REFERENCE §8).
PAN_HAMROCK_CENTRAL = (2.922, -0.166, 0.692, 0.470)
#: (A, λ0, n) of the rough film's thickening g(λ) = A/(1 + (λ/λ0)^n), h_T,c = h_c + σ g(h_c/σ):
#: a fit to the statistical EHL solver's central average gap (module docstring).
ROUGH_FILM_THICKENING = (0.20, 2.06, 3.0)
SHEAR_LAWS = ("eyring_paper", "eyring_exact", "eyring_split", "newtonian")


def split_laws(shear: str) -> tuple[str, str]:
    """(law of the shear stress, law of the flow and damping) of a shear option.

    "eyring_split": the Eyring stress τm = τ0 asinh(η us/(τ0 h)) (the secant viscosity τm h/us) in
    the friction and the sliding heat, and the tangent viscosity dτm/dγ̇ = η/cosh(τm/τ0) (the paper's
    η*) in the Reynolds flow coefficient, the Poiseuille heat and the damping (REFERENCE §4). The
    other options use one law for all."""
    if shear == "eyring_split":
        return "eyring_exact", "eyring_paper"
    return shear, shear


class FormulaContact(eqx.Module):
    """A line contact's lubrication by the closed-form EHL model, per unit face width (SI).

    Attributes:
        film_central: the average gap at the centre, h_T,c = h_c + σ g(h_c/σ), m (Pan-Hamrock's
            h_c for smooth surfaces).
        separation_central: the mean planes' separation there, d_c = h_T⁻¹(h_T,c), m (h_c for
            smooth surfaces).
        asperity_load: w_a carried by asperity contact, N/m (at most w).
        friction_sliding: Fs = μb w_a sgn + ∫ (1 − A_r/A) η_s (u2 − u1)/h_c dx, N/m (paper Eq. 15 sign: along
            u2 − u1).
        friction_asperity: the boundary-friction part of Fs, N/m.
        friction_rolling: Fr (Goksem-Hargreaves), N/m (paper Eq. 15 sign: positive).
        damping: cm = ∫ (1 − A_r/A) η_s/h_c dx, N s/m² (paper Eq. 13 per unit width).
        power_sliding: fluid shear plus asperity friction heat, W/m.
        power_rolling: Fr (u1 + u2), W/m.
    """

    film_central: Float[Array, "..."]
    separation_central: Float[Array, "..."]
    asperity_load: Float[Array, "..."]
    friction_sliding: Float[Array, "..."]
    friction_asperity: Float[Array, "..."]
    friction_rolling: Float[Array, "..."]
    damping: Float[Array, "..."]
    power_sliding: Float[Array, "..."]
    power_rolling: Float[Array, "..."]


def hertz_gap(t):
    """Gap of the dry Hertz line contact at X = cosh t outside the zone, in units of b²/R:
    ½ (X √(X² − 1) − arcosh X) = ¼ sinh 2t − t/2 (≈ ⅔ t³ near the edge)."""
    return 0.25 * jnp.sinh(2.0 * t) - 0.5 * t


def _shear(eta, abs_us, h, tau0, law):
    """η_s of the shear law (paper η*, exact Eyring τh/us, Newtonian η); even in us, smooth at 0."""
    if law == "newtonian":
        return eta
    z = eta * abs_us / (tau0 * h)
    if law == "eyring_paper":
        return eta / jnp.sqrt(1.0 + z * z)  # η/cosh(asinh z)
    small = z < 1e-6
    zs = jnp.where(small, 1.0, z)
    return eta * jnp.where(small, 1.0 - z * z / 6.0, jnp.arcsinh(zs) / zs)


def _smooth_min(a, cap, power=8.0):
    """≈ min(a, cap) for a ≥ 0, smooth: equal to a to 1e-9 where a < cap/10."""
    return a / (1.0 + (a / cap) ** power) ** (1.0 / power)


def ehl_formula_contact(
    reduced_radius,
    load_per_width,
    u1,
    u2,
    e_reduced,
    lubricant,
    inlet_temperature,
    composite_rq,
    *,
    boundary_friction: float = 0.1,
    shear: str = "eyring_paper",
    density_product: float = 0.05,
    slope_ratio: float = 0.01,
    sign_width=None,
    viscosity_model: str = "roelands",
    limiting_shear: float | None = None,
) -> FormulaContact:
    """Friction, damping and power loss of loaded line contacts by the closed-form EHL model.

    Args:
        reduced_radius: R, m. load_per_width: w, N/m (> 0). u1, u2: surface velocities, m/s
            (u1 + u2 > 0). e_reduced: E′, Pa. lubricant: Lubricant (η0, α, τ0 at the inlet).
        inlet_temperature: K. composite_rq: σ, m (0 for smooth surfaces: no asperity load).
        boundary_friction: μb. shear: "eyring_paper", "eyring_exact", "eyring_split" (the Eyring
            stress in the traction, its tangent viscosity η* in the damping: ``split_laws``) or
            "newtonian".
        density_product, slope_ratio: nβσ and σ/β of the Greenwood-Tripp model.
        sign_width: sliding speed over which the boundary friction's sign turns, m/s (default 1 %
            of u1 + u2); the fluid part needs none (the shear law is smooth through us = 0).
        viscosity_model: "roelands" or "barus".
        limiting_shear: Λ of a limiting shear stress τL = Λ p_f that caps the traction (smoothly,
            ``rheology.log_limited_stress``), or None (no cap). The damping is not capped.

    Returns:
        FormulaContact, per unit width.
    """
    if shear not in SHEAR_LAWS:
        raise ValueError(f"shear = {shear!r} is not valid; valid choices: {SHEAR_LAWS}")
    r, w = jnp.asarray(reduced_radius), jnp.asarray(load_per_width)
    u1, u2 = jnp.asarray(u1), jnp.asarray(u2)
    um = 0.5 * (u1 + u2)
    us = u1 - u2
    abs_us = jnp.abs(us)
    eta0 = lubricant.base_viscosity(inlet_temperature)
    alpha = lubricant.pressure_viscosity_coefficient(inlet_temperature)
    tau0 = lubricant.eyring_stress
    big_u = eta0 * um / (e_reduced * r)
    big_g = alpha * e_reduced
    big_w = w / (e_reduced * r)
    c, a_w, a_u, a_g = PAN_HAMROCK_CENTRAL
    h_c = c * big_w**a_w * big_u**a_u * big_g**a_g * r
    b = r * jnp.sqrt(8.0 * big_w / jnp.pi)
    ph = e_reduced * jnp.sqrt(big_w / (2.0 * jnp.pi))

    # asperity load: flat mean-plane separation over the zone, plus both sides of the opening gap
    # out to where the separation exceeds 8 σ (beyond, F_{5/2} < 1e-12 of its value at contact)
    rough = jnp.asarray(composite_rq) > 0
    sigma = jnp.maximum(jnp.asarray(composite_rq), 1e-15)
    a_g, lam_g, n_g = ROUGH_FILM_THICKENING
    h_c = h_c + jnp.where(rough, sigma * a_g / (1.0 + (h_c / (sigma * lam_g)) ** n_g), 0.0)
    d_c = jnp.where(rough, separation_of_gap(h_c, sigma), h_c)

    def p_asp(d):
        return asperity_pressure(d, sigma, e_reduced, density_product, slope_ratio)

    gap_scale = b * b / r
    g_far = (jnp.abs(d_c) + 8.0 * sigma) / gap_scale
    t_max = 0.5 * jnp.arcsinh(4.0 * g_far) + 0.5  # hertz_gap(t_max) > g_far for every g_far > 0
    t = 0.5 * t_max[..., None] * (_GAP_T + 1.0)
    gap_w = 0.5 * t_max[..., None] * _GAP_W
    d_out = d_c[..., None] + gap_scale[..., None] * hertz_gap(t)
    outside = jnp.sum(gap_w * p_asp(d_out) * jnp.sinh(t), axis=-1)  # ∫ p_a dX over X = cosh t > 1
    w_a = b * (2.0 * p_asp(d_c) + 2.0 * outside)
    w_a = jnp.where(rough, _smooth_min(w_a, w), 0.0)
    # the fluid shears over the share of the zone out of contact
    open_share = jnp.where(rough, 1.0 - contact_area_ratio(d_c, sigma, density_product), 1.0)

    # fluid: Hertz-shaped pressure carrying w − w_a over the zone, film h_c
    share = w_a / w
    x = _ZONE_X
    p_f = ((1.0 - share) * ph)[..., None] * jnp.sqrt(1.0 - x * x)
    eta = lubricant.viscosity(p_f, inlet_temperature, viscosity_model)
    stress_law, flow_law = split_laws(shear)
    shear_args = (eta, abs_us[..., None], h_c[..., None], tau0)
    eta_s = _shear(*shear_args, stress_law)  # secant: the traction's viscosity τ h/|us|
    eta_t = eta_s if flow_law == stress_law else _shear(*shear_args, flow_law)  # damping's
    if limiting_shear is not None:  # the traction capped at τL = Λ p_f; the damping is not
        rate = jnp.maximum(abs_us, 1e-12)[..., None] / h_c[..., None]
        floor = 1e-6 * ph[..., None]
        eta_s = (
            jnp.exp(log_limited_stress(jnp.log(eta_s * rate), p_f, limiting_shear, floor)) / rate
        )
    # traction per sliding speed, ∫ (1 − A_r/A) η_s dx/h_c
    secant = open_share * b * jnp.sum(_ZONE_W * eta_s, axis=-1) / h_c
    damping = open_share * b * jnp.sum(_ZONE_W * eta_t, axis=-1) / h_c
    fluid = secant * (u2 - u1)
    width = 0.01 * (u1 + u2) if sign_width is None else sign_width
    sign = smooth_sign(u2 - u1, width)
    asperity = boundary_friction * w_a * sign
    c_r, a_gu, a_rw = ROLLING_TRACTION
    rolling = c_r * (big_g * big_u) ** a_gu * big_w**a_rw * r / alpha
    return FormulaContact(
        film_central=h_c,
        separation_central=d_c,
        asperity_load=w_a,
        friction_sliding=fluid + asperity,
        friction_asperity=asperity,
        friction_rolling=rolling,
        damping=damping,
        power_sliding=secant * us * us + asperity * (u2 - u1),
        power_rolling=rolling * (u1 + u2),
    )
