# ruff: noqa: F722  (jaxtyping shape strings)
"""The lubricant: an ``eqx.Module`` of traced property constants with viscosity and density
accessors,
and the presets of REFERENCE §4 (Mil-L-23699 turbine oil, ISO VG 68 mineral gear oil)."""

from __future__ import annotations

import math

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, Float

from .._validation import check_choice, check_positive, check_range, is_concrete
from . import rheology

TEMPERATURE_MODELS = ("walther", "roelands")
VISCOSITY_MODELS = ("roelands", "barus")
T40 = 313.15
T100 = 373.15


class Lubricant(eqx.Module):
    """A Newtonian/Eyring lubricant, SI units. Every property is a traced field (changing a value
    never recompiles); only ``temperature_model`` is static.

    Viscosity at ambient pressure, η0(T) = ν(T) ρ(0, T), with ν(T) from the Walther equation through
    the two kinematic viscosities at 40 and 100 °C (``temperature_model="walther"``), or from the
    Roelands temperature index S0 anchored at ``roelands_reference_temperature``
    (``temperature_model="roelands"``). Pressure dependence: Roelands with index Z, or Barus with
    α(T) = Z (ln η0(T) + 9.67)/p_r (the Roelands initial slope), chosen per call.

    Attributes:
        kinematic_viscosity_40: ν at 40 °C, m²/s.
        kinematic_viscosity_100: ν at 100 °C, m²/s.
        density: ρ at ambient pressure and ``density_temperature``, kg/m³.
        density_temperature: K (15 °C by default).
        thermal_expansion: ε of ρ ∝ 1 − ε (T − T_ref), 1/K.
        roelands_z: Roelands pressure-viscosity index Z.
        roelands_s0: Roelands temperature-viscosity index S0.
        roelands_reference_temperature: T_R where the S0 form is anchored to Walther's η0, K.
        eyring_stress: τ0, Pa.
        thermal_conductivity: kf, W/(m K).
        specific_heat: cf, J/(kg K).
        temperature_model: "walther" or "roelands" (static).
    """

    kinematic_viscosity_40: Float[Array, ""] = eqx.field(converter=jnp.asarray)
    kinematic_viscosity_100: Float[Array, ""] = eqx.field(converter=jnp.asarray)
    density: Float[Array, ""] = eqx.field(converter=jnp.asarray)
    roelands_z: Float[Array, ""] = eqx.field(converter=jnp.asarray)
    roelands_s0: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=1.1)
    roelands_reference_temperature: Float[Array, ""] = eqx.field(
        converter=jnp.asarray, default=363.15
    )
    thermal_expansion: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=7e-4)
    density_temperature: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=288.15)
    eyring_stress: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=5e6)
    thermal_conductivity: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=0.15)
    specific_heat: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=2000.0)
    temperature_model: str = eqx.field(static=True, default="walther")

    def __check_init__(self):
        check_positive("Lubricant.kinematic_viscosity_40", self.kinematic_viscosity_40, "m^2/s")
        check_positive("Lubricant.kinematic_viscosity_100", self.kinematic_viscosity_100, "m^2/s")
        if is_concrete((self.kinematic_viscosity_40, self.kinematic_viscosity_100)):
            nu40 = float(self.kinematic_viscosity_40)
            nu100 = float(self.kinematic_viscosity_100)
            if not nu100 < nu40:
                raise ValueError(
                    f"Lubricant.kinematic_viscosity_100 = {nu100:.6g} m^2/s is out of range; "
                    f"valid range: (0, {nu40:.6g}) m^2/s (below the 40 °C value: viscosity falls "
                    "with temperature)"
                )
            if nu100 * 1e6 < 0.3:
                raise ValueError(
                    f"Lubricant.kinematic_viscosity_100 = {nu100:.6g} m^2/s is out of range; "
                    "valid range: [3e-07, inf) m^2/s (Walther/ASTM D341 validity)"
                )
        check_range("Lubricant.density", self.density, 300.0, 3000.0, unit="kg/m^3")
        check_range(
            "Lubricant.density_temperature", self.density_temperature, 150.0, 600.0, unit="K"
        )
        check_range("Lubricant.thermal_expansion", self.thermal_expansion, 0.0, 5e-3, unit="1/K")
        check_range("Lubricant.roelands_z", self.roelands_z, 0.0, 1.5, low_inclusive=False)
        check_range("Lubricant.roelands_s0", self.roelands_s0, 0.0, 5.0, low_inclusive=False)
        check_range(
            "Lubricant.roelands_reference_temperature",
            self.roelands_reference_temperature,
            200.0,
            600.0,
            unit="K",
        )
        check_positive("Lubricant.eyring_stress", self.eyring_stress, "Pa")
        check_positive("Lubricant.thermal_conductivity", self.thermal_conductivity, "W/(m K)")
        check_positive("Lubricant.specific_heat", self.specific_heat, "J/(kg K)")
        check_choice("Lubricant.temperature_model", self.temperature_model, TEMPERATURE_MODELS)

    # -- temperature dependence at ambient pressure ------------------------------------------------
    def walther_constants(self):
        """(A, B) of log10 log10(ν[cSt] + 0.7) = A − B log10 T[K] (ASTM D341)."""
        return rheology.walther_constants(
            self.kinematic_viscosity_40, T40, self.kinematic_viscosity_100, T100
        )

    def kinematic_viscosity(self, temperature):
        """Walther kinematic viscosity at ambient pressure, m²/s (T in K)."""
        a, b = self.walther_constants()
        return rheology.walther_kinematic_viscosity(temperature, a, b)

    def density_at(self, pressure, temperature, compressible: bool = True):
        """Density ρ(p, T), kg/m³: Dowson-Higginson (``compressible``) with thermal expansion."""
        if compressible:
            return rheology.dowson_higginson_density(
                pressure,
                temperature,
                self.density,
                self.density_temperature,
                self.thermal_expansion,
            )
        return self.density * (
            1.0 - self.thermal_expansion * (temperature - self.density_temperature)
        )

    def _walther_log_viscosity(self, temperature):
        return jnp.log(self.kinematic_viscosity(temperature)) + jnp.log(
            self.density_at(0.0, temperature, compressible=False)
        )

    def log_base_viscosity(self, temperature):
        """ln η0(T), η0 the dynamic viscosity at ambient pressure in Pa s (T in K)."""
        if self.temperature_model == "walther":
            return self._walther_log_viscosity(temperature)
        ln_ref = self._walther_log_viscosity(self.roelands_reference_temperature)
        return rheology.roelands_log_viscosity(
            0.0, temperature, ln_ref, self.roelands_reference_temperature, 1.0, self.roelands_s0
        )

    def base_viscosity(self, temperature):
        """η0(T), dynamic viscosity at ambient pressure, Pa s (T in K)."""
        return jnp.exp(self.log_base_viscosity(temperature))

    # -- pressure dependence ------------------------------------------------------------
    def pressure_viscosity_coefficient(self, temperature):
        """α(T) = d ln η/dp at p = 0, 1/Pa: the Roelands initial slope Z (ln η0(T) + 9.67)/p_r (also
        the Barus coefficient used by ``viscosity_model="barus"``)."""
        return rheology.roelands_pressure_viscosity_coefficient(
            self.log_base_viscosity(temperature), self.roelands_z
        )

    def log_viscosity(self, pressure, temperature, viscosity_model: str = "roelands"):
        """ln η(p, T), η in Pa s (p in Pa, T in K); ``viscosity_model`` "roelands" or "barus"."""
        check_choice("viscosity_model", viscosity_model, VISCOSITY_MODELS)
        # Both temperature models give ln η = ln η0(T) + (ln η0(T) + 9.67)[(1 + p/p_r)^Z − 1]: with
        # Roelands' S0 form, ln η0(T) + 9.67 = (ln η_R + 9.67) ((T − 138)/(T_R − 138))^(−S0).
        ln_eta0 = self.log_base_viscosity(temperature)
        if viscosity_model == "barus":
            alpha = rheology.roelands_pressure_viscosity_coefficient(ln_eta0, self.roelands_z)
            return ln_eta0 + rheology.barus_log_pressure_factor(pressure, alpha)
        return ln_eta0 + rheology.roelands_log_pressure_factor(pressure, ln_eta0, self.roelands_z)

    def viscosity(self, pressure, temperature, viscosity_model: str = "roelands"):
        """Dynamic viscosity η(p, T), Pa s (p in Pa, T in K)."""
        return jnp.exp(self.log_viscosity(pressure, temperature, viscosity_model))


