"""The spur gear pair: teeth, basic rack, shifts, blanks, bearings, tip relief (SI units)."""

from __future__ import annotations

import math
from typing import Any, Literal

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from .. import _inputs
from .._validation import (
    check_choice,
    check_finite,
    check_instance,
    check_non_negative,
    check_positive,
    check_range,
    check_shape,
    is_concrete,
)
from ..material import Material, steel
from . import involute as inv

ReliefShape = Literal["linear", "parabolic"]
#: Largest tip relief amount, as a fraction of the module (practical reliefs are a few per cent).
MAX_RELIEF_PER_MODULE = 0.1
RELIEF_SHAPES = ("linear", "parabolic")
#: Quantities of a GearPair derived from its other fields unless given at construction.
DERIVED_QUANTITIES = (
    "tip_radius",
    "root_radius",
    "centre_distance",
    "blank_mass",
    "blank_inertia",
    "bore_radius",
)
_PER_GEAR = "one value per gear"
_DERIVED_SHAPES = {
    "tip_radius": (2,),
    "root_radius": (2,),
    "centre_distance": (),
    "blank_mass": (2,),
    "blank_inertia": (2,),
    "bore_radius": (2,),
}


def _float_array(value) -> Float[Array, "..."]:
    """The float fields' converter: a float64 array (the default float dtype) whatever was passed."""
    return jnp.asarray(value, dtype=jnp.result_type(float))


def _pair(value, name: str) -> Float[Array, "2"]:
    """A per-gear value as an array of shape (2,): a scalar is used for both gears."""
    arr = _float_array(value)
    if arr.ndim == 0:
        arr = jnp.stack([arr, arr])
    if arr.shape != (2,):
        raise ValueError(
            f"{name} must be a scalar or a pair (gear 1, gear 2); got shape {arr.shape}"
        )
    return arr


def _checked_replace(obj, changes: dict[str, Any]):
    """``_inputs.replace`` whose errors also say which substitution was rejected."""
    try:
        return _inputs.replace(obj, **changes)
    except ValueError as err:
        raise ValueError(f"{type(obj).__name__}.replace({', '.join(changes)}): {err}") from None


class TipRelief(eqx.Module):
    """Tip relief (profile modification at the tip) of both gears.

    The relief of gear j at its own roll angle ε_j (rad; ε_j = distance from gear j's base tangency point
    along the line of action / base radius) is
    ``amount_j · ((ε_j − start_j)/(ε_tip,j − start_j))^p`` for ε_j > start_j, zero below, with p = 1
    (linear) or 2 (parabolic), smoothed at the start for gradients (see ``gear/modification.py``).

    Change a field with ``relief.replace(amount=5e-6)`` (validated; a scalar is used for both
    gears), not ``eqx.tree_at``, which skips the checks (``jaxgear._inputs.validate`` re-runs them).

    Attributes:
        amount: relief at the tip, per gear, m (shape (2,), float64; default 0).
        start_roll_angle: roll angle of gear j's own profile where relief starts, rad (shape (2,),
            float64; default 0).
        shape: "linear" or "parabolic", per gear (static; default "linear").
    """

    amount: Float[Array, "2"] = eqx.field(converter=_float_array)
    start_roll_angle: Float[Array, "2"] = eqx.field(converter=_float_array)
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
        check_shape("TipRelief.amount", self.amount, (2,), _PER_GEAR)
        check_shape("TipRelief.start_roll_angle", self.start_roll_angle, (2,), _PER_GEAR)
        check_non_negative("TipRelief.amount", self.amount, "m")
        check_range(
            "TipRelief.start_roll_angle", self.start_roll_angle, 0.0, math.pi / 2, unit="rad"
        )

    def replace(self, **changes) -> TipRelief:
        """A validated copy with fields substituted (``jaxgear._inputs.replace``); ``shape`` too."""
        relief = self
        if "shape" in changes:
            relief = TipRelief(self.amount, self.start_roll_angle, changes.pop("shape"))
        return _checked_replace(relief, changes)


