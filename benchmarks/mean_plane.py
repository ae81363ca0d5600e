"""The statistical mixed film before and after it moved to the surfaces' mean planes, side by side in
one run: solve time, asperity share, friction, central film and loss of single line contacts, and
the closed-form rung's error against the solver.

Each code tree runs in a fresh process (``PYTHONPATH`` set to it). The old tree is a checkout of
the code before the change beside this one, e.g. ``git worktree add ../old <commit>``.

Contacts: the paper's pitch contact (REFERENCE §2-§3), Mil-L-23699 at 90 °C, 700 N m, slide-to-roll
0.3, ground surfaces (``presets.ground()``, and 3 × their roughness for the boundary side), the
iso-thermal statistical film (``EHLModel(mixed="statistical")``) at 129, 257 and 513 nodes.

Run: ``python benchmarks/mean_plane.py [--old ../old]`` (writes its section of RESULTS.md).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, run_probe, write_section  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

PROBE = r"""
import json, sys, time
import jax
jax.config.update("jax_enable_x64", True)
sys.path.insert(0, "tests")
import numpy as np
import jaxgear as jg
from helpers import gear_contact

LUB = jg.presets.mil_l_23699()
out = {"time": {}, "contacts": []}
for n in (129, 257, 513):
    model = jg.EHLModel(n_nodes=n, mixed="statistical")
    c = gear_contact(700.0, 2000.0, 0.3)
    surf = jg.presets.ground()
    t0 = time.perf_counter()
    jax.block_until_ready(jg.solve_ehl(c, LUB, model, surf).p)
    first = time.perf_counter() - t0
    runs = []
    for _ in range(7):
        t0 = time.perf_counter()
        sol = jax.block_until_ready(jg.solve_ehl(c, LUB, model, surf))
        runs.append(time.perf_counter() - t0)
    out["time"][n] = dict(first=first, run=min(runs), converged=bool(sol.converged))
model = jg.EHLModel(n_nodes=257, mixed="statistical")
for rpm, scale in ((300.0, 3.0), (500.0, 1.0), (1700.0, 1.0), (3375.0, 1.0)):
    c = gear_contact(700.0, rpm, 0.3)
    surf = jg.presets.ground(scale)
    s = jg.solve_ehl(c, LUB, model, surf)
    w = float(c.load_per_width)
    i0 = int(np.argmin(np.abs(np.asarray(s.x))))
    gap = float(getattr(s, "gap", s.h)[i0])
    out["contacts"].append(dict(
        rpm=rpm, scale=scale, converged=bool(s.converged), sigma=float(surf.composite_rq),
        share=float(s.contact_load_share), mu=abs(float(s.friction_sliding)) / w,
        h_central=float(s.h_central), gap_central=gap, loss=float(s.power_loss),
        loss_sliding=float(s.power_loss_sliding), loss_rolling=float(s.power_loss_rolling),
    ))
print("RESULT " + json.dumps(out))
"""


def probe(root: Path) -> dict:
    env = {**os.environ, "PYTHONPATH": str(root), "JAXGEAR_CACHE_DIR": "off"}
    return run_probe(PROBE, root, env)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old", type=Path, default=ROOT.parent / "old")
    args = parser.parse_args()
    trees = {"before": args.old.resolve(), "mean plane": ROOT}
    load = os.getloadavg()[0]
    results = {name: probe(root) for name, root in trees.items()}
    lines = [
        f"Measured on {machine()}; compilation cache off, one process per tree; load average "
        f"{load:.1f} at the start (on 2 cores: above 1, the times are another job's as well).",
        "",
        "Solve time of one contact (2000 rpm, ground), compile + first run and the fastest of 7 "
        "runs (warm: the same program; the fastest, as the machine is shared), s:",
        "",
        "| nodes | " + " | ".join(f"{k} first | {k} run" for k in trees) + " | run ratio |",
        "|---|" + "---|---|" * len(trees) + "---|",
    ]
    for n in ("129", "257", "513"):
        cells = []
        for name in trees:
            t = results[name]["time"][n]
            flag = "" if t["converged"] else " (not converged)"
            cells.append(f"{t['first']:.1f} | {t['run'] * 1e3:.0f} ms{flag}")
        ratio = results["mean plane"]["time"][n]["run"] / results["before"]["time"][n]["run"]
        lines.append(f"| {n} | " + " | ".join(cells) + f" | {ratio:.2f} |")
    lines += [
        "",
        "Contacts (257 nodes, iso-thermal), before → mean plane: asperity share of the load, "
        "friction coefficient, central film (before: the mean film; now: the mean-plane "
        "separation d and the average gap h_T over σ), loss:",
        "",
        "| rpm | roughness | share | μ | central film / σ | loss W/m (sliding + rolling) |",
        "|---|---|---|---|---|---|",
    ]
    for old, new in zip(
        results["before"]["contacts"], results["mean plane"]["contacts"], strict=True
    ):
        sigma = new["sigma"]
        lines.append(
            f"| {new['rpm']:.0f} | {new['scale']:g} × ground (σ {sigma * 1e6:.2f} µm) | "
            f"{old['share']:.3f} → {new['share']:.3f} | {old['mu']:.4f} → {new['mu']:.4f} | "
            f"{old['h_central'] / sigma:.3f} → d {new['h_central'] / sigma:.3f}, "
            f"h_T {new['gap_central'] / sigma:.3f} | "
            f"{old['loss']:.0f} ({old['loss_sliding']:.0f} + {old['loss_rolling']:.0f}) → "
            f"{new['loss']:.0f} ({new['loss_sliding']:.0f} + {new['loss_rolling']:.0f}) |"
        )
    write_section(
        "mean_plane",
        "## The statistical film on the mean plane "
        "(`benchmarks/mean_plane.py`)\n\n" + "\n".join(lines),
    )
    print("\n".join(lines))


if __name__ == "__main__":
    main()
