"""``jaxgear sweep --config FILE.toml``: any speed sweep of ``jg.sweep``, described in one TOML file.

The file mirrors the Python inputs: ``[gear]`` (a preset and overrides), ``[lubricant]`` (a preset and
overrides), ``[surfaces]`` (preset, scale, seed), ``[operating]`` (torque, inlet °C), ``[fidelity]``
(a preset and overrides) and ``[sweep]`` (speeds, mode, chunk size, checkpointing, inputs varied per
speed); examples/sweep.toml shows every key. Writes to ``--out`` (default ``results/``): ``sweep.csv``
(every point), ``sweep_quasi_static.csv`` (the quasi-static reference, when swept), ``summary.json``,
and ``dte_rms.png``, ``power_loss.png``, ``efficiency.png`` as ``jaxgear run`` does. Unknown keys,
wrong types and out-of-range values end with exit code 2 and a message naming the key.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from jaxgear.cli.config import FIDELITY_PRESETS


def register(sub) -> None:
    p = sub.add_parser(
        "sweep",
        help="a speed sweep described by a TOML file (gear, lubricant, surfaces, fidelity, sweep)",
        description=__doc__.split("\n\n")[0] + "\n\n" + __doc__.split("\n\n")[1],
    )
    p.add_argument("--config", type=Path, required=True, help="TOML file (see examples/sweep.toml)")
    p.add_argument("--out", type=Path, default=Path("results"), help="output directory")
    p.add_argument(
        "--fidelity",
        choices=FIDELITY_PRESETS,
        help="fidelity preset; overrides [fidelity] preset (its other keys still apply); auto: "
        "the cheapest rungs whose measured error stays under [fidelity] tolerance (default 0.05) "
        "over the sweep's speeds (jg.choose_fidelity), with its reasons printed",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from jaxgear.cli.config import load_toml, sweep_from_config
    from jaxgear.sweep import sweep

    cfg = sweep_from_config(load_toml(args.config), fidelity=args.fidelity)
    if cfg.fidelity_reasons:
        print(cfg.fidelity_reasons, flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    progress = cfg.progress and not args.no_progress
    common = dict(speeds_rpm=cfg.speeds, chunk_size=cfg.chunk_size, progress=progress, **cfg.vary)
    ckpt = (lambda name: out / "checkpoint" / name) if cfg.checkpoint else (lambda name: None)

    t0 = time.perf_counter()
    main = sweep(
        cfg.pair,
        cfg.lubricant,
        cfg.surfaces,
        cfg.op,
        fidelity=cfg.fidelity,
        mode=cfg.mode,
        checkpoint_dir=ckpt(cfg.fidelity.dynamics),
        **common,
    )
    t_main = time.perf_counter() - t0
    _fail_if_nothing_ran(main)
    reference = None
    if cfg.quasi_static_reference:
        reference = sweep(
            cfg.pair,
            cfg.lubricant,
            cfg.surfaces,
            cfg.op,
            fidelity=cfg.fidelity.replace(dynamics="quasi_static"),
            mode="parallel",
            checkpoint_dir=ckpt("quasi_static_reference"),
            **common,
        )
    t_all = time.perf_counter() - t0

    written = [main.to_csv(out / "sweep.csv")]
    if reference is not None:
        written.append(reference.to_csv(out / "sweep_quasi_static.csv"))
    speeds = cfg.speeds
    if np.all(np.diff(speeds) > 0):
        written += _plots(speeds, main, reference, cfg.fidelity.dynamics, out)
    else:
        print("speeds are not strictly increasing: no figures against speed (see sweep.csv)")
    summary = _summary(cfg, main, reference, t_main, t_all)
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    written.append(out / "summary.json")
    print(json.dumps(summary["headline"], indent=1))
    print("wrote " + ", ".join(p.name for p in written) + f" in {out}")
    bad = summary["headline"]["points_not_converged"]
    if bad:
        print(f"{bad} of {speeds.size} points did not converge (kept, flagged in sweep.csv)")
    return 0


def _fail_if_nothing_ran(result) -> None:
    """A sweep whose every chunk raised (e.g. a fidelity rung that is not available) is an input
    error, not a result: report the first message."""
    if result.messages and np.all(np.asarray(result.status) == 5):
        raise ValueError(f"every point failed; first error: {result.messages[0]}")


def _plots(speeds, main, reference, dynamics, out):
    from jaxgear.plotting import plot_dte_rms, plot_efficiency, plot_power_loss

    label = dynamics.replace("_", "-")
    parts = lambda r: {
        "total": r.power_loss,
        "sliding": r.power_loss_sliding,
        "rolling": r.power_loss_rolling,
    }
    ok, att = ~main.failed, main.on_attractor
    paths = [
        plot_dte_rms(speeds, main.dte_rms, out / "dte_rms.png", label=label, ok=ok, attractor=att)
    ]
    ref_parts = parts(reference) if reference is not None else None
    labels = (label, "quasi-static")
    paths.append(
        plot_power_loss(speeds, parts(main), ref_parts, out / "power_loss.png", ok, labels, att)
    )
    ref_eff = reference.efficiency if reference is not None else None
    paths.append(
        plot_efficiency(speeds, main.efficiency, ref_eff, out / "efficiency.png", ok, labels, att)
    )
    return paths


def _summary(cfg, main, reference, t_main, t_all):
    speeds = cfg.speeds
    eff = 100 * np.asarray(main.efficiency)
    ok = ~main.failed
    fid = cfg.fidelity
    summary = {
        "headline": {
            "points": int(speeds.size),
            "speeds_rpm": [float(speeds.min()), float(speeds.max())],
            "mean_efficiency_percent": _nan_stat(np.nanmean, eff),
            "min_efficiency_percent": _nan_stat(np.nanmin, eff),
            "max_power_loss_W": _nan_stat(np.nanmax, main.power_loss),
            "max_dte_rms_um": _nan_stat(np.nanmax, 1e6 * np.asarray(main.dte_rms)),
            "points_not_converged": int(np.sum(~ok)),
            "points_on_attractor": int(np.sum(main.on_attractor)),
            # rattling teeth striking the back flanks (their loss: power_loss_back_W in the CSV)
            "points_with_back_contact": int(
                np.sum(ok & (np.nan_to_num(main.back_contact_share) > 0))
            ),
            "wall_time_s": round(t_all, 2),
        },
        "inputs": cfg.echo,
        "fidelity": fid.flat(),
        "timing_s": {"sweep": round(t_main, 2), "total": round(t_all, 2)},
        "not_converged": [
            {"point": i, "speed_rpm": float(speeds[i]), "status": name}
            for i, (name, good) in enumerate(zip(main.status_names(), ok))
            if not good
        ],
        "messages": list(main.messages),
    }
    if cfg.fidelity_reasons:
        summary["fidelity_reasons"] = cfg.fidelity_reasons
    if reference is not None:
        summary["headline"]["quasi_static_mean_efficiency_percent"] = _nan_stat(
            np.nanmean, 100 * np.asarray(reference.efficiency)
        )
    return summary


def _nan_stat(fn, values):
    values = np.asarray(values, dtype=float)
    return float(fn(values)) if np.any(np.isfinite(values)) else None
