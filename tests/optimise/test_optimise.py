"""Design optimisation on the quasi-static rung: tip relief for efficiency (the constrained
optimiser without constraints), torque and roughness scale; gradients against finite differences,
optimum against an independent grid search, bounds, status, bad input, the command line.

Default tests use the quasi-static regression rung (compiles in seconds); the tribo-dynamic run is
marked slow. The objective (mean efficiency over speeds) is re-computed here with plain loops over
``simulate`` on pairs built by the preset, not by the optimiser's own substitution code.
"""

import json
import math
import subprocess
import sys

import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
from jaxgear.cli import main
from jaxgear.fidelity import Fidelity
from jaxgear.optimise import (
    STATUS_CONVERGED,
    STATUS_SIMULATION,
    STATUS_START,
    optimise,
)
from jaxgear.tribodynamics import simulate

QS = Fidelity(dynamics="quasi_static", friction="regression")
SPEEDS = (1000.0, 2500.0, 4000.0)
LUB = jg.presets.mil_l_23699()
SURF = jg.presets.ground()
OP = jg.OperatingPoint(torque=700.0, speed_rpm=2000.0)


def mean_efficiency(amount, start_rad, shape="linear", surfaces=SURF, torque=700.0):
    """The objective, computed independently: a fresh preset pair and a Python loop over speeds."""
    pair = jg.presets.li2015_pair(tip_relief=amount, relief_start_deg=math.degrees(start_rad))
    if shape != "linear":
        pair = jg.GearPair(
            teeth=pair.teeth,
            module=pair.module,
            pressure_angle=pair.pressure_angle,
            face_width=pair.face_width,
            tip_radius=pair.tip_radius,
            root_radius=pair.root_radius,
            centre_distance=pair.centre_distance,
            backlash=pair.backlash,
            tip_relief=jg.TipRelief(amount, start_rad, shape=shape),
        )
    effs = []
    for speed in SPEEDS:
        op = jg.OperatingPoint(torque=torque, speed_rpm=speed)
        res = simulate(pair, LUB, surfaces, op, QS)
        assert bool(res.converged)
        effs.append(float(res.efficiency))
    return float(np.mean(effs))


@pytest.fixture(scope="module")
def relief_run():
    return jg.optimise_tip_relief(
        jg.presets.li2015_pair(), LUB, SURF, OP, speeds_rpm=SPEEDS, fidelity=QS
    )


def test_gradient_matches_central_differences(relief_run):
    # Steps: 0.01 µm and 1e-5 rad. The objective is smooth there (relief ramp smoothed, regression
    # friction), truncation error ~ h² f''' is < 1e-7 relative; round-off ~ 1e-16/(Δf ~ 1e-7) ~ 1e-9.
    # So 1e-4 relative tests the reverse-mode gradient, not the finite differences.
    amount, start = relief_run.x_start
    grad = relief_run.gradient_start
    h = (1e-8, 1e-5)
    fd = [
        (mean_efficiency(amount + h[0], start) - mean_efficiency(amount - h[0], start))
        / (2 * h[0]),
        (mean_efficiency(amount, start + h[1]) - mean_efficiency(amount, start - h[1]))
        / (2 * h[1]),
    ]
    np.testing.assert_allclose(grad, fd, rtol=1e-4)
    # and the start objective itself is the independent mean efficiency
    assert relief_run.objective_start == pytest.approx(mean_efficiency(amount, start), abs=1e-12)


def test_optimum_beats_start_and_grid_search(relief_run):
    r = relief_run
    assert r.names == ("tip_relief_amount", "tip_relief_start_roll_angle")
    lo, hi = r.lower, r.upper
    # Default bounds: 0-50 µm, start 5 % inside gear 1's path of contact (14.537°-27.171°, REFERENCE §3)
    assert lo[0] == 0.0 and hi[0] == pytest.approx(50e-6)
    span = math.radians(27.171 - 14.537)
    assert lo[1] == pytest.approx(math.radians(14.537) + 0.05 * span, abs=1e-5)
    assert hi[1] == pytest.approx(math.radians(27.171) - 0.05 * span, abs=1e-5)
    # The optimum reported is what simulate gives at the optimum pair.
    assert r.objective_value == pytest.approx(mean_efficiency(*r.x), abs=1e-12)
    assert r.objective_value > r.objective_start + 1e-4  # 10 µm at 20.9° is far from the best
    grid = [
        mean_efficiency(a, s)
        for a in np.linspace(lo[0], hi[0], 5)
        for s in np.linspace(lo[1], hi[1], 7)
    ]
    # At least as good as every grid point (the grid's best is on the 50 µm edge; tolerance 1e-9
    # is round-off of a mean of efficiencies, not optimiser slack).
    assert r.objective_value >= max(grid) - 1e-9
    # The optimum pair carries the optimum, on both gears.
    np.testing.assert_allclose(r.amount, [r.x[0], r.x[0]])
    np.testing.assert_allclose(r.start_roll_angle, [r.x[1], r.x[1]])
    # Path: the accepted designs, inside the box; no constraints, so no multipliers.
    assert r.path.shape[1] == 2 and r.multipliers == {} and r.limits == {}
    assert r.status == jg.Status.OK, r.message
    assert np.all(r.path >= lo) and np.all(r.path <= hi)


