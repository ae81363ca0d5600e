"""The differentiable solve: ``_solve_core``, the fine-grid solution u* = [P, H0] by a sequence
of attempts (warm, relaxed, continued, cold, pseudo-transient), differentiated by the implicit
function theorem (its ``custom_jvp`` rule), and ``_postprocess``: the SI film, friction, damping
and heat of a solution (S. Li, Tribol. Int. 88 (2015))."""

from __future__ import annotations

import dataclasses
import functools

import equinox as eqx
import jax
import jax.numpy as jnp

from ..._solvers.lazy_cond import cond_any_member
from .. import asperity as asperity_mod
from .. import rheology
from ..reynolds import smooth_positive
from .continuation import (
    _EXPONENT_STEPS,
    _adaptive_continuation,
    _pseudo_march,
    _rough_homotopy,
    _temperature_continuation,
    _with_pseudo_squeeze,
)
from .discretisation import (
    _FLOOR_FRACTION,
    _fine_level,
    _levels,
    _log_shear_factor,
    _Scales,
)
from .model import EHLModel, _Inputs
from .newton import _newton
from .solution import EHLSolution
from .starts import (
    _DIRECT_ROW,
    _FINE_CONTINUATION_NODES,
    _FINE_CONTINUATION_START,
    _RELAX_ROUNDS,
    _cold_start,
    _distributive_relaxation,
    _half_step_start,
    _hertz_start,
    _relaxation_sweeps,
    _schedules,
    _warm_start,
)

_RETRY = -1  # attempt kind: a further relaxation round from where the last Newton stopped
_HALF = -2  # attempt kind: this step's start from the solution of its half step
# the later rounds and the half step are tried only if the last Newton ended with ‖F‖∞ below this:
# they rescue about one step in five that ended above it, against more than half below it
_RELAX_GIVE_UP = 0.1


_PSEUDO = -3  # attempt kind: the pseudo-time march (deterministic roughness, after the cold ones)
_HOT = -4  # attempt kind: the continuation in the temperatures of a re-solve (deterministic film)

# which attempts ``_solve_core`` skips (its traced ``skip``): none; the warm ones (a cold solve);
# the continuation in the temperatures (a deterministic film's first solve)
SKIP_NONE, SKIP_WARM, SKIP_HOT = 0.0, 1.0, 2.0


