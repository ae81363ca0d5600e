# ruff: noqa: F722  (jaxtyping shape strings)
"""Isothermal smooth line-contact EHL: steady and one-step transient, Newtonian or Eyring, with
implicit gradients.

Method (EHL_NOTES, REFERENCE §8): Hertz-scaled variables; unknowns P at the N nodes and the film
offset
H0, with the load balance Δ Σ P = π/2 as the extra row of a bordered Newton system; cavitation as a
smoothed Fischer-Burmeister complementarity (``reynolds.py``); exact log-kernel deformation
(``deformation.py``). The Jacobian is assembled exactly: the local (banded) derivatives of the
Reynolds
operator with respect to P and H come from 8 forward-mode products with coloured seeds, the dense
part is
the banded H-derivative times the influence matrix. Robustness across the (M, L) range comes from
continuation in the piezo-viscous exponent on the coarsest grid, coarse-to-fine grid sequencing,
and a
backtracking line search on the residual norm; every loop is a ``lax.while_loop``/``lax.scan``.
A failed solve reports ``converged=False`` with its residual and finite values, never NaN.

Gradients: the converged fine-grid solution u*(θ) of F(u, θ) = 0 is differentiated by the implicit
function theorem, du = −(∂F/∂u)⁻¹ (∂F/∂θ) dθ (a ``jax.custom_jvp``; reverse mode transposes it),
never
through the iterations.

Outputs follow S. Li, Tribol. Int. 88 (2015): heat flux Eq. (12), damping Eq. (13), friction Eq.
(15).
"""

from __future__ import annotations

import dataclasses
import functools

import equinox as eqx
import jax
import jax.numpy as jnp
import jax.scipy.linalg
import numpy as np
from jaxtyping import Array, Bool, Float, Int

from .._solvers.lazy_cond import cond_any_member
from .._validation import (
    check_choice,
    check_finite,
    check_integer,
    check_positive,
    check_range,
    is_concrete,
)
from ..gear.geometry import hertz_half_width, hertz_pressure
from . import asperity as asperity_mod
from . import deformation as deformation_mod
from . import rheology
from . import thermal as thermal_mod
from .lubricant import Lubricant
from .reynolds import (
    fischer_burmeister,
    reynolds_residual,
    smooth_positive,
    wedge_term,
)

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
_LOG_VISCOSITY_CAP = 500.0  # cap on ln(η/η0): keeps iterates finite (η/η0 ≤ e^500)
_FLOOR_FRACTION = 1e-3  # smooth film floor inside ε, relative to the reference film
# smoothing of the pressure limit's kink P = min(v, P_cap) (``EHLModel.hardness``), in ph
_PLASTIC_SMOOTHING = 1e-4
# plastic gap per unit of v above the limit, × the reference film H_ref (the unknowns' scaling)
_PLASTIC_GAP_SCALE = 1.0


