"""What a sensitivity report costs against one forward simulation.

At ``Fidelity.fast()`` on the calibrated pair (Mil-L-23699, ground surfaces, 700 N m, 2500 rpm,
90 °C inlet), each in a fresh process with the on-disk compilation cache off:

- ``simulate``: the first-pass program ``jg.simulate`` compiles for a point that needs no second
  pass (tracing and lowering, XLA compilation and the run, median of 5, apart), and, for
  reference, ``jax.jit`` of ``simulate`` on traced inputs (both passes), with the report's three
  outputs (efficiency, power loss, DTE RMS);
- ``grad``: one reverse pass, ``jax.value_and_grad`` of the efficiency alone with respect to the
  same inputs: what any reverse-mode derivative costs, the same four figures;
- the sensitivity report's program for three outputs (efficiency, power loss, DTE RMS): one
  forward solve and three reverse passes (``design.sensitivity._values_and_derivatives``, the
  program ``jg.sensitivity`` compiles), the same four figures; and, end to end in one process,
  ``jg.simulate`` cold, then ``jg.sensitivity`` cold (its checks, compilation and run);
- with ``--vmap``, the same report with its reverse passes vmapped over the unit cotangents instead
  of looped (``lax.map``), for comparison.

The issue's target: report ≤ 3 × (one forward run plus its compilation). Prints a markdown table
with the machine, the date and the load average; does not write RESULTS.md. Run from the
repository root: ``python benchmarks/sensitivity_cost.py [--vmap] [--fidelity quasi_static]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

PROBE = r"""
import json, statistics, sys, time
import jax
jax.config.update("jax_enable_x64", True)
import equinox as eqx
import jax.numpy as jnp
import jaxgear as jg
import jaxgear.design.sensitivity as sens
import jaxgear.tribodynamics.passes as passes
from jaxgear.tribodynamics import first_pass

what, fidelity_name = sys.argv[1], sys.argv[2]
pair = jg.presets.li2015_pair_calibrated()
lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
op = jg.OperatingPoint(torque=700.0, speed_rpm=2500.0, inlet_temperature=363.15)
fid = jg.Fidelity.fast()
if fidelity_name == "quasi_static":
    fid = fid.replace(dynamics="quasi_static")
outputs = ("efficiency", "power_loss", "dte_rms")


def stages(fn, *args, static_argnums=()):
    t0 = time.perf_counter()
    lowered = jax.jit(fn, static_argnums=static_argnums).trace(*args).lower()
    t1 = time.perf_counter()
    compiled = lowered.compile()
    t2 = time.perf_counter()
    dynamic = [a for i, a in enumerate(args) if i not in static_argnums]
    jax.block_until_ready(compiled(*dynamic))
    runs = []
    for _ in range(5):
        t = time.perf_counter()
        jax.block_until_ready(compiled(*dynamic))
        runs.append(time.perf_counter() - t)
    return {"lower_s": t1 - t0, "compile_s": t2 - t1, "run_s": statistics.median(runs)}


def vmapped(params, rest, outputs):
    def forward(p):
        pair, lubricant, surfaces, op, fidelity = eqx.combine(p, rest)
        result, _, _ = first_pass(pair, lubricant, surfaces, op, fidelity)
        return sens._outputs_of(result, pair, outputs)

    values, pullback = jax.vjp(forward, params)
    (d,) = jax.vmap(pullback)(jnp.eye(len(outputs), dtype=values.dtype))
    return values, d


params, rest = sens._differentiated((pair, lub, surf, op, fid))


def simulate_first_pass(params):
    # the program jg.simulate compiles for a point that needs no second pass
    return passes._first_pass_outputs(*eqx.combine(params, rest))


def simulate_both_passes(params):
    # what a caller's jit of simulate compiles (traced inputs: both passes)
    p, l, s, o, f = eqx.combine(params, rest)
    return sens._outputs_of(jg.simulate(p, l, s, o, fidelity=f), p, outputs)


def efficiency_first_pass(params):
    p, l, s, o, f = eqx.combine(params, rest)
    return first_pass(p, l, s, o, f)[0].efficiency


if what == "forward":
    out = stages(simulate_first_pass, params)
