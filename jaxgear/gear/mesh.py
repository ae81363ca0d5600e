"""The mesh cycle: everything the dynamics and the EHL contacts need over one mesh period."""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, Float

from .._inputs import canonical
from .._validation import check_instance, check_positive, check_range
from ..material import reduced_modulus
from .geometry import GearGeometry, gear_geometry, normal_load, radii_of_curvature
from .involute import involute, reference_tooth_thickness
from .load_sharing import DEFAULT_CONTACT_SMOOTHING, share_load
from .modification import DEFAULT_RELIEF_SMOOTHING, relief_separation
from .pair import GearPair
from .stiffness import STIFFNESS_METHODS, pair_stiffness

#: Tip edge rounding, as a fraction of the base pitch (``mesh_cycle``'s ``edge_width``).
DEFAULT_EDGE_WIDTH = 0.01


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


def _safe_sqrt(x):
    positive = x > 0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, x, 1.0)), 0.0)


def contact_weight(geo: GearGeometry, s, edge_width: float):
    """Smooth contact flag (0 … 1) of a contact at LOA position s.

    The weight rises from 0 to 1 over ``edge_width`` base pitches at each end of the path of
    contact: a model of the tip edge rounding, which makes the mesh stiffness and static TE continuous
    in time (a sharp-cornered tooth gives step changes). With edge_width = 0 it is the hard flag.
    """
    if edge_width == 0.0:
        return ((s >= geo.path_start) & (s <= geo.path_end)).astype(jnp.result_type(float))
    width = edge_width * geo.base_pitch
    t_in = (s - geo.path_start) / width
    t_out = (geo.path_end - s) / width
    return _smoothstep(t_in) * _smoothstep(t_out)


def _smoothstep(t):
    t = jnp.clip(t, 0.0, 1.0)
    return t * t * t * (t * (6.0 * t - 15.0) + 10.0)  # C² quintic


def mesh_cycle(
    pair: GearPair,
    torque,
    n_positions: int = 64,
    *,
    stiffness: str = "potential_energy",
    edge_width: float = DEFAULT_EDGE_WIDTH,
    relief_smoothing: float = DEFAULT_RELIEF_SMOOTHING,
    contact_smoothing: float = DEFAULT_CONTACT_SMOOTHING,
) -> MeshCycle:
    """Quasi-static mesh quantities over one mesh period (see ``MeshCycle``).

    Args:
        pair: the gear pair.
        torque: gear 1 torque T1, N m (traced).
        n_positions: M, positions per mesh cycle (static).
        stiffness: "potential_energy" (default) or "iso" (ISO 6336 constant single stiffness).
        edge_width: tip edge rounding as a fraction of the base pitch over which a contact's weight rises
            from 0 to 1 at each end of the path (0 = sharp tooth corners, step changes in km).
        relief_smoothing: corner width of the tip relief start (fraction of the relief length).
        contact_smoothing: width of the first-touch smoothing of the load sharing, m.

    Returns:
        MeshCycle with arrays of shape [M] or [M, 2] (pair slots) as documented there.
    """
    return _mesh_cycle(
        *_checked(
            pair, torque, n_positions, stiffness, edge_width, relief_smoothing, contact_smoothing
        )
    )


def _checked(pair, torque, n_positions, stiffness, edge_width, relief_smoothing, contact_smoothing):
    """``mesh_cycle``'s arguments validated (errors name the field, value and range) and
    normalised for the compiled functions."""
    if isinstance(n_positions, bool) or not isinstance(n_positions, int) or n_positions < 4:
        raise ValueError(
            f"n_positions = {n_positions!r} is out of range; valid range: integer >= 4"
        )
    check_instance("pair", pair, GearPair)
    check_positive("torque", torque, "N m")
    if jnp.ndim(jnp.asarray(torque)) != 0:
        raise ValueError(
            f"torque has shape {jnp.shape(jnp.asarray(torque))}; valid: a scalar, N m (vmap for "
            "many torques)"
        )
    check_range("edge_width", edge_width, 0.0, 0.25)
    # Both smoothing widths divide their argument: zero or negative gives NaN, not a sharp corner.
    check_range("relief_smoothing", relief_smoothing, 0.0, 1.0, low_inclusive=False)
    check_range("contact_smoothing", contact_smoothing, 0.0, 1e-5, low_inclusive=False, unit="m")
    if stiffness not in STIFFNESS_METHODS:
        raise ValueError(
            f"stiffness = {stiffness!r} is not valid; valid choices: {STIFFNESS_METHODS}"
        )
    # float leaves become strong float64 arrays: one compiled cycle whatever the caller passed
    pair = canonical(pair)
    return (
        pair,
        jnp.asarray(torque, dtype=pair.module.dtype),
        n_positions,
        stiffness,
        float(edge_width),
        float(relief_smoothing),
        float(contact_smoothing),
    )


@eqx.filter_jit
def _mesh_cycle(
    pair, torque, n_positions, stiffness, edge_width, relief_smoothing, contact_smoothing
) -> MeshCycle:
    tau = jnp.arange(n_positions) / n_positions
    return _mesh_at(
        pair, torque, tau, tau, stiffness, edge_width, relief_smoothing, contact_smoothing
    )


