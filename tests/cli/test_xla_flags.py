"""The CLI's (and the tests') choice of XLA's classic CPU emitters: added to $XLA_FLAGS only where
the caller has not chosen and this jaxlib knows the flag (XLA aborts the process on an unknown one)."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys

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
