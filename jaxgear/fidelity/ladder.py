"""The fidelity ladder (DESIGN §4): what to model, at what resolution, with which numbers.

A ``Fidelity`` is composed of

- ``contact`` (``ContactModel``): the friction rung and the contact physics chosen (thermal,
  transient, mixed model, fluid shear law, limiting shear), with the contact model's physical
  constants (``ContactConstants``: μ of the constant rung, μb, nβσ, σ/β, Λ) as traced float64
  numbers;
- ``coupled`` (``CoupledDynamics``): the dynamics rung and how the contacts are coupled to it
  (fixed point or frozen, its tolerance and acceleration, backlash, back flanks, the attractor);
- ``resolution`` (``Resolution``): positions per mesh cycle, EHL nodes per contact, steps per mesh
  period, the tooth stiffness method.

Every choice is static: a disabled piece costs nothing because the choice is made at trace time
(a quasi-static run never traces the dynamics, an iso-thermal run never traces the thermal
solver). Every constant is a traced number: changing one never recompiles, and every one can be
differentiated, its sensitivity computed and calibrated (``fid.with_constants(...)``).

| axis | rungs (cheap → expensive) |
|---|---|
| dynamics | "quasi_static" (W_T = W_sT, kinematic velocities) → "tribo_dynamic" |
| friction | "constant" μ → "regression" (Xu 2007) → "ehl_formula" → "ehl_smooth" → "ehl_mixed" |
| thermal | False (iso-thermal) → True |
| transient | False (quasi-steady per position) → True |
| coupling | "frozen" (contacts solved once, at the quasi-static state) → "fixed_point" |
| resolution | n_positions per mesh cycle, n_nodes per contact, steps_per_period of the dynamics |

The flat keywords of every part (``Fidelity(friction="ehl_mixed", n_nodes=129,
boundary_friction=0.12)``) build a Fidelity and read back as attributes (``fid.n_nodes``,
``fid.boundary_friction``).
"""

from __future__ import annotations

import dataclasses
import warnings

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, Float

from .._validation import is_concrete
from ..dynamics.model import BACK_FLANK_KINDS

DYNAMICS_RUNGS = ("quasi_static", "tribo_dynamic")
FRICTION_RUNGS = ("constant", "regression", "ehl_formula", "ehl_smooth", "ehl_mixed")
COUPLING_RUNGS = ("frozen", "fixed_point")
STIFFNESS_METHODS = ("potential_energy", "iso")
SHEAR_LAWS = ("eyring_paper", "eyring_exact", "eyring_split", "newtonian")
#: ``Fidelity.paper_calibrated()``'s contact: the fluid traction law and the Greenwood-Tripp
#: density product nβσ calibrated to the paper's quasi-static loss level (see its docstring)
CALIBRATED_SHEAR = "eyring_split"
CALIBRATED_DENSITY_PRODUCT = 0.08
#: the presets ``Fidelity.named`` (and so the command line and TOML) accept
NAMED_PRESETS = ("fast", "paper", "paper_calibrated")
#: Λ carried while the limiting shear stress is off (``ContactModel.limiting_shear`` False)
_LAMBDA_OFF = 0.1


def _number(name):
    def convert(value):
        low, high = CONSTANTS[name][1]
        invalid = ValueError(
            f"Fidelity.{name} = {value!r} is out of range; valid range: [{low:g}, {high:g}]"
        )
        if isinstance(value, bool | str):
            raise invalid
        try:
            return jnp.asarray(value, dtype=jnp.result_type(float))
        except (TypeError, ValueError):
            raise invalid from None

    return eqx.field(converter=convert)


#: The contact model's constants: name → (default, valid range, what it is).
CONSTANTS = {
    "constant_mu": (0.03, (0.0, 1.0), "friction coefficient of the constant rung"),
    "boundary_friction": (0.1, (0.0, 1.0), "μb, friction coefficient of asperity contact"),
    "asperity_density_product": (
        0.05,
        (1e-4, 1.0),
        "nβσ of the Greenwood-Tripp asperity model (summit density × radius × roughness)",
    ),
    "asperity_slope_ratio": (
        0.01,
        (1e-6, 1.0),
        "σ/β of the Greenwood-Tripp asperity model (roughness over summit radius)",
    ),
    "limiting_shear_coefficient": (
        _LAMBDA_OFF,
        (1e-6, 1.0),
        "Λ of the limiting shear stress τL = Λ p (when ContactModel.limiting_shear)",
    ),
}


