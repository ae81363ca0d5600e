"""Tip relief as design variables: substituting them into a pair (traceable) and their bounds."""

from __future__ import annotations

import math

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from ..gear.geometry import gear_geometry
from ..gear.pair import GearPair

DEFAULT_RELIEF_AMOUNT_BOUNDS = (0.0, 50e-6)  # m
DEFAULT_START_MARGIN = 0.05  # fraction of each gear's roll-angle range kept clear at both ends


def with_tip_relief(pair: GearPair, x, both_gears: bool) -> GearPair:
    """``pair`` with relief parameters x substituted (traceable).

    x = (amount m, start rad) for both gears, or (amount₁, amount₂, start₁, start₂) per gear."""
    x = jnp.asarray(x)
    if both_gears:
        amount, start = jnp.stack([x[0], x[0]]), jnp.stack([x[1], x[1]])
    else:
        amount, start = x[0:2], x[2:4]
    return eqx.tree_at(
        lambda p: (p.tip_relief.amount, p.tip_relief.start_roll_angle), pair, (amount, start)
    )


def _pair_bounds(name, value, n_gears):
    """(lo, hi) or per gear ((lo1, hi1), (lo2, hi2)) → arrays lo[2], hi[2]."""
    arr = np.asarray(value, dtype=float)
    if arr.shape == (2,):
        arr = np.stack([arr, arr])
    if arr.shape != (2, 2):
        raise ValueError(
            f"bounds[{name!r}] = {value!r} must be (lower, upper) or per gear "
            "((lower₁, upper₁), (lower₂, upper₂))"
        )
    return arr[:, 0], arr[:, 1]


def tip_relief_bounds(pair: GearPair, bounds: dict | None = None, margin=DEFAULT_START_MARGIN):
    """Validated bounds of relief amount (m) and start roll angle (rad), per gear (arrays [2]).

    Defaults: amount in [0, 50 µm]; start inside each gear's own path of contact (from its start of
    active profile to its tip) less ``margin`` × that range at both ends (the relief must have a
    length). Given start bounds must lie inside the gear's path of contact."""
    bounds = {} if bounds is None else dict(bounds)
    unknown = set(bounds) - {"amount", "start_roll_angle"}
    if unknown:
        raise ValueError(
            f"unknown bounds key(s) {sorted(unknown)}; valid keys: 'amount', 'start_roll_angle'"
        )
    geo = gear_geometry(pair)
    sap = np.asarray(geo.roll_angle_start_active, dtype=float)
    tip = np.asarray(geo.roll_angle_tip, dtype=float)
    a_lo, a_hi = _pair_bounds("amount", bounds.get("amount", DEFAULT_RELIEF_AMOUNT_BOUNDS), 2)
    span = tip - sap
    default_start = np.stack([sap + margin * span, tip - margin * span], axis=1)
    s_lo, s_hi = _pair_bounds("start_roll_angle", bounds.get("start_roll_angle", default_start), 2)
    for j in range(2):
        if not (np.isfinite(a_lo[j]) and np.isfinite(a_hi[j])) or not 0.0 <= a_lo[j] < a_hi[j]:
            raise ValueError(
                f"bounds['amount'] of gear {j + 1} = ({a_lo[j]:g}, {a_hi[j]:g}) m is invalid; "
                "valid: 0 <= lower < upper, finite"
            )
        if not (np.isfinite(s_lo[j]) and np.isfinite(s_hi[j])) or not s_lo[j] < s_hi[j]:
            raise ValueError(
                f"bounds['start_roll_angle'] of gear {j + 1} = ({s_lo[j]:g}, {s_hi[j]:g}) rad is "
                "invalid; valid: finite lower < upper"
            )
        if s_lo[j] < sap[j] or s_hi[j] >= tip[j]:
            raise ValueError(
                f"bounds['start_roll_angle'] of gear {j + 1} = ({math.degrees(s_lo[j]):.4g}, "
                f"{math.degrees(s_hi[j]):.4g}) deg is outside the path of contact of gear {j + 1}; "
                f"valid range: [{math.degrees(sap[j]):.4g}, {math.degrees(tip[j]):.4g}) deg"
            )
    return (a_lo, a_hi), (s_lo, s_hi)
