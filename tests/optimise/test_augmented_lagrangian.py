"""The augmented-Lagrangian method on problems with known solutions (no model, no JAX): optimum,
multipliers, bounds, infeasibility, failed evaluations, and lockstep stepping of several problems;
the Pareto dominance filter; the command line's limits with units."""

from __future__ import annotations

import numpy as np
import pytest

from jaxgear.cli.design_args import parse_limit, parse_limits
from jaxgear.design import augmented_lagrangian as al
from jaxgear.design.pareto import dominated_mask
from jaxgear.results import Status


def quadratic(target, a, b, fail=None):
    """f = |u − target|², constraints a u ≤ b (rows), as an ``evaluate`` for ``al.drive``;
    ``fail(u)`` True marks a failed simulation there."""
    target, a, b = np.asarray(target, float), np.atleast_2d(a).astype(float), np.asarray(b, float)

    def one(u, lam, rho):
        f = float(np.sum((u - target) ** 2))
        g = a @ u - b
        shifted = np.maximum(0.0, lam + rho * g)
        merit = f + float(np.sum(shifted**2 - lam**2)) / (2.0 * rho)
        grad = 2.0 * (u - target) + a.T @ shifted
        ok = fail is None or not fail(u)
        return al.Evaluation(merit, grad, f, g, ok)

    return lambda U, L, R, active=None: [one(U[k], L[k], R[k]) for k in range(len(U))]


def solve(target, a, b, u0=(0.1, 0.1), fail=None, **kw):
    search = al.search(np.asarray(u0, float), np.atleast_2d(a).shape[0], **kw)
    return al.drive([search], quadratic(target, a, b, fail))[0]


def test_binding_linear_constraint_optimum_and_multiplier():
    # min (u0 − .8)² + (u1 − .7)² s.t. u0 + u1 ≤ 1: u* = (.55, .45), λ* = 2(.8 − .55) = .5 exactly
    out = solve((0.8, 0.7), [[1.0, 1.0]], [1.0], gtol=1e-8, ctol=1e-8)
    assert out.status == Status.OK
    # tolerance: the KKT tolerances 1e-8 bound the distance to the optimum to ~1e-7
    np.testing.assert_allclose(out.u, [0.55, 0.45], atol=1e-6)
    np.testing.assert_allclose(out.multipliers, [0.5], rtol=1e-5)
    assert out.violation <= 1e-8 and out.complementarity <= 1e-8


def test_inactive_constraint_has_zero_multiplier_and_bound_is_reached():
    # target outside the box: u* = (1, 0.3) on the bound u0 = 1; u0 + u1 ≤ 5 never binds
    out = solve((1.4, 0.3), [[1.0, 1.0]], [5.0], gtol=1e-9, ctol=1e-9)
    assert out.status == Status.OK
    np.testing.assert_allclose(out.u, [1.0, 0.3], atol=1e-7)
    assert out.multipliers[0] == 0.0
    assert out.projected_gradient <= 1e-9


def test_infeasible_limits_are_reported():
    # u0 + u1 ≤ −1 cannot hold on the unit box
    out = solve((0.5, 0.5), [[1.0, 1.0]], [-1.0], max_evaluations=200)
    assert out.status == Status.INFEASIBLE
    assert out.violation > 0.5


def test_failed_simulations_are_never_accepted():
    # the unconstrained optimum (0.9, 0.9) lies in a region where "simulations fail" (u0 > 0.6):
    # the search improves on its start, never accepts a point inside the region, and says why it
    # stopped (the failed trials), instead of using a value from there
    out = solve((0.9, 0.9), np.zeros((1, 2)), [1.0], fail=lambda u: u[0] > 0.6, max_evaluations=80)
    assert np.all(out.path[:, 0] <= 0.6)
    assert out.evaluation.objective < 2 * 0.8**2  # the start's f
    assert out.u[0] > 0.5  # it got close to the edge (the line search quarters failed steps)
    assert out.status == Status.SIMULATION


def test_failed_start_is_status_start():
    out = solve((0.9, 0.9), np.zeros((1, 2)), [1.0], fail=lambda u: True)
    assert out.status == Status.START and out.evaluations == 1


def test_lockstep_equals_one_at_a_time():
    # three problems stepped together give exactly what each gives alone
    cases = [((0.8, 0.7), 1.0), ((0.8, 0.7), 1.2), ((0.2, 0.9), 0.8)]
    alone = [solve(t, [[1.0, 1.0]], [b]) for t, b in cases]
    evaluators = [quadratic(t, [[1.0, 1.0]], [b]) for t, b in cases]

    def batch(U, L, R, active):
        # finished searches need no evaluation
        return [
            evaluators[k](U[k : k + 1], L[k : k + 1], R[k : k + 1])[0] if active[k] else None
            for k in range(len(U))
        ]

    together = al.drive([al.search(np.array([0.1, 0.1]), 1) for _ in cases], batch)
    for a, b in zip(alone, together):
        np.testing.assert_array_equal(a.u, b.u)
        assert a.evaluations == b.evaluations and a.status == b.status


def test_dominance():
    # maximise the objective, minimise the trade: (1, 1) dominates (0.5, 2); (2, 3) trades
    objective = np.array([1.0, 0.5, 2.0, 2.0])
    trade = np.array([1.0, 2.0, 3.0, 3.0])
    ok = np.array([True, True, True, False])
    mask = dominated_mask(objective, trade, +1, ok)
    # point 3 equals point 2 but failed: it dominates nothing, and point 2 is not strictly beaten
    np.testing.assert_array_equal(mask, [False, True, False, False])


@pytest.mark.parametrize(
    "text, name, value",
    [
        ("dte_rms<=1.5um", "dte_rms", 1.5e-6),
        ("hertz_pressure <= 1.2 GPa", "hertz_pressure", 1.2e9),
        ("flash_temperature<=40K", "flash_temperature", 40.0),
        ("efficiency>=99.8%", "efficiency", 0.998),
        ("power_loss<=0.3kW", "power_loss", 300.0),
    ],
)
def test_limits_with_units(text, name, value):
    got = parse_limit(text)
    assert got[0] == name and got[1] == pytest.approx(value, rel=1e-12)


@pytest.mark.parametrize(
    "text, needle",
    [
        ("dte_rms>=1.5um", "an upper limit"),
        ("efficiency<=0.99", "a lower limit"),
        ("dte_rms<=1.5", "unit '(none)'"),
        ("noise<=3dB", "unknown quantity 'noise'"),
        ("dte_rms=1.5um", "must read NAME<=VALUE"),
    ],
)
def test_bad_limits_name_the_problem(text, needle):
    with pytest.raises(ValueError, match=needle.replace("(", r"\(").replace(")", r"\)")):
        parse_limit(text)


def test_limit_given_twice():
    with pytest.raises(ValueError, match="given twice"):
        parse_limits(["dte_rms<=1um", "dte_rms<=2um"])
