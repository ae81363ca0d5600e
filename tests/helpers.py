"""What the tests share: the repository's root, contacts of the EHL tests and synthetic mesh
cycles of the dynamics tests, each computed from REFERENCE §2-§4 inputs independently of what they
are checked against.

- EHL: the paper's pitch-point contact and contacts of given Moes M, L, with the published film
  formulas (Moes; Pan & Hamrock) and Greenwood-Tripp's asperity pressure coded here as references.
- Dynamics: mesh cycles from analytic tables the dynamics did not produce, the linearised model's
  matrices assembled in numpy, and a pair of unequal gears.

Importable from every test folder as ``helpers`` (pyproject: ``pythonpath``), and from scripts
that put ``tests/`` on ``sys.path``.
"""

from __future__ import annotations

import math
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
from scipy.integrate import quad

import jaxgear as jg
from jaxgear.gear.geometry import gear_geometry
from jaxgear.gear.mesh import MeshCycle
from jaxgear.gear.pair import Bearings
from jaxgear.lubrication.passage import solve_ehl_passage
from jaxgear.lubrication.roughness import Surfaces

ROOT = Path(__file__).resolve().parents[1]  # the repository: notebooks/, examples/, jaxgear/


# -- EHL contacts ---------------------------------------------------------------------------------

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
    in Lubrication (2000). (REFERENCE §8 writes exp(−2 L M^−0.4); that variant differs by up to
    ~10 % at L = 3 and is not the published form.)
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
    dx, n = 0.5e-6, 8192
    xs = np.arange(n) * dx
    z1 = amplitude * np.exp(-(((xs - (n * dx + start * b)) / width) ** 2))
    return Surfaces(profile1=jnp.asarray(z1), profile2=jnp.zeros(n), dx=dx)


def held_passage(model, contact, lub, surfaces, dt, k):
    """``solve_ehl_passage`` of ``contact`` held for k states, Δt apart."""
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

    def f52(lam):
        value, _ = quad(lambda s: (s - lam) ** 2.5 * math.exp(-0.5 * s * s), lam, lam + 40.0)
        return value / math.sqrt(2.0 * math.pi)

    k = greenwood_tripp_constant(density_product, slope_ratio)
    return np.array([k * e_reduced * f52(float(v) / sigma) for v in np.ravel(np.asarray(h))])


# -- Dynamics: synthetic mesh cycles (analytic tables the dynamics did not produce) -------------


def synthetic_mesh(
    pair, torque, *, m=64, km_mean=3.0e8, km_amp=0.0, e_amp=0.0, e_harm=1, km_harm=1, e_phase=0.0
):
    """A MeshCycle with km(τ) = km_mean (1 + km_amp cos 2π km_harm τ) and a static TE W/km + e(τ),
    e(τ) = e_amp sin(2π e_harm τ + e_phase): smooth trigonometric tables, one pair slot loaded."""
    geo = gear_geometry(pair)
    tau = jnp.arange(m) / m
    km = km_mean * (1.0 + km_amp * jnp.cos(2 * jnp.pi * km_harm * tau))
    e = e_amp * jnp.sin(2 * jnp.pi * e_harm * tau + e_phase)
    w = torque / geo.base_radius[0]
    s = geo.path_start + (tau[:, None] + jnp.arange(2)[None, :]) * geo.base_pitch
    inc = ((s >= geo.path_start) & (s <= geo.path_end)).astype(float)
    rho = jnp.stack([s, geo.line_of_action_length - s], axis=-1)
    share = inc / inc.sum(1, keepdims=True)
    red = rho[..., 0] * rho[..., 1] / (rho[..., 0] + rho[..., 1])
    zeros = jnp.zeros((m, 2))
    return MeshCycle(
        mesh_fraction=tau,
        roll_angle=s[:, 0] / geo.base_radius[0],
        contact_position=s,
        in_contact=inc,
        radius_of_curvature=rho,
        reduced_radius=red,
        pair_stiffness=inc * km[:, None] / inc.sum(1, keepdims=True),
        mesh_stiffness=km,
        static_te=e + w / km,
        te_excitation=e,
        load_share=share,
        normal_load=share * w,
        hertz_pressure=zeros,
        hertz_half_width=zeros,
        torque=jnp.asarray(float(torque)),
        total_load=jnp.asarray(w),
    )


def numpy_matrices(pair, km):
    """Mass and stiffness matrices of the linearised model assembled independently in numpy."""
    z1, z2 = pair.teeth
    rb = np.asarray(pair.module) * np.array([z1, z2]) / 2 * np.cos(float(pair.pressure_angle))
    m = np.asarray(pair.blank_mass)
    j = np.asarray(pair.blank_inertia)
    b = pair.bearings
    mass = np.diag([j[0], m[0], m[0], j[1], m[1], m[1]])
    k = np.zeros((6, 6))
    # mesh spring on d = r1θ1 + y1 − r2θ2 − y2, bearings to ground
    idx = [0, 1, 3, 4]
    coef = [rb[0], 1.0, -rb[1], -1.0]
    for a, ca in zip(idx, coef):
        for c, cc in zip(idx, coef):
            k[a, c] += km * ca * cc
    k[1, 1] += float(b.ky[0])
    k[2, 2] += float(b.kx[0])
    k[4, 4] += float(b.ky[1])
    k[5, 5] += float(b.kx[1])
    return mass, k


def unequal_pair(backlash=0.0, teeth=(40, 61), bearings=None, mesh_damping_ratio=0.0):
    """Unequal gears: different blanks and bearings on the two shafts (and 40/61 teeth by default).

    The steady-state tests use 50/50 teeth, as the other dynamics tests do: tooth numbers are static
    fields, so sharing them shares one compilation of ``dynamic_response`` across the test session;
    the 40/61 ratio is covered by the eigen-solution test, which needs no compilation.
    ``bearings``: others than these unequal ones; ``mesh_damping_ratio``: ζ along the line of
    action (GearPair)."""
    if bearings is None:
        bearings = Bearings(
            ky=(1.15e9, 0.8e9),
            cy=(5360.0, 4100.0),
            kx=(8.0e8, 6.5e8),
            cx=(2980.0, 2500.0),
            ct=(10.0, 14.0),
        )
    return jg.GearPair(
        teeth=teeth,
        module=3e-3,
        pressure_angle=math.radians(20.0),
        face_width=0.02,
        backlash=backlash,
        blank_mass=(3.1, 7.4),
        blank_inertia=(5.2e-3, 2.9e-2),
        bearings=bearings,
        mesh_damping_ratio=mesh_damping_ratio,
    )
