"""The sensitivity report: its derivatives against central differences and forward mode, its names
and units, one program for every input value, its status handling and the command line.

By default on the quasi-static rung of ``Fidelity.fast()`` (the closed-form mixed EHL contact, whose
constants are inputs): one program (forward solve and five reverse passes) serves every test of the
file, the central differences included. The tribo-dynamic rung is a slow test.
"""

from __future__ import annotations

import json
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
import jaxgear.design.sensitivity as sens
from jaxgear.cli.main import main as cli_main

PAIR = jg.presets.li2015_pair_calibrated()
LUB, SURF = jg.presets.mil_l_23699(), jg.presets.ground()
OP = jg.OperatingPoint(torque=700.0, speed_rpm=2500.0, inlet_temperature=363.15)
QUASI_STATIC = jg.Fidelity.fast(dynamics="quasi_static")
OUTPUTS = ("efficiency", "power_loss", "dte_rms", "hertz_pressure", "flash_temperature")

# (name in the report, getter of its leaf in (pair, lubricant, surfaces, op, fidelity), element of
# a per-gear leaf or None, relative step of the central difference): written out here, not read
# from the report's own naming, so that a wrong name-to-leaf mapping fails
CHECKED = (
    ("op.torque", lambda t: t[3].torque, None, 1e-4),
    ("op.speed_rpm", lambda t: t[3].speed_rpm, None, 1e-4),
    ("op.inlet_temperature", lambda t: t[3].inlet_temperature, None, 1e-5),
    ("pair.tip_relief.amount[1]", lambda t: t[0].tip_relief.amount, 0, 1e-3),
    ("pair.tip_relief.start_roll_angle[2]", lambda t: t[0].tip_relief.start_roll_angle, 1, 1e-4),
    ("pair.module", lambda t: t[0].module, None, 1e-5),
    ("pair.pressure_angle", lambda t: t[0].pressure_angle, None, 1e-5),
    ("pair.materials[1].youngs_modulus", lambda t: t[0].materials[0].youngs_modulus, None, 1e-4),
    ("surfaces.scale", lambda t: t[2].scale, None, 1e-4),
    ("lubricant.eyring_stress", lambda t: t[1].eyring_stress, None, 1e-4),
    ("fidelity.boundary_friction", lambda t: t[4].contact.constants.boundary_friction, None, 1e-4),
    (
        "fidelity.asperity_density_product",
        lambda t: t[4].contact.constants.asperity_density_product,
        None,
        1e-4,
    ),
)


def _shifted(inputs, get, element, shift):
    leaf = get(inputs)
    new = leaf + shift if element is None else leaf.at[element].add(shift)
    return eqx.tree_at(get, inputs, new)


def _report(point, fidelity, **kwargs):
    pair, lub, surf, op = point[:4]
    return jg.sensitivity(pair, lub, surf, op, fidelity=fidelity, **kwargs)


@pytest.fixture(scope="module")
def counted_program():
    # every sensitivity call of this file goes through one program that raises on a second trace:
    # new input values (the central differences, the CLI's inputs) must not recompile
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(
            sens,
            "_program",
            eqx.filter_jit(eqx.debug.assert_max_traces(sens._values_and_derivatives, max_traces=1)),
        )
        yield


@pytest.fixture(scope="module")
def report(counted_program):
    return _report((PAIR, LUB, SURF, OP, QUASI_STATIC), QUASI_STATIC, outputs=OUTPUTS)