# -------------------------------------------------------------------------------------------------
# Inputs
# -------------------------------------------------------------------------------------------------
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
    never recompiles, and the solution can be differentiated with respect to each).

    Attributes:
        n_nodes: grid nodes N; (N − 1) should hold a power of 2 for grid sequencing.
        x_in, x_out: domain in Hertz half-widths (widened automatically for thick films,
        ``auto_domain``).
        auto_domain: widen the inlet to √(50 H_est) and the outlet to 1.2 √(2 H_est) when larger,
            H_est the Moes central film in Hertz units (fully flooded inlet at low M).
        viscosity: "roelands" or "barus".
        compressibility: "dowson_higginson" or "incompressible".
        shear: "newtonian", "eyring_paper" (η* = η/cosh(τm/τ0), paper Eq. 4), "eyring_exact"
            (τ = τ0 asinh(η us/(τ0 h))) or "eyring_split". It enters Reynolds' flow coefficient and
            the friction/heat terms. η* is the tangent viscosity dτm/dγ̇ of Eyring Couette flow and
            τm h/us its secant: "eyring_split" uses the secant (the stress τm) in the sliding
            friction and heat, and η* in the flow coefficient, the Poiseuille heat and the damping
            (the response to a small pressure flow or sliding-speed change on top of the shear).
        fb_smoothing: δ of the Fischer-Burmeister function (in ph); None (default): 1e-8, and
            1e-6 for deterministic rough films (``smoothing``). δ relaxes the complementarity to
            P·g = δ²/2, so where the exact pressure is below δ ph it is held near δ ph instead,
            above all at the first node past the inlet's P = 0; under the thick inlet film that
            jump's Poiseuille heat grows as 1/Δx. Measured (1000 rpm, SRR 0.3, smooth, 257 / 513
            / 1025 / 2049 nodes): rolling loss 158.6 / 191.6 / 308.4 / 753.8 W/m at δ = 1e-6
            (every film's default until 2026-11-29), 146.4 / 148.2 / 148.6 / 148.8 W/m at 1e-8
            and 1e-10; the sliding loss and the Newton iterations the same. Deterministic rough
            films keep 1e-6: their relaxed warm starts were tuned there, and at 1e-8 a step of
            the ground film at speed E falls back to the cold solve (99 Newton iterations against
            8; tests/test_mixed_thermal.py), while their rolling heat is the asperity edges'.
        tolerance: ‖F‖∞ below which a Newton solve has converged.
        max_iterations: Newton iterations per grid level (and per continuation step).
        coarsest_nodes: smallest grid of the sequence.
        continuation_steps: steps of the piezo-viscous exponent (s = 1/n … 1) on the coarsest grid
            in the second cold attempt (the first uses s = 1/4, 1/2, 3/4, 1). From 1025 nodes on, a
            third attempt (smooth and statistical films) takes those steps up to s = 0.75, sequences
            to the finest grid there and continues s → 1 on it adaptively.
        warm_iterations: Newton iterations allowed for a warm start before falling back to a cold
        solve.
        deformation: "dense", "fft" (DC-FFT for residuals; the Jacobian stays dense), "auto" (fft
            above 1025 nodes). Grids that take Krylov directions (``linear_solver``) always use
            DC-FFT.
        wedge_order: upwind order of the wedge term (1 or 2).
        thermal: thermal EHL (REFERENCE §5): the film's mean temperature (paper Eq. 8 profile, with
            convection) and both surface temperatures (Jaeger, paper Eq. 9) from the heat flux of
            Eq. 12, viscosity and density re-evaluated at the film temperature, iterated
            (Picard, warm-started, the temperature update relaxed by Aitken's Δ² rule) until the
            film temperature moves by < 1 % of its rise, at most ``thermal_iterations`` times.
            False skips all of it.
        thermal_iterations: most outer temperature updates; None: 4 for smooth and statistical
            films, 32 for deterministic roughness (whose hot films need 15-23 relaxed updates).
        thermal_rtol, thermal_atol: the temperature updates stop (and the solution counts as
            thermally converged) once the film temperature the film implies is within
            max(thermal_rtol × its largest rise, thermal_atol K) of the one it was solved with.
            Defaults 0.01 and 0.05 K. That error does not shrink with the time step: a transient
            passage's film temperature converges in Δt only with tighter values (measured on a
            bump passing a thermal film, 129 nodes, 2000 rpm, backward Euler: 0.24 K apart
            both between Δt/2 and Δt/8 and between Δt/4 and Δt/8 with the defaults, out of a
            3.2 K rise; at 1e-4 and 1e-4 K first order, 0.024 and 0.008 K,
            tests/test_time_scheme.py; raise ``thermal_iterations`` with them).
        boundary_friction: μb of asperity contact (paper: 0.1).
        contact_threshold: a node is in asperity contact where h is below this fraction of the
            smooth central-film estimate (there the Poiseuille flow has vanished: ε ∝ h³ < 1e-7 of
            its smooth value, and Reynolds reduces to paper Eq. 4b/4c). Smooth indicator.
        roughness_steps: n, the first step 1/n of the adaptive continuation in the roughness
            amplitude of a cold deterministic mixed solve, which starts from the smooth solution.
            Measured on one engagement along the path (257 nodes, ground, 900 steps): n = 8 takes
            30 670 Newton iterations at 3500 rpm and 78 925 at 500 rpm, against 35 055 and 87 160
            with n = 4 (38 025 / 96 971 with 2, 35 848 / 92 497 with 3, 33 327 / 80 941 with 6,
            28 498 / 77 100 with 16), 892-899 of the steps converged with any of these; the steady
            solves at the pitch contact (257-1025 nodes) take 15 fewer iterations with 8 than with 4
            where they converge, to the same solutions, and fail where 4 failed (500 rpm, 513 and
            1025 nodes).
        mixed: how rough surfaces are treated. "deterministic": the roughness profiles in the film
            (paper Eq. 5) with the unified Reynolds equation (Hu-Zhu); needs Δx ≲ 2 µm. A cold
            solve continues adaptively in the roughness amplitude from the smooth film. Measured
            with ``presets.ground()`` at the paper's pitch contact: converges at 3500 rpm
            (λ ≈ 0.4) on 257-1025 nodes; at 500 rpm (λ ≈ 0.1) on 257 nodes, while on 513 and 1025
            nodes the continuation stalls (at 0.775 and 0.43 of the roughness) and the film is
            reached by the pseudo-time march (``pseudo_transient_steps``). A continuation that
            accepted at least one step and then failed is not repeated by a second cold attempt
            (it would start from the same smooth film and take the same path).
            "statistical": the mean film with the Greenwood-Tripp asperity pressure p_a(h)
            (``asperity.py``) added to the load and the deformation (Johnson-Greenwood-Poon load
            sharing), iterated with the temperatures; robust down to λ → 0; it needs only the
            composite roughness σ.
        asperity_density_product, asperity_slope_ratio: nβσ and σ/β of the statistical model
            [typical values for ground steel: 0.05, 0.01].
        asperity_relaxation: under-relaxation of the asperity-pressure update (statistical).
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
            Measured over one engagement along the path (900 steps, 257 nodes), against 0 in the
            same hour: 108 against 172 s at 3500 rpm, 150 against 172 s at 500 rpm. None
            (default): 100 iso-thermal, 50 thermal (``_relaxation_sweeps``).
        pseudo_transient_steps: the last attempt of a deterministic rough film whose other
            attempts failed: pseudo-transient continuation (``_pseudo_march``), at most this many
            pseudo-time steps (each a continuation in the roughness from the smooth film with a
            squeeze term towards the last state, Δτ doubling from Δx/ur), then the steady problem
            from where the march settled. 0: no such attempt. The steps of a transient passage
            (``solve_ehl_passage``) never take it. Measured at 500 rpm, pitch contact, ground,
            where the direct solve fails: 700 N m on 513 nodes 34 s, on 1025 nodes 103 s, 1500 N m
            on 513 nodes 22 s after compilation; a deterministic solve compiles ~1.5 s longer.
        temperature_steps: a thermal deterministic rough film re-solved at updated temperatures
            (each update of the temperature iteration) whose warm Newton fails gets a
            continuation in the temperature rise from the one its start was solved at, first
            step 1/``temperature_steps`` of the update (``_temperature_continuation``), before
            the relaxed rounds and the cold solve. 0: none. Measured on one thermal engagement
            along the path (3500 rpm, 257 nodes, 900 steps): 514 continuations, 464 converged,
            35 Newton iterations each against the cold solve's ~200; 100 898 against 141 633
            Newton iterations in all, 88.9 against 104.6 s, the same 895 steps converged.
        linear_solver: how the Newton directions of grids from 1025 nodes are found. "dense"
            (default): the assembled Newton matrix's LU (O(N³), single precision refined on large
            grids). "krylov": GMRES on Jacobian-vector products by forward mode through the
            residual (DC-FFT deformation), preconditioned by block-Jacobi LUs of 128-node blocks
            and the load row (``_krylov_direction``): O(N log N) a Krylov vector, no N × N
            matrix. The same discrete system to the same tolerance (solutions within 1e-6,
            tests/test_ehl_krylov.py); coarser levels of the grid sequence keep the dense LU, and
            the implicit derivative keeps its dense rule. Measured on the held pitch contact at
            3500 rpm (RESULTS ``mixed_held_steps``): a step of the deterministic passage 2.2-3.5×
            cheaper on 1025-2049 nodes (ground 2.25 against 7.97 s on 2049 nodes, polished 0.13
            against 0.33 s), the same films. The polished film's warm starts then converge
            without the relaxation sweeps (``relaxation_sweeps=0``: 0.08 s a step).
        time_scheme: the squeeze term ∂(ρh)/∂t of a transient passage (``solve_ehl_passage``).
            "backward_euler" (default): first order. "bdf2": second-order backward differences
            on variable steps (the first transient step, and a step after a failed one, backward
            Euler); the same residual, one more film level carried. In a thermal passage the
            film temperature's ∂ϕm/∂t and the solids' steps in depth are BDF2 too, the solids'
            two earlier fields read at their material points' feet by cubic interpolation: a
            thermal passage then converges at second order in Δt on a fixed grid (a speed
            transient, tests/test_time_scheme.py: backward Euler's 0.076 / 0.020 K at Δt/2 /
            Δt/4 against Δt/8, BDF2's 0.022 / 0.0047 K) and on the grid a load transient moves
            (0.0027 / 0.00057 K), once the material that saw the start from cold has left the
            contact (a flux switched on heats the solids as √t) and with tight ``thermal_rtol``. A
            deterministic rough film's loss needs it: on the polished film at
            the pitch contact (3500 rpm, 2049 nodes; RESULTS ``mixed_time_steps``) backward Euler at
            Δt = Δx/ur is 36 % above the Δt → 0 limit, BDF2 25 % there and 6 % at Δx/(2 ur),
            with as many Newton iterations a step (both Eulerian; see ``transport``).
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
            so with Poiseuille heat. Measured at the pitch contact (3500 rpm, SRR 0.3; RESULTS
            ``mixed_time_steps``): on the polished film the loss at Δt = 0.5, 1, 2 and 4 Δx/ur
            agrees within 1.9 % on 2049 nodes (the Eulerian schemes: 2.5× between C = 4 and
            their Δt → 0 limit) and 1025 nodes give within 4 % of it (Eulerian: 1.8×); on the
            ground film (257 nodes) the loss is ~4× below the Eulerian schemes', whose excess is
            Poiseuille heat. Steady solves have no squeeze term and ignore it. Use it with BDF2
            and steps of a few cells: for a steady film it is the upwind difference over the C
            cells a step spans (backward Euler: first order), so a step must stay short against
            the outlet constriction. Measured on a held smooth film (2000 rpm, BDF2, 11 steps):
            the minimum film moves by ≤ 2 % up to C Δx = 0.05 b (513 nodes, C ≤ 4), by 6 % at
            0.09 b (513, C = 8), and by 85 % at 0.19 b (129, C = 4); the coupled model's
            transient rung, a third of a Hertz width a step, is no place for it.
        hardness: None (default: elastic solids, no bound on the pressure) or the pressure at
            which the surfaces yield, Pa (elastic-perfectly plastic; ~7e9 for case-hardened gear
            steel, about three times its yield stress). Where the pressure reaches it, it stays
            there and the gap opens by a plastic gap δ ≥ 0 (``EHLSolution.plastic_gap``) that
            keeps the Reynolds equation, so the flow, at every node: P and δ complementary,
            through one unknown per node (``_Level.plastic``). It bounds the asperity pressure of
            deterministic roughness, where an elastic half-space puts none (13.5 GPa on the
            ground surfaces at 500 rpm on 1025 nodes). A passage
            (``passage.solve_ehl_passage``) runs the surfaces in: what a step flattens stays in
            both profiles (half each) and travels with each surface, so a later step's δ is only
            what more yields. The statistical asperity pressure (``mixed="statistical"``) is
            outside it.
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
    asperity_relaxation: float = eqx.field(static=True, default=0.5)
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
        check_range("EHLModel.asperity_relaxation", self.asperity_relaxation, 0.01, 1.0)
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


class EHLSolution(eqx.Module):
    """Result of ``solve_ehl``, SI units, per unit face width where forces or powers.

    Attributes:
        x: node positions, m, (N,) (x = 0 at the Hertz centre, entrainment towards +x).
        p: pressure, Pa. h: film thickness, m. density: ρ, kg/m³. viscosity: η, Pa s.
        shear_viscosity: η_s of the shear model's stress (η, η* or τ h/us), Pa s: friction
            τ = η_s us/h.
        temperature: mean film temperature ϕm at the nodes, K (the inlet temperature: isothermal).
        surface_temperature1, surface_temperature2: surface temperatures of gear 1 and 2, K.
        heat_partition: ϑ = Q1/Q, share of the heat conducted into gear 1 (½ isothermal).
        heat_flux: Q of paper Eq. (12), W/m² = heat_flux_sliding (fluid shear) + heat_flux_rolling
            (Poiseuille) + heat_flux_asperity (μb p |us| in contact).
        contact: asperity-contact indicator at the nodes, 0 … 1 (smooth; deterministic mixed).
        asperity_pressure: statistical asperity pressure at the nodes, Pa (included in p).
        h_min, h_central: minimum and central (x = 0) film, m. h0: film offset, m. p_max: Pa.
        (In the cavitated outlet the gap is partly filled: the shear terms are weighted by the fill
        fraction q/(um ρ h), q the mass flux through x = 0, as in a JFO/Elrod streak model.)
        friction_sliding: Fs = ∫ η_s (u2 − u1)/h dx, N/m (paper Eq. 15, fluid part; sign of Eq. 15).
            It includes the boundary friction ∫ μb p dx of asperity contact, friction_asperity.
        friction_rolling: Fr = ∫ (h/2) ∂p/∂x dx over the fluid, N/m (paper Eq. 15).
        damping: cm = ∫ η_s/h dx over the fluid, N s/m² (paper Eq. 13 per unit width).
        power_loss: ∫ Q dx, W/m; power_loss_sliding: fluid shear plus asperity friction;
            power_loss_rolling: Poiseuille part; power_loss_asperity: the asperity part alone.
        contact_fraction: share of the Hertz zone |x| ≤ b in asperity contact.
        contact_load: ∫ p dx over contact nodes, N/m (``contact_load_share``: its share).
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
        """ρ h at the nodes, kg/m² (the previous-step input of a transient solve)."""
        return self.density * self.h


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
    asperity_pressure: Float[Array, " N"]  # Pa, statistical asperity pressure at the nodes
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


# -------------------------------------------------------------------------------------------------
# Dimensionless problem
# -------------------------------------------------------------------------------------------------
def moes_central_film(m, l):
    """Moes' central film H_M = (hc/R)(2U)^(−1/2) for given M, L (line contact, Barus,
    incompressible).

    H_RI = 3/M, H_EI = 2.621 M^(−1/5), H_RP = 1.287 L^(2/3), H_EP = 1.311 M^(−1/8) L^(3/4),
    H_M = [(H_RI^(7/3) + H_EI^(7/3))^(3s/7) + (H_RP^(−7/2) + H_EP^(−7/2))^(−2s/7)]^(1/s) with
    s = (7 + 8 exp(−2 H_EI/H_RI))/5 (C.H. Venner & A.A. Lubrecht, Multilevel Methods in Lubrication,
    2000). Used here only as the starting estimate of the film.
    """
    h_ri = 3.0 / m
    h_ei = 2.621 * m ** (-0.2)
    h_rp = 1.287 * l ** (2.0 / 3.0)
    h_ep = 1.311 * m ** (-0.125) * l**0.75
    s = (7.0 + 8.0 * jnp.exp(-2.0 * h_ei / h_ri)) / 5.0
    a = (h_ri ** (7.0 / 3.0) + h_ei ** (7.0 / 3.0)) ** (3.0 * s / 7.0)
    b = (h_rp ** (-3.5) + h_ep ** (-3.5)) ** (-2.0 * s / 7.0)
    return (a + b) ** (1.0 / s)


class _Scales(eqx.Module):
    b: Array
    ph: Array
    um: Array
    us: Array
    eta0: Array
    log_eta0: Array
    rho0: Array
    log_lambda: Array
    log_kappa: Array  # ln(η0 |us| R/(τ0 b²)): Eyring parameter s = κ η̄/H
    squeeze: Array
    h_ref: Array
    x_in: Array
    x_out: Array
    moes_m: Array
    moes_l: Array


def _scales(model: EHLModel, inp: _Inputs) -> _Scales:
    c, lub = inp.contact, inp.lubricant
    r, w, e = c.reduced_radius, c.load_per_width, c.e_reduced
    b = c.hertz_half_width
    ph = c.hertz_pressure
    um = c.rolling_velocity
    us = c.sliding_velocity
    t_in = c.inlet_temperature
    log_eta0 = lub.log_base_viscosity(t_in)
    eta0 = jnp.exp(log_eta0)
    rho0 = lub.density_at(0.0, t_in, compressible=False)
    log_lambda = jnp.log(12.0 * eta0 * um * r**2 / (b**3 * ph))
    abs_us = jnp.sqrt(us * us + (1e-6 * um) ** 2)  # smooth |us| (gradient-safe at pure rolling)
    log_kappa = jnp.log(eta0 * abs_us * r / (lub.eyring_stress * b**2))
    alpha = lub.pressure_viscosity_coefficient(t_in)
    u_dim = eta0 * um / (e * r)
    w_dim = w / (e * r)
    m = w_dim * (2.0 * u_dim) ** -0.5
    l = alpha * e * (2.0 * u_dim) ** 0.25
    h_ref = moes_central_film(m, l) * jnp.pi / (8.0 * m)
    x_in, x_out = jnp.asarray(model.x_in), jnp.asarray(model.x_out)
    if model.auto_domain:
        x_in = jnp.minimum(x_in, -jnp.sqrt(50.0 * h_ref))
        x_out = jnp.maximum(x_out, 1.2 * jnp.sqrt(2.0 * h_ref))
    squeeze = b * inp.inv_time_step / um
    return _Scales(
        b,
        ph,
        um,
        us,
        eta0,
        log_eta0,
        rho0,
        log_lambda,
        log_kappa,
        squeeze,
        h_ref,
        x_in,
        x_out,
        m,
        l,
    )


def transport_shift(model: EHLModel, distance):
    """How far back along X a transient step reads its previous films, m: the distance the mean
    velocity carries the film in the step (∫ ur dt) along the characteristics
    (``EHLModel.transport = "characteristic"``), 0 for the Eulerian squeeze term."""
    return distance if model.transport == "characteristic" else jnp.zeros_like(distance)


def _extrapolated_interp(foot, x_previous, values):
    """Linear interpolation at ``foot``, held after the last node and extrapolated linearly
    before the first (the inlet, where a step along the characteristics reads upstream of the
    domain)."""
    inside = jnp.interp(foot, x_previous, values)
    slope = (values[1] - values[0]) / (x_previous[1] - x_previous[0])
    return jnp.where(foot < x_previous[0], values[0] + (foot - x_previous[0]) * slope, inside)


def _roughness_offset(mixed, surfaces, x, d):
    """The film offset −(S1 + S2) of a deterministic rough film, m, the surfaces displaced by
    ``d``; zero for the other films."""
    if mixed != "deterministic":
        return jnp.zeros_like(x)
    return -(surfaces.displaced_height(0, x, d[0]) + surfaces.displaced_height(1, x, d[1]))


def _film_at_feet(model, mixed, surfaces, x, shift, x_prev, rho_h, rho, d, radius):
    """ρh of an earlier step (on its nodes ``x_prev``, its surfaces displaced by ``d``) where this
    step's squeeze term reads it: at the nodes ``x`` (the Eulerian term), or along the
    characteristics (``EHLModel.transport``) at their feet x − ``shift``, with the roughness there
    evaluated from the profiles, not interpolated.

    Why the roughness apart: a step along the characteristics is exact for a film carried at the
    mean velocity only if it reads that film where it stood. Linear interpolation between nodes
    flattens a roughness a few cells long: on the polished film at the pitch contact (2049 nodes,
    BDF2) Courant numbers 0.5 and 0.25, whose feet fall between nodes, gave a loss 20-22 % above
    the integer ones (1, 2, 4: within 0.6 % of each other), as the grid that follows the Hertz
    width along the path would too; with the roughness evaluated, C = 0.5 is 1.3 % below C = 1.
    The rest of ρh (the smooth gap and the deformation) and the density are interpolated.

    Upstream of the earlier grid's first node (its grid narrower: the Hertz width grows with the
    load; or a foot upstream of the inlet) the rigid gap x²/(2R) (``radius`` R, this step's) and
    the roughness are taken out, the rest (h0, the deformation: slowly varying there) extrapolated
    linearly, and the gap and the roughness there put back at the first node's density (the
    inlet's pressure is ~0). Why: held at the first node's value, as before 2026-11-28, the
    earlier film was read too thin by the gap's growth there, and the squeeze term filled a gap
    that was not opening. Where the load doubles in a step of a third of a Hertz width (the
    coupled transient rung's jumps; 257 nodes, 3500 rpm, smooth, iso-thermal) the inlet moves 56
    cells; that step's loss was 0.5 % lower (16 586 against 16 669 W/m), its film the same to
    1e-4, the later steps' losses within 2e-5. Inside the earlier grid ρh is interpolated as it
    is: in the Hertz zone the deformation cancels the rigid gap's curvature, so taking the gap out
    there would make the rest curved (a one-off run that did so moved the same step's loss by
    another 0.4 % and its central film by 0.1 %)."""
    foot = x - shift if model.transport == "characteristic" else x
    offset_prev = _roughness_offset(mixed, surfaces, x_prev, d)
    rest_prev = rho_h - rho * offset_prev
    gap_prev = rho * x_prev**2 / (2.0 * radius)
    offset_foot = _roughness_offset(mixed, surfaces, foot, d)
    upstream = _extrapolated_interp(foot, x_prev, rest_prev - gap_prev) + rho[0] * (
        foot**2 / (2.0 * radius) + offset_foot
    )
    if model.transport != "characteristic":
        inside = jnp.interp(foot, x_prev, rho_h)
    else:
        rho_foot = _extrapolated_interp(foot, x_prev, rho)
        inside = jnp.interp(foot, x_prev, rest_prev) + rho_foot * offset_foot
    return jnp.where(foot < x_prev[0], upstream, inside)


def _grid(sc: _Scales, n: int):
    x = jnp.linspace(0.0, 1.0, n) * (sc.x_out - sc.x_in) + sc.x_in
    return x, (sc.x_out - sc.x_in) / (n - 1)


def _log_shear_factor(model: EHLModel, log_s, part: str = "flow"):
    """ln(η_s/η) of the shear model for ``part`` "flow" (the Reynolds flow coefficient, the
    Poiseuille heat, the damping) or "stress" (the sliding friction and heat): one law for both
    except "eyring_split" (``ehl_formula.split_laws``)."""
    from .ehl_formula import split_laws
    from .rheology import log_eyring_exact_factor, log_eyring_paper_factor

    stress_law, flow_law = split_laws(model.shear)
    law = flow_law if part == "flow" else stress_law
    if law == "eyring_paper":
        return log_eyring_paper_factor(log_s)
    if law == "eyring_exact":
        return log_eyring_exact_factor(log_s)
    return jnp.zeros_like(log_s)


class _Level(eqx.Module):
    """The discrete system on one grid: F(u) = 0, u = [P (n), H0]."""

    model: EHLModel = eqx.field(static=True)
    n: int = eqx.field(static=True)
    inp: _Inputs
    sc: _Scales
    x: Array
    spacing: Array
    # influence matrix rows i = −2 … n (n + 3, n): D[i, j] = d(i − j); None on Krylov levels
    # (``EHLModel.use_krylov``), which apply D by FFT and never assemble J
    kernel_rows: Array | None
    # d(m) for m = −(B + 2) … B + 2 (index m + B + 2), B = _KRYLOV_BLOCK: the Toeplitz kernel near
    # its diagonal (the relaxation's and the block preconditioner's)
    kernel_near: Array
    temperature: Array
    log_eta0_nodes: Array  # ln η0(T) at the nodes (ambient pressure), η in Pa s
    alpha_nodes: Array  # α(T) at the nodes, 1/Pa
    rho_nodes: Array  # ρ(0, T)/ρ0 at the nodes
    offset: Array  # dimensionless film offset
    rho_h_prev: Array  # dimensionless ρ̄H of the previous step
    # 1, or 0 in a transient step whose squeeze term is the material derivative along the
    # characteristics (``EHLModel.transport``), which carries the wedge term
    wedge_weight: Array
    asperity: Array  # dimensionless asperity pressure (held fixed within a Newton solve)

    def with_roughness(self, factor):
        """The same system with the film offset (roughness) scaled by ``factor``."""
        return eqx.tree_at(lambda lev: lev.offset, self, self.offset * factor)

    def smooth_steady(self):
        """The same system without roughness and without the squeeze term (so with the wedge)."""
        return eqx.tree_at(
            lambda lev: (lev.offset, lev.sc.squeeze, lev.wedge_weight),
            self,
            (
                jnp.zeros_like(self.offset),
                jnp.zeros_like(self.sc.squeeze),
                jnp.ones_like(self.wedge_weight),
            ),
        )

    def density(self, p):
        """ρ̄(P) at the nodes (dimensionless)."""
        if self.model.compressibility == "dowson_higginson":
            pressure = self.sc.ph * p
            return self.rho_nodes * rheology.dowson_higginson_density(pressure, 0.0, 1.0, 0.0, 0.0)
        return self.rho_nodes

    def rho_h(self, u):
        """ρ̄H at the nodes for the state u (what the squeeze term of the next step reads)."""
        return self.density(self.plastic(u[: self.n])[0]) * self.film(u)

    def plastic(self, v):
        """(P, δ) of the pressure unknowns v: the pressure and the dimensionless plastic gap.

        Without a pressure limit (``EHLModel.hardness`` None) P = v and δ is None. With one,
        P = min(v, P_cap) and δ = c H_ref max(v − P_cap, 0) (c = ``_PLASTIC_GAP_SCALE``, both
        smoothed over ``_PLASTIC_SMOOTHING``): where the surface yields, its pressure stays at the
        limit and the gap opens by δ ≥ 0 (the asperity flattened), complementary to P_cap − P ≥ 0.
        The Reynolds equation holds at every node, plastic ones included, so the flow is conserved
        there."""
        if self.model.hardness is None:
            return v, None
        cap = self.model.hardness / self.sc.ph
        excess = smooth_positive(v - cap, _PLASTIC_SMOOTHING)
        return v - excess, _PLASTIC_GAP_SCALE * self.sc.h_ref * excess

    def shape(self, v):
        """The film without H0 and the rigid gap: deformation, offset (roughness) and plastic gap
        for the pressure unknowns v."""
        p, delta = self.plastic(v)
        h = self.deformation(p + self.asperity) + self.offset
        return h if delta is None else h + delta

    def deformation(self, p):
        if self.model.use_fft(self.n):
            return deformation_mod.deformation_fft(p, self.spacing)
        # the whole padded matrix times p, then the rows wanted: slicing the matrix first would copy
        # it (XLA does not fuse a slice into a dot operand)
        return (self.kernel_rows @ p)[2 : self.n + 2]

    def film(self, u):
        p, delta = self.plastic(u[: self.n])
        h = u[self.n] + 0.5 * self.x**2 + self.offset + self.deformation(p + self.asperity)
        return h if delta is None else h + delta

    def local(self, p, h, s):
        """Node-wise FB residual as a function of P and H (banded dependence, bandwidth −2…+1)."""
        r, diag = self.reynolds(p, h, s)
        f = fischer_burmeister(p, -r / (1.0 + diag), self.model.smoothing(self.inp.rough))
        return f.at[0].set(p[0]).at[-1].set(p[-1])

    def reynolds(self, p, h, s):
        """The discrete Reynolds residual R and its Poiseuille diagonal D (``reynolds_residual``) as
        functions of P and H."""
        m, sc = self.model, self.sc
        pressure = sc.ph * p
        log_eta = self.log_eta0_nodes - sc.log_eta0
        if m.viscosity == "barus":
            log_eta = log_eta + rheology.barus_log_pressure_factor(pressure, self.alpha_nodes)
        else:
            log_eta = log_eta + rheology.roelands_log_pressure_factor(
                pressure, self.log_eta0_nodes, self.inp.lubricant.roelands_z
            )
        log_eta = s * log_eta
        log_eta = jnp.minimum(log_eta, _LOG_VISCOSITY_CAP)
        rho = self.density(p)
        h_eff = smooth_positive(h, _FLOOR_FRACTION * sc.h_ref)
        if m.shear == "newtonian":
            log_eta_s = log_eta
        else:
            log_s = sc.log_kappa + log_eta - jnp.log(h_eff)
            log_eta_s = log_eta + _log_shear_factor(m, log_s)
        log_eps = jnp.log(rho * h_eff**3) - log_eta_s - sc.log_lambda
        return reynolds_residual(
            p,
            rho * h,
            log_eps,
            self.spacing,
            sc.squeeze,
            self.rho_h_prev,
            m.wedge_order,
            self.wedge_weight,
        )

    def load_row(self, p):
        return (self.spacing * jnp.sum(p + self.asperity) - 0.5 * jnp.pi) / (0.5 * jnp.pi)

    def residual(self, u, s=1.0):
        p = self.plastic(u[: self.n])[0]
        return jnp.concatenate([self.local(p, self.film(u), s), self.load_row(p)[None]])

    def bands(self, u, s):
        """The band derivatives of ``local`` at u (``_bands``) with respect to the unknowns v and
        to the elastic film (the film without the plastic gap), and dP/dv (None without a
        pressure limit): J = band(dv) + dh D diag(dP/dv)."""
        v = u[: self.n]
        if self.model.hardness is None:
            _, dvs, dhs = _bands(lambda pp, hh: self.local(pp, hh, s), v, self.film(u))
            return dvs, dhs, None
        elastic = self.film(u) - self.plastic(v)[1]

        def local_v(vv, hh):
            pp, dd = self.plastic(vv)
            return self.local(pp, hh + dd, s)

        _, dvs, dhs = _bands(local_v, v, elastic)
        slope = jax.jvp(lambda vv: self.plastic(vv)[0], (v,), (jnp.ones_like(v),))[1]
        return dvs, dhs, slope

    def jacobian(self, u, s=1.0):
        n = self.n
        p = u[:n]
        dps, dhs, slope = self.bands(u, s)
        rows = jnp.arange(n)
        offsets = _BAND
        # J[i, j] = Σ_k dP_k[i] [j = i + k] + Σ_k dH_k[i] D[i + k, j]: the shifted influence rows
        # are slices of the level's padded matrix (built once per solve, outside the Newton loop),
        # so the assembly is one fused elementwise pass over n² entries, with no gathers
        # the barrier ties the influence rows to this Newton iterate: otherwise XLA hoists the four
        # n × n slices (and masks) out of the Newton while-loop as loop invariants, materialising
        # them before every solve even when it takes no iteration (15 ms at N = 1025, measured)
        kernel_rows = self.kernel_rows
        if kernel_rows is None:  # a Krylov level's J for the implicit derivative: built here
            kernel_rows = deformation_mod.influence_rows(n, self.spacing, before=2, after=1)
        kernel_rows, rows_b, _ = jax.lax.optimization_barrier((kernel_rows, rows, u))
        m = rows_b[:, None] - rows_b[None, :]
        dense = jnp.zeros((n, n), dtype=p.dtype)
        for k, dp, dh in zip(offsets, dps, dhs, strict=True):
            shifted = kernel_rows[k + 2 : k + 2 + n]
            if slope is not None:  # the deformation responds to P = P(v): its columns × dP/dv
                shifted = shifted * slope[None, :]
            dense = dense + dh[:, None] * shifted + jnp.where(m == -k, dp[:, None], 0.0)
        h0_col = sum(dhs)
        top = jnp.concatenate([dense, h0_col[:, None]], axis=1)
        load = jnp.full((n,), self.spacing / (0.5 * jnp.pi), dtype=p.dtype)
        if slope is not None:
            load = load * slope
        bottom = jnp.concatenate([load[None, :], jnp.zeros((1, 1))], axis=1)
        return jnp.concatenate([top, bottom], axis=0)


_BAND = (-2, -1, 0, 1)  # node offsets k of the banded dependence of a node's residual on P, H


def _bands(fn, p, h):
    """fn(p, h) (node-wise, banded in ``_BAND``) and its band derivatives: lists over k of
    ∂fn_i/∂p_{i+k} and ∂fn_i/∂h_{i+k} (zero outside the grid), by four coloured
    directional derivatives each."""
    n = p.shape[0]
    value, lin = jax.linearize(fn, p, h)
    colour = jnp.arange(n)[None, :] % 4 == jnp.arange(4)[:, None]
    seeds = colour.astype(p.dtype)
    zero = jnp.zeros_like(seeds)
    jp = jax.vmap(lin)(seeds, zero)  # (4, n): row i, coloured column
    jh = jax.vmap(lin)(zero, seeds)
    rows = jnp.arange(n)
    dps, dhs = [], []
    for k in _BAND:
        col = rows + k
        valid = (col >= 0) & (col < n)
        dps.append(jnp.where(valid, jp[col % 4, rows], 0.0))
        dhs.append(jnp.where(valid, jh[col % 4, rows], 0.0))
    return value, dps, dhs


def _make_level(model: EHLModel, inp: _Inputs, sc: _Scales, n: int, fine_n: int) -> _Level:
    x, spacing = _grid(sc, n)
    near = deformation_mod.influence_vector(_KRYLOV_BLOCK + 3, spacing)
    kernel = (
        None
        if model.use_krylov(n)
        else deformation_mod.influence_rows(n, spacing, before=2, after=1)
    )
    r = inp.contact.reduced_radius
    h_scale = sc.b**2 / r
    if n == fine_n:
        offset = inp.film_offset / h_scale
        prev = inp.rho_h_previous / (sc.rho0 * h_scale)
        rise = inp.temperature_rise
        asperity = inp.asperity_pressure / sc.ph
    else:
        x_fine, _ = _grid(sc, fine_n)
        offset = jnp.interp(x, x_fine, inp.film_offset) / h_scale
        prev = jnp.interp(x, x_fine, inp.rho_h_previous) / (sc.rho0 * h_scale)
        rise = jnp.interp(x, x_fine, inp.temperature_rise)
        asperity = jnp.interp(x, x_fine, inp.asperity_pressure) / sc.ph
    t = inp.contact.inlet_temperature + rise
    lub = inp.lubricant
    log_eta0 = lub.log_base_viscosity(t)
    alpha = rheology.roelands_pressure_viscosity_coefficient(log_eta0, lub.roelands_z)
    rho = lub.density_at(0.0, t, compressible=False) / sc.rho0
    # a transient step along the characteristics carries the wedge in its squeeze term
    characteristic = model.transport == "characteristic"
    wedge_weight = jnp.where(characteristic & (inp.inv_time_step > 0.0), 0.0, 1.0)
    return _Level(
        model,
        n,
        inp,
        sc,
        x,
        spacing,
        kernel,
        near,
        t,
        log_eta0,
        alpha,
        rho,
        offset,
        prev,
        wedge_weight,
        asperity,
    )


# -------------------------------------------------------------------------------------------------
# Newton with backtracking
# -------------------------------------------------------------------------------------------------
def _norm_inf(f):
    return jnp.max(jnp.abs(f))


_MIXED_PRECISION_NODES = 513  # from this size on, the LU of the Newton matrix is single precision
# and from this size on for deterministic rough films, whose many Newton iterations (transient
# passages: ~100 a step) make the LU most of their cost. Measured on the thermal deterministic
# engagement along the path (3500 rpm, 257 nodes, 900 steps, same hour): 78.7 against 88.9 s with
# the double LU, 96 075 against 100 898 iterations, 896 against 895 steps converged; the mean loss
# moved by 0.8 %: 15 of the steps landed on another discrete solution (loss > 20 % apart), as the
# solver's path decides on such films (see the README, Deterministic roughness)
_MIXED_PRECISION_NODES_ROUGH = 257
_DIRECTION_TOLERANCE = 1e-3  # accepted relative residual ‖J d + F‖/‖F‖ of a mixed-precision step


def _refined(jac, f, lu):
    """Direction −J⁻¹F from a single-precision LU ``lu`` (of J or of a nearby matrix), refined twice
    against the float64 J, and whether its relative residual ‖J d + F‖/‖F‖ is acceptable
    (NaN-safe: a non-finite direction is not)."""

    def solve32(r):
        return jax.scipy.linalg.lu_solve(lu, r.astype(jnp.float32)).astype(jac.dtype)

    d = solve32(-f)
    for _ in range(2):
        d = d + solve32(-f - jac @ d)
    good = jnp.linalg.norm(jac @ d + f) <= _DIRECTION_TOLERANCE * jnp.linalg.norm(f)
    return d, good


def _mixed_precision(level: _Level) -> bool:
    rough = level.inp.rough
    return level.n >= (_MIXED_PRECISION_NODES_ROUGH if rough else _MIXED_PRECISION_NODES)


def _newton_direction(jac, f, lu_prev):
    """Newton direction d = −J⁻¹F, and the single-precision LU it used (None: the double LU; see
    ``_mixed_precision``).

    On large grids the dense LU dominates the cost (≈ 12-20 ms at N = 1025); there it is factorised
    in single precision and the direction refined twice against the float64 matrix (cond J ≈ 1e6 at
    high load: each refinement gains ~cond·ε32 ≈ 0.1). The previous iteration's LU (``lu_prev``) is
    tried first: near convergence J changes little and the refinement absorbs the difference, so no
    new factorisation is needed. A direction off by more than ``_DIRECTION_TOLERANCE`` is recomputed
    from a fresh LU, and if still off, in double precision. The convergence test stays on the
    float64 residual, so only the path to the solution changes, not the solution."""
    if lu_prev is None:
        return jnp.linalg.solve(jac, -f), None

    # lazy under vmap (a batch factorises only when some member's direction is off)
    def double(op):
        return jnp.linalg.solve(op[0], -op[1])

    def fresh(op):
        jac, f, _, _ = op
        lu = jax.scipy.linalg.lu_factor(jac.astype(jnp.float32))
        d, good = _refined(jac, f, lu)
        return cond_any_member(good, lambda op: op[2], double, (jac, f, d)), lu

    d, good = _refined(jac, f, lu_prev)
    return cond_any_member(good, lambda op: (op[3], op[2]), fresh, (jac, f, lu_prev, d))


_KRYLOV_MIN_NODES = 1025  # from this size on, linear_solver="krylov" replaces the dense LU
_KRYLOV_RESTART = 40  # Krylov vectors a GMRES cycle
_KRYLOV_CYCLES = 3  # GMRES cycles before the direction is taken as it stands
_KRYLOV_BLOCK = 128  # nodes a block of the block-Jacobi preconditioner


def _block_preconditioner(level: _Level, u, s):
    """Block-Jacobi factors of J, the preconditioner of ``_krylov_direction``: the LUs of J's
    diagonal blocks of ``_KRYLOV_BLOCK`` nodes, and J's H0 column solved with them.

    J[i, j] = ∂F_i/∂P_j + Σ_k ∂F_i/∂H_{i+k} D[i + k, j]: the Reynolds stencil plus the film's
    response through the deformation. A block keeps both within its nodes: the local elastic
    response that makes a wedge-dominated (pressurised or closing) film's equations stiff. Dropped:
    the coupling between blocks, smooth at that range, which GMRES resolves in a few vectors. (J's
    tridiagonal part alone is no preconditioner: it is singular in the outlet spike, where the
    truncated deformation derivative loses its diagonal.)"""
    n, size = level.n, _KRYLOV_BLOCK
    count = -(-n // size)
    dps, dhs, slope = level.bands(u, s)

    def blocked(v, fill=0.0):
        return jnp.concatenate([v, jnp.full((count * size - n,), fill, v.dtype)]).reshape(
            count, size
        )

    a = jnp.arange(size)
    offset = a[:, None] - a[None, :]  # i − j within a block
    centre = _KRYLOV_BLOCK + 2
    blocks = jnp.zeros((count, size, size), u.dtype)
    near = [level.kernel_near[offset + k + centre] for k in _BAND]
    if slope is not None:  # columns × dP/dv (``_Level.bands``)
        near = [d[None] * blocked(slope)[:, None, :] for d in near]
    for k, dp, dh, d in zip(_BAND, dps, dhs, near, strict=True):
        blocks = blocks + blocked(dh)[:, :, None] * d
        blocks = blocks + blocked(dp)[:, :, None] * (offset == -k)
    # the padding past the last node: identity rows
    blocks = blocks + blocked(jnp.zeros((n,), u.dtype), 1.0)[:, :, None] * (offset == 0)
    lu = jax.scipy.linalg.lu_factor(blocks)
    # B⁻¹c once per direction (every preconditioner application needs it)
    return lu, _block_solve(lu, sum(dhs), n)


def _block_solve(lu, v, n):
    """B⁻¹v for the block diagonal B factorised in ``lu`` (v zero-padded to whole blocks)."""
    count, size = lu[0].shape[:2]
    padded = jnp.concatenate([v, jnp.zeros((count * size - n,), v.dtype)]).reshape(count, size)
    return jax.scipy.linalg.lu_solve(lu, padded[..., None]).reshape(count * size)[:n]


def _bordered_solve(level: _Level, factors, v):
    """z with [B c; r 0] z = v: B the block diagonal of ``_block_preconditioner``, c the H0 column,
    r the load row (Δ/(π/2) at every node), by a block solve and the Schur complement (B⁻¹c comes
    with the factors)."""
    n = level.n
    lu, column_solved = factors
    y = _block_solve(lu, v[:n], n)
    row = level.spacing / (0.5 * jnp.pi)
    schur = row * jnp.sum(column_solved)
    xi = (row * jnp.sum(y) - v[n]) / jnp.where(schur != 0.0, schur, 1.0)
    return jnp.concatenate([y - xi * column_solved, xi[None]])


def _krylov_direction(level: _Level, u, s, f):
    """Newton direction d ≈ −J⁻¹F without forming J: GMRES (right-preconditioned by
    ``_block_preconditioner``) on J·v = ∂F/∂u·v by forward mode through the residual, whose
    deformation is the DC-FFT product. O(N log N) an iteration instead of the dense LU's O(N³).
    GMRES stops at ‖J d + F‖ ≤ ``_DIRECTION_TOLERANCE``‖F‖ (inexact Newton: each Newton iteration
    still contracts the residual by about that factor) or after ``_KRYLOV_CYCLES`` cycles.

    Measured on the first transient step at the pitch contact (3500 rpm, λs 2.5 µm; GMRES vectors
    to 1e-3, a one-off study with SciPy on the assembled J, 2026-11-27): the polished film 7 on 1025
    nodes with blocks of 64 (6 with 128), the ground film 19 (11 with 128); without a
    preconditioner 21-58, with the previous step's exact LU 74-289 (the film's Jacobian moves with
    the roughness). The Newton iterations a step do not depend on the GMRES tolerance between 1e-2
    and 1e-5 (polished, 2049 nodes: 6-8 a step with each).
    """
    import lineax as lx

    from .._solvers.krylov import EarlyExitGMRES

    factors = _block_preconditioner(level, u, s)
    _, jvp = jax.linearize(lambda v: level.residual(v, s), u)

    def preconditioned(y):
        return jvp(_bordered_solve(level, factors, y))

    op = lx.FunctionLinearOperator(preconditioned, jax.ShapeDtypeStruct(f.shape, f.dtype))
    solver = EarlyExitGMRES(
        rtol=_DIRECTION_TOLERANCE,
        atol=0.0,
        restart=_KRYLOV_RESTART,
        max_restarts=_KRYLOV_CYCLES,
    )
    y = lx.linear_solve(op, -f, solver, throw=False).value
    return _bordered_solve(level, factors, y)


def _newton(level: _Level, u0, s, max_iter: int, tol=None):
    """Damped Newton on level's system to ‖F‖∞ < ``tol`` (default: the model's tolerance).
    Returns (u, ‖F‖∞, iterations, converged)."""
    tol = level.model.tolerance if tol is None else tol

    def merit(u):
        f = level.residual(u, s)
        m = jnp.sum(f * f)
        return f, jnp.where(jnp.isfinite(m), m, jnp.inf)

    f0, m0 = merit(u0)
    # large grids carry the last single-precision LU from one iteration to the next (a chord step
    # when it still gives an accurate direction); the first iteration starts from a zero "LU",
    # whose non-finite direction fails the accuracy test, so it factorises
    n1 = u0.shape[0]
    krylov = level.model.use_krylov(level.n)
    reuse = _mixed_precision(level) and not krylov
    lu0 = (jnp.zeros((n1, n1), jnp.float32), jnp.arange(n1, dtype=jnp.int32)) if reuse else None

    def cond(state):
        u, f, m, it, stop, _ = state
        return (~stop) & (it < max_iter)

    def body(state):
        u, f, m, it, _, lu = state
        if krylov:
            d = _krylov_direction(level, u, s, f)
        else:
            d, lu = _newton_direction(jac=level.jacobian(u, s), f=f, lu_prev=lu)
        d = jnp.where(jnp.isfinite(d), d, 0.0)
        # cap the film-offset change per step: a runaway H0 is the usual way a far start diverges
        cap = 0.5 * jnp.maximum(jnp.abs(u[-1]), 10.0 * level.sc.h_ref)
        d = d * jnp.minimum(1.0, cap / jnp.maximum(jnp.abs(d[-1]), 1e-300))

        # backtracking α = 1, 1/2, … (Armijo on ½‖F‖²); one call site keeps the compiled loop small
        def ls_cond(ls):
            alpha, _, m_new, k = ls
            return (m_new > (1.0 - 1e-4 * alpha) * m) & (k < 12)

        def ls_body(ls):
            alpha, _, _, k = ls
            alpha = jnp.where(k == 0, 1.0, 0.5 * alpha)
            f_new, m_new = merit(u + alpha * d)
            return alpha, f_new, m_new, k + 1

        alpha, f_new, m_new, _ = jax.lax.while_loop(
            ls_cond,
            ls_body,
            (jnp.asarray(1.0, dtype=u.dtype), f, jnp.asarray(jnp.inf, dtype=u.dtype), 0),
        )
        ok = jnp.isfinite(m_new)
        u_new = jnp.where(ok, u + alpha * d, u)
        f_new = jnp.where(ok, f_new, f)
        m_new = jnp.where(ok, m_new, m)
        done = _norm_inf(f_new) < tol
        stalled = (~ok) | (alpha * _norm_inf(d) < 1e-15)
        return u_new, f_new, m_new, it + 1, done | stalled, lu

    init = (u0, f0, m0, jnp.asarray(0), _norm_inf(f0) < tol, lu0)
    u, f, m, it, _, _ = jax.lax.while_loop(cond, body, init)
    res = _norm_inf(f)
    return u, res, it, res < tol


def _hertz_start(level: _Level):
    # the Hertz ellipse, widened to span at least two cells: on the wide domain of a thick film
    # (M ≪ 1) a coarse grid may hold no node inside |X| < 1, and the normalisation would be 0/0
    half = jnp.maximum(1.0, 2.0 * level.spacing)
    p = jnp.sqrt(jnp.maximum(1.0 - (level.x / half) ** 2, 0.0))
    p = p * (0.5 * jnp.pi) / (level.spacing * jnp.sum(p))
    defo = level.deformation(p)
    # film offset such that the central film equals the Moes estimate
    h0 = level.sc.h_ref - jnp.interp(0.0, level.x, defo + level.offset)
    return jnp.concatenate([p, h0[None]])


def _transfer(coarse: _Level, fine: _Level, u, cubic=False):
    """Coarse-grid solution → fine-grid start. ``cubic`` (traced bool): midpoints by 4-point cubic
    interpolation, clipped at zero, instead of linear. Cubic saves 1-2 fine-grid Newton iterations
    on smooth pressures (the fine LU is the dominant cost); its overshoot next to a sharp pressure
    spike (Barus at L ≳ 15) can make the fine solve fail, so the second cold attempt uses linear."""
    pc = u[: coarse.n]
    p = jnp.interp(fine.x, coarse.x, pc)
    if fine.n == 2 * coarse.n - 1:  # the grid sequence halves Δ: coarse nodes are every other node
        before = jnp.concatenate([pc[:1], pc[:-2]])
        after = jnp.concatenate([pc[2:], pc[-1:]])
        mid = jnp.maximum((9.0 * (pc[:-1] + pc[1:]) - before - after) / 16.0, 0.0)
        p_cubic = jnp.zeros((fine.n,), dtype=pc.dtype).at[::2].set(pc).at[1::2].set(mid)
        p = jnp.where(cubic, p_cubic, p)
    p = p.at[0].set(0.0).at[-1].set(0.0)
    # keep the central film across the transfer (H0 absorbs the O(Δ) change of the discrete kernel)
    hc = jnp.interp(0.0, coarse.x, coarse.film(u))
    return jnp.concatenate([p, _offset_for_central_film(fine, p, hc)[None]])


def _offset_for_central_film(level: _Level, p, hc, window: bool = False):
    """H0 that puts the central film H(0) at ``hc`` for pressure P on ``level``; with ``window``,
    the mean film over the central window (``_central_window``) instead."""
    shape = level.shape(p)
    if window:
        w = _central_window(level.x)
        return hc - jnp.sum(w * (shape + 0.5 * level.x**2)) / jnp.sum(w)
    return hc - jnp.interp(0.0, level.x, shape)


def _central_window(big_x):
    """Nodes with |X| ≤ ½ (at least the one nearest the centre), as 0/1 weights. Over a rough film
    the mean film there is a stable measure of its level: the film at X = 0 moves by the local
    roughness (~0.4 µm rms per cell of travel for the ground surfaces, more than the film)."""
    spacing = big_x[1] - big_x[0]
    return (jnp.abs(big_x) <= jnp.maximum(0.5, 0.5 * spacing)).astype(big_x.dtype)


def _schedules(model: EHLModel, dtype):
    """Continuation schedules of the piezo-viscous exponent s on the coarsest grid, one row per
    cold attempt: four plateaus 1/4, 1/2, 3/4, 1 first (repeated values cost nothing: Newton stops
    at once when converged), then, if that failed, ``continuation_steps`` equal steps. The third
    attempt (smooth and statistical films on fine grids) follows the second schedule up to
    ``_FINE_CONTINUATION_START`` only and finishes the continuation on the finest grid. The last
    (``_DIRECT_ROW``; for a deterministic rough film, its smooth start) has no continuation: s = 1
    from the start.

    Why the last: continuation eases the hard, piezo-viscous contacts, but at light load and high
    speed (thick films, Moes M ≈ 4-7, L ≈ 6.6: the entry and exit of a tooth pair's engagement at
    3500 rpm) the reduced-exponent problems are the hard ones. There, from the Hertz start at
    s = 1/4, Newton lets the film offset run away (H0 → 10³ × the Moes film, ‖F‖∞ ≈ 0.2, no
    solution on that branch) on some domains, while at s = 1 it converges in ~11 iterations on the
    coarsest grid (measured 2026-11-26: M = 4.2 on −7 … 1.5 half-widths)."""
    k = model.continuation_steps
    i = np.arange(1, k + 1)
    rows = [np.ceil(4.0 * i / k) / 4.0, i / k, i / k, np.ones(k)]
    return jnp.asarray(np.stack(rows), dtype=dtype)


_DIRECT_ROW = 3  # the schedule row without continuation (see ``_schedules``)


# exponent s at which the third cold attempt reaches the finest grid. Measured (Barus,
# incompressible, M = 200, L = 15, ᾱ ≈ 85, 2049 nodes): the first two attempts stall at
# ‖F‖∞ ≈ 1e-2 next to the one-cell pressure spike at the outlet; continuing s = 0.8 → 1 on the
# finest grid converges (2026-11-22).
_FINE_CONTINUATION_START = 0.75
_FINE_CONTINUATION_NODES = 1025  # grids from this size on get the third attempt


_INTERMEDIATE_TOLERANCE = 1e-6


def _cold_start(model: EHLModel, levels: list[_Level], svals, cubic=False, s_end=1.0):
    """Continuation in the piezo-viscous exponent s (schedule ``svals``) on the coarsest grid, then
    grid sequencing up to the second-finest grid at exponent ``s_end``; returns the fine-grid start
    and the iterations spent."""
    coarse = levels[0]
    u = _hertz_start(coarse)
    if len(levels) == 1:
        # a single grid stops short of s = 1: the fine solve that follows finishes it
        svals = svals * (1.0 - 1.0 / (svals.shape[0] + 1.0))

    def cont(carry, s):
        u, it = carry
        u_new, _, k, _ = _newton(coarse, u, s, model.max_iterations)
        return (u_new, it + k), None

    (u, iters), _ = jax.lax.scan(cont, (u, jnp.asarray(0)), svals)
    if len(levels) == 1:
        return u, iters
    # intermediate grids only supply the next start: their own discretisation error (O(Δ²) ≈ 1e-3)
    # dwarfs any residual below _INTERMEDIATE_TOLERANCE, so iterating further buys nothing
    tol = max(model.tolerance, _INTERMEDIATE_TOLERANCE)
    for prev, lev in zip(levels[:-2], levels[1:-1], strict=False):
        u = _transfer(prev, lev, u, cubic)
        u, _, k, _ = _newton(lev, u, s_end, model.max_iterations, tol)
        iters = iters + k
    return _transfer(levels[-2], levels[-1], u, cubic), iters


# -------------------------------------------------------------------------------------------------
# The differentiable solve
# -------------------------------------------------------------------------------------------------
def _levels(model: EHLModel, inp: _Inputs):
    sc = _scales(model, inp)
    sizes = model.grid_sizes
    return sc, [_make_level(model, inp, sc, n, sizes[-1]) for n in sizes]


def _fine_level(model: EHLModel, inp: _Inputs):
    """Only the finest grid (no coarse influence matrices built)."""
    sc = _scales(model, inp)
    return sc, _make_level(model, inp, sc, model.n_nodes, model.n_nodes)


def _warm_start(fine: _Level, init_x, init_p, init_h0, window: bool = False):
    """Start from a solution of a nearby contact in Hertz-scaled variables (``_warm_args``): its
    P(X) on this grid, and its central film scaled by the ratio of the two Moes estimates. For the
    neighbouring mesh position this halves the Newton iterations of a start in physical variables
    (whose load and cavitation point are off by the change of b and ph). ``window``: the central
    film is the mean over the central window, as ``_warm_args(sol, window=True)`` gives it (rough
    films: deterministic roughness)."""
    p = jnp.interp(fine.x, init_x, init_p, left=0.0, right=0.0)
    p = p.at[0].set(0.0).at[-1].set(0.0)
    if not window:
        hc = init_h0 * fine.sc.h_ref
        return jnp.concatenate([p, _offset_for_central_film(fine, p, hc)[None]])
    # rough film whose roughness moved since (a transient step): the previous pressure averaged
    # over 5 cells, so that its asperity spikes, which stand where the roughness was, are spread
    # and the relaxation builds the new ones (measured with the relaxed warm start, 3 rounds: 138
    # against 129 of 152 steps along the path converged at 3500 rpm, 70 against 54 of 111 at
    # 500 rpm; over 3 or 7 cells fewer)
    p = jnp.where(init_h0[2] > 0.5, _box_average(p), p)
    # the previous H0 − H_c carried over (dimensionless, so the same for any contact with a
    # Hertz-like pressure); the window-matched offset if the previous solution gave none
    hc = init_h0[0] * fine.sc.h_ref
    excess = init_h0[1] * fine.inp.contact.e_reduced
    matched = _offset_for_central_film(fine, p, hc, True)
    h0 = jnp.where(jnp.isfinite(excess), hc + excess, matched)
    return jnp.concatenate([p, h0[None]])


_RELAX_DISTRIBUTIVE = 0.1  # ω of the distributive changes (wedge-dominated nodes)
_RELAX_JACOBI = 0.5  # ω of the plain Jacobi changes (Poiseuille-dominated nodes)
_RELAX_SWITCH = 0.3  # wedge-dominated: |∂R_i/∂P_i| below this × the film's self-influence term
_RELAX_LOAD_GAIN = 0.02  # film-offset change per sweep, × the load error × the reference film
# relaxed warm attempts of a deterministic film: relaxation_sweeps then Newton, then twice half as
# many sweeps from where Newton stopped and Newton again. Measured over 76 steps along the path at
# 3500 rpm (257 nodes): 47 of the warm starts converge after the first round, 64 after three (100
# sweeps then 150 more without a Newton in between: 57); over 70 at 500 rpm, 25 and 34.
_RELAX_ROUNDS = 3


def _relaxation_sweeps(model: EHLModel) -> int:
    """The relaxation sweeps of a deterministic film's warm start: the model's, or by default 100
    iso-thermal and 50 thermal. Measured over one engagement along the path (257 nodes, ground,
    900 steps, 2026-11-27, each column in one hour; run s / steps converged / Newton iterations):

    | sweeps | thermal, 3500 rpm | thermal, 500 rpm | iso-thermal, 3500 rpm | iso-thermal, 500 rpm |
    |---|---|---|---|---|
    | 100 | 63.6 / 895 / 78 827 | 100.2 / 898 / 107 837 | 30.8 / 900 / 30 467 | 73.1 / 900 / 79 861 |
    | 50 | 57.3 / 895 / 81 488 | 88.5 / 898 / 111 952 | – | – |
    | 25 | 55.9 / 895 / 85 374 | 90.8 / 900 / 117 290 | 34.4 / 900 / 46 999 | 71.9 / 899 / 92 816 |

    (thermal 3500 rpm, 10 sweeps: 57.7 s, 91 571; none: 72.6 s, 152 775). 100 sweeps cost ~9 ms,
    ~11 Newton iterations' worth. Fewer sweeps leave more of the first solves to the later
    attempts in both cases; why that costs the thermal passage less is measured, not explained.
    The losses over the converged steps were the same to 0.1 %."""
    if model.relaxation_sweeps is not None:
        return model.relaxation_sweeps
    return 50 if model.thermal else 100


_RETRY = -1  # attempt kind: a further relaxation round from where the last Newton stopped
_HALF = -2  # attempt kind: this step's start from the solution of its half step
# the later rounds and the half step are tried only if the last Newton ended with ‖F‖∞ below this.
# Measured (residual after the first round → what the later attempts gave): at 500 rpm, of 29 steps
# ending at ≥ 0.1, 5 were rescued, of 33 ending below it, 17; at 3500 rpm 3 of 12 and 13 of 16
_RELAX_GIVE_UP = 0.1


def _half_step_start(model: EHLModel, inp: _Inputs, u_start):
    """A start for a transient deterministic step whose relaxed warm starts failed: the half step
    (each surface displaced half as far, Δt/2) solved from ``u_start`` by one relaxation and Newton
    round, its pressure averaged over 5 cells and relaxed on this step's system. Only the start
    changes, not the problem solved. Measured over 152 steps along the path at 3500 rpm (257
    nodes), the half step solved in three rounds: of the 19 steps whose three relaxed rounds
    failed, the half step converged for 16 and this step then for 12; at 500 rpm, of 52, for 27
    and 20. One round, kept since it costs less: one engagement 77 against 75 s at 3500 rpm, 167
    against 183 s at 500 rpm. Returns (start, Newton iterations)."""
    half = eqx.tree_at(
        lambda i: (i.film_offset, i.inv_time_step),
        inp,
        (0.5 * (inp.film_offset + inp.film_offset_previous), 2.0 * inp.inv_time_step),
    )
    level = _fine_level(model, half)[1]
    u_half = _distributive_relaxation(level, u_start, _relaxation_sweeps(model))
    u_half, _, k, ok = _newton(level, u_half, 1.0, model.warm_iterations)
    fine = _fine_level(model, inp)[1]
    n = fine.n
    start = jnp.concatenate([_box_average(u_half[:n]), u_half[n:]])
    start = _distributive_relaxation(fine, start, _relaxation_sweeps(model))
    return jnp.where(ok, start, u_start), k


def _box_average(p):
    """P averaged over 5 cells (the end nodes kept at zero)."""
    box = jnp.convolve(p, jnp.ones(5, p.dtype) / 5.0, mode="same")
    return box.at[0].set(0.0).at[-1].set(0.0)


def _distributive_relaxation(level: _Level, u, sweeps: int):
    """``sweeps`` damped Jacobi sweeps of the Reynolds equation from ``u`` (distributive where the
    wedge and squeeze terms dominate, plain where the Poiseuille term does; cavitation by
    projection on P ≥ 0, the film offset nudged towards the load balance); returns the last
    iterate (``u`` itself if that is not finite). Returning the iterate of smallest ‖F‖∞ instead
    was measured worse: over 76 steps along the path at 3500 rpm, 42 warm starts converged against
    47 (it often keeps the unrelaxed start, whose ‖F‖∞ the first sweeps raise), and over 70 at 500
    rpm 20 against 25.

    Why: a deterministic rough film's transient step cannot be reached by Newton from the previous
    step's solution (it stalls at a local minimum of the Fischer-Burmeister merit, ‖F‖∞ ≈ 0.1-1,
    while the asperity-pressure spikes move with the roughness), yet a few local relaxation sweeps
    move those spikes and leave a start from which Newton converges in 4-11 iterations. Relaxation
    is the multigrid smoother of C.H. Venner & A.A. Lubrecht, *Multilevel Methods in Lubrication*
    (2000), §5-6: where Poiseuille flow dominates, plain Jacobi with the film's self-influence in
    the diagonal; where the wedge term does (the film nearly closed: asperity contact, or a
    pressurised film), Gauss-Seidel or Jacobi on P is unstable (the discrete operator there is the
    derivative of the deformation integral, whose downstream coefficient outweighs the diagonal),
    so each change δ_i is distributed as δ_i at node i and −δ_i/2 at its neighbours, whose
    deformation is local. Only the smoother is used (no coarse grids): Newton takes the smooth
    part of the error."""
    n = level.n
    # d(k): dimensionless film change at node j + k per unit P at node j (Toeplitz)
    infl = {k: level.kernel_near[k + _KRYLOV_BLOCK + 2] for k in range(-3, 4)}
    spread = {k: infl[k] - 0.5 * infl[k + 1] - 0.5 * infl[k - 1] for k in _BAND}

    def scaled_reynolds(p, h):
        r, diag = level.reynolds(p, h, 1.0)
        return r / (1.0 + diag)

    cap = None if level.model.hardness is None else level.model.hardness / level.sc.ph

    def sweep(u):
        p = level.plastic(u[:n])[0]
        excess = u[:n] - p  # v − P: the plastic gap in the unknowns' units
        r, dps, dhs = _bands(scaled_reynolds, p, level.film(u))
        dp, dh = dict(zip(_BAND, dps, strict=True)), dict(zip(_BAND, dhs, strict=True))
        film_self = sum(dh[k] * infl[k] for k in _BAND)
        plain = dp[0] + film_self
        distributed = dp[0] - 0.5 * (dp[-1] + dp[1]) + sum(dh[k] * spread[k] for k in _BAND)
        dist = jnp.abs(dp[0]) < _RELAX_SWITCH * jnp.abs(film_self)
        coef = jnp.where(dist, distributed, plain)
        factor = jnp.where(dist, _RELAX_DISTRIBUTIVE, _RELAX_JACOBI)
        delta = -factor * r / jnp.where(coef != 0.0, coef, 1.0)
        delta = jnp.where(jnp.isfinite(delta), delta, 0.0).at[0].set(0.0).at[-1].set(0.0)
        shared = jnp.where(dist, delta, 0.0)
        change = delta - 0.5 * (jnp.roll(shared, 1) + jnp.roll(shared, -1))
        p_new = jnp.maximum(p + change, 0.0).at[0].set(0.0).at[-1].set(0.0)
        if cap is not None:
            p_new = jnp.minimum(p_new, cap)
        h0 = u[n] + _RELAX_LOAD_GAIN * level.load_row(p_new) * level.sc.h_ref
        if cap is not None:  # back to the unknowns v: the plastic gap kept where P stays at P_cap
            p_new = p_new + jnp.where(p_new >= cap, excess, 0.0)
        return jnp.concatenate([p_new, h0[None]])

    end = jax.lax.fori_loop(0, sweeps, lambda _, v: sweep(v), u)
    return jnp.where(jnp.all(jnp.isfinite(end)), end, u)


def _warm_args(sol: EHLSolution, window: bool = False, moved: bool = False, plastic: bool = True):
    """(X, P, H_c/H_Moes) of a solution: what ``_warm_start`` reads. Guarded so that a failed or
    placeholder solution gives a harmless start (the cold fallback follows if it does not
    converge). ``window`` (deterministic roughness): H_c is the mean film over the central window,
    and the third item is [H_c/H_Moes, (H0 − H_c)/E', moved], ``moved`` telling that the roughness
    has moved since ``sol`` (a transient step: the start is filtered and relaxed). ``plastic``:
    the start carries ``sol``'s plastic gap (False where the surfaces carry it instead: a run-in
    passage)."""
    b = jnp.where(sol.hertz_half_width > 0.0, sol.hertz_half_width, 1.0)
    ph = jnp.where(sol.hertz_pressure > 0.0, sol.hertz_pressure, 1.0)
    hc = sol.h_central
    if window:
        w = _central_window(sol.x / b)
        hc = jnp.sum(w * sol.h) / jnp.sum(w)
    ratio = hc / jnp.where(sol.moes_film > 0.0, sol.moes_film, jnp.inf)
    ratio = jnp.where(jnp.isfinite(ratio) & (ratio > 0.0), jnp.clip(ratio, 0.05, 20.0), 1.0)
    p = jnp.where(jnp.isfinite(sol.fluid_pressure), sol.fluid_pressure, 0.0) / ph
    # a yielded film (``EHLModel.hardness``): the unknowns v = P + δ/(c H_ref) above the limit, so
    # that the start keeps its plastic gap (zero for elastic films)
    film_scale = _PLASTIC_GAP_SCALE * jnp.where(sol.moes_film > 0.0, sol.moes_film, jnp.inf)
    if plastic:
        gap = jnp.where(jnp.isfinite(sol.plastic_gap), sol.plastic_gap, 0.0)
        p = p + gap / film_scale
    if not window:
        return sol.x / b, p, ratio
    # and (H0 − H_c)/E' in Hertz-scaled film units, b²/R = 4 b ph/E' (Hertz line contact): the
    # next contact multiplies by its E'. NaN (unused) for a failed or placeholder solution
    excess = (sol.h0 - hc) / (4.0 * b * ph)
    good = sol.converged & jnp.isfinite(excess)
    flag = jnp.asarray(1.0 if moved else 0.0, dtype=ratio.dtype)
    return sol.x / b, p, jnp.stack([ratio, jnp.where(good, excess, jnp.nan), flag])


@functools.partial(jax.custom_jvp, nondiff_argnums=(0, 1, 2))
def _solve_core(model: EHLModel, warm: bool, mixed: bool, inp: _Inputs, init_x, init_p, init_h0):
    """u* = [P, H0] on the fine grid, plus (residual, iterations, converged) as floats.

    The fine-grid Newton loop appears once in the program: a warm solve is a scan over two attempts
    (the warm start, then, only if that failed, the cold start), so compile time does not double."""
    if mixed == "deterministic":
        inp = dataclasses.replace(inp, rough=True)
    sc, fine = _fine_level(model, inp)
    dtype = fine.x.dtype
    # attempts: [warm start,] cold with the fine schedule, cold with the coarse schedule, [cold
    # finishing the continuation on the finest grid,] cold without continuation; each runs only if
    # everything before it failed (lax.cond: no work when skipped, outside vmap). The fine-grid
    # continuation only on fine grids, where the one-cell spike trap arises (under vmap a skipped
    # attempt still runs, so coarser grids do not pay for it); deterministic mixed films continue
    # in the roughness from a smooth film instead (its start from the first, second or last row),
    # and stop after a failed continuation that got under way
    third = mixed != "deterministic" and model.n_nodes >= _FINE_CONTINUATION_NODES
    rows = [0, 1] + ([2] if third else []) + [_DIRECT_ROW]
    det = mixed == "deterministic"
    u_start = _warm_start(fine, init_x, init_p, init_h0, det) if warm else _hertz_start(fine)
    # deterministic roughness: relaxation sweeps before the warm Newton; if it fails, more sweeps
    # from where it stopped and Newton again (``_RELAX_ROUNDS`` in all), then the cold solve
    relax = warm and det and _relaxation_sweeps(model) > 0
    u_warm = u_start
    if relax:
        # only where the roughness moved since the start's solution (a re-solve at new
        # temperatures starts from the solution it refines)
        u_warm = jax.lax.cond(
            init_h0[2] > 0.5,
            lambda u: _distributive_relaxation(fine, u, _relaxation_sweeps(model)),
            lambda u: u,
            u_start,
        )
    rounds = [_RETRY] * (_RELAX_ROUNDS - 1 if relax else 0)
    # and if those fail (transient passage steps): the half step first (the roughness moved half
    # as far), its solution, relaxed, this step's start
    half = relax and inp.film_offset_previous is not None
    # a re-solve at updated temperatures: a continuation in the temperatures from the start's
    # (``_temperature_continuation``) before the relaxed rounds
    hot = warm and det and inp.temperature_rise_previous is not None
    warm_kinds = (
        ([0] + ([_HOT] if hot else []) + rounds + ([_HALF] if half else [])) if warm else []
    )
    # deterministic roughness, when everything else failed: the pseudo-time march
    pseudo = det and model.pseudo_transient_steps > 0
    kinds = jnp.asarray(warm_kinds + [r + 1 for r in rows] + ([_PSEUDO] if pseudo else []))
    false = jnp.asarray(False)

    def attempt(carry, kind):
        u, res, it, ok, stop = carry

        # The branches read only their operand (no batched value closed over): cond_any_member.
        def cold(operand):
            kind, _, inp, _ = operand
            row = jnp.clip(kind - 1, 0, _DIRECT_ROW)
            # the coarse grids are built here, inside the branch: a warm start never pays for them
            _, levels = _levels(model, inp)
            fine = levels[-1]
            schedules = _schedules(model, dtype)
            false = jnp.asarray(False)
            if mixed != "deterministic" and not third:
                return (*_cold_start(model, levels, schedules[row], cubic=row == 0), false)
            if mixed != "deterministic":
                # third attempt: reach the finest grid at s < 1, continue s → 1 there
                s_end = jnp.where(row == 2, _FINE_CONTINUATION_START, 1.0).astype(dtype)
                start, k0 = _cold_start(
                    model, levels, schedules[row] * s_end, cubic=row == 0, s_end=s_end
                )
                start, k0, _ = _adaptive_continuation(
                    model,
                    lambda r: (fine, s_end + (1.0 - s_end) * r),
                    start,
                    k0,
                    jnp.where(row == 2, 0.0, 1.0).astype(dtype),
                    _EXPONENT_STEPS,
                )
                return start, k0, false
            # mixed: the smooth steady problem first, then a continuation on the fine grid (coarse
            # grids cannot resolve the roughness anyway) in r, which scales the roughness and, in a
            # transient step, moves the squeeze term's previous film from the smooth start's ρ̄H
            # (at r = 0 the system is the smooth steady one, its squeeze term vanishing at that
            # start) to the previous step's rough one (see ``_rough_homotopy``)
            smooth = [lev.smooth_steady() for lev in levels]
            start, k0 = _cold_start(model, smooth, schedules[row], cubic=row == 0)
            rho_h_smooth = smooth[-1].rho_h(start)
            smooth_start = start
            path = fine
            if pseudo:
                # the pseudo-time attempt's first step (Δt = Δx/ur from the smooth film) is this
                # continuation with the pseudo squeeze term added; its other kinds add none
                sigma = jnp.where(kind == _PSEUDO, 1.0 / fine.spacing, 0.0)
                path = _with_pseudo_squeeze(fine, sigma, rho_h_smooth)
            start, k0, reached = _adaptive_continuation(
                model,
                _rough_homotopy(path, rho_h_smooth),
                start,
                k0,
                jnp.zeros((), dtype),
                model.roughness_steps,
            )
            if pseudo:
                # a first pseudo-time step that failed leaves nothing to march from
                go = (kind == _PSEUDO) & (reached >= 1.0)
                steps = jnp.where(go, model.pseudo_transient_steps, 0)
                start, k_march = _pseudo_march(
                    model, fine, start, smooth_start, rho_h_smooth, steps
                )
                k0 = k0 + k_march
            # once a roughness step has been accepted, the smooth start was good: if this attempt
            # fails, the next would repeat the same continuation from the same smooth film
            # (measured: a more patient continuation, 16 first steps and twice the Newton budget,
            # stalls as well at 500 rpm on 1025 nodes), so it is not run
            return start, k0, reached > 0.0

        def retry(operand):
            _, u, inp, _ = operand
            fine = _fine_level(model, inp)[1]
            start = _distributive_relaxation(fine, u, max(_relaxation_sweeps(model) // 2, 1))
            return start, jnp.asarray(0), jnp.asarray(False)

        def halfway(operand):
            _, _, inp, u_start = operand
            start, k = _half_step_start(model, inp, u_start)
            return start, k, jnp.asarray(False)

        def heated(operand):
            _, _, inp, u_start = operand
            start, k = _temperature_continuation(model, inp, u_start)
            return start, k, jnp.asarray(False)

        def prepare(operand):
            # the other branches of this solve's attempt kinds (cold for the rest)
            others = [(_RETRY, retry)] if relax else []
            others += [(_HALF, halfway)] if half else []
            others += [(_HOT, heated)] if hot else []
            if not others:
                return cold(operand)
            index = jnp.asarray(0)
            for i, (k, _) in enumerate(others):
                index = jnp.where(operand[0] == k, i + 1, index)
            return jax.lax.switch(index, [cold] + [b for _, b in others], operand)

        def keep(operand):
            return operand[1], jnp.asarray(0), jnp.asarray(False)

        # further relaxed rounds only after a Newton that got close (see ``_RELAX_GIVE_UP``)
        hopeless = ((kind == _RETRY) | (kind == _HALF)) & ~(res < _RELAX_GIVE_UP)
        # a failed roughness continuation ends the cold attempts, not the pseudo-time march
        done = ok | (stop & (kind != _PSEUDO)) | hopeless
        operand = (kind, u, inp, u_start)
        start, k0, repeat = cond_any_member(done | (kind == 0), keep, prepare, operand)
        start = jnp.where(kind == 0, u_warm, start)
        budget = model.warm_iterations if warm else model.max_iterations
        warm_kind = (kind == 0) | (kind == _RETRY) | (kind == _HALF) | (kind == _HOT)
        max_iter = jnp.where(done, 0, jnp.where(warm_kind, budget, model.max_iterations))
        u1, res1, k1, ok1 = _newton(fine, start, 1.0, max_iter)
        u1 = jnp.where(done, u, u1)
        res1 = jnp.where(done, res, res1)
        # smooth EHL: a closed film is a failure: try the next attempt (mixed: it is contact)
        ok1 = ok | ok1
        if mixed == "smooth":
            ok1 = ok1 & (jnp.min(fine.film(u1)) > 0.0)
        return (u1, res1, it + k0 + k1, ok1, stop | repeat), None

    init = (u_warm, jnp.asarray(jnp.inf, dtype=dtype), jnp.asarray(0), false, false)
    (u, res, it, ok, _), _ = jax.lax.scan(attempt, init, kinds)
    # a closed (non-positive) film is not a smooth-EHL solution, however small the residual: report
    # it
    if mixed == "smooth":
        ok = ok & (jnp.min(fine.film(u)) > 0.0)
    finite = jnp.all(jnp.isfinite(u))
    fallback = _hertz_start(fine)
    u = jnp.where(finite, u, fallback)
    res = jnp.where(finite & jnp.isfinite(res), res, jnp.finfo(u.dtype).max)
    ok = ok & finite
    return u, res, it.astype(u.dtype), ok.astype(u.dtype)


_PSEUDO = -3  # attempt kind: the pseudo-time march (deterministic roughness, after the cold ones)
_HOT = -4  # attempt kind: the continuation in the temperatures of a re-solve (deterministic film)


def _temperature_continuation(model: EHLModel, inp: _Inputs, u_start):
    """A start for a deterministic rough film's re-solve at updated temperatures whose warm
    Newton failed: the adaptive continuation (``_adaptive_continuation``) in the temperature rise
    from the one the start ``u_start`` was solved at (``inp.temperature_rise_previous``) to this
    solve's, in steps from half the update. Only the start changes, not the problem solved, nor
    the temperature iteration's sequence of updates. Returns (start, Newton iterations).

    Why: after an update that moves the hot spots at the asperity edges by ~100 K, the warm Newton
    from the last film often fails, and the cold solve (the smooth film, then the continuation in
    the roughness) costs ~200 iterations. Relaxing the update itself instead (failed warm re-solves
    retried at a quarter of it) was measured to break the Aitken secant of the temperature
    iteration: 506 s and 824 of 900 steps converged on the engagement where this continuation
    gives 88.9 s and 895 (see ``EHLModel.temperature_steps``)."""
    previous = inp.temperature_rise_previous

    def system_at(r):
        rise = previous + r * (inp.temperature_rise - previous)
        return _fine_level(model, eqx.tree_at(lambda i: i.temperature_rise, inp, rise))[1], 1.0

    dtype = u_start.dtype
    start, k, _ = _adaptive_continuation(
        model, system_at, u_start, jnp.asarray(0), jnp.zeros((), dtype), model.temperature_steps
    )
    return start, k


#: the largest pressure change of an accepted pseudo-time step (× ph) below which the march tries
#: the steady problem from its state. Measured with the eager version of the march at the case it
#: was built for (500 rpm, pitch contact, ground, 513 nodes, 2026-11-27): the steady solve failed
#: from states whose last step changed the pressure by 0.12-0.16 ph and converged, in 12
#: iterations, from one at 0.11 ph.
SETTLE_CHANGE = 0.12
_PSEUDO_SMALLEST = 2.0**-10  # the shortest pseudo-time step, × Δx/ur


def _with_pseudo_squeeze(level: _Level, sigma, rho_h_state):
    """The level with a pseudo-time squeeze term σp (ρ̄H − ρ̄H_state) added to its own (backward
    Euler in pseudo-time, σp = b/(um Δτ)). The squeeze term is linear in ρ̄H, so the sum is one
    squeeze term: σ' = σ + σp, ρ̄H'_prev = ρ̄H_prev + σp/σ' (ρ̄H_state − ρ̄H_prev). σp = 0 gives the
    level itself (to the bit)."""
    total = level.sc.squeeze + sigma
    weight = jnp.where(sigma > 0.0, sigma / jnp.where(sigma > 0.0, total, 1.0), 0.0)
    prev = level.rho_h_prev + weight * (rho_h_state - level.rho_h_prev)
    return eqx.tree_at(lambda lev: (lev.sc.squeeze, lev.rho_h_prev), level, (total, prev))


def _pseudo_march(model: EHLModel, fine: _Level, u, u_smooth, rho_h_smooth, steps):
    """Pseudo-transient continuation of a deterministic rough film whose direct solves failed.

    ``u`` is the first pseudo-time step's solution (Δτ = Δx/ur from the smooth film, see
    ``_solve_core``). Each further step solves ``fine``'s problem plus a pseudo-time squeeze term
    σp (ρ̄H − ρ̄H of the last accepted state) (``_with_pseudo_squeeze``, backward Euler with the
    roughness held) by the cold path: the continuation in the roughness amplitude from the smooth
    film ``u_smooth`` (``_rough_homotopy``: the squeeze term's reference blended from the smooth
    film's ρ̄H with the roughness). Δτ starts at 2 Δx/ur, doubles after a converged step and halves
    after a failed one (discarded), down to ``_PSEUDO_SMALLEST``. After a step that changed P by
    less than ``SETTLE_CHANGE``, Newton on ``fine``'s own problem from that state; the march stops
    when it converges. At most ``steps`` steps. Returns (the last state, iterations): the caller's
    Newton on ``fine`` finishes (at once when the march ended converged).

    Why: in deep mixed films (the paper's ground surfaces at 500 rpm, λ ≈ 0.1) the continuation in
    the roughness amplitude of the steady problem meets a fold of the discrete branch on 513 nodes
    (at 0.775 of the roughness a step of 1/2048 no longer converges, at a one-node asperity contact
    whose pressure the neighbouring fluid node's flow coefficient sets), while the same
    continuation with a squeeze term, which ties each node's film to a reference film, converges;
    as Δτ grows the reference matters less and the state approaches the steady film. Newton from
    the last state alone (no continuation) does not do: at 500 rpm and 1500 N m on 513 nodes its
    steps failed from Δτ = Δx/ur on and shrank below Δx/(1024 ur) (measured 2026-11-27), where
    the continuation's steps grew to 256 Δx/ur in 12 steps. A real transient step (σ > 0) is
    marched to its own solution the same way: the pseudo term vanishes at a steady state of the
    march."""
    n = fine.n
    dtype = u.dtype

    def cond(carry):
        _, multiple, count, _, done = carry
        return (~done) & (count < steps) & (multiple >= _PSEUDO_SMALLEST)

    def body(carry):
        u, multiple, count, k, _ = carry
        level = _with_pseudo_squeeze(fine, 1.0 / (fine.spacing * multiple), fine.rho_h(u))
        u_new, k_new, reached = _adaptive_continuation(
            model,
            _rough_homotopy(level, rho_h_smooth),
            u_smooth,
            jnp.asarray(0),
            jnp.zeros((), dtype),
            model.roughness_steps,
        )
        ok = (reached >= 1.0) & jnp.all(jnp.isfinite(u_new))
        change = _norm_inf(u_new[:n] - u[:n])
        u = jnp.where(ok, u_new, u)
        # the steady problem from a state that hardly moved (no iteration otherwise)
        settle = ok & (change < SETTLE_CHANGE)
        tries = jnp.where(settle, model.max_iterations, 0)
        u_steady, _, k_steady, done = _newton(fine, u, 1.0, tries)
        done = settle & done & jnp.all(jnp.isfinite(u_steady))
        return (
            jnp.where(done, u_steady, u),
            jnp.where(ok, 2.0 * multiple, 0.5 * multiple),
            count + 1,
            k + k_new + k_steady,
            done,
        )

    carry = (u, jnp.full((), 2.0, dtype), jnp.asarray(0), jnp.asarray(0), jnp.asarray(False))
    u, _, _, k, _ = jax.lax.while_loop(cond, body, carry)
    return u, k


def _rough_homotopy(fine: _Level, rho_h_smooth):
    """r ↦ (the system at r, s = 1) of a deterministic rough film's cold solve: the roughness
    scaled by r and the previous step's ρ̄H blended from ``rho_h_smooth`` (r = 0: the smooth steady
    film's, as the cold start gives it on the fine grid) to the step's own (r = 1), so that both
    perturbations of the smooth steady solution grow with r (a steady solve has no squeeze term:
    only the roughness moves).

    Why: a transient step that falls back to the cold solve used to continue in the roughness alone,
    with the squeeze term pulling the film towards the previous step's rough ρ̄H from r = 0 on: at
    small r a smooth gap against a rough previous film, an O(1) inconsistency from the first step.
    Measured on one engagement along the path (257 nodes, ground, 900 steps; old and new code in
    the same hour, a one-off script logging each attempt): at 3500 rpm 26 of 212 such cold solves
    failed their first roughness step and 16 steps failed in all; now 2 of 201 and 2 steps, 39.5
    against 56.0 s; at 500 rpm 28 of 506 and 43 steps, now 0 of 486 and 5 steps, 91 against 97 s. Scaling the squeeze term by r instead
    (steady at r = 0) also converges them (896 and 875 of 900 steps) but needs longer continuations
    at 500 rpm (median 202 against 127 Newton iterations)."""

    # r = 0: the reference the smooth steady film solves the system with. Without the wedge term
    # (a step along the characteristics, ``EHLModel.transport``) the squeeze term has to carry
    # the smooth film's wedge: σ (ρ̄H_s − ref) = (1 − w) d(ρ̄H_s)/dX
    missing = (1.0 - fine.wedge_weight) * wedge_term(
        rho_h_smooth, fine.spacing, fine.model.wedge_order
    )
    sigma = fine.sc.squeeze
    ref = rho_h_smooth - missing / jnp.where(sigma > 0.0, sigma, 1.0)

    def system_at(r):
        level = fine.with_roughness(r)
        blend = ref + r * (fine.rho_h_prev - ref)
        return eqx.tree_at(lambda lev: lev.rho_h_prev, level, blend), 1.0

    return system_at


_EXPONENT_STEPS = 4  # first step 1/4 of the piezo-viscous exponent's continuation on the fine grid


def _adaptive_continuation(model: EHLModel, system_at, u, k0, r0, steps: int):
    """Adaptive continuation in a parameter r from ``r0`` to 1 on the finest grid; ``system_at(r)``
    gives (level, s). Nothing runs when r0 = 1. The final solve at r = 1 is the caller's. Returns
    the last accepted state, the iterations and the r it reached.

    Used for the roughness amplitude (deterministic mixed film, from the smooth solution;
    ``steps`` = ``roughness_steps``) and for the piezo-viscous exponent (third cold attempt of a
    smooth film; ``_EXPONENT_STEPS``). Steps start at 1/``steps``; each starts from the secant
    extrapolation of the last two accepted states; a step whose Newton solve fails within half the model's iteration budget is retried at
    half the increment (down to 1/256 of the first), an accepted one lets the next grow by a third.
    Measured at the paper's pitch contact (700 N m, 3500 rpm, ground, λ ≈ 0.4): four fixed roughness
    steps failed beyond 0.8 of the roughness at 257 nodes and beyond 0.3 at 1025 nodes (residual
    0.5-4); the accepted steps shrink to ~0.03 at 513 nodes and ~0.015 at 1025 nodes, where
    asperity contact spreads.
    """
    dtype = u.dtype
    first = jnp.asarray(1.0 / steps, dtype=dtype)
    smallest = first / 256.0
    tries = 32 * steps
    budget = max(model.max_iterations // 2, 8)

    def cond(carry):
        _, _, r, _, dr, _, n = carry
        return (r < 1.0) & (dr >= smallest) & (n < tries)

    def body(carry):
        u, u_prev, r, r_prev, dr, k, n = carry
        r_try = jnp.minimum(r + dr, 1.0)
        slope = jnp.where(r > r_prev, (r_try - r) / jnp.maximum(r - r_prev, 1e-12), 0.0)
        guess = u + slope * (u - u_prev)
        level, s = system_at(r_try)
        u_new, _, k_new, ok = _newton(level, guess, s, budget)
        ok = ok & jnp.all(jnp.isfinite(u_new))
        return (
            jnp.where(ok, u_new, u),
            jnp.where(ok, u, u_prev),
            jnp.where(ok, r_try, r),
            jnp.where(ok, r, r_prev),
            jnp.where(ok, 4.0 / 3.0 * dr, 0.5 * dr),
            k + k_new,
            n + 1,
        )

    r0 = jnp.asarray(r0, dtype=dtype)
    carry = (u, u, r0, r0, first, k0, jnp.asarray(0))
    u, _, r, _, _, k, _ = jax.lax.while_loop(cond, body, carry)
    # the last accepted state: the caller's solve at r = 1 starts from it
    return u, k, r


@_solve_core.defjvp
def _solve_core_jvp(model, warm, mixed, primals, tangents):
    inp, init_x, init_p, init_h0 = primals
    d_inp = tangents[0]
    u, res, it, ok = _solve_core(model, warm, mixed, inp, init_x, init_p, init_h0)
    if mixed == "deterministic":  # the system the solve solved (``EHLModel.smoothing``)
        inp = dataclasses.replace(inp, rough=True)
        d_inp = dataclasses.replace(d_inp, rough=True)

    def fine_residual(theta):
        return _fine_level(model, theta)[1].residual(u, 1.0)

    jac = _fine_level(model, inp)[1].jacobian(u, 1.0)
    _, df = jax.jvp(fine_residual, (inp,), (d_inp,))
    du = -jnp.linalg.solve(jac, df)
    z = jnp.zeros_like(res)
    return (u, res, it, ok), (du, z, z, z)


def _contact_indicator(model: EHLModel, sc: _Scales, big_h):
    """Smooth share (0 … 1) of asperity contact at each node: 1 where the dimensionless film H is
    below ``contact_threshold`` × the smooth central-film estimate, 0 above twice that."""
    hc = model.contact_threshold * sc.h_ref
    return 0.5 * (1.0 - jnp.tanh(4.0 * (big_h - 1.5 * hc) / hc))


def _postprocess(model: EHLModel, mixed: str, inp: _Inputs, u, res, it, ok) -> EHLSolution:
    sc, lev = _fine_level(model, inp)
    c, lub = inp.contact, inp.lubricant
    n = lev.n
    r = c.reduced_radius
    h_scale = sc.b**2 / r
    p_nd, delta = lev.plastic(u[:n])
    p_dim = sc.ph * p_nd
    big_h = lev.film(u)
    h = big_h * h_scale
    x = lev.x * sc.b
    dx = lev.spacing * sc.b
    t = lev.temperature
    rho = lub.density_at(p_dim, t, model.compressibility == "dowson_higginson")
    log_eta = lub.log_viscosity(p_dim, t, model.viscosity)
    eta = jnp.exp(log_eta)
    h_eff = smooth_positive(h, _FLOOR_FRACTION * sc.h_ref * h_scale)
    abs_us = jnp.sqrt(sc.us**2 + (1e-6 * sc.um) ** 2)
    log_s = log_eta + jnp.log(abs_us / (lub.eyring_stress * h_eff))
    log_eta_s = log_eta + _log_shear_factor(model, log_s, "stress")  # secant: τ h/|us|
    if model.limiting_shear_coefficient is not None:  # τ ≤ τL = Λ p (smooth); not the damping
        log_rate = jnp.log(abs_us / h_eff)
        log_tau = rheology.log_limited_stress(
            log_eta_s + log_rate, p_dim, inp.numbers.limiting_shear_coefficient, 1e-6 * sc.ph
        )
        log_eta_s = log_tau - log_rate
    eta_s = jnp.exp(log_eta_s)
    eta_t = jnp.exp(log_eta + _log_shear_factor(model, log_s, "flow"))  # flow coefficient, damping
    # asperity contact (paper Eq. 4b/4c, 12, 15): boundary friction μb p on closed nodes
    if mixed == "deterministic":
        contact = _contact_indicator(model, sc, big_h)
    else:
        contact = jnp.zeros_like(big_h)
    p_asp = inp.asperity_pressure  # statistical asperity pressure (zero otherwise)
    fluid = 1.0 - contact
    dpdx = jnp.gradient(p_dim, dx)
    # Fill fraction of the cavitated outlet: the mass flux through x = 0 carried as Couette streaks.
    rho_h = rho * h_eff
    eps_flux = rho * h_eff**3 / (12.0 * eta_t) * dpdx
    q = jnp.interp(0.0, x, rho_h * sc.um - eps_flux)
    fill = jnp.where(x > 0.0, jnp.clip(q / (sc.um * rho_h), 0.0, 1.0), 1.0)
    weights = jnp.full((n,), dx).at[0].set(0.5 * dx).at[-1].set(0.5 * dx)
    q_slide = fluid * fill * eta_s * sc.us**2 / h_eff  # paper Eq. (12), sliding part
    q_asp = (
        inp.numbers.boundary_friction * (contact * p_dim + p_asp) * abs_us
    )  # paper Eq. (12), h = 0
    # Poiseuille terms on cell faces, as the Reynolds discretisation has them (flow coefficient
    # averaged to the face, pressure gradient by the face difference)
    flow = fluid * h_eff**3 / (12.0 * eta_t)
    dp_face = jnp.diff(p_dim) / dx
    q_roll_face = 0.5 * (flow[1:] + flow[:-1]) * dp_face**2  # paper Eq. (12), rolling part
    q_roll = 0.5 * (jnp.pad(q_roll_face, (1, 0)) + jnp.pad(q_roll_face, (0, 1)))
    sign = (c.u2 - c.u1) / abs_us
    # paper Eq. (15): Fs = Σ μb p (asperity) + Σ η*(u2 − u1)/h (fluid); Fr = Σ (h/2) ∂p/∂x (fluid)
    fs_fluid = jnp.sum(weights * fluid * fill * eta_s * (c.u2 - c.u1) / h_eff)
    fs_asp = jnp.sum(weights * inp.numbers.boundary_friction * (contact * p_dim + p_asp)) * sign
    h_face = 0.5 * (h[1:] + h[:-1]) * 0.5 * (fluid[1:] + fluid[:-1])
    fr = jnp.sum(0.5 * h_face * jnp.diff(p_dim))
    cm = jnp.sum(weights * fluid * fill * eta_t / h_eff)  # paper Eq. (13) per unit width
    # sub-grid minimum film by a parabola through the smallest node and its neighbours
    i = jnp.clip(jnp.argmin(big_h), 1, n - 2)
    hm, h_0, hp = big_h[i - 1], big_h[i], big_h[i + 1]
    curv = hm - 2.0 * h_0 + hp
    safe = jnp.where(curv > 0, curv, 1.0)
    h_min = jnp.where(curv > 0, h_0 - (hp - hm) ** 2 / (8.0 * safe), h_0) * h_scale
    h_central = jnp.interp(0.0, lev.x, big_h) * h_scale
    load_err = jnp.sum(weights * (p_dim + p_asp)) / c.load_per_width - 1.0
    # nodes of the Hertz zone (at least the one nearest the centre: a coarse grid on a wide domain
    # may have no node inside |X| ≤ 1)
    hertz_zone = (jnp.abs(lev.x) <= jnp.maximum(1.0, 0.5 * lev.spacing)).astype(p_dim.dtype)
    p_loss_slide = jnp.sum(weights * q_slide)
    p_loss_asp = jnp.sum(weights * q_asp)
    p_loss_roll = jnp.sum(q_roll_face) * dx
    t_in = jnp.broadcast_to(c.inlet_temperature, t.shape)
    if mixed == "statistical":
        area = asperity_mod.contact_area_ratio(
            jnp.maximum(h, 0.0) + jnp.minimum(h, 0.0),
            inp.roughness,
            inp.numbers.asperity_density_product,
        )
        fraction = jnp.sum(hertz_zone * area) / jnp.sum(hertz_zone)
    else:
        fraction = jnp.sum(hertz_zone * contact) / jnp.sum(hertz_zone)
    return EHLSolution(
        x=x,
        p=p_dim + p_asp,
        h=h,
        density=rho,
        viscosity=eta,
        shear_viscosity=eta_s,
        temperature=t,
        surface_temperature1=t_in,
        surface_temperature2=t_in,
        heat_partition=jnp.full_like(t, 0.5),
        heat_flux=q_slide + q_roll + q_asp,
        heat_flux_sliding=q_slide,
        heat_flux_rolling=q_roll,
        heat_flux_asperity=q_asp,
        contact=contact,
        asperity_pressure=p_asp,
        h_min=h_min,
        h_central=h_central,
        h0=u[n] * h_scale,
        p_max=jnp.max(p_dim + p_asp),
        friction_sliding=fs_fluid + fs_asp,
        friction_asperity=fs_asp,
        friction_rolling=fr,
        damping=cm,
        power_loss=p_loss_slide + p_loss_asp + p_loss_roll,
        power_loss_sliding=p_loss_slide + p_loss_asp,
        power_loss_rolling=p_loss_roll,
        power_loss_asperity=p_loss_asp,
        contact_fraction=fraction,
        contact_load=jnp.sum(weights * (contact * p_dim + p_asp)),
        plastic_gap=jnp.zeros_like(h) if delta is None else delta * h_scale,
        load_error=load_err,
        hertz_half_width=sc.b,
        hertz_pressure=sc.ph,
        moes_m=sc.moes_m,
        moes_l=sc.moes_l,
        moes_film=sc.h_ref * h_scale,
        converged=ok > 0.5,
        residual=res,
        iterations=jax.lax.stop_gradient(it).astype(jnp.int32),
        thermal_residual=jnp.zeros_like(res),
    )


def _temperatures(inp: _Inputs, sol: EHLSolution, solids, transient=None):
    """Film and surface temperature rises of a solution's heat source (REFERENCE §5).

    ``transient``: None (steady Jaeger surfaces, quasi-steady film) or (response, film_previous,
    dt): the surfaces' diagonal responses ((offset1, gain1), (offset2, gain2)) of one transient step
    (paper Eq. 9 with memory) and the film's mean temperature rise at the previous step."""
    lub, c = inp.lubricant, inp.contact
    response, film_previous, dt = (None, None, None) if transient is None else transient
    return thermal_mod.solve_contact_temperatures(
        sol.x,
        sol.heat_flux,
        jnp.maximum(sol.h, 0.0),
        c.u1,
        c.u2,
        solids[0],
        solids[1],
        sol.density,
        lub.specific_heat,
        lub.thermal_conductivity,
        convection=True,
        surface_response=response,
        inlet_temperature=0.0,
        previous_film_mean=film_previous,
        dt=dt,
    )


def _with_temperatures(sol: EHLSolution, temps, inlet, thermal_residual) -> EHLSolution:
    return eqx.tree_at(
        lambda s: (
            s.surface_temperature1,
            s.surface_temperature2,
            s.heat_partition,
            s.thermal_residual,
        ),
        sol,
        (inlet + temps.surface1, inlet + temps.surface2, temps.partition, thermal_residual),
    )


def _solve_impl(model, warm, mixed, inp, init_x, init_p, init_h0, solids, transient=None):
    """One solve (steady or one transient step); thermal when ``model.thermal``; with the
    statistical asperity pressure when ``mixed == "statistical"``.

    Returns (solution, temperatures or None)."""
    u, res, it, ok = _solve_core(model, warm, mixed, inp, init_x, init_p, init_h0)
    sol = _postprocess(model, mixed, inp, u, res, it, ok)
    statistical = mixed == "statistical"
    if not (model.thermal or statistical):
        return sol, None
    n_outer = _thermal_iterations(model, mixed) if model.thermal else 0
    if statistical:
        n_outer = max(n_outer, _ASPERITY_ITERATIONS)
    ph = sol.hertz_pressure
    max_step = _DETERMINISTIC_TEMPERATURE_STEP if mixed == "deterministic" else None
    # a deterministic film's re-solves know the temperatures their start was solved at
    hot = model.thermal and mixed == "deterministic" and model.temperature_steps > 0
    if hot:
        inp = dataclasses.replace(inp, temperature_rise_previous=inp.temperature_rise)

    def asperity_of(sol, inp_k):
        return asperity_mod.asperity_pressure(
            sol.h,
            inp_k.roughness,
            inp_k.contact.e_reduced,
            inp_k.numbers.asperity_density_product,
            inp_k.numbers.asperity_slope_ratio,
        )

    def thermal_settled(change, rise):
        # the film temperature moved by < thermal_rtol of its largest rise (or < thermal_atol K)
        return change <= jnp.maximum(
            model.thermal_rtol * jnp.max(jnp.abs(rise)), model.thermal_atol
        )

    def updates(sol, inp_k, solids, transient, relax):
        """The inputs the solution ``sol`` implies (temperatures, relaxed; relaxed asperity
        pressure), whether they agree with those it was solved with (then the outer iteration has
        converged), and the temperature relaxation's new state (``_aitken``)."""
        inp_next, settled = inp_k, jnp.asarray(True)
        if model.thermal:
            temps = _temperatures(inp_k, sol, solids, transient)
            rise = _safe_rise(temps.film_mean)
            change = jnp.max(jnp.abs(rise - inp_k.temperature_rise))
            settled = settled & thermal_settled(change, rise)
            relaxed, relax = _aitken(inp_k.temperature_rise, rise, relax, max_step)
            inp_next = eqx.tree_at(lambda i: i.temperature_rise, inp_next, relaxed)
            if hot:
                previous = inp_k.temperature_rise
                inp_next = eqx.tree_at(lambda i: i.temperature_rise_previous, inp_next, previous)
        if statistical:
            ph = sol.hertz_pressure
            beta = model.asperity_relaxation
            target = jnp.where(jnp.isfinite(sol.h), asperity_of(sol, inp_k), 0.0)
            target = jnp.minimum(target, 20.0 * ph)
            settled = settled & (jnp.max(jnp.abs(target - inp_k.asperity_pressure)) <= 1e-3 * ph)
            pa = (1.0 - beta) * inp_k.asperity_pressure + beta * target
            inp_next = eqx.tree_at(lambda i: i.asperity_pressure, inp_next, pa)
        return inp_next, settled, relax

    # Outer (Picard) iteration: Reynolds at fixed temperatures and asperity pressures (Newton, warm
    # started), then the temperatures of its heat source and the asperity pressure of its film. It
    # stops once they agree with those the film was solved with (the remaining steps are skipped by
    # lax.cond: no work when solved one contact at a time; a scan, not a while loop, so that
    # reverse-mode differentiation works). Under vmap the skipped steps still run; the vmap-lazy
    # ``cond_any_member`` was measured slower here (an 8-point parallel sweep, thermal transient
    # mixed, 32 positions × 129 nodes: 5.4-5.8 s against 4.2 s), so it is kept to the solver's
    # fallback attempts, where it pays.
    def stay(op):
        return op[0], op[1], jnp.asarray(True), op[2]

    def solve(op):
        sol, _, inp_next, relax = op
        args = _warm_args(sol, mixed == "deterministic")
        u, res, it, ok = _solve_core(model, True, mixed, inp_next, *args)
        new = _postprocess(model, mixed, inp_next, u, res, it, ok)
        new = eqx.tree_at(lambda s: s.iterations, new, new.iterations + sol.iterations)
        # a deterministic film whose re-solve failed (every attempt) ends the iteration, reported
        # not converged: the temperatures of a film that is not a Reynolds solution lead nowhere,
        # and each further re-solve ran every cold attempt (~500 Newton iterations each). Measured
        # on one thermal engagement along the path (257 nodes, same hour, against going on to the
        # last update): 3500 rpm 66.3 against 77.4 s, 894 against 896 of 900 steps converged;
        # 2000 rpm 72.6 against 99.5 s, 898 both (one step had burnt 30 000 iterations on 18
        # failed re-solves); 4000 rpm 66.1 against 90.8 s, 893 against 890; 500 rpm no re-solve
        # failed. A failed first solve still gets its updates: new temperatures can make it
        # solvable (measured at 2000 rpm: 1 such step converged). Two failed solves in a row as
        # the stop instead cascaded at 3500 rpm: the failed step's successor restarts steady,
        # and from step 812 on every restart failed (807 of 900 converged).
        stop = ~new.converged if mixed == "deterministic" else jnp.asarray(False)
        return new, inp_next, stop, relax

    def step(op):
        sol, inp_k, relax, solids, transient = op
        inp_next, settled, relax_next = updates(sol, inp_k, solids, transient, relax)
        # settled: ``sol`` is the answer for the inputs it was solved with; keep both
        return jax.lax.cond(
            settled,
            lambda op: stay((op[0], op[1], relax)),
            solve,
            (sol, inp_k, inp_next, relax_next),
        )

    def picard(carry, _):
        sol, inp_k, done, relax = carry
        return jax.lax.cond(
            done,
            lambda op: (op[0], op[1], jnp.asarray(True), op[2]),
            step,
            (sol, inp_k, relax, solids, transient),
        ), None

    zero = jnp.zeros_like(inp.temperature_rise)
    init = (sol, inp, jnp.asarray(False), (jnp.ones((), zero.dtype), zero, jnp.asarray(False)))
    (sol, inp_last, _, _), _ = jax.lax.scan(picard, init, None, length=n_outer)
    if statistical:
        # the asperity pressure of the final film agrees with the one the film was solved with
        pa_gap = jnp.max(jnp.abs(asperity_of(sol, inp_last) - inp_last.asperity_pressure))
        pa_ok = pa_gap <= 1e-3 * ph
        sol = eqx.tree_at(lambda s: s.converged, sol, sol.converged & pa_ok)
    if not model.thermal:
        return sol, None
    temps = _finite_temperatures(_temperatures(inp_last, sol, solids, transient))
    change = jnp.max(jnp.abs(temps.film_mean - inp_last.temperature_rise))
    change = jnp.where(jnp.isfinite(change), change, jnp.finfo(change.dtype).max)
    thermal_ok = thermal_settled(change, temps.film_mean)
    sol = eqx.tree_at(lambda s: s.converged, sol, sol.converged & thermal_ok)
    return _with_temperatures(sol, temps, inp.contact.inlet_temperature, change), temps


def _thermal_iterations(model: EHLModel, mixed: str) -> int:
    """Outer temperature updates: the model's, or by default 4 (smooth and statistical films settle
    in 1-3) and 32 for deterministic roughness (at full ground roughness, speed E: 23 updates on
    513 nodes, see ``_DETERMINISTIC_TEMPERATURE_STEP``). Updates after the temperatures settle are
    skipped (no cost, outside vmap)."""
    if model.thermal_iterations is not None:
        return model.thermal_iterations
    return 32 if mixed == "deterministic" else 4


_AITKEN_MIN = 0.05  # smallest relaxation factor of the temperature update

# K: the most a node's film temperature may move in one update of a deterministic rough film. Its
# first update comes from the iso-thermal film's heat, whose Poiseuille part is far larger than
# the hot film's: at speed E (ground, 700 N m) it asked for a film 1292 K hot on 513 nodes, the
# Reynolds solves at the 400-900 K films that followed failed, and after 16 updates the solve was
# reported as not converged. Limited to 200 K a step it settles in 23 updates to a film up to 348 K
# hot; on 257 nodes the same solutions come out with fewer Newton iterations (measured 2026-11-27:
# 704 against 2451 at 3500 rpm, 846 against 1278 at 500 rpm, 808 against 1140 at 2000 rpm; losses
# within 0.04 %, the thermal tolerance). 100 K: 818 at 3500 rpm on 257 nodes, not settled in 16 on
# 513. Smooth and statistical films keep the unlimited update (their first rises are tens of K).
_DETERMINISTIC_TEMPERATURE_STEP = 200.0


def _aitken(x, g, state, max_step=None):
    """One relaxed fixed-point update x ← x + ω (g − x) of the film temperature rise, with ω by
    Aitken's Δ² rule for vectors (Irons-Tuck; Küttler & Wall, Comput. Mech. 43, 2008):
    ω_k = −ω_{k−1} r_{k−1}·(r_k − r_{k−1}) / |r_k − r_{k−1}|², r = g − x, clipped to
    [``_AITKEN_MIN``, 1] and 1 at the first update. A contracting, monotone iteration keeps ω = 1
    (unrelaxed: the smooth and statistical films' usual 2-3 updates); one that oscillates gets
    ω < 1. Why: with the deterministic roughness at full ground amplitude the unrelaxed update
    swings between films 150 and 740 K hot (its Poiseuille heat falls as the viscosity does), and
    never settles (measured at speed E, 257 nodes, 16 updates: change still 250 K).

    ``max_step`` (K, optional): ω is further limited so that no node's temperature moves by more
    than this in one update (a trust region; the limited ω is the one the next Δ² step reads).

    ``state`` = (ω_{k−1}, r_{k−1}, whether there is a previous update); returns the new x and
    state."""
    omega_prev, r_prev, have = state
    r = g - x
    dr = r - r_prev
    denom = jnp.sum(dr * dr)
    safe = jnp.where(denom > 0.0, denom, 1.0)
    omega = -omega_prev * jnp.sum(r_prev * dr) / safe
    omega = jnp.where(have & (denom > 0.0) & jnp.isfinite(omega), omega, 1.0)
    # the fixed point does not depend on ω: no derivative flows through it
    omega = jnp.clip(omega, _AITKEN_MIN, 1.0)
    if max_step is not None:
        largest = jnp.max(jnp.abs(r))
        omega = jnp.minimum(omega, max_step / jnp.maximum(largest, 1e-300))
    omega = jax.lax.stop_gradient(omega)
    return x + omega * r, (omega, r, jnp.asarray(True))


_ASPERITY_ITERATIONS = 12  # outer iterations of the statistical asperity pressure (β = ½: 2^-12)
# K: a temperature rise outside [_MIN_RISE, _MAX_RISE] only comes from a failed solve (converged
# films: ≤ 440 K above the inlet at their hottest node, the 1025-node thermal deterministic film; the
# heat only flows into the film, so a rise below 0 is numerical undershoot). The bounds keep the
# film within 150-1600 K for every valid inlet (200-600 K), where the lubricant models stay finite:
# the linear thermal expansion's density reaches 0 near 1700 K (Mil-L-23699), and a bound of 1500 K
# let a failed 1025-node passage step report NaN viscosities and losses (2026-11-27)
_MAX_RISE = 1000.0
_MIN_RISE = -50.0


def _safe_rise(t):
    """Temperatures of a failed solve are kept finite and bounded (the failure is reported by
    ``converged``), so that the next Picard step and the outputs never carry NaN."""
    return jnp.where(jnp.isfinite(t), jnp.clip(t, _MIN_RISE, _MAX_RISE), 0.0)


def _finite_temperatures(temps):
    """The temperature rises bounded by ``_safe_rise``; the heat fluxes (W/m², ~1e8-1e9 in a gear
    contact: never clipped to the temperature bound) only made finite."""
    rise = ("surface1", "surface2", "film_mean")
    finite = lambda a, fill: jnp.where(jnp.isfinite(a), a, fill)
    return eqx.tree_at(
        lambda t: (t.surface1, t.surface2, t.film_mean, t.flux1, t.flux2, t.convected, t.partition),
        temps,
        tuple(_safe_rise(getattr(temps, f)) for f in rise)
        + tuple(finite(getattr(temps, f), 0.0) for f in ("flux1", "flux2", "convected"))
        + (finite(temps.partition, 0.5),),
    )


def solve_ehl(
    contact: LineContact,
    lubricant: Lubricant,
    model: EHLModel | None = None,
    surfaces=None,
    *,
    initial: EHLSolution | None = None,
    previous: EHLSolution | None = None,
    time_step=None,
    displacement=None,
    solids=None,
    temperature_rise=None,
) -> EHLSolution:
    """Solve a line-contact EHL problem: smooth or mixed (rough), isothermal or thermal, steady or
    one backward-Euler step.

    Args:
        contact: the LineContact (SI).
        lubricant: the Lubricant.
        model: static EHLModel (default ``EHLModel()``: 257 nodes, Roelands, Dowson-Higginson,
            paper Eyring, isothermal). ``EHLModel(thermal=True)`` adds the temperatures.
        surfaces: ``None`` (smooth) or a :class:`~jaxgear.lubrication.roughness.Surfaces`: mixed
            lubrication with the roughness S1 + S2 in the film (paper Eq. 5), asperity contact
            where the film closes (Hu-Zhu unified Reynolds, paper Eq. 4b/4c) and boundary friction
            μb p there. The grid must resolve the roughness: under-resolved features make
            asperity contact a resolved film does not have (a waviness needs ≳ 13 nodes a
            wavelength; ``benchmarks/roughness_resolution.py``).
            A deep mixed deterministic film whose direct solve fails (500 rpm, ground, 513 nodes
            and finer) is reached by pseudo-transient continuation (``model.pseudo_transient_steps``).
        initial: a previous EHLSolution to warm-start from (any contact; its p(x) is interpolated
            and its h0 reused). A failed warm start falls back to a cold solve.
        previous: the solution at the previous time step; with ``time_step`` Δt (s) the squeeze term
            ∂(ρh)/∂t ≈ (ρh − ρh_prev)/Δt is included (backward Euler). ρh_prev is interpolated onto
            this solve's nodes (same nodes when the contact's Hertz half-width is unchanged).
        time_step: Δt, s (required with ``previous``).
        displacement: (d1, d2), m: how far each surface has moved, ∫ uj dt; the roughness is
            Sj = scale · zj(x − xj0 − dj). Default (0, 0).
        solids: (Material of gear 1, Material of gear 2) for the surface temperatures (default:
            steel, REFERENCE §4). Used only when ``model.thermal``.
        temperature_rise: starting film temperature rise at the nodes (K), e.g. from a previous
            time step; default zero. Isothermal: the film is held at this temperature field.

    Returns:
        EHLSolution (SI, per unit width), with ``converged``, ``residual`` and ``iterations``.
    """
    from ..lubrication.roughness import Surfaces

    model = EHLModel() if model is None else model
    if not isinstance(model, EHLModel):
        raise ValueError(f"model = {model!r} is not valid; valid: an EHLModel")
    if surfaces is not None and not isinstance(surfaces, Surfaces):
        raise ValueError(
            f"surfaces = {type(surfaces).__name__} is not valid; valid: None or a Surfaces"
        )
    if not isinstance(contact, LineContact):
        raise ValueError(f"contact = {type(contact).__name__} is not valid; valid: a LineContact")
    if not isinstance(lubricant, Lubricant):
        raise ValueError(f"lubricant = {type(lubricant).__name__} is not valid; valid: a Lubricant")
    dtype = jnp.result_type(float)
    if dtype != jnp.float64:
        raise ValueError(
            f"solve_ehl computes in {dtype}; EHL needs float64 (pressures ~1e9 Pa against films "
            "~1e-8 m). Enable it with jax.config.update('jax_enable_x64', True) before use"
        )
    solids = _default_solids() if solids is None else tuple(solids)
    if previous is not None:
        if time_step is None:
            raise ValueError(
                "time_step = None is not valid with previous=; valid range: (0, inf) s"
            )
        check_positive("time_step", time_step, "s")
    mixed = "smooth" if surfaces is None else model.mixed
    # numbers become arrays (a Python float would be a static argument of the compiled call below,
    # one compilation per value)
    time_step, displacement, temperature_rise = (
        None if v is None else jnp.asarray(v, dtype=dtype)
        for v in (time_step, displacement, temperature_rise)
    )
    # everything below is array work: one compiled call, so that an eager call from Python costs
    # the solve and not dozens of dispatches
    return _solve_entry(
        model,
        mixed,
        contact,
        lubricant,
        surfaces,
        initial,
        previous,
        time_step,
        displacement,
        solids,
        temperature_rise,
    )


@functools.cache
def _default_solids():
    """(steel, steel): built once (constructing and validating a Material costs ~1 ms eagerly).
    Built with concrete values even when first called inside a trace (a cached tracer would leak
    into later compilations)."""
    from ..material import steel

    with jax.ensure_compile_time_eval():
        return steel(), steel()


@eqx.filter_jit
def _solve_entry(
    model,
    mixed,
    contact,
    lubricant,
    surfaces,
    initial,
    previous,
    time_step,
    displacement,
    solids,
    temperature_rise,
):
    numbers, model = _split_numbers(model)
    n = model.n_nodes
    dtype = jnp.result_type(float)
    x_here = _grid_positions(model, contact, lubricant)
    d = jnp.zeros((2,), dtype=dtype) if displacement is None else jnp.asarray(displacement)
    if previous is not None:
        dt = jnp.asarray(time_step, dtype=dtype)
        inv_dt = 1.0 / dt
        shift = transport_shift(model, contact.rolling_velocity * dt)
        # the surfaces stood a step back at the previous solution
        d_prev = d - jnp.stack([contact.u1, contact.u2]) * dt
        rho_h_prev = _film_at_feet(
            model,
            mixed,
            surfaces,
            x_here,
            shift,
            previous.x,
            previous.rho_h,
            previous.density,
            d_prev,
            contact.reduced_radius,
        )
    else:
        inv_dt = jnp.zeros((), dtype=dtype)
        rho_h_prev = jnp.zeros((n,), dtype=dtype)
    sigma = jnp.zeros((), dtype=dtype) if surfaces is None else surfaces.composite_rq
    offset = _roughness_offset(mixed, surfaces, x_here, d)
    rise = (
        jnp.zeros((n,), dtype=dtype)
        if temperature_rise is None
        else jnp.broadcast_to(jnp.asarray(temperature_rise, dtype=dtype), (n,))
    )
    z = jnp.zeros((n,), dtype=dtype)
    seed = z
    if mixed == "statistical" and initial is not None:
        seed = jnp.interp(x_here, initial.x, initial.asperity_pressure)
    inp = _Inputs(contact, lubricant, rho_h_prev, inv_dt, offset, rise, seed, sigma, numbers)
    if initial is not None:
        args = _warm_args(initial, mixed == "deterministic", moved=previous is not None)
        return _solve_impl(model, True, mixed, inp, *args, solids)[0]
    z = jnp.zeros((2,), dtype=dtype)
    return _solve_impl(model, False, mixed, inp, z, z, jnp.zeros((), dtype=dtype), solids)[0]


def _grid_positions(model: EHLModel, contact: LineContact, lubricant: Lubricant):
    """Node positions x (m) of ``solve_ehl``'s fine grid for this contact."""
    n = model.n_nodes
    z = jnp.zeros((n,))
    if model.boundary_friction is not None:  # a full model: its static part selects the grid
        _, model = _split_numbers(model)
    zero = jnp.zeros(())
    numbers = _Numbers(zero, zero, zero, zero)  # the grid does not depend on them
    inp = _Inputs(contact, lubricant, z, zero, z, z, z, zero, numbers)
    sc = _scales(model, inp)
    x, _ = _grid(sc, n)
    return x * sc.b


def hertz_film_scale(contact: LineContact):
    """b²/R, m: the film thickness unit of the Hertz scaling H = h R/b²."""
    return contact.hertz_half_width**2 / contact.reduced_radius
