"""Benchmark of the thermal kernels: steady Jaeger surface temperature, one transient step, and the
contact temperature solve. Compile and run are timed separately (after ``block_until_ready``);
medians are written to benchmarks/RESULTS.md between the ``thermal`` markers.

Run: ``python benchmarks/thermal.py [--repeats 20]``
"""

from __future__ import annotations

import argparse
import datetime
import os
import pathlib
import platform
import statistics
import time

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.lubrication import thermal as th  # noqa: E402

RESULTS = pathlib.Path(__file__).with_name("RESULTS.md")
BEGIN, END = "<!-- BEGIN thermal -->", "<!-- END thermal -->"


def _time(fn, args, repeats):
    t0 = time.perf_counter()
    compiled = jax.jit(fn).lower(*args).compile()
    compile_s = time.perf_counter() - t0
    jax.block_until_ready(compiled(*args))  # warm-up
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        jax.block_until_ready(compiled(*args))
        runs.append(time.perf_counter() - t0)
    return compile_s, statistics.median(runs)


def _contact(n):
    b = 267e-6
    x = jnp.linspace(-4.5 * b, 1.5 * b, n)
    flux = 1e9 * jnp.sqrt(jnp.clip(1 - (x / b) ** 2, 0.0, None))
    return x, flux


def main(repeats: int) -> list[tuple[str, int, float, float]]:
    steel = jg.presets.steel()
    rows = []
    for n in (513, 1025, 2049):
        x, flux = _contact(n)
        rows.append(
            ("surface_temperature_rise (builds K)", n)
            + _time(lambda x, q: th.surface_temperature_rise(x, q, 4.0, steel), (x, flux), repeats)
        )
        dx = float(x[1] - x[0])
        rows.append(
            ("surface_temperature_rise_uniform (FFT)", n)
            + _time(
                lambda q, dx=dx: th.surface_temperature_rise_uniform(dx, q, 4.0, steel),
                (flux,),
                repeats,
            )
        )
        mats = th.moving_source_matrices(x)
        rows.append(
            ("surface_temperature_rise (given K)", n)
            + _time(
                lambda m, x, q: th.surface_temperature_rise(x, q, 4.0, steel, matrices=m),
                (mats, x, flux),
                repeats,
            )
        )
    for n in (513, 1025, 2049):
        x, flux = _contact(n)
        dx = float(x[1] - x[0])
        state = th.transient_init(n)
        rows.append(
            ("transient_step (48 depth nodes)", n)
            + _time(
                lambda s, q, dx=dx: th.transient_step(s, q, dx, 4.0, dx / 2.7, steel),
                (state, flux),
                repeats,
            )
        )
    for n in (513, 1025):
        x, flux = _contact(n)
        h = jnp.full_like(x, 0.3e-6)
        mats = th.moving_source_matrices(x)
        rows.append(
            ("solve_contact_temperatures (steady, convection, 12 it.)", n)
            + _time(
                lambda m, q, h, x=x: th.solve_contact_temperatures(
                    x, q, h, 4.5, 3.5, steel, steel, 1004.0, 2000.0, 0.15, matrices=m
                ),
                (mats, flux, h),
                max(3, repeats // 4),
            )
        )
    return rows


def write(rows, repeats):
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            names = [ln.split(":", 1)[1].strip() for ln in fh if ln.startswith("model name")]
            cpu = names[0] if names else cpu
    except OSError:
        pass
    date = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    lines = [
        BEGIN,
        "## Thermal kernels (`benchmarks/thermal.py`)",
        "",
        f"Machine: {cpu}, {os.cpu_count()} logical CPUs, {jax.devices()[0].platform}, "
        f"jax {jax.__version__}, float64. Date: {date}. Median of {repeats} runs "
        "(contact solve: fewer). The CPU was shared with other jobs while this ran, so run times "
        "are upper bounds.",
        "",
        "| kernel | nodes | compile (s) | run, median (ms) |",
        "|---|---:|---:|---:|",
    ]
    lines += [f"| {name} | {n} | {c:.2f} | {r * 1e3:.3f} |" for name, n, c, r in rows]
    lines += [END]
    section = "\n".join(lines)
    text = RESULTS.read_text() if RESULTS.exists() else "# jaxgear benchmark results\n"
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        text = head + section + tail
    else:
        text = text.rstrip("\n") + "\n\n" + section + "\n"
    RESULTS.write_text(text)
    print(section)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args()
    write(main(args.repeats), args.repeats)
