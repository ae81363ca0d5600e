"""Calibration of the model's constants to measured power losses: weighted nonlinear least squares.

``calibrate(pair, lubricant, surfaces, fidelity, operating_points, measured_power_loss,
parameters=("boundary_friction", "asperity_density_product"))`` finds the constants θ (the contact
model's traced constants, ``Fidelity.with_constants``, and optionally the roughness scale
``Surfaces.scale``) that minimise

    Σᵢ rᵢ(θ)²,   rᵢ = wᵢ (Φ̄ᵢ(θ) − Φ̄ᵢ,meas) / Φ̄ᵢ,meas,

over the measured points i = 1..n (Φ̄ the cycle-mean mesh power loss of ``simulate``, W; wᵢ the
optional weights, default 1).

Numerics:

- **Relative residuals.** Each point's misfit is a fraction of its own measured loss, so a 300 W and
  a 3 kW point weigh alike; a weight wᵢ = 1/σᵢ (σᵢ the relative uncertainty of point i) makes the
  sum the usual χ².
- **Log parameters.** The solver works on η = ln θ (θ = exp η): every calibrated quantity is
  positive (a friction coefficient, a density product, a scale), and in η no step can make one
  negative or zero; steps are relative changes of θ. Values, standard errors and covariance are
  reported in the natural units of θ.
- **Levenberg-Marquardt** (``optimistix.LevenbergMarquardt``, QR linear solves), the model over
  all points in one traced function (vmapped, or mapped on the EHL and tribo-dynamic rungs:
  ``batches_points``); the Jacobian in forward mode through jaxgear's implicit
  derivatives of its converged solves (the constants are traced numbers: nothing recompiles between
  steps, and the same two programs serve every calibration of the same shapes).
- **Failed points are never fitted.** A point whose simulation reports a status other than 0 (a
  contact or fixed point not converged, a mean over an attractor whose derivatives are NaN) gives a
  NaN residual inside the solve, so the trust region rejects any step onto it; a point failing at
  the start stops the calibration before the solve (status ``START``), one failing at the result
  marks it (status ``SIMULATION``), and so does one failing at the Gauss-Newton step the solver
  would still take from the result (a fit held against constants where the simulation fails stops
  there with every point fine, but not at a minimum). Each names the points (``failed_points``,
  ``message``).
- **Standard errors** from the Jacobian J = ∂r/∂θ at the optimum (linearised, natural units):
  cov = s² (JᵀJ)⁻¹ with s² = RSS/(n − p), the residual variance, when the weights are relative
  (``absolute_sigma=False``, the default; scipy's ``curve_fit`` convention). With n = p the fit
  interpolates the data, s² is undefined and so are the standard errors: NaN, said in ``note``.
  With ``absolute_sigma=True`` the weights are taken as 1/σᵢ of known relative uncertainties and
  cov = (JᵀJ)⁻¹ for any n ≥ p. A Jacobian of lower rank than p (parameters the data cannot
  separate) gives infinite standard errors. Correlations near ±1 (``correlation``) say the same for
  a pair of parameters that the points can barely separate, e.g. μb and nβσ, which both scale the
  asperity friction.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from .._inputs import canonical, validate
from .._validation import check_instance, is_concrete
from ..fidelity import Fidelity
from ..fidelity.ladder import CONSTANTS
from ..lubrication.roughness import Surfaces
from ..operating import OperatingPoint
from ..results import MESSAGES, Status
from ..tribodynamics import check_inputs
from ..tribodynamics.passes import simulate_with_state

#: The roughness scale (``Surfaces.scale``), calibratable beside the contact constants.
ROUGHNESS_SCALE = "roughness_scale"
#: Every calibratable parameter → (valid range, what it is).
PARAMETERS = {
    **{name: (spec[1], spec[2]) for name, spec in CONSTANTS.items()},
    ROUGHNESS_SCALE: ((0.0, math.inf), "roughness scale factor S_j = scale · z_j (Surfaces.scale)"),
}
DEFAULT_PARAMETERS = ("boundary_friction", "asperity_density_product")

STATUS_CONVERGED = Status.OK
STATUS_MAX_STEPS = Status.MAX_STEPS
STATUS_SIMULATION = Status.SIMULATION
STATUS_START = Status.START
STATUS_NON_FINITE = Status.NON_FINITE
STATUS_RANGE = Status.RANGE
#: The codes a CalibrationResult can carry → their messages.
STATUS_NAMES = {
    int(Status.OK): "converged (parameter and residual changes below tolerance)",
    int(Status.MAX_STEPS): "step cap reached before the tolerances",
    int(Status.SIMULATION): "the simulation failed at or next to the fitted constants",
    int(Status.START): "the simulation failed at the start values; nothing fitted",
    int(Status.NON_FINITE): "non-finite residual or Jacobian at the fitted constants",
    int(Status.RANGE): MESSAGES[Status.RANGE],
}


class CalibrationResult(eqx.Module):
    """Constants fitted to measured power losses (``calibrate``).

    Attributes:
        names: the calibrated parameters, in order (p of them).
        x: fitted values, natural units [p] (the start values where nothing was fitted).
        x_start: start values [p].
        covariance: covariance of the fitted values [p, p] (see the module docstring; NaN where
            undefined).
        jacobian: ∂rᵢ/∂θⱼ at the fitted values, per natural unit of θ [n, p].
        residuals: rᵢ = wᵢ (Φ̄ᵢ − Φ̄ᵢ,meas)/Φ̄ᵢ,meas at the fitted values [n] (dimensionless).
        residuals_start: the same at the start values [n].
        model_power_loss: Φ̄ᵢ at the fitted values, W [n].
        measured_power_loss: Φ̄ᵢ,meas, W [n].
        weights: wᵢ [n].
        point_status: each point's simulation status at the fitted values (at the start values
            when status is START) [n] (``results.Status``; 0 ok).
        steps: Levenberg-Marquardt steps taken (accepted and rejected).
        status: see ``STATUS_NAMES``.
        note: what the standard errors rest on, or why they are undefined.
        detail: which points failed, or which value left its range ('' if none).
        failed_points: indices of the points whose simulation failed: at the start values
            (status START), at the fitted values, or at the Gauss-Newton step the solver would
            still take from them (status SIMULATION: the fit stopped against constants where the
            simulation fails, not at a minimum).
        fidelity: the fidelity with the fitted constants (the input's where a fitted value left
            its range or nothing was fitted).
        surfaces: the surfaces with the fitted roughness scale (the input's otherwise).
    """

    names: tuple[str, ...] = eqx.field(static=True)
    x: np.ndarray
    x_start: np.ndarray
    covariance: np.ndarray
    jacobian: np.ndarray
    residuals: np.ndarray
    residuals_start: np.ndarray
    model_power_loss: np.ndarray
    measured_power_loss: np.ndarray
    weights: np.ndarray
    point_status: np.ndarray
    steps: int
    status: int
    note: str = eqx.field(static=True)
    detail: str = eqx.field(static=True)
    failed_points: tuple[int, ...] = eqx.field(static=True)
    fidelity: Fidelity
    surfaces: Surfaces

    @property
    def values(self) -> dict[str, float]:
        """name → fitted value (natural units)."""
        return {n: float(v) for n, v in zip(self.names, self.x, strict=True)}

    @property
    def standard_errors(self) -> dict[str, float]:
        """name → standard error of the fitted value, √cov_jj (natural units)."""
        se = np.sqrt(np.diag(self.covariance))
        return {n: float(v) for n, v in zip(self.names, se, strict=True)}

    @property
    def correlation(self) -> np.ndarray:
        """Correlation matrix of the fitted values [p, p]."""
        se = np.sqrt(np.diag(self.covariance))
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.covariance / np.outer(se, se)

    @property
    def residual_sum_of_squares(self) -> float:
        return float(np.sum(self.residuals**2))

    @property
    def degrees_of_freedom(self) -> int:
        """n − p."""
        return int(self.residuals.size - len(self.names))

    @property
    def converged(self) -> bool:
        return self.status == STATUS_CONVERGED

    @property
    def message(self) -> str:
        words = STATUS_NAMES[self.status]
        return f"{words}: {self.detail}" if self.detail else words


# ---------------------------------------------------------------------------------------------------
# The model: Φ̄ at every point as a function of the parameters, in one traced function
# ---------------------------------------------------------------------------------------------------


def _simulate_point(pair, lubricant, surfaces, op, fidelity):
    """One point's SimulationResult (both passes, traceable)."""
    return simulate_with_state(pair, lubricant, surfaces, op, fidelity)[0]


def substitute(fidelity: Fidelity, surfaces: Surfaces, names, theta):
    """(fidelity, surfaces) with the parameters ``names`` set to ``theta`` [p] (traceable)."""
    constants = {n: theta[i] for i, n in enumerate(names) if n != ROUGHNESS_SCALE}
    if constants:
        fidelity = fidelity.with_constants(**constants)
    if ROUGHNESS_SCALE in names:
        scale = theta[names.index(ROUGHNESS_SCALE)]
        surfaces = eqx.tree_at(lambda s: s.scale, surfaces, jnp.asarray(scale, dtype=float))
    return fidelity, surfaces


def batches_points(fidelity: Fidelity) -> bool:
    """Whether ``PowerLossModel`` vmaps its points (True) or maps them one after another
    (``lax.map``): vmapped on the quasi-static formula rungs; mapped where the contacts are EHL
    solves or the dynamics are tribo-dynamic, whose lazy branches (``_solvers.lazy_cond``) do not
    support forward-mode differentiation of a vmap (jvp of a vmapped transient EHL passage fails
    while tracing), which is what the Levenberg-Marquardt linearisation takes. On a CPU the
    points of those rungs run one after another either way."""
    return fidelity.dynamics == "quasi_static" and not fidelity.uses_ehl


class PowerLossModel(eqx.Module):
    """Φ̄ at each calibration point as a function of the parameters θ (natural units).

    Call with θ [p]; returns (Φ̄ W [n], simulation status [n]). The points are one
    OperatingPoint whose fields are arrays [n], vmapped over, or mapped (``batches_points``)."""

    pair: object
    lubricant: object
    surfaces: Surfaces
    points: OperatingPoint
    fidelity: Fidelity
    names: tuple[str, ...] = eqx.field(static=True)

    def __call__(self, theta):
        fidelity, surfaces = substitute(self.fidelity, self.surfaces, self.names, theta)

        def one(op):
            result = _simulate_point(self.pair, self.lubricant, surfaces, op, fidelity)
            return result.power_loss, result.status

        if batches_points(self.fidelity):
            return jax.vmap(one)(self.points)
        return jax.lax.map(one, self.points)


@eqx.filter_jit
def _evaluate(model: PowerLossModel, theta):
    """Φ̄ [n], status [n] and ∂Φ̄/∂θ [n, p] (forward mode) at θ."""

    def fn(t):
        loss, status = model(t)
        return loss, (loss, status)

    jac, (loss, status) = jax.jacfwd(fn, has_aux=True)(theta)
    return loss, status, jac


def _residuals(eta, args):
    model, measured, weights = args
    loss, status = model(jnp.exp(eta))
    r = weights * (loss - measured) / measured
    # a failed point is never fitted: NaN makes the trust region reject a step onto it
    return jnp.where(status == 0, r, jnp.nan), (loss, status)


@eqx.filter_jit
def _solve(model, eta0, measured, weights, solver, max_steps):
    sol = optx.least_squares(
        _residuals,
        solver,
        eta0,
        args=(model, measured, weights),
        has_aux=True,
        max_steps=max_steps,
        throw=False,
    )
    return sol.value, sol.result, sol.stats["num_steps"]


# ---------------------------------------------------------------------------------------------------
# Input checks
# ---------------------------------------------------------------------------------------------------


def _fmt_range(low, high) -> str:
    return f"> {low:g}" if math.isinf(high) else f"({low:g}, {high:g}]"


def _check_parameters(parameters, fidelity) -> tuple[str, ...]:
    if isinstance(parameters, str):
        parameters = (parameters,)
    names = tuple(parameters)
    if not names:
        raise ValueError(
            f"parameters = {parameters!r} is empty; valid: one or more of {', '.join(PARAMETERS)}"
        )
    for name in names:
        if name not in PARAMETERS:
            raise ValueError(
                f"parameters: {name!r} is not a calibratable parameter; valid names: "
                f"{', '.join(PARAMETERS)}"
            )
    if len(set(names)) != len(names):
        raise ValueError(f"parameters = {names!r} names a parameter twice")
    if "limiting_shear_coefficient" in names and not fidelity.contact.limiting_shear:
        raise ValueError(
            "parameters: 'limiting_shear_coefficient' acts only with the limiting shear stress on; "
            "build the fidelity with limiting_shear_coefficient=... (or limiting_shear=True)"
        )
    return names


def _stack_points(operating_points) -> OperatingPoint:
    fields = ("torque", "speed_rpm", "inlet_temperature")
    if isinstance(operating_points, OperatingPoint):
        arrays = jnp.broadcast_arrays(
            *(jnp.atleast_1d(getattr(operating_points, f)) for f in fields)
        )
        if any(a.ndim != 1 for a in arrays):
            raise ValueError(
                "operating_points: an OperatingPoint's fields must be scalars or 1-D arrays "
                f"(one entry per point); got shapes {[jnp.shape(a) for a in arrays]}"
            )
    else:
        if not isinstance(operating_points, Sequence) or isinstance(operating_points, str):
            raise ValueError(
                f"operating_points = {operating_points!r} is not valid; valid: a sequence of "
                "jaxgear.OperatingPoint or one OperatingPoint with array fields"
            )
        for i, op in enumerate(operating_points):
            check_instance(f"operating_points[{i}]", op, OperatingPoint)
            for f in fields:
                if jnp.shape(getattr(op, f)) != ():
                    raise ValueError(
                        f"operating_points[{i}].{f} has shape {jnp.shape(getattr(op, f))}; valid: "
                        "a scalar (or pass one OperatingPoint with array fields)"
                    )
        if not operating_points:
            arrays = [jnp.zeros(0)] * 3
        else:
            arrays = [jnp.stack([getattr(op, f) for op in operating_points]) for f in fields]
    if arrays[0].size == 0:
        raise ValueError("operating_points is empty; valid: at least one operating point")
    points = OperatingPoint(torque=arrays[0], speed_rpm=arrays[1], inlet_temperature=arrays[2])
    return points


def _per_point(name, value, n, default=None) -> np.ndarray:
    if value is None:
        return np.full(n, default, dtype=float)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r} is not valid; valid: {n} positive numbers") from None
    if arr.shape != (n,):
        raise ValueError(
            f"{name} has shape {arr.shape}; valid: shape ({n},), one value per operating point"
        )
    bad = np.flatnonzero(~np.isfinite(arr) | (arr <= 0))
    if bad.size:
        i = int(bad[0])
        raise ValueError(
            f"{name}[{i}] = {float(arr[i])!r} is out of range; valid range: finite and > 0"
            + (" W" if name == "measured_power_loss" else "")
        )
    return arr


