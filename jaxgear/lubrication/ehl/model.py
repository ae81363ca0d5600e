# ruff: noqa: F722  (jaxtyping shape strings)
"""What a solve is given: the contact (``LineContact``), the solver's configuration
(``EHLModel``: static choices and traced physical constants, ``MODEL_NUMBERS``), the choices'
valid values, and the bundle of continuous inputs the solver carries (``_Inputs``, with the
model's numbers split off by ``_split_numbers``)."""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from ..._validation import (
    check_choice,
    check_finite,
    check_integer,
    check_positive,
    check_range,
    is_concrete,
)
from ...gear.geometry import hertz_half_width, hertz_pressure
from ..lubricant import Lubricant

VISCOSITY_MODELS = ("roelands", "barus")
COMPRESSIBILITY_MODELS = ("dowson_higginson", "incompressible")
SHEAR_MODELS = ("newtonian", "eyring_paper", "eyring_exact", "eyring_split")
DEFORMATION_METHODS = ("dense", "fft", "auto")
MIXED_MODELS = ("deterministic", "statistical")
LINEAR_SOLVERS = ("dense", "krylov")
TIME_SCHEMES = ("backward_euler", "bdf2")
TRANSPORT_SCHEMES = ("eulerian", "characteristic")


# Fischer-Burmeister δ (in ph) by default (``EHLModel.fb_smoothing``): smooth and statistical
# films, deterministic rough films
_FB_SMOOTHING = 1e-8
_FB_SMOOTHING_ROUGH = 1e-6
_KRYLOV_MIN_NODES = 1025  # from this size on, linear_solver="krylov" replaces the dense LU


class LineContact(eqx.Module):
    """A smooth line contact, SI units (every field traced).

    Attributes:
        reduced_radius: R, 1/R = 1/R1 + 1/R2, m.
        load_per_width: w' = W/L, N/m.
        u1, u2: surface velocities in the rolling direction, m/s (entrainment um = (u1+u2)/2 > 0).
        e_reduced: E', 2/E' = (1−ν1²)/E1 + (1−ν2²)/E2, Pa.
        inlet_temperature: lubricant inlet (and, isothermal, film) temperature, K.
    """

    reduced_radius: Float[Array, ""] = eqx.field(converter=jnp.asarray)
    load_per_width: Float[Array, ""] = eqx.field(converter=jnp.asarray)
    u1: Float[Array, ""] = eqx.field(converter=jnp.asarray)
    u2: Float[Array, ""] = eqx.field(converter=jnp.asarray)
    e_reduced: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=2.2747e11)
    inlet_temperature: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=363.15)

    def __check_init__(self):
        check_positive("LineContact.reduced_radius", self.reduced_radius, "m")
        check_positive("LineContact.load_per_width", self.load_per_width, "N/m")
        check_finite("LineContact.u1", self.u1)
        check_finite("LineContact.u2", self.u2)
        check_positive("LineContact.e_reduced", self.e_reduced, "Pa")
        check_range("LineContact.inlet_temperature", self.inlet_temperature, 200.0, 600.0, unit="K")
        if is_concrete((self.u1, self.u2)):
            um = 0.5 * (np.asarray(self.u1) + np.asarray(self.u2))
            if not np.all(um > 0):
                raise ValueError(
                    f"LineContact.u1, u2 give the entrainment velocity (u1+u2)/2 = {um} m/s, "
                    "out of range; valid range: (0, inf) m/s"
                )

    @property
    def rolling_velocity(self):
        """um = (u1 + u2)/2, m/s."""
        return 0.5 * (self.u1 + self.u2)

    @property
    def sliding_velocity(self):
        """us = u1 − u2, m/s."""
        return self.u1 - self.u2

    @property
    def hertz_half_width(self):
        """b = √(8 w' R/(π E')), m."""
        return hertz_half_width(self.load_per_width, self.reduced_radius, self.e_reduced)

    @property
    def hertz_pressure(self):
        """ph = √(w' E'/(2π R)), Pa."""
        return hertz_pressure(self.load_per_width, self.reduced_radius, self.e_reduced)


