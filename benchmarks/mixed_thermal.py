"""Benchmark of the thermal mixed EHL solve (issue 4): what each switch costs per contact, and the
transient passage per step and per engagement.

Contacts: the paper's pitch-point contact carrying the whole 700 N m load (ph ≈ 1.19 GPa), slide-to-roll
ratio 0.3, at 500 and 3500 rpm, ground surfaces. Compile (first call) and run (median of repeats)
are timed separately. Writes the ``mixed_thermal`` section of benchmarks/RESULTS.md.

Run: ``python benchmarks/mixed_thermal.py [--repeats 3] [--steps 40]``

``--passage-iterations``: where the deterministic passage spends its time: the Newton iterations
of each step (all attempts) with the warm-start budget of the default model (12) and with 60, at
500 and 3500 rpm on 257 nodes; writes the ``mixed_passage_iterations`` section.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1] / "tests"))

from _report import machine, time_call, write_section  # noqa: E402
from ehl_cases import gear_contact  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.lubrication.passage import grid_time_step, solve_ehl_passage  # noqa: E402

LUB = jg.presets.mil_l_23699()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--steps", type=int, default=40, help="passage steps timed")
    ap.add_argument("--nodes", type=int, nargs="+", default=[257, 513], help="grid sizes")
    ap.add_argument(
        "--passage-iterations",
        action="store_true",
        help="per-step Newton iterations of the deterministic passage",
    )
    args = ap.parse_args(argv)
    if args.passage_iterations:
        return passage_iterations(args.steps)
    surf = jg.presets.ground()
    rows = []
    cases = [
        ("smooth, iso-thermal", dict(), None),
        ("smooth, thermal", dict(thermal=True), None),
        ("statistical mixed, iso-thermal", dict(mixed="statistical"), surf),
        ("statistical mixed, thermal", dict(mixed="statistical", thermal=True), surf),
        ("deterministic mixed, iso-thermal", dict(mixed="deterministic"), surf),
    ]
    for n in args.nodes:
        for label, kw, s in cases:
            model = jg.EHLModel(n_nodes=n, **kw)
            for rpm in (500.0, 3500.0):
                c = gear_contact(rpm=rpm)
                fn = lambda c, model=model, s=s: jg.solve_ehl(c, LUB, model, s)  # noqa: E731
                first, run = time_call(fn, c, repeats=args.repeats)
                sol = fn(c)
                rows.append(
                    f"| {n} | {label} | {rpm:.0f} | {first:.1f} | {run * 1e3:.0f} | "
                    f"{bool(sol.converged)} | {int(sol.iterations)} | "
                    f"{float(sol.power_loss) * 0.02:.1f} | {float(sol.contact_load_share):.3f} |"
                )
                print(rows[-1], flush=True)
    # transient passage: per step, and extrapolated to one engagement (Δt = Δx/ur)
    prow = []
    for rpm in (500.0, 3500.0):
        for label, kw, s in cases[1:4:2] + cases[4:]:
            model = jg.EHLModel(n_nodes=257, **kw)
            c = gear_contact(rpm=rpm)
            dt = float(grid_time_step(c, LUB, model))
            k = args.steps
            contacts = jax.tree_util.tree_map(lambda a, k=k: jnp.full((k,), a), c)
            times = jnp.arange(k) * dt
            fn = lambda cs, t, model=model, s=s: solve_ehl_passage(  # noqa: E731
                cs, LUB, model, s, times=t
            )
            first, run = time_call(fn, contacts, times, repeats=1)
            # one engagement of the paper's pair: the roughness travels ~15 mm of surface
            steps_engagement = 15e-3 / (float(c.rolling_velocity) * dt)
            prow.append(
                f"| {label} | {rpm:.0f} | {first:.0f} | {run / k * 1e3:.0f} | "
                f"{steps_engagement:.0f} | {run / k * steps_engagement:.0f} |"
            )
            print(prow[-1], flush=True)
    body = "\n".join(
        [
            "## Thermal mixed EHL (issue 4)",
            "",
            f"Machine: {machine()}. Pitch-point contact, 700 N m, SRR 0.3, ground surfaces.",
            "Loss is per contact over the 20 mm face width.",
            "",
            "| nodes | model | rpm | compile+first, s | run, ms | converged | Newton its | "
            "loss, W | contact load share |",
            "|---|---|---|---|---|---|---|---|---|",
            *rows,
            "",
            f"Transient passage, 257 nodes, {args.steps} steps timed (Δt = Δx/ur); one engagement "
            "extrapolated to the ~15 mm of surface that passes the contact:",
            "",
            "| model | rpm | compile+first, s | per step, ms | steps per engagement | "
            "engagement, s |",
            "|---|---|---|---|---|---|",
            *prow,
        ]
    )
    write_section("mixed_thermal", body)


def passage_iterations(k):
    """Per-step Newton iterations of the deterministic transient passage (iso-thermal, 257 nodes,
    Δt = Δx/ur). The first step is a steady cold solve; every later one tries a warm start from the
    step before within ``warm_iterations`` and falls back to a cold solve (smooth film, then
    continuation in the roughness amplitude) when that fails. A warm start that converged would
    cost at most ``warm_iterations``; the excess over the budget is the cold fallback."""
    surf = jg.presets.ground()
    rows = []
    for rpm in (500.0, 3500.0):
        for warm in (12, 60):
            model = jg.EHLModel(n_nodes=257, mixed="deterministic", warm_iterations=warm)
            c = gear_contact(rpm=rpm)
            dt = float(grid_time_step(c, LUB, model))
            contacts = jax.tree_util.tree_map(lambda a, k=k: jnp.full((k,), a), c)
            times = jnp.arange(k) * dt
            fn = lambda cs, t, model=model: solve_ehl_passage(  # noqa: E731
                cs, LUB, model, surf, times=t
            )
            first, run = time_call(fn, contacts, times, repeats=1)
            sols = fn(contacts, times)
            its = [int(i) for i in sols.iterations]
            later = its[1:]
            warm_ok = sum(i <= warm for i in later)
            rows.append(
                f"| {rpm:.0f} | {warm} | {k} | {run / k * 1e3:.0f} | {its[0]} | "
                f"{min(later)}-{max(later)} (median {sorted(later)[len(later) // 2]}) | "
                f"{warm_ok} of {len(later)} | {int(sum(bool(v) for v in sols.converged))} of {k} |"
            )
            print(rows[-1], flush=True)
    body = "\n".join(
        [
            "## Deterministic transient passage: where the steps go (`--passage-iterations`)",
            "",
            f"Machine: {machine()}. Pitch-point contact, 700 N m, SRR 0.3, ground, 257 nodes, "
            "iso-thermal, Δt = Δx/ur. Newton iterations per step, all attempts counted; a warm "
            "start converges within its budget or the step falls back to a cold solve.",
            "",
            "| rpm | warm budget | steps | per step, ms | first (steady, cold) | later steps | "
            "warm start enough | converged |",
            "|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("mixed_passage_iterations", body)


if __name__ == "__main__":
    main()
