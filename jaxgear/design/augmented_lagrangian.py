"""An augmented-Lagrangian method for a few bounded design variables under many smooth inequality
constraints, driven from Python around one compiled value-and-gradient program.

Problem, on the unit box u ∈ [0, 1]ⁿ (the caller scales its design variables onto it):

    minimise f(u)  subject to  g_i(u) ≤ 0  (i = 1…m),  0 ≤ u ≤ 1.

Method (Powell-Hestenes-Rockafellar augmented Lagrangian; Nocedal & Wright, Numerical Optimization,
2nd ed., §17.4; Conn, Gould & Toint's bound-constrained variant, as in LANCELOT):

- **Merit.** L(u; λ, ρ) = f(u) + (1/2ρ) Σ_i [max(0, λ_i + ρ g_i(u))² − λ_i²]. Its gradient is
  ∇f + Σ_i max(0, λ_i + ρ g_i) ∇g_i: the Lagrangian's gradient at the updated multipliers, so one
  reverse-mode pass of the scalar L gives everything the method needs, whatever m is.
- **Inner solve: projected quasi-Newton on the box** (Bertsekas, "Projected Newton methods for
  optimization problems with simple constraints", SIAM J. Control Optim. 20 (1982)). Variables at a
  bound whose gradient pushes outwards are held; on the free ones the step is −H∇L with H a BFGS
  inverse-Hessian estimate (reset to the identity when it stops giving descent); the step is
  projected onto the box and shortened until the Armijo condition holds. A trial point whose
  simulation did not converge counts as a failed trial (the step is cut by 4), never as a value.
- **Outer update.** λ ← max(0, λ + ρ g); ρ ← 10ρ (at most ``RHO_MAX``) when the largest violation has
  not fallen to a quarter of the previous one.
- **Converged** when the largest violation max(g, 0) ≤ ``ctol``, the projected gradient of the
  Lagrangian ‖P(u − ∇L) − u‖ ≤ ``gtol`` and complementary slackness max |λ_i g_i| ≤ ``ctol``
  (KKT conditions, to those tolerances).

The method is written as a generator (``search``) that yields trial points and receives their
evaluations, so a batch of independent problems (the ε-constraint points of a Pareto front) can be
stepped in lockstep, each trial batch evaluated in one vectorised call (``drive``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Generator, Sequence

import numpy as np

from ..results import Status

#: Largest penalty parameter.
RHO_MAX = 1e6
#: Largest step along a quasi-Newton direction, in box widths (a trust limit on a poor H).
MAX_STEP = 0.5
_ARMIJO = 1e-4
_BOUND = 1e-10


@dataclasses.dataclass(frozen=True)
class Evaluation:
    """One evaluation of the merit at a trial point.

    Attributes:
        merit: L(u; λ, ρ).
        gradient: ∇_u L [n].
        objective: f(u) (the merit's objective part).
        constraints: g(u) [m] (≤ 0 feasible).
        ok: every simulation behind the value converged (else the value is not used).
    """

    merit: float
    gradient: np.ndarray
    objective: float
    constraints: np.ndarray
    ok: bool


@dataclasses.dataclass(frozen=True)
class Outcome:
    """What a search ends with.

    Attributes:
        u: last accepted point [n] (box units).
        evaluation: its evaluation at the final multipliers.
        multipliers: λ [m] (scaled units: per unit of g, in units of f).
        rho: the final penalty parameter.
        violation: max(g, 0) at u.
        projected_gradient: ‖P(u − ∇L) − u‖ at u, the Lagrangian's projected gradient.
        complementarity: max |λ_i g_i|.
        status: ``Status.OK``; ``MAX_STEPS`` (budget spent, or the line search found no
            decrease); ``INFEASIBLE`` (stopped short of OK with a constraint still violated beyond
            ``ctol``: the limits may not be attainable); ``SIMULATION`` (the trials along a descent
            direction did not converge); ``START`` (the start point's simulation failed).
        evaluations: merit evaluations used.
        outer_iterations: multiplier updates made.
        history: per outer iteration (objective, violation, projected gradient), array [k, 3].
        path: accepted points [j, n] (box units).
    """

    u: np.ndarray
    evaluation: Evaluation
    multipliers: np.ndarray
    rho: float
    violation: float
    projected_gradient: float
    complementarity: float
    status: int
    evaluations: int
    outer_iterations: int
    history: np.ndarray
    path: np.ndarray


def projected_gradient_norm(u: np.ndarray, gradient: np.ndarray) -> float:
    """‖P(u − ∇) − u‖₂ on the unit box: zero at a stationary point, interior or on a bound."""
    return float(np.linalg.norm(np.clip(u - gradient, 0.0, 1.0) - u))


def _kkt(u, ev, lam):
    g = ev.constraints
    violation = float(np.max(np.maximum(g, 0.0), initial=0.0))
    complementarity = float(np.max(np.abs(lam * g), initial=0.0))
    return violation, projected_gradient_norm(u, ev.gradient), complementarity


def search(
    u0: np.ndarray,
    n_constraints: int,
    *,
    ctol: float = 1e-3,
    gtol: float = 1e-3,
    max_evaluations: int = 120,
    max_outer: int = 12,
    max_inner: int = 30,
    rho0: float = 10.0,
    multipliers0: np.ndarray | None = None,
) -> Generator[tuple[np.ndarray, np.ndarray, float], Evaluation, Outcome]:
    """The augmented-Lagrangian search as a generator: it yields trials (u [n], λ [m], ρ) and is
    sent their ``Evaluation``; its return value (``StopIteration.value``) is the ``Outcome``.

    Args:
        u0: start in the unit box [n] (clipped into it).
        n_constraints: m (zero for a bound-constrained problem: then only the inner solve runs).
        ctol: tolerance on constraint violation and complementary slackness (units of g).
        gtol: tolerance on the Lagrangian's projected gradient (units of f per box width).
        max_evaluations: evaluation budget (every trial counts).
        max_outer, max_inner: caps on multiplier updates and on quasi-Newton steps per update.
        rho0: first penalty parameter.
        multipliers0: first multipliers (default zero): a warm start.
    """
    u = np.clip(np.asarray(u0, dtype=float), 0.0, 1.0)
    n = u.size
    lam = np.zeros(n_constraints) if multipliers0 is None else np.asarray(multipliers0, float)
    rho = float(rho0)
    ev = yield u, lam, rho
    evaluations = 1
    history, path = [], [u.copy()]

    def outcome(status):
        violation, pg, comp = _kkt(u, ev, lam)
        return Outcome(
            u=u, evaluation=ev, multipliers=lam, rho=rho, violation=violation,
            projected_gradient=pg, complementarity=comp, status=int(status),
            evaluations=evaluations, outer_iterations=len(history),
            history=np.asarray(history, dtype=float).reshape(-1, 3), path=np.asarray(path),
        )  # fmt: skip

    if not ev.ok or not np.isfinite(ev.merit) or not np.all(np.isfinite(ev.gradient)):
        return outcome(Status.START)
    previous_violation = np.inf
    status = Status.MAX_STEPS
    for _ in range(max_outer):
        # --- inner: projected quasi-Newton on L(·; λ, ρ) ---
        h = np.eye(n)
        stalled = False
        for _ in range(max_inner):
            d = ev.gradient
            if projected_gradient_norm(u, d) <= gtol:
                break
            held = ((u <= _BOUND) & (d > 0)) | ((u >= 1.0 - _BOUND) & (d < 0))
            free = ~held
            p = np.zeros(n)
            p[free] = -h[np.ix_(free, free)] @ d[free]
            if d @ p >= 0.0:
                h = np.eye(n)
                p = np.where(free, -d, 0.0)
            alpha = min(1.0, MAX_STEP / max(float(np.max(np.abs(p))), 1e-300))
            accepted, trial_ok = None, True
            while evaluations < max_evaluations and alpha > 1e-8:
                trial = np.clip(u + alpha * p, 0.0, 1.0)
                ev_t = yield trial, lam, rho
                evaluations += 1
                good = ev_t.ok and np.isfinite(ev_t.merit) and np.all(np.isfinite(ev_t.gradient))
                trial_ok = bool(good)
                if good and ev_t.merit <= ev.merit + _ARMIJO * float(d @ (trial - u)):
                    accepted = (trial, ev_t)
                    break
                alpha *= 0.5 if good else 0.25
            if accepted is None:
                stalled = True
                break
            trial, ev_t = accepted
            s, y = trial - u, ev_t.gradient - d
            if float(s @ y) > 1e-12 * float(np.linalg.norm(s) * np.linalg.norm(y)):
                r = 1.0 / float(s @ y)
                v = np.eye(n) - r * np.outer(s, y)
                h = v @ h @ v.T + r * np.outer(s, s)
            u, ev = trial, ev_t
            path.append(u.copy())
        # --- outer: multipliers and penalty ---
        g = ev.constraints
        lam = np.maximum(0.0, lam + rho * g)
        violation, pg, comp = _kkt(u, ev, lam)
        history.append((ev.objective, violation, pg))
        if violation <= ctol and pg <= gtol and comp <= ctol:
            status = Status.OK
            break
        if stalled:
            # no acceptable step along a descent direction: the simulations failed there, or the
            # merit is not smooth enough for the line search at this tolerance
            status = Status.SIMULATION if not trial_ok else Status.MAX_STEPS
            break
        if violation > 0.25 * previous_violation:
            rho = min(10.0 * rho, RHO_MAX)
        previous_violation = violation
        if evaluations >= max_evaluations:
            break
        ev = yield u, lam, rho  # the merit changed with λ and ρ
        evaluations += 1
        if not ev.ok:  # cannot happen for a point already evaluated; guard anyway
            status = Status.SIMULATION
            break
    if status != Status.OK and _kkt(u, ev, lam)[0] > ctol:
        status = Status.INFEASIBLE
    return outcome(status)


def drive(
    searches: Sequence[Generator],
    evaluate: Callable[..., Sequence[Evaluation | None]],
) -> list[Outcome]:
    """Step searches in lockstep: each round evaluates the trials in one call
    ``evaluate(u [K, n], λ [K, m], ρ [K], active [K])`` and sends each unfinished search
    (``active``) its evaluation; finished ones repeat their last trial, and ``evaluate`` may skip
    them (return None there). Returns the outcomes in order."""
    trials = [next(s) for s in searches]
    outcomes: list[Outcome | None] = [None] * len(searches)
    while any(o is None for o in outcomes):
        u = np.stack([t[0] for t in trials])
        lam = np.stack([t[1] for t in trials])
        rho = np.asarray([t[2] for t in trials], dtype=float)
        active = np.asarray([o is None for o in outcomes])
        evaluations = evaluate(u, lam, rho, active)
        for k, search_k in enumerate(searches):
            if outcomes[k] is not None:
                continue
            try:
                trials[k] = search_k.send(evaluations[k])
            except StopIteration as stop:
                outcomes[k] = stop.value
    return outcomes  # type: ignore[return-value]
