"""Calibration of the paper fidelity's open contact constants to the paper's quasi-static losses.

``jg.calibrate`` fits the Greenwood-Tripp density product nβσ (and, with ``--fit``, μb or σ/β) of
``Fidelity.paper(shear="eyring_split")`` (the contact that ``Fidelity.paper_calibrated()`` builds
on), quasi-static rung, to the paper's thermal quasi-static Φ̄ at points A, B, D, E (276, 302, 526,
532 W; REFERENCE §7 R2) at their nominal speeds (1700, 1800, 3400, 3500 rpm), the calibrated pair,
ground surfaces, 700 N m, 90 °C. It prints the fit (values, standard errors, residuals) and, with
``--checks``, what the fit leaves as a check: the quasi-static losses at A-E with the fitted
constants (C at 2600 rpm is not fitted; the paper gives no number there), on ``--check-nodes``
nodes (the grid's own effect when it differs from the fit's), and with ``--tribo-dynamic`` the
tribo-dynamic losses against the paper's 257, 343, 431, 948 W and its R3 ordering. Writes the section ``calibration`` of
benchmarks/RESULTS.md with the machine, the date and the wall times.

Run: ``python benchmarks/calibration.py [--nodes 257] [--fit asperity_density_product]
[--start 0.05] [--atol 1e-4] [--max-steps 12] [--checks [--check-nodes 257] [--tribo-dynamic]]``.
"""

from __future__ import annotations

import argparse
import os
import time

import jax

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402
from _report import machine, write_section  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.paper.reference import (  # noqa: E402
    NOMINAL_POINTS_RPM,
    PAPER_QUASI_STATIC_W,
    PAPER_TRIBO_DYNAMIC_W,
)

FITTED = ("A", "B", "D", "E")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, default=257, help="EHL nodes per contact (paper: 257)")
    ap.add_argument("--fit", default="asperity_density_product", help="comma-separated names")
    ap.add_argument("--start", type=float, default=None, help="start nβσ (default paper()'s)")
    ap.add_argument("--atol", type=float, default=1e-4, help="calibrate atol (Picard noise 1e-3)")
    ap.add_argument("--rtol", type=float, default=1e-4)
    ap.add_argument("--max-steps", type=int, default=12)
    ap.add_argument("--checks", action="store_true", help="quasi-static Φ̄ at A-E after the fit")
    ap.add_argument("--check-nodes", type=int, default=None, help="their nodes (default --nodes)")
    ap.add_argument("--tribo-dynamic", action="store_true", help="the checks' tribo-dynamic Φ̄ too")
    ap.add_argument("--no-write", action="store_true", help="print only")
    args = ap.parse_args(argv)

    pair = jg.presets.li2015_pair_calibrated()
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    base = jg.Fidelity.paper(shear="eyring_split", n_nodes=args.nodes)
    qs = base.replace(dynamics="quasi_static")
    names = tuple(n.strip() for n in args.fit.split(","))
    initial = {"asperity_density_product": args.start} if args.start is not None else None
    points = [
        jg.OperatingPoint(torque=700.0, speed_rpm=NOMINAL_POINTS_RPM[k], inlet_temperature=363.15)
        for k in FITTED
    ]
    measured = [PAPER_QUASI_STATIC_W[k] for k in FITTED]

    t0 = time.perf_counter()
    fit = jg.calibrate(
        pair, lub, surf, qs, points, measured, names, initial=initial,
        rtol=args.rtol, atol=args.atol, max_steps=args.max_steps,
    )  # fmt: skip
    wall = time.perf_counter() - t0
    se = fit.standard_errors
    lines = [
        "## Calibration: the paper fidelity's contact fitted to the paper's quasi-static losses "
        "(`benchmarks/calibration.py`)",
        "",
        f"Machine: {machine()}. `jg.calibrate` of {', '.join(names)} on "
        f'`Fidelity.paper(shear="eyring_split", n_nodes={args.nodes}, dynamics="quasi_static")`'
        f" (thermal, statistical mixed, transient; 32 positions), calibrated pair, ground, 700 N m, "
        f"90 °C, to the paper's quasi-static Φ̄ at A, B, D, E (nominal speeds); relative residuals, "
        f"unit weights, rtol {args.rtol:g}, atol {args.atol:g}. Wall time of the fit (compilation "
        f"included): {wall:.0f} s, {fit.steps} Levenberg-Marquardt steps; status {fit.status}: "
        f"{fit.message}. Load average (1 min) after the fit: {os.getloadavg()[0]:.1f} on "
        f"{os.cpu_count()} cores.",
        "",
        "| parameter | start | fitted | standard error |",
        "|---|---|---|---|",
    ]
    for j, name in enumerate(names):
        lines.append(f"| {name} | {fit.x_start[j]:.4g} | {fit.x[j]:.4g} | {se[name]:.2g} |")
    lines += [
        "",
        f"Standard errors: {fit.note}.",
        "",
        "| point | rpm | paper Φ̄ QS (W) | model at start (W) | model fitted (W) | residual |",
        "|---|---|---|---|---|---|",
    ]
    start_loss = np.asarray(measured) * (1.0 + fit.residuals_start / fit.weights)
    for i, k in enumerate(FITTED):
        lines.append(
            f"| {k} | {NOMINAL_POINTS_RPM[k]:.0f} | {measured[i]:.0f} | {start_loss[i]:.1f} | "
            f"{fit.model_power_loss[i]:.1f} | {fit.residuals[i]:+.3f} |"
        )
    print("\n".join(lines), flush=True)
    if args.checks and fit.status in (0, 9):
        nodes = args.check_nodes or args.nodes
        lines += ["", *_checks(pair, lub, surf, fit, nodes, args.tribo_dynamic)]
    if not args.no_write:
        write_section("calibration", "\n".join(lines))


