"""Constrained, multi-objective tip relief over a duty cycle: ``optimise_tip_relief``.

The designer's question: which relief (amount and start, linear or parabolic, on both gears or per
gear) gives the best efficiency (or the lowest loss, DTE, pressure or flash temperature) while DTE,
Hertz pressure, flash temperature, loss or efficiency stay within limits at every speed and torque of
a duty cycle. Solved by the augmented-Lagrangian method of ``augmented_lagrangian`` with reverse-mode
gradients of one compiled program (``problem.merit_and_gradient``), on the tribo-dynamic rung or any
other of the fidelity ladder.

Points without a stable periodic orbit (``simulate``'s status 6) or whose orbit strikes the back
flanks (status 7: the loss needs the second pass) have no derivative: the start is refused with the
failing points named (status ``START``), and a trial step that reaches one is cut back, never used.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from .._validation import check_choice
from ..fidelity import Fidelity
from ..gear.pair import RELIEF_SHAPES, GearPair, TipRelief
from ..operating import OperatingPoint
from ..results import Status, message
from ..tribodynamics import check_inputs
from . import augmented_lagrangian as al
from .metrics import FIELDS
from .problem import (
    CONSTRAINTS,
    EPIGRAPH_MAX,
    OBJECTIVES,
    TipReliefProblem,
    constraint_count,
    merit_and_gradient,
)
from .relief import tip_relief_bounds, with_tip_relief

#: Most operating points a duty cycle may have.
MAX_POINTS = 1000


class DesignResult(eqx.Module):
    """A constrained tip relief optimisation's result (SI units).

    Attributes:
        names: design variable names (``tip_relief_amount``, ``tip_relief_start_roll_angle``,
            suffixed _1/_2 per gear).
        x, x_start, lower, upper: the optimum, the start and the bounds, SI [n].
        objective: the objective's name (an ``OBJECTIVES`` key).
        objective_value, objective_start: its value at the optimum and at the start (natural units:
            the duty-cycle mean, or the peak for the max objectives).
        gradient_start: ∂objective/∂x at the start, per SI unit of each variable [n] (NaN for the
            max objectives, whose peak has no single gradient).
        speeds_rpm, torques: the duty cycle's points, rpm and N m [P] (every speed at every torque).
        values, values_start: quantity → its value per point [P] (a field's peak over the mesh
            cycle), for the objective's quantity and every constrained one.
        limits: constrained quantity → its limit (SI; efficiency a lower limit, the others upper).
        multipliers: constrained quantity → its Lagrange multiplier per point [P]: the objective's
            change per unit tightening of that point's limit (objective units per quantity unit;
            zero where the constraint does not bind). A field's multiplier sums its entries.
        point_status: simulation status per point at the optimum [P] (``jaxgear.results.Status``).
        failed_points: the points whose simulation failed, in words ("" if none).
        violation: largest constraint violation, relative to each limit (≤ ``ctol`` converged).
        projected_gradient: the Lagrangian's projected gradient at the optimum (objective scaled
            to unit initial gradient, per box width).
        complementarity: max |λ g| over the constraint entries (scaled units).
        status: ``Status`` code (OK, MAX_STEPS, INFEASIBLE, SIMULATION, START); ``message`` in words.
        evaluations: merit evaluations (each one forward and one reverse pass over the duty cycle).
        outer_iterations: multiplier updates.
        history: per multiplier update (objective, violation, projected gradient) [k, 3].
        path: accepted designs, SI [j, n].
        pair: the optimum GearPair; lubricant, surfaces, op, fidelity: the other inputs.
    """

    names: tuple[str, ...] = eqx.field(static=True)
    x: np.ndarray
    x_start: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    objective: str = eqx.field(static=True)
    objective_value: float
    objective_start: float
    gradient_start: np.ndarray
    speeds_rpm: np.ndarray
    torques: np.ndarray
    values: dict
    values_start: dict
    limits: dict
    multipliers: dict
    point_status: np.ndarray
    failed_points: str
    violation: float
    projected_gradient: float
    complementarity: float
    status: int
    evaluations: int
    outer_iterations: int
    history: np.ndarray
    path: np.ndarray
    pair: GearPair
    lubricant: object
    surfaces: object
    op: OperatingPoint
    fidelity: Fidelity

    @property
    def converged(self) -> bool:
        return self.status == Status.OK

    @property
    def message(self) -> str:
        return message(self.status)

    @property
    def amount(self) -> np.ndarray:
        """Optimum tip relief amount per gear, m [2]."""
        return np.asarray(self.pair.tip_relief.amount)

    @property
    def start_roll_angle(self) -> np.ndarray:
        """Optimum relief start roll angle per gear, rad [2]."""
        return np.asarray(self.pair.tip_relief.start_roll_angle)

    @property
    def shape(self) -> tuple[str, str]:
        """Relief shape per gear of the optimum pair."""
        return self.pair.tip_relief.shape

    def value(self, name: str) -> np.ndarray:
        """Optimum value(s) of a design variable by name (SI); per-gear ones as a pair."""
        if name in self.names:
            return np.asarray(self.x[self.names.index(name)])
        per_gear = [f"{name}_1", f"{name}_2"]
        if all(n in self.names for n in per_gear):
            return np.asarray([self.x[self.names.index(n)] for n in per_gear])
        raise ValueError(f"no design variable {name!r}; variables: {', '.join(self.names)}")

    def to_dict(self) -> dict:
        """A JSON-ready summary (SI units)."""
        return {
            "status": int(self.status),
            "message": self.message,
            "objective": self.objective,
            "objective_value": self.objective_value,
            "objective_start": self.objective_start,
            "variables": {n: float(v) for n, v in zip(self.names, self.x)},
            "variables_start": {n: float(v) for n, v in zip(self.names, self.x_start)},
            "shape": list(self.shape),
            "points": {
                "speed_rpm": self.speeds_rpm.tolist(),
                "torque_Nm": self.torques.tolist(),
                "status": self.point_status.tolist(),
            },
            "failed_points": self.failed_points,
            "limits": {k: float(v) for k, v in self.limits.items()},
            "values": {k: np.asarray(v).tolist() for k, v in self.values.items()},
            "values_start": {k: np.asarray(v).tolist() for k, v in self.values_start.items()},
            "multipliers": {k: np.asarray(v).tolist() for k, v in self.multipliers.items()},
            "violation": self.violation,
            "projected_gradient": self.projected_gradient,
            "complementarity": self.complementarity,
            "evaluations": self.evaluations,
            "outer_iterations": self.outer_iterations,
        }


# ---------------------------------------------------------------------------------------------------
# Input checks
# ---------------------------------------------------------------------------------------------------


def _duty_cycle(speeds_rpm, torques, op):
    """(torques [P], speeds [P]): every speed at every torque; op's where not given."""

    def values(name, given, default, unit):
        if given is None:
            return np.atleast_1d(np.asarray(default, dtype=float))
        arr = np.atleast_1d(np.asarray(given, dtype=float))
        if arr.ndim != 1 or arr.size == 0:
            raise ValueError(
                f"{name} = {given!r} is empty or not a list; valid: a non-empty list of {unit}"
            )
        if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
            raise ValueError(
                f"{name} = {arr.tolist()} is out of range; valid range: (0, inf) {unit}"
            )
        return arr

    speeds = values("speeds_rpm", speeds_rpm, op.speed_rpm, "rpm")
    torques = values("torques", torques, op.torque, "N m")
    if speeds.size * torques.size > MAX_POINTS:
        raise ValueError(
            f"the duty cycle has {speeds.size * torques.size} points; valid: at most {MAX_POINTS}"
        )
    t, s = np.meshgrid(torques, speeds, indexing="ij")
    return t.ravel(), s.ravel()