elif what == "forward_both":
    out = stages(simulate_both_passes, params)
elif what == "grad":
    out = stages(jax.value_and_grad(efficiency_first_pass), params)
elif what == "report":
    out = stages(sens._values_and_derivatives, params, rest, outputs, static_argnums=(2,))
elif what == "report_vmap":
    out = stages(vmapped, params, rest, outputs, static_argnums=(2,))
elif what == "public":
    t0 = time.perf_counter()
    jg.simulate(pair, lub, surf, op, fidelity=fid)
    t1 = time.perf_counter()
    report = jg.sensitivity(pair, lub, surf, op, fidelity=fid, outputs=outputs)
    t2 = time.perf_counter()
    runs = []
    for _ in range(5):
        t = time.perf_counter()
        jg.sensitivity(pair, lub, surf, op, fidelity=fid, outputs=outputs)
        runs.append(time.perf_counter() - t)
    out = {
        "simulate_first_call_s": t1 - t0,
        "first_call_s": t2 - t1,
        "run_s": statistics.median(runs),
        "status": report.status,
    }
print("RESULT " + json.dumps(out))
"""


def measure(what: str, fidelity: str) -> dict:
    env = {**os.environ, "JAXGEAR_CACHE_DIR": "off", "PYTHONPATH": str(ROOT)}
    proc = subprocess.run(
        [sys.executable, "-c", PROBE, what, fidelity],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    for line in proc.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[len("RESULT ") :])
    raise RuntimeError(f"{what} failed:\n{proc.stderr[-3000:]}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--vmap", action="store_true", help="also the vmapped reverse passes")
    parser.add_argument("--fidelity", choices=("fast", "quasi_static"), default="fast")
    args = parser.parse_args(argv)
    from benchmarks._report import machine

    load = os.getloadavg()
    keys = ("forward", "forward_both", "grad", "report")
    rows = {key: measure(key, args.fidelity) for key in keys}
    if args.vmap:
        rows["report_vmap"] = measure("report_vmap", args.fidelity)
    public = measure("public", args.fidelity)
    load_after = os.getloadavg()
    report = rows["report"]["lower_s"] + rows["report"]["compile_s"] + rows["report"]["run_s"]
    base = rows["forward"]["lower_s"] + rows["forward"]["compile_s"] + rows["forward"]["run_s"]
    print(f"Fidelity.{args.fidelity}, calibrated pair, 700 N m, 2500 rpm, 90 °C; {machine()}")
    print(
        f"load average before {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}, "
        f"after {load_after[0]:.2f} {load_after[1]:.2f} {load_after[2]:.2f}\n"
    )
    print(
        "| program | trace + lower, s | XLA compile, s | run, s (median of 5) | total / forward |"
    )
    print("|---|---:|---:|---:|---:|")
    labels = {
        "forward": "simulate (its first-pass program, as jg.simulate compiles it)",
        "forward_both": "simulate, both passes (as a caller's jit compiles it), 3 outputs",
        "grad": "value_and_grad of efficiency (1 reverse pass, first pass)",
        "report": "sensitivity program, 3 outputs (lax.map of 3 reverse passes)",
        "report_vmap": "sensitivity program, 3 outputs (vmap of 3 reverse passes)",
    }
    for key, row in rows.items():
        total = row["lower_s"] + row["compile_s"] + row["run_s"]
        print(
            f"| {labels[key]} | {row['lower_s']:.1f} | {row['compile_s']:.1f} | "
            f"{row['run_s']:.3f} | {total / base:.2f} |"
        )
    print(
        f"\nEnd to end in one fresh process: `jg.simulate` cold {public['simulate_first_call_s']:.1f} s; "
        f"then `jg.sensitivity` cold {public['first_call_s']:.1f} s "
        f"({public['first_call_s'] / public['simulate_first_call_s']:.2f} × the cold simulate), "
        f"warm {public['run_s']:.3f} s (status {public['status']})"
    )
    verdict = "met" if report <= 3.0 * base else "not met"
    print(f"Target, report <= 3 x (forward compile + run): {report / base:.2f} x, {verdict}.")


if __name__ == "__main__":
    main()
