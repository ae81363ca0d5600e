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
    return np.array2string(value, precision=6, threshold=8)


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
    check_finite(name, arr)
    ok_low = arr >= low if low_inclusive else arr > low
    ok_high = arr <= high if high_inclusive else arr < high
    if not np.all(ok_low & ok_high):
        lb = "[" if low_inclusive else "("
        hb = "]" if high_inclusive else ")"
        u = f" {unit}" if unit else ""
        raise ValueError(
            f"{name} = {_fmt(arr)}{u} is out of range; valid range: {lb}{low:g}, {high:g}{hb}{u}"
        )


def check_positive(name: str, value: Any, unit: str = "") -> None:
    """Raise unless every element is finite and strictly positive."""
    check_range(name, value, 0.0, math.inf, low_inclusive=False, unit=unit)


def check_non_negative(name: str, value: Any, unit: str = "") -> None:
    """Raise unless every element is finite and ≥ 0."""
    check_range(name, value, 0.0, math.inf, unit=unit)


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
