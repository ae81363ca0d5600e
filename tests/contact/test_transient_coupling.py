"""The transient rung of the coupled model (Fidelity.transient = True): one tooth pair marched through
its engagement by the transient passage, put back on the [position, slot] table.

Checked against what it does not produce: the quasi-steady table in the limit of a long mesh period
(squeeze → 0), and the direction of the squeeze film's lag behind the quasi-steady film.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
from jaxgear.contact import kinematic_velocities
from jaxgear.contact.ehl import ehl_contact_forces
from jaxgear.gear.geometry import mesh_period
from jaxgear.gear.mesh import mesh_cycle

jax.config.update("jax_enable_x64", True)

PAIR = jg.presets.li2015_pair_calibrated()
LUB = jg.presets.mil_l_23699()
FID = jg.Fidelity(dynamics="quasi_static", friction="ehl_smooth", n_positions=24, n_nodes=65)


def _engagement(a):
    """[M, 2] → one tooth pair's engagement: slot 0's positions, then slot 1's."""
    return np.asarray(jnp.reshape(jnp.swapaxes(a, 0, 1), (-1,)))


@pytest.fixture(scope="module")
def tables():
    op = jg.OperatingPoint(torque=700.0, speed_rpm=4000.0, inlet_temperature=363.15)
    mesh = mesh_cycle(PAIR, op.torque, FID.n_positions)
    v = kinematic_velocities(PAIR, mesh, op.omega1)
    common = (PAIR, LUB, None, mesh)
    state = (mesh.normal_load, v[..., 0], v[..., 1], op.inlet_temperature)
    steady = ehl_contact_forces(*common, FID, *state)
    period = float(mesh_period(PAIR, op.speed_rpm))
    transient = ehl_contact_forces(*common, FID.replace(transient=True), *state, period=period)
    slow = ehl_contact_forces(*common, FID.replace(transient=True), *state, period=1e3)
    loaded = _engagement(mesh.normal_load) > 1e-4 * float(mesh.total_load)
    return steady, transient, slow, loaded


def test_long_period_limit_is_the_quasi_steady_table(tables):
    (f_ss, s_ss), _, (f_slow, s_slow), loaded = tables
    assert bool(f_slow.converged)
    # A 1000 s mesh period makes the squeeze term ∂(ρh)/∂t ~ 1e-7 of the Couette term: each state
    # must be the steady solution at the same [position, slot] (1e-5: a few times the Newton
    # tolerance 1e-8 carried through the film ratio). This also checks the [M, 2] ↔ engagement
    # ordering: every state has a different load, radius and speed.
    h_ss, h_slow = _engagement(s_ss.h_central), _engagement(s_slow.h_central)
    np.testing.assert_allclose(h_slow[loaded], h_ss[loaded], rtol=1e-5)
    np.testing.assert_allclose(f_slow.friction_sliding, f_ss.friction_sliding, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(f_slow.power_sliding, f_ss.power_sliding, rtol=1e-5, atol=1e-9)


def test_squeeze_film_lags_the_quasi_steady_film(tables):
    (_, s_ss), (f_tr, s_tr), _, loaded = tables
    assert bool(f_tr.converged)
    h_ss, h_tr = _engagement(s_ss.h_central), _engagement(s_tr.h_central)
    # Where the quasi-steady film falls from one position to the next (the load rising into the
    # single-tooth zone), the squeeze term keeps the transient film thicker; where it rises, thinner.
    # Only states whose neighbour before is loaded too, and changes above 1 % (away from the noise
    # of the slow drift).
    change = np.diff(h_ss) / h_ss[1:]
    both = loaded[1:] & loaded[:-1]
    falling = both & (change < -0.01)
    rising = both & (change > 0.01)
    assert falling.sum() >= 1 and rising.sum() >= 1  # the 700 N m cycle has both jumps
    assert np.all(h_tr[1:][falling] > h_ss[1:][falling])
    assert np.all(h_tr[1:][rising] < h_ss[1:][rising])
    # Magnitude: at 4000 rpm the jump into single-tooth contact takes one position (Δt ≈ 12 µs);
    # the film cannot follow, so the lag is of the order of the jump itself; and squeeze only slows
    # the thinning, it does not reverse it: the transient film does not grow across the jump. (The
    # central film follows the inlet film a transit time a/u ≈ 30 µs later, 2-3 positions here:
    # measured, the transient film moves 0.1 % in the step where the steady one falls 16 %.)
    jump = np.argmin(np.where(both, change, 0.0))
    assert h_tr[jump + 1] - h_ss[jump + 1] > 0.3 * (h_ss[jump] - h_ss[jump + 1])
    assert h_tr[jump + 1] <= h_tr[jump]


def test_transient_rung_runs_in_the_coupled_model():
    op = jg.OperatingPoint(torque=700.0, speed_rpm=3000.0, inlet_temperature=363.15)
    res = jg.simulate(PAIR, LUB, jg.presets.ground(), op, fidelity=FID.replace(transient=True))
    steady = jg.simulate(PAIR, LUB, jg.presets.ground(), op, fidelity=FID)
    assert bool(res.converged) and int(res.status) == 0
    # The squeeze term moves the film by a few % where the load jumps; the loss, an integral over
    # the cycle, moves less (measured +0.25 % at 2000 rpm, 129 nodes). The 5 % bound catches gross
    # wiring errors only; the physics is checked by the two tests above.
    assert abs(float(res.power_loss) / float(steady.power_loss) - 1.0) < 0.05


def test_deterministic_roughness_with_transient_rung_is_refused():
    op = jg.OperatingPoint(torque=700.0, speed_rpm=3000.0, inlet_temperature=363.15)
    fid = FID.replace(friction="ehl_mixed", mixed_model="deterministic", transient=True)
    with pytest.raises(ValueError, match="mixed_model"):
        jg.simulate(PAIR, LUB, jg.presets.ground(), op, fidelity=fid)
