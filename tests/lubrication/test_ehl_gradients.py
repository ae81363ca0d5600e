"""Implicit gradients of the EHL solution against central finite differences (float64)."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import gear_contact

import jaxgear as jg

MODEL = jg.EHLModel(n_nodes=129)  # the suite's standard model (compiled once)
LUB = jg.presets.mil_l_23699()

# every continuous input: contact fields and lubricant constants
PARAMS = {
    "load_per_width": lambda m: m[0].load_per_width,
    "u1": lambda m: m[0].u1,
    "u2": lambda m: m[0].u2,
    "reduced_radius": lambda m: m[0].reduced_radius,
    "e_reduced": lambda m: m[0].e_reduced,
    "inlet_temperature": lambda m: m[0].inlet_temperature,
    "roelands_z": lambda m: m[1].roelands_z,
    "kinematic_viscosity_40": lambda m: m[1].kinematic_viscosity_40,
    "eyring_stress": lambda m: m[1].eyring_stress,
    "thermal_expansion": lambda m: m[1].thermal_expansion,
}
OUTPUTS = ("h_central", "friction_sliding", "friction_rolling", "power_loss", "damping")


def _outputs(pair):
    s = jg.solve_ehl(pair[0], pair[1], MODEL)
    return jnp.stack([getattr(s, k) for k in OUTPUTS])


def test_implicit_gradients_match_central_differences():
    pair = (gear_contact(rpm=2000.0, slide_to_roll=0.3), LUB)
    jac = eqx.filter_jit(jax.jacrev(_outputs))(pair)  # implicit adjoint, no iteration unrolling
    f = eqx.filter_jit(_outputs)
    for name, get in PARAMS.items():
        x0 = float(get(pair))
        step = 1e-5 * abs(x0)
        plus = eqx.tree_at(get, pair, jnp.asarray(x0 + step))
        minus = eqx.tree_at(get, pair, jnp.asarray(x0 - step))
        fd = (np.asarray(f(plus)) - np.asarray(f(minus))) / (2 * step)
        ad = np.asarray(get(jac))
        # central differences: truncation O(step²) ~1e-10 relative, solver noise ~ tol/step ≲ 1e-6
        # relative; 1e-4 relative leaves a wide margin (absolute floor for derivatives that vanish)
        scale = np.abs(np.asarray(f(pair))) / abs(x0)
        for k, out in enumerate(OUTPUTS):
            assert ad[k] == pytest.approx(fd[k], rel=1e-4, abs=1e-7 * scale[k]), (
                name,
                out,
                ad[k],
                fd[k],
            )
    # the physics signs: film thickens with speed and viscosity, thins with load
    g = {name: np.asarray(get(jac)) for name, get in PARAMS.items()}
    assert g["load_per_width"][0] < 0 < g["u1"][0] + g["u2"][0]
    assert g["kinematic_viscosity_40"][0] > 0
