"""Bad input everywhere (DESIGN §7): every public constructor, preset and function rejects NaN,
zero/negative where invalid and out-of-range values with a ValueError that names the field, the value
and the valid range; the command line exits 2 with one line on stderr and no traceback.

Every case fails before any model is compiled, so the whole file runs in seconds.
"""

import dataclasses
import math
import os
import subprocess
import sys

import numpy as np
import pytest
from helpers import ROOT

import jaxgear as jg
from jaxgear.cli import main
from jaxgear.cli.commands import ehl as ehl_command
from jaxgear.lubrication.lubricant import Lubricant

NAN = float("nan")
INF = float("inf")

PAIR_ARGS = dict(teeth=(50, 50), module=3e-3, pressure_angle=math.radians(20.0), face_width=0.02)
MATERIAL_ARGS = dict(
    youngs_modulus=207e9,
    poisson_ratio=0.3,
    density=7850.0,
    thermal_conductivity=46.7,
    specific_heat=470.0,
)
LUBRICANT_ARGS = dict(
    kinematic_viscosity_40=27.6e-6, kinematic_viscosity_100=5.1e-6, density=1004.0, roelands_z=0.6
)
CONTACT_ARGS = dict(reduced_radius=0.0128, load_per_width=5e5, u1=6.0, u2=4.0)
PROFILE = np.sin(np.arange(16.0))
SURFACE_ARGS = dict(profile1=PROFILE, profile2=PROFILE)


def expect_rejection(call, field, value, valid="valid"):
    """``call()`` raises ValueError naming ``field``, showing ``value`` and stating what is valid."""
    with pytest.raises(ValueError) as info:
        call()
    message = str(info.value)
    assert field in message, message
    assert value in message, message
    assert valid in message, message
    assert "\n" not in message, message
    return message


def _pair(**kw):
    return jg.GearPair(**{**PAIR_ARGS, **kw})


# (field in the message, kwargs, value as the message shows it)
GEAR_PAIR_CASES = [
    ("module", dict(module=NAN), "nan"),
    ("module", dict(module=-3e-3), "-0.003"),
    ("face_width", dict(face_width=0.0), "0"),
    ("face_width", dict(face_width=INF), "inf"),
    ("pressure_angle", dict(pressure_angle=NAN), "nan"),
    ("pressure_angle", dict(pressure_angle=1.0), "1"),
    ("teeth[0]", dict(teeth=(NAN, 50)), "nan"),
    ("teeth[0]", dict(teeth=("50", 50)), "'50'"),
    ("teeth[1]", dict(teeth=(50, 4)), "4"),
    ("profile_shift", dict(profile_shift=(2.0, 0.0)), "2."),
    ("addendum_coefficient", dict(addendum_coefficient=NAN), "nan"),
    ("dedendum_coefficient", dict(dedendum_coefficient=-1.0), "-1"),
    ("tip_radius", dict(tip_radius=(NAN, 0.078)), "nan"),
    ("root_radius", dict(root_radius=0.0), "0."),
    ("centre_distance", dict(centre_distance=NAN), "nan"),
    ("centre_distance", dict(centre_distance=0.1), "0.1"),
    ("backlash", dict(backlash=-1e-4), "-0.0001"),
    ("backlash", dict(backlash=INF), "inf"),
    ("blank_mass", dict(blank_mass=(-1.0, 1.0)), "-1."),
    ("blank_inertia", dict(blank_inertia=NAN), "nan"),
    ("bore_radius", dict(bore_radius=-0.01), "-0.01"),
    ("bore_radius[0]", dict(bore_radius=0.2), "0.2"),  # outside the root circle
    ("material", dict(material="steel"), "'steel'"),
    ("bearings", dict(bearings="paper"), "'paper'"),
    ("tip_relief", dict(tip_relief=10e-6), "1e-05"),
    (
        "tip_relief.amount[0]",
        dict(tip_relief=jg.TipRelief(amount=1e-3, start_roll_angle=0.365)),
        "0.001",
    ),
]


