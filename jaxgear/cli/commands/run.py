"""``jaxgear run``: the main job — the paper's baseline speed sweep on the embedded default.

500-4200 rpm in 25 rpm steps, ground surfaces, 700 N m, 90 °C inlet, Mil-L-23699, the paper's gear pair,
tribo-dynamic against quasi-static at the chosen fidelity. Writes to ``--out`` (default ``results/``):
``sweep.csv`` (every speed, both models), ``summary.json``, and the figures ``dte_rms.png`` (paper
Fig. 3), ``power_loss.png`` (Fig. 4a) and ``efficiency.png`` (Fig. 4b). Finished chunks are kept in
``<out>/checkpoint``: an interrupted run resumes without recomputing them.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from jaxgear.cli.config import FIDELITY_PRESETS

#: Most speeds one run takes (the paper's sweep has 149).
MAX_SPEEDS = 100_000


def _speeds(text: str) -> np.ndarray:
    try:
        start, stop, step = (float(v) for v in text.split(":"))
    except ValueError:
        raise ValueError(
            f"--speeds = {text!r} must be START:STOP:STEP in rpm, e.g. 500:4200:25"
        ) from None
    if not all(map(math.isfinite, (start, stop, step))) or not (
        start > 0 and stop >= start and step > 0
    ):
        raise ValueError(
            f"--speeds = {text!r} is out of range; valid range: finite 0 < START <= STOP, STEP > 0 "
            "(rpm)"
        )
    # Count before allocating: 1:1e9:1 would otherwise fill the memory before any check.
    count = math.floor((stop - start) / step + 0.5) + 1
    if count > MAX_SPEEDS:
        raise ValueError(
            f"--speeds = {text!r} gives {count} speeds; valid range: at most {MAX_SPEEDS} speeds"
        )
    return np.arange(start, stop + 0.5 * step, step)


def register(sub) -> None:
    p = sub.add_parser(
        "run",
        help="the main job: the paper's baseline speed sweep, tribo-dynamic vs quasi-static",
        description=__doc__.split("\n\n")[0] + "\n\n" + __doc__.split("\n\n")[1],
    )
    p.add_argument("--out", type=Path, default=Path("results"), help="output directory")
    p.add_argument(
        "--speeds", default="500:4200:25", help="START:STOP:STEP in rpm (default 500:4200:25)"
    )
    p.add_argument("--torque", type=float, default=700.0, help="gear 1 torque, N m (default 700)")
    p.add_argument(
        "--inlet-temperature", type=float, default=90.0, help="oil inlet, °C (default 90)"
    )
    p.add_argument("--surfaces", choices=("ground", "polished", "smooth"), default="ground")
    p.add_argument(
        "--fidelity",
        choices=FIDELITY_PRESETS,
        default="fast",
        help="fidelity (default fast); auto: the cheapest rungs whose measured error stays under "
        "--tolerance over this sweep (jg.Fidelity.auto), with its reasons printed",
    )
    p.add_argument(
        "--tolerance",
        type=float,
        default=0.05,
        help="relative error tolerance of --fidelity auto on the power loss (default 0.05)",
    )
    p.add_argument("--chunk-size", type=int, default=50, help="speeds per chunk (default 50)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import jaxgear as jg
    from jaxgear.plotting import plot_dte_rms, plot_efficiency, plot_power_loss
    from jaxgear.sweep import sweep

    speeds = _speeds(args.speeds)
    if args.chunk_size < 1:
        raise ValueError(f"--chunk-size = {args.chunk_size} is out of range; valid range: >= 1")
    pair = _default_pair(jg)
    lub = jg.presets.mil_l_23699()
    surf = getattr(jg.presets, args.surfaces)()
    op = jg.OperatingPoint(
        torque=args.torque,
        speed_rpm=float(speeds[0]),
        inlet_temperature=args.inlet_temperature + 273.15,
    )
    fid, reasons = _fidelity(args, pair, lub, surf, op, speeds)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    td = sweep(
        pair,
        lub,
        surf,
        op,
        speeds_rpm=speeds,
        fidelity=fid,
        mode="continuation",
        chunk_size=args.chunk_size,
        checkpoint_dir=out / "checkpoint" / "tribo_dynamic",
        progress=not args.no_progress,
    )
    t_td = time.perf_counter() - t0
    qs = sweep(
        pair,
        lub,
        surf,
        op,
        speeds_rpm=speeds,
        fidelity=fid.replace(dynamics="quasi_static"),
        chunk_size=args.chunk_size,
        checkpoint_dir=out / "checkpoint" / "quasi_static",
        progress=not args.no_progress,
    )
    t_all = time.perf_counter() - t0

    _write_csv(out / "sweep.csv", speeds, td, qs)
    ok, att = ~td.failed, td.on_attractor
    plot_dte_rms(speeds, td.dte_rms, out / "dte_rms.png", ok=ok, attractor=att)
    parts = lambda r: {
        "total": r.power_loss,
        "sliding": r.power_loss_sliding,
        "rolling": r.power_loss_rolling,
    }
    plot_power_loss(speeds, parts(td), parts(qs), out / "power_loss.png", ok=ok, attractor=att)
    plot_efficiency(
        speeds, td.efficiency, qs.efficiency, out / "efficiency.png", ok=ok, attractor=att
    )
    summary = _summary(speeds, td, qs, fid, args, t_td, t_all)
    if reasons:
        summary["inputs"]["fidelity_reasons"] = reasons
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    print(json.dumps(summary["headline"], indent=1))
    print(
        f"wrote {out / 'sweep.csv'}, {out / 'summary.json'}, dte_rms.png, power_loss.png, "
        f"efficiency.png in {out}"
    )
    on = summary["headline"]["points_on_attractor"]
    if on:
        print(
            f"{on} of {len(speeds)} speeds have no stable periodic orbit (parametric instability "
            "or rattling): their values are means over the attractor the gears settle on "
            "(status 6 in sweep.csv; listed in summary.json)"
        )
    bad = summary["headline"]["points_not_converged"]
    if bad:
        print(
            f"{bad} of {len(speeds)} speeds did not converge (kept, flagged in sweep.csv and "
            "summary.json)"
        )
    return 0


def _fidelity(args, pair, lub, surf, op, speeds):
    """(Fidelity, reasons or None) for ``--fidelity``; auto prints its reasons."""
    from jaxgear.fidelity import Fidelity

    if args.fidelity != "auto":
        return Fidelity.named(args.fidelity), None
    from jaxgear.fidelity.choose import choose_fidelity

    choice = choose_fidelity(pair, lub, surf, op, args.tolerance, speeds_rpm=speeds)
    print(choice.reasons, flush=True)
    return choice.fidelity, choice.reasons


def _default_pair(jg):
    calibrated = getattr(jg.presets, "li2015_pair_calibrated", None)
    return calibrated() if calibrated is not None else jg.presets.li2015_pair()


def _write_csv(path, speeds, td, qs):
    import csv

    cols = {
        "speed_rpm": speeds,
        "power_loss_W": td.power_loss,
        "power_loss_sliding_W": td.power_loss_sliding,
        "power_loss_rolling_W": td.power_loss_rolling,
        "efficiency_percent": 100 * td.efficiency,
        "dte_rms_um": 1e6 * td.dte_rms,
        "status": td.status,
        "power_loss_back_W": td.power_loss_back,
        "back_contact_share": td.back_contact_share,
        "qs_power_loss_W": qs.power_loss,
        "qs_power_loss_sliding_W": qs.power_loss_sliding,
        "qs_power_loss_rolling_W": qs.power_loss_rolling,
        "qs_efficiency_percent": 100 * qs.efficiency,
        "qs_status": qs.status,
    }
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(list(cols))
        for i in range(len(speeds)):
            w.writerow([f"{float(np.asarray(v)[i]):.10g}" for v in cols.values()])


def _peak(speeds, values, lo, hi):
    mask = (speeds >= lo) & (speeds <= hi) & np.isfinite(values)
    if not mask.any():
        return None
    i = np.argmax(np.where(mask, values, -np.inf))
    return {"speed_rpm": float(speeds[i]), "dte_rms_um": float(values[i] * 1e6)}


def _summary(speeds, td, qs, fid, args, t_td, t_all):
    from jaxgear.paper.reproduce import _resonance_dte

    ok = ~td.failed
    resonance = _resonance_dte(td)
    return {
        "headline": {
            "speeds_rpm": [float(speeds[0]), float(speeds[-1]), len(speeds)],
            "mean_efficiency_percent": float(np.nanmean(100 * td.efficiency)),
            "min_efficiency_percent": float(np.nanmin(100 * td.efficiency)),
            "max_power_loss_W": float(np.nanmax(td.power_loss)),
            "dte_rms_peak_low": _peak(speeds, td.dte_rms, 0, 2600),
            "dte_rms_peak_high": _peak(speeds, td.dte_rms, 2600, 1e9),
            # the same among the speeds whose teeth do not strike the back flanks: the mesh
            # resonances' peaks, apart from a back-flank rattle's larger DTE (figures' R1)
            "dte_rms_resonance_peak_low": _peak(speeds, resonance, 0, 2600),
            "dte_rms_resonance_peak_high": _peak(speeds, resonance, 2600, 1e9),
            "points_not_converged": int(np.sum(~ok)),
            "points_on_attractor": int(np.sum(td.on_attractor)),
            # rattling teeth striking the back flanks (SimulationResult.back_contact_share)
            "points_with_back_contact": int(
                np.sum(ok & (np.nan_to_num(td.back_contact_share) > 0))
            ),
            "wall_time_s": round(t_all, 2),
        },
        "inputs": {
            "torque_Nm": args.torque,
            "inlet_temperature_C": args.inlet_temperature,
            "surfaces": args.surfaces,
            "fidelity": {
                f: getattr(fid, f)
                for f in (
                    "dynamics",
                    "friction",
                    "thermal",
                    "transient",
                    "coupling",
                    "n_positions",
                    "n_nodes",
                    "steps_per_period",
                    "back_flank",
                )
            },
        },
        "timing_s": {"tribo_dynamic_sweep": round(t_td, 2), "total": round(t_all, 2)},
        "not_converged": [
            {"speed_rpm": float(s), "status": name}
            for s, name, good in zip(speeds, td.status_names(), ok)
            if not good
        ],
        "on_attractor": [float(s) for s, on in zip(speeds, td.on_attractor) if on],
        "back_contact": [
            {"speed_rpm": float(s), "share": float(b), "power_loss_back_W": float(p)}
            for s, b, p, good in zip(speeds, td.back_contact_share, td.power_loss_back, ok)
            if good and b > 0
        ],
    }
