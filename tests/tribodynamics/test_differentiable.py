"""The coupled model differentiated end to end: reverse mode over every float input and model
constant, against forward mode and central differences; substitution that neither recompiles nor
skips validation; a failed implicit solve that gives NaN, not an exception."""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
import pytest

import jaxgear as jg
import jaxgear.tribodynamics.passes as passes
from jaxgear._solvers.implicit import NaNImplicitAdjoint
from jaxgear._solvers.krylov import EarlyExitGMRES

PAIR = jg.presets.li2015_pair_calibrated()
LUB, SURF = jg.presets.mil_l_23699(), jg.presets.ground()
OP = jg.OperatingPoint(torque=700.0, speed_rpm=2500.0, inlet_temperature=363.15)
# the fixed point converged far below the default 1e-4 of its tables, so that central differences
# of Ψ are not noise (a Ψ change of ~1e-10 per step below)
FAST = jg.Fidelity.fast(fixed_point_tolerance=1e-10)

# (label, getter, relative step of the central difference)
CHECKED = (
    ("torque", lambda t: t[2].torque, 1e-4),
    ("relief amount", lambda t: t[0].tip_relief.amount, 1e-3),
    ("relief start", lambda t: t[0].tip_relief.start_roll_angle, 1e-4),
    ("module", lambda t: t[0].module, 1e-5),
    ("pressure angle", lambda t: t[0].pressure_angle, 1e-5),
    ("roughness scale", lambda t: t[1].scale, 1e-4),
    ("boundary friction", lambda t: t[3].contact.constants.boundary_friction, 1e-4),
    ("asperity density product", lambda t: t[3].contact.constants.asperity_density_product, 1e-4),
)


def _efficiency(inputs):
    pair, surfaces, op, fidelity = inputs
    return jg.simulate(pair, LUB, surfaces, op, fidelity=fidelity).efficiency


def _split(inputs):
    return eqx.partition(inputs, eqx.is_inexact_array)


def _direction(inputs, get):
    """A tangent of ``inputs`` that is 1 on the leaf ``get`` picks (both gears of a pair)."""
    params, _ = _split(inputs)
    zeros = jax.tree_util.tree_map(jnp.zeros_like, params)
    return eqx.tree_at(get, zeros, jnp.ones_like(get(params)))


def _psi_of_params(inputs):
    params, static = _split(inputs)

    def psi(p):
        return _efficiency(eqx.combine(p, static))

    return params, psi


def _outputs_of_params(inputs):
    """(params, their function → (Ψ, DTE RMS))."""
    params, static = _split(inputs)

    def outputs(p):
        pair, surfaces, op, fidelity = eqx.combine(p, static)
        res = jg.simulate(pair, LUB, surfaces, op, fidelity=fidelity)
        return res.efficiency, res.dte_rms

    return params, outputs


class Derivatives(eqx.Module):
    """The module's programs' results: reverse mode of Ψ and of the DTE RMS over every float
    input (``grads``, ``dte_grads``), forward mode along the CHECKED directions (``forward``,
    ``forward_dte``), and Ψ at other inputs (``efficiency_at``)."""

    inputs: tuple
    value: jax.Array
    grads: object
    dte_grads: object
    forward: np.ndarray
    forward_dte: np.ndarray
    efficiency_at: object = eqx.field(static=True)


@pytest.fixture(scope="module")
def reverse_and_forward():
    inputs = (PAIR, SURF, OP, FAST)
    params, outputs = _outputs_of_params(inputs)

    # one reverse-mode program, its cotangent an argument: run once per output
    def pullback(p, cotangent):
        values, vjp = jax.vjp(outputs, p)
        return values, vjp(cotangent)[0]

    reverse = jax.jit(pullback)
    one, nought = jnp.ones(()), jnp.zeros(())
    (value, _), grads = reverse(params, (one, nought))
    _, dte_grads = reverse(params, (nought, one))
    # one forward-mode program, run once per direction: it compiles in ~3/4 of the time the
    # program vmapped over the directions takes (as jacfwd runs them: the slow test below). Its
    # primal output is Ψ itself, the central differences' forward model: no third program
    jvp = jax.jit(lambda p, t: jax.jvp(outputs, (p,), (t,)))
    tangents = [jvp(params, _direction(inputs, get))[1] for _, get, _ in CHECKED]
    zero = jax.tree_util.tree_map(jnp.zeros_like, params)

    def efficiency_at(p):
        return float(jvp(p, zero)[0][0])

    return Derivatives(
        inputs=inputs,
        value=value,
        grads=grads,
        dte_grads=dte_grads,
        forward=np.asarray([float(t[0]) for t in tangents]),
        forward_dte=np.asarray([float(t[1]) for t in tangents]),
        efficiency_at=efficiency_at,
    )


