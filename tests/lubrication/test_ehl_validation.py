"""EHL films against the published formulas (Moes; Pan & Hamrock), grid convergence and the
rolling-power identity. Heavy grids are ``slow``; each slow test has a cheap default sibling."""

import jax.numpy as jnp
import numpy as np
import pytest
from helpers import gear_contact, moes_central, moes_contact, pan_hamrock

import jaxgear as jg

LUB = jg.presets.mil_l_23699()
MOES_PHYSICS = dict(viscosity="barus", compressibility="incompressible", shear="newtonian")


def _moes_error(m, l, model):
    c = moes_contact(m, l, LUB)
    s = jg.solve_ehl(c, LUB, model)
    u = (
        float(LUB.base_viscosity(363.15))
        * float(c.rolling_velocity)
        / (float(c.e_reduced) * float(c.reduced_radius))
    )
    h_m = float(s.h_central) / float(c.reduced_radius) / np.sqrt(2 * u)
    return s, h_m / moes_central(m, l) - 1.0


@pytest.mark.parametrize("m, l", [(5.0, 3.0), (5.0, 8.0), (20.0, 3.0), (20.0, 8.0)])
def test_moes_central_film_moderate_load(m, l):
    # N = 257 resolves these (small spikes): measured |error| ≤ 2 %; Moes' fit is good to a few %,
    # the bound is 4 %.
    s, err = _moes_error(m, l, jg.EHLModel(n_nodes=257, **MOES_PHYSICS))
    assert bool(s.converged)
    assert abs(err) < 0.04, err


@pytest.mark.slow
@pytest.mark.parametrize("m", [5.0, 20.0, 50.0, 100.0, 200.0, 300.0])
@pytest.mark.parametrize("l", [3.0, 8.0, 15.0])
def test_moes_central_film_full_range(m, l):
    # high M needs fine grids (REFERENCE §8): 1025 nodes up to M = 100, 2049 beyond. Measured
    # (2026-11-22): |error| ≤ 4 % everywhere except at L = 15, where Barus gives ᾱ = L √(M/2π)
    # = 27-85 and every case sits 3-5 % above Moes' fit: (5, 15) +3.99 %, (20, 15) +4.69 %
    # (+3.28 / +4.31 / +4.69 % on 257 / 513 / 1025 nodes, extrapolated ≈ +4.9 %), (50, 15)
    # +3.99 %, (100, 15) +2.96 %, (200, 15) +4.27 %. 5 % bounds that row; the 4 % is not met
    # there (README, known open points). The excess is the fit's, not the discretisation's
    # (measured 2026-11-22 at (20, 15)): the first-order upwind wedge approaches from above (+9.16 /
    # +7.16 / +6.09 % on 257 / 513 / 1025 nodes, first order, extrapolated +4.9 %) and the
    # second-order one from below (extrapolated +4.9 %), and doubling the inlet length at equal Δx
    # adds another +0.45 %. (200, 15) needs the third cold attempt (continuation of the
    # piezo-viscous exponent on the finest grid): before it, the solve stalled at ‖F‖∞ ≈ 1e-2.
    n = 1025 if m <= 100 else 2049
    s, err = _moes_error(m, l, jg.EHLModel(n_nodes=n, **MOES_PHYSICS))
    assert bool(s.converged)
    assert abs(err) < (0.05 if l == 15.0 else 0.04), err


def test_rolling_power_identity_incompressible_newtonian():
    """For a steady, incompressible, Newtonian film the Poiseuille dissipation equals the rolling
    power: ∫ h³ p'²/(12η) dx = (u1 + u2) ∫ (h/2) p' dx (integrate −∫ q p' dx by parts, dq/dx = 0
    where
    p > 0, p = 0 elsewhere). The two sides use different outputs (power_loss_rolling and
    friction_rolling): the identity holds only if p satisfies Reynolds."""
    model = jg.EHLModel(n_nodes=257, **MOES_PHYSICS)
    c = moes_contact(20.0, 3.0, LUB, slide_to_roll=0.5)  # no pressure spike at L = 3
    s = jg.solve_ehl(c, LUB, model)
    lhs = float(s.power_loss_rolling)
    rhs = float(c.u1 + c.u2) * float(s.friction_rolling)
    # O(Δ) quadrature differences between the node sums: 2 % at 257 nodes
    assert lhs == pytest.approx(rhs, rel=0.02)
    # the sliding loss follows from the friction: ∫ η us²/h = |Fs| |us| (Newtonian)
    assert float(s.power_loss_sliding) == pytest.approx(
        abs(float(s.friction_sliding) * float(c.u1 - c.u2)), rel=1e-9
    )


# Pan-Hamrock: Roelands + Dowson-Higginson, pure rolling (η* = η), the paper's pair at the pitch
# point
@pytest.mark.parametrize("torque, rpm", [(200.0, 500.0), (700.0, 2000.0), (700.0, 4200.0)])
def test_pan_hamrock_moderate(torque, rpm):
    c = gear_contact(torque, rpm, slide_to_roll=0.0)
    s = jg.solve_ehl(c, LUB, jg.EHLModel(n_nodes=257))
    hmin, hc = pan_hamrock(c, LUB)
    assert bool(s.converged)
    # issue bounds: h_min 6 %, h_central 12 % (the formula families differ by ~6 %, REFERENCE §8);
    # measured at 257 nodes: ≤ 3 % and ≤ 5 %
    assert float(s.h_min) == pytest.approx(hmin, rel=0.06)
    assert float(s.h_central) == pytest.approx(hc, rel=0.12)


@pytest.mark.slow
@pytest.mark.parametrize("torque", [200.0, 700.0, 1500.0])
@pytest.mark.parametrize("rpm", [500.0, 2000.0, 4200.0])
def test_pan_hamrock_gear_range(torque, rpm):
    # light to heavy load (M ≈ 7-160), slow to fast; 1025 nodes resolve M ≈ 160 (REFERENCE §8)
    c = gear_contact(torque, rpm, slide_to_roll=0.0)
    s = jg.solve_ehl(c, LUB, jg.EHLModel(n_nodes=1025))
    hmin, hc = pan_hamrock(c, LUB)
    assert bool(s.converged)
    assert float(s.h_min) == pytest.approx(hmin, rel=0.06)
    assert float(s.h_central) == pytest.approx(hc, rel=0.12)


def _grid_study(sizes, contact):
    out = []
    for n in sizes:
        s = jg.solve_ehl(contact, LUB, jg.EHLModel(n_nodes=n))
        assert bool(s.converged), n
        out.append((float(s.h_min), float(s.friction_sliding), float(s.power_loss)))
    return np.array(out)


def test_grid_convergence_coarse():
    # h_min and friction change less with each refinement (65 → 129 → 257 nodes)
    r = _grid_study((65, 129, 257), gear_contact())
    d = np.abs(np.diff(r, axis=0)) / np.abs(r[-1])
    assert np.all(d[1] < d[0]), d


@pytest.mark.slow
def test_grid_convergence_fine_and_default_error():
    sizes = (129, 257, 513, 1025, 2049)
    r = _grid_study(sizes, gear_contact())
    d = np.abs(np.diff(r, axis=0)) / np.abs(r[-1])
    assert np.all(d[1:] < d[:-1]), d
    # the default grid (257 nodes) against the finest: stated in benchmarks/RESULTS.md
    err = np.abs(r[1] - r[-1]) / np.abs(r[-1])
    assert err[0] < 0.10 and err[1] < 0.05, err
    assert jnp.all(jnp.isfinite(jnp.asarray(r)))
