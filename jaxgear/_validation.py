"""Boundary checks: clear ``ValueError`` messages that name the field, the value and the valid range.

Checks run only on concrete values. Inside ``jit``/``vmap`` (tracers) they are skipped: validation is
done where the user builds inputs, in Python, and failures inside compiled code are reported through
``converged``/``status`` fields instead (see DESIGN §7).
"""

from __future__ import annotations

import math
from typing import Any

import jax
import numpy as np


def is_concrete(value: Any) -> bool:
    """True if ``value`` holds no JAX tracer (so it can be inspected in Python)."""
    leaves = jax.tree_util.tree_leaves(value)
    return not any(isinstance(leaf, jax.core.Tracer) for leaf in leaves)


def _as_array(value: Any) -> np.ndarray | None:
    if not is_concrete(value):
        return None
    return np.asarray(value, dtype=float)


def _fmt(value: np.ndarray) -> str:
    if value.ndim == 0:
        return f"{float(value):.6g}"
    # One line, whatever the rank: the CLI prints the message as a single line.
    text = np.array2string(value.ravel(), precision=6, threshold=8, max_line_width=10**9)
    return text if value.ndim == 1 else f"{text} (shape {value.shape})"


def check_finite(name: str, value: Any) -> None:
    """Raise if any element of ``value`` is NaN or infinite."""
    arr = _as_array(value)
    if arr is not None and not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} = {_fmt(arr)} is not finite; valid range: finite real numbers")


def check_range(
    name: str,
    value: Any,
    low: float = -math.inf,
    high: float = math.inf,
    *,
    low_inclusive: bool = True,
    high_inclusive: bool = True,
    unit: str = "",
) -> None:
    """Raise ``ValueError`` unless every element of ``value`` is finite and inside [low, high].

    The message names the field, the offending value and the valid range, e.g.
    ``face_width = -0.01 m is out of range; valid range: (0, inf) m``.
    """
    arr = _as_array(value)
    if arr is None:
        return
    # An infinite bound is never part of the range (only finite values pass).
    lb = "[" if low_inclusive and math.isfinite(low) else "("
    hb = "]" if high_inclusive and math.isfinite(high) else ")"
    u = f" {unit}" if unit else ""
    valid = f"valid range: {lb}{low:g}, {high:g}{hb}{u}"
    if not np.all(np.isfinite(arr)):
        # Name the real range, not just "finite": the user needs to know what to put instead.
        raise ValueError(f"{name} = {_fmt(arr)} is not finite; {valid}")
    ok_low = arr >= low if low_inclusive else arr > low
    ok_high = arr <= high if high_inclusive else arr < high
    if not np.all(ok_low & ok_high):
        raise ValueError(f"{name} = {_fmt(arr)}{u} is out of range; {valid}")


def check_positive(name: str, value: Any, unit: str = "") -> None:
    """Raise unless every element is finite and strictly positive."""
    check_range(name, value, 0.0, math.inf, low_inclusive=False, unit=unit)


def check_non_negative(name: str, value: Any, unit: str = "") -> None:
    """Raise unless every element is finite and ≥ 0."""
    check_range(name, value, 0.0, math.inf, unit=unit)


def check_instance(name: str, value: Any, cls: type, what: str | None = None) -> None:
    """Raise unless ``value`` is an instance of ``cls`` (a wrong type would fail later, obscurely)."""
    if not isinstance(value, cls):
        what = what or f"a jaxgear.{cls.__name__}"
        raise ValueError(f"{name} = {_short_repr(value)} is not valid; valid: {what}")


def check_integer(name: str, value: Any, low: int, high: int | None = None) -> None:
    """Raise unless ``value`` is a Python/NumPy integer (not bool) in [low, high]."""
    ok = isinstance(value, int | np.integer) and not isinstance(value, bool)
    ok = ok and value >= low and (high is None or value <= high)
    if not ok:
        top = "inf)" if high is None else f"{high}]"
        raise ValueError(
            f"{name} = {value!r} is out of range; valid range: integer in [{low}, {top}"
        )


def _short_repr(value: Any) -> str:
    text = repr(value) if isinstance(value, str | int | float | bool | None) else None
    return text if text is not None else f"<{type(value).__name__}>"


def check_choice(name: str, value: Any, choices: tuple) -> None:
    """Raise unless ``value`` is one of ``choices``."""
    if value not in choices:
        raise ValueError(
            f"{name} = {value!r} is not valid; valid choices: {', '.join(map(repr, choices))}"
        )


def check_float64(name: str, value: Any) -> None:
    """Raise if a floating array is not float64 where float32 cannot resolve the physics."""
    dtype = getattr(value, "dtype", None)
    if dtype is not None and np.issubdtype(dtype, np.floating) and dtype != np.float64:
        raise ValueError(
            f"{name} has dtype {dtype}; jaxgear needs float64 here. Enable it with "
            "jax.config.update('jax_enable_x64', True) before creating arrays."
        )


def check_shape(name: str, value: Any, shape: tuple[int, ...], what: str = "") -> None:
    """Raise unless ``value`` has the array shape ``shape`` (checked on tracers too: shapes are
    static). The message names the field, its shape and the valid shape, e.g.
    ``TipRelief.amount has shape (); valid shape: (2,) (one value per gear)``."""
    got = np.shape(value)
    if got != tuple(shape):
        note = f" ({what})" if what else ""
        raise ValueError(f"{name} has shape {got}; valid shape: {tuple(shape)}{note}")
