"""`jaxgear run`, the main job: files, summary, resume, bad input (exit 2, no traceback)."""

import json
import subprocess
import sys

import matplotlib.image
import numpy as np

from jaxgear.cli import main


def test_run_writes_results_and_resumes(tmp_path, capsys):
    out = tmp_path / "results"
    args = [
        "run",
        "--speeds",
        "1000:1500:500",
        "--out",
        str(out),
        "--no-progress",
        "--chunk-size",
        "2",
    ]
    assert main(args) == 0
    for name in ("sweep.csv", "summary.json", "dte_rms.png", "power_loss.png", "efficiency.png"):
        assert (out / name).stat().st_size > 200, name
    for name in ("dte_rms.png", "power_loss.png", "efficiency.png"):
        # a real picture, not an empty canvas: it decodes as a PNG, and its pixels are not all
        # one colour (the axes, labels and curves)
        image = matplotlib.image.imread(out / name)
        assert image.ndim == 3 and image.shape[0] > 200 and image.shape[1] > 200, name
        assert float(np.ptp(image[..., :3])) > 0.5, name
    summary = json.loads((out / "summary.json").read_text())
    head = summary["headline"]
    assert head["speeds_rpm"] == [1000.0, 1500.0, 2]
    assert head["points_not_converged"] == 0
    # REFERENCE §7 R4: efficiency within 99.6-99.85 % at the paper's conditions. Not the band
    # itself: Fidelity.fast() shares the paper fidelity's loss level, 0.3-0.6 of the paper's, so
    # its Ψ sits at the band's upper edge or just above (99.84-99.91 % over the baseline sweep,
    # README); 99.95 % catches a loss level off by another factor of 2, not the known gap.
    assert 99.6 < head["mean_efficiency_percent"] < 99.95
    rows = (out / "sweep.csv").read_text().splitlines()
    assert rows[0].startswith("speed_rpm,power_loss_W") and len(rows) == 3
    # stable orbits at these speeds: no back-flank strikes, whose loss Φ̄ would leave out
    header = rows[0].split(",")
    assert [r.split(",")[header.index("back_contact_share")] for r in rows[1:]] == ["0", "0"]
    assert head["points_with_back_contact"] == 0 and summary["back_contact"] == []
    # A second run finds the finished chunks and reproduces the table exactly.
    first = (out / "sweep.csv").read_text()
    assert main(args) == 0
    assert (out / "sweep.csv").read_text() == first


def test_run_bad_input_exit_2(tmp_path):
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "jaxgear.cli",
            "run",
            "--speeds",
            "4200:500:25",
            "--out",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 2
    assert "--speeds" in proc.stderr and "Traceback" not in proc.stderr


def test_summary_reports_the_resonance_peaks_apart_from_a_back_flank_rattle():
    # A synthetic sweep shaped like the calibrated pair's baseline at Fidelity.fast(): resonance
    # peaks at 1750 and 3375 rpm, and a band (3950-4050 rpm) where the rattling teeth strike the
    # back flanks with a DTE above the higher peak. The summary's global peaks keep reporting the
    # largest DTE (the rattle's); its resonance peaks must be the mesh resonances'.
    from types import SimpleNamespace

    import numpy as np

    from jaxgear.cli.commands.run import _summary
    from jaxgear.fidelity import Fidelity

    speeds = np.arange(500.0, 4200.0 + 1e-9, 25.0)
    dte = 5e-6 + 22e-6 * np.exp(-(((speeds - 1750.0) / 60.0) ** 2))
    dte += 30e-6 * np.exp(-(((speeds - 3375.0) / 80.0) ** 2))
    rattle = (speeds >= 3950.0) & (speeds <= 4050.0)
    dte = np.where(rattle, 40e-6 + 6e-6 * (speeds - 3950.0) / 100.0, dte)
    n = speeds.size
    td = SimpleNamespace(
        dte_rms=dte,
        converged=~rattle,
        on_attractor=rattle,
        failed=np.zeros(n, bool),
        efficiency=np.full(n, 0.997),
        power_loss=np.full(n, 500.0),
        back_contact_share=0.4 * rattle,
        power_loss_back=100.0 * rattle,
        status_names=lambda: ["converged"] * n,
    )
    args = SimpleNamespace(torque=700.0, inlet_temperature=90.0, surfaces="ground")
    head = _summary(speeds, td, None, Fidelity.fast(), args, 1.0, 2.0)["headline"]
    assert head["dte_rms_peak_high"]["speed_rpm"] == 4050.0  # the largest DTE, as before
    assert abs(head["dte_rms_peak_high"]["dte_rms_um"] - 46.0) < 1e-9
    assert head["dte_rms_resonance_peak_high"]["speed_rpm"] == 3375.0
    assert head["dte_rms_resonance_peak_low"]["speed_rpm"] == 1750.0
    assert head["points_with_back_contact"] == int(rattle.sum())
