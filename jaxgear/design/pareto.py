"""Pareto fronts of tip relief designs by the ε-constraint method: ``pareto_front``.

The front of an objective (efficiency by default) against a trade quantity (DTE RMS, peak Hertz
pressure, flash temperature or loss): for each limit ε_k of a sequence, the relief that optimises the
objective with trade ≤ ε_k at every point of the duty cycle (and any further constraints). The K
problems share one structure, so they are stepped in lockstep (``augmented_lagrangian.drive``) and
each round of K trial designs is one batch through the sweep engine (``sweep.engine.run_points``:
vectorised on an accelerator and shardable over devices, one after the other on a CPU; a failed
point kept apart from the good ones; on a CPU only the unfinished problems).

Without given limits, a coarse grid of designs over the bounds (``grid`` per variable, values only)
sets the range: from just above the smallest trade value a feasible grid design reaches (5 % of the
range above it) to the trade value of the grid design with the best objective. Each problem starts from the best feasible grid design under
its limit. Points that turn out dominated (another point at least as good in both, better in one) are
flagged, not dropped.

Reference: V. Chankong, Y. Y. Haimes, Multiobjective Decision Making: Theory and Methodology
(North-Holland, 1983), ch. 4 (the ε-constraint method).
"""

from __future__ import annotations

import csv
import itertools
import math
from pathlib import Path

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._validation import check_choice
from ..results import Status, message
from ..sweep.engine import run_points
from . import augmented_lagrangian as al
from .problem import CONSTRAINTS, OBJECTIVES, batch_point, constraint_count, evaluate_designs
from .tip_relief import DesignResult, build_problem, evaluation, result_from

#: Quantities a front may trade the objective against (upper limits).
TRADES = tuple(name for name, (_, kind) in CONSTRAINTS.items() if kind == "upper")


class ParetoFront(eqx.Module):
    """An ε-constraint Pareto front (SI units), ordered by the trade's limit.

    Attributes:
        objective: the objective's name; trade: the traded quantity's name.
        limits: ε_k, SI [K] (ascending).
        objective_values: the objective at each point's optimum [K] (duty-cycle mean or peak).
        trade_values: the trade quantity's largest value over the duty cycle at each optimum [K].
        x: each optimum's design variables, SI [K, n]; names: their names.
        status: each optimisation's ``Status`` code [K].
        dominated: whether another converged point is at least as good in both and better in one [K].
        results: each point's DesignResult.
    """

    objective: str = eqx.field(static=True)
    trade: str = eqx.field(static=True)
    names: tuple[str, ...] = eqx.field(static=True)
    limits: np.ndarray
    objective_values: np.ndarray
    trade_values: np.ndarray
    x: np.ndarray
    status: np.ndarray
    dominated: np.ndarray
    results: tuple[DesignResult, ...]

    @property
    def efficient(self) -> np.ndarray:
        """Converged and not dominated: the front proper [K]."""
        return (self.status == Status.OK) & ~self.dominated

    def to_csv(self, path: str | Path) -> Path:
        """One row per point: limit, objective, trade, design variables (SI), status."""
        path = Path(path)
        with path.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["limit", self.objective, self.trade, *self.names, "status",
                        "status_name", "dominated"])  # fmt: skip
            for k in range(self.limits.size):
                w.writerow([f"{self.limits[k]:.10g}", f"{self.objective_values[k]:.10g}",
                            f"{self.trade_values[k]:.10g}", *(f"{v:.10g}" for v in self.x[k]),
                            int(self.status[k]), message(self.status[k]),
                            int(self.dominated[k])])  # fmt: skip
        return path

    def to_dict(self) -> dict:
        return {
            "objective": self.objective,
            "trade": self.trade,
            "names": list(self.names),
            "limits": self.limits.tolist(),
            "objective_values": self.objective_values.tolist(),
            "trade_values": self.trade_values.tolist(),
            "x": self.x.tolist(),
            "status": self.status.tolist(),
            "dominated": self.dominated.tolist(),
        }


