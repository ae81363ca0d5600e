"""``jaxgear ehl``: solve one smooth line contact and print the result as JSON.

Values come from the command line, from a TOML file (``--config``), or both (the command line wins).
TOML layout::

    lubricant = "mil_l_23699"          # or "iso_vg68"
    [contact]                          # SI units
    reduced_radius = 0.012826          # m
    load_per_width = 496600.0          # N/m
    u1 = 6.17                          # m/s
    u2 = 4.57                          # m/s
    e_reduced = 2.2747e11              # Pa
    inlet_temperature = 363.15         # K
    [model]
    n_nodes = 257
    shear = "eyring_paper"
"""

from __future__ import annotations

import argparse
import json
import sys

CONTACT_FIELDS = (
    ("reduced_radius", "m"),
    ("load_per_width", "N/m"),
    ("u1", "m/s"),
    ("u2", "m/s"),
    ("e_reduced", "Pa"),
    ("inlet_temperature", "K"),
)
MODEL_FIELDS = ("n_nodes", "viscosity", "compressibility", "shear", "deformation")
#: [model] keys a config may set (EHLModel's fields) and their TOML types.
MODEL_KEYS = {
    "n_nodes": int,
    "x_in": float,
    "x_out": float,
    "auto_domain": bool,
    "viscosity": str,
    "compressibility": str,
    "shear": str,
    "fb_smoothing": float,
    "tolerance": float,
    "max_iterations": int,
    "coarsest_nodes": int,
    "continuation_steps": int,
    "warm_iterations": int,
    "deformation": str,
    "wedge_order": int,
    "hardness": float,
}
SCALARS = (
    "h_min",
    "h_central",
    "h0",
    "p_max",
    "friction_sliding",
    "friction_rolling",
    "damping",
    "power_loss",
    "power_loss_sliding",
    "power_loss_rolling",
    "load_error",
    "hertz_half_width",
    "hertz_pressure",
    "moes_m",
    "moes_l",
    "residual",
)
UNITS = {
    "h_min": "m",
    "h_central": "m",
    "h0": "m",
    "p_max": "Pa",
    "friction_sliding": "N/m",
    "friction_rolling": "N/m",
    "damping": "N s/m^2",
    "power_loss": "W/m",
    "power_loss_sliding": "W/m",
    "power_loss_rolling": "W/m",
    "hertz_half_width": "m",
    "hertz_pressure": "Pa",
}


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "ehl",
        help="solve one smooth EHL line contact, print JSON",
        description="Solve one isothermal smooth EHL line contact (SI inputs) and print JSON.",
    )
    p.add_argument("--config", help="TOML file with [contact], [model] and lubricant")
    for name, unit in CONTACT_FIELDS:
        p.add_argument(f"--{name.replace('_', '-')}", type=float, dest=name, help=f"{name}, {unit}")
    p.add_argument("--lubricant", choices=("mil_l_23699", "iso_vg68"), help="lubricant preset")
    p.add_argument("--nodes", type=int, dest="n_nodes", help="grid nodes (default 257)")
    p.add_argument("--viscosity", choices=("roelands", "barus"))
    p.add_argument("--compressibility", choices=("dowson_higginson", "incompressible"))
    p.add_argument("--shear", choices=("newtonian", "eyring_paper", "eyring_exact", "eyring_split"))
    p.add_argument("--deformation", choices=("dense", "fft", "auto"))
    p.add_argument("--arrays", action="store_true", help="include x, p, h arrays in the JSON")
    p.add_argument("--png", help="write a figure of p(x) and h(x) to this file")
    p.set_defaults(func=run)


def _load_config(path: str | None) -> dict:
    """The TOML file, its tables and keys checked (a missing file, a typo or a wrong type is a
    ValueError naming it, so the command exits 2 with one line instead of a traceback)."""
    if path is None:
        return {}
    from jaxgear.cli.config import check_keys, check_top_level, load_toml

    cfg = load_toml(path)
    check_top_level(cfg, ("lubricant", "contact", "model"))
    if not isinstance(cfg.get("lubricant", ""), str):
        raise ValueError(f"lubricant = {cfg['lubricant']!r} has the wrong type; expected str")
    for table in ("contact", "model"):
        if not isinstance(cfg.get(table, {}), dict):
            raise ValueError(f"{table} = {cfg[table]!r} must be a table [{table}]")
    check_keys(cfg.get("contact", {}), {name: float for name, _ in CONTACT_FIELDS}, "contact")
    check_keys(cfg.get("model", {}), MODEL_KEYS, "model")
    return cfg


def run(args: argparse.Namespace) -> int:
    import jaxgear as jg

    cfg = _load_config(args.config)
    contact_cfg = dict(cfg.get("contact", {}))
    model_cfg = dict(cfg.get("model", {}))
    for name, _ in CONTACT_FIELDS:
        if getattr(args, name) is not None:
            contact_cfg[name] = getattr(args, name)
    for name in MODEL_FIELDS:
        if getattr(args, name, None) is not None:
            model_cfg[name] = getattr(args, name)
    missing = [n for n in ("reduced_radius", "load_per_width", "u1", "u2") if n not in contact_cfg]
    if missing:
        raise ValueError(f"{', '.join(missing)} missing; give them as options or in [contact]")
    unknown = set(contact_cfg) - {n for n, _ in CONTACT_FIELDS}
    if unknown:
        raise ValueError(
            f"[contact] {sorted(unknown)} not valid; valid: {[n for n, _ in CONTACT_FIELDS]}"
        )
    lub_name = args.lubricant or cfg.get("lubricant", "mil_l_23699")
    presets = {"mil_l_23699": jg.presets.mil_l_23699, "iso_vg68": jg.presets.iso_vg68}
    if lub_name not in presets:
        raise ValueError(f"lubricant = {lub_name!r} is not valid; valid choices: {sorted(presets)}")
    contact = jg.LineContact(**{k: float(v) for k, v in contact_cfg.items()})
    model = jg.EHLModel(**model_cfg)
    sol = jg.solve_ehl(contact, presets[lub_name](), model)
    out = {k: float(getattr(sol, k)) for k in SCALARS}
    out["converged"] = bool(sol.converged)
    out["iterations"] = int(sol.iterations)
    out["units"] = UNITS
    out["lubricant"] = lub_name
    out["n_nodes"] = model.n_nodes
    if args.arrays:
        out["x"] = [float(v) for v in sol.x]
        out["p"] = [float(v) for v in sol.p]
        out["h"] = [float(v) for v in sol.h]
    if args.png:
        _plot(sol, args.png)
        out["png"] = args.png
    json.dump(out, sys.stdout, indent=2)
    sys.stdout.write("\n")
    return 0 if out["converged"] else 1


def _plot(sol, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    b = float(sol.hertz_half_width)
    x = np.asarray(sol.x) / b
    fig, ax1 = plt.subplots(figsize=(7, 4))
    ax1.plot(x, np.asarray(sol.p) / 1e9, "C0")
    ax1.set_xlabel("x / b")
    ax1.set_ylabel("pressure (GPa)", color="C0")
    ax2 = ax1.twinx()
    ax2.plot(x, np.asarray(sol.h) * 1e6, "C1")
    ax2.set_ylabel("film thickness (µm)", color="C1")
    hmax = 4.0 * float(sol.h_central) * 1e6
    ax2.set_ylim(0.0, hmax)
    ax1.set_title(
        f"h_c = {float(sol.h_central) * 1e9:.1f} nm, h_min = {float(sol.h_min) * 1e9:.1f} nm, "
        f"M = {float(sol.moes_m):.0f}, L = {float(sol.moes_l):.1f}"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
