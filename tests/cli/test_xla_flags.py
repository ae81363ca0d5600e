"""The CLI's (and the tests') choice of XLA's classic CPU emitters: added to $XLA_FLAGS only where
the caller has not chosen and this jaxlib knows the flag (XLA aborts the process on an unknown one).
The tests' unoptimised machine code (conftest.py) against the optimised code users run."""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys

import pytest

from jaxgear.cli import enable_fast_cpu_compilation

# the module (jaxgear.cli.main the attribute is the CLI's main function)
cli_main = importlib.import_module("jaxgear.cli.main")

FLAG = "--xla_cpu_use_fusion_emitters=false"


def test_the_flag_is_appended_to_the_callers_flags(monkeypatch):
    monkeypatch.setenv("XLA_FLAGS", "--xla_force_host_platform_device_count=1")
    monkeypatch.delenv("JAXGEAR_FAST_CPU_COMPILATION", raising=False)
    monkeypatch.setattr(cli_main, "_jaxlib_knows", lambda flag: True)
    assert enable_fast_cpu_compilation()
    assert os.environ["XLA_FLAGS"] == f"--xla_force_host_platform_device_count=1 {FLAG}"


def test_a_callers_own_choice_an_opt_out_and_an_unknown_flag_leave_xla_flags_alone(monkeypatch):
    monkeypatch.setattr(cli_main, "_jaxlib_knows", lambda flag: True)
    monkeypatch.delenv("JAXGEAR_FAST_CPU_COMPILATION", raising=False)
    monkeypatch.setenv("XLA_FLAGS", "--xla_cpu_use_fusion_emitters=true")
    assert not enable_fast_cpu_compilation()
    assert os.environ["XLA_FLAGS"] == "--xla_cpu_use_fusion_emitters=true"
    monkeypatch.setenv("XLA_FLAGS", "")
    monkeypatch.setenv("JAXGEAR_FAST_CPU_COMPILATION", "off")
    assert not enable_fast_cpu_compilation()
    assert os.environ["XLA_FLAGS"] == ""
    monkeypatch.delenv("JAXGEAR_FAST_CPU_COMPILATION")
    monkeypatch.setattr(cli_main, "_jaxlib_knows", lambda flag: False)
    assert not enable_fast_cpu_compilation()
    assert os.environ["XLA_FLAGS"] == ""