def test_bounds_respected_and_reached():
    # Efficiency rises monotonically with relief amount on this rung (checked below independently),
    # so the amount must end exactly on its upper bound: projection reaches it.
    bounds = {"amount": (5e-6, 20e-6), "start_roll_angle": (math.radians(18), math.radians(22))}
    r = jg.optimise_tip_relief(
        jg.presets.li2015_pair(), LUB, SURF, OP, speeds_rpm=SPEEDS, fidelity=QS, bounds=bounds
    )
    s = math.radians(21.0)
    assert mean_efficiency(20e-6, s) > mean_efficiency(12e-6, s) > mean_efficiency(5e-6, s)
    assert np.all(r.path[:, 0] >= 5e-6) and np.all(r.path[:, 0] <= 20e-6)
    assert np.all(r.path[:, 1] >= math.radians(18) - 1e-15)
    assert np.all(r.path[:, 1] <= math.radians(22) + 1e-15)
    assert r.x[0] == 20e-6
    # The unconstrained best start (≈23.1° at 50 µm) lies above this box: it must sit on 22°.
    assert r.x[1] == pytest.approx(math.radians(22.0), abs=1e-9)
    # stationary on the box: the projected gradient (objective scaled to unit start gradient)
    assert r.projected_gradient <= 1e-2


def test_per_gear_relief_and_step_cap():
    r = jg.optimise_tip_relief(
        jg.presets.li2015_pair(),
        LUB,
        SURF,
        OP,
        speeds_rpm=SPEEDS,
        fidelity=QS,
        max_evaluations=4,
        both_gears=False,
    )
    assert r.status == jg.Status.MAX_STEPS and not r.converged and r.evaluations == 4
    assert "step cap" in r.message
    assert r.path.shape[1] == 4
    np.testing.assert_allclose(r.amount, r.value("tip_relief_amount"))
    # Relief on either gear unloads a tooth end where sliding is fastest: both amount gradients are
    # positive at the start (gear 1's tip works in the recess, gear 2's in the approach).
    g = r.gradient_start
    assert g[0] > 0 and g[1] > 0
    assert r.objective_value >= r.objective_start
    r0 = jg.optimise_tip_relief(
        jg.presets.li2015_pair(), LUB, SURF, OP, speeds_rpm=SPEEDS, fidelity=QS, max_evaluations=1
    )
    assert r0.evaluations == 1 and r0.objective_value == r0.objective_start


def test_a_search_traces_its_merit_program_once(monkeypatch):
    # the start, every step of the search and the final evaluation run one compiled program: the
    # numbers it is given (a Python float penalty at the start, NumPy scalars later) must not
    # change its input types (a weakly typed scalar traced and compiled it a second time, ~18 s
    # on the tribo-dynamic rung). A fresh jit of the same function counts its traces.
    import equinox as eqx

    from jaxgear.design import problem as problem_mod

    traces = []

    def counted(*args):
        traces.append(1)
        return problem_mod._merit_and_gradient(*args)

    monkeypatch.setattr(problem_mod, "_merit_and_gradient_jit", eqx.filter_jit(counted))
    r = jg.optimise_tip_relief(
        jg.presets.li2015_pair(), LUB, SURF, OP, speeds_rpm=SPEEDS[:1], fidelity=QS,
        max_evaluations=4,
    )  # fmt: skip
    assert r.evaluations >= 2
    assert len(traces) == 1


def test_shape_both_returns_the_better():
    kw = dict(speeds_rpm=SPEEDS, fidelity=QS, max_evaluations=30)
    pair = jg.presets.li2015_pair()
    both = jg.optimise_tip_relief(pair, LUB, SURF, OP, shape="both", **kw)
    lin = jg.optimise_tip_relief(pair, LUB, SURF, OP, shape="linear", **kw)
    par = jg.optimise_tip_relief(pair, LUB, SURF, OP, shape="parabolic", **kw)
    assert both.objective_value == max(lin.objective_value, par.objective_value)
    assert par.shape == ("parabolic", "parabolic")
    assert par.objective_value == pytest.approx(
        mean_efficiency(*par.x, shape="parabolic"), abs=1e-12
    )


