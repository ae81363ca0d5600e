"""The command line: help, the mesh job, config errors with exit code 2 and no traceback."""

import json
import subprocess
import sys

import pytest

from jaxgear.cli import main


def _run(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "jaxgear.cli", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=600,
    )


def test_help_lists_commands():
    out = _run("--help")
    assert out.returncode == 0
    assert "mesh" in out.stdout


def test_mesh_writes_files(tmp_path, capsys):
    rc = main(["mesh", "--positions", "16", "--format", "json", "--out", str(tmp_path)])
    assert rc == 0
    data = json.loads(capsys.readouterr().out.split("\nwrote ")[0])
    assert abs(data["summary"]["contact_ratio"] - 1.7547) < 1e-3
    assert len(data["rows"]) == 16
    for name in ("mesh_cycle.csv", "mesh_cycle.json", "mesh_cycle.png"):
        assert (tmp_path / name).stat().st_size > 100
    shares = [r["load_share_1"] + r["load_share_2"] for r in data["rows"]]
    assert all(abs(s - 1.0) < 1e-9 for s in shares)


def test_mesh_from_config(tmp_path, capsys):
    cfg = tmp_path / "pair.toml"
    cfg.write_text(
        '[gear]\npreset = "none"\nteeth = [23, 47]\nmodule_mm = 4.0\npressure_angle_deg = 25.0\n'
        "face_width_mm = 30.0\n[gear.tip_relief]\namount_um = 5.0\nstart_roll_angle_deg = 22.0\n"
        "[operating]\ntorque_Nm = 300.0\n"
    )
    assert main(["mesh", "--config", str(cfg), "--positions", "8", "--format", "csv"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0].startswith("roll_angle_deg,")
    assert len(lines) == 9


@pytest.mark.parametrize(
    "text, needle",
    [
        ("[gear]\nmodul_mm = 3.0\n", "unknown key gear.modul_mm"),
        ("[gear]\nmodule_mm = 'three'\n", "gear.module_mm = 'three' has the wrong type"),
        ("[gear]\nface_width_mm = -20.0\n", "face_width = -0.02 m is out of range"),
        ("[gears]\n", "unknown table [gears]"),
        ("[gear\n", "not valid TOML"),
    ],
)
def test_bad_config_exit_2_without_traceback(tmp_path, text, needle):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(text)
    out = _run("mesh", "--config", str(cfg))
    assert out.returncode == 2
    assert needle in out.stderr
    assert "Traceback" not in out.stderr


def test_missing_config_file_exit_2():
    out = _run("mesh", "--config", "/nonexistent/x.toml")
    assert out.returncode == 2 and "does not exist" in out.stderr and "Traceback" not in out.stderr
