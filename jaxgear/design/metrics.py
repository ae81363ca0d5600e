"""The design quantities of one simulated operating point, by name: what an optimisation may take as
its objective or constrain, and what the sensitivity report differentiates.

Per point (one ``SimulationResult`` of one pair at one operating point):

- ``efficiency``: Ψ = 1 − Φ̄/(T1 ω1) (paper Eq. 17), dimensionless.
- ``power_loss``: Φ̄, the cycle-mean mesh power loss, W; ``power_loss_sliding`` and
  ``power_loss_rolling`` its parts, W.
- ``dte_rms``: RMS dynamic transmission error over the first ten mesh harmonics, m.
- ``hertz_pressure``: the maximum Hertz pressure of each flank pair at each mesh position, Pa [M, 2]
  (zero where a pair carries no load). Its peak is the largest entry.
- ``flash_temperature``: Blok's flash temperature rise of each flank pair at each position, K [M, 2]
  (REFERENCE §5):

      ΔT = 1.11 μ w′ |u1 − u2| / (√(2b) (√(k1 ρ1 c1 |u1|) + √(k2 ρ2 c2 |u2|))),

  with μ the pair's friction coefficient, w′ = W/L its load per unit face width, u1, u2 the surface
  velocities and b = 2w′/(π pH) the Hertz half-width (from the Hertz pressure pH, so no second
  curvature is needed). H. Blok, "Theoretical study of temperature rise at surfaces of actual
  contact under oiliness lubricating conditions", Proc. General Discussion on Lubrication, IMechE
  (1937) 222-235.

Field quantities ([M, 2]) enter constraints position by position (a smooth constraint per entry, so
an augmented Lagrangian sees no kink where the peak moves from one position to another); reports
give their peak. Every quantity is traceable and differentiable (its square roots are guarded at zero
load).
"""

from __future__ import annotations

import jax.numpy as jnp

from ..contact.base import safe_sqrt as _guarded_sqrt

#: Scalar quantities per point → (unit, sense of "better": +1 larger, −1 smaller).
SCALARS = {
    "efficiency": ("-", +1),
    "power_loss": ("W", -1),
    "power_loss_sliding": ("W", -1),
    "power_loss_rolling": ("W", -1),
    "dte_rms": ("m", -1),
}
#: Field quantities per point ([M, 2] per position and flank pair) → (unit, sense).
FIELDS = {
    "hertz_pressure": ("Pa", -1),
    "flash_temperature": ("K", -1),
}
#: Every named quantity.
QUANTITIES = {**SCALARS, **FIELDS}

_BLOK = 1.11


def flash_temperature(result, pair):
    """Blok's flash temperature rise ΔT per position and flank pair, K [..., M, 2] (see the module
    docstring); ``result`` a SimulationResult (a batch of them allowed), ``pair`` its GearPair."""
    w = jnp.maximum(result.tooth_force, 0.0) / pair.face_width  # N/m
    p = result.hertz_pressure
    loaded = (w > 0.0) & (p > 0.0)
    half_width = jnp.where(loaded, 2.0 * w / (jnp.pi * jnp.where(loaded, p, 1.0)), 0.0)
    u1 = result.surface_velocity[..., 0]
    u2 = result.surface_velocity[..., 1]
    m1, m2 = pair.materials
    e1 = m1.thermal_conductivity * m1.density * m1.specific_heat
    e2 = m2.thermal_conductivity * m2.density * m2.specific_heat
    conductance = _guarded_sqrt(e1 * jnp.abs(u1)) + _guarded_sqrt(e2 * jnp.abs(u2))
    denominator = _guarded_sqrt(2.0 * half_width) * conductance
    numerator = _BLOK * jnp.abs(result.friction_coefficient) * w * jnp.abs(u1 - u2)
    ok = loaded & (denominator > 0.0)
    return jnp.where(ok, numerator / jnp.where(ok, denominator, 1.0), 0.0)


def quantity(name: str, result, pair):
    """The named quantity of one point (a scalar, or a field [M, 2]); see ``QUANTITIES``."""
    if name in SCALARS:
        return getattr(result, name)
    if name == "hertz_pressure":
        return result.hertz_pressure
    if name == "flash_temperature":
        return flash_temperature(result, pair)
    raise ValueError(f"unknown quantity {name!r}; valid names: {', '.join(QUANTITIES)}")


def peak(name: str, value):
    """A quantity's value as reported per point: the scalar itself, or a field's peak."""
    return jnp.max(value, axis=(-2, -1)) if name in FIELDS else value
