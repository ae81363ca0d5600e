"""What a viscous mesh damping along the line of action changes (``GearPair.mesh_damping_ratio``).

The paper's model has no mesh damping along the line of action (REFERENCE §1): its only mesh damping
is the EHL film's, along the common tangent. Gear-dynamics models usually carry one (ζ of a few
per cent: the film's squeeze and the teeth's material damping lumped), and the calibrated pair's
back-flank rattle at 3850-4050 rpm (``studies/attractor/attractor.py``) is an undamped vibro-impact
regime.
This benchmark runs the baseline sweep at ``Fidelity.fast()`` (calibrated pair, ground, 700 N m,
90 °C, continuation, 500-4200 rpm every ``--step`` rpm) for several ζ and reports, per ζ: the speeds
without a stable periodic orbit (status 6), the speeds whose teeth strike the back flanks and how
hard, the DTE-RMS resonance peaks (among speeds without back strikes) and the largest DTE, Φ̄ and
TD/QS at the points A-E (1700, 1800, 2550, 3300, 3500 rpm) and the sweep's wall time (compiled).

Writes the section ``mesh_damping`` of studies/mesh_damping/README.md. Run (repository root):
    python studies/mesh_damping/mesh_damping.py [--step 25] [--ratios 0 0.01 0.02 0.05 0.1]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import equinox as eqx  # noqa: E402
import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
README = Path(__file__).with_name("README.md")  # this study's sections
sys.path.insert(0, str(ROOT / "benchmarks"))  # _report

from _report import bands, machine, write_section  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.cli.commands.run import _peak as run_peak  # noqa: E402
from jaxgear.paper.reproduce import _resonance_dte  # noqa: E402

POINTS = {"A": 1700.0, "B": 1800.0, "C": 2550.0, "D": 3300.0, "E": 3500.0}


def _sweep(pair, fid, speeds):
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    op = jg.OperatingPoint(torque=700.0, speed_rpm=500.0, inlet_temperature=363.15)
    t0 = time.perf_counter()
    res = jg.sweep(pair, lub, surf, op, speeds_rpm=speeds, fidelity=fid, mode="continuation")
    return res, time.perf_counter() - t0


def _peak(speeds, dte, lo, hi):
    """'rpm (µm)' of the largest DTE in [lo, hi] rpm (``jaxgear run``'s summary peak)."""
    peak = run_peak(speeds, dte, lo, hi)
    return "none" if peak is None else f"{peak['speed_rpm']:.0f} ({peak['dte_rms_um']:.1f})"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--step", type=float, default=25.0, help="speed step of the sweep, rpm")
    ap.add_argument(
        "--ratios", type=float, nargs="+", default=[0.0, 0.01, 0.02, 0.05, 0.1], help="ζ values"
    )
    args = ap.parse_args(argv)
    speeds = np.arange(500.0, 4200.0 + 1e-9, args.step)
    base = jg.presets.li2015_pair_calibrated()
    fid = jg.Fidelity.fast()
    qs, _ = _sweep(base, fid.replace(dynamics="quasi_static"), speeds)
    at = {k: int(np.argmin(np.abs(speeds - v))) for k, v in POINTS.items()}
    rows, point_rows = [], []
    for zeta in args.ratios:
        pair = eqx.tree_at(lambda p: p.mesh_damping_ratio, base, jnp.asarray(zeta))
        res, first = _sweep(pair, fid, speeds)
        _, again = _sweep(pair, fid, speeds + 1e-3)
        status = np.asarray(res.status)
        back = np.nan_to_num(np.asarray(res.back_contact_share))
        dte = np.asarray(res.dte_rms)
        resonance = _resonance_dte(res)
        strikes = back > 0
        rows.append(
            f"| {zeta:g} | {int((status == 6).sum())}: {bands(speeds, status == 6)} | "
            f"{bands(speeds, strikes)} | {back.max():.2f} | "
            f"{np.nan_to_num(np.asarray(res.power_loss_back)).max():.1f} | "
            f"{_peak(speeds, resonance, 0, 2600)} | {_peak(speeds, resonance, 2600, 1e9)} | "
            f"{_peak(speeds, dte, 0, 1e9)} | {int(np.sum(np.asarray(res.failed)))} | "
            f"{first:.1f} / {again:.1f} |"
        )
        cells = []
        for i in at.values():
            td, q = float(res.power_loss[i]), float(qs.power_loss[i])
            mark = "‡" if status[i] == 6 else ""
            damper = float(res.mesh_damping_power[i])
            cells.append(f"{td:.1f}{mark} ({100 * (td / q - 1):+.1f} %; {damper:.0f} W)")
        point_rows.append(f"| {zeta:g} | " + " | ".join(cells) + " |")
        print(rows[-1], flush=True)
        print(point_rows[-1], flush=True)
    qs_cells = " | ".join(f"{float(qs.power_loss[i]):.1f}" for i in at.values())
    body = "\n".join(
        [
            "## A viscous mesh damping along the line of action (`mesh_damping.py`)",
            "",
            f"Machine: {machine()}.",
            "",
            "`Fidelity.fast()`, calibrated pair (`li2015_pair_calibrated`), ground, 700 N m, "
            f"90 °C, continuation, {speeds[0]:.0f}-{speeds[-1]:.0f} rpm every {args.step:g} rpm "
            f"({speeds.size} speeds), with `GearPair.mesh_damping_ratio` ζ (0: the paper's "
            "model). Status 6: no stable periodic orbit, means over the attractor. Back "
            "strikes: speeds whose teeth strike the back flanks (`back_contact_share` > 0); "
            "largest share of the cycle and back loss over them. Resonance peaks: the largest "
            "DTE RMS (µm) below and above 2600 rpm among the speeds without back strikes (as "
            "`jaxgear figures` places A-E); largest DTE: over every speed. Wall time: the sweep "
            "with compilation / compiled (a second sweep, speeds shifted by 1e-3 rpm).",
            "",
            "| ζ | status 6 | back strikes (rpm) | largest back share | largest back loss (W) | "
            "resonance peak low: rpm (µm) | resonance peak high: rpm (µm) | largest DTE: rpm "
            "(µm) | failed | wall time, s |",
            "|---|---|---|---|---|---|---|---|---|---|",
            *rows,
            "",
            "Φ̄ (W) tribo-dynamic at the points' nominal speeds, against the quasi-static loss, "
            "and the power the mesh damper dissipates there (`SimulationResult."
            "mesh_damping_power`, not part of Φ̄; ‡: over the attractor):",
            "",
            "| ζ | " + " | ".join(f"{k} {v:.0f} rpm" for k, v in POINTS.items()) + " |",
            "|---|" + "---|" * len(POINTS),
            f"| quasi-static | {qs_cells} |",
            *point_rows,
        ]
    )
    write_section("mesh_damping", body, README)
    print(body)


if __name__ == "__main__":
    main()