class Bearings(eqx.Module):
    """Bearing and torsional support of both gears (paper Eq. 1), per gear (shape (2,), float64).

    Change a field with ``bearings.replace(ky=1e9)`` (validated; a scalar is used for both gears).

    Attributes:
        ky, cy: line-of-action (LOA) stiffness N/m and damping N s/m (default 1.15e9, 5360).
        kx, cx: off-line-of-action (OLOA) stiffness N/m and damping N s/m (default 8.0e8, 2980).
        ct: torsional damping, N m s/rad (default 10).
    """

    ky: Float[Array, "2"] = eqx.field(converter=_float_array)
    cy: Float[Array, "2"] = eqx.field(converter=_float_array)
    kx: Float[Array, "2"] = eqx.field(converter=_float_array)
    cx: Float[Array, "2"] = eqx.field(converter=_float_array)
    ct: Float[Array, "2"] = eqx.field(converter=_float_array)

    def __init__(self, ky=1.15e9, cy=5360.0, kx=8.0e8, cx=2980.0, ct=10.0):
        # Defaults: the paper's bearings (REFERENCE §2), the same for both gears.
        self.ky = _pair(ky, "Bearings.ky")
        self.cy = _pair(cy, "Bearings.cy")
        self.kx = _pair(kx, "Bearings.kx")
        self.cx = _pair(cx, "Bearings.cx")
        self.ct = _pair(ct, "Bearings.ct")

    def __check_init__(self):
        for name in ("ky", "cy", "kx", "cx", "ct"):
            check_shape(f"Bearings.{name}", getattr(self, name), (2,), _PER_GEAR)
        check_positive("Bearings.ky", self.ky, "N/m")
        check_positive("Bearings.kx", self.kx, "N/m")
        check_non_negative("Bearings.cy", self.cy, "N s/m")
        check_non_negative("Bearings.cx", self.cx, "N s/m")
        check_non_negative("Bearings.ct", self.ct, "N m s/rad")

    def replace(self, **changes) -> Bearings:
        """A validated copy with fields substituted (``jaxgear._inputs.replace``)."""
        return _checked_replace(self, changes)


