"""What the design tools cost a user at ``Fidelity.fast()`` (tribo-dynamic), each in a fresh process
with the compilation cache off, on the calibrated pair (ground, Mil-L-23699, 90 °C):

- a constrained tip relief optimisation over 1000, 2000 and 3000 rpm at 700 N m (mean efficiency,
  DTE RMS ≤ 1.5 µm at every speed), wall time including compilation;
- a 10-point Pareto front of efficiency against DTE RMS over the same duty cycle;
- a sensitivity report (efficiency, power loss, DTE RMS with respect to every input) at 2500 rpm,
  against one forward ``simulate`` (compile and run apart).

Writes the section ``optimisation`` of benchmarks/RESULTS.md. Run from the repository root on a quiet
machine (the load average is printed; on 2 cores another job doubles the times):
    python benchmarks/optimisation.py [--skip-pareto]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, write_section  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

COMMON = r"""
import json, math, time
import jax
jax.config.update("jax_enable_x64", True)
import numpy as np
import jaxgear as jg
pair = jg.presets.li2015_pair_calibrated()
lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
op = jg.OperatingPoint(torque=700.0, speed_rpm=2000.0, inlet_temperature=363.15)
fid = jg.Fidelity.fast()
"""

PROBES = {
    "optimise": COMMON
    + r"""
t0 = time.perf_counter()
r = jg.optimise_tip_relief(pair, lub, surf, op, speeds_rpm=[1000.0, 2000.0, 3000.0], fidelity=fid,
                           constraints={"dte_rms": 1.5e-6})
wall = time.perf_counter() - t0
print(json.dumps({"wall": wall, "status": r.message, "evaluations": r.evaluations,
                  "amount_um": float(r.x[0] * 1e6), "start_deg": math.degrees(r.x[1]),
                  "efficiency": r.objective_value, "efficiency_start": r.objective_start,
                  "dte_um": (np.asarray(r.values["dte_rms"]) * 1e6).tolist()}))
""",
    "pareto": COMMON
    + r"""
from jaxgear.design.pareto import pareto_front
t0 = time.perf_counter()
f = pareto_front(pair, lub, surf, op, speeds_rpm=[1000.0, 2000.0, 3000.0], fidelity=fid,
                 n_points=10)
wall = time.perf_counter() - t0
print(json.dumps({"wall": wall, "ok": int((f.status == 0).sum()), "efficient": int(f.efficient.sum()),
                  "evaluations": int(max(r.evaluations for r in f.results)),
                  "dte_um": (f.trade_values * 1e6).tolist(),
                  "efficiency": f.objective_values.tolist()}))
""",
    "sensitivity": COMMON
    + r"""
op = jg.OperatingPoint(torque=700.0, speed_rpm=2500.0, inlet_temperature=363.15)
from jaxgear.tribodynamics.passes import simulate_with_state
fwd = jax.jit(lambda p, o: simulate_with_state(p, lub, surf, o, fid)[0].efficiency)
t0 = time.perf_counter(); c = fwd.lower(pair, op).compile(); t1 = time.perf_counter()
jax.block_until_ready(c(pair, op)); t2 = time.perf_counter()
jax.block_until_ready(c(pair, op)); t3 = time.perf_counter()
rep = jg.sensitivity(pair, lub, surf, op, fidelity=fid)
t4 = time.perf_counter()
rep = jg.sensitivity(pair, lub, surf, op, fidelity=fid)
t5 = time.perf_counter()
print(json.dumps({"forward_compile": t1 - t0, "forward_first": t2 - t1, "forward_run": t3 - t2,
                  "report_first": t4 - t3, "report_again": t5 - t4, "rows": len(rep.table),
                  "status": rep.message}))
""",
}


def probe(name: str) -> dict:
    env = {**os.environ, "JAX_COMPILATION_CACHE_DIR": "", "PYTHONPATH": str(ROOT)}
    out = subprocess.run(
        [sys.executable, "-c", PROBES[name]], cwd=ROOT, env=env, capture_output=True, text=True
    )
    if out.returncode != 0:
        raise RuntimeError(f"{name} probe failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-pareto", action="store_true")
    parser.add_argument(
        "--only", choices=tuple(PROBES), default=None, help="one probe only (printed, not written)"
    )
    args = parser.parse_args()
    load = os.getloadavg()[0]
    if args.only:
        print(args.only, probe(args.only))
        return
    names = [n for n in PROBES if not (args.skip_pareto and n == "pareto")]
    got = {}
    for name in names:
        got[name] = probe(name)
        print(name, got[name], flush=True)
    lines = [
        f"Measured on {machine()}; compilation cache off, one process each; load average "
        f"{load:.1f} at the start.",
        "",
        "| task | wall, s (compile included) | target | details |",
        "|---|---|---|---|",
    ]
    o = got["optimise"]
    lines.append(
        f"| constrained tip relief, 3 speeds, DTE ≤ 1.5 µm | {o['wall']:.0f} | ≤ 120 | "
        f"{o['status']}; {o['evaluations']} evaluations; {o['amount_um']:.2f} µm from "
        f"{o['start_deg']:.2f}°; Ψ {100 * o['efficiency_start']:.4f} → "
        f"{100 * o['efficiency']:.4f} %; DTE {', '.join(f'{d:.2f}' for d in o['dte_um'])} µm |"
    )
    if "pareto" in got:
        p = got["pareto"]
        lines.append(
            f"| Pareto front, 10 points, efficiency against DTE RMS | {p['wall']:.0f} | ≤ 300 | "
            f"{p['ok']} converged, {p['efficient']} non-dominated; ≤ {p['evaluations']} "
            "evaluations per point |"
        )
    s = got["sensitivity"]
    budget = 3 * (s["forward_compile"] + s["forward_first"])
    lines.append(
        f"| sensitivity report, 3 outputs × {s['rows'] // 3} inputs | {s['report_first']:.0f} "
        f"(again {s['report_again']:.1f}) | ≤ 3 × ({s['forward_compile']:.0f} + "
        f"{s['forward_first']:.2f}) = {budget:.0f} | forward run {s['forward_run']:.2f} s |"
    )
    body = "\n".join(lines)
    write_section("optimisation", "## Design tools (`benchmarks/optimisation.py`)\n\n" + body)
    print(body)


if __name__ == "__main__":
    main()
