"""The coupled model on whatever JAX backend is present (CPU here, a GPU where one is lent).

Times, compile and run apart (compile = first call − second call, the second on speeds shifted by
0.001 rpm so nothing is cached by value), medians not needed at these run lengths:

1. the paper's baseline sweep (500-4200 rpm, 25 rpm: 149 speeds) at ``Fidelity.fast()``, in
   ``mode="parallel"`` (one vmapped batch) and ``mode="continuation"`` (``lax.scan``);
2. one speed (C, 2500 rpm) at ``Fidelity.paper()`` with ``simulate`` (``--paper``).

It also writes every Φ̄ of the parallel sweep to ``--out`` (JSON), so the values on one backend can be
compared with another's (``--compare FILE``: largest relative difference of Φ̄ over the speeds both
runs converged).

Run (repository root): ``python benchmarks/accelerator.py --out acc.json [--paper] [--compare F]``;
``--report A.json [B.json]`` builds the section from one or two runs' files without running. Prints a markdown
section; ``--section`` also writes it to benchmarks/RESULTS.md as ``accelerator``.
"""

from __future__ import annotations

import argparse
import json
import time

import jax

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402
from _report import machine, write_section  # noqa: E402

import jaxgear as jg  # noqa: E402

PAIR = jg.presets.li2015_pair_calibrated()
LUB, SURF = jg.presets.mil_l_23699(), jg.presets.ground()


def _op(rpm):
    return jg.OperatingPoint(torque=700.0, speed_rpm=rpm, inlet_temperature=363.15)


def _timed(fn, *args):
    t0 = time.perf_counter()
    out = fn(*args)
    jax.block_until_ready(out)
    return out, time.perf_counter() - t0


def _sweep(mode, speeds):
    res = jg.sweep(
        PAIR, LUB, SURF, _op(500.0), speeds_rpm=speeds, fidelity=jg.Fidelity.fast(), mode=mode
    )
    return res, res.power_loss


