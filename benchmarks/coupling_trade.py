"""The coupling axis measured: ``Fidelity.coupling = "frozen"`` against the full fixed point.

For the quick scenario set of ``fidelity_trade`` (the baseline at 1750, 2500 and 3300 rpm, 60 °C,
1500 N m, polished), the tribo-dynamic statistical-mixed transient rungs (iso-thermal and thermal)
at the coarse and default resolution levels, each with both couplings: Φ̄ and DTE RMS against the
paper-fidelity reference of ``jaxgear/data/fidelity_errors.json`` (the table ``Fidelity.auto``
reads, measured by ``fidelity_trade``), and the time per point (compile and run separately: the
first call compiles, the run time is the median of the next ``--repeats`` calls).

Writes the section ``coupling_trade`` of benchmarks/RESULTS.md.

Run (from the repository root; about 20 minutes on 2 cores, mostly compiling):
    PYTHONPATH=benchmarks python benchmarks/coupling_trade.py
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import equinox as eqx  # noqa: E402
from _report import machine, write_section  # noqa: E402
from fidelity_trade import LEVELS, SCENARIOS  # noqa: E402

import jaxgear as jg  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TABLE = ROOT / "jaxgear" / "data" / "fidelity_errors.json"
SIM = eqx.filter_jit(jg.simulate)


def _run(fid, scenario, pair, repeats):
    args = scenario.inputs(pair)
    t0 = time.perf_counter()
    res = jax.block_until_ready(SIM(*args, fid))
    first = time.perf_counter() - t0
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = jax.block_until_ready(SIM(*args, fid))
        runs.append(time.perf_counter() - t0)
    return res, first, statistics.median(runs)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=2, help="timed runs per point after the first")
    ap.add_argument("--dry", action="store_true", help="print, do not write RESULTS.md")
    args = ap.parse_args()

    table = json.loads(TABLE.read_text())
    pair = jg.presets.li2015_pair_calibrated()
    scenarios = [s for s in SCENARIOS if s.quick]
    reference = {s.name: table["scenarios"][s.name]["reference_result"] for s in scenarios}
    rows = []
    for level in ("coarse", "default"):
        for thermal in (False, True):
            for coupling in ("frozen", "fixed_point"):
                fid = jg.Fidelity(
                    dynamics="tribo_dynamic",
                    friction="ehl_mixed",
                    thermal=thermal,
                    transient=True,
                    coupling=coupling,
                    **LEVELS[level],
                )
                label = f"{'thermal' if thermal else 'iso'}/{coupling}@{level}"
                per = {}
                compile_s = None
                for s in scenarios:
                    res, first, run = _run(fid, s, pair, args.repeats)
                    if compile_s is None:
                        compile_s = first - run
                    ref = reference[s.name]
                    per[s.name] = {
                        "power_loss": float(res.power_loss),
                        "err": float(res.power_loss) / ref["power_loss"] - 1.0,
                        "dte_err": float(res.dte_rms) / ref["dte_rms"] - 1.0,
                        "status": int(res.status),
                        "iterations": int(res.fixed_point_iterations),
                        "run_s": run,
                    }
                    print(label, s.name, per[s.name], flush=True)
                rows.append((label, level, thermal, coupling, compile_s, per))

    names = [s.name for s in scenarios]
    base = [n for n in names if n.startswith("base_")]
    ref_run = {n: reference[n]["run_s"] for n in names}
    lines = [
        "## Coupling: frozen contacts against the full fixed point (`benchmarks/coupling_trade.py`)",
        "",
        f"Machine: {machine()}. Tribo-dynamic, statistical mixed EHL, transient, on the calibrated "
        "pair; levels as in fidelity_trade (coarse 24 positions × 65 nodes × 32 steps, default "
        "32 × 129 × 64). Reference: Fidelity.paper() (32 × 257, thermal), its Φ̄, DTE RMS and run "
        "time per point from jaxgear/data/fidelity_errors.json (fidelity_trade's run, same machine "
        "type). `frozen` solves the contacts once at the quasi-static state, with their load "
        "derivative, and scales them to the dynamic loads and velocities (Fidelity.coupling); "
        "`fixed_point` solves them again in every fixed-point iteration.",
        "",
        "| rung | Φ̄ error % per scenario (" + ", ".join(names) + ") | max | max on the baseline "
        "| DTE err % max | run s/point (median) | cheaper than paper (baseline) | compile s | "
        "status ≠ 0 |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for label, _, _, _, compile_s, per in rows:
        errs = [100 * per[n]["err"] for n in names]
        base_err = max(abs(100 * per[n]["err"]) for n in base)
        dte = max(abs(100 * per[n]["dte_err"]) for n in names)
        run = statistics.median(per[n]["run_s"] for n in names)
        ratio = statistics.mean(ref_run[n] / per[n]["run_s"] for n in base)
        bad = [n for n in names if per[n]["status"] != 0]
        lines.append(
            f"| {label} | {' / '.join(f'{e:+.1f}' for e in errs)} | "
            f"{max(abs(e) for e in errs):.1f} | {base_err:.1f} | {dte:.2f} | {run:.3g} | "
            f"{ratio:.0f}× | {compile_s:.0f} | {', '.join(bad) or '–'} |"
        )
    lines += [
        "",
        "Signed errors (+: above the paper fidelity). 'cheaper than paper': the mean over the "
        "baseline scenarios of the reference's run time over the rung's (the issue's Reach for "
        "`Fidelity.fast()`: within 15 % on the baseline and ≥ 50× cheaper).",
    ]
    text = "\n".join(lines)
    print(text)
    if not args.dry:
        write_section("coupling_trade", text)


if __name__ == "__main__":
    main()
