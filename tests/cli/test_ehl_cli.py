"""``jaxgear ehl``: JSON from options and TOML, PNG output, errors naming the field."""

import argparse
import json

import pytest
from helpers import gear_contact

from jaxgear.cli.commands import ehl as ehl_command

# the suite's standard model (129 nodes, default physics): compiled once for all EHL tests
ARGS = ["--nodes", "129"]


def _run(argv, capsys):
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers(dest="command")
    ehl_command.register(sub)
    args = parser.parse_args(["ehl", *argv])
    code = args.func(args)
    return code, capsys.readouterr().out


def _contact_args(c):
    return [
        "--reduced-radius", str(float(c.reduced_radius)),
        "--load-per-width", str(float(c.load_per_width)),
        "--u1", str(float(c.u1)),
        "--u2", str(float(c.u2)),
        "--e-reduced", str(float(c.e_reduced)),
    ]  # fmt: skip


def test_cli_options_toml_and_png_agree(tmp_path, capsys):
    c = gear_contact()
    code, out = _run([*_contact_args(c), *ARGS, "--png", str(tmp_path / "ehl.png")], capsys)
    assert code == 0
    a = json.loads(out)
    assert a["converged"] and a["h_central"] > a["h_min"] > 0
    assert (tmp_path / "ehl.png").stat().st_size > 1000
    # the same contact from TOML gives the same numbers
    toml = tmp_path / "c.toml"
    toml.write_text(
        'lubricant = "mil_l_23699"\n[contact]\n'
        + "".join(
            f"{k} = {float(getattr(c, k))!r}\n"
            for k in (
                "reduced_radius",
                "load_per_width",
                "u1",
                "u2",
                "e_reduced",
                "inlet_temperature",
            )
        )
        + "[model]\nn_nodes = 129\n"
    )
    code, out = _run(["--config", str(toml), "--arrays"], capsys)
    b = json.loads(out)
    assert code == 0
    assert b["h_central"] == pytest.approx(a["h_central"], rel=1e-12)
    assert len(b["p"]) == 129


def test_cli_bad_input_names_the_field(capsys):
    c = gear_contact()
    argv = _contact_args(c)
    argv[argv.index("--load-per-width") + 1] = "-5"
    with pytest.raises(ValueError, match="load_per_width"):
        _run([*argv, *ARGS], capsys)
    with pytest.raises(ValueError, match="u2"):
        _run(["--reduced-radius", "0.01", "--load-per-width", "1e5", "--u1", "1"], capsys)


def test_cli_main_exit_code_2_on_bad_input(capsys):
    # through the dispatcher (every registered subcommand must import)
    from jaxgear.cli import main

    code = main(
        ["ehl", "--reduced-radius", "0", "--load-per-width", "1e5", "--u1", "1", "--u2", "1"]
    )
    assert code == 2
    assert "reduced_radius" in capsys.readouterr().err