@pytest.mark.parametrize("field, kwargs, value", GEAR_PAIR_CASES)
def test_gear_pair(field, kwargs, value):
    expect_rejection(lambda: _pair(**kwargs), field, value)


@pytest.mark.parametrize(
    "field, kwargs, value",
    [
        ("TipRelief.amount", dict(amount=NAN), "nan"),
        ("TipRelief.amount", dict(amount=-1e-6), "-1.e-06"),
        ("TipRelief.start_roll_angle", dict(start_roll_angle=NAN), "nan"),
        ("TipRelief.start_roll_angle", dict(start_roll_angle=-0.1), "-0.1"),
        ("TipRelief.shape", dict(shape="cubic"), "'cubic'"),
    ],
)
def test_tip_relief(field, kwargs, value):
    expect_rejection(lambda: jg.TipRelief(**kwargs), field, value)


@pytest.mark.parametrize("name", ["ky", "cy", "kx", "cx", "ct"])
@pytest.mark.parametrize("bad, value", [(NAN, "nan"), (-1.0, "-1."), (INF, "inf")])
def test_bearings(name, bad, value):
    expect_rejection(lambda: jg.Bearings(**{name: bad}), f"Bearings.{name}", value)


@pytest.mark.parametrize("name", list(MATERIAL_ARGS))
def test_material_nan(name):
    expect_rejection(lambda: jg.Material(**{**MATERIAL_ARGS, name: NAN}), name, "nan")


@pytest.mark.parametrize(
    "name, bad, value",
    [("youngs_modulus", 0.0, "0"), ("poisson_ratio", 0.5, "0.5"), ("density", -1.0, "-1")],
)
def test_material_range(name, bad, value):
    expect_rejection(lambda: jg.Material(**{**MATERIAL_ARGS, name: bad}), name, value)


@pytest.mark.parametrize(
    "field, kwargs, value",
    [
        ("torque", dict(torque=NAN, speed_rpm=1000.0), "nan"),
        ("torque", dict(torque=0.0, speed_rpm=1000.0), "0"),
        ("torque", dict(torque=-700.0, speed_rpm=1000.0), "-700"),
        ("torque", dict(torque=INF, speed_rpm=1000.0), "inf"),
        ("torque", dict(torque="700 N m", speed_rpm=1000.0), "'700 N m'"),
        ("speed_rpm", dict(torque=700.0, speed_rpm=NAN), "nan"),
        ("speed_rpm", dict(torque=700.0, speed_rpm=-1000.0), "-1000"),
        # °C given where K is expected: the message shows the value and the kelvin range
        ("inlet_temperature", dict(torque=700.0, speed_rpm=1e3, inlet_temperature=90.0), "90"),
        ("inlet_temperature", dict(torque=700.0, speed_rpm=1e3, inlet_temperature=NAN), "nan"),
    ],
)
def test_operating_point(field, kwargs, value):
    msg = expect_rejection(lambda: jg.OperatingPoint(**kwargs), f"OperatingPoint.{field}", value)
    if field == "inlet_temperature":
        assert "[200, 600] K" in msg


@pytest.mark.parametrize(
    "name", [f.name for f in dataclasses.fields(Lubricant) if f.name != "temperature_model"]
)
def test_lubricant_nan(name):
    expect_rejection(lambda: Lubricant(**{**LUBRICANT_ARGS, name: NAN}), name, "nan")


@pytest.mark.parametrize(
    "name, bad, value",
    [
        ("kinematic_viscosity_40", 0.0, "0"),
        ("kinematic_viscosity_100", 30e-6, "3e-05"),  # above the 40 °C value
        ("density", 5000.0, "5000"),
        ("roelands_z", 2.0, "2"),
        ("thermal_expansion", -1e-4, "-0.0001"),
        ("eyring_stress", -5e6, "-5e+06"),
        ("temperature_model", "vogel", "'vogel'"),
    ],
)
def test_lubricant_range(name, bad, value):
    expect_rejection(lambda: Lubricant(**{**LUBRICANT_ARGS, name: bad}), name, value)