def dominated_mask(objective, trade, sense, ok) -> np.ndarray:
    """Which points are dominated by another ``ok`` point: objective (sense +1: larger is better)
    at least as good and trade (smaller better) at most as large, one of them strictly."""
    better_obj = sense * np.asarray(objective, dtype=float)
    trade = np.asarray(trade, dtype=float)
    k = better_obj.size
    out = np.zeros(k, dtype=bool)
    for i, j in itertools.product(range(k), repeat=2):
        if i == j or not ok[j]:
            continue
        weakly = better_obj[j] >= better_obj[i] and trade[j] <= trade[i]
        strictly = better_obj[j] > better_obj[i] or trade[j] < trade[i]
        out[i] |= weakly and strictly
    return out


def _grid(problem, n_design, grid):
    """Box points of a grid over the design variables (the epigraph variable at its start)."""
    axes = [np.linspace(0.0, 1.0, grid)] * n_design
    points = np.asarray(list(itertools.product(*axes)))
    n = int(problem.lower.shape[0])
    if n > n_design:  # an epigraph variable: at 1/EPIGRAPH_MAX, its start value 1
        fill = (1.0 - float(problem.lower[-1])) / float(problem.upper[-1] - problem.lower[-1])
        points = np.hstack([points, np.full((points.shape[0], n - n_design), fill)])
    return points


def _check_grid(grid, n_design):
    if isinstance(grid, bool) or not isinstance(grid, int) or not 2 <= grid <= 21:
        raise ValueError(f"grid = {grid!r} is out of range; valid range: integer in [2, 21]")
    if grid**n_design > 2000:
        raise ValueError(
            f"grid = {grid} gives {grid**n_design} designs for {n_design} variables; valid: at "
            "most 2000 (give limits, or a smaller grid)"
        )


