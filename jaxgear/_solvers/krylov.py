"""GMRES that stops as soon as it has converged, for the implicit derivative of the fixed point.

The tribo-dynamic fixed point is differentiated implicitly (``optx.ImplicitAdjoint``): each
direction costs a solve of (I − ∂T/∂x) v = ∂T/∂θ·dθ, one JVP of the fixed-point map T per Krylov
vector. ``lineax.GMRES`` checks convergence only between restart cycles and ends only when two
cycles agree, so it costs at least two full cycles (41 JVPs at restart 20) even where T contracts so
strongly that a handful of Krylov vectors solve the system: 85 % of the gradient's cost at
``Fidelity.fast()``. This GMRES tracks the residual of its
least-squares problem at every Arnoldi step (Givens rotations) and stops there; each cycle ends with
the true residual b − A x, so a cycle cannot report convergence that rounding has faked.

The unknowns are a pytree whose leaves carry different units (N, m/s, m, scaled orbit states). The
solve runs in variables scaled per leaf by the magnitude of the root (the point the operator is
linearised at) — a similarity transform, which changes neither the solution nor the spectrum — so
the residual norm weighs every leaf by its own size, not by its unit.

The transposed system of reverse mode, (I − ∂T/∂x)ᵀ λ = ḡ, has cotangents for unknowns: their units
are the inverse of the root's, so they are scaled by the inverse magnitudes (``transpose``, or the
option ``"transposed"``). Scaled by the root's own magnitudes, the norm would weigh a cotangent leaf
by the square of its unit's size: the residual on the leaves of large magnitude (forces, in N)
would count for nothing beside that on the small ones (the DTE, in m), and the solve would stop
with the former unconverged.
"""

from __future__ import annotations

from typing import Any

import equinox as eqx
import jax
import jax.numpy as jnp
import lineax as lx
from jax.flatten_util import ravel_pytree


def _leaf_scales(x) -> Any:
    """Per-leaf magnitude of ``x`` (max |leaf|; 1 where a leaf is zero, non-finite or not inexact)."""

    def one(leaf):
        leaf = jnp.asarray(leaf)
        if not jnp.issubdtype(leaf.dtype, jnp.inexact) or leaf.size == 0:
            return jnp.ones((), dtype=float)
        m = jnp.max(jnp.abs(leaf))
        return jnp.where(jnp.isfinite(m) & (m > 0), m, 1.0)

    return jax.tree_util.tree_map(one, x)


def _inverse(scales) -> Any:
    """The per-leaf scales of the cotangents of a point scaled by ``scales`` (their inverses)."""
    return jax.tree_util.tree_map(lambda s: 1.0 / s, scales)


def _givens(a, b):
    """(c, s) with [c s; −s c]·[a, b] = [r, 0]."""
    r = jnp.hypot(a, b)
    safe = jnp.where(r > 0, r, 1.0)
    return jnp.where(r > 0, a / safe, 1.0), jnp.where(r > 0, b / safe, 0.0)