@functools.partial(jax.custom_jvp, nondiff_argnums=(0, 1, 2))
def _solve_core(
    model: EHLModel, warm: bool, mixed: bool, inp: _Inputs, init_x, init_p, init_h0, skip
):
    """u* = [P, H0] on the fine grid, plus (residual, iterations, converged) as floats.

    The fine-grid Newton loop appears once in the program: a warm solve is a scan over two attempts
    (the warm start, then, only if that failed, the cold start), so compile time does not double.
    ``skip`` (a traced scalar) skips attempts of a warm solve: ``SKIP_WARM`` makes it a cold one
    (its warm attempts skipped, its cold ones run as a cold solve runs them), ``SKIP_HOT`` makes a
    deterministic film's re-solve (``inp.temperature_rise_previous`` given) its first solve (no
    continuation in the temperatures), ``SKIP_NONE`` skips none; so a first solve and its re-solves
    can share one trace (``outer._solve_and_update``)."""
    if mixed == "deterministic":
        inp = dataclasses.replace(inp, rough=True)
    sc, fine = _fine_level(model, inp)
    dtype = fine.x.dtype
    # attempts: [warm start,] cold with the fine schedule, cold with the coarse schedule, [cold
    # finishing the continuation on the finest grid,] cold without continuation; each runs only if
    # everything before it failed (lax.cond: no work when skipped, outside vmap). The fine-grid
    # continuation only on fine grids, where the one-cell spike trap arises (under vmap a skipped
    # attempt still runs, so coarser grids do not pay for it); deterministic mixed films continue
    # in the roughness from a smooth film instead (its start from the first, second or last row),
    # and stop after a failed continuation that got under way
    third = mixed != "deterministic" and model.n_nodes >= _FINE_CONTINUATION_NODES
    rows = [0, 1] + ([2] if third else []) + [_DIRECT_ROW]
    det = mixed == "deterministic"
    u_start = _warm_start(fine, init_x, init_p, init_h0, det) if warm else _hertz_start(fine)
    # deterministic roughness: relaxation sweeps before the warm Newton; if it fails, more sweeps
    # from where it stopped and Newton again (``_RELAX_ROUNDS`` in all), then the cold solve
    relax = warm and det and _relaxation_sweeps(model) > 0
    u_warm = u_start
    if relax:
        # only where the roughness moved since the start's solution (a re-solve at new
        # temperatures starts from the solution it refines)
        u_warm = jax.lax.cond(
            init_h0[2] > 0.5,
            lambda u: _distributive_relaxation(fine, u, _relaxation_sweeps(model)),
            lambda u: u,
            u_start,
        )
    rounds = [_RETRY] * (_RELAX_ROUNDS - 1 if relax else 0)
    # and if those fail (transient passage steps): the half step first (the roughness moved half
    # as far), its solution, relaxed, this step's start
    half = relax and inp.film_offset_previous is not None
    # a re-solve at updated temperatures: a continuation in the temperatures from the start's
    # (``_temperature_continuation``) before the relaxed rounds
    hot = warm and det and inp.temperature_rise_previous is not None
    warm_kinds = (
        ([0] + ([_HOT] if hot else []) + rounds + ([_HALF] if half else [])) if warm else []
    )
    # deterministic roughness, when everything else failed: the pseudo-time march
    pseudo = det and model.pseudo_transient_steps > 0
    kinds = jnp.asarray(warm_kinds + [r + 1 for r in rows] + ([_PSEUDO] if pseudo else []))
    false = jnp.asarray(False)

    def attempt(carry, kind):
        u, res, it, ok, stop = carry

        # The branches read only their operand (no batched value closed over): cond_any_member.
        def cold(operand):
            kind, _, inp, _ = operand
            row = jnp.clip(kind - 1, 0, _DIRECT_ROW)
            # the coarse grids are built here, inside the branch: a warm start never pays for them
            _, levels = _levels(model, inp)
            fine = levels[-1]
            schedules = _schedules(model, dtype)
            false = jnp.asarray(False)
            if mixed != "deterministic" and not third:
                return (*_cold_start(model, levels, schedules[row], cubic=row == 0), false)
            if mixed != "deterministic":
                # third attempt: reach the finest grid at s < 1, continue s → 1 there
                s_end = jnp.where(row == 2, _FINE_CONTINUATION_START, 1.0).astype(dtype)
                start, k0 = _cold_start(
                    model, levels, schedules[row] * s_end, cubic=row == 0, s_end=s_end
                )
                start, k0, _ = _adaptive_continuation(
                    model,
                    lambda r: (fine, s_end + (1.0 - s_end) * r),
                    start,
                    k0,
                    jnp.where(row == 2, 0.0, 1.0).astype(dtype),
                    _EXPONENT_STEPS,
                )
                return start, k0, false
            # mixed: the smooth steady problem first, then a continuation on the fine grid (coarse
            # grids cannot resolve the roughness anyway) in r, which scales the roughness and, in a
            # transient step, moves the squeeze term's previous film from the smooth start's ρ̄H
            # (at r = 0 the system is the smooth steady one, its squeeze term vanishing at that
            # start) to the previous step's rough one (see ``_rough_homotopy``)
            smooth = [lev.smooth_steady() for lev in levels]
            start, k0 = _cold_start(model, smooth, schedules[row], cubic=row == 0)
            rho_h_smooth = smooth[-1].rho_h(start)
            smooth_start = start
            path = fine
            if pseudo:
                # the pseudo-time attempt's first step (Δt = Δx/ur from the smooth film) is this
                # continuation with the pseudo squeeze term added; its other kinds add none
                sigma = jnp.where(kind == _PSEUDO, 1.0 / fine.spacing, 0.0)
                path = _with_pseudo_squeeze(fine, sigma, rho_h_smooth)
            start, k0, reached = _adaptive_continuation(
                model,
                _rough_homotopy(path, rho_h_smooth),
                start,
                k0,
                jnp.zeros((), dtype),
                model.roughness_steps,
            )
            if pseudo:
                # a first pseudo-time step that failed leaves nothing to march from
                go = (kind == _PSEUDO) & (reached >= 1.0)
                steps = jnp.where(go, model.pseudo_transient_steps, 0)
                start, k_march = _pseudo_march(
                    model, fine, start, smooth_start, rho_h_smooth, steps
                )
                k0 = k0 + k_march
            # once a roughness step has been accepted, the smooth start was good: if this attempt
            # fails, the next would repeat the same continuation from the same smooth film (a
            # more patient one, 16 first steps and twice the Newton budget, stalls as well at
            # 500 rpm on 1025 nodes), so it is not run
            return start, k0, reached > 0.0

        def retry(operand):
            _, u, inp, _ = operand
            fine = _fine_level(model, inp)[1]
            start = _distributive_relaxation(fine, u, max(_relaxation_sweeps(model) // 2, 1))
            return start, jnp.asarray(0), jnp.asarray(False)

        def halfway(operand):
            _, _, inp, u_start = operand
            start, k = _half_step_start(model, inp, u_start)
            return start, k, jnp.asarray(False)

        def heated(operand):
            _, _, inp, u_start = operand
            start, k = _temperature_continuation(model, inp, u_start)
            return start, k, jnp.asarray(False)

        def prepare(operand):
            # the other branches of this solve's attempt kinds (cold for the rest)
            others = [(_RETRY, retry)] if relax else []
            others += [(_HALF, halfway)] if half else []
            others += [(_HOT, heated)] if hot else []
            if not others:
                return cold(operand)
            index = jnp.asarray(0)
            for i, (k, _) in enumerate(others):
                index = jnp.where(operand[0] == k, i + 1, index)
            return jax.lax.switch(index, [cold] + [b for _, b in others], operand)

        def keep(operand):
            return operand[1], jnp.asarray(0), jnp.asarray(False)

        # further relaxed rounds only after a Newton that got close (see ``_RELAX_GIVE_UP``)
        hopeless = ((kind == _RETRY) | (kind == _HALF)) & ~(res < _RELAX_GIVE_UP)
        warm_kind = (kind == 0) | (kind == _RETRY) | (kind == _HALF) | (kind == _HOT)
        # a warm solve told to be cold skips its warm attempts
        skipped = (warm_kind & (skip == SKIP_WARM)) | ((kind == _HOT) & (skip == SKIP_HOT))
        # a failed roughness continuation ends the cold attempts, not the pseudo-time march
        done = ok | (stop & (kind != _PSEUDO)) | hopeless | skipped
        operand = (kind, u, inp, u_start)
        start, k0, repeat = cond_any_member(done | (kind == 0), keep, prepare, operand)
        start = jnp.where(kind == 0, u_warm, start)
        budget = model.warm_iterations if warm else model.max_iterations
        max_iter = jnp.where(done, 0, jnp.where(warm_kind, budget, model.max_iterations))
        u1, res1, k1, ok1 = _newton(fine, start, 1.0, max_iter)
        u1 = jnp.where(done, u, u1)
        res1 = jnp.where(done, res, res1)
        # smooth EHL: a closed film is a failure: try the next attempt (mixed: it is contact)
        ok1 = ok | (ok1 & ~skipped)
        if mixed == "smooth":
            ok1 = ok1 & (jnp.min(fine.film(u1)) > 0.0)
        return (u1, res1, it + k0 + k1, ok1, stop | repeat), None

    init = (u_warm, jnp.asarray(jnp.inf, dtype=dtype), jnp.asarray(0), false, false)
    (u, res, it, ok, _), _ = jax.lax.scan(attempt, init, kinds)
    # a closed (non-positive) film is not a smooth-EHL solution, however small the residual: report
    # it
    if mixed == "smooth":
        ok = ok & (jnp.min(fine.film(u)) > 0.0)
    finite = jnp.all(jnp.isfinite(u))
    fallback = _hertz_start(fine)
    u = jnp.where(finite, u, fallback)
    res = jnp.where(finite & jnp.isfinite(res), res, jnp.finfo(u.dtype).max)
    ok = ok & finite
    return u, res, it.astype(u.dtype), ok.astype(u.dtype)


@_solve_core.defjvp
def _solve_core_jvp(model, warm, mixed, primals, tangents):
    inp, init_x, init_p, init_h0, skip = primals
    d_inp = tangents[0]
    u, res, it, ok = _solve_core(model, warm, mixed, inp, init_x, init_p, init_h0, skip)
    if mixed == "deterministic":  # the system the solve solved (``EHLModel.smoothing``)
        inp = dataclasses.replace(inp, rough=True)
        d_inp = dataclasses.replace(d_inp, rough=True)

    def fine_residual(theta):
        return _fine_level(model, theta)[1].residual(u, 1.0)

    jac = _fine_level(model, inp)[1].jacobian(u, 1.0)
    _, df = jax.jvp(fine_residual, (inp,), (d_inp,))
    du = -jnp.linalg.solve(jac, df)
    z = jnp.zeros_like(res)
    return (u, res, it, ok), (du, z, z, z)


def _contact_indicator(model: EHLModel, sc: _Scales, big_h):
    """Smooth share (0 … 1) of asperity contact at each node: 1 where the dimensionless film H is
    below ``contact_threshold`` × the smooth central-film estimate, 0 above twice that."""
    hc = model.contact_threshold * sc.h_ref
    return 0.5 * (1.0 - jnp.tanh(4.0 * (big_h - 1.5 * hc) / hc))


def _solution_structure(model: EHLModel, mixed: str, inp: _Inputs):
    """The structure (shapes, dtypes) of the ``EHLSolution`` a solve of ``inp`` returns, found
    without tracing the solve: its unknowns are shaped as the Hertzian start of the fine grid."""

    def solution():
        theta = dataclasses.replace(inp, rough=True) if mixed == "deterministic" else inp
        u = _hertz_start(_fine_level(model, theta)[1])
        one = jnp.ones((), u.dtype)
        return _postprocess(model, mixed, inp, u, one, one, one)

    return eqx.filter_eval_shape(solution)


def _postprocess(model: EHLModel, mixed: str, inp: _Inputs, u, res, it, ok) -> EHLSolution:
    sc, lev = _fine_level(model, inp)
    c, lub = inp.contact, inp.lubricant
    n = lev.n
    r = c.reduced_radius
    h_scale = sc.b**2 / r
    p_nd, delta = lev.plastic(u[:n])
    big_h = lev.film(u)
    # the statistical film: p_nd the total pressure, big_h the mean-plane separation; the fluid
    # carries its own pressure through the average gap (``_Level.fluid``, ``_Level.gap``)
    p_asp = sc.ph * lev.asperity(big_h)
    p_dim = sc.ph * lev.fluid(p_nd, big_h)  # the fluid's pressure
    h = big_h * h_scale
    gap = lev.gap(big_h) * h_scale
    factor = lev.flow_factor(big_h)
    x = lev.x * sc.b
    dx = lev.spacing * sc.b
    t = lev.temperature
    rho = lub.density_at(p_dim, t, model.compressibility == "dowson_higginson")
    log_eta = lub.log_viscosity(p_dim, t, model.viscosity)
    eta = jnp.exp(log_eta)
    h_eff = smooth_positive(gap, _FLOOR_FRACTION * sc.h_ref * h_scale)
    abs_us = jnp.sqrt(sc.us**2 + (1e-6 * sc.um) ** 2)
    log_s = log_eta + jnp.log(abs_us / (lub.eyring_stress * h_eff))
    log_eta_s = log_eta + _log_shear_factor(model, log_s, "stress")  # secant: τ h/|us|
    if model.limiting_shear_coefficient is not None:  # τ ≤ τL = Λ p (smooth); not the damping
        log_rate = jnp.log(abs_us / h_eff)
        log_tau = rheology.log_limited_stress(
            log_eta_s + log_rate, p_dim, inp.numbers.limiting_shear_coefficient, 1e-6 * sc.ph
        )
        log_eta_s = log_tau - log_rate
    eta_s = jnp.exp(log_eta_s)
    eta_t = jnp.exp(log_eta + _log_shear_factor(model, log_s, "flow"))  # flow coefficient, damping
    # asperity contact (paper Eq. 4b/4c, 12, 15): boundary friction μb p on closed nodes
    # (deterministic), μb p_a on the real contact area (statistical)
    if mixed == "deterministic":
        contact = _contact_indicator(model, sc, big_h)
    elif inp.mean_plane:
        contact = asperity_mod.contact_area_ratio(
            h, jnp.maximum(inp.roughness, 1e-12), inp.numbers.asperity_density_product
        )
    else:
        contact = jnp.zeros_like(big_h)
    fluid = 1.0 - contact
    # the load on the asperities: the closed nodes' pressure (deterministic), p_a (statistical)
    p_solid = p_asp if inp.mean_plane else contact * p_dim
    dpdx = jnp.gradient(p_dim, dx)
    # Fill fraction of the cavitated outlet: the mass flux through x = 0 carried as Couette streaks.
    rho_h = rho * h_eff
    eps_flux = factor * rho * h_eff**3 / (12.0 * eta_t) * dpdx
    q = jnp.interp(0.0, x, rho_h * sc.um - eps_flux)
    fill = jnp.where(x > 0.0, jnp.clip(q / (sc.um * rho_h), 0.0, 1.0), 1.0)
    weights = jnp.full((n,), dx).at[0].set(0.5 * dx).at[-1].set(0.5 * dx)
    q_slide = fluid * fill * eta_s * sc.us**2 / h_eff  # paper Eq. (12), sliding part
    q_asp = inp.numbers.boundary_friction * p_solid * abs_us  # paper Eq. (12), h = 0
    # Poiseuille terms on cell faces, as the Reynolds discretisation has them (flow coefficient
    # averaged to the face, pressure gradient by the face difference)
    flow = (1.0 - contact if mixed == "deterministic" else factor) * h_eff**3 / (12.0 * eta_t)
    dp_face = jnp.diff(p_dim) / dx
    q_roll_face = 0.5 * (flow[1:] + flow[:-1]) * dp_face**2  # paper Eq. (12), rolling part
    q_roll = 0.5 * (jnp.pad(q_roll_face, (1, 0)) + jnp.pad(q_roll_face, (0, 1)))
    sign = (c.u2 - c.u1) / abs_us
    # paper Eq. (15): Fs = Σ μb p (asperity) + Σ η*(u2 − u1)/h (fluid); Fr = Σ (h/2) ∂p/∂x (fluid)
    fs_fluid = jnp.sum(weights * fluid * fill * eta_s * (c.u2 - c.u1) / h_eff)
    fs_asp = jnp.sum(weights * inp.numbers.boundary_friction * p_solid) * sign
    film_gap = gap if inp.mean_plane else h
    open_face = 1.0 if inp.mean_plane else 0.5 * (fluid[1:] + fluid[:-1])
    h_face = 0.5 * (film_gap[1:] + film_gap[:-1]) * open_face
    fr = jnp.sum(0.5 * h_face * jnp.diff(p_dim))
    cm = jnp.sum(weights * fluid * fill * eta_t / h_eff)  # paper Eq. (13) per unit width
    # sub-grid minimum film by a parabola through the smallest node and its neighbours
    i = jnp.clip(jnp.argmin(big_h), 1, n - 2)
    hm, h_0, hp = big_h[i - 1], big_h[i], big_h[i + 1]
    curv = hm - 2.0 * h_0 + hp
    safe = jnp.where(curv > 0, curv, 1.0)
    h_min = jnp.where(curv > 0, h_0 - (hp - hm) ** 2 / (8.0 * safe), h_0) * h_scale
    h_central = jnp.interp(0.0, lev.x, big_h) * h_scale
    load_err = jnp.sum(weights * (p_dim + p_asp)) / c.load_per_width - 1.0
    # nodes of the Hertz zone (at least the one nearest the centre: a coarse grid on a wide domain
    # may have no node inside |X| ≤ 1)
    hertz_zone = (jnp.abs(lev.x) <= jnp.maximum(1.0, 0.5 * lev.spacing)).astype(p_dim.dtype)
    p_loss_slide = jnp.sum(weights * q_slide)
    p_loss_asp = jnp.sum(weights * q_asp)
    p_loss_roll = jnp.sum(q_roll_face) * dx
    t_in = jnp.broadcast_to(c.inlet_temperature, t.shape)
    fraction = jnp.sum(hertz_zone * contact) / jnp.sum(hertz_zone)
    return EHLSolution(
        x=x,
        p=p_dim + p_asp,
        h=h,
        gap=gap,
        density=rho,
        viscosity=eta,
        shear_viscosity=eta_s,
        temperature=t,
        surface_temperature1=t_in,
        surface_temperature2=t_in,
        heat_partition=jnp.full_like(t, 0.5),
        heat_flux=q_slide + q_roll + q_asp,
        heat_flux_sliding=q_slide,
        heat_flux_rolling=q_roll,
        heat_flux_asperity=q_asp,
        contact=contact,
        asperity_pressure=p_asp,
        h_min=h_min,
        h_central=h_central,
        h0=u[n] * h_scale,
        p_max=jnp.max(p_dim + p_asp),
        friction_sliding=fs_fluid + fs_asp,
        friction_asperity=fs_asp,
        friction_rolling=fr,
        damping=cm,
        power_loss=p_loss_slide + p_loss_asp + p_loss_roll,
        power_loss_sliding=p_loss_slide + p_loss_asp,
        power_loss_rolling=p_loss_roll,
        power_loss_asperity=p_loss_asp,
        contact_fraction=fraction,
        contact_load=jnp.sum(weights * p_solid),
        plastic_gap=jnp.zeros_like(h) if delta is None else delta * h_scale,
        load_error=load_err,
        hertz_half_width=sc.b,
        hertz_pressure=sc.ph,
        moes_m=sc.moes_m,
        moes_l=sc.moes_l,
        moes_film=sc.h_ref * h_scale,
        converged=ok > 0.5,
        residual=res,
        iterations=jax.lax.stop_gradient(it).astype(jnp.int32),
        thermal_residual=jnp.zeros_like(res),
    )
