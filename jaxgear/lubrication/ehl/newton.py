"""Newton with backtracking on a level's system, and its linear solves: the dense LU (single
precision refined on large grids), or GMRES on Jacobian-vector products with a block-Jacobi,
bordered preconditioner (``linear_solver="krylov"``)."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import jax.scipy.linalg
import lineax as lx

from ..._solvers.krylov import EarlyExitGMRES
from ..._solvers.lazy_cond import cond_any_member
from .discretisation import _BAND, _KRYLOV_BLOCK, _Level


def _norm_inf(f):
    return jnp.max(jnp.abs(f))


_MIXED_PRECISION_NODES = 513  # from this size on, the LU of the Newton matrix is single precision
# and from this size on for deterministic rough films, whose many Newton iterations (transient
# passages: ~100 a step) make the LU most of their cost: a thermal engagement along the path at
# 257 nodes runs ~11 % faster, the same steps converged; a few steps land on another discrete
# solution of such a film, as the solver's path decides there (docs/limitations.md, deterministic
# roughness)
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


# (_KRYLOV_MIN_NODES: ``model.py``, read by ``EHLModel.use_krylov``; _KRYLOV_BLOCK:
# ``discretisation.py``, which sizes a level's near kernel by it)
_KRYLOV_RESTART = 40  # Krylov vectors a GMRES cycle
_KRYLOV_CYCLES = 3  # GMRES cycles before the direction is taken as it stands


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
    dps, dhs, slope, _ = level.bands(u, s)

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


def _krylov_direction(level: _Level, u, s):
    """(F(u), Newton direction d ≈ −J⁻¹F) without forming J: GMRES (right-preconditioned by
    ``_block_preconditioner``) on J·v = ∂F/∂u·v by forward mode through the residual, whose
    deformation is the DC-FFT product. O(N log N) an iteration instead of the dense LU's O(N³).
    GMRES stops at ‖J d + F‖ ≤ ``_DIRECTION_TOLERANCE``‖F‖ (inexact Newton: each Newton iteration
    still contracts the residual by about that factor) or after ``_KRYLOV_CYCLES`` cycles.

    Why 128-node blocks: on a transient step at the pitch contact (3500 rpm, 1025 nodes) GMRES
    needs 6-11 vectors with them, 7-19 with blocks of 64, 21-58 without a preconditioner and
    74-289 with the previous step's exact LU (the film's Jacobian moves with the roughness). The
    Newton iterations a step do not depend on the GMRES tolerance between 1e-2 and 1e-5.
    """
    factors = _block_preconditioner(level, u, s)
    f, jvp = jax.linearize(lambda v: level.residual(v, s), u)

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
    return f, _bordered_solve(level, factors, y)


def _newton(level: _Level, u0, s, max_iter: int, tol=None):
    """Damped Newton on level's system to ‖F‖∞ < ``tol`` (default: the model's tolerance).
    Returns (u, ‖F‖∞, iterations, converged)."""
    tol = level.model.tolerance if tol is None else tol

    def merit_of(f):
        m = jnp.sum(f * f)
        return jnp.where(jnp.isfinite(m), m, jnp.inf)

    def merit(u):
        f = level.residual(u, s)
        return f, merit_of(f)

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
        u, _, _, it, _, lu = state
        # the residual at u comes with the linearisation the direction needs (no evaluation of its
        # own: the residual is most of the program, and each call site is compiled anew)
        if krylov:
            f, d = _krylov_direction(level, u, s)
        else:
            f, jac = level.residual_and_jacobian(u, s)
            d, lu = _newton_direction(jac=jac, f=f, lu_prev=lu)
        m = merit_of(f)
        # a start that meets the tolerance is kept as it is, and takes no iteration
        converged = _norm_inf(f) < tol
        d = jnp.where(jnp.isfinite(d) & ~converged, d, 0.0)
        # cap the film-offset change per step: a runaway H0 is the usual way a far start diverges
        cap = 0.5 * jnp.maximum(jnp.abs(u[-1]), 10.0 * level.sc.h_ref)
        d = d * jnp.minimum(1.0, cap / jnp.maximum(jnp.abs(d[-1]), 1e-300))

        # backtracking α = 1, 1/2, … (Armijo on ½‖F‖²); one call site keeps the compiled loop small
        def ls_cond(ls):
            alpha, _, m_new, k = ls
            return (m_new > (1.0 - 1e-4 * alpha) * m) & (k < 12) & ~converged

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
        ok = jnp.isfinite(m_new) & ~converged
        u_new = jnp.where(ok, u + alpha * d, u)
        f_new = jnp.where(ok, f_new, f)
        m_new = jnp.where(ok, m_new, m)
        done = converged | (_norm_inf(f_new) < tol)
        stalled = (~ok) | (alpha * _norm_inf(d) < 1e-15)
        return u_new, f_new, m_new, it + jnp.where(converged, 0, 1), done | stalled, lu

    dtype = u0.dtype
    init = (
        u0,
        jnp.full_like(u0, jnp.inf),
        jnp.asarray(jnp.inf, dtype),
        jnp.asarray(0),
        jnp.asarray(False),
        lu0,
    )
    u, f, m, it, _, _ = jax.lax.while_loop(cond, body, init)
    res = _norm_inf(f)
    return u, res, it, res < tol