def pareto_front(
    pair,
    lubricant,
    surfaces,
    op,
    *,
    speeds_rpm=None,
    torques=None,
    fidelity=None,
    objective: str = "efficiency",
    trade: str = "dte_rms",
    limits=None,
    n_points: int = 10,
    constraints=None,
    bounds=None,
    shape=None,
    both_gears: bool = True,
    grid: int = 5,
    ctol: float = 1e-3,
    gtol: float = 1e-2,
    max_evaluations: int = 80,
) -> ParetoFront:
    """The Pareto front of ``objective`` against ``trade`` over tip relief designs.

    Args:
        pair, lubricant, surfaces, op, speeds_rpm, torques, fidelity, bounds, shape, both_gears:
            as for ``optimise_tip_relief`` (shape "linear", "parabolic", per gear or None).
        objective: an ``OBJECTIVES`` name, not the trade itself.
        trade: the quantity limited by ε ("dte_rms", "hertz_pressure", "flash_temperature",
            "power_loss"), at every point of the duty cycle.
        limits: ε values, SI (positive); default ``n_points`` spaced over the range a grid of
            designs shows (module docstring).
        n_points: points of the default limits (≥ 2).
        constraints: further limits that hold at every point of the front ({quantity: limit}).
        grid: grid points per design variable for the default limits and the starts.
        ctol, gtol, max_evaluations: per point, as for ``optimise_tip_relief``.

    Returns:
        ParetoFront, ordered by limit, every point's DesignResult with it.
    """
    check_choice("trade", trade, TRADES)
    if objective in OBJECTIVES and OBJECTIVES[objective][0] == trade:
        raise ValueError(
            f"objective = {objective!r} and trade = {trade!r} are the same quantity; a front needs "
            "two"
        )
    extra = dict(constraints or {})
    if trade in extra:
        raise ValueError(
            f"constraints[{trade!r}] is the traded quantity; its limits are the front's ε values"
        )
    if limits is None and (isinstance(n_points, bool) or not isinstance(n_points, int)
                           or not 2 <= n_points <= 100):  # fmt: skip
        raise ValueError(
            f"n_points = {n_points!r} is out of range; valid range: integer in [2, 100]"
        )
    placeholder = 1.0
    problem, names, x0, limit_map = build_problem(
        pair, lubricant, surfaces, op, speeds_rpm=speeds_rpm, torques=torques, fidelity=fidelity,
        objective=objective, constraints={**extra, trade: placeholder}, bounds=bounds,
        shape=shape, both_gears=both_gears,
    )  # fmt: skip
    n_design = len(names)
    sense = OBJECTIVES[objective][2]
    other = {n: v for n, v in limit_map.items() if n != trade}

    # --- a grid of designs: the limits' range and every point's start ---
    _check_grid(grid, n_design)
    grid_u = _grid(problem, n_design, grid)
    peaks, status = evaluate_designs(problem, jnp.asarray(grid_u))
    peaks = {k: np.asarray(v) for k, v in peaks.items()}
    good = np.all(np.asarray(status) == 0, axis=1)
    for name, limit in other.items():
        q = peaks[name]
        good &= np.all(q >= limit, axis=1) if CONSTRAINTS[name][1] == "lower" else np.all(
            q <= limit, axis=1)  # fmt: skip
    if not np.any(good):
        raise ValueError(
            "no design of the start grid converges at every point and meets the other constraints; "
            "check the duty cycle (speeds without a stable orbit) and the limits"
        )
    objective_name, aggregate, _ = OBJECTIVES[objective]
    q_obj = peaks[objective_name]
    grid_objective = q_obj.mean(axis=1) if aggregate == "mean" else q_obj.max(axis=1)
    grid_trade = peaks[trade].max(axis=1)
    default_limits = limits is None
    if default_limits:
        best = np.argmax(np.where(good, sense * grid_objective, -np.inf))
        lowest = float(np.min(grid_trade[good]))
        hi = float(grid_trade[best])
        if not hi > lowest:
            hi = lowest * 1.5
        # not at the lowest value itself: there the feasible set shrinks to a point (no interior,
        # no constraint qualification) and the multiplier grows without bound
        limits = np.linspace(lowest + 0.05 * (hi - lowest), hi, n_points)
    limits = np.sort(np.atleast_1d(np.asarray(limits, dtype=float)))
    if limits.ndim != 1 or limits.size == 0 or not np.all(np.isfinite(limits)) or np.any(
            limits <= 0):  # fmt: skip
        raise ValueError(f"limits = {limits.tolist()} are out of range; valid: positive, finite SI")

    starts = [_grid_start(eps, good, grid_trade, grid_objective, sense, grid_u) for eps in limits]
    k_points = limits.size
    rows = {"limits": _limit_rows(limits, problem.constraint_names, trade, limit_map)}
    n_con = constraint_count(problem, jnp.asarray(rows["limits"][0]))

    on_cpu = jax.default_backend() == "cpu"

    def batch(u, lam, rho, rows_k=None):
        """The merit at each row's trial (``rows_k``: the rows to evaluate, default all)."""
        rows_k = np.arange(len(u)) if rows_k is None else np.asarray(rows_k)
        inputs = {
            "u": jnp.asarray(u[rows_k]),
            "multipliers": jnp.asarray(lam[rows_k]),
            "rho": jnp.asarray(rho[rows_k]),
            "limits": jnp.asarray(rows["limits"][rows_k]),
        }
        # on a CPU one problem per chunk, so that finished problems cost nothing and every round
        # runs the same compiled program; on an accelerator the whole batch at once
        return run_points(batch_point, inputs, args=problem, converged_key=None, label="pareto",
                          sequential=on_cpu, chunk_size=1 if on_cpu else None)  # fmt: skip

    # --- the objective's scale at the first start (shared by every point: one structure) ---
    first = batch(np.stack(starts), np.zeros((k_points, n_con)), np.full(k_points, 1e-12))
    out0 = first.outputs
    ref = float(np.asarray(out0["objective"])[0])
    if problem.epigraph:
        size = ref
    else:
        size = float(np.nanmax(np.abs(np.asarray(out0["gradient"], dtype=float))))
        size = size if math.isfinite(size) and size > 0 else 1.0
    problem = eqx.tree_at(lambda p: (p.reference, p.scale), problem,
                          (jnp.asarray(ref), jnp.asarray(size)))  # fmt: skip

    def evaluate(u, lam, rho, active):
        # an accelerator evaluates the whole batch (one shape, one program); a CPU the active rows
        rows_k = np.nonzero(active)[0] if on_cpu else np.arange(k_points)
        swept = batch(u, lam, rho, rows_k)
        ok = swept.status == 0
        got = {int(k): _row_evaluation(swept.outputs, i, ok[i]) for i, k in enumerate(rows_k)}
        return [got.get(k) for k in range(k_points)]

    def solve(starts, multipliers):
        searches = [
            al.search(starts[k], n_con, ctol=ctol, gtol=gtol, max_evaluations=max_evaluations,
                      multipliers0=multipliers[k])
            for k in range(k_points)
        ]  # fmt: skip
        outcomes = al.drive(searches, evaluate)
        final = batch(
            np.stack([o.u for o in outcomes]),
            np.stack([o.multipliers for o in outcomes]),
            np.asarray([max(o.rho, 1.0) for o in outcomes]),
        ).outputs
        return outcomes, final

    outcomes, final = solve(starts, [None] * k_points)
    if default_limits:
        # limits above the unconstrained optimum's trade value all give that optimum: found now,
        # it is the front's loose end; solve again over the range that binds, warm-started
        trades = np.max(np.asarray(final["peaks"][trade]).reshape(k_points, -1), axis=1)
        loose = [k for k, o in enumerate(outcomes)
                 if o.status == Status.OK and trades[k] < limits[k] * (1 - 10 * ctol)]  # fmt: skip
        if len(loose) >= 2:
            limits = np.linspace(limits[0], float(np.min(trades[loose])), k_points)
            rows["limits"] = _limit_rows(limits, problem.constraint_names, trade, limit_map)
            warm = [_warm_start(eps, outcomes, trades, sense, ctol) for eps in limits]
            starts = [outcomes[w].u if w is not None else starts[k] for k, w in enumerate(warm)]
            multipliers = [outcomes[w].multipliers if w is not None else None for w in warm]
            outcomes, final = solve(starts, multipliers)
    limit_rows = rows["limits"]
    start_out = first.outputs
    results = []
    for k, outcome in enumerate(outcomes):
        final_k = {key: _row(value, k) for key, value in final.items()}
        start_k = {key: _row(value, k) for key, value in start_out.items()}
        point_limits = {n: float(limit_rows[k][i]) for i, n in enumerate(problem.constraint_names)}
        x_start = np.asarray(problem.design(jnp.asarray(starts[k])))
        results.append(
            result_from(problem, outcome, start_k, names, x_start, point_limits, op, final_k)
        )
    objective_values = np.asarray([r.objective_value for r in results])
    trade_values = np.asarray([float(np.max(r.values[trade])) for r in results])
    status = np.asarray([r.status for r in results], dtype=np.int32)
    return ParetoFront(
        objective=objective,
        trade=trade,
        names=tuple(names),
        limits=limits,
        objective_values=objective_values,
        trade_values=trade_values,
        x=np.stack([r.x for r in results]),
        status=status,
        dominated=dominated_mask(objective_values, trade_values, sense, status == Status.OK),
        results=tuple(results),
    )