class GearPair(eqx.Module):
    """An external spur gear pair; gear 1 (the pinion) drives. SI units, radians.

    Physical fields are traced float64 arrays, so changing a value (relief, module, mass...) never
    recompiles; only the tooth numbers, relief shapes and the names of the overridden quantities are
    static.

    The tip and root radii, the centre distance, the blanks' mass and inertia and the bore radius
    are derived from the other fields where they are used (properties), unless given at
    construction: then that value is kept whatever else changes. The names of the given ones are
    the static ``overrides``; their values are the always-present fields ``<name>_override`` (zero
    and unused for a derived quantity). So substituting the module, by ``replace`` or by a raw
    ``eqx.tree_at``, gives a consistent pair with finite derivatives.

    Change fields with ``pair.replace(module=2.5e-3)``, ``pair.replace(tip_radius=0.077)`` (an
    override; ``None`` derives it again) or ``pair.replace(**{"tip_relief.amount": 5e-6})``: the
    copy is validated like a constructed pair and a scalar is used for both gears of a per-gear
    field. ``eqx.tree_at`` skips the checks (``jaxgear._inputs.validate`` re-runs them).

    Args:
        teeth: (z1, z2), integers in [5, 10000].
        module: m, metres.
        pressure_angle: reference (basic rack) pressure angle α, rad, in (0, 45°].
        face_width: b, metres.
        profile_shift: (x1, x2), dimensionless, in [−1.5, 1.5] (default 0).
        addendum_coefficient: h_a* of the basic rack, in (0, 2.5] (default 1.0).
        dedendum_coefficient: h_f* of the basic rack, in (0, 3] (default 1.25).
        tip_radius: (ra1, ra2), m (default derived: m(z/2 + h_a* + x)).
        root_radius: (rf1, rf2), m (default derived: m(z/2 − h_f* + x)).
        centre_distance: operating centre distance a_w, m (default derived: the zero-backlash
            distance from the shifts, inv α_w = inv α + 2 tan α (x1 + x2)/(z1 + z2),
            a_w = m (z1 + z2)/2 · cos α/cos α_w).
        backlash: total clearance along the line of action 2ℓ, m (default 0).
        material: a Material for both gears or a pair (default steel()).
        blank_mass: (m1, m2), kg (default derived: solid disks of reference radius and face width,
            ρ π r² b).
        blank_inertia: (J1, J2), kg m² (default derived: solid disks, blank_mass · r²/2).
        bearings: Bearings (default the paper's).
        tip_relief: TipRelief (default none: zero amount, starting at the tips).
        bore_radius: (r_int1, r_int2), m, inner radius of the gear body used by the fillet-foundation
            stiffness (default derived: 0.5 × root radius).
        mesh_damping_ratio: ζ of a viscous mesh damping along the line of action, acting only while
            a flank pair touches (default 0: the paper's model, whose only mesh damping is the EHL
            film's along the common tangent). The damping coefficient is c = 2ζ √(k̄m me), k̄m the
            mean mesh stiffness of the cycle and me = me1 me2/(me1 + me2), mej = Jj/rbj², the
            mesh mode's equivalent mass; the damper acts on the flanks' rate of compression while
            they touch (a Kelvin-Voigt contact). Valid range [0, 1).

    References: ISO 21771 (geometry), ISO 53 (basic rack).
    """

    teeth: tuple[int, int] = eqx.field(static=True)
    module: Float[Array, ""] = eqx.field(converter=_float_array)
    pressure_angle: Float[Array, ""] = eqx.field(converter=_float_array)
    face_width: Float[Array, ""] = eqx.field(converter=_float_array)
    profile_shift: Float[Array, "2"] = eqx.field(converter=_float_array)
    addendum_coefficient: Float[Array, ""] = eqx.field(converter=_float_array)
    dedendum_coefficient: Float[Array, ""] = eqx.field(converter=_float_array)
    backlash: Float[Array, ""] = eqx.field(converter=_float_array)
    materials: tuple[Material, Material] = eqx.field(converter=tuple)
    bearings: Bearings
    tip_relief: TipRelief
    mesh_damping_ratio: Float[Array, ""] = eqx.field(converter=_float_array)
    overrides: tuple[str, ...] = eqx.field(static=True)
    tip_radius_override: Float[Array, "2"] = eqx.field(converter=_float_array)
    root_radius_override: Float[Array, "2"] = eqx.field(converter=_float_array)
    centre_distance_override: Float[Array, ""] = eqx.field(converter=_float_array)
    blank_mass_override: Float[Array, "2"] = eqx.field(converter=_float_array)
    blank_inertia_override: Float[Array, "2"] = eqx.field(converter=_float_array)
    bore_radius_override: Float[Array, "2"] = eqx.field(converter=_float_array)

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
        self.teeth = (int(teeth[0]), int(teeth[1]))
        self.module = _float_array(module)
        self.pressure_angle = _float_array(pressure_angle)
        self.face_width = _float_array(face_width)
        self.profile_shift = _pair(profile_shift, "profile_shift")
        self.addendum_coefficient = _float_array(addendum_coefficient)
        self.dedendum_coefficient = _float_array(dedendum_coefficient)
        self.backlash = _float_array(backlash)
        self.mesh_damping_ratio = _float_array(mesh_damping_ratio)

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
        self.bearings = Bearings() if bearings is None else bearings
        check_instance("bearings", self.bearings, Bearings)

        given = dict(
            tip_radius=tip_radius,
            root_radius=root_radius,
            centre_distance=centre_distance,
            blank_mass=blank_mass,
            blank_inertia=blank_inertia,
            bore_radius=bore_radius,
        )
        self.overrides = tuple(name for name in DERIVED_QUANTITIES if given[name] is not None)
        for name in DERIVED_QUANTITIES:
            value = given[name]
            shape = _DERIVED_SHAPES[name]
            if value is None:
                value = jnp.zeros(shape)
            elif shape == (2,):
                value = _pair(value, name)
            setattr(self, f"{name}_override", _float_array(value))

        # Ranges first: the default relief below is computed from these fields.
        self._check_scalars()
        if tip_relief is None:
            # No relief: zero amount, starting at the tips (where a relief of any amount is zero).
            tip_relief = TipRelief(amount=0.0, start_roll_angle=_tip_roll_angles(self))
        check_instance("tip_relief", tip_relief, TipRelief)
        self.tip_relief = tip_relief

    def __check_init__(self):
        self._check_shapes()
        self._check_scalars()
        check_positive("blank_mass", self.blank_mass, "kg")
        check_positive("blank_inertia", self.blank_inertia, "kg m^2")
        check_positive("bore_radius", self.bore_radius, "m")
        if not is_concrete(self):
            return
        leaves = [leaf for leaf in jax.tree_util.tree_leaves(self) if hasattr(leaf, "dtype")]
        check_finite("GearPair", jnp.concatenate([jnp.ravel(a) for a in leaves]))
        _check_geometry(self)

    def _check_shapes(self) -> None:
        """Shapes and types of the fields (also on tracers): a value substituted by ``eqx.tree_at``
        with the wrong shape is named here rather than failing as an index error later."""
        scalars = (
            "module",
            "pressure_angle",
            "face_width",
            "addendum_coefficient",
            "dedendum_coefficient",
            "backlash",
            "mesh_damping_ratio",
        )
        for name in scalars:
            check_shape(name, getattr(self, name), (), "a scalar")
        check_shape("profile_shift", self.profile_shift, (2,), _PER_GEAR)
        unknown = set(self.overrides) - set(DERIVED_QUANTITIES)
        if unknown:
            raise ValueError(
                f"overrides = {self.overrides!r} names {sorted(unknown)}; valid names: "
                f"{', '.join(DERIVED_QUANTITIES)}"
            )
        for name in DERIVED_QUANTITIES:
            what = _PER_GEAR if _DERIVED_SHAPES[name] else "a scalar"
            check_shape(
                f"{name}_override", getattr(self, f"{name}_override"), _DERIVED_SHAPES[name], what
            )
        if (
            not isinstance(self.materials, tuple)
            or len(self.materials) != 2
            or not all(isinstance(m, Material) for m in self.materials)
        ):
            raise ValueError(
                f"materials = {self.materials!r} is not valid; valid: a pair of jaxgear.Material"
            )
        check_instance("bearings", self.bearings, Bearings)
        check_instance("tip_relief", self.tip_relief, TipRelief)

    def _check_scalars(self) -> None:
        """Ranges of the fields every derived quantity depends on (skipped on tracers)."""
        check_positive("module", self.module, "m")
        check_range(
            "pressure_angle",
            self.pressure_angle,
            0.0,
            math.radians(45.0),
            low_inclusive=False,
            unit="rad",
        )
        check_positive("face_width", self.face_width, "m")
        check_range("profile_shift", self.profile_shift, -1.5, 1.5)
        check_range(
            "addendum_coefficient", self.addendum_coefficient, 0.0, 2.5, low_inclusive=False
        )
        check_range(
            "dedendum_coefficient", self.dedendum_coefficient, 0.0, 3.0, low_inclusive=False
        )
        check_non_negative("backlash", self.backlash, "m")
        check_range("mesh_damping_ratio", self.mesh_damping_ratio, 0.0, 1.0, high_inclusive=False)
        for name, unit in (("tip_radius", "m"), ("root_radius", "m"), ("centre_distance", "m")):
            if name in self.overrides:
                check_positive(name, getattr(self, f"{name}_override"), unit)

    def replace(self, **changes) -> GearPair:
        """A copy with fields substituted, validated like a constructed pair.

        Keys are the constructor's arguments (``module=2.5e-3``, ``material=...``; ``materials`` is
        accepted for ``material``), with a derived quantity's name giving an override
        (``tip_radius=0.077``) and ``None`` removing one, or dotted paths into the nested inputs
        (``**{"tip_relief.amount": 5e-6}``, ``bearings__ky=1e9``; see ``jaxgear._inputs.replace``).
        Values become float64 arrays; a scalar is used for both gears of a per-gear field. Works on
        traced values too (the checks are then skipped, as in the constructor).

        Raises:
            ValueError: naming the substitution and the field that is out of range.
        """
        arguments = self._arguments()
        top, nested = {}, {}
        for key, value in changes.items():
            path = key.replace("__", ".")
            if "." in path:
                nested[path] = value
                continue
            name = "material" if path == "materials" else path
            if name not in arguments:
                raise ValueError(
                    f"GearPair has no field {key!r}; valid fields: {', '.join(arguments)}"
                )
            top[name] = value
        try:
            pair = GearPair(**{**arguments, **top}) if top else self
        except ValueError as err:
            raise ValueError(f"GearPair.replace({', '.join(changes)}): {err}") from None
        return _checked_replace(pair, nested)

    def _arguments(self) -> dict[str, Any]:
        """Constructor arguments that rebuild this pair (overrides given, the rest derived)."""
        arguments: dict[str, Any] = dict(
            teeth=self.teeth,
            module=self.module,
            pressure_angle=self.pressure_angle,
            face_width=self.face_width,
            profile_shift=self.profile_shift,
            addendum_coefficient=self.addendum_coefficient,
            dedendum_coefficient=self.dedendum_coefficient,
            backlash=self.backlash,
            material=self.materials,
            bearings=self.bearings,
            tip_relief=self.tip_relief,
            mesh_damping_ratio=self.mesh_damping_ratio,
        )
        for name in DERIVED_QUANTITIES:
            overridden = name in self.overrides
            arguments[name] = getattr(self, f"{name}_override") if overridden else None
        return arguments

    @property
    def material(self) -> Material:
        """Material of gear 1 (use ``materials`` for both)."""
        return self.materials[0]

    @property
    def gear_ratio(self) -> float:
        """z2/z1."""
        return self.teeth[1] / self.teeth[0]

    @property
    def reference_radius(self) -> Float[Array, "2"]:
        """Reference pitch radii m z/2, m (shape (2,))."""
        return inv.reference_radius(self.module, self.teeth)

    @property
    def base_radius(self) -> Float[Array, "2"]:
        """Base radii m z cos α/2, m (shape (2,))."""
        return inv.base_radius(self.module, self.teeth, self.pressure_angle)

    @property
    def tip_radius(self) -> Float[Array, "2"]:
        """Tip radii (ra1, ra2), m: the override, or m (z/2 + h_a* + x)."""
        if "tip_radius" in self.overrides:
            return self.tip_radius_override
        return inv.tip_radius(
            self.module, self.teeth, self.addendum_coefficient, self.profile_shift
        )

    @property
    def root_radius(self) -> Float[Array, "2"]:
        """Root radii (rf1, rf2), m: the override, or m (z/2 − h_f* + x)."""
        if "root_radius" in self.overrides:
            return self.root_radius_override
        return inv.root_radius(
            self.module, self.teeth, self.dedendum_coefficient, self.profile_shift
        )

    @property
    def centre_distance(self) -> Float[Array, ""]:
        """Operating centre distance a_w, m: the override, or the zero-backlash distance of the
        shifted gears (``involute.zero_backlash_centre_distance``)."""
        if "centre_distance" in self.overrides:
            return self.centre_distance_override
        return inv.zero_backlash_centre_distance(
            self.module, self.teeth, self.pressure_angle, self.profile_shift
        )

    @property
    def blank_mass(self) -> Float[Array, "2"]:
        """Blank masses (m1, m2), kg: the override, or solid disks ρ π r² b (r the reference
        radius, b the face width)."""
        if "blank_mass" in self.overrides:
            return self.blank_mass_override
        rho = jnp.stack([mat.density for mat in self.materials])
        return rho * jnp.pi * self.reference_radius**2 * self.face_width

    @property
    def blank_inertia(self) -> Float[Array, "2"]:
        """Blank polar inertias (J1, J2), kg m²: the override, or solid disks blank_mass · r²/2."""
        if "blank_inertia" in self.overrides:
            return self.blank_inertia_override
        return 0.5 * self.blank_mass * self.reference_radius**2

    @property
    def bore_radius(self) -> Float[Array, "2"]:
        """Bore radii (r_int1, r_int2), m: the override, or 0.5 × root radius."""
        if "bore_radius" in self.overrides:
            return self.bore_radius_override
        return 0.5 * self.root_radius


