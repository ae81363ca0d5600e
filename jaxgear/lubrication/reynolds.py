"""Discrete Reynolds equation of a line contact in Hertz-scaled variables, with cavitation as a
smoothed Fischer-Burmeister complementarity.

Scaling (EHL_NOTES): X = x/b, P = p/ph, H = h R/b², ρ̄ = ρ/ρ0, η̄ = η/η0. The steady Reynolds
equation
d/dx(ρh³/(12η) dp/dx) = um d(ρh)/dx + ∂(ρh)/∂t becomes

    R(X) = d/dX(ε dP/dX) − d(ρ̄H)/dX − σ (ρ̄H − ρ̄H_prev) = 0,  ε = ρ̄H³/(η̄ λ̄),
    λ̄ = 12 η0 um R²/(b³ ph),  σ = b/(um Δt)  (backward Euler; σ = 0 when steady; BDF2 is the same term with a scaled σ
    and a blended ρ̄H_prev, ``passage._squeeze_history``). Along the characteristics
    (``EHLModel.transport``) the wedge term is dropped and ρ̄H_prev is read at the feet X − T of
    the characteristics: the squeeze term is then the material derivative D(ρ̄H)/DT.

Finite volumes on a uniform grid: the Poiseuille term with ε at cell faces (arithmetic mean), the
wedge
term by second-order (or first-order) upwind differences (flow from low to high X, um > 0), as in
C.H. Venner & A.A. Lubrecht, Multilevel Methods in Lubrication (2000).

Cavitation (Reynolds/JFO outlet condition) is the complementarity P ≥ 0, −R ≥ 0, P·R = 0, written as
φ(P, −R/(1 + D)) = 0 with φ(a, b) = a + b − √(a² + b² + δ²) (smoothed Fischer-Burmeister), D the
Poiseuille diagonal: the scaled residual is O(pressure) everywhere, so δ is a pressure-like
smoothing.
"""

from __future__ import annotations

import jax.numpy as jnp


def fischer_burmeister(a, b, smoothing):
    """Smoothed Fischer-Burmeister function a + b − √(a² + b² + δ²); zero ⇔ a, b > 0, a b = δ²/2."""
    return a + b - jnp.sqrt(a * a + b * b + smoothing * smoothing)


def smooth_positive(h, floor):
    """A smooth positive floor ½(h + √(h² + f²)): ≈ h for h ≫ f, f/2 at h = 0, f²/(4|h|) for h ≪ −f.

    Written without cancellation on either side, so it is finite and positive with finite
    derivatives
    for any h (a gradient-safe double ``where``)."""
    r = jnp.sqrt(h * h + floor * floor)
    positive = h > 0.0
    h_pos = jnp.where(positive, h, 0.0)
    h_neg = jnp.where(positive, 0.0, h)
    return jnp.where(positive, 0.5 * (h_pos + r), 0.5 * floor * floor / (r - h_neg))


def wedge_term(rho_h, spacing, wedge_order: int = 2):
    """d(ρ̄H)/dX by first- or second-order upwind differences (flow towards +X), shape (N,)."""
    back1 = jnp.concatenate([rho_h[:1], rho_h[:-1]])  # ρ̄H_{i−1}
    first = (rho_h - back1) / spacing
    if wedge_order == 1:
        return first
    back2 = jnp.concatenate([rho_h[:2], rho_h[:-2]])
    second = (3.0 * rho_h - 4.0 * back1 + back2) / (2.0 * spacing)
    return jnp.where(jnp.arange(rho_h.shape[0]) < 2, first, second)


def reynolds_residual(
    pressure,
    rho_h,
    log_flow_coefficient,
    spacing,
    squeeze,
    rho_h_previous,
    wedge_order: int = 2,
    wedge_weight=1.0,
):
    """R_i of the discrete Reynolds equation at every node (boundary entries are meaningless).

    Args:
        pressure: P at the nodes, shape (N,).
        rho_h: ρ̄H at the nodes.
        log_flow_coefficient: ln ε at the nodes, ε = ρ̄H³/(η̄ λ̄).
        spacing: Δ (Hertz half-widths).
        squeeze: σ = b/(um Δt), 0 for a steady solve.
        rho_h_previous: ρ̄H of the previous time step (ignored when σ = 0).
        wedge_order: 1 or 2 (upwind order of d(ρ̄H)/dX).
        wedge_weight: 1, or 0 where the squeeze term is the material derivative D(ρ̄H)/DT along
            the characteristics X − T (``rho_h_previous`` read at their feet), which carries
            the wedge term itself (``EHLModel.transport = "characteristic"``).

    Returns:
        (R, D): the residual and the magnitude of its Poiseuille diagonal (ε_{i−½} + ε_{i+½})/Δ²,
        both
        shape (N,). R/(1 + D) is O(pressure) in both the Poiseuille- and the wedge-dominated
        regions,
        which is the scaling the complementarity needs.
    """
    eps = jnp.exp(log_flow_coefficient)
    eps_face = 0.5 * (eps[1:] + eps[:-1])  # faces i+1/2, i = 0..N-2
    flux = eps_face * (pressure[1:] - pressure[:-1]) / spacing  # ε dP/dX at faces
    poiseuille = jnp.zeros_like(pressure).at[1:-1].set((flux[1:] - flux[:-1]) / spacing)
    wedge = wedge_weight * wedge_term(rho_h, spacing, wedge_order)
    diag = jnp.zeros_like(pressure).at[1:-1].set((eps_face[1:] + eps_face[:-1]) / spacing**2)
    return poiseuille - wedge - squeeze * (rho_h - rho_h_previous), diag