@pytest.mark.parametrize(
    "field, kwargs, value",
    [
        ("reduced_radius", dict(reduced_radius=NAN), "nan"),
        ("reduced_radius", dict(reduced_radius=0.0), "0"),
        ("load_per_width", dict(load_per_width=-1.0), "-1"),
        ("u1", dict(u1=NAN), "nan"),
        ("e_reduced", dict(e_reduced=0.0), "0"),
        ("inlet_temperature", dict(inlet_temperature=90.0), "90"),
        ("u1, u2", dict(u1=-1.0, u2=-1.0), "-1.0"),
    ],
)
def test_line_contact(field, kwargs, value):
    expect_rejection(lambda: jg.LineContact(**{**CONTACT_ARGS, **kwargs}), field, value)


@pytest.mark.parametrize(
    "field, kwargs, value",
    [
        ("n_nodes", dict(n_nodes=5), "5"),
        ("n_nodes", dict(n_nodes=NAN), "nan"),
        ("x_in", dict(x_in=1.0), "1.0"),
        ("viscosity", dict(viscosity="vogel"), "'vogel'"),
        ("tolerance", dict(tolerance=NAN), "nan"),
        ("fb_smoothing", dict(fb_smoothing=0.0), "0"),
        ("max_iterations", dict(max_iterations=0), "0"),
        ("wedge_order", dict(wedge_order=3), "3"),
        ("coarsest_nodes", dict(coarsest_nodes=4), "4"),
        ("coarsest_nodes", dict(coarsest_nodes=65.0), "65.0"),
        ("auto_domain", dict(auto_domain="yes"), "'yes'"),
        ("thermal", dict(thermal=1), "1"),
    ],
)
def test_ehl_model(field, kwargs, value):
    expect_rejection(lambda: jg.EHLModel(**kwargs), f"EHLModel.{field}", value)


@pytest.mark.parametrize(
    "field, kwargs, value",
    [
        ("dx", dict(dx=NAN), "nan"),
        ("dx", dict(dx=0.0), "0"),
        ("scale", dict(scale=-1.0), "-1"),
        ("scale", dict(scale=INF), "inf"),
        ("offset", dict(offset=(NAN, 0.0)), "nan"),
        ("offset", dict(offset=(0.0,)), "(1,)"),
        ("profile1", dict(profile1=np.full(16, NAN)), "nan"),
        ("profile2", dict(profile2=np.zeros(2)), "(2,)"),
    ],
)
def test_surfaces(field, kwargs, value):
    expect_rejection(lambda: jg.Surfaces(**{**SURFACE_ARGS, **kwargs}), f"Surfaces.{field}", value)


@pytest.mark.parametrize(
    "field, kwargs, value",
    [
        ("dynamics", dict(dynamics="dynamic"), "'dynamic'"),
        ("friction", dict(friction="ehl"), "'ehl'"),
        ("n_positions", dict(n_positions=8), "8"),
        ("n_positions", dict(n_positions=32.0), "32.0"),
        ("n_nodes", dict(n_nodes=NAN), "nan"),
        ("steps_per_period", dict(steps_per_period=-1), "-1"),
        ("constant_mu", dict(constant_mu=NAN), "nan"),
        ("constant_mu", dict(constant_mu=-0.1), "-0.1"),
        ("boundary_friction", dict(boundary_friction=2.0), "2.0"),
        ("fixed_point_tolerance", dict(fixed_point_tolerance=0.0), "0.0"),
        ("max_fixed_point_iterations", dict(max_fixed_point_iterations=0), "0"),
        ("relaxation", dict(relaxation=NAN), "nan"),
        ("anderson_memory", dict(anderson_memory=-1), "-1"),
        ("anderson_memory", dict(anderson_memory=1.5), "1.5"),
        ("backlash", dict(backlash="soft"), "'soft'"),
        ("back_flank", dict(back_flank="drive"), "'drive'"),
        ("stiffness", dict(stiffness="fem"), "'fem'"),
    ],
)
def test_fidelity(field, kwargs, value):
    expect_rejection(lambda: jg.Fidelity(**kwargs), f"Fidelity.{field}", value)


