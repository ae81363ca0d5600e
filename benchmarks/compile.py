"""What compilation costs a user, old code against new, side by side in one run.

For each source tree (this checkout, and the code before the differentiable-core change checked out
beside it with ``git worktree add ../old 83eda1e``), a fresh process with the on-disk compilation
cache off measures, at ``Fidelity.fast()`` on the calibrated pair (ground, 700 N m, 90 °C,
2500 rpm):

- ``simulate``: tracing (``jax.jit(...).trace``), lowering and XLA compilation apart, the lowered
  program's size (StableHLO lines and ``while`` loops), and the run (median of 5, compiled);
- the reverse gradient of Ψ with respect to the whole float part of (pair, operating point,
  fidelity) with ``eqx.filter_value_and_grad``: the same four figures (where the tree supports it);
- ``jaxgear run`` cold (a fresh process, compilation cache off): wall time.

This checkout is measured twice: with XLA's default CPU emitters, as the code before, and with its
classic emitters (``--xla_cpu_use_fusion_emitters=false``), which the tests and the CLI (but at
the paper fidelity) select (``jaxgear.cli.enable_fast_cpu_compilation``).

Writes the section ``compile`` of benchmarks/RESULTS.md. Run from the repository root:
    python benchmarks/compile.py [--old ../old] [--skip-run]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

PROBE = r"""
import json, statistics, sys, time
import jax
jax.config.update("jax_enable_x64", True)
import equinox as eqx
import jax.numpy as jnp
import jaxgear as jg

out = {"jaxgear": jg.__file__}
pair = jg.presets.li2015_pair_calibrated()
lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
op = jg.OperatingPoint(torque=700.0, speed_rpm=2500.0, inlet_temperature=363.15)
fid = jg.Fidelity.fast()

# simulate as a user calls it, first thing in the process: the first call compiles what it needs,
# the second (10 rpm higher: same program) only runs
t = time.perf_counter(); jax.block_until_ready(jg.simulate(pair, lub, surf, op, fid).efficiency)
first = time.perf_counter() - t
op2 = jg.OperatingPoint(torque=700.0, speed_rpm=2510.0, inlet_temperature=363.15)
t = time.perf_counter(); jax.block_until_ready(jg.simulate(pair, lub, surf, op2, fid).efficiency)
out["simulate_call"] = {"first_s": first, "second_s": time.perf_counter() - t}


def stages(fn, *args):
    t0 = time.perf_counter(); traced = jax.jit(fn).trace(*args); t1 = time.perf_counter()
    lowered = traced.lower(); t2 = time.perf_counter()
    compiled = lowered.compile(); t3 = time.perf_counter()
    text = lowered.as_text()
    res = compiled(*args); jax.block_until_ready(res)
    runs = []
    for _ in range(5):
        t = time.perf_counter(); jax.block_until_ready(compiled(*args)); runs.append(time.perf_counter() - t)
    return {
        "trace_s": t1 - t0, "lower_s": t2 - t1, "compile_s": t3 - t2,
        "hlo_lines": text.count("\n"), "hlo_while": text.count("stablehlo.while"),
        "run_s": statistics.median(runs),
    }, res


def forward(pair, op):
    return jg.simulate(pair, lub, surf, op, fidelity=fid).efficiency


out["simulate"], eff = stages(forward, pair, op)
out["efficiency"] = float(eff)
try:  # the program simulate compiles on concrete inputs: its first pass (the second is apart)
    from jaxgear.tribodynamics.passes import _first_pass_outputs
except ImportError:  # the old tree: one program, the traced one
    out["first_pass"] = out["simulate"]
else:
    out["first_pass"], _ = stages(
        lambda pair, op: _first_pass_outputs(pair, lub, surf, op, fid)[0].efficiency, pair, op
    )

params, static = eqx.partition((pair, op), eqx.is_inexact_array)
if hasattr(fid, "with_constants"):
    fparams, fstatic = eqx.partition(fid, eqx.is_inexact_array)
else:
    fparams, fstatic = None, fid


def objective(params, fparams):
    p, o = eqx.combine(params, static)
    f = fstatic if fparams is None else eqx.combine(fparams, fstatic)
    return jg.simulate(p, lub, surf, o, fidelity=f).efficiency


