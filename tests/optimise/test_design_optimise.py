"""Constrained tip relief on the tribo-dynamic rung, and Pareto fronts: a DTE limit that binds gives
an interior optimum amount that meets the limit, satisfies the KKT conditions (checked with central
differences of the model, not with the optimiser's own gradients) and that no design of a brute-force
grid beats; Pareto points are non-dominated and ordered; bad input names the field; the CLI.

The tribo-dynamic problem: the calibrated pair at 2000 rpm, 700 N m, `Fidelity.fast()` with its
fixed point converged to 1e-10 (so that central differences are not noise). Along the amount at a
21.4° start, DTE RMS falls to ~0.47 µm near 45 µm and rises to ~0.97 µm at the 50 µm bound, while the
efficiency keeps rising: a 0.75 µm limit binds between 45 and 50 µm.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
from jaxgear.cli import main
from jaxgear.design.pareto import pareto_front
from jaxgear.design.problem import evaluate_designs
from jaxgear.design.tip_relief import build_problem

PAIR = jg.presets.li2015_pair_calibrated().replace(**{"tip_relief.amount": 40e-6})
LUB, SURF = jg.presets.mil_l_23699(), jg.presets.ground()
OP = jg.OperatingPoint(torque=700.0, speed_rpm=2000.0, inlet_temperature=363.15)
FAST = jg.Fidelity.fast(fixed_point_tolerance=1e-10)
BOUNDS = {"amount": (0.0, 50e-6), "start_roll_angle": (math.radians(21.2), math.radians(21.4))}
DTE_LIMIT = 0.75e-6
QS = jg.Fidelity(dynamics="quasi_static", friction="regression")


@pytest.fixture(scope="module")
def constrained():
    return jg.optimise_tip_relief(
        PAIR, LUB, SURF, OP, speeds_rpm=[2000.0], fidelity=FAST,
        constraints={"dte_rms": DTE_LIMIT}, bounds=BOUNDS,
    )  # fmt: skip


@pytest.fixture(scope="module")
def independent(constrained):
    """The model's values on a brute-force grid over the box and at the optimum ± central steps,
    in one values-only program that shares nothing with the optimiser's gradient program."""
    r = constrained
    problem, *_ = build_problem(
        PAIR, LUB, SURF, OP, speeds_rpm=[2000.0], torques=None, fidelity=FAST,
        objective="efficiency", constraints={"dte_rms": DTE_LIMIT}, bounds=BOUNDS, shape=None,
        both_gears=True,
    )  # fmt: skip
    lo, hi = np.asarray(problem.lower), np.asarray(problem.upper)
    grid = np.asarray([[a, s] for a in np.linspace(0, 1, 26) for s in np.linspace(0, 1, 3)])
    u_opt = (r.x - lo) / (hi - lo)
    # central steps: 0.05 µm in amount (box 1e-3); the start is on its bound, so one-sided there
    h = 1e-3
    fd = np.asarray([u_opt + [h, 0], u_opt - [h, 0], u_opt, u_opt - [0, h]])
    peaks, status = evaluate_designs(problem, jnp.asarray(np.vstack([grid, fd])))
    eff = np.asarray(peaks["efficiency"])[:, 0]
    dte = np.asarray(peaks["dte_rms"])[:, 0]
    assert np.all(np.asarray(status) == 0)
    n = grid.shape[0]
    width = hi - lo
    return {
        "grid_x": lo + width * grid,
        "grid_eff": eff[:n],
        "grid_dte": dte[:n],
        "d_eff_d_amount": (eff[n] - eff[n + 1]) / (2 * h * width[0]),
        "d_dte_d_amount": (dte[n] - dte[n + 1]) / (2 * h * width[0]),
        "d_eff_d_start_back": (eff[n + 2] - eff[n + 3]) / (h * width[1]),
        "d_dte_d_start_back": (dte[n + 2] - dte[n + 3]) / (h * width[1]),
        "eff_opt": eff[n + 2],
        "dte_opt": dte[n + 2],
    }