def test_reverse_gradient_of_efficiency_is_finite_for_every_float_input(reverse_and_forward):
    d = reverse_and_forward
    inputs, value, grads = d.inputs, d.value, d.grads
    assert 0.99 < float(value) < 1.0
    leaves = jax.tree_util.tree_leaves(grads)
    # every float leaf of the pair, surfaces, operating point and fidelity (its constants)
    assert len(leaves) == len(jax.tree_util.tree_leaves(_split(inputs)[0])) > 30
    assert all(bool(jnp.all(jnp.isfinite(g))) for g in leaves)


@pytest.mark.parametrize("index", range(len(CHECKED)), ids=[c[0] for c in CHECKED])
def test_reverse_gradient_matches_forward_mode_and_central_differences(reverse_and_forward, index):
    d = reverse_and_forward
    inputs, grads, forward, efficiency_at = d.inputs, d.grads, d.forward, d.efficiency_at
    label, get, rel = CHECKED[index]
    reverse = float(jnp.sum(get(grads)))
    # reverse against forward: the same implicit rules, transposed; round-off only
    assert reverse == pytest.approx(float(forward[index]), rel=1e-6, abs=1e-14), label
    # central differences of the compiled forward model (Ψ, the primal output of the forward-mode
    # program: simulate's forward solves): the step is the stated fraction of the
    # value (both gears together for per-gear fields), truncation O(h²) ~1e-8 relative; the
    # fixed point to 1e-10 and the orbit's Newton to 1e-9 leave noise ~1e-10 in Ψ. A wrong
    # tangent (an unconverged implicit solve, a missed dependence) is off by far more than 1e-3.
    params = _split(inputs)[0]
    x = get(params)
    h = rel * float(jnp.max(jnp.abs(x)))

    def at(shift):
        return efficiency_at(eqx.tree_at(get, params, x + shift))

    fd = (at(h) - at(-h)) / (2.0 * h)
    assert reverse == pytest.approx(fd, rel=1e-3, abs=1e-12), (label, reverse, fd)


@pytest.mark.parametrize("index", range(len(CHECKED)), ids=[c[0] for c in CHECKED])
def test_reverse_gradient_of_dte_matches_forward_mode(reverse_and_forward, index):
    # the DTE RMS is a fixed-point output of metres among leaves of newtons: reverse mode's
    # transposed implicit solve scales its cotangents by the inverse of the root's magnitudes
    # (EarlyExitGMRES, "transposed"); scaled as tangents it stopped with the newton leaves
    # unconverged, 0.3-0.8 % off forward mode. Both modes solve to GMRES's 1e-10 and a dense
    # solve of the shooting: they agree to ~1e-11, and 1e-7 leaves room for round-off only
    d = reverse_and_forward
    label, get, _ = CHECKED[index]
    reverse = float(jnp.sum(get(d.dte_grads)))
    assert np.isfinite(reverse) and reverse != 0.0, label
    assert reverse == pytest.approx(float(d.forward_dte[index]), rel=1e-7), label