def test_roughness_scale_gradient_and_optimum():
    r = jg.optimise_roughness_scale(
        jg.presets.li2015_pair(), LUB, SURF, OP, speeds_rpm=SPEEDS, fidelity=QS, bounds=(0.1, 3.0)
    )
    pair = jg.presets.li2015_pair()

    def eff(scale):
        return mean_efficiency(10e-6, pair.tip_relief.start_roll_angle[0], surfaces=SURF_at(scale))

    h = 1e-4  # relative FD error ~ h² ≈ 1e-8 (smooth in the composite Rq)
    fd = (eff(1.0 + h) - eff(1.0 - h)) / (2 * h)
    assert r.gradient_start[0] == pytest.approx(fd, rel=1e-4)
    # Rougher surfaces lose more (Xu et al.'s friction grows with Rq): the best is the lower bound.
    assert fd < 0
    assert r.x[0] == 0.1 and float(r.surfaces.scale) == 0.1
    assert r.objective == pytest.approx(eff(0.1), abs=1e-12)
    assert r.objective > r.objective_start


def SURF_at(scale):
    return jg.presets.ground(scale=scale)


def test_torque_optimum_within_bounds_and_above_grid():
    r = jg.optimise_torque(
        jg.presets.li2015_pair(), LUB, SURF, OP, speeds_rpm=SPEEDS, fidelity=QS, bounds=(400, 1200)
    )
    assert 400.0 <= r.x[0] <= 1200.0 and float(r.op.torque) == r.x[0]
    start = math.radians(20.9)
    grid = [mean_efficiency(10e-6, start, torque=t) for t in np.linspace(400.0, 1200.0, 9)]
    assert r.objective >= max(grid) - 1e-9
    assert r.objective == pytest.approx(mean_efficiency(10e-6, start, torque=r.x[0]), abs=1e-12)


def test_generic_optimiser_on_a_known_quadratic():
    # f = −(x − 0.3)² − 10 (y − 7)² on [0, 1] × [0, 5]: optimum (0.3, 5) with y on its bound.
    def objective(x):
        return -((x[0] - 0.3) ** 2) - 10.0 * (x[1] - 7.0) ** 2, jnp.asarray(True)

    r = optimise(objective, [0.9, 1.0], ([0.0, 0.0], [1.0, 5.0]), steps=200, gtol=1e-4)
    assert r.converged and r.status == STATUS_CONVERGED
    assert r.x[1] == 5.0
    assert r.x[0] == pytest.approx(0.3, abs=1e-3)


def test_non_converged_points_are_never_used():
    # The "simulation" fails for x > 0.5; the ascent walks towards 1 and must stop before, keeping
    # the best converged point.
    def objective(x):
        return x[0], x[0] <= 0.5

    r = optimise(objective, [0.1], ([0.0], [1.0]), steps=100)
    assert r.status == STATUS_SIMULATION and not r.converged
    assert np.all(r.history_x <= 0.5) and r.x[0] <= 0.5 and r.objective == r.x[0]
    bad = optimise(lambda x: (x[0], x[0] < 0.0), [0.1], ([0.0], [1.0]))
    assert bad.status == STATUS_START and bad.steps == 0


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        (dict(bounds={"amount": (40e-6, 10e-6)}), "bounds['amount']"),
        (dict(bounds={"amount": (-1e-6, 10e-6)}), "bounds['amount']"),
        (
            dict(bounds={"start_roll_angle": (math.radians(10), math.radians(20))}),
            "path of contact",
        ),
        (
            dict(bounds={"start_roll_angle": (math.radians(20), math.radians(28))}),
            "path of contact",
        ),
        (dict(bounds={"amont": (0, 1e-5)}), "unknown bounds key"),
        (dict(max_evaluations=-1), "max_evaluations = -1"),
        (dict(ctol=0.0), "ctol = 0.0"),
        (dict(shape="cubic"), "shape = 'cubic'"),
        (dict(objective="noise"), "objective = 'noise'"),
        (dict(constraints={"noise": 1.0}), "unknown constraint 'noise'"),
        (dict(constraints={"dte_rms": -1e-6}), "constraints['dte_rms'] = -1e-06"),
        (dict(constraints={"efficiency": 99.5}), "constraints['efficiency'] = 99.5"),
        (dict(speeds_rpm=[]), "speeds_rpm = [] is empty"),
        (dict(torques=[700.0, 0.0]), "torques = [700.0, 0.0] is out of range"),
        (dict(speeds_rpm=[1000.0, -5.0]), "speeds_rpm"),
        (dict(fidelity="fast"), "fidelity = 'fast' is not valid"),
    ],
)
def test_bad_input_names_the_field(kwargs, needle):
    kwargs.setdefault("fidelity", QS)
    with pytest.raises(ValueError) as err:
        jg.optimise_tip_relief(jg.presets.li2015_pair(), LUB, SURF, OP, **kwargs)
    assert needle in str(err.value)