def test_binding_dte_limit_gives_an_interior_amount(constrained):
    r = constrained
    assert r.status == jg.Status.OK, r.message
    # interior: more than 1 µm from either amount bound (the limit binds between 45 and 50 µm)
    assert 1e-6 < r.x[0] - BOUNDS["amount"][0] and 1e-6 < BOUNDS["amount"][1] - r.x[0]
    # the limit holds at the point within the optimiser's tolerance (0.1 %), and binds (within 1 %)
    dte = float(r.values["dte_rms"][0])
    assert dte <= DTE_LIMIT * (1 + 1e-3)
    assert dte >= DTE_LIMIT * (1 - 1e-2)
    assert r.multipliers["dte_rms"][0] > 0.0
    # the start ends on its upper bound: the efficiency rises with it, and so does DTE here less
    # than the amount can trade back
    assert r.x[1] == pytest.approx(BOUNDS["start_roll_angle"][1], abs=1e-9)


def test_kkt_conditions_by_central_differences(constrained, independent):
    r, ind = constrained, independent
    # the reported values are the model's at the optimum (same numbers through another program)
    assert r.objective_value == pytest.approx(ind["eff_opt"], abs=1e-12)
    assert float(r.values["dte_rms"][0]) == pytest.approx(ind["dte_opt"], rel=1e-9)
    # stationarity in the free variable: ∂Ψ/∂a = μ ∂DTE/∂a, μ the reported multiplier (Ψ per metre
    # of DTE). Tolerance 5 %: the optimiser stops at a projected gradient of 1e-2 of the start's,
    # and the central differences carry ~1e-3 relative truncation error at a 0.05 µm step.
    mu = r.multipliers["dte_rms"][0]
    assert ind["d_eff_d_amount"] == pytest.approx(mu * ind["d_dte_d_amount"], rel=5e-2)
    # on the start's upper bound, the Lagrangian must not increase inwards: ∂Ψ/∂s − μ ∂DTE/∂s ≥ 0
    # (one-sided differences; slack of 1e-3 of |∂Ψ/∂s| for their error)
    lagrangian_slope = ind["d_eff_d_start_back"] - mu * ind["d_dte_d_start_back"]
    assert lagrangian_slope >= -1e-3 * abs(ind["d_eff_d_start_back"])
    # complementary slackness: the multiplier is positive only because the limit binds
    assert r.complementarity <= 1e-3 and r.violation <= 1e-3


def test_no_grid_design_beats_the_optimum(constrained, independent):
    r, ind = constrained, independent
    feasible = ind["grid_dte"] <= DTE_LIMIT
    assert feasible.sum() >= 3  # the grid has feasible designs to compare
    best = float(np.max(ind["grid_eff"][feasible]))
    # resolution: the optimum may use the 0.1 % constraint tolerance, worth μ·1e-3·limit of Ψ
    slack = r.multipliers["dte_rms"][0] * 1e-3 * DTE_LIMIT + 1e-10
    assert best <= r.objective_value + slack
    # and the optimum beats the best feasible grid design by less than the grid's step in Ψ
    # (0.2 µm of amount near the limit is worth ~1e-5 of Ψ here): a check that it is not far off
    assert r.objective_value - best < 5e-5


def test_pareto_points_are_non_dominated_and_ordered():
    # quasi-static rung: efficiency against the static transmission error's RMS (its "DTE"), which
    # at a 20.9° start falls to ~1.45 µm near 45 µm of relief and rises to ~2.1 µm at 50 µm while the
    # efficiency keeps rising: a trade
    front = pareto_front(
        jg.presets.li2015_pair(), LUB, SURF, OP, speeds_rpm=[2000.0], fidelity=QS,
        trade="dte_rms", n_points=4, grid=5,
    )  # fmt: skip
    assert front.limits.size == 4 and np.all(np.diff(front.limits) > 0)
    # every point feasible (0.1 % tolerance) and near-stationary. The tight points may stop at the
    # evaluation cap with a projected gradient a few times the 1e-2 tolerance: the quasi-static
    # transmission error bends sharply where the relief start crosses one of the 32 mesh positions,
    # and the line search creeps along such a kink. Measured: 0.037 and 0.011 at the two tightest.
    for r in front.results:
        assert r.status in (jg.Status.OK, jg.Status.MAX_STEPS), r.message
        assert r.violation <= 1e-3 and r.projected_gradient <= 0.1
    assert np.all(front.trade_values <= front.limits * (1 + 1e-3))
    assert not np.any(front.dominated)
    # the loose end is the unconstrained optimum, found by the first round and solved again
    assert front.results[-1].multipliers["dte_rms"][0] == 0.0
    # ordered: a looser limit never gives a worse efficiency (1e-9: round-off of Ψ)
    assert np.all(np.diff(front.objective_values) >= -1e-9)
    assert np.all(np.diff(front.trade_values) >= -1e-3 * front.limits[:-1])
    # the ends bracket a real trade: the loosest point is better than the tightest
    assert front.objective_values[-1] > front.objective_values[0]


