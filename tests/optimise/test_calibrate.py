"""``jg.calibrate``: constants recovered from data the model made, standard errors against a Monte
Carlo of noisy fits and the Jacobian against central differences, failed points reported, bad input
rejected, and the ``jaxgear calibrate`` command.

Everything runs on the quasi-static closed-form rung (``Fidelity.fast(dynamics="quasi_static")``:
~1 s to compile a point, ~10 ms to run one), whose Φ̄ is a closed form of the constants: no
iterative solve adds noise to the data or the derivatives. The synthetic "measurements" are made by
``jg.simulate`` point by point (a program of its own), the fits run the vmapped model of
``calibrate``.
"""

from __future__ import annotations

import json
import re

import equinox as eqx
import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
from jaxgear.cli.main import main
from jaxgear.design import calibrate as calibrate_module

PAIR = jg.presets.li2015_pair_calibrated()
LUB, SURF = jg.presets.mil_l_23699(), jg.presets.ground()
FID = jg.Fidelity.fast(dynamics="quasi_static")
NAMES = ("boundary_friction", "asperity_density_product")
TRUTH = {"boundary_friction": 0.12, "asperity_density_product": 0.06}
# start values off by ×1.5 and ×0.7
START = {"boundary_friction": 0.18, "asperity_density_product": 0.042}
# torque (N m), speed (rpm), inlet (°C): loads, speeds and viscosities varied together, so that μb
# and nβσ (which both scale the asperity friction) are separated by the fluid share they move
ROWS = (
    (300.0, 800.0, 60.0),
    (700.0, 1500.0, 90.0),
    (1100.0, 2500.0, 75.0),
    (1500.0, 3500.0, 90.0),
    (500.0, 4000.0, 60.0),
    (900.0, 3000.0, 80.0),
    (1300.0, 1200.0, 70.0),
    (600.0, 2200.0, 85.0),
)
POINTS = [
    jg.OperatingPoint(torque=t, speed_rpm=s, inlet_temperature=c + 273.15) for t, s, c in ROWS
]
NOISE = 0.01  # relative standard deviation of the synthetic measurement noise


def _losses(fidelity, points=POINTS, surfaces=SURF):
    return np.array(
        [float(jg.simulate(PAIR, LUB, surfaces, op, fidelity=fidelity).power_loss) for op in points]
    )


@pytest.fixture(scope="module")
def measured():
    """Φ̄ of the model itself at the true constants, W [8]."""
    return _losses(FID.with_constants(**TRUTH))


@pytest.fixture(scope="module")
def noise_free_fit(measured):
    return jg.calibrate(PAIR, LUB, SURF, FID, POINTS, measured, NAMES, initial=START)


def test_recovers_the_constants_that_made_noise_free_data(noise_free_fit, measured):
    fit = noise_free_fit
    assert fit.converged, fit.message
    assert fit.names == NAMES and fit.steps > 0
    # the start was far off (it missed the points by 5-19 %), so the fit had work to do
    assert np.max(np.abs(fit.residuals_start)) > 0.1
    # noise-free data: the residual vanishes at the truth. The solver stops at |Δη| < 1e-6 |η|
    # (η = ln θ) after quadratic convergence, and the model is closed-form (round-off ~1e-13 in
    # Φ̄); the μb-nβσ correlation (~ -0.9997) amplifies that by ~50. 1e-6 relative has margin on
    # both and is 100× tighter than a 1e-4 requirement.
    for name in NAMES:
        assert fit.values[name] == pytest.approx(TRUTH[name], rel=1e-6), name
    assert np.max(np.abs(fit.residuals)) < 1e-8
    np.testing.assert_allclose(fit.model_power_loss, measured, rtol=1e-8)
    # the fitted fidelity carries the values and runs as a fidelity
    assert float(fit.fidelity.boundary_friction) == pytest.approx(fit.values["boundary_friction"])
    again = _losses(fit.fidelity, POINTS[:1])
    assert again[0] == pytest.approx(measured[0], rel=1e-8)
    assert int(fit.status) == 0 and fit.failed_points == () and fit.degrees_of_freedom == 6