def test_fidelity_presets():
    expect_rejection(lambda: jg.Fidelity.named("slow"), "fidelity", "'slow'")
    expect_rejection(lambda: jg.Fidelity.fast(n_position=32), "n_position", "n_position")
    expect_rejection(lambda: jg.Fidelity.paper(n_nodes=8), "Fidelity.n_nodes", "8")
    expect_rejection(lambda: jg.Fidelity.fast().replace(speed=3), "speed", "speed")
    with pytest.raises(ValueError, match=r"Fidelity\.thermal = 1 must be True or False"):
        jg.Fidelity(thermal=1)


@pytest.mark.parametrize(
    "field, kwargs, value",
    [
        ("backlash", dict(backlash="soft"), "'soft'"),
        ("back_flank", dict(back_flank="drive"), "'drive'"),
        ("backlash_width", dict(backlash_width=0.0), "0"),
        ("newton_tol", dict(newton_tol=NAN), "nan"),
        ("steps_per_period", dict(steps_per_period=NAN), "nan"),
        ("steps_per_period", dict(steps_per_period=8.5), "8.5"),
        ("steps_per_mode_period", dict(steps_per_mode_period=-1.0), "-1"),
        ("max_steps_per_period", dict(max_steps_per_period=16), "16"),
        ("newton_max_steps", dict(newton_max_steps=0), "0"),
        ("newton_batch_steps", dict(newton_batch_steps=0), "0"),
        ("transient_periods", dict(transient_periods=-1), "-1"),
        ("n_positions", dict(n_positions=2), "2"),
    ],
)
def test_dynamics_options(field, kwargs, value):
    expect_rejection(lambda: jg.DynamicsOptions(**kwargs), f"DynamicsOptions.{field}", value)


def test_mesh_interface():
    z = np.zeros((8, 2))
    expect_rejection(
        lambda: jg.MeshInterface(damping=np.zeros(8), friction_1=z, friction_2=z),
        "MeshInterface.damping",
        "(8,)",
    )
    expect_rejection(
        lambda: jg.MeshInterface(damping=z - 1.0, friction_1=z, friction_2=z),
        "MeshInterface.damping",
        "-1.",
    )
    expect_rejection(
        lambda: jg.MeshInterface(damping=z, friction_1=z, friction_2=z + NAN),
        "MeshInterface.friction_2",
        "nan",
    )


P = jg.presets


@pytest.mark.parametrize(
    "call, field, value",
    [
        (lambda: P.li2015_pair(tip_relief=NAN), "TipRelief.amount", "nan"),
        (lambda: P.li2015_pair(tip_relief=-1e-6), "TipRelief.amount", "-1.e-06"),
        (lambda: P.li2015_pair(tip_relief=1e-3), "tip_relief.amount[0]", "0.001"),
        (lambda: P.li2015_pair(relief_start_deg=NAN), "TipRelief.start_roll_angle", "nan"),
        (lambda: P.li2015_pair(relief_start_deg=5.0), "start_roll_angle[0]", "5 deg"),
        (lambda: P.li2015_pair_calibrated(tip_relief=-1e-6), "TipRelief.amount", "-1.e-06"),
        (lambda: P.mil_l_23699("vogel"), "temperature_model", "'vogel'"),
        (lambda: P.iso_vg68("vogel"), "temperature_model", "'vogel'"),
        (lambda: P.ground(scale=-1.0), "Surfaces.scale", "-1"),
        (lambda: P.polished(scale=NAN), "Surfaces.scale", "nan"),
        (lambda: P.ground(seed=-1), "seed", "-1"),
        (lambda: P.ground(seed=1.5), "seed", "1.5"),
        (lambda: P.ground(n=2), "n", "2"),
        (lambda: P.ground(correlation_length=0.0), "correlation_length", "0"),
        (lambda: P.ground(short_cutoff=-2.5e-6), "short_cutoff", "-2.5e-06"),
        (lambda: P.smooth(n=2), "Surfaces.profile1", "(2,)"),
        (lambda: P.smooth(dx=0.0), "Surfaces.dx", "0"),
    ],
)
def test_presets(call, field, value):
    expect_rejection(call, field, value)