try:
    out["gradient"], (val, grads) = stages(jax.value_and_grad(objective, argnums=(0, 1)), params, fparams)
    leaves = jax.tree_util.tree_leaves(grads)
    out["gradient"]["finite"] = bool(all(bool(jnp.all(jnp.isfinite(g))) for g in leaves))
    out["gradient"]["entries"] = int(sum(g.size for g in leaves))
except Exception as exc:  # the old tree: reverse mode fails
    out["gradient"] = {"error": f"{type(exc).__name__}: {str(exc).splitlines()[0][:200]}"}
print("RESULT " + json.dumps(out))
"""


CLASSIC = "--xla_cpu_use_fusion_emitters=false"


def _xla_flags(classic: bool) -> str:
    """$XLA_FLAGS for a probe: the caller's, with XLA's classic CPU emitters or without."""
    flags = os.environ.get("XLA_FLAGS", "").replace(CLASSIC, "").strip()
    return f"{flags} {CLASSIC}".strip() if classic else flags


def probe(root: Path, classic: bool = False) -> dict:
    env = {
        **os.environ,
        "XLA_FLAGS": _xla_flags(classic),
        "JAXGEAR_FAST_CPU_COMPILATION": "on" if classic else "off",
        "PYTHONPATH": str(root),
        "JAXGEAR_CACHE_DIR": "off",
        "JAX_COMPILATION_CACHE_DIR": "",
    }
    from _report import run_probe

    return run_probe(PROBE, root, env)


def jaxgear_run(root: Path, classic: bool = False) -> float:
    exe = Path(sys.executable).with_name("jaxgear")
    with tempfile.TemporaryDirectory() as out:
        env = {**os.environ, "PYTHONPATH": str(root), "JAXGEAR_CACHE_DIR": "off"}
        env["XLA_FLAGS"] = _xla_flags(classic)
        env["JAXGEAR_FAST_CPU_COMPILATION"] = "on" if classic else "off"
        env["MPLBACKEND"] = "Agg"
        t0 = time.perf_counter()
        subprocess.run(
            [str(exe), "run", "--out", out], check=True, env=env, cwd=root, capture_output=True
        )
        return time.perf_counter() - t0


def _row(label, r):
    if "error" in r:
        return f"| {label} | {r['error']} | | | | | |"
    return (
        f"| {label} | {r['trace_s']:.1f} | {r['lower_s']:.1f} | {r['compile_s']:.1f} | "
        f"{r['hlo_lines']:,} ({r['hlo_while']}) | {r['run_s'] * 1e3:.0f} |"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--old", type=Path, default=ROOT.parent / "old")
    parser.add_argument("--skip-run", action="store_true", help="skip the jaxgear run timing")
    args = parser.parse_args()
    sys.path.insert(0, str(Path(__file__).parent))
    from _report import machine, write_section

    # (source tree, XLA's classic CPU emitters): the default emitters for both trees, and the
    # classic ones (what the CLI and the tests select) for this one
    trees = {
        "before (83eda1e)": (args.old.resolve(), False),
        "now": (ROOT, False),
        "now, classic CPU emitters": (ROOT, True),
    }
    load = os.getloadavg()[0]
    results = {name: probe(*tree) for name, tree in trees.items()}
    if not args.skip_run:
        for name, tree in trees.items():
            results[name]["jaxgear_run_s"] = jaxgear_run(*tree)
    lines = [
        "## Compilation: `simulate` and its reverse gradient against the code before "
        "(`benchmarks/compile.py`)",
        "",
        f"Machine: {machine()}. `Fidelity.fast()`, calibrated pair, ground, 700 N m, 2500 rpm "
        "(a stable periodic orbit); compilation cache off, each tree in a fresh process, both in "
        f"this run; load average {load:.1f} at the start"
        + (
            " (above 1: another job shared the machine, and both trees' times are slower)."
            if load > 1.0
            else " (a quiet machine)."
        ),
        "",
        "| program | trace s | lower s | XLA compile s | StableHLO lines (while loops) | run ms |",
        "|---|---|---|---|---|---|",
    ]
    for name, r in results.items():
        lines.append(_row(f"`simulate` on concrete inputs, {name}", r["first_pass"]))
    for name, r in results.items():
        lines.append(_row(f"`simulate` inside a caller's `jit`, {name}", r["simulate"]))
    for name, r in results.items():
        lines.append(_row(f"reverse gradient, {name}", r["gradient"]))
    lines += ["", "| `simulate`'s first call (compiles) | s | second call (runs) | s |"]
    lines += ["|---|---|---|---|"]
    for name, r in results.items():
        c = r["simulate_call"]
        lines.append(f"| {name} | {c['first_s']:.1f} | | {c['second_s']:.3f} |")
    if not args.skip_run:
        lines += ["", "| `jaxgear run` cold | s |", "|---|---|"]
        lines += [f"| {name} | {r['jaxgear_run_s']:.0f} |" for name, r in results.items()]
    old, new = results["before (83eda1e)"], results["now"]

    def total(r):
        return r["trace_s"] + r["lower_s"] + r["compile_s"]

    grad = new["gradient"]
    lines += [
        "",
        "On concrete inputs `simulate` compiles the first pass alone (the quasi-static rung or the "
        "fixed point) and compiles the second (the attractor, the back flanks' loss) only at a "
        "point that needs it; inside a caller's `jit` both are traced into the caller's program. "
        "The code before compiled one program for both.",
        "",
        f"- `simulate` on concrete inputs: trace + lower + compile {total(old['first_pass']):.1f} → "
        f"{total(new['first_pass']):.1f} s ({total(old['first_pass']) / total(new['first_pass']):.1f}×), "
        f"its first call {old['simulate_call']['first_s']:.1f} → "
        f"{new['simulate_call']['first_s']:.1f} s "
        f"({old['simulate_call']['first_s'] / new['simulate_call']['first_s']:.1f}×); the program "
        f"{old['first_pass']['hlo_lines'] / new['first_pass']['hlo_lines']:.2f}× smaller.",
        f"- inside a caller's `jit`: {total(old['simulate']):.1f} → {total(new['simulate']):.1f} s "
        f"({total(old['simulate']) / total(new['simulate']):.1f}×), the program "
        f"{old['simulate']['hlo_lines'] / new['simulate']['hlo_lines']:.2f}× smaller.",
    ]
    if "error" not in grad:
        lines += [
            f"- reverse gradient over all {grad['entries']} float inputs (all finite: "
            f"{grad['finite']}): run {grad['run_s'] / new['simulate']['run_s']:.1f}× the forward's "
            f"(inside `jit`); compile (trace + lower + XLA) {total(grad) / total(new['simulate']):.1f}× "
            f"the same forward program's, {total(grad) / total(new['first_pass']):.1f}× the "
            "program `simulate` compiles on concrete inputs.",
        ]
    classic = results["now, classic CPU emitters"]
    cgrad = classic["gradient"]
    lines += [
        f"- XLA's classic CPU emitters (`{CLASSIC}`, what `jaxgear` and the tests select): "
        f"`simulate`'s first call {new['simulate_call']['first_s']:.1f} → "
        f"{classic['simulate_call']['first_s']:.1f} s; on concrete inputs trace + lower + compile "
        f"{total(new['first_pass']):.1f} → {total(classic['first_pass']):.1f} s and run "
        f"{new['first_pass']['run_s'] * 1e3:.0f} → {classic['first_pass']['run_s'] * 1e3:.0f} ms.",
    ]
    if "error" not in cgrad:
        lines[-1] += (
            f" The reverse gradient: compile {total(grad):.1f} → {total(cgrad):.1f} s, run "
            f"{grad['run_s'] * 1e3:.0f} → {cgrad['run_s'] * 1e3:.0f} ms; with these emitters it "
            f"runs {cgrad['run_s'] / classic['simulate']['run_s']:.1f}× and compiles "
            f"{total(cgrad) / total(classic['simulate']):.1f}× the forward program inside `jit`."
        )
    if not args.skip_run:
        lines[-1] += (
            f" `jaxgear run` cold {new['jaxgear_run_s']:.0f} → {classic['jaxgear_run_s']:.0f} s."
        )
    print("\n".join(lines))
    print(json.dumps(results, indent=1))
    write_section("compile", "\n".join(lines))


if __name__ == "__main__":
    main()
