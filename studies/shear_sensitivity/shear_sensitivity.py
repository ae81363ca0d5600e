"""Sensitivity of the paper-fidelity loss to the fluid shear law (REFERENCE §4).

The paper's η* = η/cosh(τm/τ0) keeps the fluid shear stress below τ0; the exact Eyring law
τ = τ0 asinh(η us/(τ0 h)) does not. REFERENCE §4 asks for both and the sensitivity. This runs the
paper fidelity (thermal, statistical mixed, transient; 32 positions × 257 nodes) at the nominal
speeds of the points A-E (``figures.NOMINAL_POINTS_RPM``), quasi-static and tribo-dynamic,
with each shear law and the same τ0 (5 MPa, the preset's), and writes its section of
studies/shear_sensitivity/README.md.

Run: ``python studies/shear_sensitivity/shear_sensitivity.py [--quick | --trends]`` (``--quick``:
quasi-static only, points B and E; ``--trends``: the paper's trends R5-R9 and R3 at 3300 rpm
under each law, section ``shear_trends``; ``--trends --density-product 0.08``: the same at another
Greenwood-Tripp nβσ, with R3 at the speeds of A-E, section ``shear_trends_asperity``). Full: about 10 min on 2 cores, the
trends about 20 min; ``--limiting``: where a limiting shear stress τL = Λ p binds, section
``shear_limiting``, about 10 min. Run one JAX process at a time on 2 cores: two at once slowed each point here
by 10-40× (thread pools contending), not 2×.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

ROOT = Path(__file__).resolve().parents[2]
README = Path(__file__).with_name("README.md")  # this study's sections
sys.path.insert(0, str(ROOT / "benchmarks"))  # _report

from _report import effective_friction, machine, write_section  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.paper.reference import (  # noqa: E402
    NEARLY_EQUAL,
    NOMINAL_POINTS_RPM,
    PAPER_QUASI_STATIC_W,
    PAPER_R3,
    PAPER_TRIBO_DYNAMIC_W,
)

PAIR = jg.presets.li2015_pair_calibrated()
LUB = jg.presets.mil_l_23699()
SURF = jg.presets.ground()
SHEARS = ("eyring_paper", "eyring_exact", "eyring_split")


def _r3_table(rows, points):
    """TD/QS per shear law and point against the paper's R3 (lower / higher / nearly equal)."""
    loss = {(dyn, shear, name): total for dyn, shear, name, total, *_ in rows}
    out = [
        "R3, tribo-dynamic against quasi-static (the paper's direction in brackets; C counts as "
        f"nearly equal within {100 * NEARLY_EQUAL:.0f} %):",
        "",
        "| shear | " + " | ".join(f"{n} ({PAPER_R3[n]})" for n in points) + " |",
        "|---|" + "---|" * len(points),
    ]
    for shear in SHEARS:
        cells = []
        for n in points:
            td, qs = loss[("tribo_dynamic", shear, n)], loss[("quasi_static", shear, n)]
            cells.append(f"{100 * (td / qs - 1):+.1f} %")
        out.append(f"| {shear} | " + " | ".join(cells) + " |")
    return out