class ContactConstants(eqx.Module):
    """The physical constants of the contact models, as traced float64 numbers.

    Attributes:
        constant_mu: friction coefficient of the "constant" rung (default 0.03).
        boundary_friction: μb, friction coefficient of asperity contact (paper: 0.1).
        asperity_density_product: nβσ of the statistical (Greenwood-Tripp) asperity model:
            summit density n (1/m²) × summit radius β (m) × composite roughness σ (m),
            dimensionless, valid range [1e-4, 1]; of order a few hundredths for machined surfaces,
            default 0.05. The asperity pressure scales as K′ ∝ (nβσ)² √(σ/β) and the real
            contact area as (nβσ)² (``lubrication/asperity.py``).
        asperity_slope_ratio: σ/β of the same model, valid range [1e-6, 1], default 0.01.
            The paper (S. Li 2015) puts measured profiles in the film and gives neither; with μb,
            τ0 and the shear law they set the friction level in deep mixed lubrication.
        limiting_shear_coefficient: Λ of a limiting shear stress τL = Λ p (Bair & Winer) that
            caps the fluid traction and sliding heat of the EHL and closed-form rungs; acts only
            where ``ContactModel.limiting_shear`` is on (not in the paper). Valid range
            [1e-6, 1].

    Every field acts only on the rungs that use it: μ on "constant"; μb, nβσ, σ/β on the mixed
    rungs ("ehl_formula", "ehl_mixed" with the statistical model); Λ with the cap on.
    """

    constant_mu: Float[Array, ""] = _number("constant_mu")
    boundary_friction: Float[Array, ""] = _number("boundary_friction")
    asperity_density_product: Float[Array, ""] = _number("asperity_density_product")
    asperity_slope_ratio: Float[Array, ""] = _number("asperity_slope_ratio")
    limiting_shear_coefficient: Float[Array, ""] = _number("limiting_shear_coefficient")

    def __init__(self, **values):
        unknown = set(values) - set(CONSTANTS)
        if unknown:
            raise ValueError(
                f"unknown contact constant(s): {', '.join(sorted(unknown))}; valid names: "
                f"{', '.join(CONSTANTS)}"
            )
        for name, (default, _, _) in CONSTANTS.items():
            setattr(self, name, values.get(name, default))

    def __check_init__(self):
        for name, (_, (low, high), _) in CONSTANTS.items():
            _float_in(f"Fidelity.{name}", getattr(self, name), low, high)

    def as_dict(self) -> dict:
        """name → value (a float where concrete)."""
        return {name: _as_float(getattr(self, name)) for name in CONSTANTS}


class ContactModel(eqx.Module):
    """The contact physics chosen (static) and its constants (traced).

    Attributes:
        friction: "constant", "regression", "ehl_formula", "ehl_smooth" or "ehl_mixed".
            "ehl_formula" is the statistical mixed EHL contact in closed form (Pan-Hamrock film
            read as the average gap, Greenwood-Tripp asperity load at the mean-plane separation,
            Eyring fluid traction over the Hertz zone's non-contact share,
            Goksem-Hargreaves rolling traction: ``lubrication/ehl_formula.py``); it uses
            ``shear``, μb and the asperity constants like the EHL rungs, and is iso-thermal and
            quasi-steady (``thermal`` and ``transient`` act on the EHL rungs only).
        thermal: thermal EHL (film and surface temperatures) instead of iso-thermal.
        transient: transient EHL marching through the engagement instead of quasi-steady
            contacts.
        mixed_model: roughness treatment of the "ehl_mixed" rung: "statistical" (the film on the
            surfaces' mean planes: average gap, Patir-Cheng flow factor, Greenwood-Tripp asperity
            pressure; from full film to boundary lubrication) or
            "deterministic" (the roughness profiles in the film, unified Reynolds; it needs
            n_nodes ≳ 513 and does not converge in deep mixed lubrication).
        shear: fluid shear law (``EHLModel.shear``): "eyring_paper" (the paper's η* =
            η/cosh(τm/τ0), Eq. 4), "eyring_exact" (τ = τ0 asinh(η us/(τ0 h))), "eyring_split" (the
            stress τm in the friction and sliding heat, its tangent η* in the flow coefficient,
            the Poiseuille heat and the damping) or "newtonian".
        limiting_shear: cap the fluid shear stress at τL = Λ p (``ContactConstants``).
        constants: ContactConstants.
    """

    friction: str = eqx.field(static=True, default="regression")
    thermal: bool = eqx.field(static=True, default=False)
    transient: bool = eqx.field(static=True, default=False)
    mixed_model: str = eqx.field(static=True, default="statistical")
    shear: str = eqx.field(static=True, default="eyring_paper")
    limiting_shear: bool = eqx.field(static=True, default=False)
    constants: ContactConstants = eqx.field(default_factory=ContactConstants)

    def __check_init__(self):
        _choice("Fidelity.friction", self.friction, FRICTION_RUNGS)
        _choice("Fidelity.mixed_model", self.mixed_model, ("statistical", "deterministic"))
        _choice("Fidelity.shear", self.shear, SHEAR_LAWS)
        for name in ("thermal", "transient", "limiting_shear"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"Fidelity.{name} = {getattr(self, name)!r} must be True or False")