def check_objective(objective: str) -> None:
    check_choice("objective", objective, tuple(OBJECTIVES))


def check_constraints(constraints: Mapping | None) -> dict:
    """Validated {quantity: limit} (SI, floats)."""
    if constraints is None:
        return {}
    if not isinstance(constraints, Mapping):
        raise ValueError(
            f"constraints = {constraints!r} must be a mapping quantity → limit, e.g. "
            "{'dte_rms': 1.5e-6}"
        )
    out = {}
    for name, limit in constraints.items():
        if name not in CONSTRAINTS:
            raise ValueError(f"unknown constraint {name!r}; valid names: {', '.join(CONSTRAINTS)}")
        unit, kind = CONSTRAINTS[name]
        try:
            value = float(limit)
        except (TypeError, ValueError):
            raise ValueError(f"constraints[{name!r}] = {limit!r} is not a number") from None
        if kind == "lower":
            if not 0.0 < value < 1.0:
                raise ValueError(
                    f"constraints[{name!r}] = {value!r} is out of range; valid range: (0, 1) "
                    "(a lower limit on the efficiency)"
                )
        elif not (math.isfinite(value) and value > 0.0):
            raise ValueError(
                f"constraints[{name!r}] = {value!r} {unit} is out of range; valid range: (0, inf) "
                f"{unit} (an upper limit)"
            )
        out[name] = value
    return out