def test_jacobian_and_standard_errors_against_central_differences(noise_free_fit, measured):
    """J = ∂r/∂θ at the fit against central differences of ``jg.simulate`` in each constant, and
    the standard errors recomputed from that Jacobian."""
    fit = noise_free_fit
    theta = fit.x
    fd = np.empty_like(fit.jacobian)
    for j, name in enumerate(NAMES):
        # step 1e-4 of the value: truncation O(h²) ~1e-8 relative, round-off ~1e-13/1e-4 ~1e-9
        h = 1e-4 * theta[j]
        up = _losses(FID.with_constants(**{**fit.values, name: theta[j] + h}))
        down = _losses(FID.with_constants(**{**fit.values, name: theta[j] - h}))
        fd[:, j] = (up - down) / (2.0 * h) / measured
    # forward mode through the model against differences of a separate program: 1e-6 relative
    # leaves ~100× the truncation and round-off estimate above; a missed dependence or a wrong
    # scaling (the 1/Φ̄ of the relative residual, the log parameters) is off by O(1)
    np.testing.assert_allclose(fit.jacobian, fd, rtol=1e-6)
    # the standard errors are the formula's on that Jacobian (noise-free residuals: s² ~ 1e-26,
    # so compare the unscaled covariance (JᵀJ)⁻¹ through the reported one divided by s²)
    s2 = fit.residual_sum_of_squares / fit.degrees_of_freedom
    np.testing.assert_allclose(fit.covariance / s2, np.linalg.inv(fd.T @ fd), rtol=1e-4)
    assert fit.correlation[0, 1] < -0.99  # μb and nβσ: the data barely separate them


def test_noisy_fit_lies_within_its_standard_errors_and_they_match_a_monte_carlo(
    measured, noise_free_fit
):
    """1 % multiplicative noise (seeded): the fit lies within 3 standard errors of the truth, and
    over 30 noise draws the spread of the fitted values matches the linearised standard error
    σ √diag((JᵀJ)⁻¹) at the truth, with σ = 1 % known."""
    rng = np.random.default_rng(20150415)
    draws = measured * (1.0 + NOISE * rng.standard_normal((31, measured.size)))
    fits = [jg.calibrate(PAIR, LUB, SURF, FID, POINTS, d, NAMES, initial=START) for d in draws]
    first = fits[0]
    assert first.converged, first.message
    truth = np.array([TRUTH[n] for n in NAMES])
    se = np.array([first.standard_errors[n] for n in NAMES])
    assert np.all(np.isfinite(se)) and np.all(se > 0)
    # 3 SE: a t-distributed deviation with 6 degrees of freedom exceeds it with p ≈ 0.024
    assert np.all(np.abs(first.x - truth) < 3.0 * se), (first.x, truth, se)
    # the reported SE is s √diag((JᵀJ)⁻¹), s² = RSS/6 the estimate of σ² = 1e-4
    assert 0.3 < np.sqrt(first.residual_sum_of_squares / 6) / NOISE < 1.8  # χ²₆ 99.8 % band
    # Monte Carlo: the spread of 30 fits against the linearised SE at the truth (the noise-free
    # fit's Jacobian is the Jacobian at the truth). A sample standard deviation of 30 draws is
    # within ±13 % of the true one at 1σ; [0.6, 1.5] is a ≥ 3σ band, room for the nonlinearity
    # of a strongly correlated pair (correlation ~ -0.9997)
    for fit in fits:
        assert fit.converged, fit.message
    x = np.array([f.x for f in fits[1:]])
    jac_truth = noise_free_fit.jacobian
    se_linear = NOISE * np.sqrt(np.diag(np.linalg.inv(jac_truth.T @ jac_truth)))
    ratio = x.std(axis=0, ddof=1) / se_linear
    assert np.all((0.6 < ratio) & (ratio < 1.5)), ratio
    # and the reported SEs are the same size, on the median over the draws
    reported = np.median([[f.standard_errors[n] for n in NAMES] for f in fits], axis=0)
    assert np.all((0.6 < reported / se_linear) & (reported / se_linear < 1.5))


def test_roughness_scale_with_as_many_points_as_parameters(monkeypatch):
    """The roughness scale alone from one point: recovered, and n = p leaves the standard errors
    undefined (NaN, with the reason), unless the weights are known uncertainties. The points are
    mapped one after another (``lax.map``), the path of the EHL and tribo-dynamic rungs, here on
    the cheap rung (a parameter no other test fits: its own compiled programs)."""
    monkeypatch.setattr(calibrate_module, "batches_points", lambda fidelity: False)
    point = [POINTS[1]]
    truth = 1.3
    data = _losses(FID, point, surfaces=eqx.tree_at(lambda s: s.scale, SURF, jnp.asarray(truth)))
    fit = jg.calibrate(PAIR, LUB, SURF, FID, point, data, ("roughness_scale",))
    assert fit.converged, fit.message
    assert fit.values["roughness_scale"] == pytest.approx(truth, rel=1e-6)
    assert float(fit.surfaces.scale) == pytest.approx(truth, rel=1e-6)
    assert np.isnan(fit.standard_errors["roughness_scale"]) and "n = p" in fit.note
    known = jg.calibrate(
        PAIR, LUB, SURF, FID, point, data, ("roughness_scale",), weights=[1.0 / NOISE],
        absolute_sigma=True,
    )  # fmt: skip
    # σ = 1 % of Φ̄: SE = σ / |∂(Φ̄/Φ̄meas)/∂scale|, the Jacobian's own column
    expected = 1.0 / abs(known.jacobian[0, 0])
    assert known.standard_errors["roughness_scale"] == pytest.approx(expected, rel=1e-12)
    assert 0 < known.standard_errors["roughness_scale"] < 0.1 * truth