def test_every_input_is_named_with_a_unit_and_every_derivative_is_finite(report):
    names = report.input_names
    assert len(names) == len(set(names)) > 50
    missing = [n for n, u in zip(names, report.input_units) if u == sens.UNKNOWN_UNIT]
    assert not missing, f"inputs without a unit in design.sensitivity.UNITS: {missing}"
    # the float fields of each input, per gear where they are pairs; the overridden blanks of the
    # calibrated pair, not the derived quantities it does not override; the contact constants
    for name in (
        "pair.profile_shift[2]",
        "pair.materials[2].density",
        "pair.bearings.ct[1]",
        "pair.blank_mass[1]",
        "pair.blank_inertia[2]",
        "lubricant.kinematic_viscosity_40",
        "surfaces.offset[1]",
        "op.speed_rpm",
        "fidelity.constant_mu",
        "fidelity.limiting_shear_coefficient",
    ):
        assert name in names
    assert PAIR.overrides == ("blank_mass", "blank_inertia")
    assert not any(n.startswith(("pair.tip_radius", "pair.centre_distance")) for n in names)
    assert not any("profile1" in n or "override" in n for n in names)
    assert report.status == 0 and report.converged
    assert np.all(np.isfinite(report.derivatives))
    assert 0.98 < report.outputs["efficiency"][0] < 1.0
    assert report.outputs["hertz_pressure"] == (pytest.approx(report.output_values[3]), "Pa")
    # every input the generic enumeration finds has a unit (here for the plain pair too, whose
    # derived quantities are not overridden, and with the cap of the limiting shear on)
    fid = jg.Fidelity.fast(limiting_shear_coefficient=0.05)
    listed = sens.input_names(jg.presets.li2015_pair(), LUB, SURF, OP, fid)
    keys = {n.replace("[1]", "").replace("[2]", "") for n in listed}
    assert keys <= set(sens.UNITS), keys - set(sens.UNITS)


@pytest.mark.parametrize("index", range(len(CHECKED)), ids=[c[0] for c in CHECKED])
def test_derivatives_match_central_differences(report, index):
    name, get, element, rel = CHECKED[index]
    inputs = (PAIR, LUB, SURF, OP, QUASI_STATIC)
    leaf = get(inputs)
    x = float(leaf if element is None else leaf[element])
    assert report.inputs[name][0] == pytest.approx(x, rel=1e-15)
    h = rel * abs(x)

    def at(shift):
        shifted = _shifted(inputs, get, element, shift)
        return _report(shifted, shifted[4], outputs=OUTPUTS).output_values

    fd = (at(h) - at(-h)) / (2.0 * h)
    for k, out in enumerate(OUTPUTS):
        d = report.derivative(out, name)
        y = report.output_values[k]
        # truncation O(h²) at these steps: measured agreement 1e-9 typically, 4e-6 at worst (the
        # pressure angle); the absolute floor, an elasticity of 1e-6, holds the derivatives that
        # are zero or nearly (a peak Hertz pressure where the relief does not act), whose
        # differences are round-off. A missed dependence or a wrong tangent is off by far more.
        assert d == pytest.approx(fd[k], rel=3e-5, abs=1e-6 * abs(y / x)), (out, name, d, fd[k])


def test_reverse_matches_forward_mode(report):
    # the report's reverse passes against jax.jvp of simulate's outputs, one input at a time (a
    # program of its own): the same rules, transposed; round-off only
    inputs = (PAIR, LUB, SURF, OP, QUASI_STATIC)
    params, static = eqx.partition(inputs, eqx.is_inexact_array)

    def outputs_of(p):
        pair, lub, surf, op, fid = eqx.combine(p, static)
        res = jg.simulate(pair, lub, surf, op, fidelity=fid)
        return jnp.stack([res.efficiency, res.power_loss, res.dte_rms])

    jvp = jax.jit(lambda p, t: jax.jvp(outputs_of, (p,), (t,))[1])
    for name, get, element, _ in (CHECKED[0], CHECKED[3], CHECKED[10]):
        zeros = jax.tree_util.tree_map(jnp.zeros_like, params)
        tangent = _shifted(zeros, get, element, 1.0)
        forward = np.asarray(jvp(params, tangent))
        for k, out in enumerate(("efficiency", "power_loss", "dte_rms")):
            reverse = report.derivative(out, name)
            assert reverse == pytest.approx(forward[k], rel=1e-8, abs=1e-300), (out, name)