def _with_shape(pair: GearPair, shape) -> GearPair:
    if shape is None:
        return pair
    shapes = (shape, shape) if isinstance(shape, str) else tuple(shape)
    if len(shapes) != 2:
        raise ValueError(f"shape = {shape!r}; valid: 'linear', 'parabolic' or one per gear")
    for s in shapes:
        check_choice("shape", s, RELIEF_SHAPES)
    tr = pair.tip_relief
    return eqx.tree_at(
        lambda p: p.tip_relief,
        pair,
        TipRelief(amount=tr.amount, start_roll_angle=tr.start_roll_angle, shape=shapes),
    )


def _variables(pair, bounds, both_gears):
    (a_lo, a_hi), (s_lo, s_hi) = tip_relief_bounds(pair, bounds)
    amount0 = np.asarray(pair.tip_relief.amount, dtype=float)
    start0 = np.asarray(pair.tip_relief.start_roll_angle, dtype=float)
    if both_gears:
        lower = np.asarray([max(a_lo), max(s_lo)])
        upper = np.asarray([min(a_hi), min(s_hi)])
        if not np.all(lower < upper):
            raise ValueError(
                "bounds of the two gears do not overlap; use both_gears=False for per-gear relief"
            )
        x0 = np.asarray([amount0.mean(), start0.mean()])
        names = ("tip_relief_amount", "tip_relief_start_roll_angle")
    else:
        lower, upper = np.concatenate([a_lo, s_lo]), np.concatenate([a_hi, s_hi])
        x0 = np.concatenate([amount0, start0])
        names = tuple(
            f"{base}_{j}"
            for base in ("tip_relief_amount", "tip_relief_start_roll_angle")
            for j in (1, 2)
        )
    return names, np.clip(x0, lower, upper), lower, upper


# ---------------------------------------------------------------------------------------------------
# Building and solving
# ---------------------------------------------------------------------------------------------------


def build_problem(
    pair, lubricant, surfaces, op, *, speeds_rpm, torques, fidelity, objective, constraints,
    bounds, shape, both_gears,
):  # fmt: skip
    """Checked inputs → (TipReliefProblem, names, x0 [n] SI, limits dict). The scale and reference
    are placeholders (one and zero) until ``normalise_objective``."""
    fidelity = Fidelity.fast() if fidelity is None else fidelity
    check_inputs(pair, lubricant, surfaces, op, fidelity)
    check_objective(objective)
    limits = check_constraints(constraints)
    pair = _with_shape(pair, shape)
    t, s = _duty_cycle(speeds_rpm, torques, op)
    names, x0, lower, upper = _variables(pair, bounds, both_gears)
    epigraph = OBJECTIVES[objective][1] == "max"
    if epigraph:
        lower, upper = np.append(lower, 0.0), np.append(upper, EPIGRAPH_MAX)
        x0 = np.append(x0, 1.0)
    problem = TipReliefProblem(
        pair=pair,
        lubricant=lubricant,
        surfaces=surfaces,
        fidelity=fidelity,
        torques=jnp.asarray(t),
        speeds_rpm=jnp.asarray(s),
        inlet_temperature=jnp.asarray(op.inlet_temperature, dtype=float),
        lower=jnp.asarray(lower),
        upper=jnp.asarray(upper),
        scale=jnp.asarray(1.0),
        reference=jnp.asarray(0.0),
        objective=objective,
        constraint_names=tuple(limits),
        both_gears=bool(both_gears),
    )
    return problem, names, x0, limits