@pytest.mark.slow
def test_reverse_gradient_matches_forward_mode_vmapped_over_the_directions(reverse_and_forward):
    # the forward mode of the test above with its directions batched by vmap, as jax.jacfwd runs
    # them (under vmap a cond runs both branches as a select, and a while loop runs until every
    # member stops): the same tangents, round-off only
    d = reverse_and_forward
    inputs, grads, forward = d.inputs, d.grads, d.forward
    params, psi = _psi_of_params(inputs)
    tangents = [_direction(inputs, get) for _, get, _ in CHECKED]
    stacked = jax.tree_util.tree_map(lambda *a: jnp.stack(a), *tangents)
    batched = np.asarray(jax.jit(jax.vmap(lambda t: jax.jvp(psi, (params,), (t,))[1]))(stacked))
    for index, (label, get, _) in enumerate(CHECKED):
        reverse = float(jnp.sum(get(grads)))
        assert float(batched[index]) == pytest.approx(reverse, rel=1e-6, abs=1e-14), label
        assert float(batched[index]) == pytest.approx(float(forward[index]), rel=1e-6, abs=1e-14)


def _counted_first_pass(monkeypatch):
    fresh = eqx.filter_jit(eqx.debug.assert_max_traces(passes._first_pass_outputs, max_traces=1))
    monkeypatch.setattr(passes, "_first_pass_jit", fresh)


def test_substituting_fields_with_python_floats_does_not_recompile(monkeypatch):
    # eqx.tree_at puts the Python float in as it is; simulate turns it into a float64 array at its
    # boundary, so the one compiled program runs every value (assert_max_traces raises on a
    # second trace). A per-gear field takes its Python float through ``replace``, which
    # broadcasts it to both gears (put in by tree_at, a scalar is refused: the test below).
    _counted_first_pass(monkeypatch)
    fid = jg.Fidelity.fast(dynamics="quasi_static")
    base = jg.simulate(PAIR, LUB, SURF, OP, fidelity=fid)
    variants = [  # (pair, operating point, fidelity)
        (PAIR, eqx.tree_at(lambda o: o.torque, OP, 650.0), fid),
        (PAIR.replace(**{"tip_relief.amount": 12e-6}), OP, fid),
        (eqx.tree_at(lambda p: p.module, PAIR, 3.1e-3), OP, fid),
        (PAIR, OP, eqx.tree_at(lambda f: f.contact.constants.boundary_friction, fid, 0.12)),
    ]
    losses = set()
    for pair, op, f in variants:
        res = jg.simulate(pair, LUB, SURF, op, fidelity=f)
        assert int(res.status) == 0
        losses.add(round(float(res.power_loss), 6))
    # each substitution changed the answer (the value went in, not a constant of the program)
    assert len(losses) == len(variants) and float(base.power_loss) not in losses


def test_an_invalid_substituted_value_is_rejected_naming_the_field():
    fid = jg.Fidelity.fast(dynamics="quasi_static")
    bad_relief = eqx.tree_at(lambda p: p.tip_relief.amount, PAIR, jnp.asarray([-50e-6, -50e-6]))
    with pytest.raises(ValueError, match=r"TipRelief\.amount"):
        jg.simulate(bad_relief, LUB, SURF, OP, fidelity=fid)
    with pytest.raises(ValueError, match=r"TipRelief\.amount"):
        PAIR.replace(**{"tip_relief.amount": -50e-6})
    scalar = eqx.tree_at(lambda p: p.tip_relief.amount, PAIR, 12e-6)
    with pytest.raises(ValueError, match=r"TipRelief\.amount.*shape"):
        jg.simulate(scalar, LUB, SURF, OP, fidelity=fid)
    bad_mu = eqx.tree_at(lambda f: f.contact.constants.boundary_friction, fid, 3.0)
    with pytest.raises(ValueError, match=r"Fidelity\.boundary_friction"):
        jg.simulate(PAIR, LUB, SURF, OP, fidelity=bad_mu)
    with pytest.raises(ValueError, match=r"Fidelity\.boundary_friction"):
        fid.with_constants(boundary_friction=-0.1)
    with pytest.raises(ValueError, match=r"OperatingPoint\.torque"):
        jg.simulate(PAIR, LUB, SURF, eqx.tree_at(lambda o: o.torque, OP, -1.0), fidelity=fid)