def _failing_where(condition):
    """``_simulate_point`` with status 3 (contact) forced where ``condition(op, fidelity)``."""
    real = calibrate_module._simulate_point

    def patched(pair, lubricant, surfaces, op, fidelity):
        result = real(pair, lubricant, surfaces, op, fidelity)
        status = jnp.where(condition(op, fidelity), 3, result.status).astype(result.status.dtype)
        return eqx.tree_at(lambda r: r.status, result, status)

    return patched


# The failure tests trace patched models: they fit one parameter to three and to four points,
# shapes no other test here compiles, so no test reuses another's compiled program.


def test_a_point_failing_at_the_start_stops_before_the_solve(monkeypatch, measured):
    monkeypatch.setattr(
        calibrate_module,
        "_simulate_point",
        _failing_where(lambda op, fid: op.speed_rpm > 1000.0),
    )
    fit = jg.calibrate(
        PAIR, LUB, SURF, FID, POINTS[:3], measured[:3], ("boundary_friction",),
        initial={"boundary_friction": 0.1},
    )  # fmt: skip
    assert fit.status == jg.Status.START and not fit.converged
    assert fit.failed_points == (1, 2) and fit.steps == 0
    assert "1 (status 3" in fit.message and "2 (status 3" in fit.message
    assert fit.values["boundary_friction"] == 0.1  # nothing fitted


def test_a_fit_held_against_failing_constants_is_reported_not_returned_as_a_minimum(
    monkeypatch, measured
):
    """Point 1 fails wherever μb > 0.11, the truth is 0.12: the solver can only stop at the edge
    of the failure region with every point fine there, and the result says so."""
    monkeypatch.setattr(
        calibrate_module,
        "_simulate_point",
        _failing_where(lambda op, fid: (op.speed_rpm == 1500.0) & (fid.boundary_friction > 0.11)),
    )
    data = _losses(FID.with_constants(boundary_friction=0.12), POINTS[:4])
    fit = jg.calibrate(
        PAIR, LUB, SURF, FID, POINTS[:4], data, ("boundary_friction",),
        initial={"boundary_friction": 0.1},
    )  # fmt: skip
    assert fit.status == jg.Status.SIMULATION, fit.message
    assert fit.failed_points == (1,) and "Gauss-Newton step" in fit.message
    assert fit.values["boundary_friction"] <= 0.11


@pytest.mark.parametrize(
    "change, match",
    [
        (dict(parameters=("boundary_friction", "tau0")), "'tau0' is not a calibratable.*valid"),
        (dict(parameters=()), "parameters = .* is empty"),
        (dict(parameters=("boundary_friction", "boundary_friction")), "names a parameter twice"),
        (dict(parameters=("limiting_shear_coefficient",)), "limiting shear stress on"),
        (dict(operating_points=[]), "operating_points is empty"),
        (dict(operating_points=[POINTS[0], 3.0]), r"operating_points\[1\]"),
        (dict(measured_power_loss=[100.0, 200.0]), r"measured_power_loss has shape \(2,\)"),
        (dict(measured_power_loss=[100.0, -1.0, 50.0]), r"measured_power_loss\[1\] = -1.0"),
        (dict(measured_power_loss=[100.0, np.nan, 50.0]), r"measured_power_loss\[1\] = nan"),
        (dict(weights=[1.0, 0.0, 1.0]), r"weights\[1\] = 0.0 .*> 0"),
        (dict(weights=[1.0, 1.0]), r"weights has shape \(2,\)"),
        (dict(initial={"boundary_friction": 0.0}), "initial boundary_friction = 0.0 is out"),
        (dict(initial={"constant_mu": 0.1}), "'constant_mu' is not among"),
        (dict(operating_points=POINTS[:1], measured_power_loss=[1.0]), "1 point.* for 2 param"),
        (dict(rtol=0.0), "rtol = 0.0"),
        (dict(max_steps=0), "max_steps = 0"),
        (dict(fidelity="fast"), "fidelity"),
    ],
)
def test_bad_input_is_rejected_naming_it(change, match):
    args = dict(
        pair=PAIR,
        lubricant=LUB,
        surfaces=SURF,
        fidelity=FID,
        operating_points=POINTS[:3],
        measured_power_loss=[100.0, 200.0, 300.0],
        parameters=NAMES,
    )
    args.update(change)
    with pytest.raises(ValueError, match=match):
        jg.calibrate(**args)