def _start_values(names, fidelity, surfaces, initial) -> np.ndarray:
    initial = {} if initial is None else initial
    if not isinstance(initial, Mapping):
        raise ValueError(f"initial = {initial!r} is not valid; valid: a dict name → start value")
    extra = sorted(set(initial) - set(names))
    if extra:
        raise ValueError(
            f"initial: {extra[0]!r} is not among the calibrated parameters {', '.join(names)}"
        )
    values = []
    for name in names:
        if name in initial:
            value = initial[name]
        elif name == ROUGHNESS_SCALE:
            value = surfaces.scale
        else:
            value = getattr(fidelity.constants, name)
        if not is_concrete(value):
            raise ValueError(f"initial {name} must be a concrete number, not a traced value")
        low, high = PARAMETERS[name][0]
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise ValueError(
                f"initial {name} = {value!r} is out of range; valid range: {_fmt_range(low, high)}"
            ) from None
        if not (math.isfinite(number) and max(low, 0.0) < number <= high):
            raise ValueError(
                f"initial {name} = {number!r} is out of range; valid range: "
                f"{_fmt_range(max(low, 0.0), high)} (fitted in log space: > 0)"
            )
        values.append(number)
    return np.asarray(values)


def _check_settings(rtol, atol, max_steps):
    for name, value in (("rtol", rtol), ("atol", atol)):
        if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0:
            raise ValueError(f"{name} = {value!r} is out of range; valid range: > 0")
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
        raise ValueError(f"max_steps = {max_steps!r} is out of range; valid range: integer >= 1")