# -- functions ---------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def model():
    return dict(
        pair=P.li2015_pair(),
        lub=P.mil_l_23699(),
        surf=P.ground(),
        op=jg.OperatingPoint(700.0, 2000.0),
        fid=jg.Fidelity(dynamics="quasi_static", friction="regression"),
    )


def test_simulate(model):
    pair, lub, surf, op, fid = (model[k] for k in ("pair", "lub", "surf", "op", "fid"))
    expect_rejection(lambda: jg.simulate(None, lub, surf, op, fid), "pair", "None")
    expect_rejection(lambda: jg.simulate(pair, "oil", surf, op, fid), "lubricant", "'oil'")
    expect_rejection(lambda: jg.simulate(pair, lub, None, op, fid), "surfaces", "None")
    expect_rejection(lambda: jg.simulate(pair, lub, surf, (700.0, 2e3), fid), "op", "<tuple>")
    expect_rejection(lambda: jg.simulate(pair, lub, surf, op, "fast"), "fidelity", "'fast'")
    two = jg.OperatingPoint(torque=[700.0, 800.0], speed_rpm=2000.0)
    expect_rejection(lambda: jg.simulate(pair, lub, surf, two, fid), "op.torque", "(2,)")


@pytest.mark.parametrize(
    "kwargs, field, value",
    [
        (dict(speeds_rpm=[1000.0, NAN]), "speeds_rpm", "nan"),
        (dict(speeds_rpm=[1000.0, -5.0]), "speeds_rpm", "-5"),
        (dict(speeds_rpm=[]), "speeds_rpm", "(0,)"),
        (dict(speeds_rpm=[[1e3, 2e3], [3e3, 4e3]]), "speeds_rpm", "(2, 2)"),
        (dict(speeds_rpm=["fast"]), "speeds_rpm", "'fast'"),
        (dict(speeds_rpm=1e3, torque=[0.0]), "torque", "0"),
        (dict(speeds_rpm=1e3, inlet_temperature=[20.0]), "inlet_temperature", "20"),
        (dict(speeds_rpm=1e3, roughness_scale=[-1.0]), "roughness_scale", "-1"),
        (dict(speeds_rpm=1e3, tip_relief_amount=[1e-3]), "tip_relief_amount", "0.001"),
        (dict(speeds_rpm=1e3, backlash=[-1e-6]), "backlash", "-1.e-06"),
        (dict(speeds_rpm=1e3, chunk_size=0), "chunk_size", "0"),
        (dict(speeds_rpm=1e3, mode="serial"), "mode", "'serial'"),
        (dict(speeds_rpm=1e3, fidelity="fast"), "fidelity", "'fast'"),
        (dict(speeds_rpm=1e3, module=[3e-3]), "module", "'module'"),
    ],
)
def test_sweep(model, kwargs, field, value):
    kwargs = {"fidelity": model["fid"], **kwargs}
    args = (model["pair"], model["lub"], model["surf"], model["op"])
    expect_rejection(lambda: jg.sweep(*args, **kwargs), field, value)


