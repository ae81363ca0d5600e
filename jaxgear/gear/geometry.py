"""Involute spur gear geometry: radii, line of action, path of contact, roll angles, curvature,
kinematics and Hertz contact.

Conventions: s is the distance along the line of action (LOA) from T1, gear 1's base-circle tangency
point, towards T2. The roll angle of gear 1 at a contact point is ε1 = s / rb1; gear 2's own roll angle
is ε2 = (T1T2 − s) / rb2. Contact runs from s_start (tip of gear 2 on the LOA, the start of active
profile of gear 1) to s_end (tip of gear 1). Gear 1 drives, turning at ω1 > 0.
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, Float

from .._validation import check_instance
from . import involute as inv
from .pair import GearPair


class GearGeometry(eqx.Module):
    """Derived geometry of a GearPair (m, rad). Per-gear quantities have shape (2,)."""

    base_radius: Float[Array, "2"]
    reference_pitch_radius: Float[Array, "2"]
    pitch_radius: Float[Array, "2"]  # operating pitch radius
    tip_radius: Float[Array, "2"]
    root_radius: Float[Array, "2"]
    centre_distance: Float[Array, ""]
    operating_pressure_angle: Float[Array, ""]
    line_of_action_length: Float[Array, ""]  # T1T2
    base_pitch: Float[Array, ""]
    path_start: Float[Array, ""]  # s at the start of active profile of gear 1
    path_end: Float[Array, ""]  # s at the tip of gear 1
    path_length: Float[Array, ""]
    contact_ratio: Float[Array, ""]
    # roll angles of gear 1, rad
    roll_angle_start: Float[Array, ""]
    roll_angle_lowest_single: Float[Array, ""]
    roll_angle_pitch: Float[Array, ""]
    roll_angle_highest_single: Float[Array, ""]
    roll_angle_end: Float[Array, ""]
    # each gear's own roll angles at its start of active profile and at its tip, rad
    roll_angle_start_active: Float[Array, "2"]
    roll_angle_tip: Float[Array, "2"]

    @property
    def pitch_point(self) -> Float[Array, ""]:
        """s of the pitch point, m."""
        return self.base_radius[0] * jnp.tan(self.operating_pressure_angle)


def gear_geometry(pair: GearPair) -> GearGeometry:
    """Geometry of ``pair`` (differentiable in every traced field; formulas in ``gear/involute.py``)."""
    check_instance("pair", pair, GearPair)
    rb = pair.base_radius
    a_w = pair.centre_distance
    ra = pair.tip_radius
    cos_aw = (rb[0] + rb[1]) / a_w
    alpha_w = inv.operating_pressure_angle(rb, a_w)
    t1t2, s_start, s_end = inv.path_of_contact(rb, ra, a_w)
    pb = inv.base_pitch(rb[0], pair.teeth[0])
    path = s_end - s_start
    eps_sap = jnp.stack([s_start / rb[0], (t1t2 - s_end) / rb[1]])
    return GearGeometry(
        base_radius=rb,
        reference_pitch_radius=pair.reference_radius,
        pitch_radius=rb / cos_aw,
        tip_radius=ra,
        root_radius=pair.root_radius,
        centre_distance=a_w,
        operating_pressure_angle=alpha_w,
        line_of_action_length=t1t2,
        base_pitch=pb,
        path_start=s_start,
        path_end=s_end,
        path_length=path,
        contact_ratio=path / pb,
        roll_angle_start=s_start / rb[0],
        roll_angle_lowest_single=(s_end - pb) / rb[0],
        roll_angle_pitch=jnp.tan(alpha_w),
        roll_angle_highest_single=(s_start + pb) / rb[0],
        roll_angle_end=s_end / rb[0],
        roll_angle_start_active=eps_sap,
        roll_angle_tip=inv.roll_angle(ra, rb),
    )


def contact_position(geo: GearGeometry, mesh_fraction, pair_index):
    """s (m) of tooth pair ``pair_index`` at mesh-cycle fraction τ ∈ [0, 1).

    Pair 0 entered contact at τ = 0 (s = s_start + τ pb); pair k is k base pitches ahead.
    One mesh period is 2π/(z1 ω1) seconds: τ = t z1 ω1 / (2π).
    """
    return geo.path_start + (mesh_fraction + pair_index) * geo.base_pitch


def in_contact(geo: GearGeometry, s):
    """True where the LOA position s lies on the path of contact."""
    return (s >= geo.path_start) & (s <= geo.path_end)


def roll_angles(geo: GearGeometry, s):
    """(ε1, ε2): each gear's own roll angle (rad) at the contact at LOA position s."""
    return s / geo.base_radius[0], (geo.line_of_action_length - s) / geo.base_radius[1]


def position_from_roll_angle(geo: GearGeometry, roll_angle_1):
    """LOA position s (m) of the contact at gear 1's roll angle ε1 (rad)."""
    return roll_angle_1 * geo.base_radius[0]


def mesh_period(pair: GearPair, speed_rpm):
    """Duration of one mesh cycle, s, at gear 1 speed (rpm)."""
    return 60.0 / (speed_rpm * pair.teeth[0])


def radii_of_curvature(geo: GearGeometry, s):
    """(ρ1, ρ2): involute radii of curvature at the contact (m) = the friction moment arms R1, R2."""
    return s, geo.line_of_action_length - s


def reduced_radius(geo: GearGeometry, s):
    """1/R = 1/ρ1 + 1/ρ2, m."""
    r1, r2 = radii_of_curvature(geo, s)
    return r1 * r2 / (r1 + r2)


class Kinematics(eqx.Module):
    """Kinematic surface velocities at a contact (m/s), gear 1 at ω1 rad/s."""

    u1: Array
    u2: Array

    @property
    def rolling_velocity(self):
        """ur = (u1 + u2)/2."""
        return 0.5 * (self.u1 + self.u2)

    @property
    def sliding_velocity(self):
        """us = u1 − u2 (positive where gear 1's surface is faster, beyond the pitch point)."""
        return self.u1 - self.u2

    @property
    def slide_to_roll_ratio(self):
        """SR = us/ur."""
        return self.sliding_velocity / self.rolling_velocity


def kinematics(pair: GearPair, geo: GearGeometry, s, omega1) -> Kinematics:
    """Surface velocities uj = ρj ωj at LOA position s, gear 1 at ω1 (rad/s), ω2 = ω1 z1/z2."""
    rho1, rho2 = radii_of_curvature(geo, s)
    omega2 = omega1 * pair.teeth[0] / pair.teeth[1]
    return Kinematics(u1=rho1 * omega1, u2=rho2 * omega2)


def hertz_half_width(load_per_width, reduced_radius, e_reduced):
    """Line-contact Hertz half-width b = √(8 w' R/(π E')), m (w' in N/m, R in m, E' in Pa)."""
    return jnp.sqrt(8.0 * load_per_width * reduced_radius / (jnp.pi * e_reduced))


def hertz_pressure(load_per_width, reduced_radius, e_reduced):
    """Line-contact maximum Hertz pressure ph = √(w' E'/(2π R)), Pa."""
    return jnp.sqrt(load_per_width * e_reduced / (2.0 * jnp.pi * reduced_radius))


def normal_load(pair: GearPair, torque):
    """Total normal tooth load W = T1/rb1, N (gear 1 torque T1 in N m)."""
    return torque / pair.base_radius[0]
