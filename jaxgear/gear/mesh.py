"""The mesh cycle: everything the dynamics and the EHL contacts need over one mesh period."""

from __future__ import annotations

import equinox as eqx
from jaxtyping import Array, Float


class MeshCycle(eqx.Module):
    """Quasi-static mesh quantities at M equally spaced positions τ_i = i/M of one mesh period.

    Pair slot 0 is the pair that entered contact at τ = 0 (LOA position s = s_start + τ pb); slot 1 is
    one base pitch ahead (in contact while s ≤ s_end). One tooth pair's whole engagement is slot 0's
    trajectory followed by slot 1's. Out-of-contact entries carry zero load and stiffness.

    Attributes (SI):
        mesh_fraction: τ, shape [M].
        roll_angle: gear 1 roll angle of pair slot 0, rad, [M].
        contact_position: s of each slot, m, [M, 2].
        in_contact: 1.0 where the slot's contact lies on the path of contact, else 0.0, [M, 2].
        radius_of_curvature: ρ of [position, pair, gear], m (the friction moment arms R1, R2), [M, 2, 2].
        reduced_radius: R = ρ1ρ2/(ρ1+ρ2), m, [M, 2].
        pair_stiffness: tooth-pair stiffness along the LOA, N/m, [M, 2] (0 out of contact).
        mesh_stiffness: km = stiffness of the pairs that carry load (smooth), N/m, [M].
        static_te: loaded static transmission error along the LOA (composite deflection plus relief
            separation), m, [M].
        te_excitation: e(t) with km (static_te − e) = W: the displacement excitation the dynamics
            subtracts from r1θ1 + y1 − r2θ2 − y2 (paper Eq. 1's εs), m, [M].
        load_share: share of the total normal load per pair, rows sum to 1, [M, 2].
        normal_load: quasi-static tooth force W_sT per pair, N, [M, 2].
        hertz_pressure: maximum Hertz pressure per pair, Pa, [M, 2] (0 out of contact).
        hertz_half_width: Hertz half-width per pair, m, [M, 2].
        torque: gear 1 torque, N m.
        total_load: W = T1/rb1, N.
    """

    mesh_fraction: Float[Array, " M"]
    roll_angle: Float[Array, " M"]
    contact_position: Float[Array, "M 2"]
    in_contact: Float[Array, "M 2"]
    radius_of_curvature: Float[Array, "M 2 2"]
    reduced_radius: Float[Array, "M 2"]
    pair_stiffness: Float[Array, "M 2"]
    mesh_stiffness: Float[Array, " M"]
    static_te: Float[Array, " M"]
    te_excitation: Float[Array, " M"]
    load_share: Float[Array, "M 2"]
    normal_load: Float[Array, "M 2"]
    hertz_pressure: Float[Array, "M 2"]
    hertz_half_width: Float[Array, "M 2"]
    torque: Float[Array, ""]
    total_load: Float[Array, ""]

    @property
    def n_positions(self) -> int:
        return self.mesh_fraction.shape[0]
