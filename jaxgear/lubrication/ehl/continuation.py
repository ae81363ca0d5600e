"""Continuations on the finest grid, for starts Newton cannot reach directly: the adaptive
continuation in a parameter (``_adaptive_continuation``) in the piezo-viscous exponent, in the
roughness amplitude from the smooth film (``_rough_homotopy``) or in the temperatures of a
re-solve (``_temperature_continuation``), and the pseudo-transient march of a deep rough film
(``_pseudo_march``)."""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp

from ..reynolds import wedge_term
from .discretisation import _fine_level, _Level
from .model import EHLModel, _Inputs
from .newton import _newton, _norm_inf


def _temperature_continuation(model: EHLModel, inp: _Inputs, u_start):
    """A start for a deterministic rough film's re-solve at updated temperatures whose warm
    Newton failed: the adaptive continuation (``_adaptive_continuation``) in the temperature rise
    from the one the start ``u_start`` was solved at (``inp.temperature_rise_previous``) to this
    solve's, in steps from half the update. Only the start changes, not the problem solved, nor
    the temperature iteration's sequence of updates. Returns (start, Newton iterations).

    Why: after an update that moves the hot spots at the asperity edges by ~100 K, the warm Newton
    from the last film often fails, and the cold solve (the smooth film, then the continuation in
    the roughness) costs ~200 iterations. Not by relaxing the update itself (failed warm re-solves
    retried at a fraction of it): that breaks the Aitken secant of the temperature iteration, and
    an engagement then costs several times more and converges fewer steps
    (``EHLModel.temperature_steps``)."""
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
#: the steady problem from its state. At the case the march was built for (500 rpm, pitch contact,
#: ground, 513 nodes) the steady solve fails from states whose last step changed the pressure by
#: 0.12-0.16 ph and converges, in 12 iterations, from one at 0.11 ph.
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
    steps fail from Δτ = Δx/ur on and shrink below Δx/(1024 ur), where the continuation's steps
    grow to 256 Δx/ur in 12 steps. A real transient step (σ > 0) is
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

    Why both: a continuation in the roughness alone, with the squeeze term pulling the film towards
    the previous step's rough ρ̄H from r = 0 on, starts from a smooth gap against a rough previous
    film, an O(1) inconsistency from the first step: 5-12 % of such cold solves along an
    engagement then fail their first roughness step, against ≤ 1 % with the blend. Scaling the
    squeeze term by r instead (steady at r = 0) converges nearly as many but needs longer
    continuations (median ~1.6× the Newton iterations at 500 rpm)."""

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
    extrapolation of the last two accepted states; a step whose Newton solve fails within half the
    model's iteration budget is retried at half the increment (down to 1/256 of the first), an
    accepted one lets the next grow by a third. Why adaptive: at the paper's pitch contact (700 N m,
    3500 rpm, ground, λ ≈ 0.4) four fixed roughness steps fail beyond 0.8 of the roughness at 257
    nodes and beyond 0.3 at 1025 nodes, where the accepted steps shrink to ~0.015 as asperity
    contact spreads.
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
