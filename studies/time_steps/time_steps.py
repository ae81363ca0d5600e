"""The transient passage's time step and time scheme against a rough film's friction.

A deterministic rough film's roughness moves through the contact with the surfaces; with the time
step tied to the grid (Δt = Δx/ur, EHL_NOTES) the shortest roughness wavelength the grid resolves
passes a node in a few steps, so the squeeze term's truncation error need not be small. This
measures it: the pitch-point contact held (700 N m, slide-to-roll 0.3, 3500 rpm, iso-thermal), the
polished surfaces filtered at λs = 2.5 µm (a full film: `figures.field_surfaces("polished")`),
`EHLModel(mixed="deterministic", linear_solver="krylov", relaxation_sweeps=0)`, marched from a
steady start over the same rolling distance (40 cells of the 2049-node grid, 31 µm) with
Δt = C Δx/ur, C the Courant number, by backward Euler and by BDF2 (`EHLModel.time_scheme`), on
1025, 2049 and 4097 nodes; and the ground surfaces (unfiltered) on the 257 nodes of the
deterministic engagement (`mixed_engagement`, studies/mixed_thermal); each with the Eulerian wedge and squeeze terms and
along the characteristics (`EHLModel.transport`); and, for the polished film by BDF2 at C = 0.5 on
2049 nodes, the Newton tolerance (`EHLModel.tolerance`) from 1e-7 to 1e-3. Reported: the loss per width at the window's end (the roughness then
stands at the same place in every run), the mean over the window's second half, p_max and h_min
at the end, and the cost. Writes the ``mixed_time_steps`` section of studies/time_steps/README.md.

Run: ``python studies/time_steps/time_steps.py [--rows FILE]`` (``--rows`` keeps measured rows
across runs).
"""

from __future__ import annotations

import sys
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
README = Path(__file__).with_name("README.md")  # this study's sections
sys.path.insert(0, str(ROOT / "benchmarks"))  # _report
sys.path.insert(0, str(Path(__file__).parents[2] / "tests"))

from _report import (  # noqa: E402
    compile_then_run,
    machine,
    row_cache_from_command_line,
    write_section,
)
from helpers import gear_contact  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.lubrication.passage import grid_time_step, solve_ehl_passage  # noqa: E402
from jaxgear.paper import field_surfaces  # noqa: E402

LUB = jg.presets.mil_l_23699()
WINDOW_CELLS_2049 = 40  # the rolling distance, in cells of the 2049-node grid

GROUND_WINDOW_CELLS_2049 = 320  # the ground film's: 40 cells of its 257-node grid (250 µm)

# (film, nodes, scheme, Courant numbers, transport)
RUNS = (
    ("polished", 2049, "backward_euler", (4.0, 2.0, 1.0, 0.5, 0.25), "eulerian"),
    ("polished", 2049, "bdf2", (4.0, 2.0, 1.0, 0.5, 0.25), "eulerian"),
    ("polished", 1025, "backward_euler", (1.0,), "eulerian"),
    ("polished", 1025, "bdf2", (1.0, 0.5, 0.25), "eulerian"),
    ("polished", 4097, "backward_euler", (1.0,), "eulerian"),
    ("polished", 4097, "bdf2", (1.0, 0.5), "eulerian"),
    ("ground", 257, "backward_euler", (1.0, 0.5, 0.25), "eulerian"),
    ("ground", 257, "bdf2", (1.0, 0.5, 0.25), "eulerian"),
    # along the characteristics (``EHLModel.transport``)
    ("polished", 2049, "bdf2", (4.0, 2.0, 1.0, 0.5), "characteristic"),
    ("polished", 2049, "backward_euler", (1.0,), "characteristic"),
    ("polished", 1025, "bdf2", (2.0, 1.0), "characteristic"),
    ("polished", 4097, "bdf2", (2.0, 1.0), "characteristic"),
    ("ground", 257, "bdf2", (2.0, 1.0, 0.5), "characteristic"),
    ("ground", 257, "backward_euler", (1.0,), "characteristic"),
)
# the Newton tolerance (‖F‖∞, pressures in ph) of the polished film by BDF2 at C = 0.5 on 2049
# nodes, against the default 1e-9: how much of a step's cost buys digits the time step has not
TOLERANCES = (1e-7, 1e-6, 1e-5, 1e-4, 1e-3)