def _float64(value):
    """A model constant as a float64 array (a Python float would be a static leaf: one compilation
    per value, and no derivative)."""
    if isinstance(value, bool | str):
        raise ValueError(f"{value!r} is not valid; valid: a real number")
    return jnp.asarray(value, dtype=jnp.result_type(float))


def _float64_or_none(value):
    return None if value is None else _float64(value)


#: EHLModel's physical constants: traced numbers (every other field is a static choice)
MODEL_NUMBERS = (
    "boundary_friction",
    "asperity_density_product",
    "asperity_slope_ratio",
    "limiting_shear_coefficient",
)


class EHLModel(eqx.Module):
    """Configuration of ``solve_ehl``: static choices (changing one recompiles) and the contact's
    physical constants ``MODEL_NUMBERS`` (μb, nβσ, σ/β, Λ: float64 arrays, traced: changing one
    never recompiles, and the solution can be differentiated with respect to each). Methods:
    REFERENCE §5, §8; S. Li, Tribol. Int. 88 (2015).

    Attributes:
        n_nodes: grid nodes N, ≥ 17 (default 257); N − 1 should hold a power of 2 for grid
            sequencing.
        x_in, x_out: domain in Hertz half-widths, x_in < 0 < x_out (default −4.5, 1.5; widened
            for thick films by ``auto_domain``).
        auto_domain: widen the inlet to √(50 H_est) and the outlet to 1.2 √(2 H_est) when larger,
            H_est the Moes central film in Hertz units (fully flooded inlet at low M). Default True.
        viscosity: "roelands" (default) or "barus".
        compressibility: "dowson_higginson" (default) or "incompressible".
        shear: "newtonian", "eyring_paper" (default; η* = η/cosh(τm/τ0), paper Eq. 4),
            "eyring_exact" (τ = τ0 asinh(η us/(τ0 h))) or "eyring_split". It enters Reynolds' flow
            coefficient and the friction/heat terms. η* is the tangent viscosity dτm/dγ̇ of Eyring
            Couette flow and τm h/us its secant: "eyring_split" uses the secant (the stress τm) in
            the sliding friction and heat, and η* in the flow coefficient, the Poiseuille heat and
            the damping (the response to a small pressure flow or sliding-speed change on top of
            the shear).
        fb_smoothing: δ of the Fischer-Burmeister function, in ph, in (0, 1e-2]; None (default):
            1e-8, and 1e-6 for deterministic rough films (``smoothing``). δ relaxes the
            complementarity to P·g = δ²/2, so where the exact pressure is below δ ph it is held
            near δ ph, above all at the first node past the inlet's P = 0, whose Poiseuille heat
            grows as 1/Δx: at 1e-6 a smooth film's rolling loss grows ~5× from 257 to 2049 nodes,
            at 1e-8 by under 2 %. Deterministic rough films keep 1e-6, where their relaxed warm
            starts converge (their rolling heat is the asperity edges').
        tolerance: ‖F‖∞ below which a Newton solve has converged, in (0, 1e-2] (default 1e-9).
        max_iterations: Newton iterations per grid level and per continuation step (default 30).
        coarsest_nodes: smallest grid of the sequence, ≥ 17 (default 65; above ``n_nodes``: a
            single grid).
        continuation_steps: steps of the piezo-viscous exponent (s = 1/n … 1) on the coarsest grid
            in the second cold attempt (the first uses s = 1/4, 1/2, 3/4, 1); default 12. From
            1025 nodes on, a third attempt (smooth and statistical films) takes those steps up to
            s = 0.75, sequences to the finest grid there and continues s → 1 on it adaptively.
        warm_iterations: Newton iterations allowed for a warm start before falling back to a cold
            solve (default 12).
        deformation: "dense", "fft" (DC-FFT for residuals; the Jacobian stays dense) or "auto"
            (default: fft above 1025 nodes). Grids that take Krylov directions
            (``linear_solver``) always use DC-FFT.
        wedge_order: upwind order of the wedge term, 1 or 2 (default).
        thermal: thermal EHL (REFERENCE §5): the film's mean temperature (paper Eq. 8 profile, with
            convection) and both surface temperatures (Jaeger, paper Eq. 9) from the heat flux of
            Eq. 12, viscosity and density re-evaluated at the film temperature, iterated
            (Picard, warm-started, the temperature update relaxed by Aitken's Δ² rule) until the
            film temperature moves by < 1 % of its rise, at most ``thermal_iterations`` times.
            False (default) skips all of it.
        thermal_iterations: most outer temperature updates; None (default): 4 for smooth and
            statistical films, 32 for deterministic roughness (whose hot films need 15-23 relaxed
            updates).
        thermal_rtol, thermal_atol: the temperature updates stop (and the solution counts as
            thermally converged) once the film temperature the film implies is within
            max(thermal_rtol × its largest rise, thermal_atol K) of the one it was solved with;
            thermal_rtol in (0, 0.5] (default 0.01), thermal_atol in (0, 10] K (default 0.05). That
            error does not shrink with the time step: a transient passage's film temperature
            converges in Δt only with tighter values (e.g. 1e-4 and 1e-4 K, with more
            ``thermal_iterations``).
        boundary_friction: μb of asperity contact, in [0, 1] (default 0.1, the paper's).
        contact_threshold: a node is in asperity contact where h is below this fraction of the
            smooth central-film estimate (there the Poiseuille flow has vanished: ε ∝ h³ < 1e-7 of
            its smooth value, and Reynolds reduces to paper Eq. 4b/4c). Smooth indicator. In
            [1e-4, 0.1] (default 5e-3).
        roughness_steps: n, the first step 1/n of the adaptive continuation in the roughness
            amplitude of a cold deterministic mixed solve, which starts from the smooth solution.
            Default 8: about 10 % fewer Newton iterations along an engagement than 4, with the
            same steps converged.
        mixed: how rough surfaces are treated. "deterministic" (default): the roughness profiles
            in the film (paper Eq. 5) with the unified Reynolds equation (Hu-Zhu); needs
            Δx ≲ 2 µm. A cold solve continues adaptively in the roughness amplitude from the
            smooth film; in deep mixed films (λ ≈ 0.1, 513 nodes and finer) that continuation can
            stall, and the film is then reached by the pseudo-time march
            (``pseudo_transient_steps``). A continuation that accepted at least one step and then
            failed is not repeated by a second cold attempt (it would start from the same smooth
            film and take the same path).
            "statistical": the film on the surfaces' mean planes (``asperity.py``): the film
            unknown is the mean-plane separation d = h0 + x²/2R + V(p), which may be negative;
            the flow carries the average gap h_T(d) with Patir and Cheng's pressure flow factor
            (the shear flow factor, ∝ Rq1² − Rq2², is left out: zero for surfaces of equal
            roughness); the Greenwood-Tripp asperity pressure p_a(d) = K′E′F_{5/2}(d/σ) is part
            of the pressure that loads and deforms the solids, solved in the same Newton system
            as the fluid's (its unknown is the total pressure); the fluid shears over the
            non-contact fraction 1 − A_r/A at the average gap, the asperities carry μb p_a. It
            spans full film (λ ≳ 3: the smooth film) to boundary lubrication (λ → 0: the dry
            rough contact) and needs only the composite roughness σ.
        asperity_density_product, asperity_slope_ratio: nβσ in [1e-4, 1] (default 0.05) and σ/β
            in [1e-6, 1] (default 0.01) of the statistical model [typical values for ground
            steel].
        limiting_shear_coefficient: Λ of a limiting shear stress τL = Λ p (Bair & Winer) capping,
            smoothly, the fluid shear stress of the friction and the sliding heat at the local
            fluid pressure (``rheology.log_limited_stress``), in (0, 1]; None (default): no cap.
            Typical Λ 0.03-0.1. The flow coefficient and the damping keep the shear law's.
        relaxation_sweeps: distributive Jacobi sweeps (``_distributive_relaxation``) run from a
            deterministic rough film's warm start before its Newton iterations where the roughness
            has moved since the start's solution (each step of a transient passage). If Newton
            fails but got close, two more rounds of half as many sweeps from where it stopped,
            then (passage steps) a start from the half step; then the cold solve. 0: none, Newton
            from the plain warm start, which then nearly always falls back to the cold solve.
            None (default): 100 iso-thermal, 50 thermal (``_relaxation_sweeps``).
        pseudo_transient_steps: the last attempt of a deterministic rough film whose other
            attempts failed: pseudo-transient continuation (``_pseudo_march``), at most this many
            pseudo-time steps (each a continuation in the roughness from the smooth film with a
            squeeze term towards the last state, Δτ doubling from Δx/ur), then the steady problem
            from where the march settled. Default 64; 0: no such attempt. The steps of a transient
            passage (``solve_ehl_passage``) never take it.
        temperature_steps: a thermal deterministic rough film re-solved at updated temperatures
            (each update of the temperature iteration) whose warm Newton fails gets a
            continuation in the temperature rise from the one its start was solved at, first
            step 1/``temperature_steps`` of the update (``_temperature_continuation``), before
            the relaxed rounds and the cold solve: ~35 Newton iterations where the cold solve
            takes ~200. Default 2; 0: none.
        linear_solver: how the Newton directions of grids from 1025 nodes are found. "dense"
            (default): the assembled Newton matrix's LU (O(N³), single precision refined on large
            grids). "krylov": GMRES on Jacobian-vector products by forward mode through the
            residual (DC-FFT deformation), preconditioned by block-Jacobi LUs of 128-node blocks
            and the load row (``_krylov_direction``): O(N log N) a Krylov vector, no N × N
            matrix. The same discrete system to the same tolerance (solutions within 1e-6);
            coarser levels of the grid sequence keep the dense LU, and the implicit derivative
            keeps its dense rule. A deterministic passage step costs 2.2-3.5× less on 1025-2049
            nodes (studies/mixed_thermal, ``mixed_held_steps``).
        time_scheme: the squeeze term ∂(ρh)/∂t of a transient passage (``solve_ehl_passage``).
            "backward_euler" (default): first order. "bdf2": second-order backward differences
            on variable steps (the first transient step, and a step after a failed one, backward
            Euler); the same residual, one more film level carried. In a thermal passage the
            film temperature's ∂ϕm/∂t and the solids' steps in depth are BDF2 too, the solids'
            two earlier fields read at their material points' feet by cubic interpolation: a
            thermal passage then converges at second order in Δt, once the material that saw the
            start from cold has left the contact (a flux switched on heats the solids as √t) and
            with tight ``thermal_rtol``. A deterministic rough film's loss needs it: on the
            polished film at Δt = Δx/ur backward Euler is 36 % above the Δt → 0 limit, BDF2 at
            Δx/(2 ur) 6 % (studies/time_steps).
        transport: how a transient step discretises the film's transport u_m ∂(ρh)/∂x + ∂(ρh)/∂t.
            "eulerian" (default): the upwind wedge term plus the squeeze term at the node.
            "characteristic": the two together as the material derivative D(ρh)/Dt along the
            characteristics x − ∫ ur dt (semi-Lagrangian, of ``time_scheme``'s order): the
            previous films are read at the characteristics' feet, their roughness evaluated from
            the profiles there (``_film_at_feet``). A film carried at the mean velocity
            (where the Poiseuille flow has vanished, as in a Hertz zone) is then moved exactly
            when a step carries it a whole number of cells, and a steady film keeps the steady
            wedge (first- or second-order upwind at Δt = Δx/ur). The Eulerian terms instead damp
            and lag a roughness a few cells long, and the film answers that with pressure flow,
            so with Poiseuille heat: on the polished film the characteristic loss agrees within
            2 % over Δt = 0.5-4 Δx/ur, the Eulerian ones vary 2.5× (studies/time_steps). Steady solves have no squeeze term and ignore it. Use it with
            BDF2 and steps of a few cells: for a steady film it is the upwind difference over the
            C cells a step spans, so a step must stay short against the outlet constriction
            (C Δx ≲ 0.05 b keeps the minimum film within 2 %); the coupled model's transient rung,
            a third of a Hertz width a step, is no place for it.
        hardness: None (default: elastic solids, no bound on the pressure) or the pressure at
            which the surfaces yield, Pa, in [1e8, 1e11] (elastic-perfectly plastic; ~7e9 for
            case-hardened gear steel, about three times its yield stress). Where the pressure
            reaches it, it stays there and the gap opens by a plastic gap δ ≥ 0
            (``EHLSolution.plastic_gap``) that keeps the Reynolds equation, so the flow, at every
            node: P and δ complementary, through one unknown per node (``_Level.plastic``). It
            bounds the asperity pressure of deterministic roughness, where an elastic half-space
            puts none (above 10 GPa on the ground surfaces). A passage
            (``passage.solve_ehl_passage``) runs the surfaces in: what a step flattens stays in
            both profiles (half each) and travels with each surface, so a later step's δ is only
            what more yields. On the statistical film (``mixed="statistical"``) it caps the
            total (fluid plus asperity) pressure.
    """

    n_nodes: int = eqx.field(static=True, default=257)
    x_in: float = eqx.field(static=True, default=-4.5)
    x_out: float = eqx.field(static=True, default=1.5)
    auto_domain: bool = eqx.field(static=True, default=True)
    viscosity: str = eqx.field(static=True, default="roelands")
    compressibility: str = eqx.field(static=True, default="dowson_higginson")
    shear: str = eqx.field(static=True, default="eyring_paper")
    fb_smoothing: float | None = eqx.field(static=True, default=None)
    tolerance: float = eqx.field(static=True, default=1e-9)
    max_iterations: int = eqx.field(static=True, default=30)
    coarsest_nodes: int = eqx.field(static=True, default=65)
    continuation_steps: int = eqx.field(static=True, default=12)
    warm_iterations: int = eqx.field(static=True, default=12)
    deformation: str = eqx.field(static=True, default="auto")
    wedge_order: int = eqx.field(static=True, default=2)
    thermal: bool = eqx.field(static=True, default=False)
    thermal_iterations: int | None = eqx.field(static=True, default=None)
    thermal_rtol: float = eqx.field(static=True, default=0.01)
    thermal_atol: float = eqx.field(static=True, default=0.05)
    boundary_friction: Float[Array, ""] = eqx.field(converter=_float64, default=0.1)
    contact_threshold: float = eqx.field(static=True, default=5e-3)
    roughness_steps: int = eqx.field(static=True, default=8)
    mixed: str = eqx.field(static=True, default="deterministic")
    asperity_density_product: Float[Array, ""] = eqx.field(converter=_float64, default=0.05)
    asperity_slope_ratio: Float[Array, ""] = eqx.field(converter=_float64, default=0.01)
    limiting_shear_coefficient: Float[Array, ""] | None = eqx.field(
        converter=_float64_or_none, default=None
    )
    relaxation_sweeps: int | None = eqx.field(static=True, default=None)
    pseudo_transient_steps: int = eqx.field(static=True, default=64)
    temperature_steps: int = eqx.field(static=True, default=2)
    linear_solver: str = eqx.field(static=True, default="dense")
    time_scheme: str = eqx.field(static=True, default="backward_euler")
    transport: str = eqx.field(static=True, default="eulerian")
    hardness: float | None = eqx.field(static=True, default=None)

    def __check_init__(self):
        if not isinstance(self.n_nodes, int) or self.n_nodes < 17:
            raise ValueError(
                f"EHLModel.n_nodes = {self.n_nodes!r} is out of range; valid range: [17, inf)"
            )
        if not (self.x_in < 0.0 < self.x_out):
            raise ValueError(
                f"EHLModel.x_in, x_out = {self.x_in}, {self.x_out} are out of range; "
                "valid range: x_in < 0 < x_out (Hertz half-widths)"
            )
        check_choice("EHLModel.viscosity", self.viscosity, VISCOSITY_MODELS)
        check_choice("EHLModel.compressibility", self.compressibility, COMPRESSIBILITY_MODELS)
        check_choice("EHLModel.shear", self.shear, SHEAR_MODELS)
        check_choice("EHLModel.deformation", self.deformation, DEFORMATION_METHODS)
        check_choice("EHLModel.wedge_order", self.wedge_order, (1, 2))
        check_choice("EHLModel.mixed", self.mixed, MIXED_MODELS)
        check_choice("EHLModel.linear_solver", self.linear_solver, LINEAR_SOLVERS)
        check_choice("EHLModel.time_scheme", self.time_scheme, TIME_SCHEMES)
        check_choice("EHLModel.transport", self.transport, TRANSPORT_SCHEMES)
        check_range("EHLModel.asperity_density_product", self.asperity_density_product, 1e-4, 1.0)
        check_range("EHLModel.asperity_slope_ratio", self.asperity_slope_ratio, 1e-6, 1.0)
        if self.limiting_shear_coefficient is not None:
            check_range(
                "EHLModel.limiting_shear_coefficient",
                self.limiting_shear_coefficient,
                0.0,
                1.0,
                low_inclusive=False,
            )
        if self.hardness is not None:
            check_range("EHLModel.hardness", self.hardness, 1e8, 1e11)
        if self.fb_smoothing is not None:
            check_range("EHLModel.fb_smoothing", self.fb_smoothing, 0.0, 1e-2, low_inclusive=False)
        check_range("EHLModel.tolerance", self.tolerance, 0.0, 1e-2, low_inclusive=False)
        check_range("EHLModel.thermal_rtol", self.thermal_rtol, 0.0, 0.5, low_inclusive=False)
        check_range("EHLModel.thermal_atol", self.thermal_atol, 0.0, 10.0, low_inclusive=False)
        for name in ("thermal", "auto_domain"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(
                    f"EHLModel.{name} = {getattr(self, name)!r} is not valid; valid: True, False"
                )
        # the coarsest grid of the sequence (a larger value than n_nodes means a single grid)
        check_integer("EHLModel.coarsest_nodes", self.coarsest_nodes, 17)
        if self.relaxation_sweeps is not None:
            check_integer("EHLModel.relaxation_sweeps", self.relaxation_sweeps, 0)
        check_integer("EHLModel.pseudo_transient_steps", self.pseudo_transient_steps, 0)
        check_integer("EHLModel.temperature_steps", self.temperature_steps, 0)
        check_range("EHLModel.boundary_friction", self.boundary_friction, 0.0, 1.0)
        check_range(
            "EHLModel.contact_threshold", self.contact_threshold, 1e-4, 0.1, low_inclusive=True
        )
        for name in (
            "max_iterations",
            "continuation_steps",
            "warm_iterations",
            "thermal_iterations",
            "roughness_steps",
        ):
            v = getattr(self, name)
            if name == "thermal_iterations" and v is None:
                continue
            if not isinstance(v, int) or v < 1:
                raise ValueError(f"EHLModel.{name} = {v!r} is out of range; valid range: [1, inf)")

    def smoothing(self, rough: bool) -> float:
        """The Fischer-Burmeister δ (in ph) of a solve: ``fb_smoothing``, or by default 1e-8, and
        1e-6 for a deterministic rough film (``rough``); see ``fb_smoothing``."""
        if self.fb_smoothing is not None:
            return self.fb_smoothing
        return _FB_SMOOTHING_ROUGH if rough else _FB_SMOOTHING

    @property
    def grid_sizes(self) -> tuple[int, ...]:
        """Node counts of the grid sequence, coarse to fine."""
        sizes = [self.n_nodes]
        while (sizes[-1] - 1) % 2 == 0 and (sizes[-1] - 1) // 2 + 1 >= self.coarsest_nodes:
            sizes.append((sizes[-1] - 1) // 2 + 1)
        return tuple(reversed(sizes))

    def use_fft(self, n: int) -> bool:
        return (
            self.deformation == "fft"
            or (self.deformation == "auto" and n > 1025)
            or self.use_krylov(n)
        )

    def use_krylov(self, n: int) -> bool:
        """Whether the Newton directions on an n-node grid come from GMRES (``linear_solver``)."""
        return self.linear_solver == "krylov" and n >= _KRYLOV_MIN_NODES


class _Numbers(eqx.Module):
    """EHLModel's physical constants, carried with the inputs (the θ of the implicit derivative)
    while the static rest of the model selects the program."""

    boundary_friction: Float[Array, ""]
    asperity_density_product: Float[Array, ""]
    asperity_slope_ratio: Float[Array, ""]
    limiting_shear_coefficient: Float[Array, ""]  # read only where the model's cap is on


def _split_numbers(model: EHLModel) -> tuple[_Numbers, EHLModel]:
    """(the model's numbers, the model with them taken out): the second is hashable, a static
    argument of the solver's programs; its ``limiting_shear_coefficient`` is True where the cap is
    on and None where it is off."""
    cap = model.limiting_shear_coefficient
    numbers = _Numbers(
        model.boundary_friction,
        model.asperity_density_product,
        model.asperity_slope_ratio,
        jnp.zeros((), dtype=jnp.result_type(float)) if cap is None else cap,
    )
    fields = ("boundary_friction", "asperity_density_product", "asperity_slope_ratio")
    static = eqx.tree_at(
        lambda m: tuple(getattr(m, f) for f in fields), model, replace=(None,) * len(fields)
    )
    if cap is not None:
        static = eqx.tree_at(lambda m: m.limiting_shear_coefficient, static, replace=True)
    return numbers, static


class _Inputs(eqx.Module):
    """Every continuous input of a solve (the θ of the implicit differentiation)."""

    contact: LineContact
    lubricant: Lubricant
    rho_h_previous: Float[Array, " N"]  # kg/m², on this solve's nodes
    inv_time_step: Float[Array, ""]  # 1/Δt, 1/s (0: steady)
    film_offset: Float[Array, " N"]  # m, added to h: −(S1 + S2), the roughness of paper Eq. (5)
    temperature_rise: Float[Array, " N"]  # K, mean film temperature above the inlet, at the nodes
    roughness: Float[Array, ""]  # m, composite roughness σ (statistical mixed model)
    numbers: _Numbers  # the model's physical constants (``MODEL_NUMBERS``), traced
    # m, the film offset with the roughness where it stood at the previous time step (transient
    # deterministic passage steps: a start generator, see ``_half_step_start``; None: none)
    film_offset_previous: Float[Array, " N"] | None = None
    # K, the film temperature rise the start's solution was solved at (a deterministic film's
    # re-solve at updated temperatures: see ``_temperature_continuation``; None: none)
    temperature_rise_previous: Float[Array, " N"] | None = None
    # a deterministic rough film's solve (set by ``_solve_core``: the Newton matrix's LU is single
    # precision on coarser grids, see ``_MIXED_PRECISION_NODES_ROUGH``)
    rough: bool = eqx.field(static=True, default=False)
    # the statistical mixed film (``EHLModel.mixed = "statistical"`` on rough surfaces): the film
    # unknown is the mean-plane separation, the flow carries its average gap, and the pressure
    # unknown is the total (fluid plus Greenwood-Tripp asperity) pressure
    mean_plane: bool = eqx.field(static=True, default=False)
