"""What a derivative of the coupled model costs against the forward program it differentiates.

In a fresh process per emitter choice (compilation cache off), at ``Fidelity.fast()`` on the
calibrated pair (ground, 700 N m, 90 °C, 2500 rpm: a stable periodic orbit), three programs of
Ψ = ``simulate(...).efficiency``'s first pass (what ``simulate`` compiles on concrete inputs):

- the forward program;
- one forward-mode tangent (``jax.jvp`` along every float input at once: one direction);
- the reverse gradient over every float input of (pair, operating point, fidelity)
  (``jax.value_and_grad``).

Each: tracing, lowering and XLA compilation apart, the lowered program's size (StableHLO lines and
``while`` loops) and the run (median of 5). A reverse program holds the forward program and the
linearised one transposed; the forward-mode tangent holds the forward program and the linearised
one as it is, so its cost is what any derivative JAX derives from this model costs at least.

Writes the section ``gradient_floor`` of benchmarks/RESULTS.md. Run from the repository root:
    python benchmarks/gradient_floor.py
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

PROBE = r"""
import json, statistics, time
import jax
jax.config.update("jax_enable_x64", True)
import equinox as eqx
import jax.numpy as jnp
import jaxgear as jg
from jaxgear.tribodynamics.passes import _first_pass_outputs

pair = jg.presets.li2015_pair_calibrated()
lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
op = jg.OperatingPoint(torque=700.0, speed_rpm=2500.0, inlet_temperature=363.15)
params, static = eqx.partition((pair, op, jg.Fidelity.fast()), eqx.is_inexact_array)


def psi(params):
    p, o, f = eqx.combine(params, static)
    return _first_pass_outputs(p, lub, surf, o, f)[0].efficiency


ones = jax.tree_util.tree_map(jnp.ones_like, params)
programs = {
    "forward": psi,
    "tangent": lambda p: jax.jvp(psi, (p,), (ones,)),
    "reverse": jax.value_and_grad(psi),
}
out = {"entries": int(sum(x.size for x in jax.tree_util.tree_leaves(params)))}
for name, fn in programs.items():
    t0 = time.perf_counter(); traced = jax.jit(fn).trace(params); t1 = time.perf_counter()
    lowered = traced.lower(); t2 = time.perf_counter()
    compiled = lowered.compile(); t3 = time.perf_counter()
    text = lowered.as_text()
    jax.block_until_ready(compiled(params))
    runs = []
    for _ in range(5):
        t = time.perf_counter(); jax.block_until_ready(compiled(params)); runs.append(time.perf_counter() - t)
    out[name] = {
        "trace_s": t1 - t0, "lower_s": t2 - t1, "compile_s": t3 - t2,
        "hlo_lines": text.count("\n"), "hlo_while": text.count("stablehlo.while"),
        "run_s": statistics.median(runs),
    }
print("RESULT " + json.dumps(out))
"""

CLASSIC = "--xla_cpu_use_fusion_emitters=false"


def probe(classic: bool) -> dict:
    flags = os.environ.get("XLA_FLAGS", "").replace(CLASSIC, "").strip()
    env = {
        **os.environ,
        "XLA_FLAGS": f"{flags} {CLASSIC}".strip() if classic else flags,
        "PYTHONPATH": str(ROOT),
        "JAXGEAR_CACHE_DIR": "off",
        "JAX_COMPILATION_CACHE_DIR": "",
    }
    from _report import run_probe

    return run_probe(PROBE, ROOT, env)


def main():
    sys.path.insert(0, str(Path(__file__).parent))
    from _report import machine, write_section

    load = os.getloadavg()[0]
    results = {
        "classic CPU emitters (jaxgear's)": probe(True),
        "XLA's default emitters": probe(False),
    }
    labels = {
        "forward": "forward (Ψ)",
        "tangent": "forward-mode tangent, one direction",
        "reverse": "reverse gradient, every float input",
    }
    lines = [
        "## What a derivative costs against its forward program (`benchmarks/gradient_floor.py`)",
        "",
        f"Machine: {machine()}. `Fidelity.fast()`, calibrated pair, ground, 700 N m, 2500 rpm; "
        "the first pass (what `simulate` compiles on concrete inputs); compilation cache off, a "
        f"fresh process per emitter choice; load average {load:.1f} at the start.",
        "",
        "| emitters | program | trace + lower + XLA compile s | × forward | StableHLO lines "
        "(while loops) | run ms | × forward |",
        "|---|---|---|---|---|---|---|",
    ]
    for emitters, r in results.items():
        fwd = r["forward"]
        total_fwd = fwd["trace_s"] + fwd["lower_s"] + fwd["compile_s"]
        for key, label in labels.items():
            p = r[key]
            total = p["trace_s"] + p["lower_s"] + p["compile_s"]
            lines.append(
                f"| {emitters} | {label} | {total:.1f} | {total / total_fwd:.1f} | "
                f"{p['hlo_lines']:,} ({p['hlo_while']}) | {p['run_s'] * 1e3:.0f} | "
                f"{p['run_s'] / fwd['run_s']:.1f} |"
            )
    entries = next(iter(results.values()))["entries"]
    lines += [
        "",
        f"The reverse gradient covers {entries} float entries. Forward mode along one direction "
        "already holds the forward program and a linearised copy of the fixed-point map (its "
        "Krylov solve's operator and right-hand side), with the shooting's own implicit solve "
        "inside; a reverse program holds the same, transposed.",
    ]
    write_section("gradient_floor", "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