# ---------------------------------------------------------------------------------------------------
# calibrate
# ---------------------------------------------------------------------------------------------------


def calibrate(
    pair,
    lubricant,
    surfaces,
    fidelity: Fidelity,
    operating_points,
    measured_power_loss,
    parameters: Sequence[str] = DEFAULT_PARAMETERS,
    weights=None,
    initial: Mapping[str, float] | None = None,
    *,
    absolute_sigma: bool = False,
    rtol: float = 1e-6,
    atol: float = 1e-8,
    max_steps: int = 50,
) -> CalibrationResult:
    """Fit model constants to measured mesh power losses (Levenberg-Marquardt, see the module
    docstring for the residual, the log parameters and the standard errors).

    Args:
        pair: GearPair.
        lubricant: Lubricant.
        surfaces: Surfaces (its ``scale`` is the start value of "roughness_scale").
        fidelity: Fidelity whose constants are calibrated (its other constants stay as they are);
            any rung, the quasi-static ones being the cheapest.
        operating_points: the measured points: a sequence of n OperatingPoint (scalar fields), or
            one OperatingPoint whose fields are arrays [n] (scalars broadcast).
        measured_power_loss: measured mesh power loss Φ̄ of each point, W [n], > 0.
        parameters: names of the calibrated parameters: the contact constants of
            ``Fidelity.with_constants`` (constant_mu, boundary_friction, asperity_density_product,
            asperity_slope_ratio, limiting_shear_coefficient) and "roughness_scale"
            (``Surfaces.scale``); p ≤ n of them. Default μb and nβσ.
        weights: wᵢ of each point's relative residual [n], > 0; default 1 (every point's misfit
            counts as a fraction of its loss). With ``absolute_sigma`` they are 1/σᵢ, σᵢ the
            relative standard uncertainty of measurement i.
        initial: start values, name → value (natural units, > 0); default the fidelity's (and
            surfaces') current values.
        absolute_sigma: the weights are known inverse uncertainties: cov = (JᵀJ)⁻¹ instead of
            s² (JᵀJ)⁻¹ (default False).
        rtol, atol: Levenberg-Marquardt stops once every |Δηⱼ| < atol + rtol |ηⱼ| (η = ln θ, so
            Δη is a relative change of θ) and every |Δrᵢ| < atol + rtol |rᵢ| (r relative
            residuals). Defaults 1e-6 and 1e-8 suit a model smooth to round-off; a model whose Φ̄
            is reproducible only to ~1e-3 (the thermal EHL rungs' Picard loops) needs atol ≈ 1e-4
            or the solver runs to ``max_steps``.
        max_steps: cap on Levenberg-Marquardt steps (accepted and rejected), default 50.

    Returns:
        CalibrationResult: ``values``, ``standard_errors``, ``covariance``, ``residuals``,
        ``model_power_loss``, ``fidelity`` (with the fitted constants), ``status``/``converged``/
        ``message`` (naming any point whose simulation failed), ``steps``.

    Raises:
        ValueError: bad input, naming the field, its value and the valid range (unknown or
            repeated parameter, no points, fewer points than parameters, a measured loss or
            weight that is not positive and finite, a length mismatch, a start value out of range).
    """
    check_instance("fidelity", fidelity, Fidelity)
    names = _check_parameters(parameters, fidelity)
    points = _stack_points(operating_points)
    n, p = int(points.torque.shape[0]), len(names)
    check_inputs(
        pair,
        lubricant,
        surfaces,
        OperatingPoint(
            torque=points.torque[0],
            speed_rpm=points.speed_rpm[0],
            inlet_temperature=points.inlet_temperature[0],
        ),
        fidelity,
    )
    # float leaves as float64 arrays (a Python float put in by eqx.tree_at would be a static leaf:
    # a recompilation per value), checked as their constructors would (as simulate does)
    pair, lubricant, surfaces, fidelity = canonical((pair, lubricant, surfaces, fidelity))
    validate((pair, lubricant, surfaces, fidelity))
    measured = _per_point("measured_power_loss", measured_power_loss, n)
    w = _per_point("weights", weights, n, default=1.0)
    if n < p:
        raise ValueError(
            f"operating_points: {n} point(s) for {p} parameters ({', '.join(names)}); valid: at "
            "least as many points as parameters"
        )
    _check_settings(rtol, atol, max_steps)
    theta0 = _start_values(names, fidelity, surfaces, initial)

    model = PowerLossModel(pair, lubricant, surfaces, points, fidelity, names)
    measured_j, w_j = jnp.asarray(measured), jnp.asarray(w)

    def residuals_and_jacobian(theta):
        loss, status, dloss = (np.asarray(a) for a in _evaluate(model, jnp.asarray(theta)))
        scale = w / measured
        return loss, status.astype(int), scale * (loss - measured), scale[:, None] * dloss

    loss0, status0, r0, jac0 = residuals_and_jacobian(theta0)
    if np.any(status0 != 0):
        return _result(
            names, theta0, theta0, jac0, r0, r0, loss0, measured, w, status0, 0, STATUS_START,
            _failed_detail(status0), np.flatnonzero(status0 != 0), model, absolute_sigma,
        )  # fmt: skip

    solver = optx.LevenbergMarquardt(rtol=float(rtol), atol=float(atol))
    eta, solver_result, steps = _solve(
        model, jnp.log(jnp.asarray(theta0)), measured_j, w_j, solver, max_steps
    )
    theta = np.exp(np.asarray(eta))
    loss, status, r, jac = residuals_and_jacobian(theta)

    detail, failed = "", np.flatnonzero(status != 0)
    if failed.size:
        code, detail = STATUS_SIMULATION, _failed_detail(status)
    elif not (np.all(np.isfinite(r)) and np.all(np.isfinite(jac))):
        code = STATUS_NON_FINITE
    elif probe := _blocked_by_failures(residuals_and_jacobian, theta, r, jac, rtol, atol):
        # the solver stopped against parameter values where the simulation fails, not at a
        # minimum: the Gauss-Newton step it would still take from here lands on failed points
        failed, code = probe[0], STATUS_SIMULATION
        detail = (
            f"the Gauss-Newton step from the fitted values fails at {probe[1]}: the fit stopped "
            "against constants where the simulation fails, not at a minimum"
        )
    elif _out_of_range(names, theta):
        code, detail = STATUS_RANGE, _out_of_range(names, theta)
    elif solver_result == optx.RESULTS.successful:
        code = STATUS_CONVERGED
    elif solver_result == optx.RESULTS.nonlinear_max_steps_reached:
        code = STATUS_MAX_STEPS
    else:
        code = STATUS_NON_FINITE
        detail = f"optimistix: {optx.RESULTS[solver_result]}"
    return _result(
        names, theta, theta0, jac, r, r0, loss, measured, w, status, int(steps), code, detail,
        failed, model, absolute_sigma,
    )  # fmt: skip


