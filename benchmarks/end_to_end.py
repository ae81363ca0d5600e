"""The coupled model end to end (issue 6's Reach): what a user waits for.

1. ``jaxgear run`` (the README's run command: the baseline sweep, tribo-dynamic and quasi-static at
   ``Fidelity.fast()``, CSV, JSON and figures) from a cold start: a fresh process with the on-disk
   compilation cache off; then twice with a fresh cache (the first fills it, the second reads it).
2. The 149-speed baseline sweep (500-4200 rpm every 25 rpm, continuation) at ``Fidelity.fast()`` and
   ``Fidelity.paper()``: wall time with compilation, and the run cost from a second sweep of the
   compiled program (speeds shifted by 0.001 rpm); compile = first − second.
3. One speed at ``Fidelity.paper()`` (``simulate``): compile and run apart, at point C (2500 rpm, a
   stable orbit) and point E (3500 rpm, no stable periodic orbit: the attractor).
4. One gradient against one forward: ``jax.jacfwd`` of Ψ with respect to the tip relief amount and
   the torque (what ``optimise_tip_relief`` takes) against the forward ``simulate``, both compiled,
   at 2500 rpm, at ``Fidelity.fast()`` and ``Fidelity.paper()`` (smooth backlash, as the optimiser).

Targets (issue 6, this 2-core CPU): ``jaxgear run`` ≤ 90 s including compilation; one speed at the
paper fidelity ≤ 2 min; a gradient ≤ 4× the forward cost.

Writes the section ``end_to_end`` of benchmarks/RESULTS.md. Run (repository root), ~1 h:
    python benchmarks/end_to_end.py [--skip-paper-sweep] [--skip-paper-gradient] [--rows FILE]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402
from _report import ROWS_HELP, RowCache, machine, write_section  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.tribodynamics import STATUS_NAMES  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PAIR = jg.presets.li2015_pair_calibrated()
LUB, SURF = jg.presets.mil_l_23699(), jg.presets.ground()
SPEEDS = np.arange(500.0, 4200.0 + 1e-9, 25.0)


def _op(rpm, torque=700.0):
    return jg.OperatingPoint(torque=torque, speed_rpm=rpm, inlet_temperature=363.15)


def _jaxgear_run(cache: str) -> float:
    """Wall time of ``jaxgear run`` in a fresh process (``cache``: JAXGEAR_CACHE_DIR)."""
    exe = Path(sys.executable).with_name("jaxgear")
    with tempfile.TemporaryDirectory() as out:
        env = {**os.environ, "JAXGEAR_CACHE_DIR": cache, "MPLBACKEND": "Agg"}
        t0 = time.perf_counter()
        subprocess.run(
            [str(exe), "run", "--out", out], check=True, env=env, cwd=ROOT, capture_output=True
        )
        return time.perf_counter() - t0


def _sweep(fid, speeds):
    t0 = time.perf_counter()
    res = jg.sweep(
        PAIR, LUB, SURF, _op(500.0), speeds_rpm=speeds, fidelity=fid, mode="continuation"
    )
    jax.block_until_ready(res.power_loss)
    return res, time.perf_counter() - t0


def _sweep_row(name, fid):
    res, first = _sweep(fid, SPEEDS)
    _, again = _sweep(fid, SPEEDS + 1e-3)
    n = len(SPEEDS)
    counts = {
        "ok": int(np.sum(res.converged)),
        "attractor": int(np.sum(res.on_attractor)),
        "failed": int(np.sum(res.failed)),
    }
    print(name, f"{first:.1f}", f"{again:.1f}", counts, flush=True)
    return (
        f"| {name} | {n} | {first:.1f} | {max(first - again, 0.0):.1f} | {again:.1f} | "
        f"{again / n:.3f} | {counts['ok']} / {counts['attractor']} / {counts['failed']} |"
    )


def _one_speed_rows(fid):
    rows = []
    for name, rpm in (("C", 2500.0), ("E", 3500.0)):
        t0 = time.perf_counter()
        r = jg.simulate(PAIR, LUB, SURF, _op(rpm), fid)
        jax.block_until_ready(r.power_loss)
        first = time.perf_counter() - t0
        t0 = time.perf_counter()
        r2 = jg.simulate(PAIR, LUB, SURF, _op(rpm + 10.0), fid)
        jax.block_until_ready(r2.power_loss)
        run = time.perf_counter() - t0
        print(name, rpm, f"{first:.1f}", f"{run:.1f}", int(r.status), flush=True)
        rows.append(
            f"| {name} | {rpm:.0f} | {first:.1f} | {max(first - run, 0.0):.1f} | {run:.1f} | "
            f"{float(r.power_loss):.1f} | {int(r.status)} ({STATUS_NAMES[int(r.status)]}) |"
        )
    return rows


def _gradient_row(name, fid):
    """Forward and jacfwd of Ψ(relief amount, torque), both jitted; medians of 3 compiled calls."""
    fid = fid.replace(backlash="smooth")

    @jax.jit
    def efficiency(x):
        pair = jg.presets.li2015_pair_calibrated(tip_relief=x[0])
        return jg.simulate(pair, LUB, SURF, _op(2500.0, torque=x[1]), fid).efficiency

    grad = jax.jit(jax.jacfwd(efficiency))
    x0 = jnp.asarray([10e-6, 700.0])

    def timed(fn):
        t0 = time.perf_counter()
        jax.block_until_ready(fn(x0))
        first = time.perf_counter() - t0
        runs = []
        for k in range(3):
            x = x0 * (1.0 + 1e-3 * (k + 1))
            t0 = time.perf_counter()
            jax.block_until_ready(fn(x))
            runs.append(time.perf_counter() - t0)
        run = float(np.median(runs))
        return max(first - run, 0.0), run

    (cf, rf), (cg, rg) = timed(efficiency), timed(grad)
    print(name, f"forward {cf:.1f}+{rf:.3f}", f"grad {cg:.1f}+{rg:.3f}", flush=True)
    return f"| {name} | {cf:.1f} | {rf:.3f} | {cg:.1f} | {rg:.3f} | {rg / rf:.2f}× |"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--skip-paper-sweep", action="store_true", help="no 149-speed paper() sweep")
    ap.add_argument("--skip-paper-gradient", action="store_true", help="no paper() gradient")
    ap.add_argument("--rows", type=Path, help=ROWS_HELP)
    args = ap.parse_args(argv)
    row = RowCache(args.rows).get

    def runs():
        cold = _jaxgear_run("off")
        with tempfile.TemporaryDirectory() as cache:
            filling = _jaxgear_run(cache)
            cached = _jaxgear_run(cache)
        print("jaxgear run", f"{cold:.1f}", f"{filling:.1f}", f"{cached:.1f}", flush=True)
        return [cold, filling, cached]

    cold, filling, cached = row("jaxgear_run", runs)
    sweeps = [row("sweep fast()", lambda: _sweep_row("fast()", jg.Fidelity.fast()))]
    if not args.skip_paper_sweep:
        sweeps.append(row("sweep paper()", lambda: _sweep_row("paper()", jg.Fidelity.paper())))
    one = row("one speed paper()", lambda: _one_speed_rows(jg.Fidelity.paper()))
    grads = [row("gradient fast()", lambda: _gradient_row("fast()", jg.Fidelity.fast()))]
    if not args.skip_paper_gradient:
        grads.append(row("gradient paper()", lambda: _gradient_row("paper()", jg.Fidelity.paper())))

    body = "\n".join(
        [
            "## End to end: `jaxgear run`, sweeps, one paper-fidelity speed, gradients "
            "(`benchmarks/end_to_end.py`)",
            "",
            f"Machine: {machine()}. Calibrated pair, Mil-L-23699, ground, 700 N m, 90 °C.",
            "",
            f"- `jaxgear run` (149 speeds, tribo-dynamic and quasi-static at `Fidelity.fast()`, "
            f"CSV, JSON, 3 PNG), a fresh process each: cold (compilation cache off) "
            f"**{cold:.1f} s** (target ≤ 90 s); with an empty on-disk cache {filling:.1f} s, "
            f"then reading it {cached:.1f} s.",
            "",
            "Baseline sweep, continuation, 500-4200 rpm every 25 rpm. Compile = first sweep − "
            "second (the compiled program, speeds shifted by 0.001 rpm). Status: converged / "
            "attractor mean (no stable periodic orbit, status 6) / failed.",
            "",
            "| fidelity | speeds | first sweep (s) | compile (s) | run (s) | run per speed (s) "
            "| status ok / attractor / failed |",
            "|---|---|---|---|---|---|---|",
            *sweeps,
            "",
            "One speed at `Fidelity.paper()` (`simulate`, tribo-dynamic; run: a second call 10 rpm "
            "higher). Target: ≤ 2 min.",
            "",
            "| point | rpm | first call (s) | compile (s) | run (s) | Φ̄ (W) | status |",
            "|---|---|---|---|---|---|---|",
            *one,
            "",
            "Gradient: `jax.jacfwd` of Ψ with respect to (tip relief amount, torque) at 2500 rpm, "
            "against the forward `simulate` (smooth backlash, as the optimiser); compiled, median "
            "of 3. Target: ≤ 4×.",
            "",
            "| fidelity | forward compile (s) | forward run (s) | gradient compile (s) "
            "| gradient run (s) | ratio |",
            "|---|---|---|---|---|---|",
            *grads,
        ]
    )
    write_section("end_to_end", body)
    print(body)


if __name__ == "__main__":
    main()
