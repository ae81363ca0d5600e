"""The fidelity ladder (DESIGN §4): a static, hashable choice of physics and resolution.

Every axis is chosen at trace time, so a disabled piece costs nothing: a quasi-static run never
traces the dynamics, an iso-thermal run never traces the thermal solver, and so on.

| axis | rungs (cheap → expensive) |
|---|---|
| dynamics | "quasi_static" (W_T = W_sT, kinematic velocities) → "tribo_dynamic" |
| friction | "constant" μ → "regression" (Xu 2007) → "ehl_formula" → "ehl_smooth" → "ehl_mixed" |
| thermal | False (iso-thermal) → True |
| transient | False (quasi-steady per position) → True |
| coupling | "frozen" (contacts solved once, at the quasi-static state) → "fixed_point" |
| resolution | n_positions per mesh cycle, n_nodes per contact, steps_per_period of the dynamics |
"""

from __future__ import annotations

import dataclasses

import equinox as eqx

from .dynamics.model import BACK_FLANK_KINDS

DYNAMICS_RUNGS = ("quasi_static", "tribo_dynamic")
FRICTION_RUNGS = ("constant", "regression", "ehl_formula", "ehl_smooth", "ehl_mixed")
COUPLING_RUNGS = ("frozen", "fixed_point")
STIFFNESS_METHODS = ("potential_energy", "iso")
#: ``Fidelity.paper_calibrated()``'s contact: the fluid traction law and the Greenwood-Tripp
#: density product nβσ calibrated to the paper's quasi-static loss level (see its docstring)
CALIBRATED_SHEAR = "eyring_split"
CALIBRATED_DENSITY_PRODUCT = 0.08
#: the presets ``Fidelity.named`` (and so the command line and TOML) accept
NAMED_PRESETS = ("fast", "paper", "paper_calibrated")


def _static(default):
    return eqx.field(static=True, default=default)