def _blocked_by_failures(evaluate, theta, r, jac, rtol, atol):
    """(failed point indices, detail) where the Gauss-Newton step δη = −J_η⁺ r from θ, larger
    than the solver's tolerance, lands on failed points; None otherwise."""
    eta = np.log(theta)
    step = -np.linalg.lstsq(jac * theta[None, :], r, rcond=None)[0]
    if not np.any(np.abs(step) > atol + rtol * np.abs(eta)):
        return None
    status = evaluate(theta * np.exp(step))[1]
    failed = np.flatnonzero(status != 0)
    return (failed, _failed_detail(status)) if failed.size else None


def _failed_detail(status) -> str:
    failed = np.flatnonzero(status != 0)
    parts = [
        f"{int(i)} (status {int(status[i])}: {MESSAGES[Status(int(status[i]))]})" for i in failed
    ]
    return "point(s) " + "; ".join(parts)


def _out_of_range(names, theta) -> str:
    for name, value in zip(names, theta, strict=True):
        low, high = PARAMETERS[name][0]
        if not low <= value <= high:
            return f"{name} = {value:.6g} is outside its valid range [{low:g}, {high:g}]"
    return ""


def covariance(jacobian, residuals, absolute_sigma=False) -> tuple[np.ndarray, str]:
    """(cov [p, p], note) from J = ∂r/∂θ [n, p] and r [n] (see the module docstring). Through the
    singular values of J: a zero singular value gives infinite variances, not a failed inverse."""
    n, p = jacobian.shape
    _, s, vt = np.linalg.svd(jacobian, full_matrices=False)
    with np.errstate(divide="ignore"):
        inv_s2 = np.where(s > s[0] * 1e-14, 1.0 / s**2, np.inf) if s.size else s
    unscaled = (vt.T * inv_s2) @ vt
    if np.any(np.isinf(inv_s2)):
        unscaled = np.where(np.isnan(unscaled), np.inf, unscaled)
    if absolute_sigma:
        return unscaled, "cov = (JᵀJ)⁻¹: the weights taken as 1/σ of known relative uncertainties"
    if n == p:
        note = (
            f"n = p = {p}: the fit interpolates the data and leaves no residual degrees of "
            "freedom; the standard errors s²(JᵀJ)⁻¹ are undefined (NaN); give absolute_sigma=True "
            "with weights 1/σ to use known uncertainties"
        )
        return np.full((p, p), np.nan), note
    s2 = float(np.sum(residuals**2)) / (n - p)
    return s2 * unscaled, f"cov = s²(JᵀJ)⁻¹, s² = RSS/(n − p) = {s2:.3g} (relative residuals)"


def _result(names, theta, theta0, jac, r, r0, loss, measured, w, status, steps, code, detail,
            failed, model, absolute_sigma) -> CalibrationResult:  # fmt: skip
    cov, note = covariance(jac, r, absolute_sigma)
    fidelity, surfaces = model.fidelity, model.surfaces
    if code not in (STATUS_START, STATUS_RANGE) and np.all(np.isfinite(theta)):
        fidelity, surfaces = substitute(fidelity, surfaces, names, jnp.asarray(theta))
    return CalibrationResult(
        names=names,
        x=np.asarray(theta),
        x_start=np.asarray(theta0),
        covariance=cov,
        jacobian=np.asarray(jac),
        residuals=np.asarray(r),
        residuals_start=np.asarray(r0),
        model_power_loss=np.asarray(loss),
        measured_power_loss=np.asarray(measured),
        weights=np.asarray(w),
        point_status=np.asarray(status),
        steps=int(steps),
        status=int(code),
        note=note,
        detail=detail,
        failed_points=tuple(int(i) for i in failed),
        fidelity=fidelity,
        surfaces=surfaces,
    )
