"""The operating point of a gear pair: torque, speed and oil inlet temperature (SI inside, rpm at the edge)."""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, Float

from ._validation import check_positive, check_range


def _as_float(name):
    def convert(value):
        try:
            return jnp.asarray(value, dtype=jnp.result_type(float))
        except (TypeError, ValueError):
            # e.g. a string from a config file: name the field instead of numpy's bare message
            raise ValueError(
                f"OperatingPoint.{name} = {value!r} is not valid; valid range: a real number"
            ) from None

    return convert


class OperatingPoint(eqx.Module):
    """Where the gear pair runs. All fields are traced, so a new torque or speed never recompiles.

    Attributes:
        torque: input torque T1 on gear 1 (the driver), N m, > 0.
        speed_rpm: speed of gear 1, rpm, > 0 (converted to rad/s once, by ``omega1``).
        inlet_temperature: oil inlet temperature, K, in [200, 600] K.
    """

    torque: Float[Array, ""] = eqx.field(converter=_as_float("torque"))
    speed_rpm: Float[Array, ""] = eqx.field(converter=_as_float("speed_rpm"))
    inlet_temperature: Float[Array, ""] = eqx.field(
        converter=_as_float("inlet_temperature"), default=363.15
    )

    def __check_init__(self):
        check_positive("OperatingPoint.torque", self.torque, "N m")
        check_positive("OperatingPoint.speed_rpm", self.speed_rpm, "rpm")
        check_range(
            "OperatingPoint.inlet_temperature", self.inlet_temperature, 200.0, 600.0, unit="K"
        )

    @property
    def omega1(self) -> Float[Array, ""]:
        """Angular speed of gear 1, rad/s."""
        return self.speed_rpm * (2.0 * jnp.pi / 60.0)