def _limit_rows(limits, names, trade, limit_map):
    """Per point, the limits of the problem's constraints in order (the trade's is ε)."""
    return np.stack([[eps if n == trade else limit_map[n] for n in names] for eps in limits])


def _grid_start(eps, good, grid_trade, grid_objective, sense, grid_u):
    """The best grid design under ε (or the best good one if none is under it)."""
    under = good & (grid_trade <= eps)
    pool = under if np.any(under) else good
    return grid_u[np.argmax(np.where(pool, sense * grid_objective, -np.inf))]


def _warm_start(eps, outcomes, trades, sense, ctol):
    """Index of the best converged solution whose trade value meets ε, or None."""
    best, index = -np.inf, None
    for k, o in enumerate(outcomes):
        value = sense * o.evaluation.objective
        if o.status == Status.OK and trades[k] <= eps * (1 + ctol) and value > best:
            best, index = value, k
    return index


def _row(value, k):
    if isinstance(value, dict):
        return {n: np.asarray(v)[k] for n, v in value.items()}
    return np.asarray(value)[k]


def _row_evaluation(outputs, k, ok) -> al.Evaluation:
    row = {key: _row(value, k) for key, value in outputs.items() if key != "peaks"}
    ev = evaluation(row)
    return al.Evaluation(ev.merit, ev.gradient, ev.objective, ev.constraints, bool(ev.ok and ok))