# -- presets (REFERENCE §4) ------------------------------------------------------------
def _np_walther_ln_eta0(nu40, nu100, rho, t_rho, expansion, temperature):
    w1 = math.log10(math.log10(nu40 * 1e6 + 0.7))
    w2 = math.log10(math.log10(nu100 * 1e6 + 0.7))
    b = (w1 - w2) / (math.log10(T100) - math.log10(T40))
    a = w1 + b * math.log10(T40)
    nu = (10.0 ** (10.0 ** (a - b * math.log10(temperature))) - 0.7) * 1e-6
    return math.log(nu * rho * (1.0 - expansion * (temperature - t_rho)))


def lubricant_from_alpha(
    kinematic_viscosity_40: float,
    kinematic_viscosity_100: float,
    density: float,
    alpha: float,
    alpha_temperature: float,
    *,
    thermal_expansion: float = 7e-4,
    density_temperature: float = 288.15,
    eyring_stress: float = 5e6,
    thermal_conductivity: float = 0.15,
    specific_heat: float = 2000.0,
    temperature_model: str = "walther",
) -> Lubricant:
    """Build a Lubricant from handbook data (Python floats, SI): the Roelands Z is set so that the
    pressure-viscosity coefficient at ``alpha_temperature`` (K) equals ``alpha`` (1/Pa), and S0 so
    that
    the Roelands temperature form has Walther's slope d ln η0/dT at that temperature."""
    args = (
        kinematic_viscosity_40,
        kinematic_viscosity_100,
        density,
        density_temperature,
        thermal_expansion,
    )
    ln0 = _np_walther_ln_eta0(*args, alpha_temperature)
    z = alpha * rheology.ROELANDS_PRESSURE / (ln0 - rheology.ROELANDS_LN_ETA_INF)
    dt = 1e-3
    slope = (
        _np_walther_ln_eta0(*args, alpha_temperature + dt)
        - _np_walther_ln_eta0(*args, alpha_temperature - dt)
    ) / (2 * dt)
    s0 = (
        -slope
        * (alpha_temperature - rheology.ROELANDS_T_INF)
        / (ln0 - rheology.ROELANDS_LN_ETA_INF)
    )
    return Lubricant(
        kinematic_viscosity_40=kinematic_viscosity_40,
        kinematic_viscosity_100=kinematic_viscosity_100,
        density=density,
        roelands_z=z,
        roelands_s0=s0,
        roelands_reference_temperature=alpha_temperature,
        thermal_expansion=thermal_expansion,
        density_temperature=density_temperature,
        eyring_stress=eyring_stress,
        thermal_conductivity=thermal_conductivity,
        specific_heat=specific_heat,
        temperature_model=temperature_model,
    )