def _checks(pair, lub, surf, fit, nodes: int, tribo_dynamic: bool) -> list[str]:
    """What the fit leaves as a check: the quasi-static Φ̄ at A-E with the fitted constants on
    ``nodes`` EHL nodes (C is not fitted, and a grid other than the fit's shows what the grid
    moves), and with ``tribo_dynamic`` the tribo-dynamic Φ̄ against the paper's (R2, R3)."""
    from jaxgear.paper.reference import PAPER_R3

    qs_fid = fit.fidelity.replace(n_nodes=nodes)
    td_fid = qs_fid.replace(dynamics="tribo_dynamic")
    rows = [
        f"Checks (not fitted): the fitted constants on {nodes} nodes per contact; time: the "
        "point's simulations, the first row with compilation.",
        "",
        "| point | rpm | Φ̄ QS (W) | paper QS | QS/paper | Φ̄ TD (W) | paper TD | TD vs QS | "
        "paper (R3) | status | time (s) |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for k in ("A", "B", "C", "D", "E"):
        op = jg.OperatingPoint(
            torque=700.0, speed_rpm=NOMINAL_POINTS_RPM[k], inlet_temperature=363.15
        )
        t0 = time.perf_counter()
        qs = jg.simulate(pair, lub, surf, op, fidelity=qs_fid)
        b = float(qs.power_loss)
        paper_qs = PAPER_QUASI_STATIC_W.get(k)
        ratio = f"{b / paper_qs:.3f}" if paper_qs else "-"
        td_cells, status = "- | - | - | -", f"{int(qs.status)}"
        if tribo_dynamic:
            td = jg.simulate(pair, lub, surf, op, fidelity=td_fid)
            a = float(td.power_loss)
            rel = (a - b) / b
            word = "nearly equal" if abs(rel) < 0.03 else ("higher" if rel > 0 else "lower")
            td_cells = (
                f"{a:.1f} | {PAPER_TRIBO_DYNAMIC_W.get(k, '-')} | {word} ({100 * rel:+.1f} %) | "
                f"{PAPER_R3[k]}"
            )
            status += f", {int(td.status)}"
        dt = time.perf_counter() - t0
        rows.append(
            f"| {k} | {NOMINAL_POINTS_RPM[k]:.0f} | {b:.1f} | {paper_qs or '-'} | {ratio} | "
            f"{td_cells} | {status} | {dt:.0f} |"
        )
        print(rows[-1], flush=True)
    return rows


if __name__ == "__main__":
    main()
