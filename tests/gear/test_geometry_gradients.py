"""Derivatives with respect to every float field of a GearPair: finite everywhere, equal to central
finite differences for the geometry's main parameters, reverse mode equal to forward mode.

Outputs: the mesh cycle's mean mesh stiffness, mean static TE, a double-contact load share and a
single-contact Hertz pressure, and the efficiency Ψ of the quasi-static rung (the fast fidelity,
2500 rpm, 700 N m) on the calibrated paper pair.

Finite differences: central, step 1e-5 of the value (1e-5 absolute for the zero profile shift).
Truncation error is ~(h/ℓ)²: ℓ, the smallest length the outputs vary over, is the width of the
smoothed relief start and contact edges (~1e-3 rad of roll angle), which a change of pressure angle
or shift moves past the fixed positions of the cycle; measured 5e-6 relative for the pressure angle
at this step, falling as h², and <2e-7 for the others; round-off, ~1e-16/1e-5 amplified by the
load sharing's solve, stays below 1e-9. Tolerance 5e-5 on the normalised sensitivity
(x/y) ∂y/∂x, with sensitivities below 1e-3 compared in absolute terms (a zero derivative, as of
the mean stiffness to the module under the pair's geometric similarity, is noise in a quotient).
Reverse against forward: the same rules evaluated in another order, 1e-6.
"""

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from jax.flatten_util import ravel_pytree

import jaxgear as jg

PAIR = jg.presets.li2015_pair_calibrated()
LUB = jg.presets.mil_l_23699()
SURF = jg.presets.ground()
OP = jg.OperatingPoint(torque=700.0, speed_rpm=2500.0)
FIDELITY = jg.Fidelity.fast(dynamics="quasi_static")
M = 32
DOUBLE, SINGLE = 5, 28  # slot 0 in double contact (τ = 5/32) and alone (τ = 28/32 > ε − 1)
MESH_OUTPUTS = ("mean mesh stiffness", "mean static TE", "load share", "Hertz pressure")

FD_STEP = 1e-5
FD_TOL = 5e-5
FLOOR = 1e-3
AD_TOL = 1e-6

# (name, substitution by the validated replace, the value's flat entries summed for its derivative)
NAMED = {
    "module": (lambda p, v: p.replace(module=v), [".module"]),
    "pressure_angle": (lambda p, v: p.replace(pressure_angle=v), [".pressure_angle"]),
    "face_width": (lambda p, v: p.replace(face_width=v), [".face_width"]),
    "profile_shift[0]": (
        lambda p, v: p.replace(profile_shift=jnp.stack([jnp.asarray(v), p.profile_shift[1]])),
        [".profile_shift[0]"],
    ),
    "tip_relief.amount": (
        lambda p, v: p.replace(**{"tip_relief.amount": v}),
        [".tip_relief.amount[0]", ".tip_relief.amount[1]"],
    ),
    "tip_relief.start_roll_angle": (
        lambda p, v: p.replace(**{"tip_relief.start_roll_angle": v}),
        [".tip_relief.start_roll_angle[0]", ".tip_relief.start_roll_angle[1]"],
    ),
}
VALUES = {
    "module": 3e-3,
    "pressure_angle": math.radians(20.0),
    "face_width": 0.02,
    "profile_shift[0]": 0.0,
    "tip_relief.amount": 10e-6,
    "tip_relief.start_roll_angle": math.radians(20.9),
}


def _flat(pair):
    """The pair's float leaves as one vector, a function rebuilding the pair from one, and a name
    for every entry (``.tip_relief.amount[1]``, ``.materials[0].density``...)."""
    params, static = eqx.partition(pair, eqx.is_inexact_array)
    flat, unravel = ravel_pytree(params)
    names = []
    for path, leaf in jax.tree_util.tree_leaves_with_path(params):
        base = jax.tree_util.keystr(path)
        names += [base] if leaf.ndim == 0 else [f"{base}[{i}]" for i in range(leaf.size)]
    assert len(names) == flat.size
    return flat, (lambda x: eqx.combine(unravel(x), static)), names


def mesh_outputs(pair):
    mesh = jg.mesh_cycle(pair, 700.0, M)
    return jnp.stack(
        [
            jnp.mean(mesh.mesh_stiffness),
            jnp.mean(mesh.static_te),
            mesh.load_share[DOUBLE, 0],
            mesh.hertz_pressure[SINGLE, 0],
        ]
    )


def efficiency(pair):
    return jg.simulate(pair, LUB, SURF, OP, fidelity=FIDELITY).efficiency


def _central_difference(f, name):
    substitute, _ = NAMED[name]
    x0 = VALUES[name]
    h = FD_STEP * (abs(x0) if x0 else 1.0)
    return (np.asarray(f(substitute(PAIR, x0 + h))) - np.asarray(f(substitute(PAIR, x0 - h)))) / (
        2 * h
    ), (abs(x0) if x0 else 1.0)


