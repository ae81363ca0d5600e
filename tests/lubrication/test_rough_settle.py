"""Deep mixed steady films by pseudo-transient continuation, the last attempt of ``solve_ehl`` for a
deterministic rough film (``ehl.continuation._pseudo_march``, issue 4): where the direct steady
solve fails, a march in pseudo-time with the roughness held reaches a state from which the steady
solve converges, inside the compiled solve."""

import jax.numpy as jnp
import numpy as np
import pytest
from helpers import gear_contact

import jaxgear as jg
from jaxgear.lubrication.ehl import discretisation
from jaxgear.lubrication.ehl.continuation import _with_pseudo_squeeze
from jaxgear.lubrication.ehl.discretisation import _grid_positions
from jaxgear.lubrication.ehl.model import _Inputs, _split_numbers
from jaxgear.lubrication.roughness import ground

LUB = jg.presets.mil_l_23699()


def _fine_level(n=65, transient=True):
    c = gear_contact(rpm=3500.0)
    x = _grid_positions(jg.EHLModel(n_nodes=n), c, LUB)
    rng = np.random.default_rng(3)
    rho_h_prev = jnp.asarray(850.0 * 1e-7 * (1.0 + 0.2 * rng.random(n)))
    inv_dt = jnp.asarray(2.0e5 if transient else 0.0)
    z = jnp.zeros(n)
    numbers, model = _split_numbers(jg.EHLModel(n_nodes=n, mixed="deterministic"))
    offset = 1e-7 * jnp.sin(x / 1e-5)
    inp = _Inputs(c, LUB, rho_h_prev, inv_dt, offset, z, jnp.zeros(()), numbers)
    return discretisation._fine_level(model, inp)[1]


@pytest.mark.parametrize("transient", [False, True])
def test_pseudo_squeeze_is_a_backward_euler_term_added_to_the_problem(transient):
    # R'(P, H) = R(P, H) − σp (ρ̄H − ρ̄H_state): the combined squeeze term of
    # ``_with_pseudo_squeeze`` must be exactly the level's own plus the pseudo-time one (the
    # squeeze term is linear in ρ̄H), and σp = 0 must give the level back bit for bit, so that the
    # march's steady tries solve the caller's problem
    level = _fine_level(transient=transient)
    n = level.n
    rng = np.random.default_rng(5)
    p = jnp.asarray(np.clip(1.0 - level.x**2, 0.0, None) + 0.01 * rng.random(n))
    h = jnp.asarray(0.3 + 0.5 * level.x**2 + 0.05 * rng.random(n))
    rho_h_state = level.density(p) * (h + 0.02 * jnp.cos(3.0 * level.x))
    r0, _ = level.reynolds(p, h, 1.0)
    same = _with_pseudo_squeeze(level, jnp.asarray(0.0), rho_h_state)
    assert np.array_equal(np.asarray(same.reynolds(p, h, 1.0)[0]), np.asarray(r0))
    sigma = jnp.asarray(37.0)
    r1, _ = _with_pseudo_squeeze(level, sigma, rho_h_state).reynolds(p, h, 1.0)
    expected = r0 - sigma * (level.density(p) * h - rho_h_state)
    # interior nodes (the boundary entries are replaced by the Dirichlet rows); rounding only
    scale = float(jnp.max(jnp.abs(expected[1:-1])))
    np.testing.assert_allclose(r1[1:-1], expected[1:-1], rtol=0.0, atol=1e-12 * scale)


def test_pseudo_transient_steps_is_validated():
    with pytest.raises(ValueError, match="pseudo_transient_steps"):
        jg.EHLModel(pseudo_transient_steps=-1)