def main(quick: bool = False):
    points = ("B", "E") if quick else ("A", "B", "C", "D", "E")
    dynamics = ("quasi_static",) if quick else ("quasi_static", "tribo_dynamic")
    rows = []
    for dyn in dynamics:
        for shear in SHEARS:
            fid = jg.Fidelity.paper(dynamics=dyn, shear=shear)
            t_first = None
            for name in points:
                op = jg.OperatingPoint(700.0, NOMINAL_POINTS_RPM[name], 363.15)
                t0 = time.perf_counter()
                r = jg.simulate(PAIR, LUB, SURF, op, fidelity=fid)
                jax.block_until_ready(r.power_loss)
                dt = time.perf_counter() - t0
                t_first = dt if t_first is None else t_first
                sliding = float(r.power_loss_sliding)
                total = float(r.power_loss)
                mu = effective_friction(r)
                rows.append((dyn, shear, name, total, sliding, mu, int(r.status), dt))
                print(
                    dyn,
                    shear,
                    name,
                    f"{total:.1f} W",
                    f"mu_eff {mu:.4f}",
                    int(r.status),
                    f"{dt:.1f} s",
                    flush=True,
                )
    lines = [
        "## Fluid shear law: the paper's η* against exact Eyring (`shear_sensitivity.py`)",
        "",
        f"Machine: {machine()}. Paper fidelity (thermal, statistical mixed, transient, 32 positions "
        "× 257 nodes), calibrated pair, ground, 700 N m, 90 °C, τ0 = 5 MPa; the points at their "
        "nominal speeds. μ_eff = sliding loss / Σ W |us| over the cycle (the mean friction "
        "coefficient the loss implies). Time: the first point of each row group includes compilation.",
        "",
        "| dynamics | shear | point | rpm | Φ̄ (W) | paper (W) | sliding (W) | μ_eff | status | time (s) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for dyn, shear, name, total, sliding, mu, status, dt in rows:
        paper = (PAPER_QUASI_STATIC_W if dyn == "quasi_static" else PAPER_TRIBO_DYNAMIC_W).get(name)
        paper = "-" if paper is None else f"{paper:.0f}"
        lines.append(
            f"| {dyn} | {shear} | {name} | {NOMINAL_POINTS_RPM[name]:.0f} | {total:.1f} | "
            f"{paper} | {sliding:.1f} | {mu:.4f} | {status} | {dt:.1f} |"
        )
    lines += [
        "",
        "The paper implies μ_eff ≈ 0.02-0.04 (REFERENCE §6). Status: 0 ok, 1 fixed point, "
        "2 dynamics, 3 a contact solve, 4 non-finite, 6 mean over an attractor.",
    ]
    if len(dynamics) == 2:
        lines += ["", *_r3_table(rows, points)]
    write_section("shear_sensitivity", "\n".join(lines), README)


#: (label, overrides of the baseline) for R5-R9: iso-thermal, 60 °C inlet, 1500 N m, polished.
VARIANTS = (
    ("baseline", {}),
    ("iso-thermal", {"thermal": False}),
    ("60 °C", {"inlet_temperature": 333.15}),
    ("1500 N m", {"torque": 1500.0}),
    ("polished", {"surfaces": "polished"}),
)
TREND_SPEEDS_RPM = (1000.0, 2500.0, 4200.0)
#: R3 at the calibrated pair's points: A, B, C at their nominal speeds, D at 3300 and 3400 rpm, E.
R3_SPEEDS_RPM = (1700.0, 1800.0, 2600.0, 3300.0, 3400.0, 3500.0)


def trends(density_product=None):
    """R5-R9 under each shear law: tribo-dynamic paper fidelity at TREND_SPEEDS_RPM for the
    baseline and each variant, and R3 at 3300 rpm (just below the calibrated pair's 3500 rpm-mode
    resonance, which sits at about 3375 rpm: where D falls relative to this model's peak).

    ``density_product``: the Greenwood-Tripp nβσ instead of the default 0.05 (0.08 brings the
    quasi-static level to the paper's, ``studies/friction_sensitivity``); then the paper's
    η* and the split law only (the exact law equals the split one within 0.2 % here), R3 at the
    speeds of A-E and 3300 rpm, and the section ``shear_trends_asperity``."""
    extra = {} if density_product is None else {"asperity_density_product": density_product}
    shears = SHEARS if density_product is None else ("eyring_paper", "eyring_split")
    r3_speeds = (3300.0,) if density_product is None else R3_SPEEDS_RPM
    rows, r3 = [], {}
    for shear in shears:
        for label, over in VARIANTS:
            fid = jg.Fidelity.paper(shear=shear, thermal=over.get("thermal", True), **extra)
            surf = jg.presets.polished() if over.get("surfaces") == "polished" else SURF
            for rpm in TREND_SPEEDS_RPM:
                op = jg.OperatingPoint(
                    over.get("torque", 700.0), rpm, over.get("inlet_temperature", 363.15)
                )
                t0 = time.perf_counter()
                r = jg.simulate(PAIR, LUB, surf, op, fidelity=fid)
                total = float(r.power_loss)
                rolling = float(r.power_loss) - float(r.power_loss_sliding)
                dt = time.perf_counter() - t0
                rows.append(
                    (shear, label, rpm, total, rolling / total, float(r.efficiency), int(r.status))
                )
                print(shear, label, rpm, f"{total:.1f} W", int(r.status), f"{dt:.1f} s", flush=True)
        cells = []
        for rpm in r3_speeds:
            op = jg.OperatingPoint(700.0, rpm, 363.15)
            td = jg.simulate(PAIR, LUB, SURF, op, fidelity=jg.Fidelity.paper(shear=shear, **extra))
            qs_fid = jg.Fidelity.paper(shear=shear, dynamics="quasi_static", **extra)
            qs = jg.simulate(PAIR, LUB, SURF, op, fidelity=qs_fid)
            rel = float(td.power_loss) / float(qs.power_loss) - 1
            mark = "‡" if int(td.status) == 6 else ("" if int(td.status) == 0 else "†")
            cells.append(
                f"{float(td.power_loss):.0f}/{float(qs.power_loss):.0f} W {100 * rel:+.1f} %{mark}"
            )
            print(shear, "R3", rpm, cells[-1], flush=True)
        r3[shear] = "; ".join(cells)

    loss = {(sh, lab, rpm): (tot, roll, eff, st) for sh, lab, rpm, tot, roll, eff, st in rows}
    lines = [
        "## Fluid shear law and the paper's trends R5-R9 (`shear_sensitivity.py --trends`)",
        "",
        f"Machine: {machine()}. Tribo-dynamic paper fidelity (thermal unless iso-thermal, "
        "statistical mixed, transient; 32 positions × 257 nodes), calibrated pair, ground, "
        "700 N m, 90 °C unless the variant says otherwise; cold single points (a status-6 point "
        "is a mean over an attractor). Φ̄ in W, Ψ in %, rolling: rolling share of Φ̄.",
        "",
        "| shear | variant | "
        + " | ".join(f"Φ̄ {v:.0f} rpm | Ψ {v:.0f} rpm | rolling {v:.0f}" for v in TREND_SPEEDS_RPM)
        + " | status |",
        "|---|---|" + "---|---|---|" * len(TREND_SPEEDS_RPM) + "---|",
    ]
    for shear in shears:
        for label, _ in VARIANTS:
            cells, stats = [], []
            for rpm in TREND_SPEEDS_RPM:
                tot, roll, eff, st = loss[(shear, label, rpm)]
                cells.append(f"{tot:.1f} | {100 * eff:.3f} | {100 * roll:.0f} %")
                stats.append(str(st))
            lines.append(f"| {shear} | {label} | " + " | ".join(cells) + f" | {','.join(stats)} |")
    lines += [
        "",
        "Ratios to the baseline of the same shear law (the paper's direction in brackets):",
        "",
    ]
    lines += [
        "| shear | R5 iso-thermal/thermal (> 1, growing) | R6 60 °C/90 °C (< 1) | "
        "R7 1500/700 N m Φ̄ (much > 1), ΔΨ (slightly < 0, points) | R8 polished/ground (< 1) | "
        f"R3 TD/QS at {', '.join(f'{v:.0f}' for v in r3_speeds)} rpm |",
        "|---|---|---|---|---|---|",
    ]
    for shear in shears:

        def ratio(label, rpm, shear=shear):
            return loss[(shear, label, rpm)][0] / loss[(shear, "baseline", rpm)][0]

        def col(label, shear=shear):
            return " / ".join(f"{ratio(label, v):.2f}" for v in TREND_SPEEDS_RPM)

        dpsi = " / ".join(
            f"{100 * (loss[(shear, '1500 N m', v)][2] - loss[(shear, 'baseline', v)][2]):+.3f}"
            for v in TREND_SPEEDS_RPM
        )
        lines.append(
            f"| {shear} | {col('iso-thermal')} | {col('60 °C')} | {col('1500 N m')}, {dpsi} | "
            f"{col('polished')} | {r3[shear]} |"
        )
    lines += [
        "",
        f"Each ratio cell lists {', '.join(f'{v:.0f}' for v in TREND_SPEEDS_RPM)} rpm in turn. "
        "R3: tribo-dynamic/quasi-static Φ̄ (‡ mean over an attractor, † not converged); the "
        "paper: lower at A (1700) and D (just below the 3500 rpm peak), higher at B (1800) and "
        "E (the peak), nearly equal at C.",
    ]
    if density_product is None:
        write_section("shear_trends", "\n".join(lines), README)
    else:
        lines[0] = (
            f"## The same at nβσ = {density_product} (`shear_sensitivity.py --trends "
            f"--density-product {density_product}`)"
        )
        write_section("shear_trends_asperity", "\n".join(lines), README)


LIMITS = (0.1, 0.05, 0.03, 0.02, 0.01, 0.005)


def limiting():
    """Where a limiting shear stress τL = Λ p (Bair & Winer) binds under the Eyring stress
    (``shear="eyring_split"``): the closed-form contact's fluid traction with the cap over without
    it at the pitch contact, and the coupled quasi-static paper fidelity's R5-R7 ratios with and
    without a binding cap. Section ``shear_limiting``."""
    from helpers import gear_contact  # tests/helpers.py: the paper's pitch contact

    from jaxgear.lubrication.ehl_formula import ehl_formula_contact

    def traction(torque, rpm, t_in, limit):
        c = gear_contact(torque, rpm, 0.3, t_in=t_in)
        f = ehl_formula_contact(
            c.reduced_radius, c.load_per_width, c.u1, c.u2, c.e_reduced, LUB, t_in, 0.0,
            shear="eyring_split", limiting_shear=limit,
        )  # fmt: skip
        return abs(float(f.friction_sliding - f.friction_asperity)), float(c.load_per_width)

    cases = [(700.0, 1000.0, 363.15), (700.0, 4200.0, 363.15), (1500.0, 1000.0, 363.15),
             (1500.0, 4200.0, 363.15), (700.0, 1000.0, 333.15), (700.0, 4200.0, 333.15)]  # fmt: skip
    lines = [
        "## A limiting shear stress τL = Λ p under the Eyring stress "
        "(`shear_sensitivity.py --limiting`)",
        "",
        f"Machine: {machine()}. Closed-form contact (`ehl_formula`, smooth surfaces, "
        '`shear="eyring_split"`), pitch contact carrying the whole load, slide-to-roll 0.3: the '
        "fluid friction coefficient without a cap, and the fluid traction with the cap over "
        "without it.",
        "",
        "| torque (N m) | rpm | inlet (°C) | μ fluid, no cap | "
        + " | ".join(f"Λ = {v}" for v in LIMITS)
        + " |",
        "|---|---|---|---|" + "---|" * len(LIMITS),
    ]
    for torque, rpm, t_in in cases:
        free, w = traction(torque, rpm, t_in, None)
        cells = [f"{traction(torque, rpm, t_in, v)[0] / free:.3f}" for v in LIMITS]
        lines.append(
            f"| {torque:.0f} | {rpm:.0f} | {t_in - 273.15:.0f} | {free / w:.4f} | "
            + " | ".join(cells)
            + " |"
        )
        print(lines[-1], flush=True)
    variants = (("baseline", {}), ("iso-thermal", {"thermal": False}),
                ("60 °C", {"inlet_temperature": 333.15}), ("1500 N m", {"torque": 1500.0}))  # fmt: skip
    coupled = {}
    for limit in (None, 0.01):
        for label, over in variants:
            fid = jg.Fidelity.paper(
                shear="eyring_split", dynamics="quasi_static", thermal=over.get("thermal", True),
                limiting_shear_coefficient=limit,
            )  # fmt: skip
            for rpm in TREND_SPEEDS_RPM:
                op = jg.OperatingPoint(
                    over.get("torque", 700.0), rpm, over.get("inlet_temperature", 363.15)
                )
                r = jg.simulate(PAIR, LUB, SURF, op, fidelity=fid)
                coupled[(limit, label, rpm)] = (float(r.power_loss), int(r.status))
                print(limit, label, rpm, coupled[(limit, label, rpm)], flush=True)
    lines += [
        "",
        "Coupled, quasi-static paper fidelity (thermal unless iso-thermal, statistical mixed, "
        "transient, 32 × 257), ground, `eyring_split`, nβσ = 0.05: Φ̄ at "
        f"{' / '.join(f'{v:.0f}' for v in TREND_SPEEDS_RPM)} rpm and the ratios of R5-R7.",
        "",
        "| Λ | Φ̄ baseline (W) | R5 iso-thermal/thermal | R6 60 °C/90 °C | R7 1500/700 N m | status |",
        "|---|---|---|---|---|---|",
    ]
    for limit in (None, 0.01):

        def col(label, limit=limit):
            return " / ".join(
                f"{coupled[(limit, label, v)][0] / coupled[(limit, 'baseline', v)][0]:.2f}"
                for v in TREND_SPEEDS_RPM
            )

        base = " / ".join(f"{coupled[(limit, 'baseline', v)][0]:.0f}" for v in TREND_SPEEDS_RPM)
        stats = {st for (lim, _, _), (_, st) in coupled.items() if lim == limit}
        lines.append(
            f"| {'none' if limit is None else limit} | {base} | {col('iso-thermal')} | "
            f"{col('60 °C')} | {col('1500 N m')} | {', '.join(map(str, sorted(stats)))} |"
        )
    write_section("shear_limiting", "\n".join(lines), README)


if __name__ == "__main__":
    if "--limiting" in sys.argv:
        sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests"))
        limiting()
    elif "--trends" in sys.argv:
        dp = None
        if "--density-product" in sys.argv:
            dp = float(sys.argv[sys.argv.index("--density-product") + 1])
        trends(dp)
    else:
        main(quick="--quick" in sys.argv)
