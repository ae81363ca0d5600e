"""The tip relief design problem over a duty cycle, as one traced function: the design variables
on the unit box → the objective, every constraint at every operating point, and the augmented
Lagrangian's value and reverse-mode gradient.

Design variables (SI): the relief amount (m) and start roll angle (rad), the same on both gears
(2 variables) or one pair per gear (4: amount₁, amount₂, start₁, start₂). An objective that is a
maximum over the duty cycle (``dte_rms_max``, the peaks of Hertz pressure and flash temperature) is
minimised in epigraph form: one more variable t ∈ [0, ``EPIGRAPH_MAX``] (the peak relative to its
value at the start) with the constraints q_k/q₀ − t ≤ 0 on every entry, so the problem stays smooth
where the peak moves from one point or mesh position to another.

Constraint scaling (g ≤ 0 feasible): an upper limit ℓ on q gives g = q/ℓ − 1; the efficiency's
lower limit ℓ gives g = (ℓ − Ψ)/(1 − ℓ), relative to the loss share, so 1e-3 means a loss 0.1 % above
its limit. Field quantities (per position and flank pair) give one constraint per entry.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from ..fidelity import Fidelity
from ..operating import OperatingPoint
from ..tribodynamics import first_pass
from . import metrics
from .relief import with_tip_relief

#: Objectives → (quantity, aggregate over the duty cycle, +1 maximise / −1 minimise).
OBJECTIVES = {
    "efficiency": ("efficiency", "mean", +1),
    "power_loss": ("power_loss", "mean", -1),
    "dte_rms": ("dte_rms", "mean", -1),
    "dte_rms_max": ("dte_rms", "max", -1),
    "hertz_pressure": ("hertz_pressure", "max", -1),
    "flash_temperature": ("flash_temperature", "max", -1),
}
#: Constrainable quantities → (unit, kind): "upper" limits q ≤ ℓ, "lower" limits q ≥ ℓ.
CONSTRAINTS = {
    "efficiency": ("-", "lower"),
    "power_loss": ("W", "upper"),
    "dte_rms": ("m", "upper"),
    "hertz_pressure": ("Pa", "upper"),
    "flash_temperature": ("K", "upper"),
}
#: Upper bound of the epigraph variable (peak relative to its start value).
EPIGRAPH_MAX = 2.0


class TipReliefProblem(eqx.Module):
    """The traced problem (array fields traced: new values or limits do not recompile).

    Attributes:
        pair, lubricant, surfaces, fidelity: the model inputs (the pair's relief is replaced).
        torques, speeds_rpm: the duty cycle's points, N m and rpm [P].
        inlet_temperature: K (the same at every point).
        lower, upper: bounds of the design variables, SI [n] (epigraph variable included).
        scale: objective units per unit of the scaled objective.
        reference: objective offset (mean objectives) or start peak (epigraph), natural units.
        objective: an ``OBJECTIVES`` name (static).
        constraint_names: the constrained quantities (static), their limits given per call.
        both_gears: 2 design variables (True) or 4 (static).
    """

    pair: object
    lubricant: object
    surfaces: object
    fidelity: Fidelity
    torques: Float[Array, " P"]
    speeds_rpm: Float[Array, " P"]
    inlet_temperature: Float[Array, ""]
    lower: Float[Array, " n"]
    upper: Float[Array, " n"]
    scale: Float[Array, ""]
    reference: Float[Array, ""]
    objective: str = eqx.field(static=True)
    constraint_names: tuple[str, ...] = eqx.field(static=True)
    both_gears: bool = eqx.field(static=True)

    @property
    def epigraph(self) -> bool:
        return OBJECTIVES[self.objective][1] == "max"

    @property
    def quantity_names(self) -> tuple[str, ...]:
        """The quantities computed per point: the objective's and the constrained ones."""
        names = [OBJECTIVES[self.objective][0], *self.constraint_names]
        return tuple(dict.fromkeys(names))

    def design(self, u):
        """Box coordinates [n] → design variables, SI [n]."""
        return self.lower + (self.upper - self.lower) * u

    def relief_pair(self, u):
        """The pair with the relief of box point u."""
        x = self.design(u)
        k = 2 if self.both_gears else 4
        return with_tip_relief(self.pair, x[:k], self.both_gears)

    def quantities(self, u):
        """Per point: {name: value [P] or [P, M, 2]} and converged [P]."""
        pair = self.relief_pair(u)
        names = self.quantity_names

        def one(torque, speed):
            op = OperatingPoint(
                torque=torque, speed_rpm=speed, inlet_temperature=self.inlet_temperature
            )
            # the second pass deferred: a point that needs it (no stable orbit, back strikes) is
            # not converged, and has no derivative
            result = first_pass(pair, self.lubricant, self.surfaces, op, self.fidelity)[0]
            return {n: metrics.quantity(n, result, pair) for n in names}, result.status

        return map_points(one, self.torques, self.speeds_rpm)

    def objective_value(self, values, u):
        """The objective in natural units (mean over points, or peak)."""
        name, aggregate, _ = OBJECTIVES[self.objective]
        q = values[name]
        if aggregate == "mean":
            return jnp.mean(q)
        return jnp.max(q)

    def constraints(self, values, limits, u):
        """g [m] ≤ 0 feasible: each constraint at every point (and entry), then the epigraph's."""
        parts = []
        for name, limit in zip(self.constraint_names, limits):
            q = values[name]
            if CONSTRAINTS[name][1] == "lower":
                parts.append(jnp.ravel((limit - q) / (1.0 - limit)))
            else:
                parts.append(jnp.ravel(q / limit - 1.0))
        if self.epigraph:
            q = values[OBJECTIVES[self.objective][0]]
            t = self.design(u)[-1]
            parts.append(jnp.ravel(q / self.reference - t))
        if not parts:
            return jnp.zeros((0,), dtype=u.dtype)
        return jnp.concatenate(parts)

    def merit(self, u, multipliers, rho, limits):
        """(L, (objective, g, peaks per point, status per point)): the augmented Lagrangian."""
        values, status = self.quantities(u)
        value = self.objective_value(values, u)
        sense = OBJECTIVES[self.objective][2]
        if self.epigraph:
            f = self.design(u)[-1]
        else:
            f = -sense * (value - self.reference) / self.scale
        g = self.constraints(values, limits, u)
        shifted = jnp.maximum(0.0, multipliers + rho * g)
        merit = f + jnp.sum(shifted**2 - multipliers**2) / (2.0 * rho)
        peaks = {n: metrics.peak(n, v) for n, v in values.items()}
        return merit, (value, g, peaks, status)


def _merit_and_gradient(problem, u, multipliers, rho, limits):
    (merit, aux), grad = jax.value_and_grad(problem.merit, has_aux=True)(
        u, multipliers, rho, limits
    )
    value, g, peaks, status = aux
    return {
        "merit": merit,
        "gradient": grad,
        "objective": value,
        "constraints": g,
        "peaks": peaks,
        "status": status,
    }


_merit_and_gradient_jit = eqx.filter_jit(_merit_and_gradient)


def merit_and_gradient(problem, u, multipliers, rho, limits):
    """The augmented Lagrangian, its gradient in u and its parts (a dict: merit, gradient,
    objective, constraints, peaks, status), from one compiled program per problem structure
    (fidelity, objective, constraint names, shapes). The numbers are taken as arrays of the
    default float dtype whatever the caller passes (a Python or NumPy scalar, an array): a weakly
    typed one would compile the program a second time."""
    dtype = jnp.result_type(float)
    numbers = (jnp.asarray(x, dtype=dtype) for x in (u, multipliers, rho, limits))
    return _merit_and_gradient_jit(problem, *numbers)


def batch_point(point, problem):
    """``merit_and_gradient`` of one problem of a batch (the sweep engine's point function):
    point = {"u", "multipliers", "rho", "limits"}."""
    out = _merit_and_gradient(
        problem, point["u"], point["multipliers"], point["rho"], point["limits"]
    )
    out["converged"] = jnp.all(out["status"] == 0)
    return out


@eqx.filter_jit
def evaluate_designs(problem, us):
    """Peaks per point of the problem's quantities, and statuses, at many box points us [K, n]
    (no derivatives: a brute-force grid, the ends of a Pareto front)."""

    def one(u):
        values, status = problem.quantities(u)
        return {n: metrics.peak(n, v) for n, v in values.items()}, status

    return map_points(one, us)


def map_points(fn, *xs):
    """``fn`` over the leading axis of ``xs``: vectorised (``jax.vmap``) on an accelerator, one after
    the other (``lax.map``) on a CPU, where a vmapped ``lax.cond`` or ``while_loop`` would run every
    branch and every iteration for every point."""
    if jax.default_backend() == "cpu":
        return jax.lax.map(lambda args: fn(*args), xs)
    return jax.vmap(fn)(*xs)


def constraint_count(problem, limits) -> int:
    """m, the number of constraint entries (without running the model)."""
    n = problem.lower.shape[0]

    def g(u):
        values, _ = problem.quantities(u)
        return problem.constraints(values, limits, u)

    return int(np.prod(eqx.filter_eval_shape(g, jnp.zeros(n)).shape))
