"""How one contact's loss grows with its load: the statistical asperity model against the roughness
in the film.

The coupled model's R3 at point E and R7's efficiency (REFERENCE §7) turn on the load exponent
k = d ln Φ/d ln W of a contact's loss (docs/limitations.md: with the statistical
Greenwood-Tripp contact k ≈ 0.6, concave, and a dynamic load swing lowers the cycle's mean loss;
``load_convexity.py`` beside this script). Greenwood-Tripp's asperity pressure is a function of the film
h/σ alone, and the film hardly depends on the load, so the asperity load grows with the Hertz
width, as √W. With the profiles in the film (the paper's measured profiles; here the synthetic
ground preset, unfiltered) the asperities inside the Hertz zone are flattened by the pressure and
their share of the load need not fall. This measures k both ways:

- held: the pitch-point contact (SRR 0.3, 3500 rpm, iso-thermal) at the load of 700 N m and of
  1500 N m (× 2.143: R7's torques) on one pair, marched from a steady start over 500 µm of rolling
  (80 cells of 257 nodes; Δt = Δx/ur, backward Euler), the means taken over the last three
  quarters of the steps that converged; statistical and deterministic on 257, 513 and 1025 nodes
  (the same profiles, resolved more finely), and the deterministic film for four roughness seeds
  on 257, 513 and 1025 nodes; the grid follows the Hertz half-width, so on n nodes the 1500 N m
  contact's cells are 1.46× wider (coarser cells make more asperity contact), and the deterministic
  1500 N m contact is solved again on 377 and 753 nodes, the 700 N m contact's cells on 257 and 513;
- along the path: one whole engagement (quasi-static load sharing of the calibrated pair, 257
  nodes, thermal, as ``mixed_engagement`` in studies/mixed_thermal) at 700 and 1500 N m: the friction energy of
  one engagement, whose ratio is the ratio of Φ̄ at one speed (Φ̄ = mesh frequency × energy per
  engagement); failed steps counted at the mean of the converged ones.

Writes the ``load_exponent`` section of studies/load_exponent/README.md.

Run: ``python studies/load_exponent/load_exponent.py [--rows FILE] [--statistical-only]``
(``--rows`` keeps measured rows across runs). ``--statistical-only`` measures the statistical rows
alone (minutes, where the deterministic ones take hours) and writes them to the section
``load_exponent_statistical``.
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
sys.path.insert(0, str(ROOT / "studies" / "mixed_thermal"))  # _path_contacts
sys.path.insert(0, str(Path(__file__).parents[2] / "tests"))

from _report import (  # noqa: E402
    ROWS_HELP,
    RowCache,
    compile_then_run,
    machine,
    write_section,
)
from helpers import gear_contact  # noqa: E402
from mixed_thermal import _path_contacts  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.lubrication.passage import grid_time_step, solve_ehl_passage  # noqa: E402

LUB = jg.presets.mil_l_23699()
TORQUES = (700.0, 1500.0)
RATIO = TORQUES[1] / TORQUES[0]
WINDOW_CELLS_257 = 80  # the held contact's rolling distance, in cells of the 257-node grid
PARTS = ("total", "sliding", "rolling", "asperity")

# held: (mixed model, nodes, seed)
HELD = (
    *[("statistical", n, 0) for n in (257, 513, 1025)],
    *[("deterministic", n, 0) for n in (257, 513, 1025)],
    *[("deterministic", n, seed) for n in (257, 513, 1025) for seed in (1, 2, 3)],
)
# the grid follows the Hertz half-width b ∝ √W, so at 1500 N m n nodes are cells 1.46× wider: the
# 1500 N m contact also on as many nodes as give the 700 N m contact's cells (376/256 = 1.47)
MATCHED = ((257, 377), (513, 753))
# along the path: (mixed model, rpm, transport), thermal, 257 nodes; along the characteristics by
# BDF2 (``EHLModel.transport``), whose deterministic rolling heat is not the Eulerian terms' excess
PATH = (
    ("statistical", 3500.0, "eulerian"),
    ("deterministic", 3500.0, "eulerian"),
    ("deterministic", 3500.0, "characteristic"),
    ("statistical", 500.0, "eulerian"),
    ("deterministic", 500.0, "eulerian"),
    ("deterministic", 500.0, "characteristic"),
)


def _parts(sol, select):
    """Mean total / sliding / rolling / asperity loss per width (W/m) over the selected steps."""
    mean = lambda a: float(np.asarray(a)[select].mean())  # noqa: E731
    return {
        "total": mean(sol.power_loss),
        "sliding": mean(sol.power_loss_sliding),
        "rolling": mean(sol.power_loss_rolling),
        "asperity": mean(sol.power_loss_asperity),
    }


def held(kind, n, seed, torque, step_nodes=None):
    """The held contact on ``n`` nodes; Δt and the number of steps those of the 700 N m contact on
    ``step_nodes`` (default ``n``) nodes: Δx/ur of that grid, over 500 µm."""
    step_nodes = n if step_nodes is None else step_nodes
    model = jg.EHLModel(n_nodes=n, mixed=kind)
    c = gear_contact(torque=torque, rpm=3500.0)
    step_model = jg.EHLModel(n_nodes=step_nodes, mixed=kind)
    dt = float(grid_time_step(gear_contact(rpm=3500.0), LUB, step_model))
    k = WINDOW_CELLS_257 * (step_nodes - 1) // 256
    contacts = jax.tree_util.tree_map(lambda a: jnp.full((k,), a), c)
    surf = jg.presets.ground(seed=seed)
    sol, _, t_run = compile_then_run(
        lambda cs, t: solve_ehl_passage(cs, LUB, model, surf, times=t),
        contacts,
        jnp.arange(k) * dt,
    )
    ok = np.asarray(sol.converged)
    select = ok & (np.arange(k) >= k // 4)
    row = {
        "steps": k,
        "converged": int(ok.sum()),
        "run_s": t_run,
        **_parts(sol, select),
        "share": float(np.asarray(sol.contact_load)[select].mean()) / float(c.load_per_width),
    }
    print(kind, n, seed, torque, row, flush=True)
    return row


def path(kind, rpm, torque, transport="eulerian"):
    scheme = "bdf2" if transport == "characteristic" else "backward_euler"
    model = jg.EHLModel(
        n_nodes=257, mixed=kind, thermal=True, transport=transport, time_scheme=scheme
    )
    contacts, times, dt = _path_contacts(rpm, model, torque=torque)
    sol, _, t_run = compile_then_run(
        lambda cs, t: solve_ehl_passage(cs, LUB, model, jg.presets.ground(), times=t),
        contacts,
        times,
    )
    ok = np.asarray(sol.converged)
    k = ok.size
    # energy per engagement over the 20 mm face width, J: failed steps at the converged mean
    energy = {part: v * 0.02 * k * dt for part, v in _parts(sol, ok).items()}
    row = {"steps": k, "converged": int(ok.sum()), "run_s": t_run, **energy}
    print(kind, rpm, torque, row, flush=True)
    return row


def _exponent(low, high, part):
    return float(np.log(high[part] / low[part]) / np.log(RATIO))


def main(argv=None):
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=Path, help=ROWS_HELP)
    ap.add_argument(
        "--statistical-only",
        action="store_true",
        help="the statistical rows alone, written to the section load_exponent_statistical",
    )
    args = ap.parse_args(argv)
    cache = RowCache(args.rows)
    kinds = ("statistical",) if args.statistical_only else ("statistical", "deterministic")

    def at_both_torques(key, measure):
        """(row at 700 N m, row at 1500 N m), measured by ``measure(torque)`` or cached."""
        return tuple(cache.get(f"{key} {t:g}", lambda t=t: measure(t)) for t in TORQUES)

    held_rows = []
    for kind, n, seed in [h for h in HELD if h[0] in kinds]:
        low, high = at_both_torques(
            f"held {kind} {n} {seed}", lambda t, kind=kind, n=n, seed=seed: held(kind, n, seed, t)
        )
        ks = " | ".join(f"{_exponent(low, high, p):.2f}" for p in PARTS)
        held_rows.append(
            f"| {kind} | {n} | {seed} | {low['converged']} + {high['converged']} of "
            f"2 × {low['steps']} | {low['total'] / 1e3:.1f} | {low['sliding'] / 1e3:.2f} | "
            f"{low['rolling'] / 1e3:.1f} | {ks} | {low['share']:.3f} → {high['share']:.3f} |"
        )
    matched_rows = []
    for n, n_high in MATCHED if "deterministic" in kinds else ():
        for seed in (0, 1, 2, 3):
            low = cache.get(f"held deterministic {n} {seed} {TORQUES[0]:g}", None)
            high = cache.get(
                f"held deterministic {n_high} {seed} {TORQUES[1]:g} steps {n}",
                lambda n=n, n_high=n_high, seed=seed: held(
                    "deterministic", n_high, seed, TORQUES[1], step_nodes=n
                ),
            )
            ks = " | ".join(f"{_exponent(low, high, p):.2f}" for p in PARTS)
            matched_rows.append(
                f"| {n} → {n_high} | {seed} | {high['converged']} of {high['steps']} | {ks} | "
                f"{low['share']:.3f} → {high['share']:.3f} |"
            )
    path_rows = []
    for kind, rpm, transport in [p for p in PATH if p[0] in kinds]:
        key = f"path {kind} {rpm:g}" + ("" if transport == "eulerian" else f" {transport}")
        low, high = at_both_torques(
            key, lambda t, kind=kind, rpm=rpm, tr=transport: path(kind, rpm, t, tr)
        )
        ratios = " | ".join(f"{high[p] / low[p]:.2f}" for p in PARTS)
        path_rows.append(
            f"| {kind}{'' if transport == 'eulerian' else ', characteristic (BDF2)'} | {rpm:.0f} | "
            f"{low['converged']} + {high['converged']} of 2 × "
            f"{low['steps']} | {low['total'] * 1e3:.1f} | {low['sliding'] * 1e3:.1f} | "
            f"{low['rolling'] * 1e3:.1f} | {ratios} |"
        )
    matched_block = (
        [
            "",
            "The grid follows the Hertz half-width (b ∝ √W): on n nodes the 1500 N m contact's "
            "cells are 1.46× the 700 N m contact's. The deterministic 1500 N m contact again on "
            "as many nodes as keep the 700 N m cells (1.47×), with the same steps and window:",
            "",
            "| nodes at 700 → 1500 N m | seed | converged at 1500 N m | k total | k sliding | "
            "k rolling | k asperity | share |",
            "|---|---|---|---|---|---|---|---|",
            *matched_rows,
        ]
        if matched_rows
        else []
    )
    body = "\n".join(
        [
            "## A contact's loss against its load: statistical against deterministic asperity "
            "contact (`load_exponent.py`)",
            "",
            f"Machine: {machine()}. Ground preset (unfiltered), Mil-L-23699, 90 °C inlet. Held: "
            "the pitch-point contact (SRR 0.3, 3500 rpm, iso-thermal) at the loads of 700 and "
            "1500 N m on one pair, marched over 500 µm of rolling (Δt = Δx/ur, backward Euler), "
            "means over the last three quarters of the converged steps; the loss at 700 N m per "
            "width, kW/m; k = ln(Φ1500/Φ700)/ln(2.143) per part (sliding: the fluid's η* us²/h "
            "and the asperities' μb p |us|; asperity: that last part alone); share: the load on "
            "asperity contact, 700 → 1500 N m.",
            "",
            "| asperity model | nodes | seed | converged | total at 700 N m | sliding | rolling | "
            "k total | k sliding | k rolling | k asperity | share |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|",
            *held_rows,
            *matched_block,
            "",
            "Along the path: one engagement (quasi-static load sharing of the calibrated pair, "
            "257 nodes, thermal, Δt = Δx/ur of the pitch contact; backward Euler, Eulerian unless "
            "marked), its friction energy at "
            "700 N m in mJ over the 20 mm face width, and the ratio 1500/700 N m of each part "
            "(the torque ratio is 2.14: above it, Ψ falls with the torque, R7).",
            "",
            "| asperity model | rpm | converged | total at 700 N m, mJ | sliding | rolling | "
            "ratio total | sliding | rolling | asperity |",
            "|---|---|---|---|---|---|---|---|---|---|",
            *path_rows,
        ]
    )
    if args.statistical_only:
        body = body.replace(
            "statistical against deterministic asperity contact", "the statistical film alone"
        )
        write_section("load_exponent_statistical", body, README)
    else:
        write_section("load_exponent", body, README)


if __name__ == "__main__":
    main()