def measure(film, n, scheme, courant, tolerance=1e-9, transport="eulerian"):
    # the polished full film: Krylov directions, unrelaxed warm starts (as --engagement-fine);
    # the ground film on 257 nodes: the default deterministic model (dense LU, relaxed starts)
    if film == "polished":
        options = {"linear_solver": "krylov", "relaxation_sweeps": 0}
        window = WINDOW_CELLS_2049
    else:
        options = {}
        window = GROUND_WINDOW_CELLS_2049
    model = jg.EHLModel(
        n_nodes=n,
        mixed="deterministic",
        time_scheme=scheme,
        tolerance=tolerance,
        transport=transport,
        **options,
    )
    c = gear_contact(rpm=3500.0)
    dt = courant * float(grid_time_step(c, LUB, model))
    # the same rolling distance on every grid: w cells of 2049 nodes = w (n − 1)/2048 of n
    steps = round(window * (n - 1) / 2048 / courant)
    k = steps + 1
    contacts = jax.tree_util.tree_map(lambda a: jnp.full((k,), a), c)
    times = jnp.arange(k) * dt
    surf = field_surfaces("polished") if film == "polished" else jg.presets.ground()
    sol, t_compile, t_run = compile_then_run(
        lambda cs, t: solve_ehl_passage(cs, LUB, model, surf, times=t), contacts, times
    )
    loss = np.asarray(sol.power_loss) / 1e3  # kW/m
    its = np.asarray(sol.iterations)
    ok = np.asarray(sol.converged)
    dx = float(sol.x[0, 1] - sol.x[0, 0])
    row = {
        "film": film,
        "nodes": n,
        "dx_um": dx * 1e6,
        "scheme": scheme,
        "transport": transport,
        "courant": courant,
        "tolerance": tolerance,
        "steps": steps,
        "compile_s": t_compile,
        "run_s": t_run,
        "its": float(its[1:].mean()),
        "converged": int(ok[1:].sum()),
        "loss_end": float(loss[-1]),
        "loss_half": float(loss[k // 2 :].mean()),
        "p_max": float(np.max(np.asarray(sol.p[-1]))) / 1e9,
        "h_min": float(np.asarray(sol.h_min)[-1]) * 1e6,
    }
    print(row, flush=True)
    return row


def main(argv=None):
    cache = row_cache_from_command_line(__doc__, argv)
    rows = []
    for film, n, scheme, courants, transport in RUNS:
        for courant in courants:
            # the Eulerian polished rows keep the keys they were first measured under
            key = f"{n} {scheme} {courant}" + ("" if film == "polished" else f" {film}")
            key += "" if transport == "eulerian" else f" {transport}"
            rows.append(
                cache.get(
                    key,
                    lambda f=film, n=n, s=scheme, c=courant, t=transport: measure(
                        f, n, s, c, transport=t
                    ),
                )
            )
    for tol in TOLERANCES:
        key = f"2049 bdf2 0.5 tol {tol:g}"
        rows.append(cache.get(key, lambda t=tol: measure("polished", 2049, "bdf2", 0.5, t)))
    table = [
        f"| {r.get('film', 'polished')} | {r['nodes']} | {r['dx_um']:.2f} | "
        f"{r['scheme'].replace('_', ' ')} | {r.get('transport', 'eulerian')} | {r['courant']:g} | {r.get('tolerance', 1e-9):g} | "
        f"{r['steps']} | {r['compile_s']:.0f} | {r['run_s']:.1f} | {r['its']:.1f} | "
        f"{r['converged']} of {r['steps']} | {r['p_max']:.3f} | {r['h_min']:.4f} | "
        f"{r['loss_end']:.2f} | {r['loss_half']:.2f} |"
        for r in rows
    ]
    body = "\n".join(
        [
            "## A rough film's friction against the time step (`time_steps.py`)",
            "",
            f"Machine: {machine()}. The pitch-point contact held (700 N m, SRR 0.3, 3500 rpm), "
            "iso-thermal. Polished: the surfaces filtered at λs = 2.5 µm (a full film), "
            '`EHLModel(mixed="deterministic", linear_solver="krylov", relaxation_sweeps=0)`, '
            "marched from a steady start over 31 µm of rolling (40 cells of the 2049-node grid). "
            "Ground: the ground preset (unfiltered) on 257 nodes, the default deterministic "
            "`EHLModel`, over 250 µm (40 of its cells). Δt = C Δx/ur. Loss per width at the window's end (the roughness at the same "
            "place in every run) and its mean over the window's second half; p_max and h_min at "
            "the end; its: Newton iterations a step (steps 1…); tolerance: `EHLModel.tolerance`, "
            "the Newton solves' ‖F‖∞ (default 1e-9).",
            "",
            "| film | nodes | Δx, µm | scheme | transport | C | tolerance | steps | compile, s | run, s | "
            "its a step | converged | p_max, GPa | h_min, µm | loss at the end, kW/m | "
            "loss, 2nd half, kW/m |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
            *table,
        ]
    )
    write_section("mixed_time_steps", body, README)


if __name__ == "__main__":
    main()