class EarlyExitGMRES(lx.AbstractLinearSolver):
    """Restarted GMRES(m) with a convergence test at every Arnoldi step, in per-leaf scaled variables.

    Converged when ‖b̂ − Â x̂‖₂ ≤ rtol ‖b̂‖₂ + atol (hats: scaled by the root's per-leaf magnitudes;
    the true residual, checked at the end of each cycle). Not converged after ``max_restarts``
    cycles (or a non-finite right-hand side): ``RESULTS.max_steps_reached``; with
    ``nan_on_failure=True`` the solution is NaN and the result reported successful instead, so
    that an implicit derivative that cannot be computed comes out NaN rather than lineax raising
    from inside the transformation (the fixed point's adjoint).

    Args:
        rtol, atol: tolerances on the scaled residual (see above).
        restart: Krylov vectors per cycle (the basis is stored: restart + 1 vectors).
        max_restarts: cycles before giving up.
        nan_on_failure: on failure return NaN as successful (above) instead of a failed result.

    Options (``lx.linear_solve(..., options=...)``):
        scale_point: the point whose per-leaf magnitudes scale the unknowns (default the
            operator's linearisation point, else no scaling).
        transposed: True where the operator is the transpose of one linearised at
            ``scale_point`` (its unknowns are cotangents): scaled by the inverse magnitudes.
    """

    rtol: float
    atol: float
    restart: int = eqx.field(static=True, default=30)
    max_restarts: int = eqx.field(static=True, default=20)
    nan_on_failure: bool = eqx.field(static=True, default=False)

    def init(self, operator, options):
        if not eqx.tree_equal(operator.in_structure(), operator.out_structure()):
            raise ValueError("EarlyExitGMRES needs a square operator (in and out structures equal)")
        # the point to scale by: the operator's linearisation point, or options["scale_point"]
        x = (options or {}).get("scale_point", getattr(operator, "x", None))
        if x is None:
            scales = jax.tree_util.tree_map(
                lambda s: jnp.ones((), dtype=s.dtype), operator.in_structure()
            )
        else:
            scales = _leaf_scales(x)
            if (options or {}).get("transposed", False):
                scales = _inverse(scales)
        return lx.linearise(operator), scales

    def compute(self, state, vector, options):
        del options
        operator, scales = state
        flat_b, unravel = ravel_pytree(vector)
        flat_d, _ = ravel_pytree(
            jax.tree_util.tree_map(
                lambda v, s: jnp.broadcast_to(s, jnp.shape(v)).astype(v.dtype), vector, scales
            )
        )
        dtype = flat_b.dtype

        def mv(v):
            return ravel_pytree(operator.mv(unravel(flat_d * v)))[0] / flat_d

        b = flat_b / flat_d
        n, m = b.shape[0], min(self.restart, b.shape[0])
        b_norm = jnp.linalg.norm(b)
        tol = self.rtol * b_norm + self.atol

        # One loop, one product with the operator per iteration: the vector it multiplies is the
        # next Krylov vector (an Arnoldi step) or, at the end of a cycle, the iterate (the true
        # residual b − A x, which also starts the next cycle). The operator (a linearised or
        # transposed fixed-point map, large) thus appears once in the program, not once per use.
        def new_cycle(r, r_norm):
            basis = jnp.zeros((m + 1, n), dtype).at[0].set(r / jnp.where(r_norm > 0, r_norm, 1.0))
            return (
                basis,
                jnp.zeros((m + 1, m), dtype),
                jnp.ones(m, dtype),
                jnp.zeros(m, dtype),
                jnp.zeros(m + 1, dtype).at[0].set(r_norm),
                jnp.asarray(0),
                r_norm,
            )

        def arnoldi(carry, w):
            x, (basis, hess, cs, sn, g, k, beta), _, res, cycles, steps, _ = carry
            live = (jnp.arange(m + 1) <= k).astype(dtype)
            # classical Gram-Schmidt, twice (as stable as modified Gram-Schmidt, vectorised)
            h = (basis @ w) * live
            w = w - h @ basis
            h2 = (basis @ w) * live
            w = w - h2 @ basis
            h = h + h2
            hn = jnp.linalg.norm(w)
            happy = hn <= 1e-14 * jnp.maximum(beta, 1e-300)  # Krylov space exhausted: exact
            basis = basis.at[k + 1].set(jnp.where(happy, 0.0, w / jnp.where(happy, 1.0, hn)))
            h = h.at[k + 1].set(hn)

            # the k earlier rotations (a loop of k, not of the cycle's m: most cycles end after a
            # few vectors), then a new one that zeroes h[k+1]
            def rotate(i, h):
                hi, hj = h[i], h[i + 1]
                return h.at[i].set(cs[i] * hi + sn[i] * hj).at[i + 1].set(-sn[i] * hi + cs[i] * hj)

            h = jax.lax.fori_loop(0, k, rotate, h)
            c_k, s_k = _givens(h[k], h[k + 1])
            h = h.at[k].set(c_k * h[k] + s_k * h[k + 1]).at[k + 1].set(0.0)
            g = g.at[k + 1].set(-s_k * g[k]).at[k].set(c_k * g[k])
            hess = hess.at[:, k].set(h)
            cs, sn, k = cs.at[k].set(c_k), sn.at[k].set(s_k), k + 1
            # the cycle ends at m vectors, at the tolerance, or with the Krylov space exhausted:
            # x += V y, y from the upper-triangular system on the k columns used (unused ones:
            # identity, zero right-hand side)
            end = (k >= m) | ~(jnp.abs(g[k]) > tol) | happy
            used = jnp.arange(m) < k
            r = jnp.where(used[:, None] & used[None, :], hess[:m, :m], jnp.eye(m, dtype=dtype))
            diag_ok = jnp.abs(jnp.diagonal(r)) > 0
            r = jnp.where(jnp.eye(m, dtype=bool) & ~diag_ok[:, None], 1.0, r)
            y = jax.scipy.linalg.solve_triangular(r, jnp.where(used, g[:m], 0.0), lower=False)
            x = jnp.where(end, x + y @ basis[:m], x)
            cycle = (basis, hess, cs, sn, g, k, beta)
            return x, cycle, ~end, res, cycles, steps + 1, jnp.asarray(False)

        def residual(carry, w):
            x, cycle, _, _, cycles, steps, _ = carry
            r = b - w
            res = jnp.linalg.norm(r)
            # another cycle only while the residual is above the tolerance (False for NaN)
            go = (res > tol) & (cycles < self.max_restarts)
            cycle = jax.lax.cond(go, lambda: new_cycle(r, res), lambda: cycle)
            return x, cycle, go, res, cycles + go.astype(cycles.dtype), steps, ~go

        def body(carry):
            x, cycle, in_arnoldi = carry[0], carry[1], carry[2]
            basis, k = cycle[0], cycle[5]
            w = mv(jnp.where(in_arnoldi, basis[jnp.minimum(k, m)], x))
            return jax.lax.cond(in_arnoldi, arnoldi, residual, carry, w)

        # x0 = 0: the first residual is b itself, no product needed
        go = (b_norm > tol) & (self.max_restarts > 0)
        init = (
            jnp.zeros_like(b),
            new_cycle(b, b_norm),
            go,
            b_norm,
            go.astype(jnp.int32),
            jnp.asarray(0),
            ~go,
        )
        x, _, _, res, _, steps, _ = jax.lax.while_loop(lambda c: ~c[6], body, init)
        ok = res <= tol
        if self.nan_on_failure:
            # a derivative that cannot be computed is NaN, never an exception from inside a
            # transformation (lineax raises on a failed result)
            x = jnp.where(ok, x, jnp.nan)
            result = lx.RESULTS.successful
        else:
            result = lx.RESULTS.where(ok, lx.RESULTS.successful, lx.RESULTS.max_steps_reached)
        return unravel(flat_d * x), result, {"num_steps": steps, "residual": res, "converged": ok}

    def transpose(self, state, options):
        # the transposed system's unknowns are cotangents: scaled by the inverse magnitudes
        operator, scales = state
        return (operator.transpose(), _inverse(scales)), options

    def conj(self, state, options):
        operator, scales = state
        return (lx.conj(operator), scales), options

    def assume_full_rank(self):
        return True
