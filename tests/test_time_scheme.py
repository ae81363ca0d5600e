"""The transient passage's roughness position and time scheme (issue 4)."""

import jax
import jax.numpy as jnp
import numpy as np
from ehl_cases import gear_contact

import jaxgear as jg
from jaxgear.lubrication.passage import grid_time_step, solve_ehl_passage
from jaxgear.lubrication.roughness import Surfaces

LUB = jg.presets.mil_l_23699()


def _bump_surfaces(b, amplitude=50e-9, width=10e-6, start=-2.5):
    # one Gaussian bump on surface 1, entering from x = start·b (as tests/test_mixed_thermal.py)
    dx, n = 0.5e-6, 8192
    xs = np.arange(n) * dx
    z1 = amplitude * np.exp(-(((xs - (n * dx + start * b)) / width) ** 2))
    return Surfaces(profile1=jnp.asarray(z1), profile2=jnp.zeros(n), dx=dx)


def _passage(model, contact, surf, dt, k):
    contacts = jax.tree_util.tree_map(lambda a: jnp.full((k,), a), contact)
    return solve_ehl_passage(contacts, LUB, model, surf, times=jnp.arange(k) * dt)


def test_passage_first_state_has_the_surfaces_at_the_given_displacement():
    # the first state is steady at times[0], the roughness where ``displacement`` puts it: the
    # same film as solve_ehl with that displacement (a passage once advanced the surfaces by a
    # step before the first state, an O(Δt) shift of the whole passage's roughness that the
    # time-step study saw as a first-order error of either scheme)
    model = jg.EHLModel(n_nodes=129, mixed="deterministic")
    c = gear_contact(rpm=2000.0, slide_to_roll=0.3)
    b = float(c.hertz_half_width)
    surf = _bump_surfaces(b, start=-0.5)
    dt = float(grid_time_step(c, LUB, model))
    d = (3e-6, -2e-6)
    contacts = jax.tree_util.tree_map(lambda a: jnp.full((2,), a), c)
    sols = solve_ehl_passage(contacts, LUB, model, surf, times=jnp.arange(2) * dt, displacement=d)
    steady = jg.solve_ehl(c, LUB, model, surf, displacement=d)
    assert bool(sols.converged[0]) and bool(steady.converged)
    # the same discrete problem to the Newton tolerance (1e-9 of ph): films equal to 1e-6 of h_c
    scale = float(steady.h_central)
    np.testing.assert_allclose(np.asarray(sols.h[0]), np.asarray(steady.h), atol=1e-6 * scale)
