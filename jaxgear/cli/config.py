"""TOML configuration → jaxgear inputs. Units at the edge (mm, µm, degrees, N m) are converted once.

Unknown keys, wrong types and out-of-range values raise ``ValueError`` naming the key, so the command
line can report them with exit code 2.

Schema (every table and key optional; missing ``[gear]`` means the paper's pair)::

    [gear]
    preset = "li2015"            # base to override: "li2015", "li2015_calibrated" (blanks tuned to
                                 # the paper's resonances) or "none" (all keys given)
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
    mesh_damping_ratio = 0.0     # viscous damping along the line of action (0: the paper's model)

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

``jaxgear sweep`` adds ``[lubricant]``, ``[surfaces]``, ``[fidelity]`` and ``[sweep]`` (see
``sweep_from_config`` and ``examples/sweep.toml``).
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from ..fidelity import NAMED_PRESETS
from ..gear.pair import Bearings, GearPair, TipRelief

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
    "mesh_damping_ratio": float,
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
            word = {float: "number", int: "integer", bool: "true or false", str: "string"}
            names = " or ".join(word.get(k, k.__name__) for k in kinds)
            raise ValueError(f"{where}.{key} = {value!r} has the wrong type; expected {names}")


def _is_kind(value, kind) -> bool:
    if kind is int:
        return isinstance(value, int) and not isinstance(value, bool)
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


GEAR_PRESETS = ("li2015", "li2015_calibrated", "none")


def gear_pair_from_config(cfg: dict[str, Any], default_preset: str = "li2015") -> GearPair:
    """Build a GearPair from the ``[gear]`` table of a config dict (see the module docstring)."""
    from .. import presets

    gear = dict(cfg.get("gear", {}))
    check_keys(gear, _GEAR_KEYS, "gear")
    preset = gear.pop("preset", default_preset)
    if preset not in GEAR_PRESETS:
        raise ValueError(
            f"gear.preset = {preset!r} is not valid; valid choices: "
            + ", ".join(map(repr, GEAR_PRESETS))
        )
    relief_cfg = gear.pop("tip_relief", None)
    bearing_cfg = gear.pop("bearings", None)
    if relief_cfg is not None:
        check_keys(relief_cfg, _RELIEF_KEYS, "gear.tip_relief")
    if bearing_cfg is not None:
        check_keys(bearing_cfg, _BEARING_KEYS, "gear.bearings")

    if preset in ("li2015", "li2015_calibrated"):
        base = presets.li2015_pair() if preset == "li2015" else presets.li2015_pair_calibrated()
        kwargs: dict[str, Any] = dict(
            teeth=base.teeth,
            module=base.module,
            pressure_angle=base.pressure_angle,
            face_width=base.face_width,
            profile_shift=base.profile_shift,
            addendum_coefficient=base.addendum_coefficient,
            dedendum_coefficient=base.dedendum_coefficient,
            backlash=base.backlash,
            bearings=base.bearings,
            tip_relief=base.tip_relief,
        )
        if preset == "li2015_calibrated":
            kwargs.update(blank_mass=base.blank_mass, blank_inertia=base.blank_inertia)
        # The preset's radii and centre distance follow from its coefficients (so from a new
        # module or shift too); its calibrated blanks belong to its own geometry.
        if any(k in gear for k in ("teeth", "module_mm", "pressure_angle_deg", "profile_shift")):
            for k in ("blank_mass", "blank_inertia"):
                kwargs.pop(k, None)
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
        "mesh_damping_ratio": ("mesh_damping_ratio", 1.0),
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


# ---------------------------------------------------------------------------------------------------
# ``jaxgear sweep``: the whole of jg.sweep's inputs from one TOML file.

SWEEP_TABLES = ("gear", "lubricant", "surfaces", "operating", "fidelity", "sweep")
LUBRICANT_PRESETS = ("mil_l_23699", "iso_vg68")
SURFACE_PRESETS = ("ground", "polished", "smooth")
FIDELITY_PRESETS = (*NAMED_PRESETS, "auto")
_SURFACE_KEYS = {
    "preset": str,
    "scale": float,
    "seed": int,
    "rq_um": float,
    "correlation_length_um": float,
    "short_cutoff_um": float,
}
_SWEEP_KEYS = {
    "speeds_rpm": list,
    "speed_range_rpm": list,
    "mode": str,
    "chunk_size": int,
    "checkpoint": bool,
    "quasi_static_reference": bool,
    "progress": bool,
    "vary": dict,
}
# Other inputs varied point by point, at the edge units of the TOML → (jg.sweep name, factor, offset).
_VARY_KEYS = {
    "torque_Nm": ("torque", 1.0, 0.0),
    "inlet_temperature_C": ("inlet_temperature", 1.0, 273.15),
    "roughness_scale": ("roughness_scale", 1.0, 0.0),
    "tip_relief_um": ("tip_relief_amount", 1e-6, 0.0),
    "mesh_damping_ratio": ("mesh_damping_ratio", 1.0, 0.0),
}
MAX_SWEEP_POINTS = 100_000


@dataclasses.dataclass(frozen=True)
class SweepConfig:
    """Everything ``jaxgear sweep`` needs, in SI (speeds in rpm), plus ``echo``: the resolved inputs
    at the edge units, for the summary. Built by ``sweep_from_config``."""

    pair: Any
    lubricant: Any
    surfaces: Any
    op: Any
    fidelity: Any
    speeds: np.ndarray
    vary: dict
    mode: str
    chunk_size: int
    checkpoint: bool
    quasi_static_reference: bool
    progress: bool
    echo: dict
    fidelity_reasons: str | None = None


def _lubricant_keys() -> dict:
    from ..lubrication.lubricant import Lubricant

    keys: dict[str, Any] = {"preset": str}
    for f in dataclasses.fields(Lubricant):
        keys[f.name] = str if f.name == "temperature_model" else float
    return keys


def lubricant_from_config(cfg: dict[str, Any]):
    """``[lubricant]``: ``preset`` ("mil_l_23699" or "iso_vg68") and any ``jg.Lubricant`` field to
    override, in that class's SI units (e.g. ``kinematic_viscosity_40 = 2.5e-5`` m²/s,
    ``eyring_stress = 5e6`` Pa)."""
    from .. import presets

    table = dict(cfg.get("lubricant", {}))
    check_keys(table, _lubricant_keys(), "lubricant")
    name = table.pop("preset", "mil_l_23699")
    if name not in LUBRICANT_PRESETS:
        raise ValueError(
            f"lubricant.preset = {name!r} is not valid; valid choices: "
            + ", ".join(map(repr, LUBRICANT_PRESETS))
        )
    lub = getattr(presets, name)()
    if table:
        try:
            lub = dataclasses.replace(lub, **table)
        except ValueError as err:
            raise ValueError(str(err).replace("Lubricant.", "lubricant.")) from None
    return lub, {"preset": name, **table}


def surfaces_from_config(cfg: dict[str, Any]):
    """``[surfaces]``: ``preset`` ("ground", "polished", "smooth"), ``scale`` (≥ 0), ``seed`` of the
    synthetic profiles, and optionally ``rq_um`` / ``correlation_length_um`` / ``short_cutoff_um``
    (the stylus cutoff λs) for other synthetic Gaussian profiles (REFERENCE §6)."""
    from .. import presets
    from .._validation import check_non_negative, check_positive
    from ..lubrication import roughness

    table = dict(cfg.get("surfaces", {}))
    check_keys(table, _SURFACE_KEYS, "surfaces")
    name = table.get("preset", "ground")
    if name not in SURFACE_PRESETS:
        raise ValueError(
            f"surfaces.preset = {name!r} is not valid; valid choices: "
            + ", ".join(map(repr, SURFACE_PRESETS))
        )
    scale = float(table.get("scale", 1.0))
    check_non_negative("surfaces.scale", scale)
    seed = table.get("seed", 0)
    if seed < 0:
        raise ValueError(f"surfaces.seed = {seed} is out of range; valid range: integer >= 0")
    kwargs = {}
    if "correlation_length_um" in table:
        check_positive("surfaces.correlation_length_um", table["correlation_length_um"], "µm")
        kwargs["correlation_length"] = table["correlation_length_um"] * 1e-6
    if "short_cutoff_um" in table:
        check_positive("surfaces.short_cutoff_um", table["short_cutoff_um"], "µm")
        kwargs["short_cutoff"] = table["short_cutoff_um"] * 1e-6
    if name == "smooth":
        extra = sorted(set(table) - {"preset"})
        if extra:
            raise ValueError(
                f"surfaces.{extra[0]} has no meaning with surfaces.preset = 'smooth'; remove it"
            )
        surf = presets.smooth()
    elif "rq_um" in table:
        check_non_negative("surfaces.rq_um", table["rq_um"], "µm")
        surf = roughness.synthetic(table["rq_um"] * 1e-6, scale=scale, seed=seed, **kwargs)
    else:
        surf = getattr(presets, name)(scale=scale, seed=seed, **kwargs)
    return surf, {"preset": name, "scale": scale, "seed": seed} | {
        k: table[k] for k in ("rq_um", "correlation_length_um", "short_cutoff_um") if k in table
    }


def _fidelity_keys() -> dict:
    from ..fidelity.ladder import FLAT_DEFAULTS

    keys: dict[str, Any] = {"preset": str, "tolerance": float}
    for name, default in FLAT_DEFAULTS.items():
        # a None default (fixed_point_tolerance: chosen by the rung; limiting_shear_coefficient:
        # no cap) is given as a number or left out
        kind = float if default is None else type(default)
        keys[name] = {bool: bool, int: int, float: float, str: str}[kind]
    return keys


def fidelity_from_config(cfg: dict[str, Any], preset: str | None = None):
    """``[fidelity]``: ``preset`` ("fast", "paper", "paper_calibrated" or "auto"; ``preset``
    given here, e.g. from the command line, wins) and any ``jg.Fidelity`` field to override
    (``n_positions = 24``, ``dynamics = "quasi_static"``...).

    Returns (Fidelity, echo). With preset "auto" the Fidelity is the *base* of the choice: its
    ladder fields (physics axes and resolution) must be left out, since ``Fidelity.auto`` sets
    them; ``tolerance`` (default 0.05) is the choice's tolerance and the caller makes the choice
    (it needs the scenario: see ``sweep_from_config``)."""
    from ..fidelity import Fidelity
    from ..fidelity.choose import LADDER_FIELDS

    table = dict(cfg.get("fidelity", {}))
    check_keys(table, _fidelity_keys(), "fidelity")
    name = preset if preset is not None else table.get("preset", "fast")
    table.pop("preset", None)
    if name not in FIDELITY_PRESETS:
        raise ValueError(
            f"fidelity preset = {name!r} is not valid; valid choices: "
            + ", ".join(map(repr, FIDELITY_PRESETS))
        )
    echo = {"preset": name, **table}
    tolerance = table.pop("tolerance", None)
    if name == "auto":
        chosen_here = sorted(set(table) & set(LADDER_FIELDS))
        if chosen_here:
            raise ValueError(
                f"fidelity.{chosen_here[0]} is chosen by preset = 'auto'; remove it, or give "
                "preset 'fast' or 'paper' to set it"
            )
        tolerance = 0.05 if tolerance is None else tolerance
        if not 0.0 < tolerance < 1.0:
            raise ValueError(
                f"fidelity.tolerance = {tolerance!r} is out of range; valid range: (0, 1)"
            )
        echo["tolerance"] = tolerance
    elif tolerance is not None:
        raise ValueError(
            f"fidelity.tolerance has no meaning with preset = {name!r}; it is the tolerance of "
            "preset = 'auto'"
        )
    try:
        fid = Fidelity(**table) if name == "auto" else Fidelity.named(name, **table)
    except ValueError as err:
        raise ValueError(str(err).replace("Fidelity.", "fidelity.")) from None
    return fid, echo


def _speeds(table) -> np.ndarray:
    from .._validation import check_positive

    if ("speeds_rpm" in table) == ("speed_range_rpm" in table):
        raise ValueError(
            "[sweep] needs exactly one of speeds_rpm = [list of rpm] or "
            "speed_range_rpm = [start, stop, step]"
        )
    if "speeds_rpm" in table:
        speeds = table["speeds_rpm"]
        if not speeds or not all(_is_kind(v, float) for v in speeds):
            raise ValueError(f"sweep.speeds_rpm = {speeds!r} must be a non-empty list of numbers")
        speeds = np.asarray(speeds, dtype=float)
        check_positive("sweep.speeds_rpm", speeds, "rpm")
        return speeds
    rng = table["speed_range_rpm"]
    if len(rng) != 3 or not all(_is_kind(v, float) for v in rng):
        raise ValueError(
            f"sweep.speed_range_rpm = {rng!r} must be [start, stop, step] in rpm, "
            "e.g. [500, 4200, 25]"
        )
    start, stop, step = (float(v) for v in rng)
    if not (start > 0 and stop >= start and step > 0):
        raise ValueError(
            f"sweep.speed_range_rpm = {rng!r} is out of range; valid range: "
            "0 < start <= stop, step > 0 (rpm)"
        )
    if (stop - start) / step + 1 > MAX_SWEEP_POINTS:
        raise ValueError(
            f"sweep.speed_range_rpm = {rng!r} gives more than {MAX_SWEEP_POINTS} points; "
            "valid range: at most that many"
        )
    return np.arange(start, stop + 0.5 * step, step)


def _vary(table, n) -> tuple[dict, dict]:
    from .._validation import check_non_negative, check_positive, check_range

    vary = dict(table.get("vary", {}))
    check_keys(vary, {k: (float, list) for k in _VARY_KEYS}, "sweep.vary")
    out, echo = {}, {}
    for key, value in vary.items():
        arr = np.atleast_1d(np.asarray(value, dtype=float))
        if arr.size not in (1, n):
            raise ValueError(
                f"sweep.vary.{key} has {arr.size} values; valid: 1 or one per speed ({n})"
            )
        where = f"sweep.vary.{key}"
        if key == "torque_Nm":
            check_positive(where, arr, "N m")
        elif key == "inlet_temperature_C":
            check_range(where, arr, -73.15, 326.85, unit="°C")
        elif key == "mesh_damping_ratio":
            check_range(where, arr, 0.0, 1.0, high_inclusive=False)
        else:
            check_non_negative(where, arr)
        name, factor, offset = _VARY_KEYS[key]
        out[name] = arr * factor + offset
        echo[key] = value
    return out, echo


def sweep_from_config(cfg: dict[str, Any], fidelity: str | None = None) -> SweepConfig:
    """Resolve a ``jaxgear sweep`` config (examples/sweep.toml shows every key):

    - ``[gear]`` as for ``jaxgear mesh`` (default preset "li2015_calibrated", the pair of ``jaxgear
      run``); ``[lubricant]``, ``[surfaces]``, ``[fidelity]``: see their ``*_from_config``.
    - ``[operating]``: ``torque_Nm`` (default 700), ``inlet_temperature_C`` (default 90); the speeds
      come from ``[sweep]``.
    - ``[sweep]``: ``speeds_rpm = [...]`` or ``speed_range_rpm = [start, stop, step]``; ``mode``
      ("continuation", the paper's stepwise speed increase, default; or "parallel"); ``chunk_size``
      (default 50); ``checkpoint`` (default true: finished chunks in ``<out>/checkpoint`` so an
      interrupted sweep resumes); ``quasi_static_reference`` (default true for a tribo-dynamic sweep:
      also sweep the quasi-static model, as the paper's Fig. 4 compares them); ``progress`` (default
      true); ``[sweep.vary]``: ``torque_Nm``, ``inlet_temperature_C``, ``roughness_scale``,
      ``tip_relief_um``, ``mesh_damping_ratio`` per speed (a list as long as the speeds) or one
      value.

    Raises ValueError naming the key, the value and the valid range.
    """
    from .._validation import check_positive, check_range
    from ..operating import OperatingPoint

    check_top_level(cfg, SWEEP_TABLES)
    pair = gear_pair_from_config(cfg, default_preset="li2015_calibrated")
    lub, lub_echo = lubricant_from_config(cfg)
    surf, surf_echo = surfaces_from_config(cfg)
    fid, fid_echo = fidelity_from_config(cfg, fidelity)

    op_table = dict(cfg.get("operating", {}))
    check_keys(op_table, _OPERATING_KEYS, "operating")
    if "speed_rpm" in op_table:
        raise ValueError(
            "operating.speed_rpm is not used by jaxgear sweep; give the speeds in [sweep] "
            "(speeds_rpm or speed_range_rpm)"
        )
    torque = float(op_table.get("torque_Nm", 700.0))
    inlet_c = float(op_table.get("inlet_temperature_C", 90.0))
    check_positive("operating.torque_Nm", torque, "N m")
    check_range("operating.inlet_temperature_C", inlet_c, -73.15, 326.85, unit="°C")

    table = dict(cfg.get("sweep", {}))
    check_keys(table, _SWEEP_KEYS, "sweep")
    speeds = _speeds(table)
    vary, vary_echo = _vary(table, speeds.size)
    mode = table.get("mode", "continuation")
    if mode not in ("continuation", "parallel"):
        raise ValueError(
            f"sweep.mode = {mode!r} is not valid; valid choices: 'continuation', 'parallel'"
        )
    chunk = table.get("chunk_size", 50)
    if chunk < 1:
        raise ValueError(f"sweep.chunk_size = {chunk} is out of range; valid range: integer >= 1")
    op = OperatingPoint(
        torque=torque, speed_rpm=float(speeds[0]), inlet_temperature=inlet_c + 273.15
    )
    reasons = None
    if fid_echo["preset"] == "auto":
        fid, reasons = _auto_fidelity(pair, lub, surf, op, speeds, vary, fid, fid_echo["tolerance"])
    reference = table.get("quasi_static_reference", fid.dynamics == "tribo_dynamic")
    if reference and fid.dynamics == "quasi_static":
        reference = False  # the sweep is the quasi-static model already
    echo = {
        "gear": dict(cfg.get("gear", {})) or {"preset": "li2015_calibrated"},
        "lubricant": lub_echo,
        "surfaces": surf_echo,
        "operating": {"torque_Nm": torque, "inlet_temperature_C": inlet_c},
        "fidelity": fid_echo,
        "sweep": {
            "speeds_rpm": [float(speeds[0]), float(speeds[-1]), int(speeds.size)],
            "mode": mode,
            "chunk_size": chunk,
            "quasi_static_reference": bool(reference),
            "vary": vary_echo,
        },
    }
    return SweepConfig(
        pair=pair,
        lubricant=lub,
        surfaces=surf,
        op=op,
        fidelity=fid,
        speeds=speeds,
        vary=vary,
        mode=mode,
        chunk_size=chunk,
        checkpoint=table.get("checkpoint", True),
        quasi_static_reference=bool(reference),
        progress=table.get("progress", True),
        echo=echo,
        fidelity_reasons=reasons,
    )


def _auto_fidelity(pair, lub, surf, op, speeds, vary, base, tolerance):
    """``[fidelity] preset = "auto"``: ``jg.choose_fidelity`` over the sweep's speeds, keeping the
    base's other fields. The indicators are those of ``[operating]``, so inputs that move them may
    not vary per speed."""
    from ..fidelity.choose import choose_fidelity

    moving = sorted(k for k in vary if k != "tip_relief_amount")
    if moving:
        key = {v[0]: k for k, v in _VARY_KEYS.items()}[moving[0]]
        raise ValueError(
            f"sweep.vary.{key} cannot be used with fidelity preset = 'auto' (the choice is made "
            "from [operating] and [surfaces]); set the value there, or give a fixed preset"
        )
    choice = choose_fidelity(pair, lub, surf, op, tolerance, speeds_rpm=speeds, base=base)
    return choice.fidelity, choice.reasons
