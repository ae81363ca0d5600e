"""``simulate``: one operating point of the coupled model, in two passes.

The first pass is the quasi-static rung, or the tribo-dynamic fixed point
(``fixed_point.py``); the second (``second_pass.finish``) is what only a few points need: the
attractor where no stable periodic orbit exists, the back flanks' loss where the gears strike them.
Called on concrete inputs, ``simulate`` compiles the second pass as a program of its own and runs
it only where the first pass asks for it, so no program carries what few points take. Called inside
a caller's ``jit``, ``grad`` or ``vmap`` (traced inputs), both passes are traced into the caller's
program, the second behind a vmap-lazy branch.
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp

from .._inputs import canonical, validate
from .._validation import check_instance, check_non_negative, is_concrete
from ..fidelity import Fidelity
from ..gear.geometry import gear_geometry
from ..gear.mesh import mesh_cycle
from ..gear.pair import GearPair
from ..lubrication.lubricant import Lubricant
from ..lubrication.roughness import Surfaces
from ..operating import OperatingPoint
from .fixed_point import Pending, WarmStart, cold_start, quasi_static, tribo_dynamic_fixed_point
from .result import (
    STATUS_DYNAMICS,
    STATUS_PENDING,
    SimulationResult,
    assemble,
    without_derivative_where,
)
from .second_pass import finish


def needs_second_pass(pending: Pending, fidelity: Fidelity):
    """Whether the point of ``pending`` needs ``finish``: no stable orbit (with the attractor
    on), or back-flank strikes on its orbit. False on the quasi-static rung (``pending`` None)."""
    if pending is None:
        return jnp.asarray(False)
    unstable = pending.unstable & (fidelity.attractor_periods > 0)
    return unstable | pending.strikes_back


def _deferred_result(pair, op, pending: Pending, fidelity: Fidelity) -> SimulationResult:
    """The result of a first pass whose second pass is deferred: the orbit's values; where the
    point needs the second pass, status 2 (no stable orbit) or 7 (back strikes not counted yet)
    and every derivative NaN (what the second pass will report has none, or another one)."""
    mesh = pending.mesh
    zeros = jnp.zeros(mesh.n_positions, dtype=pending.load.dtype)
    back = (jnp.zeros((), zeros.dtype), (zeros, zeros))
    result = assemble(
        pair, op, mesh, pending.forces, pending.load, pending.velocity, pending.dte,
        pending.status, pending.residual, pending.iterations, back, pending.damper,
    )
    unstable = pending.unstable & (fidelity.attractor_periods > 0)
    status = jnp.where(
        pending.strikes_back & ~unstable & (result.status == 0), STATUS_PENDING, result.status
    )
    status = jnp.where(unstable & (status == 0), STATUS_DYNAMICS, status).astype(jnp.int32)
    result = eqx.tree_at(lambda r: r.status, result, status)
    return without_derivative_where(result, needs_second_pass(pending, fidelity))


def first_pass(pair, lubricant, surfaces, op, fidelity, warm: WarmStart | None = None):
    """(SimulationResult with the second pass deferred, WarmStart, Pending or None). Traceable;
    ``warm``: a neighbouring point's state (continuation), ignored on the quasi-static rung."""
    mesh = mesh_cycle(pair, op.torque, fidelity.n_positions, stiffness=fidelity.stiffness)
    if fidelity.dynamics == "quasi_static":
        none = cold_start(fidelity.n_positions, op.torque.dtype)
        return quasi_static(pair, lubricant, surfaces, op, fidelity, mesh), none, None
    if warm is None:
        warm = cold_start(fidelity.n_positions, op.torque.dtype)
    pending, warm_out = tribo_dynamic_fixed_point(
        pair, lubricant, surfaces, op, fidelity, mesh, warm
    )
    return _deferred_result(pair, op, pending, fidelity), warm_out, pending