def to_box(problem, x) -> np.ndarray:
    lo, hi = np.asarray(problem.lower), np.asarray(problem.upper)
    return (np.asarray(x, dtype=float) - lo) / (hi - lo)


def evaluation(out, k=None) -> al.Evaluation:
    """A ``merit_and_gradient`` output (or row k of a batch of them) as an ``al.Evaluation``."""
    pick = (lambda a: np.asarray(a)) if k is None else (lambda a: np.asarray(a)[k])
    status = pick(out["status"])
    return al.Evaluation(
        merit=float(pick(out["merit"])),
        gradient=np.asarray(pick(out["gradient"]), dtype=float),
        objective=float(pick(out["objective"])),
        constraints=np.asarray(pick(out["constraints"]), dtype=float),
        ok=bool(np.all(status == 0)),
    )


def failed_points_message(problem, status) -> str:
    status = np.asarray(status)
    bad = np.nonzero(status != 0)[0]
    t, s = np.asarray(problem.torques), np.asarray(problem.speeds_rpm)
    items = [f"{s[i]:g} rpm at {t[i]:g} N m: {message(status[i])}" for i in bad]
    return "; ".join(items)


def normalise_objective(problem, u0, limits_array):
    """The problem with its objective normalised at the start (unit largest gradient in box units;
    the epigraph's reference the start peak), and the start's raw output."""
    n_con = constraint_count(problem, limits_array)
    zeros = jnp.zeros(n_con)
    # λ = 0 and a vanishing ρ: the merit's gradient is the objective's alone
    out = merit_and_gradient(problem, u0, zeros, 1e-12, limits_array)
    value = float(out["objective"])
    if problem.epigraph:
        scaled = eqx.tree_at(lambda p: (p.reference, p.scale), problem,
                             (jnp.asarray(value), jnp.asarray(value)))  # fmt: skip
    else:
        grad = np.asarray(out["gradient"], dtype=float)
        size = float(np.max(np.abs(grad)))
        size = size if (math.isfinite(size) and size > 0.0) else 1.0
        scaled = eqx.tree_at(lambda p: (p.reference, p.scale), problem,
                             (jnp.asarray(value), jnp.asarray(size)))  # fmt: skip
    return scaled, out, n_con


def _natural_multipliers(problem, lam, limits, n_points):
    """Scaled multipliers [m] → {quantity: [P]} in objective units per quantity unit."""
    out, offset = {}, 0
    for name in problem.constraint_names:
        limit = limits[name]
        per_point = lam[offset:offset + n_points * _entries(problem, name)]  # fmt: skip
        per_point = per_point.reshape(n_points, -1).sum(axis=1)
        offset += per_point.size * _entries(problem, name)
        slope = 1.0 / (1.0 - limit) if CONSTRAINTS[name][1] == "lower" else 1.0 / limit
        out[name] = per_point * slope * float(problem.scale)
    return out


def _entries(problem, name) -> int:
    """Constraint entries per point of a quantity: one, or one per position and flank pair."""
    return 2 * problem.fidelity.n_positions if name in FIELDS else 1


def _objective_gradient(problem, start_out, n) -> np.ndarray:
    """∂F/∂x (SI) from the unscaled start evaluation (scale 1, reference 0, λ = 0, ρ → 0, where
    the merit's gradient is −sense ∂F/∂u)."""
    if problem.epigraph:
        return np.full(n, np.nan)
    sense = OBJECTIVES[problem.objective][2]
    width = np.asarray(problem.upper - problem.lower)[:n]
    return -sense * np.asarray(start_out["gradient"], dtype=float)[:n] / width