@pytest.mark.parametrize(
    "function, kwargs, field, value",
    [
        ("optimise_tip_relief", dict(max_evaluations=-1), "max_evaluations", "-1"),
        ("optimise_tip_relief", dict(max_evaluations=2.5), "max_evaluations", "2.5"),
        ("optimise_tip_relief", dict(ctol=NAN), "ctol", "nan"),
        ("optimise_tip_relief", dict(gtol=0.0), "gtol", "0.0"),
        ("optimise_tip_relief", dict(objective="noise"), "objective", "'noise'"),
        ("optimise_tip_relief", dict(constraints={"dte_rms": NAN}), "dte_rms", "nan"),
        ("optimise_tip_relief", dict(speeds_rpm=[NAN]), "speeds_rpm", "nan"),
        ("optimise_tip_relief", dict(shape="cubic"), "shape", "'cubic'"),
        ("optimise_tip_relief", dict(bounds={"amount": (-1e-6, 1e-5)}), "amount", "-1e-06"),
        ("optimise_tip_relief", dict(bounds={"start": (0.3, 0.4)}), "bounds", "start"),
        ("optimise_tip_relief", dict(fidelity="fast"), "fidelity", "'fast'"),
        ("optimise_torque", dict(bounds=(-1.0, 10.0)), "torque", "-1"),
        ("optimise_torque", dict(bounds=(NAN, 10.0)), "torque", "nan"),
        ("optimise_torque", dict(steps=1.5), "steps", "1.5"),
        ("optimise_roughness_scale", dict(bounds=(3.0, 1.0)), "roughness_scale", "(3, 1)"),
        ("optimise_roughness_scale", dict(speeds_rpm=[-1.0]), "speeds_rpm", "-1"),
    ],
)
def test_optimise(model, function, kwargs, field, value):
    budget = {"max_evaluations": 1} if function == "optimise_tip_relief" else {"steps": 1}
    kwargs = {"fidelity": model["fid"], **budget, **kwargs}
    args = (model["pair"], model["lub"], model["surf"], model["op"])
    expect_rejection(lambda: getattr(jg, function)(*args, **kwargs), field, value)


def test_optimise_pair_and_generic():
    lub, surf, op = P.mil_l_23699(), P.ground(), jg.OperatingPoint(700.0, 2000.0)
    expect_rejection(lambda: jg.optimise_tip_relief(None, lub, surf, op), "pair", "None")
    expect_rejection(lambda: jg.optimise_torque(None, lub, surf, op), "pair", "None")

    def objective(x):
        return x[0], True

    expect_rejection(lambda: jg.optimise_bounded(objective, [NAN], ([0.0], [1.0])), "x0", "nan")
    expect_rejection(lambda: jg.optimise_bounded(objective, [0.5], ([1.0], [0.0])), "x0", "(1, 0)")


@pytest.mark.parametrize(
    "args, kwargs, field, value",
    [
        ((NAN,), {}, "torque", "nan"),
        ((-5.0,), {}, "torque", "-5"),
        (([700.0, 800.0],), {}, "torque", "(2,)"),
        ((700.0, 2), {}, "n_positions", "2"),
        ((700.0, 16.0), {}, "n_positions", "16.0"),
        ((700.0,), dict(stiffness="fem"), "stiffness", "'fem'"),
        ((700.0,), dict(edge_width=NAN), "edge_width", "nan"),
        ((700.0,), dict(relief_smoothing=0.0), "relief_smoothing", "0"),
        ((700.0,), dict(contact_smoothing=-1e-8), "contact_smoothing", "-1e-08"),
    ],
)
def test_mesh_cycle(model, args, kwargs, field, value):
    expect_rejection(lambda: jg.mesh_cycle(model["pair"], *args, **kwargs), field, value)


def test_dynamic_response(model):
    pair, op = model["pair"], model["op"]
    expect_rejection(lambda: jg.dynamic_response(None, op), "pair", "None")
    expect_rejection(lambda: jg.dynamic_response(pair, (700.0, 2e3)), "op", "<tuple>")
    expect_rejection(lambda: jg.dynamic_response_sweep(pair, op, [1e3, NAN]), "speeds_rpm", "nan")
    expect_rejection(lambda: jg.dynamic_response_sweep(pair, op, []), "speeds_rpm", "(0,)")


