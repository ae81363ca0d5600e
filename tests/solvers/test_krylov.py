"""EarlyExitGMRES (jaxgear/_solvers/krylov.py): the linear solver of the fixed point's implicit derivative.

Checked against dense solves (numpy), the finite-termination property of GMRES, and lineax's own
GMRES on the matrix-vector count it exists to cut."""

import jax
import jax.numpy as jnp
import lineax as lx
import numpy as np
import pytest

from jaxgear._solvers.krylov import EarlyExitGMRES

SIZES = (64, 13, 32)
SCALES = (1e4, 1.0, 1e-6)  # N, a scaled orbit state, m: the fixed point's leaves differ this much


def _split(v):
    a, b = SIZES[0], SIZES[0] + SIZES[1]
    return {"force": v[:a], "orbit": v[a:b], "dte": v[b:]}


def _join(t):
    return jnp.concatenate([t["force"], t["orbit"], t["dte"]])


def _problem(rho, seed=0, rank=None, output_dte=False):
    """A = D (I − J) D⁻¹ on a pytree of leaves with magnitudes SCALES (D), J of spectral radius rho
    (or of rank ``rank``); the root has the leaves' magnitudes, as the fixed point's does.
    ``output_dte``: no leaf depends on the DTE leaf (J's columns of it zero), as no part of the
    fixed-point map reads the outputs its state carries."""
    rng = np.random.default_rng(seed)
    n = sum(SIZES)
    if rank is None:
        j = rng.normal(size=(n, n))
    else:
        j = rng.normal(size=(n, rank)) @ rng.normal(size=(rank, n))
    if output_dte:
        j[:, SIZES[0] + SIZES[1] :] = 0.0
    j *= rho / np.max(np.abs(np.linalg.eigvals(j)))
    d = np.concatenate([np.full(s, c) for s, c in zip(SIZES, SCALES)])
    a = np.diag(d) @ (np.eye(n) - j) @ np.diag(1.0 / d)
    root = _split(jnp.asarray(d * (1.0 + rng.random(n))))
    op = lx.JacobianLinearOperator(lambda x, _: _split(jnp.asarray(a) @ _join(x)), root)
    b = d * rng.normal(size=n)
    return op, a, b, d


def _solve(op, b, solver):
    @jax.jit
    def run(b):
        sol = lx.linear_solve(op, _split(b), solver, throw=False)
        return _join(sol.value), sol.stats["num_steps"], sol.result == lx.RESULTS.successful

    return run(jnp.asarray(b))


@pytest.mark.parametrize("rho", [0.1, 0.5, 0.95])
def test_matches_a_dense_solve_across_leaf_scales(rho):
    op, a, b, d = _problem(rho)
    x, steps, ok = _solve(op, b, EarlyExitGMRES(rtol=1e-10, atol=0.0))
    exact = np.linalg.solve(a, b)
    # Error in the per-leaf scaled variables, relative to the solution's size there: at most the
    # residual tolerance 1e-10 times the condition number of I − J (≤ ~40 for these J), so 1e-8.
    err = np.max(np.abs(np.asarray(x) - exact) / d) / np.max(np.abs(exact) / d)
    assert bool(ok)
    assert err < 1e-8
    # every leaf is solved to its own scale, the 1e-6 one (metres) as well as the 1e4 one (N)
    for sl in (slice(0, 64), slice(64, 77), slice(77, None)):
        assert np.allclose(
            np.asarray(x)[sl], exact[sl], rtol=0, atol=1e-8 * np.max(np.abs(exact[sl]))
        )


def test_stops_when_the_krylov_space_is_exhausted():
    # GMRES solves I − J with J of rank 3 exactly in at most 4 Krylov vectors (finite
    # termination); lineax's GMRES, which tests only between restart cycles and ends when two agree,
    # spends two whole cycles (2 × restart matrix-vector products) on it.
    op, a, b, _ = _problem(0.8, seed=1, rank=3)
    x, steps, ok = _solve(op, b, EarlyExitGMRES(rtol=1e-10, atol=0.0))
    assert bool(ok)
    assert int(steps) <= 4
    assert np.allclose(np.asarray(x), np.linalg.solve(a, b), rtol=1e-8, atol=0.0)

    _, cycles, ok_lx = _solve(op, b, lx.GMRES(rtol=1e-10, atol=1e-10, restart=20))
    assert bool(ok_lx)
    assert int(cycles) >= 2  # ≥ 2 × 20 + 1 products against ≤ 4 + 2 here