def result_from(problem, outcome, start_out, names, x0, limits, op, final_out) -> DesignResult:
    """The DesignResult of a search's outcome (``final_out``: the merit output at its optimum)."""
    n = len(names)
    x_full = np.asarray(problem.design(jnp.asarray(outcome.u)))
    pair = with_tip_relief(problem.pair, jnp.asarray(x_full[: (2 if problem.both_gears else 4)]),
                           problem.both_gears)  # fmt: skip
    n_points = int(problem.torques.shape[0])
    path = np.asarray([np.asarray(problem.design(jnp.asarray(u)))[:n] for u in outcome.path])
    return DesignResult(
        names=tuple(names),
        x=x_full[:n],
        x_start=np.asarray(x0, dtype=float)[:n],
        lower=np.asarray(problem.lower)[:n],
        upper=np.asarray(problem.upper)[:n],
        objective=problem.objective,
        objective_value=float(final_out["objective"]),
        objective_start=float(start_out["objective"]),
        gradient_start=_objective_gradient(problem, start_out, n),
        speeds_rpm=np.asarray(problem.speeds_rpm),
        torques=np.asarray(problem.torques),
        values={k: np.asarray(v) for k, v in final_out["peaks"].items()},
        values_start={k: np.asarray(v) for k, v in start_out["peaks"].items()},
        limits=dict(limits),
        multipliers=_natural_multipliers(problem, outcome.multipliers, limits, n_points),
        point_status=np.asarray(final_out["status"]),
        failed_points=failed_points_message(problem, final_out["status"]),
        violation=outcome.violation,
        projected_gradient=outcome.projected_gradient,
        complementarity=outcome.complementarity,
        status=int(outcome.status),
        evaluations=outcome.evaluations,
        outer_iterations=outcome.outer_iterations,
        history=outcome.history,
        path=path,
        pair=pair,
        lubricant=problem.lubricant,
        surfaces=problem.surfaces,
        op=op,
        fidelity=problem.fidelity,
    )


def _solve(problem, names, x0, limits, op, *, ctol, gtol, max_evaluations):
    limits_array = jnp.asarray([limits[n] for n in problem.constraint_names], dtype=float)
    u0 = to_box(problem, x0)
    problem, start_out, n_con = normalise_objective(problem, u0, limits_array)
    if not np.all(np.asarray(start_out["status"]) == 0):
        outcome = al.Outcome(
            u=u0, evaluation=evaluation(start_out), multipliers=np.zeros(n_con), rho=0.0,
            violation=float("nan"), projected_gradient=float("nan"), complementarity=float("nan"),
            status=int(Status.START), evaluations=1, outer_iterations=0,
            history=np.zeros((0, 3)), path=u0[None],
        )  # fmt: skip
        return result_from(problem, outcome, start_out, names, x0, limits, op, start_out)

    def evaluate(u, lam, rho, active):
        out = merit_and_gradient(problem, u[0], lam[0], rho[0], limits_array)
        return [evaluation(out)]

    search = al.search(u0, n_con, ctol=ctol, gtol=gtol, max_evaluations=max_evaluations)
    outcome = al.drive([search], evaluate)[0]
    # the optimum's per-point values (one evaluation more: the search keeps only the merit's parts)
    final_out = merit_and_gradient(
        problem, outcome.u, outcome.multipliers, max(outcome.rho, 1.0), limits_array
    )
    return result_from(problem, outcome, start_out, names, x0, limits, op, final_out)