def test_geometry_and_modes(model):
    expect_rejection(lambda: jg.mesh_cycle(None, 700.0), "pair", "None")
    expect_rejection(lambda: jg.gear_geometry("li2015"), "pair", "'li2015'")
    expect_rejection(lambda: jg.natural_frequencies(model["pair"], NAN), "mesh_stiffness", "nan")
    expect_rejection(lambda: jg.natural_frequencies(model["pair"], -1.0), "mesh_stiffness", "-1")
    expect_rejection(lambda: jg.natural_frequencies(None, 3e8), "pair", "None")


def test_solve_ehl(model):
    contact, lub = jg.LineContact(**CONTACT_ARGS), model["lub"]
    ehl = jg.EHLModel(n_nodes=65)
    expect_rejection(lambda: jg.solve_ehl(None, lub, ehl), "contact", "NoneType")
    expect_rejection(lambda: jg.solve_ehl(contact, None, ehl), "lubricant", "NoneType")
    expect_rejection(lambda: jg.solve_ehl(contact, lub, "fast"), "model", "'fast'")
    # Not a Surfaces (the mixed-EHL solver takes one; its message is that module's)
    expect_rejection(lambda: jg.solve_ehl(contact, lub, ehl, "rough"), "surfaces", "surfaces = ")
    previous = object()  # rejected on the time step before the previous solution is read
    for dt, shown in ((-1e-6, "-1e-06"), (NAN, "nan"), (None, "None")):
        expect_rejection(
            lambda dt=dt: jg.solve_ehl(contact, lub, ehl, previous=previous, time_step=dt),
            "time_step",
            shown,
        )


# -- the command line ----------------------------------------------------------------------------


def run_cli(argv, capsys):
    """``jaxgear ARGV`` in this process: (exit code, stderr). argparse's own errors exit through
    SystemExit; the subcommands' return 2."""
    try:
        code = main(argv)
    except SystemExit as stop:
        code = stop.code
    return code, capsys.readouterr().err


@pytest.fixture(scope="module")
def configs(tmp_path_factory):
    d = tmp_path_factory.mktemp("configs")
    files = {
        "gear_key": "[gear]\nmodul_mm = 3.0\n",
        "op_key": "[operating]\ntorq_Nm = 5.0\n",
        "op_value": "[operating]\ntorque_Nm = -5.0\n",
        "syntax": "[gear\n",
        "ehl_model_key": "[contact]\nreduced_radius = 0.01\nload_per_width = 1e5\nu1 = 1.0\n"
        "u2 = 1.0\n[model]\nnodes = 129\n",
        "ehl_contact_type": "[contact]\nreduced_radius = 'small'\n",
        "ehl_table": "[contacts]\nreduced_radius = 0.01\n",
        "optimise_key": "[optimise]\nstep = 3\n",
        "optimise_steps": "[optimise]\nsteps = -3\n",
    }
    for name, text in files.items():
        (d / f"{name}.toml").write_text(text)
    return d


