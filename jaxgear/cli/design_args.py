"""Command-line edges of the design tools: limits with units ("dte_rms<=1.5um"), and the
design quantities' display units."""

from __future__ import annotations

import re

from jaxgear.design.problem import CONSTRAINTS

#: Units accepted per SI unit → factor to SI.
UNITS = {
    "m": {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "nm": 1e-9},
    "Pa": {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9},
    "K": {"K": 1.0},
    "W": {"W": 1.0, "kW": 1e3},
    "-": {"": 1.0, "%": 1e-2},
}
#: Display unit per quantity at this edge: (suffix, factor from SI).
DISPLAY = {
    "efficiency": ("percent", 100.0),
    "power_loss": ("W", 1.0),
    "power_loss_sliding": ("W", 1.0),
    "power_loss_rolling": ("W", 1.0),
    "dte_rms": ("um", 1e6),
    "dte_rms_max": ("um", 1e6),
    "hertz_pressure": ("GPa", 1e-9),
    "flash_temperature": ("K", 1.0),
}

_PATTERN = re.compile(r"^\s*([a-z_]+)\s*(<=|>=)\s*([-+0-9.eE]+)\s*([a-zA-Zµ%]*)\s*$")


def parse_limit(text: str) -> tuple[str, float]:
    """ "dte_rms<=1.5um" → ("dte_rms", 1.5e-6) (SI). Upper limits take <=, the efficiency's lower
    limit >= (a fraction, or percent with %); dimensional limits need a unit."""
    match = _PATTERN.match(text)
    if match is None:
        raise ValueError(
            f"--constraint {text!r} must read NAME<=VALUE UNIT (or efficiency>=VALUE), e.g. "
            "dte_rms<=1.5um, hertz_pressure<=1.2GPa"
        )
    name, op, number, unit = match.groups()
    if name not in CONSTRAINTS:
        raise ValueError(
            f"--constraint {text!r}: unknown quantity {name!r}; valid names: "
            f"{', '.join(CONSTRAINTS)}"
        )
    si_unit, kind = CONSTRAINTS[name]
    wanted = ">=" if kind == "lower" else "<="
    if op != wanted:
        article = "a lower" if kind == "lower" else "an upper"
        raise ValueError(
            f"--constraint {text!r}: {name} takes {article} limit; write {name}{wanted}…"
        )
    units = UNITS[si_unit]
    if unit not in units:
        valid = ", ".join(u or "(none)" for u in units)
        raise ValueError(f"--constraint {text!r}: unit {unit or '(none)'!r}; valid units: {valid}")
    try:
        value = float(number)
    except ValueError:
        raise ValueError(f"--constraint {text!r}: {number!r} is not a number") from None
    return name, value * units[unit]


def parse_limits(texts) -> dict:
    """Several --constraint values → {quantity: SI limit}; a quantity given twice is an error."""
    out = {}
    for text in texts or ():
        name, value = parse_limit(text)
        if name in out:
            raise ValueError(f"--constraint {name} is given twice")
        out[name] = value
    return out


def display(name: str, value) -> tuple[str, float]:
    """(label with unit, value in that unit) for a report."""
    suffix, factor = DISPLAY.get(name, ("", 1.0))
    label = f"{name}_{suffix}" if suffix else name
    return label, float(value) * factor
