"""The Newton matrix of a deterministic rough film is factorised in single precision from 257 nodes
(``ehl.newton._MIXED_PRECISION_NODES_ROUGH``; 513 for smooth and statistical films), each direction
refined against the float64 matrix and the convergence test kept on the float64 residual: the
path to the solution may change, the solution it converges to should not."""

import dataclasses

import jax
import numpy as np
import pytest
from helpers import gear_contact

import jaxgear as jg
from jaxgear.lubrication.ehl import newton
from jaxgear.lubrication.ehl.discretisation import _fine_level, _grid_positions
from jaxgear.lubrication.ehl.model import _Inputs, _split_numbers
from jaxgear.lubrication.roughness import ground

LUB = jg.presets.mil_l_23699()


def test_only_rough_films_take_the_single_precision_lu_at_257_nodes():
    # the flag that selects it is set on the inputs by the deterministic solve and must reach every
    # level an attempt builds from them (``dataclasses.replace``/``eqx.tree_at`` keep it)
    numbers, model = _split_numbers(jg.EHLModel(n_nodes=257))
    c = gear_contact(rpm=3500.0)
    x = _grid_positions(model, c, LUB)
    z = np.zeros(x.shape)
    inp = _Inputs(c, LUB, z, np.zeros(()), z, z, np.zeros(()), numbers)
    assert not newton._mixed_precision(_fine_level(model, inp)[1])
    rough = dataclasses.replace(inp, rough=True)
    assert newton._mixed_precision(_fine_level(model, rough)[1])
    numbers, coarse = _split_numbers(jg.EHLModel(n_nodes=129))
    z = np.zeros(129)
    small = _Inputs(c, LUB, z, np.zeros(()), z, z, np.zeros(()), numbers, rough=True)
    assert not newton._mixed_precision(_fine_level(coarse, small)[1])


@pytest.mark.parametrize("rpm", [3500.0, pytest.param(500.0, marks=pytest.mark.slow)])
def test_single_precision_lu_reaches_the_double_lu_film(rpm, monkeypatch):
    # The paper's ground surfaces in the film at the pitch contact, 257 nodes, steady: the same
    # film with either factorisation (measured 2026-11-27: P within 7e-14 ph at 3500 rpm and
    # 1.5e-12 ph at 500 rpm, the same 245 and 390 Newton iterations). Bound 1e-8 ph: each solve
    # stops at ‖F‖∞ < 1e-9 on the float64 residual, so two converged solves of the same branch
    # agree to about that, while another discrete solution of the rough film would differ by
    # O(0.1 ph) at the asperities.
    c = gear_contact(rpm=rpm)
    model = jg.EHLModel(n_nodes=257, mixed="deterministic")
    traced = []  # the single-precision solves the compiled program holds (counted when traced)
    refined = newton._refined
    monkeypatch.setattr(newton, "_refined", lambda *a: traced.append(1) or refined(*a))

    def solve():
        traced.clear()
        jax.clear_caches()  # the compiled solve read the constants when it was traced
        sol = jg.solve_ehl(c, LUB, model, ground())
        return sol, len(traced)

    single, n_single = solve()
    monkeypatch.setattr(newton, "_MIXED_PRECISION_NODES_ROUGH", 10**9)
    double, n_double = solve()
    jax.clear_caches()
    assert n_single > 0 and n_double == 0, (n_single, n_double)
    assert bool(single.converged) and bool(double.converged)
    gap = float(np.max(np.abs(single.p - double.p)) / single.hertz_pressure)
    assert gap < 1e-8, gap
