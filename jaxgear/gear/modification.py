"""Tip relief: a smooth, differentiable profile deviation (linear or parabolic).

The relief of gear j at its own roll angle ε (rad) is

    e_j(ε) = a_j · ramp((ε − ε_s,j)/(ε_tip,j − ε_s,j))^p,   p = 1 (linear) or 2 (parabolic),

with a_j the amount at the tip (m) and ε_s,j the start roll angle. ``ramp`` is max(t, 0) smoothed
over a width ``smoothing`` (in units of the relief length): w·softplus(t/w). It equals max(t, 0) to
within w·ln 2 at t = 0 and to round-off for |t| ≫ w, and it is differentiable in a_j and ε_s,j
everywhere, including at the start of the relief.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from .geometry import GearGeometry, roll_angles
from .pair import GearPair

DEFAULT_RELIEF_SMOOTHING = 0.01


def smooth_ramp(t, width):
    """w·softplus(t/w): a C∞ version of max(t, 0) with corner width ``width``."""
    return width * jax.nn.softplus(t / width)


def relief_of_gear(
    pair: GearPair,
    geo: GearGeometry,
    gear: int,
    roll_angle,
    smoothing: float = DEFAULT_RELIEF_SMOOTHING,
):
    """Tip relief (m) of gear ``gear`` (0 or 1) at its own roll angle(s) ``roll_angle`` (rad)."""
    tr = pair.tip_relief
    start = tr.start_roll_angle[gear]
    length = geo.roll_angle_tip[gear] - start
    # A relief starting at the tip (a GearPair's default: none) has no length; its 0/0 at the tip
    # would make the whole mesh position NaN (with the amount 0 as the factor), so it is zero there.
    has_length = length > 0.0
    t = (roll_angle - start) / jnp.where(has_length, length, 1.0)
    power = 1.0 if tr.shape[gear] == "linear" else 2.0
    return jnp.where(has_length, tr.amount[gear] * smooth_ramp(t, smoothing) ** power, 0.0)


def relief_separation(
    pair: GearPair, geo: GearGeometry, s, smoothing: float = DEFAULT_RELIEF_SMOOTHING
):
    """Total relief separation along the LOA (m) at LOA position s: e1(ε1(s)) + e2(ε2(s))."""
    eps1, eps2 = roll_angles(geo, s)
    return relief_of_gear(pair, geo, 0, eps1, smoothing) + relief_of_gear(
        pair, geo, 1, eps2, smoothing
    )
