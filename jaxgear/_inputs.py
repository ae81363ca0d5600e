"""Input types' shared conventions: float leaves are float64 arrays, substitution is validated.

Every float field of an input type (``GearPair``, ``OperatingPoint``, ``Lubricant``, ``Surfaces``,
``Material``, a fidelity's model constants...) is a traced float64 array, so a new value never
recompiles and can be differentiated. ``eqx.tree_at`` bypasses an input's converters and checks: a
Python float put there by it would become a static leaf under ``eqx.filter_jit`` (a recompilation
per value, no derivative), and a bad value would go unchecked. So:

- ``replace(obj, **changes)`` (and each input's ``.replace``) is the supported way to substitute
  fields: dotted paths reach nested inputs (``"tip_relief.amount"``), values become float64 arrays
  broadcast to the old field's shape, and the result is validated as a constructor would.
- ``canonical(tree)`` turns any remaining Python or NumPy float leaf into a float64 array; the
  public entry points (``simulate``, ``sweep``, ...) apply it, and ``validate(tree)`` re-runs every
  Module's ``__check_init__`` on concrete inputs, so a value substituted by ``eqx.tree_at`` is
  still checked at the boundary.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from ._validation import is_concrete


def _float_dtype():
    return jnp.result_type(float)


def _is_float_like(x) -> bool:
    if isinstance(x, bool):
        return False
    if isinstance(x, int | float | np.floating | np.integer):
        return True
    dtype = getattr(x, "dtype", None)
    return dtype is not None and jnp.issubdtype(dtype, jnp.floating)


def canonical(tree):
    """``tree`` with every float leaf (Python, NumPy or weakly typed JAX) a strong float64 array
    (the default float dtype): equal shapes share one compiled program whatever the caller passed.
    Integer arrays, booleans and non-numeric leaves are left alone; tracers are left as they are."""

    def conv(x):
        if isinstance(x, jax.core.Tracer):
            return x
        if isinstance(x, int | np.integer) and not isinstance(x, bool):
            return x  # an integer leaf is a count or an index, not a physical value
        if _is_float_like(x):
            return jnp.asarray(x, dtype=_float_dtype())
        return x

    return jax.tree_util.tree_map(conv, tree)


def _modules(tree):
    """Every eqx.Module in ``tree`` (itself included), innermost first: a part's own checks
    (shapes, ranges) run before those of the input that holds it."""
    found = []

    def visit(node):
        if isinstance(node, eqx.Module):
            for name in _field_names(node):
                visit(getattr(node, name, None))
            found.append(node)
        elif isinstance(node, list | tuple):
            for item in node:
                visit(item)
        elif isinstance(node, dict):
            for item in node.values():
                visit(item)

    visit(tree)
    return found


def _field_names(module) -> list[str]:
    return [f.name for f in dataclasses.fields(module)]


def validate(tree) -> None:
    """Re-run the ``__check_init__`` of every Module in ``tree`` (each class of its MRO), as its
    constructor did: a value substituted by ``eqx.tree_at`` gets the same ``ValueError`` (field,
    value, valid range) as one passed to the constructor. Skipped where ``tree`` holds tracers."""
    if not is_concrete(tree):
        return
    for module in _modules(tree):
        for cls in type(module).__mro__:
            check = cls.__dict__.get("__check_init__")
            if check is not None:
                check(module)


def _getter(path: str):
    parts = path.split(".")

    def get(obj):
        for part in parts:
            obj = obj[int(part)] if part.isdigit() else getattr(obj, part)
        return obj

    return get


def replace(obj, **changes: Any):
    """A copy of the input ``obj`` with fields substituted and validated.

    Keys are field names or dotted paths into nested inputs (``"tip_relief.amount"``,
    ``"bearings.ky"``, ``"materials.0.youngs_modulus"``); since Python keywords cannot hold dots,
    pass those as ``**{"tip_relief.amount": 5e-6}``, or use a double underscore
    (``tip_relief__amount=5e-6``). A value becomes a float64 array and, where the old field is an
    array of shape (2,) (a per-gear value) and the new one a scalar, is broadcast to it. The copy
    is validated like a constructed one (``validate``): a bad value raises ``ValueError`` naming
    the field, the value and the valid range.
    """
    out = obj
    for key, value in changes.items():
        path = key.replace("__", ".")
        get = _getter(path)
        try:
            old = get(out)
        except (AttributeError, IndexError, TypeError):
            raise ValueError(
                f"{type(obj).__name__} has no field {path!r}; valid fields: "
                f"{', '.join(_field_names(obj))}"
            ) from None
        new = value
        numbers = isinstance(value, list | tuple) and not any(map(_is_module, value))
        if _is_float_like(value) or numbers:
            new = jnp.asarray(value, dtype=_float_dtype())
            old_shape = jnp.shape(old) if _is_float_like(old) else None
            if old_shape is not None and new.shape != old_shape:
                if new.shape == ():
                    new = jnp.broadcast_to(new, old_shape)
                else:
                    raise ValueError(
                        f"{type(obj).__name__}.{path} has shape {old_shape}; got a value of shape "
                        f"{new.shape}"
                    )
        out = eqx.tree_at(get, out, new, is_leaf=lambda x: x is None)
    validate(out)
    return out


def _is_module(x) -> bool:
    return isinstance(x, eqx.Module)
