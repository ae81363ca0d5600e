"""``jaxgear calibrate --data FILE.csv --fit NAME[,NAME]``: model constants fitted to measured losses.

The CSV file has a header row and one row per measured operating point, with the columns

- ``torque_Nm``: gear 1 torque, N m (> 0);
- ``speed_rpm``: gear 1 speed, rpm (> 0);
- ``inlet_temperature_C``: oil inlet temperature, °C;
- ``power_loss_W``: the measured mesh power loss Φ̄, W (> 0);
- ``weight`` (optional): the weight wᵢ of the point's relative residual (> 0, default 1).

``--fit`` names the parameters (``jg.calibrate``'s: boundary_friction, asperity_density_product,
asperity_slope_ratio, constant_mu, limiting_shear_coefficient, roughness_scale). ``--config``
takes a TOML file with ``[gear]``, ``[lubricant]``, ``[surfaces]``, ``[fidelity]`` as for ``jaxgear
sweep`` (default: the paper's calibrated pair, Mil-L-23699, ground surfaces, ``Fidelity.fast()``)
and ``[calibrate]``: ``fit`` (a list, if ``--fit`` is not given), ``initial`` (a table name →
start value), ``rtol``, ``atol``, ``max_steps``, ``absolute_sigma``. Writes ``calibration.json``
(fitted values, standard errors, correlation, residuals per point, status) to ``--out`` (default
``results/``) and prints a short table. Exit code 0 when the fit converged, 1 when it did not (the
status says why), 2 on invalid input (a one-line message naming it).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
from pathlib import Path

from jaxgear.fidelity import NAMED_PRESETS

REQUIRED_COLUMNS = ("torque_Nm", "speed_rpm", "inlet_temperature_C", "power_loss_W")
OPTIONAL_COLUMNS = ("weight",)
TABLES = ("gear", "lubricant", "surfaces", "fidelity", "calibrate")
_CALIBRATE_KEYS = {
    "fit": list,
    "initial": dict,
    "rtol": float,
    "atol": float,
    "max_steps": int,
    "absolute_sigma": bool,
}


def register(sub) -> None:
    p = sub.add_parser(
        "calibrate",
        help="fit model constants (μb, nβσ, ...) to measured power losses",
        description=__doc__.split("\n\n")[0] + "\n\n" + "\n\n".join(__doc__.split("\n\n")[1:]),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--data", type=Path, required=True, help="CSV of measured points (see above)")
    p.add_argument(
        "--fit",
        help="comma-separated parameters to fit (default boundary_friction,"
        "asperity_density_product, or [calibrate] fit)",
    )
    p.add_argument("--config", type=Path, help="TOML file: [gear], [lubricant], [surfaces], ...")
    p.add_argument(
        "--fidelity",
        choices=NAMED_PRESETS,
        help="fidelity preset; overrides [fidelity] preset (its other keys still apply)",
    )
    p.add_argument(
        "--quasi-static",
        action="store_true",
        help="calibrate the quasi-static rung of the fidelity (much cheaper than tribo-dynamic)",
    )
    p.add_argument("--out", type=Path, default=Path("results"), help="output directory")
    p.set_defaults(func=run)


def read_measurements(path: Path) -> dict[str, list[float]]:
    """The CSV's columns → lists of floats (SI conversion is the caller's). ValueError naming the
    file, row and column of anything missing, unknown or not a number."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        header = [h.strip() for h in (reader.fieldnames or [])]
        missing = [c for c in REQUIRED_COLUMNS if c not in header]
        if missing:
            raise ValueError(
                f"{path}: column(s) {', '.join(missing)} missing; valid columns: "
                f"{', '.join(REQUIRED_COLUMNS + OPTIONAL_COLUMNS)} (header row first)"
            )
        unknown = [c for c in header if c not in REQUIRED_COLUMNS + OPTIONAL_COLUMNS]
        if unknown:
            raise ValueError(
                f"{path}: unknown column(s) {', '.join(unknown)}; valid columns: "
                f"{', '.join(REQUIRED_COLUMNS + OPTIONAL_COLUMNS)}"
            )
        columns: dict[str, list[float]] = {c: [] for c in header}
        for line, row in enumerate(reader, start=2):
            row = {(k or "").strip(): v for k, v in row.items()}
            if None in row.values() or "" in row:
                raise ValueError(f"{path}, line {line}: expected {len(header)} values")
            for c in header:
                text = (row[c] or "").strip()
                try:
                    value = float(text)
                except ValueError:
                    raise ValueError(
                        f"{path}, line {line}: {c} = {text!r} is not a number"
                    ) from None
                if not math.isfinite(value):
                    raise ValueError(f"{path}, line {line}: {c} = {text!r} is not finite")
                columns[c].append(value)
    if not columns[REQUIRED_COLUMNS[0]]:
        raise ValueError(f"{path}: no data rows; valid: at least one measured point")
    return columns


def _fit_names(args, table) -> tuple[str, ...]:
    from jaxgear.design.calibrate import DEFAULT_PARAMETERS

    if args.fit is not None:
        names = tuple(n.strip() for n in args.fit.split(",") if n.strip())
        if not names:
            raise ValueError(f"--fit = {args.fit!r} names no parameter")
        return names
    if "fit" in table:
        fit = table["fit"]
        if not all(isinstance(n, str) for n in fit):
            raise ValueError(f"calibrate.fit = {fit!r} must be a list of parameter names")
        return tuple(fit)
    return DEFAULT_PARAMETERS


