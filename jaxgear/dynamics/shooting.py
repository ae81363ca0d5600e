"""The periodic orbit by shooting, in one loop, differentiated by the implicit function theorem.

Unknowns w = [z0 (12 scaled states at τ = 0), s (the load-torque correction)]; equations

    R(w) = [ z(1; z0, s) − z0 ,  r1φ1(0) + r2φ2(0) ] = 0

(the second fixes the free rigid rotation). One ``lax.while_loop`` does all of it, each iteration
one integration of the period (``integrate.period_flow``), either plain or with its forward-mode
Jacobian (13 tangent lanes):

1. the exact Jacobian at the start;
2. Newton-Broyden with lazy backtracking: a trial point per iteration, accepted when its residual
   falls below the last accepted one (else the step is halved); Broyden's rank-one update on
   accepted steps; the exact Jacobian again after two rejected trials in a row;
3. the exact Jacobian at the end point: the Newton matrix of the implicit rule, and the monodromy
   matrix ∂z(1)/∂z0 = J[:12, :12] + I whose largest eigenvalue modulus is the Floquet multiplier
   (the free rigid rotation contributes exactly 1);
4. where Newton failed, or ended on an unstable orbit and ``retry_unstable`` holds, a fallback in
   the same loop: ``transient_periods`` periods integrated from ``fallback_from`` (transients
   decay onto the attractor), then steps 1-3 again with ``newton_max_steps``; the second attempt is
   kept only if it is better (stable and converged, or converged where the first was not).

Under ``vmap`` (speed sweeps) the loop runs until its last member is done, each member in its own
phase; an iteration evaluates the Jacobian for the whole batch when any member needs one (the
predicate is taken over the batch by ``batch_any``, so it stays a branch), as a batch-aware
Newton does.

The derivative of the orbit and of everything integrated along it (``PeriodFlow``) never passes
through the iterations: ``orbit_outputs`` is a ``jax.custom_jvp`` whose rule is the implicit
function theorem at the converged w*, ẇ = −(∂R/∂w)⁻¹ ∂R/∂θ·θ̇, with the loop's exact Jacobian at
w*, and the outputs' tangent ∂F/∂w ẇ + ∂F/∂θ·θ̇ from one forward-mode pass through the period at
w*. The rule is linear in θ̇ through operations that transpose (a dense solve, matrix products and
the scan of the integration), so reverse mode works as well as forward mode.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.custom_batching
import jax.numpy as jnp
from jaxtyping import Array, Bool, Float, Int

from .integrate import PeriodFlow, period_flow
from .model import LENGTH_SCALE, DynamicsOptions, GearDynamics

#: Floquet multipliers up to 1 + this count as stable (the free rigid rotation has exactly 1).
STABILITY_TOL = 1e-6

# loop phases
_JACOBIAN, _NEWTON, _TRANSIENT, _DONE = 0, 1, 2, 3


@jax.custom_batching.custom_vmap
def batch_any(flag):
    """``flag`` itself; under ``vmap``, whether any member's flag is set, unbatched."""
    return flag


@batch_any.def_vmap
def _batch_any_rule(axis_size, in_batched, flag):
    del axis_size
    (batched,) = in_batched
    return (jnp.any(flag, axis=0) if batched else flag), False


class OrbitStats(eqx.Module):
    """How the shooting ended (per orbit).

    Attributes:
        iterations: Newton trial iterations of the attempt kept.
        residual: its scaled periodicity residual max|R| / (1 + max|z0|).
        converged: the residual met ``DynamicsOptions.newton_tol``.
        floquet_multiplier: the largest |μ| of the monodromy matrix at the orbit.
    """

    iterations: Int[Array, ""]
    residual: Float[Array, ""]
    converged: Bool[Array, ""]
    floquet_multiplier: Float[Array, ""]

    @property
    def acceptable(self):
        return self.converged & (self.floquet_multiplier <= 1.0 + STABILITY_TOL)