def back_flank_phase(pair: GearPair, tau):
    """The drive-flank phase whose contacts stand where the back flanks' do at drive phase ``tau``.

    The back flanks of symmetric involute teeth touch on the other line of action (LOA2, the mirror
    image of LOA1 in the line of centres), and the mirror image of their mesh is a drive-flank mesh
    run backwards: a back contact at distance s′ from gear 1's base tangent point on LOA2 has the
    radii of curvature, load sharing and sliding of a drive contact at s = s′, and moves towards
    the start of the path as the gears turn on. For one tooth of gear 1 the two flanks' contacts
    satisfy s + s′ = rb1 (2 α_w + 2 inv α + s_ref1/r_ref1) (the tooth's thickness s_ref1 =
    m (π/2 + 2 x1 tan α) at its reference radius, in angle, plus each involute's roll from the
    reference circle to the working pitch circle), so modulo the base pitch pb the back contacts at
    phase τ are the drive contacts at phase τ′ = frac(c − τ), c = (s + s′ − 2 s_start)/pb. The
    clearance is left out: the teeth are thinned by the backlash and turn through it before the
    back flanks touch, which moves s′ by at most the clearance 2ℓ along the line (0.14 mm against
    pb = 8.86 mm for the paper's pair). Tested against the tooth thickness of an involute built
    through both contact points (tests/gear/test_back_flanks.py)."""
    geo = gear_geometry(pair)
    alpha, alpha_w = pair.pressure_angle, geo.operating_pressure_angle
    rb1, r_ref1 = geo.base_radius[0], geo.reference_pitch_radius[0]
    thickness = reference_tooth_thickness(pair.module, alpha, pair.profile_shift[0])
    both = rb1 * (2.0 * alpha_w + 2.0 * involute(alpha) + thickness / r_ref1)
    c = (both - 2.0 * geo.path_start) / geo.base_pitch
    return jnp.mod(c - tau, 1.0)


def back_flank_mesh(
    pair: GearPair,
    torque,
    n_positions: int = 64,
    *,
    stiffness: str = "potential_energy",
    edge_width: float = DEFAULT_EDGE_WIDTH,
    relief_smoothing: float = DEFAULT_RELIEF_SMOOTHING,
    contact_smoothing: float = DEFAULT_CONTACT_SMOOTHING,
) -> MeshCycle:
    """The back flanks' mesh at the drive cycle's M positions τ_i = i/M (``back_flank_phase``).

    Where rattling teeth cross the backlash the back flanks carry the mesh force; this gives their
    contacts' positions (along LOA2, from gear 1's base tangent point there), radii of curvature,
    quasi-static load shares (tip relief and stiffness as on the drive flanks: symmetric teeth) and
    Hertz fields, row i at the same instant as the drive cycle's row i. ``mesh_fraction`` is the
    drive cycle's τ; the slots are those of the drive mesh at phase τ′ (slot 0 entered contact at
    phase 0 of that cycle). Arguments as ``mesh_cycle``."""
    pair, torque, m, *options = _checked(
        pair, torque, n_positions, stiffness, edge_width, relief_smoothing, contact_smoothing
    )
    return _back_mesh(pair, torque, jnp.arange(m) / m, *options)


@eqx.filter_jit
def _back_mesh(pair, torque, tau, stiffness, edge_width, relief_smoothing, contact_smoothing):
    phase = back_flank_phase(pair, tau)
    return _mesh_at(
        pair, torque, tau, phase, stiffness, edge_width, relief_smoothing, contact_smoothing
    )


def _mesh_at(
    pair, torque, tau, phase, stiffness, edge_width, relief_smoothing, contact_smoothing
) -> MeshCycle:
    """The mesh quantities of the drive-flank contacts at phases ``phase`` [M], reported at
    ``mesh_fraction`` = ``tau``."""
    geo = gear_geometry(pair)
    slots = jnp.arange(2)
    s = geo.path_start + (phase[:, None] + slots[None, :]) * geo.base_pitch  # [M, 2]
    weight = contact_weight(geo, s, edge_width)
    inside = (s >= geo.path_start) & (s <= geo.path_end)
    # Evaluate stiffness and relief at a clipped position so out-of-path slots stay finite.
    s_eval = jnp.clip(s, geo.path_start, geo.path_end)
    k = pair_stiffness(pair, geo, s_eval, stiffness)
    e = relief_separation(pair, geo, s_eval, relief_smoothing)
    total = normal_load(pair, torque)
    d, loads, km = jax.vmap(share_load, in_axes=(0, 0, 0, None, None))(
        k, e, weight, total, contact_smoothing
    )
    rho1, rho2 = radii_of_curvature(geo, s_eval)
    rho = jnp.stack([rho1, rho2], axis=-1)
    r_red = rho1 * rho2 / (rho1 + rho2)
    e_red = reduced_modulus(*pair.materials)
    w_per_width = loads / pair.face_width
    ph = _safe_sqrt(w_per_width * e_red / (2.0 * jnp.pi * r_red))
    b = _safe_sqrt(8.0 * w_per_width * r_red / (jnp.pi * e_red))
    return MeshCycle(
        mesh_fraction=tau,
        roll_angle=s[:, 0] / geo.base_radius[0],
        contact_position=s,
        in_contact=inside.astype(tau.dtype),
        radius_of_curvature=rho,
        reduced_radius=r_red,
        pair_stiffness=k * weight,
        mesh_stiffness=km,
        static_te=d,
        te_excitation=d - total / km,
        load_share=loads / total,
        normal_load=loads,
        hertz_pressure=ph,
        hertz_half_width=b,
        torque=jnp.asarray(torque, dtype=tau.dtype),
        total_load=total,
    )
