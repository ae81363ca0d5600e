"""Entry points take any float (Python, NumPy, weakly or strongly typed JAX) as the same strong
float64 array: a value put into an input by ``eqx.tree_at`` as ``jnp.asarray(0.1)`` (weakly typed)
reuses the program compiled for the constructor's arrays instead of compiling a second one."""

import equinox as eqx
import jax.numpy as jnp
import pytest
from helpers import gear_contact

import jaxgear as jg
from jaxgear.gear import mesh as mesh_mod
from jaxgear.lubrication import passage as passage_mod
from jaxgear.lubrication.ehl import solve as solve_mod

LUB = jg.presets.mil_l_23699()


def _programs(jitted) -> int:
    """Programs an ``eqx.filter_jit`` function holds (one per distinct input structure)."""
    return jitted._cached._cache_size()


def _strong(x):
    out = jnp.asarray(float(x), dtype=jnp.float64)
    assert not out.weak_type
    return out


def _weak(x):
    # what eqx.tree_at(..., jnp.asarray(python_float)) leaves: a weakly typed float64 array
    out = jnp.asarray(float(x))
    assert out.weak_type
    return out


def test_mesh_cycle_reuses_its_program_for_a_weakly_typed_field():
    pair = jg.presets.li2015_pair(tip_relief=12e-6)
    strong = eqx.tree_at(lambda p: p.face_width, pair, _strong(pair.face_width))
    weak = eqx.tree_at(lambda p: p.face_width, pair, _weak(pair.face_width))
    jg.mesh_cycle(strong, 500.0, n_positions=8)
    before = _programs(mesh_mod._mesh_cycle)
    jg.mesh_cycle(weak, 500.0, n_positions=8)
    assert _programs(mesh_mod._mesh_cycle) == before


@pytest.mark.parametrize("which", ["steady", "passage"])
def test_film_solves_reuse_their_program_for_weakly_typed_fields(which):
    contact = gear_contact(rpm=2000.0)
    model = jg.EHLModel(n_nodes=65)
    strong_lub = eqx.tree_at(lambda l: l.density, LUB, _strong(LUB.density))
    weak_lub = eqx.tree_at(lambda l: l.density, LUB, _weak(LUB.density))
    if which == "steady":
        jitted = solve_mod._solve_entry
        run = lambda lub: jg.solve_ehl(contact, lub, model)  # noqa: E731
    else:
        jitted = passage_mod._passage
        contacts = jg.LineContact(**{f: getattr(contact, f) for f in contact.__dataclass_fields__})
        run = lambda lub: passage_mod.solve_ehl_passage(  # noqa: E731
            contacts, lub, model, times=jnp.asarray([0.0, 1e-6])
        )
    first = run(strong_lub)
    before = _programs(jitted)
    second = run(weak_lub)
    assert _programs(jitted) == before
    assert bool(jnp.all(first.converged)) and bool(jnp.all(second.converged))
