"""The matrix-free Newton directions of fine grids (``EHLModel(linear_solver="krylov")``).

They must solve the same discrete system as the dense LU: same residual, same tolerance, so the
same solution to within what that tolerance allows (‖F‖∞ < 1e-9 on both; the Newton matrix's
condition number, ~1e7 on these grids, turns that into ≲ 1e-6 of the solution). The reference is
the dense path, which the Moes / Pan-Hamrock validation (test_ehl_validation) checks.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from ehl_cases import gear_contact

import jaxgear as jg
from jaxgear.lubrication.passage import grid_time_step, solve_ehl_passage

LUB = jg.presets.mil_l_23699()
N = 1025  # the smallest grid the Krylov directions take (coarser levels keep the dense LU)


def _close(a, b, rel):
    a, b = np.asarray(a), np.asarray(b)
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b))) <= rel


def test_krylov_smooth_film_equals_dense_lu_and_its_gradient():
    contact = gear_contact(rpm=3500.0)
    dense = jg.EHLModel(n_nodes=N)
    krylov = jg.EHLModel(n_nodes=N, linear_solver="krylov")
    a = jg.solve_ehl(contact, LUB, krylov)
    b = jg.solve_ehl(contact, LUB, dense)
    assert bool(a.converged) and bool(b.converged)
    assert float(a.residual) < 1e-9
    # both to ‖F‖∞ < 1e-9 of one discrete system (module docstring)
    assert _close(a.p, b.p, 1e-6) and _close(a.h, b.h, 1e-6)
    assert abs(float(a.power_loss) / float(b.power_loss) - 1.0) < 1e-6

    # the implicit derivative is the same rule on both paths (the dense J at the solution)
    def film(load, model):
        c = contact.__class__(**{**vars(contact), "load_per_width": load})
        return jg.solve_ehl(c, LUB, model).h_central

    w = contact.load_per_width
    ga = jax.jvp(lambda x: film(x, krylov), (w,), (1.0,))[1]
    step = 1e-4 * float(w)
    fd = (float(film(w + step, krylov)) - float(film(w - step, krylov))) / (2 * step)
    # central difference of a film solved to 1e-9: truncation ~ step² h''' and noise ~ 1e-9/step
    # relative, both ≪ 1e-3
    assert abs(float(ga) / fd - 1.0) < 1e-3


@pytest.mark.slow
def test_krylov_polished_passage_equals_dense_lu():
    # the polished film (stylus-filtered, full film) marched 4 steps of Δx/ur at the pitch contact:
    # its warm steps are what the Krylov directions are for (RESULTS `mixed_held_steps`)
    contact = gear_contact(rpm=3500.0)
    surfaces = jg.presets.polished(short_cutoff=2.5e-6)
    k = 4
    out = []
    for solver in ("krylov", "dense"):
        model = jg.EHLModel(n_nodes=N, mixed="deterministic", linear_solver=solver)
        dt = float(grid_time_step(contact, LUB, model))
        contacts = jax.tree_util.tree_map(lambda v: jnp.full((k,), v), contact)
        out.append(solve_ehl_passage(contacts, LUB, model, surfaces, times=jnp.arange(k) * dt))
    a, b = out
    assert np.all(np.asarray(a.converged)) and np.all(np.asarray(b.converged))
    assert _close(a.p, b.p, 1e-6) and _close(a.h, b.h, 1e-6)


def test_linear_solver_is_validated():
    with pytest.raises(ValueError, match="linear_solver"):
        jg.EHLModel(linear_solver="lu")