def test_elasticity_is_x_over_y_times_the_derivative(report):
    rows = report.table
    assert len(rows) == len(OUTPUTS) * len(report.input_names)
    for row in rows:
        x, y = row["input_value"], row["output_value"]
        if x == 0.0:
            assert math.isnan(row["elasticity"]), row
        else:
            expected = x / y * row["derivative"]
            assert row["elasticity"] == pytest.approx(expected, rel=1e-12, abs=1e-300), row
        assert row["elasticity"] == report.elasticity(row["output"], row["input"]) or (
            math.isnan(row["elasticity"])
        )
    assert report.table[0]["derivative_unit"] == "1/m"  # efficiency per pair.module
    units = {(r["output"], r["input"]): r["derivative_unit"] for r in rows}
    assert units[("power_loss", "op.torque")] == "W/(N m)"
    assert units[("power_loss", "fidelity.boundary_friction")] == "W"
    assert units[("efficiency", "op.inlet_temperature")] == "1/K"
    assert units[("hertz_pressure", "pair.face_width")] == "Pa/m"
    assert units[("dte_rms", "pair.module")] == "-"


def test_restricted_inputs_give_the_same_numbers(report):
    names = ["fidelity.boundary_friction", "op.torque", "pair.tip_relief.amount[2]"]
    # a name without its group where that is unambiguous ("torque": the public API's example)
    short = ["boundary_friction", "torque", "tip_relief.amount[2]"]
    small = _report((PAIR, LUB, SURF, OP), QUASI_STATIC, outputs=OUTPUTS, inputs=short)
    assert small.input_names == tuple(names)
    assert report.derivative("efficiency", "torque") == report.derivative("efficiency", names[1])
    for out in OUTPUTS:
        for name in names:
            assert small.derivative(out, name) == report.derivative(out, name)


def test_other_input_values_reuse_the_program(report):
    # a new torque, relief and contact constant: the counted program raises on a second trace
    pair = PAIR.replace(**{"tip_relief.amount": 12e-6})
    fid = QUASI_STATIC.with_constants(boundary_friction=0.12)
    op = jg.OperatingPoint(torque=650.0, speed_rpm=2000.0, inlet_temperature=353.15)
    other = jg.sensitivity(pair, LUB, SURF, op, fidelity=fid, outputs=OUTPUTS)
    assert other.status == 0
    assert other.inputs["op.torque"][0] == 650.0
    assert other.inputs["fidelity.boundary_friction"][0] == pytest.approx(0.12)
    assert other.output_values[1] != report.output_values[1]


def test_unknown_names_are_rejected_naming_them(report):
    with pytest.raises(ValueError, match=r"unknown output 'efficency'.*efficiency"):
        jg.sensitivity(PAIR, LUB, SURF, OP, fidelity=QUASI_STATIC, outputs=("efficency",))
    with pytest.raises(ValueError, match=r"unknown input 'op\.torq'.*op\.torque"):
        jg.sensitivity(PAIR, LUB, SURF, OP, fidelity=QUASI_STATIC, inputs=["op.torq"])
    with pytest.raises(ValueError, match=r"output 'power_loss_rolling' is not in this report"):
        report.derivative("power_loss_rolling", "op.torque")
    with pytest.raises(ValueError, match=r"unknown input 'pair\.tip_radius\[1\]' in this report"):
        report.derivative("efficiency", "pair.tip_radius[1]")
    with pytest.raises(ValueError, match=r"unknown input 'youngs_modulus'"):  # which gear's?
        report.derivative("efficiency", "youngs_modulus")


def test_a_report_without_a_converged_point_has_no_derivative(tmp_path):
    # what sensitivity() builds from a status other than 0 (e.g. 6, a mean over an attractor, whose
    # tangents the simulation marks NaN): the numbers the program gave are not reported
    bad = sens.SensitivityReport(
        ("efficiency", "power_loss"),
        [0.99, 300.0],
        ["op.torque", "pair.backlash"],
        [700.0, 0.0],
        ["N m", "m"],
        [[1e-6, 2.0], [0.4, 3.0]],
        status=6,
    )
    assert not bad.converged and bad.status == 6
    assert "no derivative exists" in bad.message and "attractor" in bad.message
    assert np.all(np.isnan(bad.derivatives)) and np.all(np.isnan(bad.elasticities))
    assert bad.outputs["power_loss"] == (300.0, "W")
    data = json.loads(bad.to_json(tmp_path / "bad.json").read_text())
    assert (
        data["status"] == 6 and data["derivatives"]["efficiency"]["op.torque"]["derivative"] is None
    )
    with pytest.raises(ValueError, match="no derivative exists"):
        sens.plot_tornado(bad, "efficiency", tmp_path / "t.png")