class Fidelity(eqx.Module):
    """Physics and resolution of a simulation (all static).

    Attributes:
        dynamics: "quasi_static" or "tribo_dynamic".
        friction: "constant", "regression", "ehl_formula", "ehl_smooth" or "ehl_mixed".
            "ehl_formula" is the statistical mixed EHL contact in closed form (Pan-Hamrock film,
            Greenwood-Tripp asperity load, Eyring fluid traction over the Hertz zone,
            Goksem-Hargreaves rolling traction: ``lubrication/ehl_formula.py``); it uses
            ``shear``, ``boundary_friction`` and the asperity constants like the EHL rungs, and is
            iso-thermal and quasi-steady (``thermal`` and ``transient`` act on the EHL rungs only).
        thermal: thermal EHL (film and surface temperatures) instead of iso-thermal.
        transient: transient EHL marching through the engagement instead of quasi-steady contacts.
        coupling: how the tribo-dynamic rung couples the contacts to the dynamics. "fixed_point"
            (the paper's): every fixed-point iteration solves every contact again at the dynamic
            loads and velocities. "frozen": the contacts are solved once, at the quasi-static state
            (static load sharing, kinematic velocities), together with their derivative along the
            load (forward mode through the converged solves); their outputs become coefficients
            (Fs/(W s), Fr/W, cm, Φs/(W us s), Φr/(W um), s the smoothed sign of the sliding
            velocity us), each a power law in the load with the local exponent, that the fixed point
            scales to the dynamic loads and velocities, so each iteration costs one dynamics solve.
            What it leaves out: the coefficients' dependence on the sliding speed, the transient
            (squeeze) response to the dynamic load and its temperatures, and any non-power-law
            load dependence (error and cost measured in benchmarks/RESULTS.md, coupling_trade).
            No effect on the quasi-static rung.
        n_positions: positions per mesh cycle.
        n_nodes: EHL grid nodes per contact.
        steps_per_period: fixed Runge-Kutta steps per mesh period in the dynamics.
        stiffness: tooth stiffness method of the mesh cycle ("potential_energy" or "iso").
        constant_mu: friction coefficient of the "constant" rung.
        boundary_friction: μb of asperity contact (paper: 0.1).
        fixed_point_tolerance: relative change of the mesh-interface tables (each table relative
            to its largest entry) at which the tribo-dynamic fixed point counts as converged; None
            (default): 1e-4, or 3e-3 on the rungs whose contacts are solved by an outer (Picard)
            iteration, thermal or statistical mixed EHL (see ``fixed_point_rtol``).
        max_fixed_point_iterations: cap on the fixed-point iterations.
        relaxation: β, the mixing parameter of Anderson acceleration, or of the plain damped iteration
            x ← (1 − β) x + β T(x) when ``anderson_memory`` = 0; in (0, 1]. Measured on the paper's
            pair with the regression rung: Anderson (memory 4, β = 1) converges in 5-8 iterations over
            300-3500 rpm; plain iteration needs β = 0.5 and 16-19 (β = 1 chatters at low speed: the
            vibratory sliding speed near the pitch point feeds back on the friction sign).
        anderson_memory: iterates mixed by the Anderson-accelerated fixed point (0: plain damped
            iteration with ``relaxation``).
        backlash: "exact" or "smooth" backlash in the dynamics ("smooth" for gradients through
            contact loss).
        back_flank: the back flanks' mesh stiffness, excitation and line of action in the
            dynamics, where rattling teeth strike them: "mirrored" (the drive tables at the
            mirrored phase, where the back contacts stand, the force along their own line of
            action) or "same" (the drive side's km(t) at the same instant, along the drive line of
            action: the usual single backlash function). See ``DynamicsOptions.back_flank``.
        mixed_model: roughness treatment of the "ehl_mixed" rung: "statistical" (Greenwood-Tripp
            asperity pressure with the mean film: robust in deep mixed lubrication) or
            "deterministic" (the roughness profiles in the film, unified Reynolds; it needs
            n_nodes ≳ 513 and does not converge in deep mixed lubrication). See EHLModel.mixed.
        shear: fluid shear law of the EHL rungs (``EHLModel.shear``): "eyring_paper" (the paper's
            η* = η/cosh(τm/τ0), Eq. 4: the fluid shear stress stays below τ0), "eyring_exact"
            (τ = τ0 asinh(η us/(τ0 h)): grows without bound, logarithmically), "eyring_split"
            (the stress τm in the friction and sliding heat, η* = dτm/dγ̇, its tangent, in the
            Reynolds flow coefficient, the Poiseuille heat and the damping) or "newtonian".
            REFERENCE §4 asks for both Eyring forms and the sensitivity of the loss to the choice
            (``benchmarks/shear_sensitivity.py``).
        asperity_density_product: nβσ of the statistical (Greenwood-Tripp) asperity model
            (``EHLModel.asperity_density_product``): summit density n (1/m²) × summit radius β (m)
            × composite roughness σ (m), dimensionless; valid range [1e-4, 1]. Of order a few
            hundredths for machined surfaces; default 0.05. The asperity pressure scales as
            K′ ∝ (nβσ)² √(σ/β) and the real-contact area as (nβσ)² (``lubrication/asperity.py``).
        asperity_slope_ratio: σ/β of the statistical model (``EHLModel.asperity_slope_ratio``):
            composite roughness over summit radius, dimensionless; valid range [1e-6, 1]. Small,
            of order 1e-3-1e-2; default 0.01. Both act only on ``friction = "ehl_mixed"``
            with ``mixed_model = "statistical"``. The paper (S. Li 2015) puts measured profiles in
            the film and gives neither; with μb, τ0 and the shear law they set the friction level in
            deep mixed lubrication. The mesh loss depends on them only through K′; the paper's
            quasi-static losses need K′ ≈ 2.4-2.9 × the default's, e.g. nβσ ≈ 0.08 (measured:
            ``benchmarks/friction_sensitivity.py``; the defaults are not fitted to the paper).
        limiting_shear_coefficient: Λ of a limiting shear stress τL = Λ p (Bair & Winer) that caps
            the fluid traction and sliding heat of the EHL rungs and the closed-form rung
            (``EHLModel.limiting_shear_coefficient``), valid range [1e-6, 1]; None (default): no
            cap, the paper's model. Not in the paper: a traction that grows with load but not
            with the inlet viscosity (see ``benchmarks/shear_sensitivity.py``).
        attractor_periods: where the tribo-dynamic fixed point ends without a stable periodic
            orbit (a parametric instability band, or rattling through the backlash), the gears
            settle on another attractor (a period-doubled orbit, a torus, a chaotic rattle): the
            result is then the mean over this many mesh cycles of that attractor, reached by time
            integration with the last interface tables (``jaxgear.dynamics.attractor_response``),
            with the contacts evaluated at every position of 64 cycles spread over the record
            (tribodynamics.second_pass.ATTRACTOR_CONTACT_CYCLES; status 6,
            "attractor"; on the EHL rungs through the closed-form mixed EHL contact scaled to the
            rung's level on the orbit: see ``tribodynamics.second_pass.attractor_means``).
            0: report the unstable periodic orbit, flagged (status 2), as before. Default 256:
            the mean mesh force of the chaotic rattles of the calibrated pair comes within 2 % of
            T1/rb1 (its exact long-time mean) over 256 cycles, against 4-11 % over 32 (the
            window's start and end momenta). In a continuation sweep the next speed without a
            stable orbit continues from this record's end (ATTRACTOR_WARM_SETTLE = 200 settling
            cycles instead of ``settle_periods``). Integer ≥ 0 (not 1).
        settle_periods: mesh cycles integrated before the record (re-balancing the load torque so
            that the mean speed stays nominal). A weak instability (largest Floquet multiplier
            1 + ε) leaves the orbit over ~ln(1e3)/ε cycles: 2000 covers ε ≳ 0.004; weaker ones stay
            on the orbit within that time, and the record then repeats it. Integer ≥ 0.
    """

    dynamics: str = _static("tribo_dynamic")
    friction: str = _static("regression")
    thermal: bool = _static(False)
    transient: bool = _static(False)
    coupling: str = _static("fixed_point")
    n_positions: int = _static(32)
    n_nodes: int = _static(129)
    steps_per_period: int = _static(64)
    stiffness: str = _static("potential_energy")
    constant_mu: float = _static(0.03)
    boundary_friction: float = _static(0.1)
    fixed_point_tolerance: float | None = _static(None)
    max_fixed_point_iterations: int = _static(40)
    relaxation: float = _static(1.0)
    backlash: str = _static("exact")
    back_flank: str = _static("mirrored")
    anderson_memory: int = _static(4)
    mixed_model: str = _static("statistical")
    shear: str = _static("eyring_paper")
    asperity_density_product: float = _static(0.05)
    asperity_slope_ratio: float = _static(0.01)
    limiting_shear_coefficient: float | None = _static(None)
    attractor_periods: int = _static(256)
    settle_periods: int = _static(2000)

    def __check_init__(self):
        _choice("Fidelity.dynamics", self.dynamics, DYNAMICS_RUNGS)
        _choice("Fidelity.friction", self.friction, FRICTION_RUNGS)
        _choice("Fidelity.coupling", self.coupling, COUPLING_RUNGS)
        _choice("Fidelity.stiffness", self.stiffness, STIFFNESS_METHODS)
        _choice("Fidelity.backlash", self.backlash, ("exact", "smooth"))
        _choice("Fidelity.back_flank", self.back_flank, BACK_FLANK_KINDS)
        _choice("Fidelity.mixed_model", self.mixed_model, ("statistical", "deterministic"))
        _choice(
            "Fidelity.shear",
            self.shear,
            ("eyring_paper", "eyring_exact", "eyring_split", "newtonian"),
        )
        for name in ("thermal", "transient"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"Fidelity.{name} = {getattr(self, name)!r} must be True or False")
        _int_at_least("Fidelity.n_positions", self.n_positions, 24)  # 10 DTE harmonics
        _int_at_least("Fidelity.n_nodes", self.n_nodes, 33)
        _int_at_least("Fidelity.steps_per_period", self.steps_per_period, 16)
        _int_at_least("Fidelity.max_fixed_point_iterations", self.max_fixed_point_iterations, 1)
        _int_at_least("Fidelity.anderson_memory", self.anderson_memory, 0)
        _int_at_least("Fidelity.attractor_periods", self.attractor_periods, 0)
        if self.attractor_periods == 1:
            raise ValueError(
                "Fidelity.attractor_periods = 1 is out of range; valid range: 0 (off) or an "
                "integer >= 2"
            )
        _int_at_least("Fidelity.settle_periods", self.settle_periods, 0)
        _float_in("Fidelity.constant_mu", self.constant_mu, 0.0, 1.0)
        _float_in("Fidelity.boundary_friction", self.boundary_friction, 0.0, 1.0)
        # the ranges of EHLModel.__check_init__
        _float_in("Fidelity.asperity_density_product", self.asperity_density_product, 1e-4, 1.0)
        _float_in("Fidelity.asperity_slope_ratio", self.asperity_slope_ratio, 1e-6, 1.0)
        if self.limiting_shear_coefficient is not None:
            _float_in(
                "Fidelity.limiting_shear_coefficient", self.limiting_shear_coefficient, 1e-6, 1.0
            )
        if self.fixed_point_tolerance is not None:
            _float_in("Fidelity.fixed_point_tolerance", self.fixed_point_tolerance, 1e-14, 0.1)
        _float_in("Fidelity.relaxation", self.relaxation, 1e-3, 1.0)

    def replace(self, **changes) -> Fidelity:
        """A copy with some fields changed (validated), e.g. ``fid.replace(dynamics="quasi_static")``."""
        _check_fields(changes)
        return dataclasses.replace(self, **changes)

    @classmethod
    def fast(cls, **changes) -> Fidelity:
        """The CLI default: tribo-dynamic, closed-form mixed EHL friction ("ehl_formula": sliding
        and rolling loss, EHL damping), 32 positions per cycle. Measured against ``paper()``
        (benchmarks/RESULTS.md, fidelity_trade): within 8 % in Φ̄ on the six scenarios of the quick
        set, at a few hundredths of a second per point."""
        _check_fields(changes)
        return cls(**{"friction": "ehl_formula", **changes})

    @classmethod
    def paper(cls, **changes) -> Fidelity:
        """The paper's model (S. Li 2015) as far as jaxgear couples it: tribo-dynamic, thermal mixed
        EHL (film and surface temperatures, asperity contact with boundary friction μb = 0.1),
        transient (each tooth pair marched through its engagement with the squeeze term and the
        surface temperatures' memory), 32 positions per mesh cycle, 257 nodes per contact.

        Difference from the paper, stated: the roughness enters through the statistical
        (Greenwood-Tripp) asperity model, not the measured profiles in the film. The deterministic
        solver exists (``mixed_model="deterministic"``) and converges on the paper's ground
        surfaces, but the transient rung refuses it: between two mesh positions the profiles would
        move by far more than a grid cell, and its film is not grid-converged on grids a coupled
        run can afford (README, known open points: Deterministic roughness).

        The open contact parameters (``asperity_density_product``, ``shear``) keep their literal
        defaults here, which put Φ̄ at 0.28-0.60 of the paper's; ``paper_calibrated()`` is the
        same model with them set to the paper's loss level.

        The back flanks follow the paper's Eq. 1 literally (``back_flank="same"``): one backlash
        function of the mesh deflection along the drive line of action, the drive side's km(t) on
        both sides of the clearance. The other presets give the back flanks their own stiffness
        and line of action (``"mirrored"``), which this pair's rattle at 3850-4050 rpm (700 N m)
        strikes much harder: 13-47 % of the cycle in back contact against 9-23 %, DTE RMS up to
        46 µm against 12 µm, there above the 3375 rpm resonance peak (R1); both runs are in
        docs/figures (README, Results at the paper fidelity). Pass ``back_flank="mirrored"`` to
        put the back flanks' own geometry into the paper's model.
        """
        base = dict(
            back_flank="same",
            dynamics="tribo_dynamic",
            friction="ehl_mixed",
            thermal=True,
            transient=True,
            n_positions=32,
            n_nodes=257,
        )
        _check_fields(changes)
        base.update(changes)
        return cls(**base)

    @classmethod
    def paper_calibrated(cls, **changes) -> Fidelity:
        """``paper()`` with its two open contact parameters calibrated to the paper's loss level:
        the Eyring stress as the fluid traction (``shear="eyring_split"``) and the
        Greenwood-Tripp density product nβσ = 0.08 (``asperity_density_product``; 0.05 in
        ``paper()``). A fitted preset, like the calibrated blanks of
        ``presets.li2015_pair_calibrated()``: use it to study the paper's trends at the paper's
        loss level, not as a check of that level.

        What was fitted and what was not (``jaxgear figures --fidelity paper_calibrated``,
        docs/figures/paper_calibrated; benchmarks/RESULTS.md, shear_trends_asperity):

        - nβσ, a parameter the paper leaves open (REFERENCE §6), was raised to the top of its
          typical range so that the quasi-static Φ̄ at A, B, D, E (1700, 1800, 3300, 3500 rpm)
          meets the paper's (296, 310, 490, 511 W against 276, 302, 526, 532 W: −7 … +7 %).
        - The shear law is argued, not fitted: the paper's η* = η/cosh(τm/τ0) is the tangent
          viscosity of Eyring shear, right as the flow coefficient and the damping but below the
          Eyring stress τm as a traction; "eyring_split" keeps η* for the first and takes τm for
          the traction and sliding heat.
        - Then, not fitted: Ψ = 99.70-99.82 % over 500-4200 rpm, inside the paper's band (R4);
          iso-thermal above thermal by a gap growing with speed, +1.2 % to +9.3 % (R5); 60 °C
          below 90 °C (R6); polished below ground (R8); the tribo-dynamic loss above the
          quasi-static one at B and at 3500 rpm and below it at D (R3; 3500 rpm +6.2 % over the
          attractor, 543 against 511 W, where the paper has +78 %; on a 50 rpm grid the DTE peak
          falls at 3400 rpm, +2.5 %).
        - Still not the paper's: A nearly equal (−0.2 %, the paper −7 %) and C 4 % up (the paper
          equal); Φ̄ at E about half the paper's tribo-dynamic 948 W; 1500 N m raises Ψ by
          0.01-0.03 points (R7: the paper's is slightly lower); the rolling share reaches 9 % at
          4200 rpm (R9; 15 % with ``paper()``); the film temperature rise at 25° is the same at B
          and E (R11).
        """
        calibrated = dict(
            shear=CALIBRATED_SHEAR, asperity_density_product=CALIBRATED_DENSITY_PRODUCT
        )
        return cls.paper(**{**calibrated, **changes})

    @classmethod
    def auto(cls, pair, lubricant, surfaces, op, tolerance: float = 0.05, **options) -> Fidelity:
        """The cheapest rungs whose measured error stays under ``tolerance`` for this scenario.

        Logic, options and the measured table: ``jaxgear.fidelity_auto``. A Fidelity is static, so
        the reasons travel separately: ``jg.choose_fidelity`` (same arguments) returns them.
        ``base=Fidelity(...)`` keeps that Fidelity's fields other than the ladder's (μb, shear law,
        asperity constants, fixed-point settings); by default they are ``Fidelity()``'s."""
        from .fidelity_auto import auto_fidelity

        return auto_fidelity(pair, lubricant, surfaces, op, tolerance, **options)

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
        """The fixed-point tolerance in use: ``fixed_point_tolerance``, or by default 1e-4, and 3e-3
        where the contacts carry an outer iteration. The thermal and statistical-asperity Picard
        loops of the EHL solver stop once the film temperature moves by < 1 % of its rise and the
        asperity pressure by < 1e-3 ph; where they stop depends on the warm start, so the friction
        tables are reproducible only to about 1e-3 of their maximum. Measured at point E (3500 rpm,
        paper physics, 24 positions, 129 nodes): with 1e-4 the Anderson iteration flip-flops
        between two tables 9e-4 apart (relative to the maximum) until the 40-iteration cap."""
        if self.fixed_point_tolerance is not None:
            return self.fixed_point_tolerance
        picard = self.uses_ehl and (self.thermal or self.friction == "ehl_mixed")
        # frozen coupling: the contacts are solved once, outside the iteration (no Picard noise)
        return 3e-3 if picard and self.coupling == "fixed_point" else 1e-4

    @property
    def uses_ehl(self) -> bool:
        """The contacts are solved by the EHL solver (pressure and film fields exist)."""
        return self.friction in ("ehl_smooth", "ehl_mixed")

    @property
    def models_rolling(self) -> bool:
        """The friction rung gives a rolling (Poiseuille) loss and EHL damping."""
        return self.friction in ("ehl_formula", "ehl_smooth", "ehl_mixed")


def _check_fields(changes):
    fields = [f.name for f in dataclasses.fields(Fidelity)]
    unknown = set(changes) - set(fields)
    if unknown:
        raise ValueError(
            f"unknown Fidelity field(s): {', '.join(sorted(unknown))}; valid fields: "
            f"{', '.join(fields)}"
        )


def _choice(name, value, choices):
    if value not in choices:
        raise ValueError(
            f"{name} = {value!r} is not valid; valid choices: {', '.join(map(repr, choices))}"
        )


def _int_at_least(name, value, low):
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise ValueError(f"{name} = {value!r} is out of range; valid range: integer >= {low}")


def _float_in(name, value, low, high):
    if isinstance(value, bool) or not isinstance(value, int | float) or not low <= value <= high:
        raise ValueError(f"{name} = {value!r} is out of range; valid range: [{low:g}, {high:g}]")