class CoupledDynamics(eqx.Module):
    """The dynamics rung and how the contacts are coupled to it (all static).

    Attributes:
        dynamics: "quasi_static" or "tribo_dynamic".
        coupling: "fixed_point" (the paper's: every fixed-point iteration solves every contact
            again at the dynamic loads and velocities) or "frozen" (the contacts solved once, at
            the quasi-static state, with their derivative along the load; their outputs become
            power-law coefficients in the load that the fixed point scales to the dynamic loads
            and velocities: one dynamics solve per iteration). No effect when quasi-static.
        fixed_point_tolerance: relative change of the interface tables at which the fixed point
            counts as converged; None: 1e-4, or 3e-3 on the rungs whose contacts carry an outer
            (Picard) iteration (``Fidelity.fixed_point_rtol``).
        max_fixed_point_iterations: cap on the fixed-point iterations.
        relaxation: β of Anderson acceleration, or of the damped iteration when
            ``anderson_memory`` = 0; in (0, 1].
        anderson_memory: iterates mixed by Anderson acceleration (0: damped iteration).
        backlash: "exact" or "smooth" backlash ("smooth" for gradients through contact loss).
        back_flank: "mirrored" (the back flanks' own stiffness, excitation and line of action) or
            "same" (the paper's single backlash function). See ``DynamicsOptions.back_flank``.
        attractor_periods: where no stable periodic orbit exists, the result is the mean over
            this many mesh cycles of the attractor reached by time integration (status 6); 0
            reports the unstable orbit, flagged (status 2). Integer ≥ 0, not 1.
        settle_periods: mesh cycles integrated before the attractor's record. Integer ≥ 0.
    """

    dynamics: str = eqx.field(static=True, default="tribo_dynamic")
    coupling: str = eqx.field(static=True, default="fixed_point")
    fixed_point_tolerance: float | None = eqx.field(static=True, default=None)
    max_fixed_point_iterations: int = eqx.field(static=True, default=40)
    relaxation: float = eqx.field(static=True, default=1.0)
    anderson_memory: int = eqx.field(static=True, default=4)
    backlash: str = eqx.field(static=True, default="exact")
    back_flank: str = eqx.field(static=True, default="mirrored")
    attractor_periods: int = eqx.field(static=True, default=256)
    settle_periods: int = eqx.field(static=True, default=2000)

    def __check_init__(self):
        _choice("Fidelity.dynamics", self.dynamics, DYNAMICS_RUNGS)
        _choice("Fidelity.coupling", self.coupling, COUPLING_RUNGS)
        _choice("Fidelity.backlash", self.backlash, ("exact", "smooth"))
        _choice("Fidelity.back_flank", self.back_flank, BACK_FLANK_KINDS)
        _int_at_least("Fidelity.max_fixed_point_iterations", self.max_fixed_point_iterations, 1)
        _int_at_least("Fidelity.anderson_memory", self.anderson_memory, 0)
        _int_at_least("Fidelity.attractor_periods", self.attractor_periods, 0)
        if self.attractor_periods == 1:
            raise ValueError(
                "Fidelity.attractor_periods = 1 is out of range; valid range: 0 (off) or an "
                "integer >= 2"
            )
        _int_at_least("Fidelity.settle_periods", self.settle_periods, 0)
        if self.fixed_point_tolerance is not None:
            _float_in("Fidelity.fixed_point_tolerance", self.fixed_point_tolerance, 1e-14, 0.1)
        _float_in("Fidelity.relaxation", self.relaxation, 1e-3, 1.0)