def optimise_tip_relief(
    pair: GearPair,
    lubricant,
    surfaces,
    op: OperatingPoint,
    *,
    speeds_rpm: Sequence[float] | None = None,
    torques: Sequence[float] | None = None,
    fidelity: Fidelity | None = None,
    objective: str = "efficiency",
    constraints: Mapping[str, float] | None = None,
    bounds: dict | None = None,
    shape=None,
    both_gears: bool = True,
    ctol: float = 1e-3,
    gtol: float = 1e-2,
    max_evaluations: int = 120,
) -> DesignResult:
    """The tip relief that optimises ``objective`` over a duty cycle, subject to limits that hold at
    every point of it.

    Args:
        pair, lubricant, surfaces, op: the design and operating point (as for ``simulate``); the
            pair's relief is the start (clipped into the bounds; with ``both_gears`` the mean of the
            two gears'); op gives the inlet temperature, and the speed and torque where
            ``speeds_rpm`` or ``torques`` is not given.
        speeds_rpm: gear 1 speeds, rpm; torques: gear 1 torques, N m. The duty cycle is every speed
            at every torque (at most ``MAX_POINTS`` points).
        fidelity: any rung (default ``Fidelity.fast()``, tribo-dynamic).
        objective: "efficiency" (maximise the mean), "power_loss", "dte_rms" (minimise the mean),
            "dte_rms_max" (the largest over the duty cycle), "hertz_pressure", "flash_temperature"
            (the peak over every point and mesh position).
        constraints: {quantity: limit}, SI: "dte_rms" (m), "hertz_pressure" (Pa),
            "flash_temperature" (K, Blok's flash temperature rise), "power_loss" (W) are upper
            limits; "efficiency" is a lower limit in (0, 1). Each holds at every point; the field
            quantities at every mesh position.
        bounds: {"amount": (lo, hi) m, "start_roll_angle": (lo, hi) rad}, each optionally per gear
            (defaults: amount 0-50 µm, start inside the path of contact, ``tip_relief_bounds``).
        shape: "linear", "parabolic", one per gear (a pair), "both" (solve linear and parabolic, return
            the better feasible one) or None (the pair's own).
        both_gears: one relief for both gears (2 variables) or one per gear (4).
        ctol: constraint tolerance, relative to each limit (1e-3: within 0.1 %), also for
            complementary slackness.
        gtol: tolerance of the Lagrangian's projected gradient (objective scaled to a unit largest
            gradient at the start, per box width).
        max_evaluations: budget of merit evaluations (each a forward and a reverse pass over the duty
            cycle; one compilation per problem structure).

    Returns:
        DesignResult with the optimum ``pair``, ``amount``, ``start_roll_angle``, every constraint's
        value at every point, the multipliers and a status. A start with failed simulations (e.g. a
        speed without a stable orbit) gives status ``START``, ``point_status`` per point and
        ``failed_points`` naming them; nothing is averaged over them.
    """
    kwargs = dict(ctol=ctol, gtol=gtol, max_evaluations=max_evaluations)
    if isinstance(max_evaluations, bool) or not isinstance(max_evaluations, int | np.integer):
        raise ValueError(
            f"max_evaluations = {max_evaluations!r} is out of range; valid range: integer >= 1"
        )
    for name, value in kwargs.items():
        if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0:
            raise ValueError(f"{name} = {value!r} is out of range; valid range: (0, inf)")
    if shape == "both":
        results = [
            optimise_tip_relief(
                pair, lubricant, surfaces, op, speeds_rpm=speeds_rpm, torques=torques,
                fidelity=fidelity, objective=objective, constraints=constraints, bounds=bounds,
                shape=s, both_gears=both_gears, **kwargs,
            )
            for s in RELIEF_SHAPES
        ]  # fmt: skip
        sense = OBJECTIVES[objective][2]
        return max(
            results,
            key=lambda r: (r.status == Status.OK, sense * r.objective_value),
        )
    problem, names, x0, limits = build_problem(
        pair, lubricant, surfaces, op, speeds_rpm=speeds_rpm, torques=torques, fidelity=fidelity,
        objective=objective, constraints=constraints, bounds=bounds, shape=shape,
        both_gears=both_gears,
    )  # fmt: skip
    return _solve(problem, names, x0, limits, op, **kwargs)
