"""Mesh power loss and efficiency (paper Eqs. 16-17).

Per tooth pair n at mesh position i the power loss is Φn(t_i) = L ∫ Q dx (W), split into its sliding
and rolling parts; Φ(t_i) = Σn Φn(t_i); the cycle mean Φ̄ is the mean over the M equally spaced
positions of one mesh cycle (a rectangle rule, exact for the trigonometric content the positions
resolve). Efficiency Ψ = 1 − Φ̄/(T1 ω1) (REFERENCE §1: the paper's figure axis, 99.6-99.85 %, shows this
is the intended definition).
"""

from __future__ import annotations

import jax.numpy as jnp


def cycle_mean(per_position):
    """Mean over the M positions of one mesh cycle (leading axis)."""
    return jnp.mean(per_position, axis=0)


def total_per_position(per_pair):
    """Φ(t_i) = Σn Φn(t_i): sum over the pair slots (last axis) → [M]."""
    return jnp.sum(per_pair, axis=-1)


def efficiency(mean_power_loss, torque, omega1):
    """Ψ = 1 − Φ̄/(T1 ω1) (dimensionless), Φ̄ in W, T1 in N m, ω1 in rad/s."""
    return 1.0 - mean_power_loss / (torque * omega1)
