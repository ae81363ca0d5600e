"""Bounded single-objective optimisation with optax: torque and roughness scale for efficiency.

One generic bounded optimiser, ``optimise(objective, x0, bounds)``, maximises a scalar objective of a
few design parameters; ``optimise_torque`` and ``optimise_roughness_scale`` build the objective (the
mean efficiency over a set of speeds) and call it. Tip relief, with objectives beside efficiency
and constraints, is ``jaxgear.design.optimise_tip_relief``.

Numerics:

- **Scaling.** The optimiser works on the unit box u = (x − lo)/(hi − lo) ∈ [0, 1]ⁿ, so a relief amount
  (tens of µm) and a start roll angle (a few degrees) move on comparable scales whatever their SI units.
  The objective is divided by the largest |∂f/∂u| at the start, so the first gradient has unit size
  (Adam does not care; plain SGD then has a meaningful learning rate).
- **Bounds by projection.** After each optax update, u is clipped to [0, 1] (projected gradient
  ascent). A bound is reached exactly, which matters here: on the quasi-static rung the efficiency
  rises monotonically with relief amount, so the amount optimum is on its bound, where a sigmoid
  reparametrisation would only creep towards it with a vanishing gradient.
- **Gradients in forward mode** (``jax.jacfwd``: one to a few parameters, where one forward pass
  per parameter costs less than a reverse pass). The value, gradient and convergence flag of each
  step come from one jitted call.
- **Stationarity** is measured by the projected gradient g_p = P(u + g) − u (P the clip to the box; g
  the gradient in box units): zero at an interior optimum and at an optimum on a bound. The run counts
  as converged when |g_p| ≤ ``gtol`` · |g_p at the start|.
- **Non-converged simulations are never used.** The objective returns, beside its value, whether every
  simulate point converged. A step that lands on a non-converged point is rejected and the run stops,
  returning the best converged point with status ``STATUS_SIMULATION``. A speed without a stable
  periodic orbit (``simulate``'s status 6, a mean over the attractor) counts as not converged: the
  mean over a rattle is not a smooth function of the design, and its derivatives are NaN. So an
  optimisation over a speed range that crosses an instability band (the calibrated pair's
  775-825, 1925-1975, 3375-3550 and 3750-4050 rpm at ``Fidelity.fast()``) stops at its start;
  choose speeds with a stable orbit, or add mesh damping (``GearPair.mesh_damping_ratio``).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable, Sequence

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax
from jaxtyping import Array, Float

from .fidelity import Fidelity
from .gear.pair import GearPair
from .operating import OperatingPoint
from .results import MESSAGES, Status
from .tribodynamics import check_inputs, first_pass

# Status codes of an optimisation (``results.Status``).
STATUS_CONVERGED = Status.OK  # projected gradient below tolerance
STATUS_MAX_STEPS = Status.MAX_STEPS  # step cap reached before the gradient tolerance
STATUS_SIMULATION = Status.SIMULATION  # a step landed on a non-converged simulation point
STATUS_START = Status.START  # the start point itself did not converge: nothing done
STATUS_NON_FINITE = Status.NON_FINITE  # non-finite objective or gradient
#: The codes an OptimisationResult can carry → their messages.
STATUS_NAMES = {
    int(Status.OK): "converged (projected gradient below tolerance)",
    **{int(code): MESSAGES[code] for code in (STATUS_MAX_STEPS, STATUS_SIMULATION, STATUS_START)},
    int(Status.NON_FINITE): "stopped: non-finite objective or gradient (best finite point kept)",
}

DEFAULT_ROUGHNESS_BOUNDS = (0.1, 3.0)


class OptimisationResult(eqx.Module):
    """Result of a bounded design optimisation (SI units throughout).

    Attributes:
        names: parameter names, e.g. ("tip_relief_amount", "tip_relief_start_roll_angle").
        x: optimum parameters (the best converged point seen), SI [n].
        x_start: start parameters (clipped into the bounds), SI [n].
        lower, upper: the bounds, SI [n].
        objective: objective (mean efficiency) at the optimum.
        objective_start: objective at the start.
        gradient: ∂objective/∂x at the optimum, per SI unit of each parameter [n].
        gradient_start: ∂objective/∂x at the start, per SI unit [n] (e.g. the efficiency gain per unit
            roughness scale).
        gradient_norm: norm of the projected gradient at the last accepted iterate, in objective units
            per box width (dimensionless box variables u = (x − lo)/(hi − lo)).
        history_objective: objective per accepted iterate [k + 1] (entry 0 = start).
        history_x: parameters per accepted iterate, SI [k + 1, n].
        history_gradient: ∂objective/∂x per accepted iterate, SI [k + 1, n] (what the optimiser used).
        history_gradient_norm: projected gradient norm per accepted iterate [k + 1].
        steps: optimiser steps taken (accepted).
        converged: status == STATUS_CONVERGED.
        status: see ``STATUS_NAMES``.
        pair, surfaces, op: the inputs with the optimum substituted (GearPair, Surfaces,
            OperatingPoint).
        fidelity: the Fidelity used.
    """

    names: tuple[str, ...] = eqx.field(static=True)
    x: np.ndarray
    x_start: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    objective: float
    objective_start: float
    gradient: np.ndarray
    gradient_start: np.ndarray
    gradient_norm: float
    history_objective: np.ndarray
    history_x: np.ndarray
    history_gradient: np.ndarray
    history_gradient_norm: np.ndarray
    steps: int
    status: int
    pair: GearPair | None = None
    surfaces: object = None
    op: OperatingPoint | None = None
    fidelity: Fidelity | None = None

    @property
    def converged(self) -> bool:
        return self.status == STATUS_CONVERGED

    @property
    def message(self) -> str:
        return STATUS_NAMES[self.status]

    def value(self, name: str) -> np.ndarray:
        """Optimum value(s) of a parameter by name (SI), e.g. ``result.value("tip_relief_amount")``.

        Parameters optimised per gear ("…_1", "…_2") are returned as a pair."""
        if name in self.names:
            return np.asarray(self.x[self.names.index(name)])
        per_gear = [f"{name}_1", f"{name}_2"]
        if all(n in self.names for n in per_gear):
            return np.asarray([self.x[self.names.index(n)] for n in per_gear])
        raise ValueError(f"no parameter {name!r}; parameters: {', '.join(self.names)}")

    @property
    def amount(self) -> np.ndarray:
        """Optimum tip relief amount per gear, m (2,) (tip relief optimisations)."""
        if self.pair is None:
            raise ValueError("this optimisation has no gear pair")
        return np.asarray(self.pair.tip_relief.amount)

    @property
    def start_roll_angle(self) -> np.ndarray:
        """Optimum relief start roll angle per gear, rad (2,) (tip relief optimisations)."""
        if self.pair is None:
            raise ValueError("this optimisation has no gear pair")
        return np.asarray(self.pair.tip_relief.start_roll_angle)

    @property
    def shape(self) -> tuple[str, str]:
        """Relief shape per gear of the optimum pair."""
        if self.pair is None:
            raise ValueError("this optimisation has no gear pair")
        return self.pair.tip_relief.shape


# ---------------------------------------------------------------------------------------------------
# The generic bounded optimiser
# ---------------------------------------------------------------------------------------------------


@functools.lru_cache(maxsize=32)
def default_optimiser(learning_rate: float, steps: int) -> optax.GradientTransformation:
    """Adam with a cosine-decayed learning rate (in box units per step), as used by default."""
    schedule = optax.cosine_decay_schedule(learning_rate, max(steps, 1), alpha=0.02)
    return optax.adam(schedule, b2=0.99)


@eqx.filter_jit
def _value_and_gradient(objective, x):
    """Objective value, ∂/∂x (forward mode) and the convergence flag, at x (SI)."""

    def fn(x):
        value, ok = objective(x)
        return value, (value, ok)

    grad, (value, ok) = jax.jacfwd(fn, has_aux=True)(x)
    return value, grad, ok


def value_and_gradient(objective, x) -> tuple[Array, Array, Array]:
    """The value, forward-mode gradient (per SI unit of x) and convergence flag the optimiser uses."""
    return _value_and_gradient(objective, jnp.asarray(x, dtype=float))


def _check_steps(steps):
    if isinstance(steps, bool) or not isinstance(steps, int | np.integer) or steps < 0:
        raise ValueError(f"steps = {steps!r} is out of range; valid range: integer >= 0")


def _check_positive_float(name, value):
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(value)
        or value <= 0
    ):
        raise ValueError(f"{name} = {value!r} is out of range; valid range: (0, inf)")


def _check_bounds(names, lower, upper, units):
    for name, lo, hi, unit in zip(names, lower, upper, units):
        if not (math.isfinite(lo) and math.isfinite(hi)) or not lo < hi:
            raise ValueError(
                f"bounds of {name} = ({lo:g}, {hi:g}) {unit} are invalid; valid: finite lower < upper"
            )


def optimise(
    objective: Callable,
    x0,
    bounds: tuple[Sequence[float], Sequence[float]],
    *,
    steps: int = 40,
    learning_rate: float = 0.1,
    optimiser: optax.GradientTransformation | None = None,
    gtol: float = 1e-2,
    names: Sequence[str] | None = None,
) -> OptimisationResult:
    """Maximise ``objective`` over a box by projected optax steps on the unit box.

    Args:
        objective: x (SI, [n]) → (value, ok): a scalar to maximise and a boolean that is True when the
            value may be trusted (every simulation converged). Traceable; differentiated with
            ``jax.jacfwd``. An ``eqx.Module`` objective keeps its arrays traced, so a second call with
            new values does not recompile.
        x0: start, SI [n]; clipped into the bounds.
        bounds: (lower [n], upper [n]), SI, finite, lower < upper.
        steps: optimiser step cap (≥ 0; 0 evaluates the start only).
        learning_rate: of the default optimiser, in box widths per step (Adam with b2 = 0.99 so
            late steps are not throttled by the large early gradients; cosine-decayed to 2 %).
        optimiser: any optax GradientTransformation (minimising; it sees the negated, normalised
            objective in box units). Overrides ``learning_rate``.
        gtol: converged when the projected gradient norm is ≤ gtol × its value at the start.
        names: parameter names (default "x0", "x1", ...).

    Returns:
        OptimisationResult (without pair/surfaces/op: the wrappers fill those in).
    """
    _check_steps(steps)
    _check_positive_float("learning_rate", learning_rate)
    _check_positive_float("gtol", gtol)
    x0 = np.atleast_1d(np.asarray(x0, dtype=float))
    lower = np.atleast_1d(np.asarray(bounds[0], dtype=float))
    upper = np.atleast_1d(np.asarray(bounds[1], dtype=float))
    n = x0.size
    names = tuple(names) if names is not None else tuple(f"x{i}" for i in range(n))
    if lower.shape != (n,) or upper.shape != (n,) or len(names) != n:
        raise ValueError(
            f"bounds and names need {n} entries (one per parameter); got {lower.size}, "
            f"{upper.size} and {len(names)}"
        )
    if not np.all(np.isfinite(x0)):
        raise ValueError(f"x0 = {x0} is not finite; valid range: finite values inside the bounds")
    _check_bounds(names, lower, upper, [""] * n)
    width = upper - lower
    x0 = np.clip(x0, lower, upper)
    opt = optimiser if optimiser is not None else default_optimiser(float(learning_rate), steps)

    def evaluate(u):
        x = lower + width * u
        value, grad, ok = _value_and_gradient(objective, jnp.asarray(x))
        value, grad = float(value), np.asarray(grad, dtype=float)
        finite = math.isfinite(value) and bool(np.all(np.isfinite(grad)))
        return x, value, grad, bool(ok), finite

    def projected_norm(u, grad_u):
        return float(np.linalg.norm(np.clip(u + grad_u, 0.0, 1.0) - u))

    u = (x0 - lower) / width
    x, value, grad, ok, finite = evaluate(u)
    hist_f, hist_x, hist_g, hist_pg = [value], [x], [grad], []
    if not ok or not finite:
        status = STATUS_START if not ok else STATUS_NON_FINITE
        hist_pg.append(float("nan"))
        return _result(names, x, x0, lower, upper, value, value, grad, grad, hist_pg[-1],
                       hist_f, hist_x, hist_g, hist_pg, 0, status)  # fmt: skip
    grad_u = grad * width
    pg0 = projected_norm(u, grad_u)
    hist_pg.append(pg0)
    # Normalise so the first gradient has unit max-abs size (box units); constant during the run.
    scale = float(np.max(np.abs(grad_u)))
    scale = scale if scale > 0 else 1.0
    best = (value, x, grad, pg0)
    state = opt.init(jnp.asarray(u))
    status = STATUS_CONVERGED if pg0 == 0.0 else STATUS_MAX_STEPS
    taken = 0
    for _ in range(steps if status != STATUS_CONVERGED else 0):
        updates, state = opt.update(jnp.asarray(-grad_u / scale), state, jnp.asarray(u))
        u_new = np.clip(u + np.asarray(updates), 0.0, 1.0)
        x_new, v_new, g_new, ok, finite = evaluate(u_new)
        if not ok or not finite:
            status = STATUS_SIMULATION if not ok else STATUS_NON_FINITE
            break
        taken += 1
        u, grad_u = u_new, g_new * width
        pg = projected_norm(u, grad_u)
        hist_f.append(v_new), hist_x.append(x_new), hist_g.append(g_new), hist_pg.append(pg)
        if v_new > best[0]:
            best = (v_new, x_new, g_new, pg)
        if pg <= gtol * pg0:
            status = STATUS_CONVERGED
            break
    value_best, x_best, grad_best, _ = best
    return _result(names, x_best, x0, lower, upper, value_best, hist_f[0], grad_best, hist_g[0],
                   hist_pg[-1], hist_f, hist_x, hist_g, hist_pg, taken, status)  # fmt: skip


def _result(names, x, x0, lower, upper, value, value0, grad, grad0, pg, hf, hx, hg, hpg, k, status):
    return OptimisationResult(
        names=tuple(names),
        x=np.asarray(x, dtype=float),
        x_start=np.asarray(x0, dtype=float),
        lower=lower,
        upper=upper,
        objective=float(value),
        objective_start=float(value0),
        gradient=np.asarray(grad, dtype=float),
        gradient_start=np.asarray(grad0, dtype=float),
        gradient_norm=float(pg),
        history_objective=np.asarray(hf, dtype=float),
        history_x=np.asarray(hx, dtype=float),
        history_gradient=np.asarray(hg, dtype=float),
        history_gradient_norm=np.asarray(hpg, dtype=float),
        steps=int(k),
        status=int(status),
    )


# ---------------------------------------------------------------------------------------------------
# Objectives: mean efficiency over speeds, with one design input substituted
# ---------------------------------------------------------------------------------------------------


def _mean_efficiency(pair, lubricant, surfaces, op, speeds, fidelity):
    """Mean efficiency over ``speeds`` (rpm) and whether every point converged (vmapped)."""

    def one(speed):
        point = OperatingPoint(
            torque=op.torque, speed_rpm=speed, inlet_temperature=op.inlet_temperature
        )
        # the second pass deferred: a point that needs it (no stable orbit, back strikes) counts
        # as not converged, and its derivative is NaN
        result = first_pass(pair, lubricant, surfaces, point, fidelity)[0]
        return result.efficiency, result.converged

    eff, ok = jax.vmap(one)(speeds)
    return jnp.mean(eff), jnp.all(ok)


class TorqueObjective(eqx.Module):
    """Mean efficiency over ``speeds_rpm`` as a function of x = (gear 1 torque, N m)."""

    pair: GearPair
    lubricant: object
    surfaces: object
    op: OperatingPoint
    speeds_rpm: Float[Array, " N"]
    fidelity: Fidelity

    def __call__(self, x):
        op = eqx.tree_at(lambda o: o.torque, self.op, jnp.asarray(x)[0])
        return _mean_efficiency(
            self.pair, self.lubricant, self.surfaces, op, self.speeds_rpm, self.fidelity
        )


class RoughnessScaleObjective(eqx.Module):
    """Mean efficiency over ``speeds_rpm`` as a function of x = (roughness scale,)."""

    pair: GearPair
    lubricant: object
    surfaces: object
    op: OperatingPoint
    speeds_rpm: Float[Array, " N"]
    fidelity: Fidelity

    def __call__(self, x):
        surfaces = eqx.tree_at(lambda s: s.scale, self.surfaces, jnp.asarray(x)[0])
        return _mean_efficiency(
            self.pair, self.lubricant, surfaces, self.op, self.speeds_rpm, self.fidelity
        )


def _speeds(speeds_rpm, op):
    if speeds_rpm is None:
        return jnp.reshape(jnp.asarray(op.speed_rpm, dtype=float), (1,))
    arr = np.atleast_1d(np.asarray(speeds_rpm, dtype=float))
    if arr.ndim != 1 or arr.size == 0 or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ValueError(
            f"speeds_rpm = {arr} is out of range; valid range: a non-empty list of finite speeds > 0 rpm"
        )
    return jnp.asarray(arr)


def _common_checks(pair, lubricant, surfaces, op, fidelity):
    fidelity = Fidelity.fast() if fidelity is None else fidelity
    check_inputs(pair, lubricant, surfaces, op, fidelity)
    return fidelity


def _scalar_bounds(name, bounds, unit):
    try:
        lo, hi = (float(b) for b in bounds)
    except (TypeError, ValueError):
        raise ValueError(f"bounds of {name} = {bounds!r} must be (lower, upper) {unit}") from None
    if not (math.isfinite(lo) and math.isfinite(hi)) or not 0.0 < lo < hi:
        raise ValueError(
            f"bounds of {name} = ({lo:g}, {hi:g}) {unit} are invalid; valid: 0 < lower < upper, finite"
        )
    return lo, hi


def optimise_torque(
    pair: GearPair,
    lubricant,
    surfaces,
    op: OperatingPoint,
    *,
    bounds: tuple[float, float] | None = None,
    speeds_rpm=None,
    fidelity: Fidelity | None = None,
    steps: int = 40,
    learning_rate: float = 0.1,
    optimiser: optax.GradientTransformation | None = None,
    gtol: float = 1e-2,
) -> OptimisationResult:
    """Gear 1 torque (N m) maximising the mean efficiency over ``speeds_rpm`` within ``bounds``.

    The efficiency Ψ = 1 − Φ̄/(T1 ω1) is a ratio, so its best torque is where the loss grows most
    slowly relative to the transmitted power: with load-dependent friction and relief that is a real
    trade, though often at a bound. Default bounds: (0.5, 2) × op.torque. Starts at op.torque.
    Returns an OptimisationResult whose ``op`` carries the optimum torque (name "torque").
    """
    fidelity = _common_checks(pair, lubricant, surfaces, op, fidelity)
    _check_steps(steps)
    t0 = float(op.torque)
    lo, hi = _scalar_bounds("torque", bounds if bounds is not None else (0.5 * t0, 2 * t0), "N m")
    objective = TorqueObjective(pair, lubricant, surfaces, op, _speeds(speeds_rpm, op), fidelity)
    result = optimise(
        objective,
        [t0],
        ([lo], [hi]),
        steps=steps,
        learning_rate=learning_rate,
        optimiser=optimiser,
        gtol=gtol,
        names=("torque",),
    )
    best_op = OperatingPoint(
        torque=float(result.x[0]), speed_rpm=op.speed_rpm, inlet_temperature=op.inlet_temperature
    )
    return dataclasses.replace(result, pair=pair, surfaces=surfaces, op=best_op, fidelity=fidelity)


def optimise_roughness_scale(
    pair: GearPair,
    lubricant,
    surfaces,
    op: OperatingPoint,
    *,
    bounds: tuple[float, float] = DEFAULT_ROUGHNESS_BOUNDS,
    speeds_rpm=None,
    fidelity: Fidelity | None = None,
    steps: int = 40,
    learning_rate: float = 0.1,
    optimiser: optax.GradientTransformation | None = None,
    gtol: float = 1e-2,
) -> OptimisationResult:
    """Roughness scale (S_j = scale · z_j, dimensionless) maximising the mean efficiency.

    ``gradient_start`` of the result is the efficiency gain per unit roughness scale at the surfaces'
    own scale (clipped into the bounds), the figure a designer weighs against the cost of finishing.
    Default bounds (0.1, 3). Returns an OptimisationResult whose ``surfaces`` carries the optimum scale
    (name "roughness_scale").
    """
    fidelity = _common_checks(pair, lubricant, surfaces, op, fidelity)
    _check_steps(steps)
    lo, hi = _scalar_bounds("roughness_scale", bounds, "")
    objective = RoughnessScaleObjective(
        pair, lubricant, surfaces, op, _speeds(speeds_rpm, op), fidelity
    )
    result = optimise(
        objective,
        [float(surfaces.scale)],
        ([lo], [hi]),
        steps=steps,
        learning_rate=learning_rate,
        optimiser=optimiser,
        gtol=gtol,
        names=("roughness_scale",),
    )
    best = eqx.tree_at(lambda s: s.scale, surfaces, jnp.asarray(result.x[0]))
    return dataclasses.replace(result, pair=pair, surfaces=best, op=op, fidelity=fidelity)


from .design.relief import tip_relief_bounds, with_tip_relief  # noqa: E402,F401  (public names kept)

__all__ = [
    "OptimisationResult",
    "STATUS_NAMES",
    "default_optimiser",
    "optimise",
    "optimise_roughness_scale",
    "optimise_torque",
    "value_and_gradient",
]
