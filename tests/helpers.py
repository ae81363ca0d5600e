"""Contacts shared by the EHL tests: the paper's pitch-point contact and contacts of given Moes M,
L.

Everything here is computed from REFERENCE §2-§4 inputs, independently of the solver.
"""

import math

import numpy as np

import jaxgear as jg

E_REDUCED = 207e9 / (1 - 0.3**2)  # E' for two steel bodies (2/E' = 2(1−ν²)/E), Pa
PITCH_RADIUS = 12.826e-3  # Req at the pitch point (REFERENCE §3), m
BASE_RADIUS = 70.4769e-3  # m
FACE_WIDTH = 0.020  # m
ROLLING_PER_1000RPM = 2.686  # ur per 1000 rpm, m/s (REFERENCE §3)


def gear_contact(torque=700.0, rpm=2000.0, slide_to_roll=0.3, radius=PITCH_RADIUS, t_in=363.15):
    """Pitch-region line contact of the paper's pair carrying the whole load (single pair)."""
    w = torque / BASE_RADIUS / FACE_WIDTH
    ur = ROLLING_PER_1000RPM * rpm / 1000.0
    return jg.LineContact(
        reduced_radius=radius,
        load_per_width=w,
        u1=ur * (1 + slide_to_roll / 2),
        u2=ur * (1 - slide_to_roll / 2),
        e_reduced=E_REDUCED,
        inlet_temperature=t_in,
    )


def dimensionless(contact, lub):
    """(U, W', G, M, L) of a contact (REFERENCE §8), with α and η0 at the inlet temperature."""
    t = float(contact.inlet_temperature)
    eta0 = float(lub.base_viscosity(t))
    alpha = float(lub.pressure_viscosity_coefficient(t))
    e, r = float(contact.e_reduced), float(contact.reduced_radius)
    um = 0.5 * (float(contact.u1) + float(contact.u2))
    u = eta0 * um / (e * r)
    w = float(contact.load_per_width) / (e * r)
    g = alpha * e
    return u, w, g, w * (2 * u) ** -0.5, g * (2 * u) ** 0.25


def moes_contact(m, l, lub, slide_to_roll=0.0, radius=0.02, t_in=363.15):
    """A contact with Moes parameters (M, L) for ``lub``: U from L, W' from M."""
    eta0 = float(lub.base_viscosity(t_in))
    alpha = float(lub.pressure_viscosity_coefficient(t_in))
    g = alpha * E_REDUCED
    u = (l / g) ** 4 / 2
    w = m * math.sqrt(2 * u)
    um = u * E_REDUCED * radius / eta0
    return jg.LineContact(
        reduced_radius=radius,
        load_per_width=w * E_REDUCED * radius,
        u1=um * (1 + slide_to_roll / 2),
        u2=um * (1 - slide_to_roll / 2),
        e_reduced=E_REDUCED,
        inlet_temperature=t_in,
    )


def moes_central(m, l):
    """Moes' central film H_M (line contact, Barus, incompressible), coded independently here.

    Transition exponent s = (7 + 8 exp(−2 H_EI/H_RI))/5 as in Venner & Lubrecht, Multilevel Methods
    in
    Lubrication (2000). (REFERENCE §8 writes exp(−2 L M^−0.4); that variant differs by up to ~10 %
    at
    L = 3 and is not the published form.)
    """
    h_ri, h_ei = 3.0 / m, 2.621 * m**-0.2
    h_rp, h_ep = 1.287 * l ** (2 / 3), 1.311 * m**-0.125 * l**0.75
    s = (7 + 8 * np.exp(-2 * h_ei / h_ri)) / 5
    a = (h_ri ** (7 / 3) + h_ei ** (7 / 3)) ** (3 * s / 7)
    b = (h_rp**-3.5 + h_ep**-3.5) ** (-2 * s / 7)
    return (a + b) ** (1 / s)


def pan_hamrock(contact, lub):
    """(h_min, h_central) of Pan & Hamrock (1989), m (REFERENCE §8)."""
    u, w, g, _, _ = dimensionless(contact, lub)
    r = float(contact.reduced_radius)
    hmin = 1.714 * w**-0.128 * u**0.694 * g**0.568 * r
    hc = 2.922 * w**-0.166 * u**0.692 * g**0.470 * r
    return hmin, hc


def bump_surfaces(b, amplitude=50e-9, width=10e-6, start=-2.5):
    """One Gaussian bump (amplitude, 1/e half-width, m) on surface 1, entering from x = start·b."""
    import jax.numpy as jnp

    from jaxgear.lubrication.roughness import Surfaces

    dx, n = 0.5e-6, 8192
    xs = np.arange(n) * dx
    z1 = amplitude * np.exp(-(((xs - (n * dx + start * b)) / width) ** 2))
    return Surfaces(profile1=jnp.asarray(z1), profile2=jnp.zeros(n), dx=dx)


def held_passage(model, contact, lub, surfaces, dt, k):
    """``solve_ehl_passage`` of ``contact`` held for k states, Δt apart."""
    import jax
    import jax.numpy as jnp

    from jaxgear.lubrication.passage import solve_ehl_passage

    contacts = jax.tree_util.tree_map(lambda a: jnp.full((k,), a), contact)
    return solve_ehl_passage(contacts, lub, model, surfaces, times=jnp.arange(k) * dt)


def greenwood_tripp_constant(density_product, slope_ratio):
    """Greenwood-Tripp K′ = (8√2/15) π (nβσ)² √(σ/β) (Johnson, Greenwood & Poon 1972), coded here
    apart from the library's ``asperity.asperity_constant`` as the tests' reference."""
    return 8.0 * math.sqrt(2.0) / 15.0 * math.pi * density_product**2 * math.sqrt(slope_ratio)


def greenwood_tripp_pressure(h, sigma, e_reduced, density_product, slope_ratio):
    """Greenwood-Tripp asperity pressure K′ E′ F_{5/2}(h/σ) at the films ``h`` (m), Pa, with
    F_{5/2}(λ) = (2π)^(−½) ∫_λ^∞ (s − λ)^{5/2} exp(−s²/2) ds by adaptive quadrature: the tests'
    reference for the library's ``asperity.asperity_pressure``."""
    from scipy.integrate import quad

    def f52(lam):
        value, _ = quad(lambda s: (s - lam) ** 2.5 * math.exp(-0.5 * s * s), lam, lam + 40.0)
        return value / math.sqrt(2.0 * math.pi)

    k = greenwood_tripp_constant(density_product, slope_ratio)
    return np.array([k * e_reduced * f52(float(v) / sigma) for v in np.ravel(np.asarray(h))])
