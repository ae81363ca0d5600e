"""TOML configuration → jaxgear inputs. Units at the edge (mm, µm, degrees, N m) are converted once.

Unknown keys, wrong types and out-of-range values raise ``ValueError`` naming the key, so the command
line can report them with exit code 2.

Schema (every table and key optional; missing ``[gear]`` means the paper's pair)::

    [gear]
    preset = "li2015"            # base to override (default "li2015"; "none" = all keys given)
    teeth = [50, 50]
    module_mm = 3.0
    pressure_angle_deg = 20.0
    face_width_mm = 20.0
    profile_shift = [0.0, 0.0]
    addendum_coefficient = 1.0
    dedendum_coefficient = 1.25
    tip_diameter_mm = [156.0, 156.0]
    root_diameter_mm = [140.0, 140.0]
    centre_distance_mm = 150.0
    backlash_mm = 0.14
    blank_mass_kg = [2.77, 2.77]
    blank_inertia_kgm2 = [7.8e-3, 7.8e-3]

    [gear.tip_relief]
    amount_um = 10.0             # scalar or [gear 1, gear 2]
    start_roll_angle_deg = 20.9
    shape = "linear"             # or "parabolic"

    [gear.bearings]              # SI: N/m, N s/m, N m s/rad
    ky = 1.15e9
    cy = 5360.0
    kx = 8.0e8
    cx = 2980.0
    ct = 10.0

    [operating]
    torque_Nm = 700.0
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

from .gear.pair import Bearings, GearPair, TipRelief

_GEAR_KEYS = {
    "preset": str,
    "teeth": list,
    "module_mm": float,
    "pressure_angle_deg": float,
    "face_width_mm": float,
    "profile_shift": (float, list),
    "addendum_coefficient": float,
    "dedendum_coefficient": float,
    "tip_diameter_mm": (float, list),
    "root_diameter_mm": (float, list),
    "centre_distance_mm": float,
    "backlash_mm": float,
    "blank_mass_kg": (float, list),
    "blank_inertia_kgm2": (float, list),
    "tip_relief": dict,
    "bearings": dict,
}
_RELIEF_KEYS = {
    "amount_um": (float, list),
    "start_roll_angle_deg": (float, list),
    "shape": (str, list),
}
_BEARING_KEYS = {k: (float, list) for k in ("ky", "cy", "kx", "cx", "ct")}
_OPERATING_KEYS = {"torque_Nm": float, "speed_rpm": float, "inlet_temperature_C": float}


def load_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML file; a missing file or a syntax error becomes a ValueError naming the file."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"config file {str(path)!r} does not exist")
    try:
        return tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise ValueError(f"config file {str(path)!r} is not valid TOML: {err}") from None


def check_keys(table: dict, allowed: dict, where: str) -> None:
    """Unknown keys and wrong types raise ValueError naming ``where.key``."""
    for key, value in table.items():
        if key not in allowed:
            raise ValueError(
                f"unknown key {where}.{key} in config; valid keys: {', '.join(sorted(allowed))}"
            )
        kinds = allowed[key] if isinstance(allowed[key], tuple) else (allowed[key],)
        ok = any(_is_kind(value, kind) for kind in kinds)
        if not ok:
            names = " or ".join("number" if k is float else k.__name__ for k in kinds)
            raise ValueError(f"{where}.{key} = {value!r} has the wrong type; expected {names}")


def _is_kind(value, kind) -> bool:
    if kind is float:
        return isinstance(value, int | float) and not isinstance(value, bool)
    if kind is list:
        return isinstance(value, list) and all(
            isinstance(v, int | float | str) and not isinstance(v, bool) for v in value
        )
    return isinstance(value, kind)


def _scaled(value, factor):
    if isinstance(value, list):
        if len(value) != 2:
            raise ValueError(f"expected a pair [gear 1, gear 2]; got {value!r}")
        return tuple(float(v) * factor for v in value)
    return float(value) * factor


def gear_pair_from_config(cfg: dict[str, Any]) -> GearPair:
    """Build a GearPair from the ``[gear]`` table of a config dict (see the module docstring)."""
    from . import presets

    gear = dict(cfg.get("gear", {}))
    check_keys(gear, _GEAR_KEYS, "gear")
    preset = gear.pop("preset", "li2015")
    if preset not in ("li2015", "none"):
        raise ValueError(f"gear.preset = {preset!r} is not valid; valid choices: 'li2015', 'none'")
    relief_cfg = gear.pop("tip_relief", None)
    bearing_cfg = gear.pop("bearings", None)
    if relief_cfg is not None:
        check_keys(relief_cfg, _RELIEF_KEYS, "gear.tip_relief")
    if bearing_cfg is not None:
        check_keys(bearing_cfg, _BEARING_KEYS, "gear.bearings")

    if preset == "li2015":
        base = presets.li2015_pair()
        kwargs: dict[str, Any] = dict(
            teeth=base.teeth,
            module=base.module,
            pressure_angle=base.pressure_angle,
            face_width=base.face_width,
            tip_radius=base.tip_radius,
            root_radius=base.root_radius,
            centre_distance=base.centre_distance,
            backlash=base.backlash,
            bearings=base.bearings,
            tip_relief=base.tip_relief,
        )
        # Changing the basic geometry invalidates the preset's explicit radii and centre distance.
        if any(k in gear for k in ("teeth", "module_mm", "pressure_angle_deg", "profile_shift")):
            for k in ("tip_radius", "root_radius", "centre_distance"):
                kwargs.pop(k)
    else:
        for required in ("teeth", "module_mm", "pressure_angle_deg", "face_width_mm"):
            if required not in gear:
                raise ValueError(f"gear.{required} is required when gear.preset = 'none'")
        kwargs = {}

    if "teeth" in gear:
        teeth = gear["teeth"]
        if len(teeth) != 2 or not all(isinstance(t, int) for t in teeth):
            raise ValueError(f"gear.teeth = {teeth!r} must be a pair of integers")
        kwargs["teeth"] = tuple(teeth)
    simple = {
        "module_mm": ("module", 1e-3),
        "pressure_angle_deg": ("pressure_angle", math.pi / 180.0),
        "face_width_mm": ("face_width", 1e-3),
        "profile_shift": ("profile_shift", 1.0),
        "addendum_coefficient": ("addendum_coefficient", 1.0),
        "dedendum_coefficient": ("dedendum_coefficient", 1.0),
        "tip_diameter_mm": ("tip_radius", 0.5e-3),
        "root_diameter_mm": ("root_radius", 0.5e-3),
        "centre_distance_mm": ("centre_distance", 1e-3),
        "backlash_mm": ("backlash", 1e-3),
        "blank_mass_kg": ("blank_mass", 1.0),
        "blank_inertia_kgm2": ("blank_inertia", 1.0),
    }
    for key, (name, factor) in simple.items():
        if key in gear:
            try:
                kwargs[name] = _scaled(gear[key], factor)
            except ValueError as err:
                raise ValueError(f"gear.{key}: {err}") from None
    if relief_cfg is not None:
        old = kwargs.get("tip_relief", TipRelief())
        shape = relief_cfg.get("shape", old.shape)
        kwargs["tip_relief"] = TipRelief(
            amount=_scaled(relief_cfg["amount_um"], 1e-6)
            if "amount_um" in relief_cfg
            else old.amount,
            start_roll_angle=(
                _scaled(relief_cfg["start_roll_angle_deg"], math.pi / 180.0)
                if "start_roll_angle_deg" in relief_cfg
                else old.start_roll_angle
            ),
            shape=tuple(shape) if isinstance(shape, list) else shape,
        )
    if bearing_cfg is not None:
        old = kwargs.get("bearings", Bearings())
        kwargs["bearings"] = Bearings(
            **{
                k: (_scaled(bearing_cfg[k], 1.0) if k in bearing_cfg else getattr(old, k))
                for k in _BEARING_KEYS
            }
        )
    return GearPair(**kwargs)


def operating_from_config(cfg: dict[str, Any]) -> dict[str, float]:
    """The ``[operating]`` table in SI: torque (N m), speed_rpm, inlet_temperature (K)."""
    op = dict(cfg.get("operating", {}))
    check_keys(op, _OPERATING_KEYS, "operating")
    out = {}
    if "torque_Nm" in op:
        out["torque"] = float(op["torque_Nm"])
    if "speed_rpm" in op:
        out["speed_rpm"] = float(op["speed_rpm"])
    if "inlet_temperature_C" in op:
        out["inlet_temperature"] = float(op["inlet_temperature_C"]) + 273.15
    return out


def check_top_level(cfg: dict[str, Any], allowed: tuple[str, ...]) -> None:
    """Unknown top-level tables raise ValueError."""
    for key in cfg:
        if key not in allowed:
            raise ValueError(f"unknown table [{key}] in config; valid tables: {', '.join(allowed)}")