def test_bad_scalar_bounds():
    pair = jg.presets.li2015_pair()
    with pytest.raises(ValueError, match="bounds of roughness_scale"):
        jg.optimise_roughness_scale(pair, LUB, SURF, OP, fidelity=QS, bounds=(3.0, 0.1))
    with pytest.raises(ValueError, match="bounds of torque"):
        jg.optimise_torque(pair, LUB, SURF, OP, fidelity=QS, bounds=(0.0, 100.0))


def test_cli_optimise_json_and_png(tmp_path, capsys):
    rc = main(
        [
            "optimise",
            "--fidelity",
            "quasi_static",
            "--speed-range",
            "1000:4000:1500",
            "--out",
            str(tmp_path),
        ]
    )
    assert rc == 0
    data = json.loads(capsys.readouterr().out)
    assert data["speeds_rpm"] == [1000.0, 2500.0, 4000.0]
    assert data["start"] == pytest.approx(
        {"tip_relief_amount_um": 10.0, "tip_relief_start_roll_angle_deg": 20.9}, rel=1e-12
    )
    opt = data["optimum"]
    # µm and degrees at this edge: the same numbers as the library's SI optimum.
    assert 0.0 <= opt["tip_relief_amount_um"] <= 50.0
    assert 15.0 < opt["tip_relief_start_roll_angle_deg"] < 26.6
    assert (
        data["objective_optimum_efficiency_percent"] >= data["objective_start_efficiency_percent"]
    )
    assert data["status_name"] and data["status"] in (jg.Status.OK, jg.Status.MAX_STEPS)
    assert data["objective_start_efficiency_percent"] == pytest.approx(
        100 * mean_efficiency(10e-6, math.radians(20.9)), abs=1e-10
    )
    # per point: the efficiency at each speed, in percent
    assert len(data["values_optimum"]["efficiency_percent"]) == 3
    assert (tmp_path / "optimise.csv").read_text().count("\n") == 4
    assert json.loads((tmp_path / "optimise.json").read_text()) == data
    assert (tmp_path / "optimise.png").stat().st_size > 1000


def _run(*args):
    return subprocess.run(
        [sys.executable, "-m", "jaxgear.cli", *args], capture_output=True, text=True, timeout=600
    )


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--steps", "-3"], "steps = -3"),
        (["--speeds", "1000,abc"], "--speeds"),
        (["--speed-range", "4000:1000:500"], "--speed-range"),
        (["--speeds", "1000", "--torque", "-5"], "torque"),
    ],
)
def test_cli_bad_input_exit_2(args, needle):
    out = _run("optimise", "--fidelity", "quasi_static", *args)
    assert out.returncode == 2, out.stderr
    assert needle in out.stderr and "Traceback" not in out.stderr


def test_cli_bad_config_bounds_exit_2(tmp_path):
    cfg = tmp_path / "opt.toml"
    cfg.write_text("[optimise]\namount_bounds_um = [30.0, 5.0]\n")
    out = _run("optimise", "--fidelity", "quasi_static", "--config", str(cfg))
    assert out.returncode == 2 and "bounds['amount']" in out.stderr
    assert "Traceback" not in out.stderr


@pytest.mark.slow
def test_tribo_dynamic_optimisation():
    # The tribo-dynamic rung (compiles in ~1-2 min here): the same contract, and every step's points
    # converged (the optimiser stops otherwise).
    fid = Fidelity(friction="regression")
    r = jg.optimise_tip_relief(
        jg.presets.li2015_pair(),
        LUB,
        SURF,
        OP,
        speeds_rpm=(1500.0, 3000.0),
        fidelity=fid,
        max_evaluations=16,
    )
    assert r.status in (jg.Status.OK, jg.Status.MAX_STEPS), r.message
    assert r.objective_value >= r.objective_start
    # gradient against central differences of the public simulate (looser than quasi-static: the
    # fixed point is converged to 1e-4 relative, so FD noise ~ 1e-4 · Δ scale; 1e-2 relative)
    amount, start = r.x_start
    pair = jg.presets.li2015_pair

    def f(a, s):
        p = pair(tip_relief=a, relief_start_deg=math.degrees(s))
        return np.mean(
            [
                float(simulate(p, LUB, SURF, jg.OperatingPoint(700.0, v), fid).efficiency)
                for v in (1500.0, 3000.0)
            ]
        )

    h = 2e-7
    fd = (f(amount + h, start) - f(amount - h, start)) / (2 * h)
    assert r.gradient_start[0] == pytest.approx(fd, rel=1e-2)
