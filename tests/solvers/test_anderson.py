"""Anderson acceleration (jaxgear._solvers.anderson) against closed-form fixed points.

Checked against things it does not produce: the fixed point of an affine contraction solved by a
linear solve, the iteration count of plain iteration on the same map, implicit gradients against the
closed form, and the termination test on a ``measure`` when part of the state never settles.
"""

import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
import pytest

from jaxgear._solvers.anderson import Anderson

jax.config.update("jax_enable_x64", True)

# Affine contraction T(y) = A y + b θ with spectral radius 0.95: plain iteration needs
# log(1e-10)/log(0.95) ≈ 450 steps, Anderson (exact on affine maps after n+1 steps in exact
# arithmetic) a handful.
_RNG = np.random.default_rng(3)
_Q, _ = np.linalg.qr(_RNG.normal(size=(6, 6)))
_A = jnp.asarray(_Q @ np.diag([0.95, -0.9, 0.7, 0.5, -0.3, 0.1]) @ _Q.T)
_B = jnp.asarray(_RNG.normal(size=6))


def _affine(y, theta):
    return _A @ y + _B * theta


def _exact(theta):
    return jnp.linalg.solve(jnp.eye(6) - _A, _B * theta)


def test_affine_fixed_point_and_acceleration():
    solver = Anderson(rtol=1e-10, atol=1e-12, memory=6)
    sol = optx.fixed_point(_affine, solver, jnp.zeros(6), args=2.0, max_steps=100, throw=False)
    assert sol.result == optx.RESULTS.successful
    # Converged to rtol 1e-10 of a map with contraction 0.95: error ≤ 1e-10/(1 − 0.95) · |y| ~ 2e-9.
    np.testing.assert_allclose(sol.value, _exact(2.0), rtol=0, atol=1e-8)
    # Plain iteration on the same map needs ~450 steps; Anderson must need far fewer.
    assert int(sol.stats["num_steps"]) < 30


def test_implicit_gradient_matches_closed_form():
    solver = Anderson(rtol=1e-12, atol=1e-14, memory=6)

    def fp(theta):
        sol = optx.fixed_point(
            _affine, solver, jnp.zeros(6), args=theta, max_steps=100, adjoint=optx.ImplicitAdjoint()
        )
        return jnp.sum(sol.value**2)

    grad = jax.grad(fp)(1.5)
    # d/dθ |(I − A)⁻¹ b θ|² = 2 θ |(I − A)⁻¹ b|².
    exact = 2 * 1.5 * jnp.sum(_exact(1.0) ** 2)
    np.testing.assert_allclose(grad, exact, rtol=1e-8)


@pytest.mark.parametrize("use_measure", [True, False])
def test_measure_ignores_a_mixed_part_that_never_settles(use_measure):
    # State (x, w): x follows the affine contraction; w is a "warm start" that drifts by 1e-6 each
    # step and does not feed back into x (as the orbit guess in the tribo-dynamic fixed point, whose
    # shooting can land on slightly different initial states while the tables have settled).
    def fn(y, theta):
        x, w = y
        return (_affine(x, theta), w + 1e-6)

    solver = Anderson(
        rtol=1e-10,
        atol=1e-12,
        memory=6,
        core=lambda y: y,
        replace_core=lambda y, c: (c[0], y[1]),  # w drifts whatever the mixing
        measure=(lambda y: y[0]) if use_measure else None,
    )
    sol = optx.fixed_point(
        fn, solver, (jnp.zeros(6), jnp.zeros(())), args=2.0, max_steps=60, throw=False
    )
    if use_measure:
        assert sol.result == optx.RESULTS.successful
        np.testing.assert_allclose(sol.value[0], _exact(2.0), rtol=0, atol=1e-8)
    else:  # the same state measured over the whole core never meets the tolerance
        assert sol.result != optx.RESULTS.successful
