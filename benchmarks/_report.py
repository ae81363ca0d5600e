"""Shared helpers for the benchmarks and the studies: timing, and writing a section of a results
file (benchmarks/RESULTS.md, or a study's studies/<name>/README.md)."""

from __future__ import annotations

import datetime
import os
import platform
import re
import statistics
import time
from pathlib import Path

RESULTS = Path(__file__).with_name("RESULTS.md")


def machine() -> str:
    import jax

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return (
        f"{cpu}, {os.cpu_count()} cores, jax {jax.__version__} on {jax.default_backend()}, "
        f"{datetime.date.today().isoformat()}"
    )


ROWS_HELP = (
    "JSON file of measured rows: rows found there are reused, new ones added as they are measured "
    "(so a run that stops part way resumes; every row still comes from the script)"
)


class RowCache:
    """Rows measured by a benchmark, kept in an optional JSON file (``--rows``) so that a long run
    can be resumed or extended: ``cache.get(key, measure)`` returns the saved row or measures,
    saves and returns it."""

    def __init__(self, path: Path | None):
        import json

        self.path = path
        self.saved = json.loads(path.read_text()) if path and path.exists() else {}

    def get(self, key: str, measure):
        import json

        if key not in self.saved:
            self.saved[key] = measure()
            if self.path:
                self.path.write_text(json.dumps(self.saved, indent=1))
        return self.saved[key]


def row_cache_from_command_line(doc: str, argv=None) -> RowCache:
    """The RowCache of a benchmark whose only option is ``--rows`` (described by its docstring's
    first line)."""
    import argparse

    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--rows", type=Path, help=ROWS_HELP)
    return RowCache(ap.parse_args(argv).rows)


def compile_then_run(fn, *args):
    """(result, compile s, run s): ``jax.jit(fn)`` lowered and compiled for ``args``, then called
    once on them (compile and run timed apart: a long march is run once)."""
    import jax

    t0 = time.perf_counter()
    compiled = jax.jit(fn).lower(*args).compile()
    t_compile = time.perf_counter() - t0
    t0 = time.perf_counter()
    result = jax.block_until_ready(compiled(*args))
    return result, t_compile, time.perf_counter() - t0


def time_call(fn, *args, repeats: int = 20):
    """(compile+first-run seconds, median run seconds) of ``fn(*args)`` with block_until_ready."""
    import jax

    t0 = time.perf_counter()
    jax.block_until_ready(fn(*args))
    first = time.perf_counter() - t0
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        jax.block_until_ready(fn(*args))
        runs.append(time.perf_counter() - t0)
    return first, statistics.median(runs)


def write_section(name: str, body: str, path: Path = RESULTS) -> None:
    """Replace (or append) the section between <!-- BEGIN name --> and <!-- END name --> of
    ``path`` (benchmarks/RESULTS.md by default; a study passes its own README.md)."""
    path = Path(path)
    text = (
        path.read_text()
        if path.exists()
        else ("# jaxgear benchmark results\n" if path == RESULTS else f"# {path.parent.name}\n")
    )
    block = f"<!-- BEGIN {name} -->\n{body.rstrip()}\n<!-- END {name} -->"
    pattern = re.compile(
        rf"<!-- BEGIN {re.escape(name)} -->.*?<!-- END {re.escape(name)} -->", re.S
    )
    text = (
        pattern.sub(lambda _: block, text)
        if pattern.search(text)
        else text.rstrip() + "\n\n" + block + "\n"
    )
    path.write_text(text)


def effective_friction(result) -> float:
    """μ_eff of a SimulationResult: its sliding loss over the cycle mean of Σ W |us| (the mean
    friction coefficient the loss implies; REFERENCE §6)."""
    import jax.numpy as jnp

    us = result.surface_velocity[..., 0] - result.surface_velocity[..., 1]
    work = float(jnp.mean(jnp.sum(jnp.abs(result.tooth_force * us), axis=1)))
    return float(result.power_loss_sliding) / max(work, 1e-30)


def bands(speeds, mask) -> str:
    """Contiguous runs of ``speeds`` where ``mask`` holds, as "a-b, c, ..."."""
    runs, start = [], None
    for i, on in enumerate(list(mask) + [False]):
        if on and start is None:
            start = i
        if not on and start is not None:
            a, b = speeds[start], speeds[i - 1]
            runs.append(f"{a:.0f}" if a == b else f"{a:.0f}-{b:.0f}")
            start = None
    return ", ".join(runs) or "none"


def run_probe(code: str, root: Path, env: dict) -> dict:
    """Run ``python -c code`` in a fresh process in ``root`` with ``env`` and return the JSON that
    it prints on a line starting with "RESULT " (a probe's measurements, free of this process's
    compiled programs and JAX settings)."""
    import json
    import subprocess
    import sys

    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=root, env=env, capture_output=True, text=True
    )
    for line in proc.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    raise RuntimeError(f"probe in {root} failed:\n{proc.stderr[-3000:]}")
