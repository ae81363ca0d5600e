"""Elastic and thermal properties of a solid (gear steel)."""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, Float

from . import _inputs
from ._validation import check_positive, check_range, check_shape

_FIELDS = ("youngs_modulus", "poisson_ratio", "density", "thermal_conductivity", "specific_heat")


def _float_array(value) -> Float[Array, "..."]:
    return jnp.asarray(value, dtype=jnp.result_type(float))


class Material(eqx.Module):
    """Isotropic solid, SI units; every field a float64 scalar array.

    Change a field with ``material.replace(youngs_modulus=210e9)`` (validated), not
    ``eqx.tree_at``, which skips the checks (``jaxgear._inputs.validate`` re-runs them).

    Attributes:
        youngs_modulus: E, Pa.
        poisson_ratio: ν, dimensionless, in (-1, 0.5).
        density: ρ, kg/m³.
        thermal_conductivity: k, W/(m K).
        specific_heat: c, J/(kg K).
    """

    youngs_modulus: Float[Array, ""] = eqx.field(converter=_float_array)
    poisson_ratio: Float[Array, ""] = eqx.field(converter=_float_array)
    density: Float[Array, ""] = eqx.field(converter=_float_array)
    thermal_conductivity: Float[Array, ""] = eqx.field(converter=_float_array)
    specific_heat: Float[Array, ""] = eqx.field(converter=_float_array)

    def __check_init__(self):
        for name in _FIELDS:
            check_shape(f"Material.{name}", getattr(self, name), (), "a scalar")
        check_positive("Material.youngs_modulus", self.youngs_modulus, "Pa")
        check_range(
            "Material.poisson_ratio",
            self.poisson_ratio,
            -1.0,
            0.5,
            low_inclusive=False,
            high_inclusive=False,
        )
        check_positive("Material.density", self.density, "kg/m^3")
        check_positive("Material.thermal_conductivity", self.thermal_conductivity, "W/(m K)")
        check_positive("Material.specific_heat", self.specific_heat, "J/(kg K)")

    def replace(self, **changes) -> Material:
        """A validated copy with fields substituted (``jaxgear._inputs.replace``)."""
        try:
            return _inputs.replace(self, **changes)
        except ValueError as err:
            raise ValueError(f"Material.replace({', '.join(changes)}): {err}") from None

    @property
    def thermal_diffusivity(self) -> Float[Array, ""]:
        """κ = k/(ρ c), m²/s."""
        return self.thermal_conductivity / (self.density * self.specific_heat)

    @property
    def plane_strain_modulus(self) -> Float[Array, ""]:
        """E/(1 − ν²), Pa."""
        return self.youngs_modulus / (1.0 - self.poisson_ratio**2)


def reduced_modulus(m1: Material, m2: Material) -> Float[Array, ""]:
    """E' of a contact, defined by 2/E' = (1−ν1²)/E1 + (1−ν2²)/E2 (REFERENCE §8), Pa."""
    return 2.0 / (1.0 / m1.plane_strain_modulus + 1.0 / m2.plane_strain_modulus)


def steel() -> Material:
    """Gear steel (REFERENCE §4): E 207 GPa, ν 0.3, 7850 kg/m³, 46.7 W/(m K), 470 J/(kg K)."""
    return Material(
        youngs_modulus=207e9,
        poisson_ratio=0.3,
        density=7850.0,
        thermal_conductivity=46.7,
        specific_heat=470.0,
    )