def run(args: argparse.Namespace) -> int:
    import jaxgear as jg
    from jaxgear._validation import check_positive, check_range
    from jaxgear.cli.config import (
        check_keys,
        check_top_level,
        fidelity_from_config,
        gear_pair_from_config,
        load_toml,
        lubricant_from_config,
        surfaces_from_config,
    )

    cfg = load_toml(args.config) if args.config else {}
    check_top_level(cfg, TABLES)
    table = dict(cfg.get("calibrate", {}))
    check_keys(table, _CALIBRATE_KEYS, "calibrate")
    names = _fit_names(args, table)
    data = read_measurements(args.data)
    # cheap checks of the data first: bad numbers fail before any geometry or compile work
    for i, (t, s, c) in enumerate(
        zip(data["torque_Nm"], data["speed_rpm"], data["inlet_temperature_C"], strict=True)
    ):
        check_positive(f"{args.data} row {i + 1} torque_Nm", t, "N m")
        check_positive(f"{args.data} row {i + 1} speed_rpm", s, "rpm")
        check_range(f"{args.data} row {i + 1} inlet_temperature_C", c, -73.15, 326.85, unit="°C")
    pair = gear_pair_from_config(cfg, default_preset="li2015_calibrated")
    lub, _ = lubricant_from_config(cfg)
    surf, _ = surfaces_from_config(cfg)
    fid, fid_echo = fidelity_from_config(cfg, args.fidelity)
    if fid_echo["preset"] == "auto":
        raise ValueError(
            "fidelity preset = 'auto' is not valid here; valid choices: "
            + ", ".join(map(repr, NAMED_PRESETS))
        )
    if args.quasi_static:
        fid = fid.replace(dynamics="quasi_static")
    points = jg.OperatingPoint(
        torque=data["torque_Nm"],
        speed_rpm=data["speed_rpm"],
        inlet_temperature=[c + 273.15 for c in data["inlet_temperature_C"]],
    )
    settings = {k: table[k] for k in ("rtol", "atol", "max_steps", "absolute_sigma") if k in table}
    result = jg.calibrate(
        pair,
        lub,
        surf,
        fid,
        points,
        data["power_loss_W"],
        parameters=names,
        weights=data.get("weight"),
        initial=table.get("initial"),
        **settings,
    )
    report = _report(result, data, {**fid_echo, "dynamics": fid.dynamics})
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "calibration.json").write_text(json.dumps(report, indent=1))
    print(_table(result, data))
    return 0 if result.converged else 1


def _number(value):
    value = float(value)
    return value if math.isfinite(value) else None  # JSON has no NaN or infinity


def _report(result, data, fidelity_echo) -> dict:
    se = result.standard_errors
    points = []
    for i in range(len(result.residuals)):
        points.append(
            {
                "torque_Nm": data["torque_Nm"][i],
                "speed_rpm": data["speed_rpm"][i],
                "inlet_temperature_C": data["inlet_temperature_C"][i],
                "measured_power_loss_W": _number(result.measured_power_loss[i]),
                "model_power_loss_W": _number(result.model_power_loss[i]),
                "weight": _number(result.weights[i]),
                "residual": _number(result.residuals[i]),
                "residual_start": _number(result.residuals_start[i]),
                "simulation_status": int(result.point_status[i]),
            }
        )
    return {
        "parameters": {
            name: {
                "start": _number(result.x_start[j]),
                "value": _number(result.x[j]),
                "standard_error": _number(se[name]),
            }
            for j, name in enumerate(result.names)
        },
        "correlation": [[_number(c) for c in row] for row in result.correlation],
        "points": points,
        "residual_sum_of_squares": _number(result.residual_sum_of_squares),
        "degrees_of_freedom": result.degrees_of_freedom,
        "standard_errors_note": result.note,
        "steps": result.steps,
        "converged": result.converged,
        "status": result.status,
        "status_name": result.message,
        "fidelity": fidelity_echo,
    }


def _table(result, data) -> str:
    se = result.standard_errors
    lines = [f"{'parameter':<28}{'start':>12}{'fitted':>14}{'std. error':>14}"]
    for j, name in enumerate(result.names):
        lines.append(f"{name:<28}{result.x_start[j]:>12.5g}{result.x[j]:>14.6g}{se[name]:>14.3g}")
    lines.append("")
    lines.append(
        f"{'point':>5}{'torque Nm':>11}{'rpm':>8}{'inlet °C':>10}{'measured W':>12}"
        f"{'model W':>10}{'residual':>10}{'status':>8}"
    )
    for i in range(len(result.residuals)):
        lines.append(
            f"{i:>5}{data['torque_Nm'][i]:>11.1f}{data['speed_rpm'][i]:>8.0f}"
            f"{data['inlet_temperature_C'][i]:>10.1f}{result.measured_power_loss[i]:>12.1f}"
            f"{result.model_power_loss[i]:>10.1f}{result.residuals[i]:>+10.4f}"
            f"{int(result.point_status[i]):>8d}"
        )
    lines.append("")
    lines.append(f"status {result.status}: {result.message}; {result.steps} steps")
    lines.append(f"standard errors: {result.note}")
    return "\n".join(lines)