def test_a_failed_implicit_solve_gives_nan_derivatives_not_an_exception():
    # y = a cos y, differentiated implicitly as the coupled model's fixed point is, with a GMRES
    # allowed no Krylov vector at all: it cannot converge. optimistix's ImplicitAdjoint (lineax)
    # raises from inside jax.jvp; the coupled model's adjoint gives a NaN tangent instead.
    def solve(a, adjoint):
        sol = optx.fixed_point(
            lambda y, a: a * jnp.cos(y),
            optx.FixedPointIteration(rtol=1e-12, atol=1e-12),
            jnp.asarray(0.5),
            args=a,
            adjoint=adjoint,
            max_steps=500,
        )
        return sol.value

    failing = EarlyExitGMRES(rtol=1e-10, atol=0.0, max_restarts=0, nan_on_failure=True)
    one = (jnp.asarray(0.5),), (jnp.ones(()),)
    value, tangent = jax.jvp(lambda a: solve(a, NaNImplicitAdjoint(failing)), *one)
    assert bool(jnp.isfinite(value)) and bool(jnp.isnan(tangent))
    # a solve that converges gives the closed form y' = cos y / (1 + a sin y) (implicit
    # differentiation of y − a cos y = 0), in forward and reverse mode
    good = NaNImplicitAdjoint(EarlyExitGMRES(rtol=1e-12, atol=0.0, nan_on_failure=True))
    value, tangent = jax.jvp(lambda a: solve(a, good), *one)
    expected = float(jnp.cos(value) / (1.0 + 0.5 * jnp.sin(value)))
    assert float(tangent) == pytest.approx(expected, rel=1e-9)
    assert float(jax.grad(lambda a: solve(a, good))(0.5)) == pytest.approx(expected, rel=1e-9)
    assert bool(jnp.isnan(jax.grad(lambda a: solve(a, NaNImplicitAdjoint(failing)))(0.5)))
    plain = EarlyExitGMRES(rtol=1e-10, atol=0.0, max_restarts=0)
    with pytest.raises(Exception, match="max_steps|maximum"):
        jax.block_until_ready(
            jax.jvp(lambda a: solve(a, optx.ImplicitAdjoint(linear_solver=plain)), *one)
        )


# The paper's model at reduced resolution (thermal, statistical mixed, transient, tribo-dynamic;
# 24 positions, 65 nodes): its contacts carry outer (Picard) iterations for the film temperature
# and the asperity pressure that stop at 1 % of the temperature rise and 1e-3 ph, so Ψ follows its
# inputs smoothly only to those tolerances: the differences take a 1 % step of each value and must
# agree within 5 % (a missed dependence or a wrong implicit rule is off by far more).
PAPER_CHECKED = (CHECKED[0], CHECKED[5], CHECKED[6])


@pytest.mark.slow
@pytest.mark.parametrize("index", range(len(PAPER_CHECKED)), ids=[c[0] for c in PAPER_CHECKED])
def test_paper_fidelity_reverse_gradient_matches_forward_and_differences(index):
    label, get, _ = PAPER_CHECKED[index]
    fid = jg.Fidelity.paper(n_positions=24, n_nodes=65, fixed_point_tolerance=1e-6)
    inputs = (PAIR, SURF, OP, fid)
    params, static = _split(inputs)

    def psi(p):
        return _efficiency(eqx.combine(p, static))

    value, grads = jax.value_and_grad(psi)(params)
    assert 0.99 < float(value) < 1.0
    assert all(bool(jnp.all(jnp.isfinite(g))) for g in jax.tree_util.tree_leaves(grads))
    reverse = float(jnp.sum(get(grads)))
    forward = float(jax.jvp(psi, (params,), (_direction(inputs, get),))[1])
    assert reverse == pytest.approx(forward, rel=1e-6, abs=1e-14), label
    x = get(inputs)
    h = 1e-2 * float(jnp.max(jnp.abs(x)))

    def at(shift):
        return float(_efficiency(eqx.tree_at(get, inputs, x + shift)))

    fd = (at(h) - at(-h)) / (2.0 * h)
    assert reverse == pytest.approx(fd, rel=5e-2, abs=1e-12), (label, reverse, fd)