def test_a_speed_without_a_stable_orbit_is_reported_not_used(constrained):
    # 1950 rpm has no stable periodic orbit for this relief at this rung (simulate: status 6): the
    # start is refused and the point named; the same compiled program as the fixture's runs it
    r = jg.optimise_tip_relief(
        PAIR, LUB, SURF, OP, speeds_rpm=[1950.0], fidelity=FAST,
        constraints={"dte_rms": DTE_LIMIT}, bounds=BOUNDS,
    )  # fmt: skip
    assert r.status == jg.Status.START and not r.converged
    # the first pass (all the optimiser runs: the attractor's second pass has no derivative) says
    # the orbit is not a stable periodic one
    assert r.point_status.tolist() == [int(jg.Status.DYNAMICS)]
    assert "1950 rpm" in r.failed_points and "unstable" in r.failed_points
    np.testing.assert_array_equal(r.x, r.x_start)  # nothing optimised
    assert constrained.failed_points == ""


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        (dict(trade="efficiency"), "trade = 'efficiency'"),
        (dict(objective="dte_rms", trade="dte_rms"), "the same quantity"),
        (dict(constraints={"dte_rms": 1e-6}), "is the traded quantity"),
        (dict(limits=[-1.0, 2.0]), "limits"),
        (dict(n_points=1), "n_points = 1"),
        (dict(grid=1), "grid = 1"),
    ],
)
def test_pareto_bad_input(kwargs, needle):
    with pytest.raises(ValueError, match=needle.replace("(", r"\(")):
        pareto_front(jg.presets.li2015_pair(), LUB, SURF, OP, fidelity=QS, **kwargs)


def test_cli_optimise_with_a_limit_and_pareto(tmp_path, capsys):
    rc = main(
        ["optimise", "--fidelity", "quasi_static", "--speeds", "2000",
         "--constraint", "dte_rms<=1.8um", "--out", str(tmp_path / "opt")]
    )  # fmt: skip
    assert rc == 0
    data = json.loads(capsys.readouterr().out)
    assert data["limits"] == {"dte_rms_um": pytest.approx(1.8)}
    assert data["status"] == jg.Status.OK, data["status_name"]
    assert max(data["values_optimum"]["dte_rms_um"]) <= 1.8 * (1 + 1e-3)
    for name in ("optimise.json", "optimise.png"):
        assert (tmp_path / "opt" / name).stat().st_size > 100
    assert (tmp_path / "opt" / "optimise.csv").read_text().count("\n") == 2  # header + 1 point
    rc = main(
        ["pareto", "--fidelity", "quasi_static", "--speeds", "2000", "--n-points", "3",
         "--grid", "3", "--out", str(tmp_path / "front")]
    )  # fmt: skip
    assert rc == 0
    data = json.loads(capsys.readouterr().out)
    assert len(data["points"]) == 3
    for name in ("pareto.json", "pareto.csv", "pareto.png"):
        assert (tmp_path / "front" / name).stat().st_size > 100


@pytest.mark.parametrize(
    "args, needle",
    [
        (["optimise", "--constraint", "dte_rms>=1um"], "an upper limit"),
        (["optimise", "--constraint", "hertz_pressure<=1.2"], "unit"),
        (["pareto", "--limits", "1,-2"], "--limits"),
        (["pareto", "--trade", "noise"], "invalid choice"),
    ],
)
def test_cli_bad_design_input_exit_2(args, needle):
    out = subprocess.run(
        [sys.executable, "-m", "jaxgear.cli", *args, "--fidelity", "quasi_static"],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert out.returncode == 2, out.stderr
    assert needle in out.stderr and "Traceback" not in out.stderr