CLI_CASES = [
    # (argv, text the one-line message must contain)
    (["frobnicate"], "'frobnicate'"),
    (["run", "--fidelity", "slow"], "--fidelity: invalid choice: 'slow'"),
    (["run", "--torque", "abc"], "--torque: invalid float value: 'abc'"),
    (["run", "--torque", "nan"], "torque = nan is not finite; valid range: (0, inf) N m"),
    (["run", "--torque", "-5"], "torque = -5 N m is out of range"),
    (["run", "--inlet-temperature", "400"], "inlet_temperature = 673.15 K is out of range"),
    (["run", "--speeds", "100:inf:10"], "--speeds = '100:inf:10' is out of range"),
    (["run", "--speeds", "1:1e9:1"], "valid range: at most"),  # refused before allocating
    (["run", "--speeds", "fast"], "--speeds = 'fast' must be START:STOP:STEP"),
    (["run", "--chunk-size", "0"], "--chunk-size = 0 is out of range"),
    (["run", "--surfaces", "rough"], "--surfaces: invalid choice: 'rough'"),
    (["mesh", "--positions", "0"], "n_positions = 0 is out of range"),
    (["mesh", "--positions", "many"], "--positions: invalid int value: 'many'"),
    (["mesh", "--torque", "nan"], "torque = nan is not finite"),
    (["mesh", "--config", "{d}/missing.toml"], "missing.toml' does not exist"),
    (["mesh", "--config", "{d}/gear_key.toml"], "unknown key gear.modul_mm"),
    (["mesh", "--config", "{d}/op_key.toml"], "unknown key operating.torq_Nm"),
    (["mesh", "--config", "{d}/op_value.toml"], "torque = -5 N m is out of range"),
    (["mesh", "--config", "{d}/syntax.toml"], "is not valid TOML"),
    (["ehl", "--config", "{d}/missing.toml"], "missing.toml' does not exist"),
    (["ehl", "--config", "{d}/syntax.toml"], "is not valid TOML"),
    (["ehl", "--config", "{d}/ehl_model_key.toml"], "unknown key model.nodes"),
    (["ehl", "--config", "{d}/ehl_contact_type.toml"], "contact.reduced_radius = 'small'"),
    (["ehl", "--config", "{d}/ehl_table.toml"], "unknown table [contacts]"),
    (
        ["ehl", "--reduced-radius", "0.01", "--load-per-width", "1e5", "--u1", "1", "--u2", "1"]
        + ["--nodes", "5"],
        "EHLModel.n_nodes = 5 is out of range",
    ),
    (
        ["ehl", "--reduced-radius", "nan", "--load-per-width", "1e5", "--u1", "1", "--u2", "1"],
        "LineContact.reduced_radius = nan is not finite",
    ),
    (["optimise", "--speeds", "a,b"], "--speeds = 'a,b' must be comma-separated numbers"),
    (["optimise", "--speeds", "-1"], "--speeds = '-1' is out of range"),
    (["optimise", "--speed-range", "1:0:1"], "--speed-range = '1:0:1' is out of range"),
    (["optimise", "--steps", "-1"], "steps = -1 is out of range"),
    (["optimise", "--learning-rate", "nan"], "learning_rate = nan is out of range"),
    (["optimise", "--fidelity", "paper"], "--fidelity: invalid choice: 'paper'"),
    (["optimise", "--config", "{d}/missing.toml"], "missing.toml' does not exist"),
    (["optimise", "--config", "{d}/optimise_key.toml"], "unknown key optimise.step"),
    (["optimise", "--config", "{d}/optimise_steps.toml"], "steps = -3 is out of range"),
]


@pytest.mark.parametrize("argv, needle", CLI_CASES, ids=[" ".join(c[0])[:40] for c in CLI_CASES])
def test_cli_exits_2_with_one_line(argv, needle, configs, capsys):
    argv = [a.format(d=configs) for a in argv]
    code, err = run_cli(argv, capsys)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("jaxgear") and "error: " in lines[0]
    assert needle in lines[0], lines[0]
    assert "Traceback" not in err


def test_cli_in_a_real_process(configs):
    """The entry point in its own process, not just main(): exit status 2, one line on stderr, no
    traceback, nothing on stdout (test_cli.py does the same for bad [gear] configs)."""
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "jaxgear.cli",
            "ehl",
            "--config",
            str(configs / "ehl_model_key.toml"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "JAXGEAR_CACHE_DIR": "off"},
        cwd=ROOT,
    )
    assert out.returncode == 2, out.stderr
    assert out.stderr.strip().splitlines() == [
        "jaxgear ehl: error: unknown key model.nodes in config; valid keys: "
        + ", ".join(sorted(ehl_command.MODEL_KEYS))
    ]
    assert out.stdout == ""
