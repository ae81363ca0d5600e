"""Lubricant rheology: pressure-viscosity (Roelands, Barus), temperature-viscosity (Walther/ASTM
D341,
Roelands S0), density (Dowson-Higginson with thermal expansion) and Eyring shear thinning.

Pure functions of arrays, SI units (Pa, K, Pa s, kg/m³, m²/s), differentiable. Pressures below
``NEGATIVE_PRESSURE_FLOOR`` (non-physical; they only occur in Newton iterates) are clipped so that
the
Roelands and Dowson-Higginson expressions stay finite.

References: C.J.A. Roelands, thesis, Delft 1966; ASTM D341 (Walther); D. Dowson & G.R. Higginson,
Elasto-hydrodynamic Lubrication, 1966; H. Eyring, J. Chem. Phys. 4 (1936); REFERENCE §4;
S. Bair & W.O. Winer, J. Lubr. Technol. 101 (1979) (limiting shear stress τL = Λ p).
"""

from __future__ import annotations

import jax.numpy as jnp

ROELANDS_PRESSURE = 1.0 / 5.1e-9
"""p_r = 1/5.1e-9 Pa ≈ 196 MPa, the Roelands reference pressure."""
ROELANDS_LN_ETA_INF = -9.67
"""ln(η∞/(Pa s)) = −9.67 (η∞ = 6.31e-5 Pa s), Roelands' asymptotic viscosity."""
ROELANDS_T_INF = 138.0
"""Roelands' temperature asymptote, K."""
NEGATIVE_PRESSURE_FLOOR = -1.0e8
"""Pressures are clipped to ≥ this value (Pa) inside the rheology to keep iterates finite."""


def _clip_pressure(pressure):
    return jnp.maximum(pressure, NEGATIVE_PRESSURE_FLOOR)


def walther_constants(nu1, t1, nu2, t2):
    """Walther (ASTM D341) constants A, B from two kinematic viscosities.

    log10 log10(ν + 0.7) = A − B log10 T, ν in cSt, T in K.

    Args:
        nu1, nu2: kinematic viscosities at t1, t2, m²/s.
        t1, t2: temperatures, K.

    Returns:
        (A, B), dimensionless.
    """
    w1 = jnp.log10(jnp.log10(nu1 * 1e6 + 0.7))
    w2 = jnp.log10(jnp.log10(nu2 * 1e6 + 0.7))
    b = (w1 - w2) / (jnp.log10(t2) - jnp.log10(t1))
    a = w1 + b * jnp.log10(t1)
    return a, b


def walther_kinematic_viscosity(temperature, a, b):
    """Kinematic viscosity from the Walther equation (ASTM D341), m²/s (T in K)."""
    return (10.0 ** (10.0 ** (a - b * jnp.log10(temperature))) - 0.7) * 1e-6


def roelands_log_pressure_factor(pressure, ln_eta0, z):
    """ln(η(p)/η0) of the isothermal Roelands equation.

    ln η/η0 = (ln η0 + 9.67) [(1 + p/p_r)^Z − 1], p in Pa, η0 in Pa s (REFERENCE §4).
    """
    p = _clip_pressure(pressure)
    return (ln_eta0 - ROELANDS_LN_ETA_INF) * ((1.0 + p / ROELANDS_PRESSURE) ** z - 1.0)


def roelands_log_viscosity(pressure, temperature, ln_eta_ref, t_ref, z, s0):
    """ln η(p, T) of the full Roelands equation (pressure index Z, temperature index S0).

    ln η = ln η_R + (ln η_R + 9.67) [−1 + (1 + p/p_r)^Z ((T − 138)/(T_R − 138))^(−S0)],
    η_R = η(0, T_R) in Pa s, p in Pa, T in K (REFERENCE §4).
    """
    p = _clip_pressure(pressure)
    theta = (temperature - ROELANDS_T_INF) / (t_ref - ROELANDS_T_INF)
    return ln_eta_ref + (ln_eta_ref - ROELANDS_LN_ETA_INF) * (
        -1.0 + (1.0 + p / ROELANDS_PRESSURE) ** z * theta ** (-s0)
    )


def roelands_pressure_viscosity_coefficient(ln_eta0, z):
    """Initial slope α = d ln η/dp at p = 0 of the Roelands equation: Z (ln η0 + 9.67)/p_r, 1/Pa."""
    return z * (ln_eta0 - ROELANDS_LN_ETA_INF) / ROELANDS_PRESSURE


