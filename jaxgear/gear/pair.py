"""The spur gear pair: teeth, basic rack, shifts, blanks, bearings, tip relief (SI units)."""

from __future__ import annotations

import math
from typing import Literal

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from .._validation import (
    check_choice,
    check_finite,
    check_instance,
    check_non_negative,
    check_positive,
    check_range,
    is_concrete,
)
from ..material import Material, steel

ReliefShape = Literal["linear", "parabolic"]
#: Largest tip relief amount, as a fraction of the module (practical reliefs are a few per cent).
MAX_RELIEF_PER_MODULE = 0.1
RELIEF_SHAPES = ("linear", "parabolic")


def _pair(value, name: str) -> Float[Array, "2"]:
    arr = jnp.asarray(value, dtype=float) if is_concrete(value) else jnp.asarray(value)
    if arr.ndim == 0:
        arr = jnp.stack([arr, arr])
    if arr.shape != (2,):
        raise ValueError(
            f"{name} must be a scalar or a pair (gear 1, gear 2); got shape {arr.shape}"
        )
    return arr


class TipRelief(eqx.Module):
    """Tip relief (profile modification at the tip) of both gears.

    The relief of gear j at its own roll angle ε_j (rad; ε_j = distance from gear j's base tangency point
    along the line of action / base radius) is
    ``amount_j · ((ε_j − start_j)/(ε_tip,j − start_j))^p`` for ε_j > start_j, zero below, with p = 1
    (linear) or 2 (parabolic), smoothed at the start for gradients (see ``gear/modification.py``).

    Attributes:
        amount: relief at the tip, per gear, m (shape (2,)).
        start_roll_angle: roll angle of gear j's own profile where relief starts, rad (shape (2,)).
        shape: "linear" or "parabolic", per gear (static).
    """

    amount: Float[Array, "2"]
    start_roll_angle: Float[Array, "2"]
    shape: tuple[str, str] = eqx.field(static=True)

    def __init__(self, amount=0.0, start_roll_angle=0.0, shape: str | tuple[str, str] = "linear"):
        self.amount = _pair(amount, "TipRelief.amount")
        self.start_roll_angle = _pair(start_roll_angle, "TipRelief.start_roll_angle")
        shapes = (shape, shape) if isinstance(shape, str) else tuple(shape)
        if len(shapes) != 2:
            raise ValueError(
                f"TipRelief.shape must be a string or a pair of strings; got {shape!r}"
            )
        for s in shapes:
            check_choice("TipRelief.shape", s, RELIEF_SHAPES)
        self.shape = shapes  # type: ignore[assignment]

    def __check_init__(self):
        check_non_negative("TipRelief.amount", self.amount, "m")
        check_range(
            "TipRelief.start_roll_angle", self.start_roll_angle, 0.0, math.pi / 2, unit="rad"
        )


class Bearings(eqx.Module):
    """Bearing and torsional support of both gears (paper Eq. 1), per gear (shape (2,)).

    Attributes:
        ky, cy: line-of-action (LOA) stiffness N/m and damping N s/m.
        kx, cx: off-line-of-action (OLOA) stiffness N/m and damping N s/m.
        ct: torsional damping, N m s/rad.
    """

    ky: Float[Array, "2"]
    cy: Float[Array, "2"]
    kx: Float[Array, "2"]
    cx: Float[Array, "2"]
    ct: Float[Array, "2"]

    def __init__(self, ky=1.15e9, cy=5360.0, kx=8.0e8, cx=2980.0, ct=10.0):
        # Defaults: the paper's bearings (REFERENCE §2), the same for both gears.
        self.ky = _pair(ky, "Bearings.ky")
        self.cy = _pair(cy, "Bearings.cy")
        self.kx = _pair(kx, "Bearings.kx")
        self.cx = _pair(cx, "Bearings.cx")
        self.ct = _pair(ct, "Bearings.ct")

    def __check_init__(self):
        check_positive("Bearings.ky", self.ky, "N/m")
        check_positive("Bearings.kx", self.kx, "N/m")
        check_non_negative("Bearings.cy", self.cy, "N s/m")
        check_non_negative("Bearings.cx", self.cx, "N s/m")
        check_non_negative("Bearings.ct", self.ct, "N m s/rad")


def involute(angle):
    """inv(α) = tan α − α."""
    return jnp.tan(angle) - angle


