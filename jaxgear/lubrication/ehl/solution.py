# ruff: noqa: F722  (jaxtyping shape strings)
"""What a solve returns: ``EHLSolution``, the film, its temperatures and its losses in SI
units."""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, Bool, Float, Int

from ...results import Status


class EHLSolution(eqx.Module):
    """Result of ``solve_ehl``, SI units, per unit face width where forces or powers.

    Attributes:
        x: node positions, m, (N,) (x = 0 at the Hertz centre, entrainment towards +x).
        p: pressure, Pa (fluid plus asperity). h: film thickness, m; of the statistical film
            the separation of the surfaces' mean planes (negative where they overlap).
        gap: the film that carries the flow, m: the average gap h_T(h) of the statistical film
            (``asperity.average_gap``), h itself otherwise.
        density: ρ, kg/m³. viscosity: η, Pa s (both at the fluid's pressure).
        shear_viscosity: η_s of the shear model's stress (η, η* or τ h/us), Pa s: friction
            τ = η_s us/h.
        temperature: mean film temperature ϕm at the nodes, K (the inlet temperature: isothermal).
        surface_temperature1, surface_temperature2: surface temperatures of gear 1 and 2, K.
        heat_partition: ϑ = Q1/Q, share of the heat conducted into gear 1 (½ isothermal).
        heat_flux: Q of paper Eq. (12), W/m² = heat_flux_sliding (fluid shear) + heat_flux_rolling
            (Poiseuille) + heat_flux_asperity (μb p |us| in contact).
        contact: asperity-contact share at the nodes, 0 … 1: the indicator of a deterministic
            film, the real contact area ratio A_r/A of the statistical film, 0 smooth.
        asperity_pressure: statistical (Greenwood-Tripp) asperity pressure at the nodes, Pa
            (included in p).
        h_min, h_central: minimum and central (x = 0) film, m. h0: film offset, m. p_max: Pa.
        (In the cavitated outlet the gap is partly filled: the shear terms are weighted by the fill
        fraction q/(um ρ h), q the mass flux through x = 0, as in a JFO/Elrod streak model.)
        friction_sliding: Fs = ∫ (1 − A) η_s (u2 − u1)/h dx, N/m (paper Eq. 15, fluid part, A the
            contact share, h the gap; sign of Eq. 15). It includes the boundary friction of
            asperity contact, friction_asperity: ∫ μb p dx over closed nodes (deterministic),
            ∫ μb p_a dx (statistical).
        friction_rolling: Fr = ∫ (h/2) ∂p/∂x dx over the fluid, N/m (paper Eq. 15).
        damping: cm = ∫ η_s/h dx over the fluid, N s/m² (paper Eq. 13 per unit width).
        power_loss: ∫ Q dx, W/m; power_loss_sliding: fluid shear plus asperity friction;
            power_loss_rolling: Poiseuille part; power_loss_asperity: the asperity part alone.
        contact_fraction: share of the Hertz zone |x| ≤ b in asperity contact.
        contact_load: the load on the asperities, N/m: ∫ p dx over contact nodes, ∫ p_a dx
            (statistical) (``contact_load_share``: its share).
        plastic_gap: the gap the yielded surfaces opened where p reached ``EHLModel.hardness``,
            m (included in h; zero without a hardness).
        load_error: (∫ p dx − w')/w'.
        hertz_half_width (m), hertz_pressure (Pa), moes_m, moes_l: scales of the contact;
            moes_film: Moes' central-film estimate for them, m (the reference a warm start scales).
        converged, residual (‖F‖∞ of the fine-grid system), iterations (Newton, all levels).
        thermal_residual: largest change of the film temperature in the last thermal (Picard)
            iteration, K (0 isothermal).
    """

    x: Float[Array, " N"]
    p: Float[Array, " N"]
    h: Float[Array, " N"]
    gap: Float[Array, " N"]
    density: Float[Array, " N"]
    viscosity: Float[Array, " N"]
    shear_viscosity: Float[Array, " N"]
    temperature: Float[Array, " N"]
    surface_temperature1: Float[Array, " N"]
    surface_temperature2: Float[Array, " N"]
    heat_partition: Float[Array, " N"]
    heat_flux: Float[Array, " N"]
    heat_flux_sliding: Float[Array, " N"]
    heat_flux_rolling: Float[Array, " N"]
    heat_flux_asperity: Float[Array, " N"]
    contact: Float[Array, " N"]
    asperity_pressure: Float[Array, " N"]
    h_min: Float[Array, ""]
    h_central: Float[Array, ""]
    h0: Float[Array, ""]
    p_max: Float[Array, ""]
    friction_sliding: Float[Array, ""]
    friction_asperity: Float[Array, ""]
    friction_rolling: Float[Array, ""]
    damping: Float[Array, ""]
    power_loss: Float[Array, ""]
    power_loss_sliding: Float[Array, ""]
    power_loss_rolling: Float[Array, ""]
    power_loss_asperity: Float[Array, ""]
    contact_fraction: Float[Array, ""]
    contact_load: Float[Array, ""]
    plastic_gap: Float[Array, " N"]
    load_error: Float[Array, ""]
    hertz_half_width: Float[Array, ""]
    hertz_pressure: Float[Array, ""]
    moes_m: Float[Array, ""]
    moes_l: Float[Array, ""]
    moes_film: Float[Array, ""]
    converged: Bool[Array, ""]
    residual: Float[Array, ""]
    iterations: Int[Array, ""]
    thermal_residual: Float[Array, ""]

    @property
    def status(self) -> Int[Array, "..."]:
        """``jaxgear.results.Status``: 0 (OK) converged, 3 (CONTACT) not."""
        return jnp.where(self.converged, Status.OK, Status.CONTACT).astype(jnp.int32)

    @property
    def temperatures(self):
        """(film mean, surface 1, surface 2) temperatures at the nodes, K, shape (3, N); (K, 3, N)
        for a batch of K solutions."""
        temps = [self.temperature, self.surface_temperature1, self.surface_temperature2]
        return jnp.stack(temps, axis=-2)

    @property
    def fluid_pressure(self):
        """Pressure carried by the fluid, Pa (p minus the statistical asperity pressure)."""
        return self.p - self.asperity_pressure

    @property
    def contact_load_share(self):
        """Share of the load carried by asperity contact (per solution of a batch, e.g. the steps
        of a passage: the node axis is the last)."""
        load = jnp.sum(self.p, axis=-1) * (self.x[..., 1] - self.x[..., 0])
        return self.contact_load / jnp.maximum(load, 1e-300)

    @property
    def rho_h(self):
        """ρ h at the nodes, kg/m², h the film that carries the flow (``gap``): the
        previous-step input of a transient solve."""
        return self.density * self.gap