def _write_csv(path, rows, losses, header="torque_Nm,speed_rpm,inlet_temperature_C,power_loss_W"):
    lines = [header] + [
        f"{t},{s},{c},{float(p)!r}" for (t, s, c), p in zip(rows, losses, strict=True)
    ]
    path.write_text("\n".join(lines) + "\n")


def test_command_line_fits_and_writes_calibration_json(tmp_path, measured, capsys):
    data = tmp_path / "losses.csv"
    _write_csv(data, ROWS, measured)
    code = main(
        ["calibrate", "--data", str(data), "--fit", ",".join(NAMES), "--quasi-static",
         "--out", str(tmp_path / "out")]
    )  # fmt: skip
    captured = capsys.readouterr()
    printed = captured.out
    assert code == 0, captured.err
    report = json.loads((tmp_path / "out" / "calibration.json").read_text())
    assert report["converged"] and report["status"] == 0
    assert report["fidelity"]["dynamics"] == "quasi_static"
    for name in NAMES:
        # the default start (the fidelity's μb 0.1, nβσ 0.05) is off; noise-free data as above
        assert report["parameters"][name]["value"] == pytest.approx(TRUTH[name], rel=1e-6)
        assert name in printed
    assert len(report["points"]) == len(ROWS)
    assert report["points"][3]["inlet_temperature_C"] == 90.0
    assert abs(report["points"][3]["residual"]) < 1e-8
    assert "status 0" in printed


@pytest.mark.parametrize(
    "text, argv, match",
    [
        ("torque_Nm,speed_rpm,power_loss_W\n700,2000,300\n", [], "inlet_temperature_C missing"),
        (
            "torque_Nm,speed_rpm,inlet_temperature_C,power_loss_W\n700,fast,90,300\n",
            [],
            "line 2: speed_rpm = 'fast' is not a number",
        ),
        (
            "torque_Nm,speed_rpm,inlet_temperature_C,power_loss_W,gear\n700,2000,90,300,1\n",
            [],
            "unknown column",
        ),
        ("torque_Nm,speed_rpm,inlet_temperature_C,power_loss_W\n", [], "no data rows"),
        (
            "torque_Nm,speed_rpm,inlet_temperature_C,power_loss_W\n700,2000,90,-3\n",
            [],
            r"measured_power_loss\[0\] = -3.0",
        ),
        (
            "torque_Nm,speed_rpm,inlet_temperature_C,power_loss_W\n700,2000,90,300\n",
            ["--fit", "mu"],
            "'mu' is not a calibratable parameter",
        ),
    ],
)
def test_command_line_bad_data_exits_2_with_one_line(tmp_path, capsys, text, argv, match):
    data = tmp_path / "bad.csv"
    data.write_text(text)
    code = main(["calibrate", "--data", str(data), "--fit", "boundary_friction", *argv])
    err = capsys.readouterr().err
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert re.search(match, err), err


@pytest.mark.slow
def test_recovers_boundary_friction_on_the_tribo_dynamic_rung():
    """The tribo-dynamic fixed point (points mapped, second pass traced): μb from three speeds
    with a stable periodic orbit (the calibrated pair's unstable bands at this rung: 775-825,
    1925-1975, 3375-3550, 3750-4050 rpm). The fixed point converged to 1e-10 so that Φ̄ is
    reproducible far below the tolerance; noise-free data, so 1e-5 relative (the fixed point and
    the orbit's Newton leave ~1e-9 in Φ̄, amplified by the inverse slope of Φ̄ in μb, ~1)."""
    fid = jg.Fidelity.fast(fixed_point_tolerance=1e-10)
    points = [
        jg.OperatingPoint(torque=t, speed_rpm=s, inlet_temperature=363.15)
        for t, s in ((500.0, 1200.0), (700.0, 2500.0), (900.0, 3000.0))
    ]
    data = _losses(fid.with_constants(boundary_friction=0.12), points)
    fit = jg.calibrate(PAIR, LUB, SURF, fid, points, data, ("boundary_friction",))
    assert fit.converged, fit.message
    assert fit.values["boundary_friction"] == pytest.approx(0.12, rel=1e-5)
    se = fit.standard_errors["boundary_friction"]
    assert np.isfinite(se) and se < 1e-4