def test_files_and_tornado(report, tmp_path):
    csv_text = report.to_csv(tmp_path / "s.csv").read_text().splitlines()
    assert csv_text[0].split(",")[:3] == ["output", "output_value", "output_unit"]
    assert len(csv_text) == 1 + len(report.table)
    data = json.loads(report.to_json(tmp_path / "s.json").read_text())
    assert data["derivatives"]["power_loss"]["op.torque"]["derivative"] == pytest.approx(
        report.derivative("power_loss", "op.torque")
    )
    ranked = report.ranked("power_loss")
    finite = [abs(r["elasticity"]) for r in ranked if math.isfinite(r["elasticity"])]
    assert finite == sorted(finite, reverse=True)
    path = sens.plot_tornado(report, "power_loss", tmp_path / "t.png", top=8)
    assert path.stat().st_size > 5000


def test_cli_writes_the_report_and_its_figures(report, tmp_path, capsys):
    code = cli_main(
        [
            "sensitivity",
            "--fidelity",
            "quasi_static",
            "--torque",
            "650",
            "--speed",
            "2500",
            "--outputs",
            ",".join(OUTPUTS),
            "--out",
            str(tmp_path),
        ]
    )
    printed = capsys.readouterr().out
    assert code == 0
    for name in ("sensitivity.csv", "sensitivity.json", *(f"tornado_{o}.png" for o in OUTPUTS)):
        assert (tmp_path / name).stat().st_size > 0, name
    data = json.loads((tmp_path / "sensitivity.json").read_text())
    assert data["inputs"]["op.torque"]["value"] == 650.0
    assert "op.torque" in data["derivatives"]["efficiency"]
    assert "efficiency" in printed and printed.count("\n") < 80


@pytest.mark.parametrize(
    "argv, words",
    [
        (["--outputs", "efficency"], "unknown output 'efficency'"),
        (["--torque", "-5"], "torque"),
        (["--fidelity", "auto"], "invalid choice"),
    ],
)
def test_cli_rejects_bad_input_with_exit_code_2(tmp_path, capsys, argv, words):
    try:
        code = cli_main(["sensitivity", *argv, "--out", str(tmp_path)])
    except SystemExit as stop:  # argparse's own errors
        code = stop.code
    err = capsys.readouterr().err
    assert code == 2
    assert words in err and "Traceback" not in err and err.count("\n") == 1, err


# the fixed point converged far below its default 1e-4 (as
# tests/tribodynamics/test_differentiable.py), so that central differences are not noise
TRIBO = jg.Fidelity.fast(fixed_point_tolerance=1e-10)
TRIBO_OUTPUTS = ("efficiency", "power_loss", "dte_rms")


REAL_PROGRAM = sens._program


@pytest.fixture
def uncounted(monkeypatch):
    # the slow tests' fidelities compile programs of their own, beside the counted one
    monkeypatch.setattr(sens, "_program", REAL_PROGRAM)


@pytest.fixture(scope="module")
def tribo_report():
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(sens, "_program", REAL_PROGRAM)
        return _report((PAIR, LUB, SURF, OP, TRIBO), TRIBO, outputs=TRIBO_OUTPUTS)


def _tribo_central_differences(name, get, element, rel):
    inputs = (PAIR, LUB, SURF, OP, TRIBO)
    leaf = get(inputs)
    x = float(leaf if element is None else leaf[element])
    h = rel * abs(x)

    def at(shift):
        shifted = _shifted(inputs, get, element, shift)
        return _report(shifted, shifted[4], outputs=TRIBO_OUTPUTS).output_values

    return x, (at(h) - at(-h)) / (2.0 * h)


