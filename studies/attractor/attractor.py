"""Speeds without a stable periodic orbit: what the attractor changes and what it costs.

The calibrated pair (no LOA mesh damping, REFERENCE §1) has parametric instability bands where the
period-1 orbit that the shooting finds is unstable. There the coupled model now reports means over
the attractor the gears settle on (``Fidelity.attractor_periods``, status 6). This benchmark:

1. Dynamics only (frictionless, undamped mesh, 32 positions): at one speed per band, the largest
   Floquet multiplier of the unstable orbit, the attractor's period (0: none found), its contact
   loss, DTE (mesh harmonics and total), the moment-balance check (mean mesh force against T1/rb1,
   exact in the long-time limit), and the cost of one attractor (compile and run separately).
2. The baseline sweep at ``Fidelity.fast()`` (continuation, 500-4200 rpm, ``--step`` rpm) with the
   attractor on and off: the speeds that change, Φ̄ and DTE RMS on and off there, and the wall time
   of each sweep (compiled: run cost; first: with compilation).

Writes the section ``attractor`` of studies/attractor/README.md. Run (repository root):
    python studies/attractor/attractor.py [--step 25]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
README = Path(__file__).with_name("README.md")  # this study's sections
sys.path.insert(0, str(ROOT / "benchmarks"))  # _report

from _report import machine, time_call, write_section  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.dynamics import DynamicsOptions, attractor_response, dynamic_response  # noqa: E402

PAIR = jg.presets.li2015_pair_calibrated()
BANDS = (800.0, 1950.0, 3450.0, 3750.0, 3900.0)


def _dynamics_rows():
    opts = DynamicsOptions(n_positions=32)
    mesh = jg.mesh_cycle(PAIR, torque=700.0, n_positions=32)
    target = float(mesh.total_load)
    rows, cost = [], None
    for rpm in BANDS:
        op = jg.OperatingPoint(torque=700.0, speed_rpm=rpm)
        orbit = dynamic_response(PAIR, op, mesh=mesh, options=opts)

        def run(state, op=op):
            return attractor_response(
                PAIR, op, mesh=mesh, options=opts, initial_state=state
            ).dte_rms

        if cost is None:
            cost = time_call(run, orbit.initial_state, repeats=3)
        att = attractor_response(
            PAIR, op, mesh=mesh, options=opts, initial_state=orbit.initial_state
        )
        rows.append(
            f"| {rpm:.0f} | {int(orbit.status)} | {float(orbit.floquet_multiplier):.4f} | "
            f"{int(att.period)} | {float(att.contact_loss):.2f} | "
            f"{float(np.mean(np.asarray(att.mesh_force) < 0.0)):.2f} | "
            f"{1e6 * float(orbit.dte_rms):.1f} → {1e6 * float(att.dte_rms):.1f} | "
            f"{1e6 * float(att.dte_rms_total):.1f} | "
            f"{100 * (float(np.mean(att.mesh_force)) / target - 1):+.2f} % |"
        )
    return rows, cost


def _sweep(fid, speeds):
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    op = jg.OperatingPoint(torque=700.0, speed_rpm=500.0, inlet_temperature=363.15)
    t0 = time.perf_counter()
    res = jg.sweep(PAIR, lub, surf, op, speeds_rpm=speeds, fidelity=fid, mode="continuation")
    return res, time.perf_counter() - t0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--step", type=float, default=25.0, help="speed step of the sweep, rpm")
    args = ap.parse_args(argv)
    rows, (first, run) = _dynamics_rows()
    speeds = np.arange(500.0, 4200.0 + 1e-9, args.step)
    sweeps = {}
    for name, fid in (("on", jg.Fidelity.fast()), ("off", jg.Fidelity.fast(attractor_periods=0))):
        res, wall = _sweep(fid, speeds)
        _, again = _sweep(fid, speeds + 1e-3)
        sweeps[name] = (res, wall, again)
    on, off = sweeps["on"][0], sweeps["off"][0]
    # the back flanks with the drive side's km(t) at the same instant (the single backlash
    # function, the model before 2026-11-29): what the mirrored back mesh changes
    same, _ = _sweep(jg.Fidelity.fast(back_flank="same"), speeds)
    changed = np.asarray(on.status) == 6
    table = []
    for i in np.flatnonzero(changed):
        table.append(
            f"| {speeds[i]:.0f} | {float(off.power_loss[i]):.1f} → {float(on.power_loss[i]):.1f} | "
            f"{100 * (float(on.power_loss[i]) / float(off.power_loss[i]) - 1):+.1f} % | "
            f"{1e6 * float(off.dte_rms[i]):.1f} → {1e6 * float(on.dte_rms[i]):.1f} | "
            f"{float(on.back_contact_share[i]):.2f} | {float(on.power_loss_back[i]):.1f} | "
            f"{float(same.power_loss[i]):.1f} ({float(same.back_contact_share[i]):.2f}, "
            f"{float(same.power_loss_back[i]):.1f}) |"
        )
    n_att = int(changed.sum())
    extra = (sweeps["on"][2] - sweeps["off"][2]) / max(n_att, 1)
    body = "\n".join(
        [
            "## Speeds without a stable periodic orbit: the attractor (`attractor.py`)",
            "",
            f"Machine: {machine()}.",
            "",
            "Dynamics only (frictionless, undamped mesh, 32 positions; `attractor_response`, 2000 "
            "settling cycles, 256 recorded). Floquet: largest |multiplier| of the period-1 orbit; "
            "period 0: none up to 4 (a torus or a chaotic rattle); contact loss: share of the "
            "recorded samples with the drive flanks apart; back contact: the share with the back "
            "flanks striking (their own mesh stiffness and relief at the mirrored phase, "
            '`back_flank="mirrored"`); mean force: the record\'s mean mesh force '
            "against T1/rb1, which the moment balance makes exact in the long-time limit.",
            "",
            "| rpm | orbit status | Floquet | period | contact loss | back contact | DTE RMS orbit "
            "→ attractor (µm) | DTE total RMS (µm) | mean force − T1/rb1 |",
            "|---|---|---|---|---|---|---|---|---|",
            *rows,
            "",
            f"One attractor: {first:.1f} s with compilation, {run:.2f} s compiled.",
            "",
            f"Baseline sweep at `Fidelity.fast()`, continuation, {speeds[0]:.0f}-{speeds[-1]:.0f} "
            f"rpm every {args.step:g} rpm ({speeds.size} speeds): {n_att} speeds on an attractor "
            "(status 6; off: status 2, the unstable orbit). Wall time with compilation "
            f"{sweeps['on'][1]:.1f} s on, {sweeps['off'][1]:.1f} s off; compiled "
            f"{sweeps['on'][2]:.1f} s on, {sweeps['off'][2]:.1f} s off ({extra:.2f} s per "
            "attractor speed). Back contact: the share of the attractor's record with the back "
            "flanks striking (`back_contact_share`); back loss: their part of the attractor's Φ̄ "
            "(`power_loss_back`, counted since 2026-11-29). Last column: the attractor's Φ̄ "
            '(back contact, back loss) with `back_flank="same"`, the back flanks given the '
            "drive side's km(t) at the same instant (the single backlash function).",
            "",
            "| rpm | Φ̄ orbit → attractor (W) | change | DTE RMS orbit → attractor (µm) | "
            "back contact | back loss (W) | same: Φ̄ (back contact, back loss) |",
            "|---|---|---|---|---|---|---|",
            *table,
        ]
    )
    write_section("attractor", body, README)
    print(body)


if __name__ == "__main__":
    main()
