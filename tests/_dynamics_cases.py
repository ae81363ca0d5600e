"""Synthetic mesh cycles for the dynamics tests (analytic tables the dynamics did not produce)."""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from jaxgear.gear.geometry import gear_geometry
from jaxgear.gear.mesh import MeshCycle


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
