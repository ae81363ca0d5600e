"""The vmap-lazy cond (``jaxgear._solvers.lazy_cond.cond_any_member``, used by the EHL solver and the
coupled model's attractor branch): the same values as ``lax.cond``, and under vmap a branch that no member takes does not run. Plain ``vmap(lax.cond)`` runs both branches for
every member, which made a vmapped batch of 64 contacts pay for every fallback attempt (211 ms per
contact against 21 ms solved one by one; benchmarks/ehl_kernel.py)."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxgear._solvers.lazy_cond import cond_any_member


def _counting():
    runs = {"expensive": 0}

    def bump(n):
        runs["expensive"] += int(n)

    def expensive(op):
        x, k = op
        jax.debug.callback(bump, jnp.ones((), jnp.int32))
        return jnp.sin(x) * k

    def cheap(op):
        return op[0]

    return runs, expensive, cheap


@pytest.mark.parametrize(
    "pred",
    [[True, True, True], [False, False, False], [True, False, True]],
    ids=["all", "none", "some"],
)
@pytest.mark.parametrize("all_true_path", [True, False])
def test_values_equal_lax_cond_under_vmap(pred, all_true_path):
    _, expensive, cheap = _counting()
    pred = jnp.asarray(pred)
    x = jnp.asarray([0.3, 1.1, -2.0])
    k = 2.5  # an unbatched operand, broadcast by the rule
    lazy = jax.vmap(
        lambda p, x: cond_any_member(p, expensive, cheap, (x, k), all_true_path=all_true_path)
    )(pred, x)
    plain = jax.vmap(lambda p, x: jax.lax.cond(p, expensive, cheap, (x, k)))(pred, x)
    np.testing.assert_array_equal(np.asarray(lazy), np.asarray(plain))


@pytest.mark.parametrize("all_true_path", [True, False])
def test_untaken_branch_does_not_run_under_vmap(all_true_path):
    runs, expensive, cheap = _counting()
    x = jnp.asarray([0.3, 1.1, -2.0])
    f = jax.jit(
        jax.vmap(
            lambda p, x: cond_any_member(p, expensive, cheap, (x, 1.0), all_true_path=all_true_path)
        )
    )
    jax.block_until_ready(f(jnp.zeros(3, bool), x))
    assert runs["expensive"] == 0  # no member takes it: the batch skips it
    jax.block_until_ready(f(jnp.asarray([False, True, False]), x))
    assert runs["expensive"] >= 1  # one member takes it: it runs (batched)
    # the plain vmapped lax.cond runs it even when no member takes it (what this replaces)
    runs["expensive"] = 0
    g = jax.jit(jax.vmap(lambda p, x: jax.lax.cond(p, expensive, cheap, (x, 1.0))))
    jax.block_until_ready(g(jnp.zeros(3, bool), x))
    assert runs["expensive"] >= 1


def test_nested_vmap():
    runs, expensive, cheap = _counting()
    pred = jnp.asarray([[False, False], [False, True]])
    x = jnp.asarray([[0.3, 1.1], [-2.0, 0.7]])
    f = jax.vmap(jax.vmap(lambda p, x: cond_any_member(p, expensive, cheap, (x, 3.0))))
    out = f(pred, x)
    np.testing.assert_allclose(np.asarray(out), np.where(pred, 3.0 * np.sin(x), x), rtol=1e-15)
    runs["expensive"] = 0
    jax.block_until_ready(jax.jit(f)(jnp.zeros((2, 2), bool), x))
    assert runs["expensive"] == 0


def test_derivatives_are_those_of_lax_cond():
    # differentiated, it falls back to the plain cond: forward, reverse, and under vmap
    _, expensive, cheap = _counting()

    def f(x, p):
        return cond_any_member(p, expensive, cheap, (x, 3.0))

    for diff in (jax.jacfwd, jax.grad):
        assert float(diff(f)(0.4, True)) == pytest.approx(3.0 * np.cos(0.4), rel=1e-14)
        assert float(diff(f)(0.4, False)) == 1.0
    g = jax.vmap(jax.grad(f))(jnp.asarray([0.4, 0.5]), jnp.asarray([True, False]))
    np.testing.assert_allclose(np.asarray(g), [3.0 * np.cos(0.4), 1.0], rtol=1e-14)


def _recording():
    seen = []

    def expensive(op):
        x, k = op
        jax.debug.callback(lambda v: seen.append(np.asarray(v).copy()), x)
        return jnp.sin(x) * k

    return seen, expensive, lambda op: op[0]


@pytest.mark.parametrize("mixed", ["select", "map"])
def test_mixed_batch_map_runs_the_branch_only_for_the_members_that_take_it(mixed):
    # What the coupled model's attractor branch needs in a vmapped sweep: 27 of 149 speeds take a
    # 2000-cycle time integration, which the select ran batched for all 149 (benchmarks/RESULTS.md,
    # accelerator: 615 s for the baseline sweep on 2 cores).
    seen, expensive, cheap = _recording()
    pred = jnp.asarray([False, True, False, True])
    x = jnp.asarray([0.3, 1.1, -2.0, 0.7])
    f = jax.jit(jax.vmap(lambda p, x: cond_any_member(p, expensive, cheap, (x, 2.0), mixed=mixed)))
    out = jax.block_until_ready(f(pred, x))
    np.testing.assert_allclose(np.asarray(out), np.where(pred, 2.0 * np.sin(x), x), rtol=1e-15)
    values = np.concatenate([np.ravel(v) for v in seen])
    if mixed == "map":
        # one unbatched call per member that takes the branch, and none for the others
        assert len(seen) == 2 and all(np.ndim(v) == 0 for v in seen)
        np.testing.assert_array_equal(np.sort(values), np.sort(np.asarray(x)[np.asarray(pred)]))
    else:
        np.testing.assert_array_equal(np.sort(values), np.sort(np.asarray(x)))  # every member
    # nested vmaps stay lazy with map: the all-false inner batch never runs the branch
    seen.clear()
    g = jax.jit(
        jax.vmap(jax.vmap(lambda p, x: cond_any_member(p, expensive, cheap, (x, 2.0), mixed=mixed)))
    )
    pred2, x2 = pred.reshape(2, 2), x.reshape(2, 2)
    out2 = jax.block_until_ready(g(pred2, x2))
    np.testing.assert_allclose(np.asarray(out2), np.where(pred2, 2.0 * np.sin(x2), x2), rtol=1e-15)
    if mixed == "map":
        assert sorted(float(np.ravel(v)[0]) for v in seen) == sorted([1.1, 0.7])
    with pytest.raises(ValueError, match="mixed"):
        cond_any_member(True, expensive, cheap, (x, 2.0), mixed="both")