def static_guess(dyn: GearDynamics) -> Float[Array, " 13"]:
    """Shooting unknowns of the static equilibrium at τ = 0 (frictionless, in contact, at rest)."""
    tab = dyn.tables(0.0)
    km, e = tab[0], tab[1]
    force = dyn.torque / dyn.base_radius[0]
    y1 = -force / dyn.ky[0]
    y2 = force / dyn.ky[1]
    rel = e + force / km - y1 + y2  # r1φ1 − r2φ2 with the mesh deflection at F/km
    q = jnp.stack([0.5 * rel, y1, 0.0, -0.5 * rel, y2, 0.0]) / LENGTH_SCALE
    return jnp.concatenate([q, jnp.zeros(6), jnp.zeros(1)])


def _residual(flow: PeriodFlow, w):
    z0 = w[:12]
    return jnp.concatenate([flow.final - z0, (z0[0] + z0[3])[None]])


def _newton_matrix(jac: PeriodFlow):
    """∂R/∂w [13, 13] from the flow's Jacobian with respect to w."""
    top = jac.final - jnp.eye(12, 13, dtype=jac.final.dtype)
    gauge = jnp.zeros(13, dtype=top.dtype).at[0].set(1.0).at[3].set(1.0)
    return jnp.concatenate([top, gauge[None]], axis=0)


def _scaled_norm(r, w):
    return jnp.max(jnp.abs(r)) / (1.0 + jnp.max(jnp.abs(w[:12])))


def _floquet(jac: PeriodFlow):
    mono = jac.final[:, :12]
    return jnp.max(jnp.abs(jnp.linalg.eigvals(mono)))


def _regauge(z):
    rigid = 0.5 * (z[0] + z[3])
    return z.at[0].add(-rigid).at[3].add(-rigid)


class _Attempt(eqx.Module):
    w: Array
    stats: OrbitStats
    flow: PeriodFlow
    jac: PeriodFlow