def _assert_close(fd, ad, x_scale, y_scale, tol, label):
    s_fd, s_ad = fd * x_scale / y_scale, ad * x_scale / y_scale
    err = np.abs(s_fd - s_ad) / np.maximum(np.abs(s_ad), FLOOR)
    assert np.all(err < tol), (label, s_fd, s_ad, err)
    return float(np.max(err))


def _named_derivative(jacobian_columns, names, name):
    idx = [names.index(n) for n in NAMED[name][1]]
    return np.sum(np.asarray(jacobian_columns)[..., idx], axis=-1)


def test_mesh_cycle_derivatives_finite_for_every_field_and_match_differences():
    flat, rebuild, names = _flat(PAIR)
    jac = np.asarray(jax.jacfwd(lambda x: mesh_outputs(rebuild(x)))(flat))  # [4, fields]
    bad = [names[j] for j in np.flatnonzero(~np.all(np.isfinite(jac), axis=0))]
    assert not bad, bad
    y = np.asarray(mesh_outputs(PAIR))
    worst = {}
    for name in NAMED:
        fd, x_scale = _central_difference(mesh_outputs, name)
        ad = _named_derivative(jac, names, name)
        worst[name] = _assert_close(fd, ad, x_scale, np.abs(y), FD_TOL, name)
    print("mesh outputs, max normalised |FD − AD| per parameter:", worst)
    # The geometry's parameters do move the cycle (not a test that passes on zeros).
    for name in ("pressure_angle", "face_width", "profile_shift[0]"):
        assert np.max(np.abs(_named_derivative(jac, names, name)) / np.abs(y)) > 1e-3, name


def test_efficiency_gradient_finite_for_every_field_and_matches_differences():
    flat, rebuild, names = _flat(PAIR)
    grad = np.asarray(jax.grad(lambda x: efficiency(rebuild(x)))(flat))
    bad = [names[j] for j in np.flatnonzero(~np.isfinite(grad))]
    assert not bad, bad
    loss = 1.0 - float(efficiency(PAIR))  # Ψ's sensitivities relative to the lost fraction
    worst = {}
    for name in NAMED:
        fd, x_scale = _central_difference(efficiency, name)
        ad = _named_derivative(grad, names, name)
        worst[name] = _assert_close(fd, ad, x_scale, loss, FD_TOL, name)
        assert abs(ad) * x_scale / loss > 1e-3, name  # a real dependence
    print("efficiency, max normalised |FD − AD| per parameter:", worst)


@pytest.mark.slow
def test_reverse_mode_equals_forward_mode_for_every_field():
    # Every override given as well, so that their fields are used and differentiated.
    given = PAIR.replace(
        tip_radius=PAIR.tip_radius,
        root_radius=PAIR.root_radius,
        centre_distance=PAIR.centre_distance,
        bore_radius=PAIR.bore_radius,
    )
    for pair in (PAIR, given):
        flat, rebuild, names = _flat(pair)
        y = np.abs(np.asarray(mesh_outputs(pair)))[:, None]
        x = np.where(np.asarray(flat) != 0, np.abs(np.asarray(flat)), 1.0)[None, :]
        f = lambda v, rebuild=rebuild: mesh_outputs(rebuild(v))
        fwd = np.asarray(jax.jacfwd(f)(flat)) * x / y
        rev = np.asarray(jax.jacrev(f)(flat)) * x / y
        err = np.abs(fwd - rev) / np.maximum(np.abs(fwd), FLOOR)
        assert np.all(err < AD_TOL), [names[j] for j in np.flatnonzero(np.any(err >= AD_TOL, 0))]
        print(f"mesh outputs, overrides {pair.overrides}: max |rev − fwd| {err.max():.1e}")
    flat, rebuild, names = _flat(PAIR)
    psi = lambda v: efficiency(rebuild(v))
    grad = np.asarray(jax.grad(psi)(flat))
    # Forward mode along every field at once (a random mix) and along each named parameter.
    direction = np.random.default_rng(0).normal(size=flat.size) * np.where(flat != 0, flat, 1.0)
    _, jvp = jax.jvp(psi, (flat,), (jnp.asarray(direction),))
    mixed = abs(float(jvp) - grad @ direction) / np.abs(grad * direction).sum()
    print(f"efficiency along a random mix of every field: |jvp − grad·t| / Σ|grad t| {mixed:.1e}")
    assert mixed <= AD_TOL
    columns = [names.index(n) for name in NAMED for n in NAMED[name][1]]
    basis = jnp.eye(flat.size)[jnp.asarray(columns)]
    fwd = np.asarray(jax.vmap(lambda t: jax.jvp(psi, (flat,), (t,))[1])(basis))
    print("efficiency, named fields: max rel |fwd − rev|", np.max(np.abs(fwd / grad[columns] - 1)))
    np.testing.assert_allclose(fwd, grad[columns], rtol=AD_TOL, atol=0.0)
