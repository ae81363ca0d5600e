"""``jaxgear pareto``: the Pareto front of a tip relief objective against DTE RMS (or peak pressure,
flash temperature, loss) over a duty cycle, by the ε-constraint method."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from jaxgear.cli.commands.optimise import (
    _OPTIMISE_KEYS,
    FIDELITIES,
    _relief_bounds,
    _unit,
    design_inputs,
    model_inputs,
    read_config,
)
from jaxgear.design.pareto import TRADES
from jaxgear.design.problem import OBJECTIVES

_PARETO_KEYS = {**_OPTIMISE_KEYS, "trade": str, "n_points": int, "grid": int}


def register(sub) -> None:
    p = sub.add_parser(
        "pareto",
        help="Pareto front of a tip relief objective against DTE RMS (or pressure) by ε-constraint",
        description=(
            "For each limit ε on --trade (at every speed and torque of the duty cycle), the tip "
            "relief that optimises --objective under it and any --constraint; the problems run "
            "side by side through the sweep engine. Prints JSON; with --out writes pareto.csv, "
            "pareto.json and pareto.png."
        ),
    )
    p.add_argument("--config", type=Path, help="TOML file with [gear], [operating], [optimise]")
    speeds = p.add_mutually_exclusive_group()
    speeds.add_argument("--speeds", help="comma-separated gear 1 speeds, rpm, e.g. 1000,2000,3000")
    speeds.add_argument("--speed-range", help="START:STOP:STEP in rpm")
    p.add_argument("--torque", type=float, default=None, help="gear 1 torque, N m (default 700)")
    p.add_argument("--torques", default=None, help="comma-separated torques, N m (duty cycle)")
    p.add_argument("--objective", choices=tuple(OBJECTIVES), default=None)
    p.add_argument("--trade", choices=TRADES, default=None, help="traded quantity (dte_rms)")
    p.add_argument(
        "--limits",
        default=None,
        help="comma-separated ε values in the trade's display unit (µm, GPa, K, W); default: "
        "--n-points over the range a grid of designs shows",
    )
    p.add_argument("--n-points", type=int, default=None, help="front points (default 10)")
    p.add_argument("--grid", type=int, default=None, help="grid points per variable (default 5)")
    p.add_argument("--constraint", action="append", default=None, help="a further limit")
    p.add_argument("--shape", choices=("linear", "parabolic"), default=None)
    p.add_argument("--per-gear", action="store_true", help="separate relief for each gear")
    p.add_argument("--max-evaluations", type=int, default=None, help="per point (default 80)")
    p.add_argument("--fidelity", choices=FIDELITIES, default="fast")
    p.add_argument("--out", type=Path, default=None, help="directory for pareto.csv/.json/.png")
    p.set_defaults(func=run)


def _limits(text, trade):
    from jaxgear.cli.design_args import DISPLAY

    if text is None:
        return None
    _, factor = DISPLAY[trade]
    try:
        values = [float(v) / factor for v in text.split(",") if v.strip()]
    except ValueError:
        raise ValueError(f"--limits = {text!r} must be comma-separated numbers") from None
    if not values or not all(np.isfinite(v) and v > 0 for v in values):
        raise ValueError(f"--limits = {text!r} is out of range; valid: positive values")
    return values


def run(args: argparse.Namespace) -> int:
    from jaxgear.cli.design_args import display
    from jaxgear.design.pareto import pareto_front
    from jaxgear.design.plots import plot_pareto

    cfg, opt_cfg, speeds = read_config(args, _PARETO_KEYS)
    objective, constraints, torques = design_inputs(args, opt_cfg)
    trade = args.trade or opt_cfg.get("trade", "dte_rms")
    if trade not in TRADES:
        raise ValueError(f"optimise.trade = {trade!r} is not valid; valid choices: {TRADES}")
    limits = _limits(args.limits, trade)
    n_points = args.n_points if args.n_points is not None else opt_cfg.get("n_points", 10)
    grid = args.grid if args.grid is not None else opt_cfg.get("grid", 5)
    budget = args.max_evaluations or opt_cfg.get("max_evaluations", 80)
    pair, lub, surf, op, fidelity = model_inputs(args, cfg)
    front = pareto_front(
        pair, lub, surf, op, speeds_rpm=speeds,
        torques=torques, fidelity=fidelity, objective=objective, trade=trade, limits=limits,
        n_points=n_points, constraints=constraints, bounds=_relief_bounds(opt_cfg),
        shape=args.shape or opt_cfg.get("shape"), both_gears=not args.per_gear, grid=grid,
        max_evaluations=budget,
    )  # fmt: skip
    t_label = display(trade, 0.0)[0]
    o_label = display(objective, 0.0)[0]
    report = {
        "objective": objective,
        "trade": trade,
        "fidelity": args.fidelity,
        "points": [
            {
                f"limit_{t_label}": display(trade, front.limits[k])[1],
                o_label: display(objective, front.objective_values[k])[1],
                t_label: display(trade, front.trade_values[k])[1],
                **{_unit(n)[0]: float(v * _unit(n)[1]) for n, v in zip(front.names, front.x[k])},
                "status": int(front.status[k]),
                "status_name": front.results[k].message,
                "dominated": bool(front.dominated[k]),
            }
            for k in range(front.limits.size)
        ],
    }
    print(json.dumps(report, indent=1))
    if args.out is not None:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "pareto.json").write_text(json.dumps(report, indent=1))
        front.to_csv(out / "pareto.csv")
        plot_pareto(front, out / "pareto.png")
    return 0