def _ehl_rows():
    """The EHL kernel alone: one cold high-load solve on 1025 nodes (M ≈ 250, the issue-3 Reach
    case) and a vmapped batch of 64 cold solves on 257 nodes (the contacts of a mesh cycle), as in
    benchmarks/ehl_kernel.py; compile = first − median of 3 runs."""
    import sys
    from pathlib import Path

    import equinox as eqx
    import jax.numpy as jnp

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from helpers import gear_contact

    def timed(fn, *args):
        t0 = time.perf_counter()
        out = jax.block_until_ready(fn(*args))
        first = time.perf_counter() - t0
        runs = []
        for _ in range(3):
            t0 = time.perf_counter()
            jax.block_until_ready(fn(*args))
            runs.append(time.perf_counter() - t0)
        run = float(np.median(runs))
        return out, max(first - run, 0.0), run

    rows = []
    heavy = gear_contact(1500.0, 190.0, 0.3)
    model = jg.EHLModel(n_nodes=1025)
    sol, c, r = timed(eqx.filter_jit(lambda x: jg.solve_ehl(x, LUB, model)), heavy)
    print("ehl 1025", c, r, bool(sol.converged), flush=True)
    rows.append(
        f"| solve_ehl, high load (M ≈ 250), cold | 1 | {c:.1f} | {r:.3f} | {r * 1e3:.0f} | "
        f"converged {bool(sol.converged)} |"
    )
    base = gear_contact(700.0, 2000.0, 0.3)
    k = jnp.linspace(0.0, 1.0, 64)
    scale = dict(load_per_width=0.8 + 0.4 * k, reduced_radius=0.8 + 0.4 * k)
    fields = ("reduced_radius", "load_per_width", "u1", "u2", "e_reduced", "inlet_temperature")
    batch = jg.LineContact(
        **{f: jnp.broadcast_to(getattr(base, f), (64,)) * scale.get(f, 1.0) for f in fields}
    )
    model = jg.EHLModel(n_nodes=257)
    sols, c, r = timed(eqx.filter_jit(jax.vmap(lambda x: jg.solve_ehl(x, LUB, model))), batch)
    ok = int(np.sum(np.asarray(sols.converged)))
    print("ehl batch", c, r, ok, flush=True)
    rows.append(
        f"| solve_ehl, vmapped batch of 64, 257 nodes, cold | 64 | {c:.1f} | {r:.3f} | "
        f"{r / 64 * 1e3:.1f} | {ok} / 0 / {64 - ok} |"
    )
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="JSON file for the parallel sweep's Φ̄ and the timings")
    ap.add_argument("--paper", action="store_true", help="also one speed at Fidelity.paper()")
    ap.add_argument("--ehl", action="store_true", help="also the EHL kernel (solve_ehl) alone")
    ap.add_argument("--skip-sweeps", action="store_true", help="no fast() sweeps")
    ap.add_argument(
        "--modes",
        default="parallel,continuation",
        help="comma-separated sweep modes to time, in this order",
    )
    ap.add_argument("--compare", help="JSON from another backend's run: Φ̄ differences")
    ap.add_argument("--speeds", type=int, default=None, help="first N baseline speeds")
    ap.add_argument("--step", type=float, default=25.0, help="speed step of the sweep, rpm")
    ap.add_argument(
        "--exclude-rpm",
        nargs="+",
        default=[],
        metavar="LO:HI",
        help="leave out the speeds in these ranges (rpm, inclusive), e.g. the attractor bands",
    )
    ap.add_argument("--section", action="store_true", help="write the RESULTS.md section")
    ap.add_argument("--note", default="", help="a paragraph appended to the section")
    ap.add_argument(
        "--report",
        nargs="+",
        metavar="JSON",
        help="no run: the section from one or two --out files",
    )
    args = ap.parse_args(argv)
    if args.report:
        recs = []
        for name in args.report:
            with open(name) as f:
                recs.append(json.load(f))
        text = report(*recs) + (f"\n\n{args.note}" if args.note else "")
        print(text)
        if args.section:
            write_section("accelerator", text)
        return
    speeds = np.arange(500.0, 4200.0 + 1e-9, args.step)[: args.speeds]
    for band in args.exclude_rpm:
        lo, hi = (float(v) for v in band.split(":"))
        speeds = speeds[(speeds < lo) | (speeds > hi)]
    dev = jax.devices()[0]
    print("backend", jax.default_backend(), dev.device_kind, flush=True)

    rows = []
    record = {
        "backend": jax.default_backend(),
        "device": dev.device_kind,
        "machine": f"{machine()} ({dev.device_kind})",
        "rows": rows,
    }

    def save():  # after every row, so a run cut short keeps what it measured
        if args.out:
            with open(args.out, "w") as f:
                json.dump(record, f)

    for mode in () if args.skip_sweeps else args.modes.split(","):
        (res, _), first = _timed(lambda s, m=mode: _sweep(m, s), speeds)
        # printed and saved before the second call: a run cut off there keeps the first call
        print(mode, "first call (compile + run)", f"{first:.1f}", flush=True)
        record[f"{mode}_first_call_s"] = first
        save()
        (_, _), again = _timed(lambda s, m=mode: _sweep(m, s), speeds + 1e-3)
        counts = (
            int(np.sum(res.converged)),
            int(np.sum(res.on_attractor)),
            int(np.sum(res.failed)),
        )
        print(mode, f"{first:.1f}", f"{again:.2f}", counts, flush=True)
        rows.append(
            f"| fast() sweep, {mode} | {len(speeds)} | {max(first - again, 0.0):.1f} | {again:.2f} | "
            f"{again / len(speeds) * 1e3:.1f} | {counts[0]} / {counts[1]} / {counts[2]} |"
        )
        if mode == "parallel":
            record["power_loss"] = [float(x) for x in np.asarray(res.power_loss)]
            record["status"] = [int(x) for x in np.asarray(res.status)]
        save()
    if args.paper:
        fid = jg.Fidelity.paper()
        r, first = _timed(lambda: jg.simulate(PAIR, LUB, SURF, _op(2500.0), fid))
        print("paper C first call (compile + run)", f"{first:.1f}", flush=True)
        record["paper_first_call_s"] = first
        save()
        r2, again = _timed(lambda: jg.simulate(PAIR, LUB, SURF, _op(2510.0), fid))
        print(
            "paper C",
            f"{first:.1f}",
            f"{again:.2f}",
            float(r.power_loss),
            int(r.status),
            flush=True,
        )
        rows.append(
            f"| paper() one speed (2500 rpm) | 1 | {max(first - again, 0.0):.1f} | {again:.2f} | "
            f"{again * 1e3:.0f} | Φ̄ {float(r.power_loss):.2f} W, status {int(r.status)} |"
        )
        record["paper_2500"] = float(r.power_loss)
        save()
    if args.ehl:
        rows += _ehl_rows()
        save()
    other = None
    if args.compare:
        with open(args.compare) as f:
            other = json.load(f)
    text = report(record, other) + (f"\n\n{args.note}" if args.note else "")
    print(text)
    if args.section:
        write_section("accelerator", text)


def report(record, other=None) -> str:
    """The markdown section: ``record``'s table (and ``other``'s), and Φ̄ differences between them."""
    lines = [
        "## Accelerators: the fast() sweep and the EHL kernel on a GPU and on the CPU "
        "(`benchmarks/accelerator.py`)",
        "",
        "Sweeps: baseline speeds 500-4200 rpm every 25 rpm, calibrated pair, ground, 700 N m, "
        "90 °C; compile = first call − a later call (the sweeps: one call on speeds shifted by "
        "0.001 rpm; the EHL kernel: the median of 3).",
    ]
    for rec in (record, other) if other else (record,):
        lines += [
            "",
            f"{rec['machine']}:",
            "",
            "| what | points | compile (s) | run (s) | run per point (ms) | ok / attractor / failed |",
            "|---|---|---|---|---|---|",
            *rec["rows"],
        ]
    if other and "power_loss" in record and "power_loss" in other:
        a, b = np.asarray(record["power_loss"]), np.asarray(other["power_loss"])
        both = (np.asarray(record["status"]) == 0) & (np.asarray(other["status"]) == 0)
        rel = np.abs(a[both] / b[both] - 1.0)
        same_status = int(np.sum(np.asarray(record["status"]) == np.asarray(other["status"])))
        lines += [
            "",
            f"Against {other['backend']} ({other['device']}): Φ̄ of the parallel sweep differs by at "
            f"most {np.max(rel):.1e} relative over the {int(np.sum(both))} speeds both converged; "
            f"the status agrees at {same_status} of {len(a)} speeds.",
        ]
        if "paper_2500" in record and "paper_2500" in other:
            d = record["paper_2500"] / other["paper_2500"] - 1.0
            lines.append(f"paper() at 2500 rpm: Φ̄ differs by {d:+.1e} relative.")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