class Resolution(eqx.Module):
    """Discretisation (all static).

    Attributes:
        n_positions: positions per mesh cycle (≥ 24: the DTE's 10 mesh harmonics).
        n_nodes: EHL grid nodes per contact (≥ 33).
        steps_per_period: least fixed Runge-Kutta steps per mesh period in the dynamics (≥ 16).
        stiffness: tooth stiffness method of the mesh cycle ("potential_energy" or "iso").
    """

    n_positions: int = eqx.field(static=True, default=32)
    n_nodes: int = eqx.field(static=True, default=129)
    steps_per_period: int = eqx.field(static=True, default=64)
    stiffness: str = eqx.field(static=True, default="potential_energy")

    def __check_init__(self):
        _int_at_least("Fidelity.n_positions", self.n_positions, 24)
        _int_at_least("Fidelity.n_nodes", self.n_nodes, 33)
        _int_at_least("Fidelity.steps_per_period", self.steps_per_period, 16)
        _choice("Fidelity.stiffness", self.stiffness, STIFFNESS_METHODS)


_PARTS = {
    "contact": ContactModel,
    "coupled": CoupledDynamics,
    "resolution": Resolution,
}
_CHOICE_FIELDS = {
    part: tuple(f.name for f in dataclasses.fields(cls) if f.name != "constants")
    for part, cls in _PARTS.items()
}
#: The flat name of every choice → the part that holds it.
CHOICES = {name: part for part, names in _CHOICE_FIELDS.items() for name in names}
#: Every flat keyword a Fidelity takes (choices, then constants), in a stable order.
FLAT_FIELDS = (*CHOICES, *CONSTANTS)


def _defaults() -> dict:
    out = {}
    for cls in _PARTS.values():
        for f in dataclasses.fields(cls):
            if f.name != "constants":
                out[f.name] = f.default
    out.update({name: spec[0] for name, spec in CONSTANTS.items()})
    out["limiting_shear_coefficient"] = None
    return out


#: The default of every flat keyword (``limiting_shear_coefficient`` None: no cap).
FLAT_DEFAULTS = _defaults()


def _split(flat: dict):
    """Flat keywords → (choices per part, constants); ``limiting_shear_coefficient`` None/number
    sets the cap's choice and its number."""
    unknown = set(flat) - set(FLAT_FIELDS)
    if unknown:
        raise ValueError(
            f"unknown Fidelity field(s): {', '.join(sorted(unknown))}; valid fields: "
            f"{', '.join(FLAT_FIELDS)}"
        )
    parts = {part: {} for part in _PARTS}
    constants = {}
    for name, value in flat.items():
        if name in CONSTANTS:
            constants[name] = value
        else:
            parts[CHOICES[name]][name] = value
    if "limiting_shear_coefficient" in constants:
        value = constants.pop("limiting_shear_coefficient")
        parts["contact"]["limiting_shear"] = value is not None
        if value is not None:
            constants["limiting_shear_coefficient"] = value
    return parts, constants


