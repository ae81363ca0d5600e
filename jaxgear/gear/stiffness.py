"""Tooth-pair stiffness along the path of contact.

Two methods:

* ``"potential_energy"``: each tooth is a non-uniform cantilever on an elastic foundation. The bending,
  shear and axial-compression energies are integrated numerically over the real involute tooth (section
  half-thickness from the involute, a constant-thickness section between the base and root circles when
  the root lies below the base circle), as in Yang & Sun (1985), Tian (2004) and Chen & Shao (2011);
  the fillet-foundation deflection is Sainsot, Velex & Duverger (J. Mech. Des. 126, 2004); the Hertzian
  term is Yang & Sun's constant k_h = π E' L / 4. Per pair:
  1/k = 1/k_h + Σ_j (1/k_b,j + 1/k_s,j + 1/k_a,j + 1/k_f,j).
* ``"iso"``: ISO 6336-1 method B single stiffness c' (constant along the path): the cheap alternative.

A force F applied along the LOA at the contact loads tooth j with F cos α1 across the tooth centreline
and F sin α1 along it (compression), α1 = ε_j − α2,j, where ε_j is gear j's own roll angle and α2,j the
half tooth angle at the base circle.
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from ..material import reduced_modulus
from . import involute as inv
from .geometry import GearGeometry, roll_angles
from .pair import GearPair

STIFFNESS_METHODS = ("potential_energy", "iso")
#: h_fP/m of ISO 53's standard basic rack profile, the default of ``iso_single_stiffness``.
ISO_BASIC_RACK_DEDENDUM = 1.25

_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(24)
_GL8_NODES, _GL8_WEIGHTS = np.polynomial.legendre.leggauss(8)

# Sainsot et al. (2004) fillet-foundation coefficients: X* = A/θf² + B h² + C h/θf + D/θf + E h + F,
# rows L*, M*, P*, Q*; columns A..F.
_SAINSOT = np.array(
    [
        [-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045],
        [60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086],
        [-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236],
        [-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904],
    ]
)


def base_half_angle(pair: GearPair):
    """α2 per gear: half the tooth angle at the base circle, rad (shape (2,))."""
    return inv.base_half_angle(pair.teeth, pair.pressure_angle, pair.profile_shift)


def _sqrt_positive(x):
    """√max(x, 0) whose derivative is 0 where x ≤ 0 (the double where)."""
    positive = x > 0.0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, x, 1.0)), 0.0)


def _gauss(f, lo, hi, nodes, weights):
    """∫_lo^hi f over the last axis, Gauss-Legendre (lo, hi broadcast with the leading shape)."""
    half = 0.5 * (hi - lo)
    mid = 0.5 * (hi + lo)
    t = mid[..., None] + half[..., None] * jnp.asarray(nodes)
    return half * jnp.sum(f(t) * jnp.asarray(weights), axis=-1)


def tooth_compliances(pair: GearPair, gear: int, roll_angle):
    """Bending, shear, axial and fillet-foundation compliances (m/N) of tooth ``gear`` (0, 1) loaded
    along the LOA at its own roll angle ``roll_angle`` (rad, any shape).

    Returns a dict with keys "bending", "shear", "axial", "fillet".
    """
    mat = pair.materials[gear]
    e_mod = mat.youngs_modulus
    g_mod = e_mod / (2.0 * (1.0 + mat.poisson_ratio))
    width = pair.face_width
    rb = pair.base_radius[gear]
    rf = pair.root_radius[gear]
    a2 = base_half_angle(pair)[gear]
    eps = jnp.asarray(roll_angle)
    a1 = eps - a2

    def involute_point(t):
        r = rb * jnp.sqrt(1.0 + t**2)
        phi = a2 - (t - jnp.arctan(t))
        return r * jnp.cos(phi), r * jnp.sin(phi)

    def involute_dx(t):
        r = rb * jnp.sqrt(1.0 + t**2)
        dr = rb * t / jnp.sqrt(1.0 + t**2)
        phi = a2 - (t - jnp.arctan(t))
        dphi = -(t**2) / (1.0 + t**2)
        return dr * jnp.cos(phi) - r * jnp.sin(phi) * dphi

    xc, yc = involute_point(eps)
    cos1, sin1 = jnp.cos(a1), jnp.sin(a1)

    def energy_density(x, y):
        # per unit force: bending M²/(EI), shear 1.2 V²/(GA), axial N²/(EA)
        area = 2.0 * y * width
        inertia = (2.0 / 3.0) * width * y**3
        moment = cos1[..., None] * (xc[..., None] - x) - sin1[..., None] * yc[..., None]
        return (
            moment**2 / (e_mod * inertia),
            1.2 * cos1[..., None] ** 2 / (g_mod * area),
            sin1[..., None] ** 2 / (e_mod * area),
        )

    # Involute part: from the base circle (or the root circle if it lies above) to the contact point.
    # (0 when the root lies below the base circle; its derivative is then 0, not √'(0) × 0 = NaN.)
    t_low = inv.roll_angle(rf, rb)
    t_lo = jnp.broadcast_to(t_low, eps.shape)

    def inv_integrand(k):
        def f(t):
            x, y = involute_point(t)
            return energy_density(x, y)[k] * involute_dx(t)

        return f

    comp = [_gauss(inv_integrand(k), t_lo, eps, _GL_NODES, _GL_WEIGHTS) for k in range(3)]

    # Constant-thickness section between the root circle and the base circle (root below base).
    y_base = rb * jnp.sin(a2)
    x_base = rb * jnp.cos(a2)
    x_root = _sqrt_positive(rf**2 - y_base**2)
    x_root = jnp.minimum(x_root, x_base)
    x_lo = jnp.broadcast_to(x_root, eps.shape)
    x_hi = jnp.broadcast_to(x_base, eps.shape)

    def rect_integrand(k):
        def f(x):
            return energy_density(x, jnp.broadcast_to(y_base, x.shape))[k]

        return f

    comp = [
        c + _gauss(rect_integrand(k), x_lo, x_hi, _GL8_NODES, _GL8_WEIGHTS)
        for k, c in enumerate(comp)
    ]

    # Fillet foundation (Sainsot et al. 2004).
    y_root = jnp.minimum(y_base, 0.999 * rf)
    theta_f = jnp.arcsin(y_root / rf)
    s_f = 2.0 * rf * theta_f
    h_f = rf / pair.bore_radius[gear]
    u_f = xc - yc * jnp.tan(a1) - rf
    coef = jnp.asarray(_SAINSOT)
    terms = jnp.stack(
        [1.0 / theta_f**2, h_f**2, h_f / theta_f, 1.0 / theta_f, h_f, jnp.ones_like(h_f)]
    )
    l_s, m_s, p_s, q_s = coef @ terms
    ratio = u_f / s_f
    fillet = (
        cos1**2
        / (e_mod * width)
        * (l_s * ratio**2 + m_s * ratio + p_s * (1.0 + q_s * jnp.tan(a1) ** 2))
    )
    return {"bending": comp[0], "shear": comp[1], "axial": comp[2], "fillet": fillet}


def hertz_contact_stiffness(pair: GearPair):
    """Yang & Sun's linearised Hertzian stiffness of a line contact, k_h = π E' L / 4 (N/m)."""
    e_red = reduced_modulus(*pair.materials)
    return jnp.pi * e_red * pair.face_width / 4.0


def iso_single_stiffness(pair: GearPair, basic_rack_dedendum=ISO_BASIC_RACK_DEDENDUM):
    """ISO 6336-1 method B single stiffness c' per unit face width (N/m per m, i.e. Pa).

    c' = c'_th C_M C_R C_B with c'_th = 1/q' (solid disks C_R = 1, C_M = 0.8,
    ``C_B = [1 + 0.5(1.2 − h_fP/m)][1 − 0.02(20° − α)]``, h_fP/m clipped to ISO's 1.2-1.4).

    ``basic_rack_dedendum`` is h_fP/m of the basic rack profile the rating refers to (default ISO
    53's 1.25). It is not the pair's ``dedendum_coefficient``, which places the root circle: the
    cutting tool may take the root deeper than the basic rack (the paper's pair: h_f* = 5/3), a depth
    the potential-energy method models and ISO's factor does not.
    """
    zn1, zn2 = float(pair.teeth[0]), float(pair.teeth[1])
    x1, x2 = pair.profile_shift[0], pair.profile_shift[1]
    q = (
        0.04723
        + 0.15551 / zn1
        + 0.25791 / zn2
        - 0.00635 * x1
        - 0.11654 * x1 / zn1
        - 0.00193 * x2
        - 0.24188 * x2 / zn2
        + 0.00529 * x1**2
        + 0.00182 * x2**2
    )  # mm µm / N
    c_th = 1.0 / q  # N / (mm µm)
    hfp = jnp.clip(basic_rack_dedendum, 1.2, 1.4)
    c_b = (1.0 + 0.5 * (1.2 - hfp)) * (1.0 - 0.02 * (20.0 - jnp.degrees(pair.pressure_angle)))
    c_prime = c_th * 0.8 * 1.0 * c_b
    return c_prime * 1e9  # N/(mm µm) = 1e9 N/m²


def iso_mesh_stiffness(pair: GearPair, geo: GearGeometry):
    """ISO 6336-1 mean mesh stiffness cγα b = c' (0.75 εα + 0.25) b, N/m."""
    return iso_single_stiffness(pair) * (0.75 * geo.contact_ratio + 0.25) * pair.face_width


def pair_stiffness(pair: GearPair, geo: GearGeometry, s, method: str = "potential_energy"):
    """Stiffness (N/m) of one tooth pair in contact at LOA position(s) s (m), along the LOA."""
    if method == "iso":
        return jnp.broadcast_to(iso_single_stiffness(pair) * pair.face_width, jnp.shape(s))
    if method != "potential_energy":
        raise ValueError(f"stiffness method = {method!r} is not valid; valid: {STIFFNESS_METHODS}")
    eps1, eps2 = roll_angles(geo, s)
    compliance = 1.0 / hertz_contact_stiffness(pair)
    for gear, eps in ((0, eps1), (1, eps2)):
        parts = tooth_compliances(pair, gear, eps)
        compliance = (
            compliance + parts["bending"] + parts["shear"] + parts["axial"] + parts["fillet"]
        )
    return 1.0 / compliance