def _tip_roll_angles(pair: GearPair) -> Float[Array, "2"]:
    return inv.roll_angle(pair.tip_radius, pair.base_radius)


def _check_geometry(pair: GearPair) -> None:
    """Checks that need the derived geometry: undercut, tip/root order, contact ratio, relief start."""
    z = np.asarray(pair.teeth, dtype=float)
    alpha = float(pair.pressure_angle)
    x = np.asarray(pair.profile_shift)
    ha = float(pair.addendum_coefficient)
    # Generation by a rack: no undercut if z ≥ 2 (h_a* − x)/sin² α (ISO 21771 / textbook).
    z_min = np.asarray(inv.undercut_limit(alpha, ha, x))
    for j in range(2):
        if z[j] < z_min[j] - 1e-9:
            raise ValueError(
                f"teeth[{j}] = {int(z[j])} undercuts for pressure_angle = {math.degrees(alpha):.3g} deg "
                f"and profile_shift[{j}] = {x[j]:.3g}; valid range: teeth[{j}] >= {math.ceil(z_min[j] - 1e-9)} "
                f"(or increase profile_shift[{j}] to >= {ha - z[j] * math.sin(alpha) ** 2 / 2:.3f})"
            )
    ra = np.asarray(pair.tip_radius)
    rf = np.asarray(pair.root_radius)
    rb = np.asarray(pair.base_radius)
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
    t1t2, s_start, s_end = (float(v) for v in inv.path_of_contact(rb, ra, a_w))
    cr = (s_end - s_start) / float(inv.base_pitch(rb[0], z[0]))
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
    # Each gear's own roll angles at its start of active profile and at its tip.
    lo = np.asarray([s_start / rb[0], (t1t2 - s_end) / rb[1]])
    hi = np.asarray(inv.roll_angle(ra, rb))
    for j in range(2):
        if amount[j] > 0 and not (lo[j] <= start[j] < hi[j]):
            raise ValueError(
                f"tip_relief.start_roll_angle[{j}] = {math.degrees(start[j]):.4g} deg is outside the path "
                f"of contact of gear {j + 1}; valid range: [{math.degrees(lo[j]):.4g}, "
                f"{math.degrees(hi[j]):.4g}) deg"
            )
