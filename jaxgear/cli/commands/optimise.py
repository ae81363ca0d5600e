"""``jaxgear optimise``: tip relief for an objective under limits over a duty cycle (or torque, or
roughness scale, for the best mean efficiency)."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

from jaxgear.design.problem import OBJECTIVES

TARGETS = ("tip_relief", "torque", "roughness_scale")
FIDELITIES = ("fast", "quasi_static")
_OPTIMISE_KEYS = {
    "target": str,
    "objective": str,
    "constraints": list,
    "torques_Nm": list,
    "max_evaluations": int,
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
        help="optimise tip relief under limits (or torque, roughness scale) over a duty cycle",
        description=(
            "Tip relief (default target): the amount and start roll angle that optimise "
            "--objective over every speed and torque of the duty cycle while each --constraint "
            "holds at every point (augmented Lagrangian, reverse-mode gradients through the model). "
            "Torque or roughness scale: the best mean efficiency over the speeds (optax Adam). "
            "Prints JSON; with --out also writes optimise.json, optimise.csv (tip relief: each "
            "point's values) and a PNG."
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
    p.add_argument(
        "--torques",
        default=None,
        help="comma-separated torques, N m: the duty cycle's (tip relief)",
    )
    p.add_argument(
        "--objective",
        choices=tuple(OBJECTIVES),
        default=None,
        help="tip relief objective (default efficiency: the mean, maximised)",
    )
    p.add_argument(
        "--constraint",
        action="append",
        default=None,
        help="a limit at every point, e.g. dte_rms<=1.5um, hertz_pressure<=1.2GPa, "
        "flash_temperature<=40K, efficiency>=99.8%% (repeatable)",
    )
    p.add_argument(
        "--max-evaluations", type=int, default=None, help="tip relief evaluation budget (120)"
    )
    p.add_argument("--target", choices=TARGETS, default=None, help="what to optimise")
    p.add_argument("--shape", choices=("linear", "parabolic", "both"), default=None)
    p.add_argument("--per-gear", action="store_true", help="separate relief for each gear")
    p.add_argument(
        "--steps", type=int, default=None, help="torque/roughness: optimiser step cap (default 40)"
    )
    p.add_argument(
        "--learning-rate", type=float, default=None, help="torque/roughness: box widths per step"
    )
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


def _relief_bounds(opt_cfg) -> dict:
    """[optimise] amount_bounds_um / start_roll_angle_bounds_deg → SI bounds."""
    bounds = {}
    if "amount_bounds_um" in opt_cfg:
        lo, hi = _pair_of_numbers("amount_bounds_um", opt_cfg["amount_bounds_um"])
        bounds["amount"] = (lo * 1e-6, hi * 1e-6)
    if "start_roll_angle_bounds_deg" in opt_cfg:
        lo, hi = _pair_of_numbers(
            "start_roll_angle_bounds_deg", opt_cfg["start_roll_angle_bounds_deg"]
        )
        bounds["start_roll_angle"] = (math.radians(lo), math.radians(hi))
    return bounds


def parse_torques(text, opt_cfg):
    """--torques "a,b" (or [optimise] torques_Nm) → list of N m, or None."""
    if text is None and "torques_Nm" in opt_cfg:
        text = ",".join(str(v) for v in opt_cfg["torques_Nm"])
    if text is None:
        return None
    try:
        values = [float(v) for v in str(text).split(",") if v.strip()]
    except ValueError:
        raise ValueError(f"--torques = {text!r} must be comma-separated numbers (N m)") from None
    if not values or not all(math.isfinite(v) and v > 0 for v in values):
        raise ValueError(f"--torques = {text!r} is out of range; valid: torques > 0 N m")
    return values


def design_inputs(args, opt_cfg):
    """(objective, constraints SI, torques) of a tip relief command, checked before any compile."""
    from jaxgear.cli.design_args import parse_limits
    from jaxgear.design.tip_relief import check_objective

    objective = args.objective or opt_cfg.get("objective", "efficiency")
    check_objective(objective)
    texts = args.constraint if args.constraint is not None else opt_cfg.get("constraints", [])
    return objective, parse_limits(texts), parse_torques(args.torques, opt_cfg)


def _run_tip_relief(args, opt_cfg, design, model, speeds, fidelity, shape) -> int:
    import jaxgear as jg
    from jaxgear.cli.design_args import display

    objective, constraints, torques = design
    pair, lub, surf, op = model
    budget = args.max_evaluations or opt_cfg.get("max_evaluations", 120)
    result = jg.optimise_tip_relief(
        pair, lub, surf, op, speeds_rpm=speeds, torques=torques, fidelity=fidelity,
        objective=objective, constraints=constraints, bounds=_relief_bounds(opt_cfg), shape=shape,
        both_gears=not args.per_gear, max_evaluations=budget,
    )  # fmt: skip
    report = design_report(result, args.fidelity)
    print(json.dumps(report, indent=1))
    if args.out is not None:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "optimise.json").write_text(json.dumps(report, indent=1))
        from jaxgear.design.plots import plot_design

        plot_design(result, out / "optimise.png")
        with (out / "optimise.csv").open("w") as fh:
            names = list(result.values)
            labels = [display(n, 0.0)[0] for n in names]
            fh.write(",".join(["speed_rpm", "torque_Nm", *labels, "status"]) + "\n")
            for k in range(result.speeds_rpm.size):
                row = [f"{result.speeds_rpm[k]:g}", f"{result.torques[k]:g}"]
                row += [f"{display(n, result.values[n][k])[1]:.8g}" for n in names]
                fh.write(",".join([*row, str(int(result.point_status[k]))]) + "\n")
    return 0


def design_report(result, fidelity_name) -> dict:
    """A DesignResult as JSON, in display units (µm, degrees, %, GPa)."""
    from jaxgear.cli.design_args import display

    def variables(x):
        return {_unit(n)[0]: float(v * _unit(n)[1]) for n, v in zip(result.names, x)}

    def per_point(values):
        out = {}
        for name, v in values.items():
            label = display(name, 0.0)[0]
            out[label] = [display(name, x)[1] for x in np.ravel(v)]
        return out

    label, start = display(result.objective, result.objective_start)
    _, optimum = display(result.objective, result.objective_value)
    return {
        "target": "tip_relief",
        "fidelity": fidelity_name,
        "objective": result.objective,
        f"objective_start_{label}": start,
        f"objective_optimum_{label}": optimum,
        "speeds_rpm": result.speeds_rpm.tolist(),
        "torques_Nm": result.torques.tolist(),
        "limits": {display(n, 0.0)[0]: display(n, v)[1] for n, v in result.limits.items()},
        "start": variables(result.x_start),
        "optimum": variables(result.x),
        "shape": list(result.shape),
        "values_start": per_point(result.values_start),
        "values_optimum": per_point(result.values),
        "multipliers": {n: np.ravel(v).tolist() for n, v in result.multipliers.items()},
        "point_status": result.point_status.tolist(),
        "failed_points": result.failed_points,
        "violation": result.violation,
        "projected_gradient": result.projected_gradient,
        "evaluations": result.evaluations,
        "converged": result.converged,
        "status": result.status,
        "status_name": result.message,
    }


def _pair_of_numbers(name, value):
    if len(value) != 2 or not all(isinstance(v, int | float) for v in value):
        raise ValueError(f"optimise.{name} = {value!r} must be [lower, upper]")
    return float(value[0]), float(value[1])


def read_config(args, keys) -> tuple[dict, dict, list[float] | None]:
    """(config, its [optimise] table, the speeds) of an optimise/pareto command, keys checked."""
    from jaxgear.cli.config import check_keys, check_top_level, load_toml

    cfg = load_toml(args.config) if args.config else {}
    check_top_level(cfg, ("gear", "operating", "optimise"))
    opt_cfg = dict(cfg.get("optimise", {}))
    check_keys(opt_cfg, keys, "optimise")
    speeds = parse_speeds(args.speeds, args.speed_range)
    if speeds is None and "speeds_rpm" in opt_cfg:
        speeds = parse_speeds(",".join(str(v) for v in opt_cfg["speeds_rpm"]), None)
    return cfg, opt_cfg, speeds


def model_inputs(args, cfg):
    """(pair, lubricant, surfaces, operating point, fidelity) of an optimise/pareto command."""
    import jaxgear as jg
    from jaxgear.cli.config import gear_pair_from_config, operating_from_config
    from jaxgear.fidelity import Fidelity

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
    return pair, jg.presets.mil_l_23699(), jg.presets.ground(), op, fidelity


def run(args: argparse.Namespace) -> int:
    import jaxgear as jg
    from jaxgear.optimise import _check_positive_float, _check_steps

    cfg, opt_cfg, speeds = read_config(args, _OPTIMISE_KEYS)
    target = args.target or opt_cfg.get("target", "tip_relief")
    if target not in TARGETS:
        raise ValueError(f"optimise.target = {target!r} is not valid; valid choices: {TARGETS}")
    steps = args.steps if args.steps is not None else opt_cfg.get("steps", 40)
    lr = args.learning_rate if args.learning_rate is not None else opt_cfg.get("learning_rate", 0.1)
    shape = args.shape or opt_cfg.get("shape")
    # Cheap checks first: bad numbers fail before any geometry or compile work.
    _check_steps(steps)
    _check_positive_float("learning_rate", lr)
    design = design_inputs(args, opt_cfg) if target == "tip_relief" else None
    pair, lub, surf, op, fidelity = model_inputs(args, cfg)
    common = dict(speeds_rpm=speeds, fidelity=fidelity, steps=steps, learning_rate=lr)

    if target == "tip_relief":
        return _run_tip_relief(
            args, opt_cfg, design, (pair, lub, surf, op), speeds, fidelity, shape
        )
    if target == "torque":
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
    return report, scales, labels