def roelands_z_from_alpha(alpha, ln_eta0):
    """Roelands pressure index Z matching a pressure-viscosity coefficient α (1/Pa) at η0 (Pa s)."""
    return alpha * ROELANDS_PRESSURE / (ln_eta0 - ROELANDS_LN_ETA_INF)


def barus_log_pressure_factor(pressure, alpha):
    """ln(η/η0) = α p of the Barus equation (α in 1/Pa, p in Pa)."""
    return alpha * _clip_pressure(pressure)


def dowson_higginson_density(pressure, temperature, rho_ref, t_ref, thermal_expansion):
    """Dowson-Higginson density with linear thermal expansion, kg/m³.

    ``ρ = ρ_ref [1 + 0.6e-9 p/(1 + 1.7e-9 p)] [1 − ε (T − T_ref)]``, p in Pa, T in K (REFERENCE §4).
    """
    p = _clip_pressure(pressure)
    return (
        rho_ref
        * (1.0 + 0.6e-9 * p / (1.0 + 1.7e-9 * p))
        * (1.0 - thermal_expansion * (temperature - t_ref))
    )


def eyring_shear_stress(viscosity, shear_rate, eyring_stress):
    """Exact Eyring shear stress τ = τ0 asinh(η γ̇/τ0), Pa (γ̇ in 1/s, τ0 in Pa).

    For plain Couette flow γ̇ = us/h this is the mid-film stress τm of REFERENCE §4.
    """
    return eyring_stress * jnp.arcsinh(viscosity * shear_rate / eyring_stress)


def log_eyring_paper_factor(log_s):
    """ln(η*/η) of the paper's η* = η/cosh(τm/τ0) with τm = τ0 asinh(s), s = η|us|/(τ0 h).

    cosh(asinh s) = √(1 + s²), so ln(η*/η) = −½ ln(1 + s²), evaluated from ln s without overflow
    (paper Eq. 4 and REFERENCE §4).
    """
    return -0.5 * jnp.logaddexp(0.0, 2.0 * log_s)


def log_eyring_exact_factor(log_s):
    """ln(η_e/η) with η_e = τ h/|us| the effective viscosity of exact Eyring Couette shear:
    η_e/η = asinh(s)/s, s = η|us|/(τ0 h), evaluated from ln s without overflow (→ 0 as s → 0)."""
    small = log_s < jnp.log(1e-4)
    large = log_s > 20.0
    log_mid = jnp.clip(log_s, jnp.log(1e-4), 20.0)
    mid = jnp.log(jnp.arcsinh(jnp.exp(log_mid))) - log_mid
    log_big = jnp.maximum(log_s, 20.0)
    big = jnp.log(jnp.log(2.0) + log_big) - log_big
    s_small = jnp.exp(jnp.minimum(log_s, jnp.log(1e-4)))
    return jnp.where(small, -(s_small**2) / 6.0, jnp.where(large, big, mid))


#: Sharpness of the smooth cap at the limiting shear stress: τ = τ_law/(1 + (τ_law/τL)^n)^(1/n)
#: (n = 8: within 0.1 % of τ_law at τ_law = τL/2, 8.3 % below τL where τ_law = τL).
LIMITING_SHARPNESS = 8.0


def log_limited_stress(log_tau, pressure, coefficient, pressure_floor):
    """ln of the shear stress capped, smoothly, at the limiting shear stress τL = Λ p (Bair & Winer):
    ln τ − softplus(n (ln τ − ln τL))/n, n = LIMITING_SHARPNESS, i.e. τ/(1 + (τ/τL)^n)^(1/n).

    ``log_tau``: ln of the shear law's stress, Pa. ``pressure``: the fluid pressure, Pa, floored at
    ``pressure_floor`` (> 0) so that unloaded nodes keep a small finite cap. ``coefficient``: Λ.
    Written in logs: finite with finite derivatives for any stress and pressure."""
    log_cap = jnp.log(coefficient) + jnp.log(jnp.maximum(pressure, pressure_floor))
    n = LIMITING_SHARPNESS
    return log_tau - jnp.logaddexp(0.0, n * (log_tau - log_cap)) / n