@pytest.mark.slow
def test_tribo_dynamic_derivatives_match_central_differences_and_status_6_has_none(
    tribo_report, uncounted
):
    rep = tribo_report
    assert rep.status == 0
    for name, get, element, rel in CHECKED[::3]:
        x, fd = _tribo_central_differences(name, get, element, rel)
        for k, out in enumerate(TRIBO_OUTPUTS[:2]):
            # fixed point to 1e-10 and the orbit's Newton to 1e-9: noise ~1e-10 relative in y
            d, y = rep.derivative(out, name), rep.output_values[k]
            assert d == pytest.approx(fd[k], rel=1e-3, abs=1e-6 * abs(y / x)), (out, name)
    # in an instability band of the calibrated pair (no stable periodic orbit): status 6, values
    # reported, no derivative
    slow = jg.OperatingPoint(torque=700.0, speed_rpm=800.0, inlet_temperature=363.15)
    unstable = jg.sensitivity(PAIR, LUB, SURF, slow, fidelity=TRIBO, outputs=TRIBO_OUTPUTS)
    assert unstable.status == 6 and "no derivative exists" in unstable.message
    assert np.all(np.isfinite(unstable.output_values))
    assert np.all(np.isnan(unstable.derivatives))
    # the values are simulate's (the attractor's means)
    res = jg.simulate(PAIR, LUB, SURF, slow, fidelity=TRIBO)
    assert unstable.outputs["power_loss"][0] == pytest.approx(float(res.power_loss), rel=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("index", [0, 3], ids=[CHECKED[0][0], CHECKED[3][0]])
def test_tribo_dynamic_dte_derivative_matches_central_differences(tribo_report, uncounted, index):
    # the DTE RMS, a fixed-point output in metres beside leaves in newtons: reverse mode once
    # stopped its transposed implicit solve with those leaves unconverged (0.3 % off on the
    # relief amount, 0.06 % on the torque). Central differences: the relief's measured stable to
    # 1e-7 relative over steps of 1e-5 to 1e-2 relative; the torque's step of 1e-4 leaves noise
    # ~1e-6 relative (y's ~1e-10); 2e-5 is well below either defect
    name, get, element, rel = CHECKED[index]
    x, fd = _tribo_central_differences(name, get, element, rel)
    d = tribo_report.derivative("dte_rms", name)
    assert d == pytest.approx(fd[2], rel=2e-5), (name, d, fd[2])


@pytest.mark.slow
def test_a_periodic_orbit_striking_the_back_flanks_has_derivatives(uncounted):
    # tests/gear/test_back_flanks.py's striking orbit (backlash 5 µm, 1500 N m, 3350 rpm): its
    # second pass counts the back flanks' loss, and the report's program with both passes
    # differentiates it; checked on the torque against central differences (steps of 1e-4
    # relative; the constant-μ rung and a fixed point to 1e-10: noise ~1e-9 relative in y)
    pair = eqx.tree_at(lambda p: p.backlash, PAIR, 5e-6)
    fid = jg.Fidelity(friction="constant", n_positions=32, fixed_point_tolerance=1e-10)
    op = jg.OperatingPoint(torque=1500.0, speed_rpm=3350.0)
    outputs = ("efficiency", "power_loss")
    rep = jg.sensitivity(pair, LUB, SURF, op, fidelity=fid, outputs=outputs, inputs=["torque"])
    res = jg.simulate(pair, LUB, SURF, op, fidelity=fid)
    assert rep.status == 0 and float(res.power_loss_back) > 0.0
    assert rep.outputs["power_loss"][0] == pytest.approx(float(res.power_loss), rel=1e-9)
    h = 1e-4 * 1500.0

    def at(torque):
        o = jg.OperatingPoint(torque=torque, speed_rpm=3350.0)
        return jg.sensitivity(pair, LUB, SURF, o, fidelity=fid, outputs=outputs).output_values

    fd = (at(1500.0 + h) - at(1500.0 - h)) / (2.0 * h)
    for k, out in enumerate(outputs):
        assert rep.derivative(out, "torque") == pytest.approx(fd[k], rel=1e-3), out
