"""The contact of Fig. 12 and R10 on finer grids: which grid and which profile give a film that
no longer moves.

R10 (REFERENCE §7): at roll angle 17° and speed E, ground surfaces give asperity pressures above
3 GPa, polished ones a full film with p well below 2 GPa. The figures solve that contact with the
roughness profiles in the film (steady, iso-thermal deterministic mixed EHL at the coupled model's
load and surface velocities). The synthetic profiles (exponential autocorrelation) have no finest
scale, so their film moves with the grid (``roughness_resolution``); a measured profile is
band-limited by the stylus's short-wave cutoff λs (ISO 3274: 2.5 µm for λc = 0.8 mm), which
``short_cutoff`` applies. This benchmark solves the R10 contact, quasi-static loads at the speed
given (the figures' own reproduction path, ``jaxgear.paper.field_contact``), with both profiles,
unfiltered and at λs = 2.5 µm, on 513-4097 nodes.

Run: ``python studies/roughness_resolution/fig12_resolution.py [--nodes 513 1025 2049 4097]
[--rpm 3500] [--rows FILE.json]``. Writes the ``fig12_resolution`` section of
studies/roughness_resolution/README.md.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

ROOT = Path(__file__).resolve().parents[2]
README = Path(__file__).with_name("README.md")  # this study's sections
sys.path.insert(0, str(ROOT / "benchmarks"))  # _report
sys.path.insert(0, str(Path(__file__).parent))

from _report import ROWS_HELP, RowCache, machine, write_section  # noqa: E402
from roughness_resolution import add_cutoffs, timed_solve  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.paper import reference, reproduce  # noqa: E402

FACE_WIDTH = 0.02  # m, the paper's pair
ROLL_ANGLE = 17.0  # degrees of gear 1 (Fig. 12)


def r10_contact(rpm: float):
    """The loaded contact nearest 17° of a quasi-static quick reproduction at ``rpm`` (the loads of
    the calibrated pair's mesh cycle at 700 N m, 24 positions), and its roll angle."""
    repro = reproduce.reproduce_paper(
        jg.Fidelity(dynamics="quasi_static"),
        quick=True,
        speeds_rpm=[rpm],
        variant_speeds_rpm=[rpm],
    )
    result = repro.quasi_static
    i, slot, roll = reproduce._slot_at(repro, ROLL_ANGLE, result.tooth_force[0])
    return reproduce.field_contact(repro, result, 0, i, slot), roll, repro.lubricant


def _row(contact, lub, kind, cutoff_um, n):
    surf = reproduce.field_surfaces(kind, None if cutoff_um == 0.0 else cutoff_um * 1e-6)
    sol, wall = timed_solve(contact, lub, surf, n)
    dx = float(sol.x[1] - sol.x[0])
    label = "unfiltered" if cutoff_um == 0.0 else f"λs = {cutoff_um:g} µm"
    row = (
        f"| {kind} | {label} | {n} | {dx * 1e6:.2f} | {bool(sol.converged)} | "
        f"{int(sol.iterations)} | {wall:.1f} | {float(sol.contact_load_share) * 100:.2f} | "
        f"{float(sol.p_max) / 1e9:.3f} | {float(sol.h_min) * 1e6:.3f} | "
        f"{float(sol.power_loss) * FACE_WIDTH:.0f} |"
    )
    print(row, flush=True)
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, nargs="+", default=[513, 1025, 2049, 4097])
    add_cutoffs(ap, [0.0, reference.FIELD_SHORT_CUTOFF * 1e6])
    ap.add_argument("--kinds", nargs="+", default=["polished", "ground"])
    ap.add_argument("--rpm", type=float, default=3500.0)
    ap.add_argument("--rows", type=Path, help=ROWS_HELP)
    args = ap.parse_args(argv)
    cache = RowCache(args.rows)
    contact, roll, lub = r10_contact(args.rpm)
    order = {"polished": 0, "ground": 1}
    for kind in args.kinds:
        for cut in args.cutoffs:
            for n in args.nodes:
                key = f"{order[kind]} {cut:g} {n} {args.rpm:g}"
                cache.get(key, lambda kind=kind, cut=cut, n=n: _row(contact, lub, kind, cut, n))
    rows = [
        cache.saved[k]
        for k in sorted(cache.saved, key=lambda k: tuple(float(v) for v in k.split()))
        if float(k.split()[3]) == args.rpm
    ]
    body = "\n".join(
        [
            "## The contact of Fig. 12 and R10 on finer grids (`fig12_resolution.py`)",
            "",
            f"Machine: {machine()}. The loaded contact nearest 17° (gear 1 roll angle "
            f"{roll:.2f}°) of the calibrated pair's quasi-static mesh cycle at {args.rpm:.0f} rpm, "
            f"700 N m, 90 °C (24 positions; load {float(contact.load_per_width) * FACE_WIDTH:.0f}"
            f" N, ph {float(contact.hertz_pressure) / 1e9:.3f} GPa, u1 "
            f"{float(contact.u1):.2f} m/s, u2 {float(contact.u2):.2f} m/s). Steady iso-thermal "
            'deterministic solve (`EHLModel(mixed="deterministic")`, what Fig. 12 uses) of the '
            "presets' profiles (seed 0; ground Rq 0.40 µm, polished 0.05 µm per surface, ℓ 20 µm), "
            "unfiltered and filtered at λs (ISO 16610-21 Gaussian, Rq kept). Wall: one call, the "
            "first of each grid with its compilation. Loss per contact over the 20 mm face width.",
            "",
            "| surfaces | profile | nodes | Δx, µm | converged | Newton its | wall, s | "
            "asperity load share, % | p_max, GPa | h_min, µm | loss, W |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("fig12_resolution", body, README)


if __name__ == "__main__":
    main()
