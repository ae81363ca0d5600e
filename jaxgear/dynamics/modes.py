"""Natural frequencies and mode shapes of the linearised 6-DOF gear model (paper Eq. 1).

Linearisation: teeth in contact (no backlash), constant mesh stiffness km, no damping, no friction.
Coordinates (θ1, y1, x1, θ2, y2, x2) with mass matrix diag(J1, m1, m1, J2, m2, m2) and stiffness
K = km g gᵀ + diag(0, ky1, kx1, 0, ky2, kx2), where g = (r1, 1, 0, −r2, −1, 0) is the gradient of the
mesh deflection. The rigid-body rotation (r1θ1 = r2θ2) is a zero-frequency mode.
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, Float

from .._validation import check_instance, check_positive
from ..gear.geometry import gear_geometry
from ..gear.pair import GearPair


class Modes(eqx.Module):
    """Modes of the linearised model, ascending frequency (the first is the rigid-body rotation, 0 Hz).

    Attributes:
        frequencies: natural frequencies, Hz [6].
        shapes: mass-normalised mode shapes, columns, in (θ1 rad, y1 m, x1 m, θ2 rad, y2 m, x2 m) [6, 6].
        mesh_energy_fraction: share of each mode's strain energy stored in the mesh spring [6]
            (≈ 1 for the mesh-coupled modes that the transmission error excites; 0 for the rigid mode).
    """

    frequencies: Float[Array, " 6"]
    shapes: Float[Array, "6 6"]
    mesh_energy_fraction: Float[Array, " 6"]


def _matrices(pair, mesh_stiffness):
    rb = gear_geometry(pair).base_radius
    m, j, b = pair.blank_mass, pair.blank_inertia, pair.bearings
    mass = jnp.stack([j[0], m[0], m[0], j[1], m[1], m[1]])
    g = jnp.stack([rb[0], 1.0, 0.0, -rb[1], -1.0, 0.0])
    support = jnp.stack([0.0, b.ky[0], b.kx[0], 0.0, b.ky[1], b.kx[1]])
    km = jnp.asarray(mesh_stiffness, float)
    stiffness = km * jnp.outer(g, g) + jnp.diag(support)
    return mass, stiffness, g, km


def mode_shapes(pair, mesh_stiffness) -> Modes:
    """Modes of ``pair`` with constant mesh stiffness ``mesh_stiffness`` (N/m, scalar, e.g. the mean km).

    Solved as the symmetric eigenproblem of M^(−1/2) K M^(−1/2) (``jnp.linalg.eigh``); differentiable.
    """
    check_instance("pair", pair, GearPair)
    check_positive("mesh_stiffness", mesh_stiffness, "N/m")
    mass, stiffness, g, km = _matrices(pair, mesh_stiffness)
    s = 1.0 / jnp.sqrt(mass)
    lam, vec = jnp.linalg.eigh(stiffness * s[:, None] * s[None, :])
    shapes = vec * s[:, None]
    omega = jnp.sqrt(jnp.clip(lam, 0.0))
    mesh_energy = km * (g @ shapes) ** 2
    total = jnp.einsum("im,ij,jm->m", shapes, stiffness, shapes)
    # The rigid-body mode stores no strain energy: its fraction is 0, not round-off over round-off.
    elastic = total > 1e-9 * jnp.max(total)
    frac = jnp.where(elastic, mesh_energy / jnp.where(elastic, total, 1.0), 0.0)
    return Modes(frequencies=omega / (2.0 * jnp.pi), shapes=shapes, mesh_energy_fraction=frac)


def natural_frequencies(pair, mesh_stiffness) -> Float[Array, " 6"]:
    """Natural frequencies (Hz, ascending, first = rigid-body 0 Hz) of the linearised model."""
    return mode_shapes(pair, mesh_stiffness).frequencies
