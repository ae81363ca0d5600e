"""``jaxgear sensitivity``: the derivative of a point's outputs with respect to every input and
model constant (``jg.sensitivity``), as CSV, JSON and tornado charts.

The point comes from ``--config FILE.toml`` (``[gear]``, default preset "li2015_calibrated";
``[lubricant]``, ``[surfaces]``, ``[fidelity]`` as for ``jaxgear sweep``; ``[operating]`` with
``torque_Nm``, ``speed_rpm``, ``inlet_temperature_C``) and the options, which win over the file.
Writes ``sensitivity.csv``, ``sensitivity.json`` and ``tornado_<output>.png`` per output to
``--out``, and prints each output's ten inputs of largest elasticity. Bad input ends with exit
code 2 and a one-line message; a point without derivatives (a simulation status other than 0)
writes its values and status, no charts, and ends with exit code 1.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from jaxgear.cli.config import FIDELITY_PRESETS

#: ``--fidelity`` choices: the named presets, and "quasi_static" (``Fidelity.fast()`` on the
#: quasi-static rung). "auto" chooses a fidelity for a sweep, not for one derivative: not offered.
FIDELITIES = (*(f for f in FIDELITY_PRESETS if f != "auto"), "quasi_static")
SENSITIVITY_TABLES = ("gear", "lubricant", "surfaces", "operating", "fidelity")
TOP = 10


def register(sub) -> None:
    p = sub.add_parser(
        "sensitivity",
        help="derivatives of efficiency, power loss, DTE... with respect to every input",
        description=__doc__.split("\n\n")[0] + "\n\n" + __doc__.split("\n\n")[1],
    )
    p.add_argument("--config", type=Path, help="TOML file ([gear], [lubricant], [surfaces], ...)")
    p.add_argument(
        "--fidelity",
        choices=FIDELITIES,
        help="fidelity preset (default: [fidelity] preset, else fast); quasi_static: fast on the "
        "quasi-static rung",
    )
    p.add_argument("--torque", type=float, default=None, help="gear 1 torque, N m (default 700)")
    p.add_argument("--speed", type=float, default=None, help="gear 1 speed, rpm (default 2000)")
    p.add_argument(
        "--inlet-temperature", type=float, default=None, help="oil inlet temperature, °C (90)"
    )
    p.add_argument(
        "--outputs",
        default="efficiency,power_loss,dte_rms",
        help="comma-separated outputs (efficiency, power_loss, power_loss_sliding, "
        "power_loss_rolling, dte_rms, hertz_pressure, flash_temperature)",
    )
    p.add_argument("--out", type=Path, default=Path("results"), help="output directory")
    p.set_defaults(func=run)


def _inputs(args):
    import jaxgear as jg
    from jaxgear.cli.config import (
        check_top_level,
        fidelity_from_config,
        gear_pair_from_config,
        load_toml,
        lubricant_from_config,
        operating_from_config,
        surfaces_from_config,
    )

    cfg = load_toml(args.config) if args.config else {}
    check_top_level(cfg, SENSITIVITY_TABLES)
    name = args.fidelity
    if name is None and cfg.get("fidelity", {}).get("preset") == "auto":
        raise ValueError(
            "fidelity preset 'auto' is not valid for jaxgear sensitivity; valid choices: "
            + ", ".join(map(repr, FIDELITIES))
        )
    fidelity, _ = fidelity_from_config(cfg, "fast" if name == "quasi_static" else name)
    if name == "quasi_static":
        fidelity = fidelity.replace(dynamics="quasi_static")
    pair = gear_pair_from_config(cfg, default_preset="li2015_calibrated")
    lubricant, _ = lubricant_from_config(cfg)
    surfaces, _ = surfaces_from_config(cfg)
    op = operating_from_config(cfg)
    if args.torque is not None:
        op["torque"] = args.torque
    if args.speed is not None:
        op["speed_rpm"] = args.speed
    if args.inlet_temperature is not None:
        op["inlet_temperature"] = args.inlet_temperature + 273.15
    op = jg.OperatingPoint(
        torque=op.get("torque", 700.0),
        speed_rpm=op.get("speed_rpm", 2000.0),
        inlet_temperature=op.get("inlet_temperature", 363.15),
    )
    return pair, lubricant, surfaces, op, fidelity


def run(args: argparse.Namespace) -> int:
    import jaxgear as jg
    from jaxgear.design.sensitivity import plot_tornado

    outputs = tuple(o.strip() for o in args.outputs.split(",") if o.strip())
    pair, lubricant, surfaces, op, fidelity = _inputs(args)
    report = jg.sensitivity(pair, lubricant, surfaces, op, fidelity=fidelity, outputs=outputs)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report.to_csv(out / "sensitivity.csv")
    report.to_json(out / "sensitivity.json")
    print(
        f"torque {float(op.torque):g} N m, speed {float(op.speed_rpm):g} rpm, inlet "
        f"{float(op.inlet_temperature) - 273.15:g} °C: status {report.status} ({report.message})"
    )
    for output in report.output_names:
        value, unit = report.outputs[output]
        print(f"\n{output} = {value:.6g} {unit}")
        if not report.converged:
            continue
        plot_tornado(report, output, out / f"tornado_{output}.png")
        print(f"  {'input':<40} {'value':>12} {'d/d input':>12}  {'unit':<14} {'elasticity':>10}")
        for row in report.ranked(output)[:TOP]:
            print(
                f"  {row['input']:<40} {row['input_value']:>12.5g} {row['derivative']:>12.4g}  "
                f"{row['derivative_unit']:<14} {row['elasticity']:>10.3g}"
            )
    print(f"\nwritten to {out}/: sensitivity.csv, sensitivity.json, tornado_<output>.png")
    return 0 if report.converged else 1
