"""``Fidelity.fast()`` against ``Fidelity.paper()`` over the paper's baseline sweep (issue 7's Reach).

Both fidelities sweep the baseline (calibrated pair, ground, 700 N m, 90 °C) from 500 to 4200 rpm in
continuation, as the paper's stepwise speed increase, at ``--step`` rpm (default 100: the paper
fidelity costs ~10-20 s a point on 2 cores). Per speed: Φ̄ of both, the relative error of fast(), the
status of both. Summary: max and median |error| over the speeds where both converged, and the same
over all speeds. Timing: wall time of each sweep including compilation, and of a second sweep of each (compiled):
the per-point run cost; beside it the cold single-point cost of the paper fidelity that
``fidelity_trade`` measured (``jaxgear/data/fidelity_errors.json``, reference run s/point).

Writes the section ``fast_vs_paper`` of benchmarks/RESULTS.md. Run (repository root):
    python benchmarks/fast_vs_paper.py [--step 100]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402
from _report import machine, write_section  # noqa: E402

import jaxgear as jg  # noqa: E402

TABLE = Path(__file__).resolve().parents[1] / "jaxgear" / "data" / "fidelity_errors.json"


def _sweep(fid, speeds):
    pair = jg.presets.li2015_pair_calibrated()
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    op = jg.OperatingPoint(torque=700.0, speed_rpm=500.0, inlet_temperature=363.15)
    t0 = time.perf_counter()
    res = jg.sweep(pair, lub, surf, op, speeds_rpm=speeds, fidelity=fid, mode="continuation")
    jax.block_until_ready(res.power_loss)
    return res, time.perf_counter() - t0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--step", type=float, default=100.0, help="speed step, rpm")
    args = ap.parse_args(argv)
    speeds = np.arange(500.0, 4200.0 + 1e-9, args.step)
    fast, fast_wall = _sweep(jg.Fidelity.fast(), speeds)
    _, fast_again = _sweep(jg.Fidelity.fast(), speeds + 1e-3)  # compiled: the run cost
    paper, paper_wall = _sweep(jg.Fidelity.paper(), speeds)
    _, paper_again = _sweep(jg.Fidelity.paper(), speeds + 1e-3)
    phi_f, phi_p = np.asarray(fast.power_loss), np.asarray(paper.power_loss)
    st_f, st_p = np.asarray(fast.status), np.asarray(paper.status)
    err = phi_f / phi_p - 1.0
    both = (st_f == 0) & (st_p == 0)
    table = json.loads(TABLE.read_text())
    single_point = table["reference"]["summary_run_s"]
    paper_point = paper_again / len(speeds)
    fast_point = fast_again / len(speeds)
    lines = [
        "## Fidelity.fast() against Fidelity.paper() over the baseline sweep "
        "(`benchmarks/fast_vs_paper.py`)",
        "",
        f"Machine: {machine()}. Calibrated pair, ground, 700 N m, 90 °C, 500-4200 rpm every "
        f"{args.step:g} rpm, continuation. fast(): {jg.Fidelity.fast().friction} friction, "
        f"tribo-dynamic, {jg.Fidelity.fast().n_positions} positions; paper(): thermal statistical "
        "mixed transient EHL, 32 positions × 257 nodes.",
        "",
        f"- |Φ̄ error| of fast() where both converged ({int(both.sum())} of {len(speeds)} speeds): "
        f"max {100 * np.max(np.abs(err[both])):.1f} %, median "
        f"{100 * np.median(np.abs(err[both])):.1f} %; over all speeds max "
        f"{100 * np.max(np.abs(err)):.1f} %.",
        f"- Sweep wall time with compilation: fast() {fast_wall:.0f} s, paper() {paper_wall:.0f} s "
        f"({paper_wall / len(speeds):.1f} s per point).",
        f"- Run cost per point in a compiled continuation sweep (a second sweep, speeds shifted "
        f"by 0.001 rpm): fast() {fast_point:.3f} s, paper() {paper_point:.2f} s: "
        f"{paper_point / fast_point:.0f}× cheaper. A single cold point of the paper fidelity costs "
        f"{single_point:.1f} s (fidelity_trade's reference, median over its scenarios; continuation "
        f"starts each speed from the last), {single_point / fast_point:.0f}× fast()'s sweep point; by "
        f"the first sweeps' walls, compilation included, {paper_wall / fast_wall:.0f}×.",
        "",
        "| rpm | Φ̄ fast (W) | Φ̄ paper (W) | error | status fast | status paper |",
        "|---|---|---|---|---|---|",
    ]
    for n, a, b, e, sa, sb in zip(speeds, phi_f, phi_p, err, st_f, st_p):
        lines.append(f"| {n:.0f} | {a:.1f} | {b:.1f} | {100 * e:+.1f} % | {sa} | {sb} |")
    lines += [
        "",
        "Status: 0 ok, 1 fixed point not converged, 2 periodic orbit not converged or unstable "
        "(the calibrated pair rattles), 3 a contact solve, 4 non-finite; flagged points are kept.",
    ]
    text = "\n".join(lines)
    write_section("fast_vs_paper", text)
    print(text)
    print(f"median fast error {statistics.median(np.abs(err).tolist()):.3f}")


if __name__ == "__main__":
    main()