def solve_orbit(dyn, w0, options: DynamicsOptions, n_positions: int, fallback_from, retry_unstable):
    """The loop of the module docstring for one system (vmap it for a batch).

    Args:
        dyn: GearDynamics (not differentiated here: see ``orbit_outputs``).
        w0: start [13]. fallback_from: start of the fallback's transient [13].
        retry_unstable: traced bool; False redoes only a failed Newton, not an unstable orbit.

    Returns:
        (w* [13], OrbitStats, PeriodFlow at w*, its Jacobian with respect to w).
    """
    dyn = jax.lax.stop_gradient(dyn)
    w0 = jax.lax.stop_gradient(w0)
    fallback_from = jax.lax.stop_gradient(fallback_from)
    dtype = w0.dtype
    tol = options.newton_tol

    def plain(x):
        return period_flow(dyn, x, options, n_positions)

    def with_jacobian(x):
        basis = jnp.eye(13, dtype=dtype)
        flow, jac = jax.vmap(lambda t: jax.jvp(plain, (x,), (t,)), out_axes=(None, -1))(basis)
        return flow, jac

    flow0 = jax.eval_shape(plain, w0)
    zeros_flow = jax.tree_util.tree_map(lambda s: jnp.zeros(s.shape, s.dtype), flow0)
    zeros_jac = jax.tree_util.tree_map(
        lambda s: jnp.zeros((*s.shape, 13), s.dtype), flow0
    )
    no_stats = OrbitStats(
        iterations=jnp.asarray(0, jnp.int32),
        residual=jnp.asarray(jnp.inf, dtype),
        converged=jnp.asarray(False),
        floquet_multiplier=jnp.asarray(jnp.inf, dtype),
    )
    state = dict(
        phase=jnp.asarray(_JACOBIAN, jnp.int32),
        attempt=jnp.asarray(0, jnp.int32),
        w=w0,
        r=jnp.zeros(13, dtype),
        rn=jnp.asarray(jnp.inf, dtype),
        jm=jnp.eye(13, dtype=dtype),
        lam=jnp.asarray(1.0, dtype),
        fails=jnp.asarray(0, jnp.int32),
        trials=jnp.asarray(0, jnp.int32),
        exact=jnp.asarray(False),  # the stored Jacobian is exact at w (no accepted step since)
        flow=zeros_flow,
        jac=zeros_jac,
        transient=jnp.asarray(0, jnp.int32),
        best=_Attempt(w=w0, stats=no_stats, flow=zeros_flow, jac=zeros_jac),
        it=jnp.asarray(0, jnp.int32),
    )
    budgets = (min(options.newton_batch_steps, options.newton_max_steps), options.newton_max_steps)
    # every phase bounded: two attempts of (budget trials + as many refreshes + two Jacobians)
    cap = 2 * (2 * budgets[0] + 2) + 2 * (2 * budgets[1] + 2) + options.transient_periods + 4

    def step_of(st):
        jm_safe = jnp.where(jnp.all(jnp.isfinite(st["jm"])), st["jm"], jnp.eye(13, dtype=dtype))
        return jnp.linalg.solve(jm_safe, -st["r"])

    def cond(st):
        return (st["phase"] != _DONE) & (st["it"] < cap)

    def body(st):
        phase = st["phase"]
        in_newton = phase == _NEWTON
        refresh = in_newton & (st["fails"] >= 2)
        needs_jacobian = (phase == _JACOBIAN) | refresh
        trial = st["w"] + st["lam"] * step_of(st)
        x = jnp.where(
            phase == _TRANSIENT,
            st["w"],
            jnp.where(in_newton & ~refresh, trial, st["w"]),
        )
        flow, jac = jax.lax.cond(
            batch_any(needs_jacobian),
            with_jacobian,
            lambda x: (plain(x), zeros_jac),
            x,
        )
        r_x = _residual(flow, x)
        finite = jnp.all(jnp.isfinite(r_x))
        rn_x = jnp.where(finite, _scaled_norm(r_x, x), jnp.inf)

        # -- a Jacobian evaluation (at the start, a refresh, or at the end point) --------------
        jm_new = _newton_matrix(jac)
        budget = jnp.where(st["attempt"] == 0, budgets[0], budgets[1])
        converged_here = rn_x <= tol
        out_of_budget = st["trials"] >= budget
        # the end of an attempt: converged, stuck, or out of trials (judged at this exact Jacobian)
        ends = (phase == _JACOBIAN) & (converged_here | out_of_budget | (st["lam"] < 1e-4))
        jac_state = dict(
            st,
            w=x,
            r=r_x,
            rn=rn_x,
            jm=jm_new,
            lam=jnp.asarray(1.0, dtype),
            fails=jnp.asarray(0, jnp.int32),
            exact=jnp.asarray(True),
            flow=flow,
            jac=jac,
            phase=jnp.where(ends, _DONE, _NEWTON),  # _DONE: provisional, settled below
        )

        # -- a trial (Newton-Broyden with backtracking) ---------------------------------------
        accept = rn_x < st["rn"]
        dw, dr = x - st["w"], r_x - st["r"]
        denom = jnp.sum(dw * dw)
        upd = jnp.outer(dr - st["jm"] @ dw, dw) / jnp.where(denom > 0, denom, 1.0)
        jm_t = jnp.where(accept & (denom > 0), st["jm"] + upd, st["jm"])
        lam_t = jnp.where(accept, 1.0, 0.5 * st["lam"])
        rn_t = jnp.where(accept, rn_x, st["rn"])
        trials = st["trials"] + 1
        finished = (rn_t <= tol) | (lam_t < 1e-4) | (trials >= budget)
        trial_state = dict(
            st,
            w=jnp.where(accept, x, st["w"]),
            r=jnp.where(accept, r_x, st["r"]),
            rn=rn_t,
            jm=jm_t,
            lam=lam_t,
            fails=jnp.where(accept, 0, st["fails"] + 1),
            trials=trials,
            exact=st["exact"] & ~accept,
            flow=jax.tree_util.tree_map(lambda a, b: jnp.where(accept, a, b), flow, st["flow"]),
            # the end point's exact Jacobian next (already exact when nothing was accepted since)
            phase=jnp.where(finished, _JACOBIAN, _NEWTON),
        )

        # -- a transient period ---------------------------------------------------------------
        z = _regauge(flow.final)
        count = st["transient"] + 1
        settled = count >= options.transient_periods
        transient_state = dict(
            st,
            w=jnp.concatenate([z, x[12:]]),
            transient=count,
            phase=jnp.where(settled, _JACOBIAN, _TRANSIENT),
        )

        new = jax.tree_util.tree_map(
            lambda a, b, c, d: jnp.where(
                phase == _TRANSIENT, c, jnp.where(needs_jacobian, a, jnp.where(in_newton, b, d))
            ),
            jac_state,
            trial_state,
            transient_state,
            st,
        )
        # A trial that finishes where the Jacobian is already exact at w ends the attempt now.
        finished_exact = in_newton & ~refresh & finished & trial_state["exact"]
        new["phase"] = jnp.where(finished_exact, _DONE, new["phase"])
        ended = (needs_jacobian & ~refresh & ends) | finished_exact

        # -- an attempt ended: judge it, keep the better, fall back or stop ---------------------
        stats = OrbitStats(
            iterations=new["trials"],
            residual=new["rn"],
            converged=new["rn"] <= tol,
            floquet_multiplier=jnp.where(ended, _floquet(new["jac"]), jnp.inf),
        )
        this = _Attempt(w=new["w"], stats=stats, flow=new["flow"], jac=new["jac"])
        first = st["attempt"] == 0
        best = st["best"]
        better = stats.acceptable | (stats.converged & ~best.stats.converged)
        keep_new = first | better
        kept = jax.tree_util.tree_map(lambda a, b: jnp.where(keep_new, a, b), this, best)
        retry = first & (~stats.converged | (retry_unstable & ~stats.acceptable))
        after = dict(
            new,
            best=kept,
            phase=jnp.where(retry, _TRANSIENT, _DONE),
            attempt=jnp.where(retry, 1, new["attempt"]),
            w=jnp.where(retry, fallback_from, new["w"]),
            transient=jnp.asarray(0, jnp.int32),
            trials=jnp.where(retry, 0, new["trials"]),
            rn=jnp.where(retry, jnp.inf, new["rn"]),
        )
        if options.transient_periods == 0:
            after["phase"] = jnp.where(retry, _JACOBIAN, _DONE)
        out = jax.tree_util.tree_map(lambda a, b: jnp.where(ended, a, b), after, new)
        out["it"] = st["it"] + 1
        return out

    st = jax.lax.while_loop(cond, body, state)
    best = st["best"]
    return best.w, best.stats, best.flow, best.jac


