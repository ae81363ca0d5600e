"""Does the deterministic film converge as the grid refines? The roughness decides.

The synthetic ground profile (exponential autocorrelation, Rq 0.40 µm, ℓ 20 µm) has no finest
scale: its spectrum falls as 1/f², so a finer EHL grid samples steeper asperities (rms slope ∝
1/√Δx) and the film's asperity pressures do not settle. A measured profile has a finest scale, the
stylus instrument's short-wave cutoff λs (ISO 3274: 2.5 µm for ground gear flanks), which
``short_cutoff`` applies to the synthetic profile (the ISO 16610-21 Gaussian filter; Rq kept).
This benchmark solves the same steady deterministic contact (the pitch point at speed E, iso-thermal)
on each grid with both profiles and reports how the film, the asperity load and the loss move.

Run: ``python studies/roughness_resolution/roughness_resolution.py [--nodes 257 513 1025 2049]
[--rpm 3500] [--polished] [--rows FILE.json]``.
Writes the ``roughness_resolution`` section of studies/roughness_resolution/README.md.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
README = Path(__file__).with_name("README.md")  # this study's sections
sys.path.insert(0, str(ROOT / "benchmarks"))  # _report
sys.path.insert(0, str(Path(__file__).parents[2] / "tests"))

from _report import ROWS_HELP, RowCache, machine, write_section  # noqa: E402
from helpers import gear_contact  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.lubrication import roughness as rough  # noqa: E402
from jaxgear.paper.reference import FIELD_SHORT_CUTOFF  # noqa: E402

LUB = jg.presets.mil_l_23699()
CUTOFF = FIELD_SHORT_CUTOFF  # m, ISO 3274 λs for Ra 0.1-2 µm profiles (λc = 0.8 mm)
FACE_WIDTH = 0.02  # m, the paper's pair


SINE_WAVELENGTH = 4.096e-3 / 200  # m: 200 periods of the 8192 × 0.5 µm profile


def _sine(amplitude):
    """A single waviness of wavelength SINE_WAVELENGTH on gear 1, gear 2 smooth: a band-limited
    roughness whose resolution is known (nodes per wavelength)."""
    dx, n = rough.DEFAULT_SPACING, rough.DEFAULT_POINTS
    z = amplitude * np.sin(2.0 * np.pi * dx * np.arange(n) / SINE_WAVELENGTH)
    return rough.Surfaces(z, np.zeros(n), dx, 1.0)


def _gap_slope(surf, x):
    """rms slope (rad) of the combined roughness S1 + S2 as the grid samples it (central
    differences over 2 Δx, interior nodes)."""
    s = surf.displaced_height(0, x, 0.0) + surf.displaced_height(1, x, 0.0)
    d = (s[2:] - s[:-2]) / (x[2:] - x[:-2])
    return float(jnp.sqrt(jnp.mean(d**2)))


def _hertz_mean(h, x, contact):
    """Mean film thickness (m) over the Hertz zone |x| ≤ b (the central node's film is a local
    value of a rough film)."""
    inside = jnp.abs(x) <= contact.hertz_half_width
    return float(jnp.sum(jnp.where(inside, h, 0.0)) / jnp.sum(inside))


def timed_solve(contact, lub, surf, n):
    """The steady deterministic solve of ``contact`` with the profiles ``surf`` on ``n`` nodes
    (the profiles at their origin), and its wall time, s (one call, compilation included)."""
    model = jg.EHLModel(n_nodes=n, mixed="deterministic")
    t0 = time.perf_counter()
    sol = jg.solve_ehl(contact, lub, model, surf, displacement=jnp.zeros(2))
    jax.block_until_ready(sol.p)
    return sol, time.perf_counter() - t0


def add_cutoffs(ap, default_um):
    """The ``--cutoffs`` option (short-wave cutoffs λs in µm, 0 for the unfiltered profile)."""
    ap.add_argument(
        "--cutoffs",
        type=float,
        nargs="+",
        default=default_um,
        help="short-wave cutoffs λs, µm (0: the unfiltered profile)",
    )


def _row(label, surf, n, rpm):
    contact = gear_contact(rpm=rpm)
    sol, wall = timed_solve(contact, LUB, surf, n)
    x = sol.x
    dx = float(x[1] - x[0])
    ph = float(contact.hertz_pressure)
    row = (
        f"| {label} | {n} | {dx * 1e6:.2f} | {_gap_slope(surf, x):.3f} | {bool(sol.converged)} | "
        f"{int(sol.iterations)} | {wall:.1f} | {float(sol.contact_load_share):.3f} | "
        f"{float(sol.p_max) / ph:.2f} | {_hertz_mean(sol.h, x, contact) * 1e6:.3f} | "
        f"{float(sol.power_loss) * FACE_WIDTH:.0f} | "
        f"{float(sol.power_loss_rolling) * FACE_WIDTH:.0f} |"
    )
    print(row, flush=True)
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, nargs="+", default=[257, 513, 1025, 2049])
    add_cutoffs(ap, [0.0, CUTOFF * 1e6])
    ap.add_argument(
        "--sine-amplitude",
        type=float,
        default=0.0,
        help="also a single sinusoidal waviness of this amplitude (µm) and wavelength "
        f"{SINE_WAVELENGTH * 1e6:.2f} µm on gear 1, gear 2 smooth (0: none)",
    )
    ap.add_argument(
        "--polished",
        action="store_true",
        help="the polished surfaces (Rq 0.05 µm per surface) instead of the ground ones",
    )
    ap.add_argument("--rpm", type=float, default=3500.0)
    ap.add_argument("--rows", type=Path, help=ROWS_HELP)
    args = ap.parse_args(argv)
    cache = RowCache(args.rows)
    slopes = {}
    make, prefix = (jg.presets.polished, "p ") if args.polished else (jg.presets.ground, "")
    for cut in args.cutoffs:
        label = "unfiltered" if cut == 0.0 else f"λs = {cut:.1f} µm"
        label = f"polished, {label}" if args.polished else label
        surf = make(short_cutoff=None if cut == 0.0 else cut * 1e-6)
        slopes[label] = np.asarray(surf.rms_slope).round(3).tolist()
        for n in args.nodes:
            key = f"{prefix}{cut:g} {n} {args.rpm:g}"
            cache.get(key, lambda label=label, surf=surf, n=n: _row(label, surf, n, args.rpm))
    if args.sine_amplitude > 0.0:
        amp = args.sine_amplitude
        label = f"sine {SINE_WAVELENGTH * 1e6:.2f} µm, {amp:.2f} µm"
        for n in args.nodes:
            key = f"-{amp:g} {n} {args.rpm:g}"  # sorted before the Gaussian profiles
            cache.get(key, lambda label=label, n=n: _row(label, _sine(amp * 1e-6), n, args.rpm))

    def order(key):
        # ground rows (the sine first), then the polished ones ("p " keys); by cutoff and grid
        polished = key.startswith("p ")
        return (polished, *(float(v) for v in key.removeprefix("p ").split()))

    rows = [cache.saved[k] for k in sorted(cache.saved, key=order) if order(k)[3] == args.rpm]
    body = "\n".join(
        [
            "## Roughness resolution: the deterministic film on finer grids "
            "(`roughness_resolution.py`)",
            "",
            f"Machine: {machine()}. Pitch-point contact, {args.rpm:.0f} rpm, 700 N m, SRR 0.3, "
            "ground (Rq 0.40 µm per surface, ℓ 20 µm, seed 0; polished rows: Rq 0.05 µm), "
            "iso-thermal steady deterministic "
            'solve (the default `EHLModel(mixed="deterministic")` on each grid). Δq: rms slope of '
            "S1 + S2 as the grid samples it. Wall: one call, compilation included. Loss per "
            "contact over the 20 mm face width. The profiles' own Δq at their 0.5 µm sampling "
            f"(gear 1, gear 2; the cutoffs of this run): {slopes}.",
            "",
            "| profile | nodes | Δx, µm | Δq, rad | converged | Newton its | wall, s | "
            "asperity load share | p_max/ph | mean film over the Hertz zone, µm | loss, W | "
            "rolling loss, W |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("roughness_resolution", body, README)


if __name__ == "__main__":
    main()
