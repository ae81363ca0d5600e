"""Compile and run time of ``mesh_cycle`` at M = 64 and 256 positions (issue 2 target: run < 5 ms at
M = 256 on a 2-core CPU). Run: ``python benchmarks/mesh.py``; writes its section of RESULTS.md."""

from __future__ import annotations

import jax

jax.config.update("jax_enable_x64", True)

from _report import machine, time_call, write_section  # noqa: E402

import jaxgear as jg  # noqa: E402


def main() -> None:
    pair = jg.presets.li2015_pair()
    rows = []
    for method in ("potential_energy", "iso"):
        for m in (64, 256):
            fn = lambda torque, m=m, method=method: jg.mesh_cycle(pair, torque, m, stiffness=method)
            first, run = time_call(fn, 700.0)
            # A new torque value must not recompile (traced field): time it as a run.
            _, run_new = time_call(fn, 1500.0, repeats=5)
            rows.append((method, m, first, run, run_new))
            print(
                f"{method:17s} M={m:4d} compile+first {first:6.2f} s  run {run * 1e3:7.2f} ms"
                f"  (new torque {run_new * 1e3:6.2f} ms)"
            )
    lines = [
        "## Mesh cycle (`benchmarks/mesh.py`)",
        "",
        f"Machine: {machine()}.",
        "",
        "| stiffness | M | compile + first call (s) | run, median of 20 (ms) | run with a new torque (ms) |",
        "|---|---|---|---|---|",
    ]
    for method, m, first, run, run_new in rows:
        lines.append(f"| {method} | {m} | {first:.2f} | {run * 1e3:.2f} | {run_new * 1e3:.2f} |")
    lines += [
        "",
        "Target: run < 5 ms at M = 256. The run time includes the Python-side input validation of",
        "`mesh_cycle` (a few µs) and the dispatch of the jitted core; a new torque does not recompile.",
    ]
    write_section("mesh", "\n".join(lines))


if __name__ == "__main__":
    main()
