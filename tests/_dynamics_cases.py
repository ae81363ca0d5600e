"""Synthetic mesh cycles for the dynamics tests (analytic tables the dynamics did not produce)."""

from __future__ import annotations

import math

import jax.numpy as jnp
import numpy as np

import jaxgear as jg
from jaxgear.gear.geometry import gear_geometry
from jaxgear.gear.mesh import MeshCycle
from jaxgear.gear.pair import Bearings


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
