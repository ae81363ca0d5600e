"""``jaxgear mesh``: the quasi-static mesh-cycle table (load sharing, Hertz pressure, km, static TE)."""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
from pathlib import Path

import numpy as np

COLUMNS = (
    ("roll_angle_deg", "gear 1 roll angle of the entering pair, deg"),
    ("in_contact_1", "pair slot 1 on the path of contact (0/1)"),
    ("in_contact_2", "pair slot 2 on the path of contact (0/1)"),
    ("load_share_1", "share of the normal load, slot 1"),
    ("load_share_2", "share of the normal load, slot 2"),
    ("normal_load_1_N", "tooth force, slot 1, N"),
    ("normal_load_2_N", "tooth force, slot 2, N"),
    ("hertz_pressure_1_GPa", "maximum Hertz pressure, slot 1, GPa"),
    ("hertz_pressure_2_GPa", "maximum Hertz pressure, slot 2, GPa"),
    ("reduced_radius_1_mm", "reduced radius of curvature, slot 1, mm"),
    ("reduced_radius_2_mm", "reduced radius of curvature, slot 2, mm"),
    ("mesh_stiffness_N_per_m", "mesh stiffness km, N/m"),
    ("static_te_um", "loaded static transmission error, µm"),
    ("te_excitation_um", "TE excitation of the dynamics, µm"),
)


def register(sub) -> None:
    p = sub.add_parser(
        "mesh",
        help="quasi-static mesh cycle: load sharing, Hertz pressure, mesh stiffness, static TE",
        description=(
            "Tabulate the quasi-static mesh cycle of the paper's gear pair (or a TOML config): "
            "load share, tooth force and Hertz pressure per pair, mesh stiffness and static "
            "transmission error against roll angle."
        ),
    )
    p.add_argument("--config", type=Path, help="TOML file with [gear] and [operating] tables")
    p.add_argument("--torque", type=float, default=None, help="gear 1 torque, N m (default 700)")
    p.add_argument(
        "--positions", type=int, default=64, help="positions per mesh cycle (default 64)"
    )
    p.add_argument("--stiffness", choices=("potential_energy", "iso"), default="potential_energy")
    p.add_argument(
        "--format",
        choices=("table", "csv", "json"),
        default="table",
        help="what to print on stdout",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="directory to write mesh_cycle.csv, mesh_cycle.json and mesh_cycle.png",
    )
    p.set_defaults(func=run)


def _rows(mesh) -> list[list[float]]:
    cols = [
        np.degrees(np.asarray(mesh.roll_angle)),
        np.asarray(mesh.in_contact[:, 0]),
        np.asarray(mesh.in_contact[:, 1]),
        np.asarray(mesh.load_share[:, 0]),
        np.asarray(mesh.load_share[:, 1]),
        np.asarray(mesh.normal_load[:, 0]),
        np.asarray(mesh.normal_load[:, 1]),
        np.asarray(mesh.hertz_pressure[:, 0]) / 1e9,
        np.asarray(mesh.hertz_pressure[:, 1]) / 1e9,
        np.asarray(mesh.reduced_radius[:, 0]) * 1e3,
        np.asarray(mesh.reduced_radius[:, 1]) * 1e3,
        np.asarray(mesh.mesh_stiffness),
        np.asarray(mesh.static_te) * 1e6,
        np.asarray(mesh.te_excitation) * 1e6,
    ]
    return np.stack(cols, axis=1).tolist()


def _summary(pair, geo, mesh) -> dict:
    deg = lambda v: math.degrees(float(v))
    te = np.asarray(mesh.static_te)
    return {
        "teeth": list(pair.teeth),
        "contact_ratio": float(geo.contact_ratio),
        "roll_angles_deg": {
            "start_active_profile": deg(geo.roll_angle_start),
            "lowest_single_contact": deg(geo.roll_angle_lowest_single),
            "pitch": deg(geo.roll_angle_pitch),
            "highest_single_contact": deg(geo.roll_angle_highest_single),
            "tip": deg(geo.roll_angle_end),
        },
        "torque_Nm": float(mesh.torque),
        "total_normal_load_N": float(mesh.total_load),
        "mean_mesh_stiffness_N_per_m": float(np.mean(np.asarray(mesh.mesh_stiffness))),
        "static_te_peak_to_peak_um": float((te.max() - te.min()) * 1e6),
        "max_hertz_pressure_GPa": float(np.max(np.asarray(mesh.hertz_pressure)) / 1e9),
    }


def run(args: argparse.Namespace) -> int:
    import jaxgear as jg
    from jaxgear.cli.config import (
        check_top_level,
        gear_pair_from_config,
        load_toml,
        operating_from_config,
    )

    cfg = load_toml(args.config) if args.config else {}
    check_top_level(cfg, ("gear", "operating"))
    pair = gear_pair_from_config(cfg)
    torque = (
        args.torque if args.torque is not None else operating_from_config(cfg).get("torque", 700.0)
    )
    mesh = jg.mesh_cycle(pair, torque, args.positions, stiffness=args.stiffness)
    geo = jg.gear_geometry(pair)
    rows = _rows(mesh)
    names = [c[0] for c in COLUMNS]
    summary = _summary(pair, geo, mesh)

    if args.format == "csv":
        buf = io.StringIO()
        writer = csv.writer(buf)
        writer.writerow(names)
        writer.writerows([[f"{v:.8g}" for v in r] for r in rows])
        print(buf.getvalue(), end="")
    elif args.format == "json":
        print(
            json.dumps(
                {
                    "summary": summary,
                    "columns": dict(COLUMNS),
                    "rows": [dict(zip(names, r)) for r in rows],
                },
                indent=1,
            )
        )
    else:
        print(json.dumps(summary, indent=1))
        short = ["roll_deg", "share1", "share2", "ph1_GPa", "ph2_GPa", "km_1e8", "TE_um"]
        print(" ".join(f"{h:>9}" for h in short))
        for r in rows:
            vals = (r[0], r[3], r[4], r[7], r[8], r[11] / 1e8, r[12])
            print(" ".join(f"{v:9.4f}" for v in vals))

    if args.out is not None:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        with open(out / "mesh_cycle.csv", "w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(names)
            writer.writerows([[f"{v:.10g}" for v in r] for r in rows])
        (out / "mesh_cycle.json").write_text(
            json.dumps(
                {
                    "summary": summary,
                    "columns": dict(COLUMNS),
                    "rows": [dict(zip(names, r)) for r in rows],
                },
                indent=1,
            )
        )
        from jaxgear.plotting import plot_mesh_cycle

        plot_mesh_cycle(mesh, out / "mesh_cycle.png")
        print(
            f"wrote {out / 'mesh_cycle.csv'}, {out / 'mesh_cycle.json'}, {out / 'mesh_cycle.png'}"
        )
    return 0
