"""The contact layer's common currency: what the contacts of a mesh cycle give the dynamics.

Every friction rung of the coupled model (constant μ, the regression formula, the closed-form
mixed EHL contact, the EHL solvers, the frozen coupling) turns the tooth forces and surface
velocities of one mesh cycle into ``ContactForces`` per [position, pair slot]; the dynamics reads
them through ``interface_from_forces`` (paper Eqs. 13-15).
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, Bool, Float, Int

from ..dynamics.model import MeshInterface
from ..gear.mesh import MeshCycle
from ..gear.pair import GearPair

# The friction force of the formula rungs changes sign with the sliding velocity through a smooth
# sign over a slide-to-roll ratio of SIGN_SLIDE_TO_ROLL: real EHL traction grows linearly with slip
# up to ~1-2 % SRR before it saturates, and a discontinuous sign makes the tribo-dynamic fixed point
# chatter between neighbouring states (vibration moves the sign change from one position to the
# next).
SIGN_SLIDE_TO_ROLL = 0.02

#: A slot counts as loaded above this share of the total load (below it the contact is a
#: few-newton touch at the edge of relief, where EHL has no meaning and contributes nothing
#: measurable).
LOADED_SHARE = 1e-4


class ContactForces(eqx.Module):
    """What the contacts of one mesh cycle give back, per [position, pair] (SI).

    Attributes:
        friction_sliding: Fs, N (sign along u2 − u1, paper Eq. 15).
        friction_rolling: Fr, N (paper Eq. 15).
        damping: cm, N s/m (paper Eq. 13).
        power_sliding: sliding part of Φn, W.
        power_rolling: rolling part of Φn, W.
        friction_coefficient: (Fs² + Fr²)^½ / W_T where loaded (informative), dimensionless.
        converged: every contact solve converged.
        failed: number of loaded contacts whose solve failed (their outputs are carried over from
            the nearest good contact; see ``contact.coefficients.patch_failed``).
    """

    friction_sliding: Float[Array, "M 2"]
    friction_rolling: Float[Array, "M 2"]
    damping: Float[Array, "M 2"]
    power_sliding: Float[Array, "M 2"]
    power_rolling: Float[Array, "M 2"]
    friction_coefficient: Float[Array, "M 2"]
    converged: Bool[Array, ""]
    failed: Int[Array, ""]


def safe_sqrt(x):
    """√x where x > 0, else 0, with a finite derivative everywhere."""
    ok = x > 0
    return jnp.where(ok, jnp.sqrt(jnp.where(ok, x, 1.0)), 0.0)


def interface_from_forces(forces: ContactForces) -> MeshInterface:
    """Paper Eq. 14-15 without the cm term (the dynamics adds cm times the vibratory sliding speed):
    F1 = Fs − Fr, F2 = Fs + Fr."""
    return MeshInterface(
        damping=forces.damping,
        friction_1=forces.friction_sliding - forces.friction_rolling,
        friction_2=forces.friction_sliding + forces.friction_rolling,
    )


def kinematic_velocities(pair: GearPair, mesh: MeshCycle, omega1):
    """Kinematic surface velocities uj = ρj ωj per [position, pair, gear], m/s."""
    omega = jnp.stack([omega1, omega1 * pair.teeth[0] / pair.teeth[1]])
    return mesh.radius_of_curvature * omega