def inverse_involute(value, n_iter: int = 30):
    """α with inv(α) = value, 0 ≤ value < ~1, by Newton (d inv/dα = tan² α)."""
    value = jnp.asarray(value)
    alpha = jnp.clip(jnp.cbrt(3.0 * value), 1e-6, 1.5)  # inv α ≈ α³/3 for small α
    for _ in range(n_iter):  # fixed, tiny scalar count: unrolled, exact to round-off
        f = jnp.tan(alpha) - alpha - value
        alpha = jnp.clip(alpha - f / jnp.tan(alpha) ** 2, 1e-9, 1.55)
    return alpha


class GearPair(eqx.Module):
    """An external spur gear pair; gear 1 (the pinion) drives. SI units, radians.

    Physical fields are traced arrays, so changing a value (relief, module, mass...) never recompiles;
    only the tooth numbers and relief shapes are static.

    Args:
        teeth: (z1, z2).
        module: m, metres.
        pressure_angle: reference (basic rack) pressure angle α, rad.
        face_width: b, metres.
        profile_shift: (x1, x2), dimensionless (default 0).
        addendum_coefficient: h_a* of the basic rack (default 1.0).
        dedendum_coefficient: h_f* of the basic rack (default 1.25).
        tip_radius: (ra1, ra2), m (default m(z/2 + h_a* + x)).
        root_radius: (rf1, rf2), m (default m(z/2 − h_f* + x)).
        centre_distance: operating centre distance a_w, m (default: zero-backlash distance from the
            shifts, inv α_w = inv α + 2 tan α (x1 + x2)/(z1 + z2)).
        backlash: total clearance along the line of action 2ℓ, m (default 0).
        material: a Material for both gears or a pair (default steel()).
        blank_mass: (m1, m2), kg (default solid disks of pitch radius and face width).
        blank_inertia: (J1, J2), kg m² (default solid disks, m r²/2).
        bearings: Bearings (default the paper's).
        tip_relief: TipRelief (default none).
        bore_radius: (r_int1, r_int2), m, inner radius of the gear body used by the fillet-foundation
            stiffness (default 0.5 × root radius).
        mesh_damping_ratio: ζ of a viscous mesh damping along the line of action, acting only while
            a flank pair touches (default 0: the paper's model, whose only mesh damping is the EHL
            film's along the common tangent). The damping coefficient is c = 2ζ √(k̄m me), k̄m the
            mean mesh stiffness of the cycle and me = me1 me2/(me1 + me2), mej = Jj/rbj², the
            mesh mode's equivalent mass; the damper acts on the flanks' rate of compression while
            they touch (a Kelvin-Voigt contact). Valid range [0, 1).
    """

    teeth: tuple[int, int] = eqx.field(static=True)
    module: Float[Array, ""]
    pressure_angle: Float[Array, ""]
    face_width: Float[Array, ""]
    profile_shift: Float[Array, "2"]
    addendum_coefficient: Float[Array, ""]
    dedendum_coefficient: Float[Array, ""]
    tip_radius: Float[Array, "2"]
    root_radius: Float[Array, "2"]
    centre_distance: Float[Array, ""]
    backlash: Float[Array, ""]
    materials: tuple[Material, Material]
    blank_mass: Float[Array, "2"]
    blank_inertia: Float[Array, "2"]
    bearings: Bearings
    tip_relief: TipRelief
    bore_radius: Float[Array, "2"]
    mesh_damping_ratio: Float[Array, ""]

    def __init__(
        self,
        teeth: tuple[int, int],
        module,
        pressure_angle,
        face_width,
        *,
        profile_shift=(0.0, 0.0),
        addendum_coefficient=1.0,
        dedendum_coefficient=1.25,
        tip_radius=None,
        root_radius=None,
        centre_distance=None,
        backlash=0.0,
        material: Material | tuple[Material, Material] | None = None,
        blank_mass=None,
        blank_inertia=None,
        bearings: Bearings | None = None,
        tip_relief: TipRelief | None = None,
        bore_radius=None,
        mesh_damping_ratio=0.0,
    ):
        if len(tuple(teeth)) != 2:
            raise ValueError(f"teeth must be a pair (z1, z2); got {teeth!r}")
        for name, z in zip(("teeth[0]", "teeth[1]"), teeth):
            # NaN, strings and fractions would fail in int() with a message naming no field.
            if (
                isinstance(z, bool)
                or not isinstance(z, int | float | np.integer | np.floating)
                or not math.isfinite(z)
                or int(z) != z
            ):
                raise ValueError(f"{name} = {z!r} must be an integer; valid range: [5, 10000]")
            check_range(name, z, 5, 10000)
        z1, z2 = int(teeth[0]), int(teeth[1])
        self.teeth = (z1, z2)
        # Check scalars before they are used in derived defaults.
        check_positive("module", module, "m")
        check_range(
            "pressure_angle",
            pressure_angle,
            0.0,
            math.radians(45.0),
            low_inclusive=False,
            unit="rad",
        )
        check_positive("face_width", face_width, "m")
        self.module = jnp.asarray(module, dtype=float)
        self.pressure_angle = jnp.asarray(pressure_angle, dtype=float)
        self.face_width = jnp.asarray(face_width, dtype=float)
        self.profile_shift = _pair(profile_shift, "profile_shift")
        check_range("profile_shift", self.profile_shift, -1.5, 1.5)
        check_range("addendum_coefficient", addendum_coefficient, 0.0, 2.5, low_inclusive=False)
        check_range("dedendum_coefficient", dedendum_coefficient, 0.0, 3.0, low_inclusive=False)
        self.addendum_coefficient = jnp.asarray(addendum_coefficient, dtype=float)
        self.dedendum_coefficient = jnp.asarray(dedendum_coefficient, dtype=float)

        m = self.module
        z = jnp.asarray([z1, z2], dtype=float)
        x = self.profile_shift
        r_ref = m * z / 2.0
        if tip_radius is None:
            tip_radius = r_ref + m * (self.addendum_coefficient + x)
        if root_radius is None:
            root_radius = r_ref - m * (self.dedendum_coefficient - x)
        self.tip_radius = _pair(tip_radius, "tip_radius")
        self.root_radius = _pair(root_radius, "root_radius")
        check_positive("tip_radius", self.tip_radius, "m")
        check_positive("root_radius", self.root_radius, "m")
        if centre_distance is None:
            alpha = self.pressure_angle
            inv_w = involute(alpha) + 2.0 * jnp.tan(alpha) * (x[0] + x[1]) / (z1 + z2)
            alpha_w = inverse_involute(inv_w)
            centre_distance = m * (z1 + z2) / 2.0 * jnp.cos(alpha) / jnp.cos(alpha_w)
        check_positive("centre_distance", centre_distance, "m")
        self.centre_distance = jnp.asarray(centre_distance, dtype=float)
        check_non_negative("backlash", backlash, "m")
        self.backlash = jnp.asarray(backlash, dtype=float)

        if material is None:
            material = steel()
        if isinstance(material, Material):
            material = (material, material)
        if (
            not isinstance(material, tuple | list)
            or len(material) != 2
            or not all(isinstance(m, Material) for m in material)
        ):
            raise ValueError(
                f"material = {material!r} is not valid; valid: a jaxgear.Material or a pair of them"
            )
        self.materials = tuple(material)

        r_pitch = r_ref
        rho = jnp.stack([mat.density for mat in self.materials])
        if blank_mass is None:
            blank_mass = rho * jnp.pi * r_pitch**2 * self.face_width
        self.blank_mass = _pair(blank_mass, "blank_mass")
        if blank_inertia is None:
            blank_inertia = 0.5 * self.blank_mass * r_pitch**2
        self.blank_inertia = _pair(blank_inertia, "blank_inertia")
        self.bearings = Bearings() if bearings is None else bearings
        check_instance("bearings", self.bearings, Bearings)
        if tip_relief is None:
            tip_relief = TipRelief(amount=0.0, start_roll_angle=_tip_roll_angles(self))
        check_instance("tip_relief", tip_relief, TipRelief)
        self.tip_relief = tip_relief
        if bore_radius is None:
            bore_radius = 0.5 * self.root_radius
        self.bore_radius = _pair(bore_radius, "bore_radius")
        check_range("mesh_damping_ratio", mesh_damping_ratio, 0.0, 1.0, high_inclusive=False)
        self.mesh_damping_ratio = jnp.asarray(mesh_damping_ratio, dtype=float)

    def __check_init__(self):
        check_positive("blank_mass", self.blank_mass, "kg")
        check_positive("blank_inertia", self.blank_inertia, "kg m^2")
        check_positive("bore_radius", self.bore_radius, "m")
        if not is_concrete(self):
            return
        check_finite("GearPair", jnp.concatenate([jnp.ravel(a) for a in _float_leaves(self)]))
        _check_geometry(self)

    @property
    def material(self) -> Material:
        """Material of gear 1 (use ``materials`` for both)."""
        return self.materials[0]

    @property
    def gear_ratio(self) -> float:
        """z2/z1."""
        return self.teeth[1] / self.teeth[0]