def simulate_with_state(pair, lubricant, surfaces, op, fidelity, warm: WarmStart | None = None):
    """``simulate`` that also returns the WarmStart of its converged state, with both passes in
    one program (traceable: no checks). The quasi-static rung's WarmStart is zeros. Call it
    inside ``jit`` (``eqx.filter_jit(simulate_with_state)``): run eagerly, the model's loops are
    compiled again at every call."""
    result, warm_out, pending = first_pass(pair, lubricant, surfaces, op, fidelity, warm)
    if pending is None:
        return result, warm_out
    return finish(pair, lubricant, surfaces, op, fidelity, pending)[0], warm_out


def _first_pass_outputs(pair, lubricant, surfaces, op, fidelity):
    result, _, pending = first_pass(pair, lubricant, surfaces, op, fidelity)
    return result, pending, needs_second_pass(pending, fidelity)


_first_pass_jit = eqx.filter_jit(_first_pass_outputs)


@eqx.filter_jit
def _finish_jit(pair, lubricant, surfaces, op, fidelity, pending):
    return finish(pair, lubricant, surfaces, op, fidelity, pending)[0]


@eqx.filter_jit
def _simulate_traced(pair, lubricant, surfaces, op, fidelity):
    return simulate_with_state(pair, lubricant, surfaces, op, fidelity)[0]


def simulate(
    pair: GearPair,
    lubricant,
    surfaces,
    op: OperatingPoint,
    fidelity: Fidelity | None = None,
) -> SimulationResult:
    """Power loss, efficiency and dynamic response of ``pair`` at ``op``.

    Args:
        pair: GearPair.
        lubricant: Lubricant (inlet viscosity, rheology).
        surfaces: Surfaces (roughness; ``jg.presets.smooth()`` for none).
        op: OperatingPoint (torque N m, speed rpm, inlet temperature K).
        fidelity: Fidelity (default ``Fidelity.fast()``).

    Returns:
        SimulationResult; ``converged``/``status`` report failures, never silent NaN.
        Differentiable in every float input, in forward mode (``jax.jvp``, ``jax.jacfwd``) and
        reverse mode (``jax.grad``, ``eqx.filter_grad``), except where the result is a mean over
        an attractor (status 6, no stable periodic orbit): there every derivative is NaN, since
        the mean over a rattle or a quasi-periodic motion is not a smooth function of the design;
        the value and its status are still reported.
    """
    fidelity = Fidelity.fast() if fidelity is None else fidelity
    check_inputs(pair, lubricant, surfaces, op, fidelity)
    # a field substituted by eqx.tree_at with a Python float becomes a float64 array here (not a
    # static leaf: no recompilation per value), and is checked as its constructor would
    pair, lubricant, surfaces, op, fidelity = canonical((pair, lubricant, surfaces, op, fidelity))
    validate((pair, lubricant, surfaces, op, fidelity))
    if is_concrete(surfaces):
        check_non_negative("surfaces.composite_rq", surfaces.composite_rq, "m")
    gear_geometry(pair)
    if not is_concrete((pair, lubricant, surfaces, op)):
        return _simulate_traced(pair, lubricant, surfaces, op, fidelity)
    result, pending, later = _first_pass_jit(pair, lubricant, surfaces, op, fidelity)
    if bool(later):
        result = _finish_jit(pair, lubricant, surfaces, op, fidelity, pending)
    return result


def check_inputs(pair, lubricant, surfaces, op, fidelity) -> None:
    """Types of ``simulate``'s (and ``sweep``'s) arguments: a wrong one would fail deep inside the
    trace with an AttributeError naming no argument."""
    check_instance("fidelity", fidelity, Fidelity)
    check_instance("op", op, OperatingPoint)
    check_instance("pair", pair, GearPair)
    check_instance("lubricant", lubricant, Lubricant)
    check_instance(
        "surfaces", surfaces, Surfaces, "a jaxgear.Surfaces (jg.presets.smooth() for none)"
    )
    for name in ("torque", "speed_rpm", "inlet_temperature"):
        shape = jnp.shape(getattr(op, name))
        if shape != ():
            raise ValueError(
                f"op.{name} has shape {shape}; valid: a scalar (use jg.sweep for many points)"
            )

