"""``jaxgear optimise``: tip relief (or torque, or roughness scale) for the best mean efficiency."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

TARGETS = ("tip_relief", "torque", "roughness_scale")
FIDELITIES = ("fast", "quasi_static")
_OPTIMISE_KEYS = {
    "target": str,
    "speeds_rpm": list,
    "steps": int,
    "learning_rate": float,
    "shape": str,
    "amount_bounds_um": list,
    "start_roll_angle_bounds_deg": list,
    "torque_bounds_Nm": list,
    "roughness_scale_bounds": list,
}


def register(sub) -> None:
    p = sub.add_parser(
        "optimise",
        help="optimise tip relief (or torque, roughness scale) for the best mean efficiency",
        description=(
            "Maximise the mean efficiency over a set of speeds by gradient-based optimisation "
            "(optax Adam, forward-mode gradients through the model) of the tip relief amount and "
            "start roll angle (default), of the torque, or of the roughness scale. Prints JSON; "
            "with --out also writes optimise.json and a PNG of the history."
        ),
    )
    p.add_argument("--config", type=Path, help="TOML file with [gear], [operating], [optimise]")
    speeds = p.add_mutually_exclusive_group()
    speeds.add_argument("--speeds", help="comma-separated gear 1 speeds, rpm, e.g. 1000,2000,3000")
    speeds.add_argument(
        "--speed-range",
        help="START:STOP:STEP in rpm, stop included if on the grid, e.g. 500:4200:500",
    )
    p.add_argument("--torque", type=float, default=None, help="gear 1 torque, N m (default 700)")
    p.add_argument("--target", choices=TARGETS, default=None, help="what to optimise")
    p.add_argument("--shape", choices=("linear", "parabolic", "both"), default=None)
    p.add_argument("--per-gear", action="store_true", help="separate relief for each gear")
    p.add_argument("--steps", type=int, default=None, help="optimiser step cap (default 40)")
    p.add_argument("--learning-rate", type=float, default=None, help="box widths per step (0.1)")
    p.add_argument("--fidelity", choices=FIDELITIES, default="fast")
    p.add_argument("--out", type=Path, default=None, help="directory for optimise.json/.png")
    p.set_defaults(func=run)


def parse_speeds(speeds: str | None, speed_range: str | None) -> list[float] | None:
    """--speeds "a,b,c" or --speed-range "start:stop:step" (rpm) → list of speeds, or None."""
    if speeds is not None:
        try:
            values = [float(v) for v in speeds.split(",") if v.strip()]
        except ValueError:
            raise ValueError(
                f"--speeds = {speeds!r} must be comma-separated numbers (rpm)"
            ) from None
        if not values or not all(math.isfinite(v) and v > 0 for v in values):
            raise ValueError(f"--speeds = {speeds!r} is out of range; valid: speeds > 0 rpm")
        return values
    if speed_range is not None:
        parts = speed_range.split(":")
        try:
            start, stop, step = (float(v) for v in parts)
        except ValueError:
            raise ValueError(
                f"--speed-range = {speed_range!r} must be START:STOP:STEP in rpm"
            ) from None
        if not (0 < start <= stop and step > 0 and math.isfinite(stop)):
            raise ValueError(
                f"--speed-range = {speed_range!r} is out of range; valid: 0 < START <= STOP, STEP > 0"
            )
        values = np.arange(start, stop + 1e-9 * stop, step)
        if values.size > 1000:
            raise ValueError(
                f"--speed-range = {speed_range!r} gives {values.size} speeds; max 1000"
            )
        return values.tolist()
    return None


def _pair_of_numbers(name, value):
    if len(value) != 2 or not all(isinstance(v, int | float) for v in value):
        raise ValueError(f"optimise.{name} = {value!r} must be [lower, upper]")
    return float(value[0]), float(value[1])


def run(args: argparse.Namespace) -> int:
    import jaxgear as jg
    from jaxgear.cli.config import (
        check_keys,
        check_top_level,
        gear_pair_from_config,
        load_toml,
        operating_from_config,
    )
    from jaxgear.fidelity import Fidelity
    from jaxgear.optimise import _check_positive_float, _check_steps

    cfg = load_toml(args.config) if args.config else {}
    check_top_level(cfg, ("gear", "operating", "optimise"))
    opt_cfg = dict(cfg.get("optimise", {}))
    check_keys(opt_cfg, _OPTIMISE_KEYS, "optimise")
    speeds = parse_speeds(args.speeds, args.speed_range)
    if speeds is None and "speeds_rpm" in opt_cfg:
        speeds = parse_speeds(",".join(str(v) for v in opt_cfg["speeds_rpm"]), None)
    target = args.target or opt_cfg.get("target", "tip_relief")
    if target not in TARGETS:
        raise ValueError(f"optimise.target = {target!r} is not valid; valid choices: {TARGETS}")
    steps = args.steps if args.steps is not None else opt_cfg.get("steps", 40)
    lr = args.learning_rate if args.learning_rate is not None else opt_cfg.get("learning_rate", 0.1)
    shape = args.shape or opt_cfg.get("shape")
    # Cheap checks first: bad numbers fail before any geometry or compile work.
    _check_steps(steps)
    _check_positive_float("learning_rate", lr)
    pair = gear_pair_from_config(cfg)
    op_cfg = operating_from_config(cfg)
    if args.torque is not None:
        op_cfg["torque"] = args.torque
    op = jg.OperatingPoint(
        torque=op_cfg.get("torque", 700.0),
        speed_rpm=op_cfg.get("speed_rpm", 2000.0),
        inlet_temperature=op_cfg.get("inlet_temperature", 363.15),
    )
    fidelity = (
        Fidelity.fast()
        if args.fidelity == "fast"
        else Fidelity(dynamics="quasi_static", friction="regression")
    )
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    common = dict(speeds_rpm=speeds, fidelity=fidelity, steps=steps, learning_rate=lr)

    if target == "tip_relief":
        bounds = {}
        if "amount_bounds_um" in opt_cfg:
            lo, hi = _pair_of_numbers("amount_bounds_um", opt_cfg["amount_bounds_um"])
            bounds["amount"] = (lo * 1e-6, hi * 1e-6)
        if "start_roll_angle_bounds_deg" in opt_cfg:
            lo, hi = _pair_of_numbers(
                "start_roll_angle_bounds_deg", opt_cfg["start_roll_angle_bounds_deg"]
            )
            bounds["start_roll_angle"] = (math.radians(lo), math.radians(hi))
        result = jg.optimise_tip_relief(
            pair, lub, surf, op, bounds=bounds, shape=shape, both_gears=not args.per_gear, **common
        )
    elif target == "torque":
        bounds = opt_cfg.get("torque_bounds_Nm")
        bounds = _pair_of_numbers("torque_bounds_Nm", bounds) if bounds is not None else None
        result = jg.optimise_torque(pair, lub, surf, op, bounds=bounds, **common)
    else:
        bounds = opt_cfg.get("roughness_scale_bounds", [0.1, 3.0])
        bounds = _pair_of_numbers("roughness_scale_bounds", bounds)
        result = jg.optimise_roughness_scale(pair, lub, surf, op, bounds=bounds, **common)

    report, scales, labels = _report(result, target, speeds, op, args.fidelity)
    print(json.dumps(report, indent=1))
    if args.out is not None:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "optimise.json").write_text(json.dumps(report, indent=1))
        from jaxgear.plotting import plot_optimisation_history

        plot_optimisation_history(result, out / "optimise.png", scales=scales, labels=labels)
    return 0


# Display units of each parameter at this edge: (suffix, factor from SI).
_UNITS = {
    "tip_relief_amount": ("um", 1e6),
    "tip_relief_start_roll_angle": ("deg", 180.0 / math.pi),
    "torque": ("Nm", 1.0),
    "roughness_scale": ("", 1.0),
}


def _unit(name):
    base = name[:-2] if name[-2:] in ("_1", "_2") else name
    suffix, factor = _UNITS[base]
    return (f"{name}_{suffix}" if suffix else name), factor


def _report(result, target, speeds, op, fidelity_name):
    labels, scales = [], []
    for name in result.names:
        label, factor = _unit(name)
        labels.append(label)
        scales.append(factor)
    optimum = {lab: float(v * f) for lab, v, f in zip(labels, result.x, scales)}
    start = {lab: float(v * f) for lab, v, f in zip(labels, result.x_start, scales)}
    report = {
        "target": target,
        "fidelity": fidelity_name,
        "speeds_rpm": [float(op.speed_rpm)] if speeds is None else [float(s) for s in speeds],
        "torque_Nm": float(op.torque),
        "efficiency_start_percent": 100.0 * result.objective_start,
        "efficiency_optimum_percent": 100.0 * result.objective,
        "efficiency_gain_percent_points": 100.0 * (result.objective - result.objective_start),
        "start": start,
        "optimum": optimum,
        "gradient_norm": result.gradient_norm,
        "steps": result.steps,
        "converged": result.converged,
        "status": result.status,
        "status_name": result.message,
    }
    if target == "tip_relief":
        report["shape"] = list(result.shape)
    return report, scales, labels