def test_restarts_converge_and_failure_is_reported_not_nan():
    op, a, b, _ = _problem(0.5, seed=2)
    # a short restart still converges, over several cycles
    x, steps, ok = _solve(op, b, EarlyExitGMRES(rtol=1e-10, atol=0.0, restart=6))
    assert bool(ok) and int(steps) > 6
    assert np.allclose(np.asarray(x), np.linalg.solve(a, b), rtol=1e-7, atol=0.0)
    # too few Krylov vectors in total: not converged, reported, finite
    x, steps, ok = _solve(op, b, EarlyExitGMRES(rtol=1e-10, atol=0.0, restart=2, max_restarts=2))
    assert not bool(ok)
    assert np.all(np.isfinite(np.asarray(x)))
    with pytest.raises(Exception, match="max_steps|maximum"):
        jax.block_until_ready(
            lx.linear_solve(
                op,
                _split(jnp.asarray(b)),
                EarlyExitGMRES(rtol=1e-10, atol=0.0, restart=2, max_restarts=2),
            ).value
        )


def test_zero_right_hand_side_and_vmap_equal_loop():
    op, a, b, _ = _problem(0.5, seed=3)
    x, steps, ok = _solve(op, np.zeros_like(b), EarlyExitGMRES(rtol=1e-10, atol=0.0))
    assert bool(ok) and int(steps) == 0 and np.all(np.asarray(x) == 0.0)

    rng = np.random.default_rng(4)
    bs = jnp.asarray(b[None, :] * rng.normal(size=(3, 1)) + rng.normal(size=(3, b.size)))
    solver = EarlyExitGMRES(rtol=1e-12, atol=0.0)

    def one(bb):
        return _join(lx.linear_solve(op, _split(bb), solver).value)

    batched = jax.jit(jax.vmap(one))(bs)
    for k in range(3):
        assert np.allclose(np.asarray(batched[k]), np.asarray(jax.jit(one)(bs[k])), rtol=1e-10)


def _leafwise_error(x, exact):
    """Largest error of each leaf relative to that leaf's largest exact entry."""
    x, exact = _split(np.asarray(x)), _split(exact)
    return {k: np.max(np.abs(x[k] - exact[k])) / np.max(np.abs(exact[k])) for k in exact}


@pytest.mark.parametrize("rho", [0.5, 0.95])
def test_transposed_solve_scales_cotangents_by_inverse_magnitudes(rho):
    # reverse mode's system Aᵀ λ = g: the unknowns are cotangents, of the inverse units of the
    # root's leaves, and g is the cotangent of one output in metres (the DTE leaf alone, 1/1e-6),
    # an output that no leaf depends on. Scaled by the root's magnitudes, the residual on the
    # other leaves weighs (1e-6 / their magnitude)² of the DTE leaf's, and the solve stops with
    # them unconverged; by their inverses every leaf is solved to its own scale: the error of each
    # leaf relative to its size is at most the tolerance 1e-10 times the condition number of
    # I − J (as above), so 1e-8
    op, a, _, d = _problem(rho, seed=5, output_dte=True)
    rng = np.random.default_rng(6)
    g = np.zeros(sum(SIZES))
    g[SIZES[0] + SIZES[1] :] = rng.normal(size=SIZES[2]) / SCALES[2]
    exact = np.linalg.solve(a.T, g)
    solver = EarlyExitGMRES(rtol=1e-10, atol=0.0)
    root = op.x

    def transposed(g, flag):
        options = {"scale_point": root, "transposed": flag}
        sol = lx.linear_solve(op.T, _split(g), solver, options=options, throw=False)
        return _join(sol.value)

    errors = _leafwise_error(transposed(jnp.asarray(g), True), exact)
    assert max(errors.values()) < 1e-8, errors
    # the tangents' scaling leaves the other leaves far off (the defect this option fixes)
    wrong = _leafwise_error(transposed(jnp.asarray(g), False), exact)
    assert min(wrong["force"], wrong["orbit"]) > 1e-3, wrong

    # lineax's own transpose of the solve (the reverse mode of linear_solve): the solver's
    # ``transpose`` inverts the scales likewise
    def solve(b):
        return _join(lx.linear_solve(op, _split(b), solver).value)

    _, pullback = jax.vjp(solve, jnp.zeros(sum(SIZES)))
    errors = _leafwise_error(jax.jit(pullback)(jnp.asarray(g))[0], exact)
    assert max(errors.values()) < 1e-8, errors