@jax.custom_jvp
def orbit_outputs(dyn, w, flow, jac, options_and_m):
    """(w*, PeriodFlow at w*) as values; their derivative by the implicit function theorem.

    ``w``, ``flow`` and ``jac`` come from ``solve_orbit`` (no derivative passes through them);
    ``options_and_m`` is (DynamicsOptions, M), static in effect."""
    del dyn, jac, options_and_m
    return w, flow


@orbit_outputs.defjvp
def _orbit_outputs_jvp(primals, tangents):
    dyn, w, flow, jac, (options, m) = primals
    d_dyn = tangents[0]
    # ∂F/∂θ·θ̇ at fixed w: one forward-mode pass through the period
    _, d_flow = jax.jvp(lambda d: period_flow(d, w, options, m), (dyn,), (d_dyn,))
    rhs = jnp.concatenate([d_flow.final, jnp.zeros((1,), w.dtype)])
    dw = -jnp.linalg.solve(_newton_matrix(jac), rhs)
    d_out = jax.tree_util.tree_map(lambda j, d: j @ dw + d, jac, d_flow)
    return (w, flow), (dw, d_out)


def periodic_orbit(
    dyn: GearDynamics,
    w0,
    options: DynamicsOptions,
    n_positions: int,
    fallback_from=None,
    retry_unstable=True,
):
    """The periodic orbit of ``dyn`` from the start ``w0`` [13] (``solve_orbit``), with its
    implicit derivative (``orbit_outputs``).

    Returns (w* [13], OrbitStats, PeriodFlow at w*), differentiable in ``dyn`` in both modes."""
    start = w0 if fallback_from is None else fallback_from
    w, stats, flow, jac = solve_orbit(
        dyn, w0, options, n_positions, start, jnp.asarray(retry_unstable)
    )
    static_options = eqx.partition(options, eqx.is_array)[1]  # the rule needs only its choices
    w, flow = orbit_outputs(dyn, w, flow, jac, _Static((static_options, n_positions)))
    return w, stats, flow


class _Static(eqx.Module):
    """A value carried through ``orbit_outputs`` untraced (its options and position count)."""

    value: object = eqx.field(static=True)

    def __iter__(self):
        return iter(self.value)