def test_a_converged_direct_solve_never_reaches_the_march():
    # speed E on 129 nodes: the direct steady solve converges, so the march attempt is skipped:
    # the same Newton iterations and the same film with and without it. The two are different
    # programs, which XLA may compile to round-off-different code (the tests' unoptimised code
    # does: ~1e-17 of the peak pressure apart); a march reached would change the iteration count
    # and move the film by the Newton tolerance, ~1e-9 of the peak
    c = gear_contact(rpm=3500.0)
    with_march = jg.solve_ehl(c, LUB, jg.EHLModel(n_nodes=129, mixed="deterministic"), ground())
    without = jg.solve_ehl(
        c, LUB, jg.EHLModel(n_nodes=129, mixed="deterministic", pseudo_transient_steps=0), ground()
    )
    assert bool(with_march.converged) and bool(without.converged)
    assert int(with_march.iterations) == int(without.iterations)
    p, q = np.asarray(with_march.p), np.asarray(without.p)
    np.testing.assert_allclose(p, q, rtol=0.0, atol=1e-13 * np.max(np.abs(q)))


@pytest.mark.slow
def test_deep_mixed_film_at_1500_nm_converges_by_the_pseudo_time_march():
    # ~170 s in the default run of 2026-11-28 (its largest test), so slow since. 500 rpm, 1500 N m, ground, 513 nodes, pitch contact: the direct solve (march switched off)
    # ends at residual 2e-3 (measured 2026-11-27); with the march, the compiled solve converges
    # (~22 s after compilation; the eager march it replaces measured 22.9 % on the asperities)
    c = gear_contact(rpm=500.0, torque=1500.0)
    direct = jg.solve_ehl(
        c, LUB, jg.EHLModel(n_nodes=513, mixed="deterministic", pseudo_transient_steps=0), ground()
    )
    assert not bool(direct.converged), "the direct solve converges now: pick a case it fails"
    model = jg.EHLModel(n_nodes=513, mixed="deterministic")
    settled = jg.solve_ehl(c, LUB, model, ground())
    assert bool(settled.converged), float(settled.residual)
    assert float(settled.residual) < model.tolerance
    assert abs(float(settled.load_error)) < 1e-6
    # deep mixed at twice the torque: a larger share of the load on the asperities than the
    # 700 N m film's 5.9 % on this grid (measured 22.9 %), and asperity pressures well above Hertz
    assert 0.059 < float(settled.contact_load_share) < 1.0
    assert float(settled.p_max / settled.hertz_pressure) > 3.0


@pytest.mark.slow
def test_deep_mixed_steady_film_on_513_nodes_converges_where_the_direct_solve_fails():
    # 500 rpm (λ ≈ 0.1), pitch contact, ground, 513 nodes: the direct solve's roughness continuation
    # meets a fold at 0.775 of the roughness and ends not converged (residual 1.4, measured
    # 2026-11-27); the march reaches a state from which the steady solve converges (measured:
    # p_max 5.9 ph, 5.9 % of the load on the asperities)
    c = gear_contact(rpm=500.0)
    direct = jg.solve_ehl(
        c, LUB, jg.EHLModel(n_nodes=513, mixed="deterministic", pseudo_transient_steps=0), ground()
    )
    assert not bool(direct.converged)
    settled = jg.solve_ehl(c, LUB, jg.EHLModel(n_nodes=513, mixed="deterministic"), ground())
    assert bool(settled.converged), float(settled.residual)
    # a steady solution of the same contact: the load is carried (the load row is part of the
    # system, so this checks the returned fields, not the solver), the film still mixed, and its
    # asperity pressures those of the paper's ground surfaces at this speed on the coarser grid,
    # where the direct solve converges: the share within a factor 3 (sharper, fewer contact spots
    # are resolved on 513 nodes), p_max of both between 3 and 10 ph (Fig. 12's "well above Hertz")
    assert abs(float(settled.load_error)) < 1e-6
    coarse = jg.solve_ehl(c, LUB, jg.EHLModel(n_nodes=257, mixed="deterministic"), ground())
    assert bool(coarse.converged)
    share, share_coarse = float(settled.contact_load_share), float(coarse.contact_load_share)
    assert share_coarse / 3.0 < share < 3.0 * share_coarse, (share, share_coarse)
    for sol in (settled, coarse):
        assert 3.0 < float(sol.p_max / sol.hertz_pressure) < 10.0