def _float_leaves(tree):
    import jax

    return [leaf for leaf in jax.tree_util.tree_leaves(tree) if hasattr(leaf, "dtype")]


def _tip_roll_angles(pair: GearPair) -> Float[Array, "2"]:
    rb = pair.module * jnp.asarray(pair.teeth, dtype=float) / 2.0 * jnp.cos(pair.pressure_angle)
    return jnp.sqrt(pair.tip_radius**2 - rb**2) / rb


def _check_geometry(pair: GearPair) -> None:
    """Checks that need the derived geometry: undercut, tip/root order, contact ratio, relief start."""
    from .geometry import gear_geometry

    z = np.asarray(pair.teeth, dtype=float)
    alpha = float(pair.pressure_angle)
    x = np.asarray(pair.profile_shift)
    ha = float(pair.addendum_coefficient)
    # Generation by a rack: no undercut if z ≥ 2 (h_a* − x)/sin² α (ISO 21771 / textbook).
    z_min = 2.0 * (ha - x) / math.sin(alpha) ** 2
    for j in range(2):
        if z[j] < z_min[j] - 1e-9:
            raise ValueError(
                f"teeth[{j}] = {int(z[j])} undercuts for pressure_angle = {math.degrees(alpha):.3g} deg "
                f"and profile_shift[{j}] = {x[j]:.3g}; valid range: teeth[{j}] >= {math.ceil(z_min[j] - 1e-9)} "
                f"(or increase profile_shift[{j}] to >= {ha - z[j] * math.sin(alpha) ** 2 / 2:.3f})"
            )
    ra = np.asarray(pair.tip_radius)
    rf = np.asarray(pair.root_radius)
    rb = np.asarray(pair.module) * z / 2.0 * math.cos(alpha)
    for j in range(2):
        if not rb[j] < ra[j]:
            raise ValueError(
                f"tip_radius[{j}] = {ra[j]:.6g} m must exceed the base radius {rb[j]:.6g} m; "
                f"valid range: ({rb[j]:.6g}, inf) m"
            )
        if not rf[j] < ra[j]:
            raise ValueError(
                f"root_radius[{j}] = {rf[j]:.6g} m must be below tip_radius[{j}] = {ra[j]:.6g} m"
            )
    bore = np.asarray(pair.bore_radius)
    for j in range(2):
        if not bore[j] < rf[j]:
            raise ValueError(
                f"bore_radius[{j}] = {bore[j]:.6g} m is out of range; valid range: "
                f"(0, {rf[j]:.6g}) m (below the root radius of gear {j + 1})"
            )
    a_w = float(pair.centre_distance)
    if not a_w > rb.sum():
        raise ValueError(
            f"centre_distance = {a_w:.6g} m is out of range; valid range: ({rb.sum():.6g}, inf) m "
            "(it must exceed the sum of the base radii)"
        )
    if not a_w > ra[0] + rf[1] - 1e-12 or not a_w > ra[1] + rf[0] - 1e-12:
        raise ValueError(
            f"centre_distance = {a_w:.6g} m makes a tip cut into the mating root; valid range: "
            f"[{max(ra[0] + rf[1], ra[1] + rf[0]):.6g}, inf) m"
        )
    geo = gear_geometry(pair)
    cr = float(geo.contact_ratio)
    if not 1.0 <= cr < 2.0:
        raise ValueError(
            f"contact ratio = {cr:.4f} (from teeth, module, pressure_angle, tip_radius, centre_distance) "
            "is out of range; valid range: [1, 2) — jaxgear models one or two tooth pairs in contact"
        )
    tr = pair.tip_relief
    start = np.asarray(tr.start_roll_angle)
    amount = np.asarray(tr.amount)
    top = MAX_RELIEF_PER_MODULE * float(pair.module)
    for j in range(2):
        if not amount[j] <= top:
            raise ValueError(
                f"tip_relief.amount[{j}] = {amount[j]:.6g} m is out of range; valid range: "
                f"[0, {top:.6g}] m ({MAX_RELIEF_PER_MODULE:g} x module: deeper is another tooth "
                "form, not a profile modification)"
            )
    lo = np.asarray([geo.roll_angle_start_active[0], geo.roll_angle_start_active[1]])
    hi = np.asarray(geo.roll_angle_tip)
    for j in range(2):
        if amount[j] > 0 and not (lo[j] <= start[j] < hi[j]):
            raise ValueError(
                f"tip_relief.start_roll_angle[{j}] = {math.degrees(start[j]):.4g} deg is outside the path "
                f"of contact of gear {j + 1}; valid range: [{math.degrees(lo[j]):.4g}, "
                f"{math.degrees(hi[j]):.4g}) deg"
            )