def test_the_installed_jaxlib_runs_with_the_flag_it_is_said_to_know():
    # a fresh process: the flag set before the backend starts, then one computation. Where the
    # detection says "known" and XLA did not register it, XLA aborts the process (exit != 0)
    code = (
        "from jaxgear.cli import enable_fast_cpu_compilation\n"
        "import os, jax.numpy as jnp\n"
        "known = enable_fast_cpu_compilation()\n"
        "print(known, float(jnp.sum(jnp.arange(4.0) ** 2)), os.environ.get('XLA_FLAGS', ''))\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("XLA_FLAGS",)}
    env.pop("JAXGEAR_FAST_CPU_COMPILATION", None)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    known, value, flags = out.stdout.split(maxsplit=2)
    assert value == "14.0"
    assert (FLAG in flags) == (known == "True")


def test_the_detection_does_not_accept_a_flag_xla_does_not_have():
    assert not cli_main._jaxlib_knows("xla_cpu_no_such_flag_in_any_jaxlib_0123")
    # a prefix of a registered name is not a flag (XLA would abort on it)
    assert not cli_main._jaxlib_knows("xla_cpu_use_fusion_emitter")


def _flags_of_a_cli_call(argv, monkeypatch):
    """$XLA_FLAGS after ``jaxgear ARGV`` chose its emitters (the command itself not run)."""
    monkeypatch.setenv("XLA_FLAGS", "")
    monkeypatch.delenv("JAXGEAR_FAST_CPU_COMPILATION", raising=False)
    monkeypatch.setattr(cli_main, "_jaxlib_knows", lambda flag: True)
    monkeypatch.setattr(cli_main, "enable_float64", lambda: None)
    monkeypatch.setattr(cli_main, "enable_compilation_cache", lambda: None)
    args = cli_main.build_parser().parse_args(argv)
    args.func = lambda a: 0

    class Parsed:
        def parse_args(self, argv=None):
            return args

    with monkeypatch.context() as m:
        m.setattr(cli_main, "build_parser", Parsed)
        assert cli_main.main(argv) == 0
    return os.environ["XLA_FLAGS"]


def test_the_cli_selects_the_classic_emitters_except_at_the_paper_fidelity(monkeypatch):
    # the paper fidelity's programs compile ~1.45x slower with them (benchmarks/paper_point.py)
    assert FLAG in _flags_of_a_cli_call(["figures", "--fidelity", "fast"], monkeypatch)
    assert FLAG in _flags_of_a_cli_call(["run"], monkeypatch)
    for name in ("paper", "paper_calibrated"):
        assert FLAG not in _flags_of_a_cli_call(["figures", "--fidelity", name], monkeypatch)


def round_off_values() -> dict:
    """What the round-off test below compares: a coupled simulation, and the thermal statistical
    film in which XLA's optimised code once evaluated the temperatures 0.4 % apart inside the
    temperature iteration and after it (a cold solve at 500 rpm, then a warm and a cold solve at
    510 rpm, 257 nodes: test_mixed_energy.py's check)."""
    import jax.numpy as jnp
    from helpers import gear_contact

    import jaxgear as jg
    from jaxgear.lubrication.roughness import ground

    lub = jg.presets.mil_l_23699()
    res = jg.simulate(
        jg.presets.li2015_pair_calibrated(),
        lub,
        jg.presets.ground(),
        jg.OperatingPoint(torque=700.0, speed_rpm=2500.0, inlet_temperature=363.15),
        fidelity=jg.Fidelity.fast(fixed_point_tolerance=1e-10),
    )
    model = jg.EHLModel(n_nodes=257, mixed="statistical", thermal=True)
    first = jg.solve_ehl(gear_contact(rpm=500.0), lub, model, ground())
    warm = jg.solve_ehl(gear_contact(rpm=510.0), lub, model, ground(), initial=first)
    cold = jg.solve_ehl(gear_contact(rpm=510.0), lub, model, ground())
    return {
        "efficiency": float(res.efficiency),
        "power_loss": float(res.power_loss),
        "dte_rms": float(res.dte_rms),
        "status": int(res.status),
        "films_converged": bool(first.converged & warm.converged & cold.converged),
        "warm_film_loss": float(warm.power_loss),
        "cold_film_loss": float(cold.power_loss),
        "warm_peak_temperature": float(jnp.max(warm.temperature)),
    }


# a fresh process compiling as users do: XLA_FLAGS without the tests' optimisation level
_OPTIMISED = """
import json, sys
from jaxgear.cli import enable_compilation_cache, enable_fast_cpu_compilation
enable_fast_cpu_compilation()
import jax
jax.config.update("jax_enable_x64", True)
enable_compilation_cache()
sys.path[:0] = [{tests!r}, {here!r}]
from test_xla_flags import round_off_values
print(json.dumps(round_off_values()))
"""


def test_the_tests_unoptimised_code_computes_what_the_users_optimised_code_does():
    # The tests compile without LLVM's optimisation (conftest.py: a third less time); users'
    # programs are optimised. The values of round_off_values in both: measured ~1e-15 relative
    # apart, round-off through converged iterations; 1e-9 leaves room for an iteration more or
    # less and fails on anything a compiler would have to get wrong. In the optimised process
    # the warm film must also reach the cold one (the check that the unoptimised code cannot
    # make for it: the 0.4 % discrepancy was the optimised code's alone).
    mine = os.environ.get("XLA_FLAGS", "")
    users = " ".join(f for f in mine.split() if "xla_backend_optimization_level" not in f)
    # conftest.py chose level 0 (unless the caller set a level or this jaxlib lacks the flag)
    assert mine != users or not cli_main._jaxlib_knows("xla_backend_optimization_level")
    here = os.path.dirname(os.path.abspath(__file__))
    code = _OPTIMISED.format(tests=os.path.dirname(here), here=here)
    # the tests' on-disk cache (its keys include the XLA flags: no program is shared)
    env = dict(os.environ, XLA_FLAGS=users)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    optimised = json.loads(out.stdout.strip().splitlines()[-1])
    tests = round_off_values()
    for values in (tests, optimised):
        assert values["status"] == 0 and values["films_converged"]
        assert values["warm_film_loss"] == pytest.approx(values["cold_film_loss"], rel=1e-6)
    for key in ("efficiency", "power_loss", "dte_rms", "warm_film_loss", "warm_peak_temperature"):
        assert tests[key] == pytest.approx(optimised[key], rel=1e-9), key