def mil_l_23699(temperature_model: str = "walther") -> Lubricant:
    """Mil-L-23699 (MIL-PRF-23699) 5 cSt polyol ester turbine oil, the paper's lubricant (REFERENCE
    §4):
    27.6 / 5.1 cSt at 40 / 100 °C, 1004 kg/m³ at 15 °C, expansion 7e-4 1/K, α = 11.3 GPa⁻¹ at 90 °C,
    τ0 = 5 MPa, kf = 0.15 W/(m K), cf = 2000 J/(kg K)."""
    return lubricant_from_alpha(
        27.6e-6,
        5.1e-6,
        1004.0,
        11.3e-9,
        363.15,
        thermal_expansion=7e-4,
        eyring_stress=5e6,
        thermal_conductivity=0.15,
        specific_heat=2000.0,
        temperature_model=temperature_model,
    )


def iso_vg68(temperature_model: str = "walther") -> Lubricant:
    """ISO VG 68 mineral gear oil (REFERENCE §4, typical): 68 / 8.7 cSt at 40 / 100 °C, 880 kg/m³,
    expansion 7e-4 1/K, α = 22 GPa⁻¹ at 40 °C, τ0 = 5 MPa, kf = 0.13 W/(m K), cf = 2000 J/(kg K)."""
    return lubricant_from_alpha(
        68e-6,
        8.7e-6,
        880.0,
        22e-9,
        313.15,
        thermal_expansion=7e-4,
        eyring_stress=5e6,
        thermal_conductivity=0.13,
        specific_heat=2000.0,
        temperature_model=temperature_model,
    )