class Fidelity(eqx.Module):
    """Physics, resolution and the contact model's numbers of a simulation.

    Built from its parts (``Fidelity(contact=ContactModel(...), coupled=CoupledDynamics(...),
    resolution=Resolution(...))``) or from flat keywords, every one of the parts' fields and
    constants (``Fidelity(friction="ehl_mixed", n_nodes=129, boundary_friction=0.12)``), on top
    of the defaults (``FLAT_DEFAULTS``: tribo-dynamic, regression friction, 32 positions, 129
    nodes, 64 steps per mesh period). Every flat name reads back as an attribute; the constants
    read back as traced float64 arrays.

    Changing a choice (``fid.replace(n_nodes=257)``) compiles a new program; changing a constant
    (``fid.with_constants(boundary_friction=0.12)``) does not, and can be differentiated.

    Attributes:
        contact: ContactModel (friction rung, thermal, transient, mixed model, shear law,
            limiting shear; its ``constants``).
        coupled: CoupledDynamics (dynamics rung, coupling, fixed point, backlash, back flanks,
            attractor).
        resolution: Resolution (positions, nodes, steps per period, stiffness method).
    """

    contact: ContactModel
    coupled: CoupledDynamics
    resolution: Resolution

    def __init__(
        self,
        contact: ContactModel | None = None,
        coupled: CoupledDynamics | None = None,
        resolution: Resolution | None = None,
        **flat,
    ):
        parts, constants = _split(flat)
        given = {"contact": contact, "coupled": coupled, "resolution": resolution}
        for part, cls in _PARTS.items():
            base = given[part] if given[part] is not None else cls()
            if not isinstance(base, cls):
                raise ValueError(
                    f"Fidelity.{part} = {base!r} is not valid; valid: a jaxgear.{cls.__name__}"
                )
            if parts[part]:
                base = dataclasses.replace(base, **parts[part])
            given[part] = base
        contact = given["contact"]
        if constants:
            contact = dataclasses.replace(
                contact,
                constants=ContactConstants(**{**contact.constants.as_dict(), **constants}),
            )
        self.contact = contact
        self.coupled = given["coupled"]
        self.resolution = given["resolution"]

    def __getattr__(self, name):
        # the flat view: every part's fields and constants by their own names
        part = CHOICES.get(name)
        if part is not None:
            return getattr(object.__getattribute__(self, part), name)
        if name in CONSTANTS:
            return getattr(object.__getattribute__(self, "contact").constants, name)
        raise AttributeError(name)

    @property
    def constants(self) -> ContactConstants:
        """The contact model's constants (traced numbers)."""
        return self.contact.constants

    def flat(self) -> dict:
        """Every flat keyword → its value (constants as floats where concrete;
        ``limiting_shear_coefficient`` None while the cap is off): ``Fidelity(**fid.flat())``
        rebuilds ``fid``."""
        out = {name: getattr(self, name) for name in CHOICES}
        out.update(self.contact.constants.as_dict())
        out.pop("limiting_shear", None)
        if not self.contact.limiting_shear:
            out["limiting_shear_coefficient"] = None
        return out

    def replace(self, **changes) -> Fidelity:
        """A copy with parts or flat fields changed (validated), e.g.
        ``fid.replace(dynamics="quasi_static", n_nodes=65)``. A constant given here works but is
        deprecated: use ``with_constants`` (it keeps the fidelity's choices, so nothing
        recompiles)."""
        part_changes = {k: changes.pop(k) for k in list(changes) if k in _PARTS}
        moved = sorted(set(changes) & set(CONSTANTS) - {"limiting_shear_coefficient"})
        if moved:
            warnings.warn(
                f"Fidelity.replace({', '.join(moved)}=...) is deprecated: the contact model's "
                "constants are traced numbers now; use fid.with_constants(...)",
                DeprecationWarning,
                stacklevel=2,
            )
        parts = {
            "contact": self.contact,
            "coupled": self.coupled,
            "resolution": self.resolution,
            **part_changes,
        }
        return Fidelity(**parts, **changes)

    def with_constants(self, **constants) -> Fidelity:
        """A copy with the contact model's constants changed (``CONSTANTS``: constant_mu,
        boundary_friction, asperity_density_product, asperity_slope_ratio,
        limiting_shear_coefficient), validated, as traced float64 numbers: the same compiled
        programs run it. ``limiting_shear_coefficient`` needs the cap on
        (``limiting_shear=True``)."""
        unknown = set(constants) - set(CONSTANTS)
        if unknown:
            raise ValueError(
                f"unknown contact constant(s): {', '.join(sorted(unknown))}; valid names: "
                f"{', '.join(CONSTANTS)}"
            )
        if "limiting_shear_coefficient" in constants and not self.contact.limiting_shear:
            raise ValueError(
                "limiting_shear_coefficient acts only with the limiting shear stress on; build "
                "the fidelity with limiting_shear_coefficient=... (or limiting_shear=True)"
            )
        values = {name: getattr(self.contact.constants, name) for name in CONSTANTS}
        values.update(constants)
        new = ContactConstants(**values)
        return eqx.tree_at(lambda f: f.contact.constants, self, new)

    @classmethod
    def fast(cls, **changes) -> Fidelity:
        """The CLI default: tribo-dynamic, closed-form mixed EHL friction ("ehl_formula": sliding
        and rolling loss, EHL damping), 32 positions per cycle, at a few hundredths of a second
        per point (measured against ``paper()``: benchmarks/RESULTS.md, fidelity_trade)."""
        return cls(**{"friction": "ehl_formula", **changes})

    @classmethod
    def paper(cls, **changes) -> Fidelity:
        """The paper's model (S. Li 2015) as far as jaxgear couples it: tribo-dynamic, thermal
        mixed EHL (film and surface temperatures, asperity contact with boundary friction
        μb = 0.1), transient (each tooth pair marched through its engagement with the squeeze
        term and the surface temperatures' memory), 32 positions per mesh cycle, 257 nodes per
        contact, the back flanks by the paper's single backlash function (``back_flank="same"``).

        Difference from the paper, stated: the roughness enters through the statistical
        (Greenwood-Tripp) asperity model, not the measured profiles in the film. The
        deterministic solver exists (``mixed_model="deterministic"``) but the transient rung
        refuses it: between two mesh positions the profiles would move by far more than a grid
        cell, and its film is not grid-converged on grids a coupled run can afford
        (docs/limitations.md, deterministic roughness). The open contact parameters keep their
        literal defaults here; ``paper_calibrated()`` is the same model with two of them fitted."""
        base = dict(
            back_flank="same",
            dynamics="tribo_dynamic",
            friction="ehl_mixed",
            thermal=True,
            transient=True,
            n_positions=32,
            n_nodes=257,
        )
        return cls(**{**base, **changes})

    @classmethod
    def paper_calibrated(cls, **changes) -> Fidelity:
        """``paper()`` with its two open contact parameters set to the paper's loss level: the
        Eyring stress as the fluid traction (``shear="eyring_split"``, a model choice, not fitted)
        and the Greenwood-Tripp density product nβσ = 0.08 (``asperity_density_product``; 0.05 in
        ``paper()``), fitted by ``jg.calibrate`` to the paper's quasi-static Φ̄ at points A, B, D
        and E (0.08 within the fit's standard error; ``benchmarks/calibration.py``). One constant
        cannot follow the paper's speed trend: A and B stay above the paper's losses, D and E below
        (by up to ~13 %). A fitted preset, like the calibrated blanks of
        ``presets.li2015_pair_calibrated()``: use it to study the paper's trends at the paper's
        loss level, not as a check of that level; point C, the tribo-dynamic losses and the trends
        remain checks. ``changes``: flat Fidelity keywords applied on top."""
        calibrated = dict(
            shear=CALIBRATED_SHEAR, asperity_density_product=CALIBRATED_DENSITY_PRODUCT
        )
        return cls.paper(**{**calibrated, **changes})

    @classmethod
    def named(cls, name: str, **changes) -> Fidelity:
        """A preset by name: "fast", "paper" or "paper_calibrated" (the names the command line
        accepts)."""
        if name not in NAMED_PRESETS:
            raise ValueError(
                f"fidelity = {name!r} is not valid; valid choices: "
                f"{', '.join(map(repr, NAMED_PRESETS))}"
            )
        return getattr(cls, name)(**changes)

    @property
    def fixed_point_rtol(self) -> float:
        """The fixed-point tolerance in use: ``fixed_point_tolerance``, or by default 1e-4, and
        3e-3 where the contacts carry an outer iteration (the thermal Picard loop, which stops
        once the film temperature moves by < 1 % of its rise, so the friction tables are
        reproducible only to about 1e-3 of their maximum; with 1e-4 the Anderson iteration
        flip-flops between two tables ~1e-3 apart until its cap)."""
        if self.coupled.fixed_point_tolerance is not None:
            return self.coupled.fixed_point_tolerance
        picard = self.uses_ehl and self.contact.thermal
        # frozen coupling: the contacts are solved once, outside the iteration (no Picard noise)
        return 3e-3 if picard and self.coupled.coupling == "fixed_point" else 1e-4

    @property
    def uses_ehl(self) -> bool:
        """The contacts are solved by the EHL solver (pressure and film fields exist)."""
        return self.contact.friction in ("ehl_smooth", "ehl_mixed")

    @property
    def models_rolling(self) -> bool:
        """The friction rung gives a rolling (Poiseuille) loss and EHL damping."""
        return self.contact.friction in ("ehl_formula", "ehl_smooth", "ehl_mixed")


def _as_float(value):
    return float(value) if is_concrete(value) and jnp.ndim(value) == 0 else value


def _choice(name, value, choices):
    if value not in choices:
        raise ValueError(
            f"{name} = {value!r} is not valid; valid choices: {', '.join(map(repr, choices))}"
        )


def _int_at_least(name, value, low):
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise ValueError(f"{name} = {value!r} is out of range; valid range: integer >= {low}")


def _float_in(name, value, low, high):
    if isinstance(value, bool):
        raise ValueError(f"{name} = {value!r} is out of range; valid range: [{low:g}, {high:g}]")
    if not is_concrete(value):
        return
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(
            f"{name} = {value!r} is out of range; valid range: [{low:g}, {high:g}]"
        ) from None
    if not low <= number <= high:
        raise ValueError(f"{name} = {number!r} is out of range; valid range: [{low:g}, {high:g}]")
