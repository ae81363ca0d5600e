"""Where a fine-grid Newton solve starts: the Hertz start, grid transfer and the cold start
(continuation in the piezo-viscous exponent on the coarsest grid, then grid sequencing), the
warm start from a nearby solution (``_warm_args``, ``_warm_start``), and the distributive
relaxation sweeps and half-step start of a deterministic rough film's transient step."""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .. import asperity as asperity_mod
from .discretisation import _BAND, _KRYLOV_BLOCK, _PLASTIC_GAP_SCALE, _bands, _fine_level, _Level
from .model import EHLModel, _Inputs
from .newton import _newton
from .solution import EHLSolution


def _hertz_start(level: _Level):
    # the Hertz ellipse, widened to span at least two cells: on the wide domain of a thick film
    # (M ≪ 1) a coarse grid may hold no node inside |X| < 1, and the normalisation would be 0/0
    half = jnp.maximum(1.0, 2.0 * level.spacing)
    p = jnp.sqrt(jnp.maximum(1.0 - (level.x / half) ** 2, 0.0))
    p = p * (0.5 * jnp.pi) / (level.spacing * jnp.sum(p))
    defo = level.deformation(p)
    # film offset such that the central film equals the Moes estimate
    h0 = level.sc.h_ref - jnp.interp(0.0, level.x, defo + level.offset)
    return jnp.concatenate([p, h0[None]])


def _transfer(coarse: _Level, fine: _Level, u, cubic=False):
    """Coarse-grid solution → fine-grid start. ``cubic`` (traced bool): midpoints by 4-point cubic
    interpolation, clipped at zero, instead of linear. Cubic saves 1-2 fine-grid Newton iterations
    on smooth pressures (the fine LU is the dominant cost); its overshoot next to a sharp pressure
    spike (Barus at L ≳ 15) can make the fine solve fail, so the second cold attempt uses linear."""
    pc = u[: coarse.n]
    p = jnp.interp(fine.x, coarse.x, pc)
    if fine.n == 2 * coarse.n - 1:  # the grid sequence halves Δ: coarse nodes are every other node
        before = jnp.concatenate([pc[:1], pc[:-2]])
        after = jnp.concatenate([pc[2:], pc[-1:]])
        mid = jnp.maximum((9.0 * (pc[:-1] + pc[1:]) - before - after) / 16.0, 0.0)
        p_cubic = jnp.zeros((fine.n,), dtype=pc.dtype).at[::2].set(pc).at[1::2].set(mid)
        p = jnp.where(cubic, p_cubic, p)
    p = p.at[0].set(0.0).at[-1].set(0.0)
    # keep the central film across the transfer (H0 absorbs the O(Δ) change of the discrete kernel)
    hc = jnp.interp(0.0, coarse.x, coarse.film(u))
    return jnp.concatenate([p, _offset_for_central_film(fine, p, hc)[None]])


def _offset_for_central_film(level: _Level, p, hc, window: bool = False):
    """H0 that puts the central film H(0) at ``hc`` for pressure P on ``level``; with ``window``,
    the mean film over the central window (``_central_window``) instead."""
    shape = level.shape(p)
    if window:
        w = _central_window(level.x)
        return hc - jnp.sum(w * (shape + 0.5 * level.x**2)) / jnp.sum(w)
    return hc - jnp.interp(0.0, level.x, shape)


def _central_window(big_x):
    """Nodes with |X| ≤ ½ (at least the one nearest the centre), as 0/1 weights. Over a rough film
    the mean film there is a stable measure of its level: the film at X = 0 moves by the local
    roughness (~0.4 µm rms per cell of travel for the ground surfaces, more than the film)."""
    spacing = big_x[1] - big_x[0]
    return (jnp.abs(big_x) <= jnp.maximum(0.5, 0.5 * spacing)).astype(big_x.dtype)


def _schedules(model: EHLModel, dtype):
    """Continuation schedules of the piezo-viscous exponent s on the coarsest grid, one row per
    cold attempt: four plateaus 1/4, 1/2, 3/4, 1 first (repeated values cost nothing: Newton stops
    at once when converged), then, if that failed, ``continuation_steps`` equal steps. The third
    attempt (smooth and statistical films on fine grids) follows the second schedule up to
    ``_FINE_CONTINUATION_START`` only and finishes the continuation on the finest grid. The last
    (``_DIRECT_ROW``; for a deterministic rough film, its smooth start) has no continuation: s = 1
    from the start.

    Why the last: continuation eases the hard, piezo-viscous contacts, but at light load and high
    speed (thick films, Moes M ≈ 4-7, L ≈ 6.6: the entry and exit of a tooth pair's engagement at
    3500 rpm) the reduced-exponent problems are the hard ones. There, from the Hertz start at
    s = 1/4, Newton lets the film offset run away (H0 → 10³ × the Moes film, ‖F‖∞ ≈ 0.2, no
    solution on that branch) on some domains, while at s = 1 it converges in ~11 iterations on the
    coarsest grid (M = 4.2 on −7 … 1.5 half-widths)."""
    k = model.continuation_steps
    i = np.arange(1, k + 1)
    rows = [np.ceil(4.0 * i / k) / 4.0, i / k, i / k, np.ones(k)]
    return jnp.asarray(np.stack(rows), dtype=dtype)


_DIRECT_ROW = 3  # the schedule row without continuation (see ``_schedules``)


# exponent s at which the third cold attempt reaches the finest grid. Why: in hard piezo-viscous
# contacts on fine grids (Barus, incompressible, M = 200, L = 15, 2049 nodes) the first two
# attempts stall at ‖F‖∞ ≈ 1e-2 next to the one-cell pressure spike at the outlet, while the
# continuation of the last steps of s on the finest grid converges.
_FINE_CONTINUATION_START = 0.75
_FINE_CONTINUATION_NODES = 1025  # grids from this size on get the third attempt


_INTERMEDIATE_TOLERANCE = 1e-6


def _cold_start(model: EHLModel, levels: list[_Level], svals, cubic=False, s_end=1.0):
    """Continuation in the piezo-viscous exponent s (schedule ``svals``) on the coarsest grid, then
    grid sequencing up to the second-finest grid at exponent ``s_end``; returns the fine-grid start
    and the iterations spent."""
    coarse = levels[0]
    u = _hertz_start(coarse)
    if len(levels) == 1:
        # a single grid stops short of s = 1: the fine solve that follows finishes it
        svals = svals * (1.0 - 1.0 / (svals.shape[0] + 1.0))

    def cont(carry, s):
        u, it = carry
        u_new, _, k, _ = _newton(coarse, u, s, model.max_iterations)
        return (u_new, it + k), None

    (u, iters), _ = jax.lax.scan(cont, (u, jnp.asarray(0)), svals)
    if len(levels) == 1:
        return u, iters
    # intermediate grids only supply the next start: their own discretisation error (O(Δ²) ≈ 1e-3)
    # dwarfs any residual below _INTERMEDIATE_TOLERANCE, so iterating further buys nothing
    tol = max(model.tolerance, _INTERMEDIATE_TOLERANCE)
    for prev, lev in zip(levels[:-2], levels[1:-1], strict=False):
        u = _transfer(prev, lev, u, cubic)
        u, _, k, _ = _newton(lev, u, s_end, model.max_iterations, tol)
        iters = iters + k
    return _transfer(levels[-2], levels[-1], u, cubic), iters


def _warm_start(fine: _Level, init_x, init_p, init_h0, window: bool = False):
    """Start from a solution of a nearby contact in Hertz-scaled variables (``_warm_args``): its
    P(X) on this grid, and its central film scaled by the ratio of the two Moes estimates. For the
    neighbouring mesh position this halves the Newton iterations of a start in physical variables
    (whose load and cavitation point are off by the change of b and ph). ``window``: the central
    film is the mean over the central window, as ``_warm_args(sol, window=True)`` gives it (rough
    films: deterministic roughness)."""
    p = jnp.interp(fine.x, init_x, init_p, left=0.0, right=0.0)
    p = p.at[0].set(0.0).at[-1].set(0.0)
    if not window:
        hc = init_h0 * fine.sc.h_ref
        if fine.inp.mean_plane:
            # the ratio scales the central average gap (positive however deep the contact); the
            # film unknown is the mean-plane separation under it
            hc = asperity_mod.separation_of_gap(hc, fine._roughness())
        return jnp.concatenate([p, _offset_for_central_film(fine, p, hc)[None]])
    # rough film whose roughness moved since (a transient step): the previous pressure averaged
    # over 5 cells, so that its asperity spikes, which stand where the roughness was, are spread
    # and the relaxation builds the new ones (more warm starts converge than unaveraged, or
    # averaged over 3 or 7 cells)
    p = jnp.where(init_h0[2] > 0.5, _box_average(p), p)
    # the previous H0 − H_c carried over (dimensionless, so the same for any contact with a
    # Hertz-like pressure); the window-matched offset if the previous solution gave none
    hc = init_h0[0] * fine.sc.h_ref
    excess = init_h0[1] * fine.inp.contact.e_reduced
    matched = _offset_for_central_film(fine, p, hc, True)
    h0 = jnp.where(jnp.isfinite(excess), hc + excess, matched)
    return jnp.concatenate([p, h0[None]])


_RELAX_DISTRIBUTIVE = 0.1  # ω of the distributive changes (wedge-dominated nodes)
_RELAX_JACOBI = 0.5  # ω of the plain Jacobi changes (Poiseuille-dominated nodes)
_RELAX_SWITCH = 0.3  # wedge-dominated: |∂R_i/∂P_i| below this × the film's self-influence term
_RELAX_LOAD_GAIN = 0.02  # film-offset change per sweep, × the load error × the reference film
# relaxed warm attempts of a deterministic film: relaxation_sweeps then Newton, then twice half as
# many sweeps from where Newton stopped and Newton again (the later rounds rescue about a third
# more warm starts than the first alone, and more than the same sweeps without Newton between)
_RELAX_ROUNDS = 3


def _relaxation_sweeps(model: EHLModel) -> int:
    """The relaxation sweeps of a deterministic film's warm start: the model's, or by default 100
    iso-thermal and 50 thermal: over an engagement along the path (257 nodes, ground, 500 and
    3500 rpm) within 3 % of the run time of the cheapest of 25, 50 and 100 sweeps, with the same
    steps converged and the same losses to 0.1 %. 100 sweeps cost about 11 Newton iterations."""
    if model.relaxation_sweeps is not None:
        return model.relaxation_sweeps
    return 50 if model.thermal else 100


def _half_step_start(model: EHLModel, inp: _Inputs, u_start):
    """A start for a transient deterministic step whose relaxed warm starts failed: the half step
    (each surface displaced half as far, Δt/2) solved from ``u_start`` by one relaxation and Newton
    round, its pressure averaged over 5 cells and relaxed on this step's system. Only the start
    changes, not the problem solved: it rescues about half the steps whose relaxed rounds
    failed. Returns (start, Newton iterations)."""
    half = eqx.tree_at(
        lambda i: (i.film_offset, i.inv_time_step),
        inp,
        (0.5 * (inp.film_offset + inp.film_offset_previous), 2.0 * inp.inv_time_step),
    )
    level = _fine_level(model, half)[1]
    u_half = _distributive_relaxation(level, u_start, _relaxation_sweeps(model))
    u_half, _, k, ok = _newton(level, u_half, 1.0, model.warm_iterations)
    fine = _fine_level(model, inp)[1]
    n = fine.n
    start = jnp.concatenate([_box_average(u_half[:n]), u_half[n:]])
    start = _distributive_relaxation(fine, start, _relaxation_sweeps(model))
    return jnp.where(ok, start, u_start), k


def _box_average(p):
    """P averaged over 5 cells (the end nodes kept at zero)."""
    box = jnp.convolve(p, jnp.ones(5, p.dtype) / 5.0, mode="same")
    return box.at[0].set(0.0).at[-1].set(0.0)


def _distributive_relaxation(level: _Level, u, sweeps: int):
    """``sweeps`` damped Jacobi sweeps of the Reynolds equation from ``u`` (distributive where the
    wedge and squeeze terms dominate, plain where the Poiseuille term does; cavitation by
    projection on P ≥ 0, the film offset nudged towards the load balance); returns the last
    iterate (``u`` itself if that is not finite). Not the iterate of smallest ‖F‖∞: that is often
    the unrelaxed start, whose ‖F‖∞ the first sweeps raise, and fewer warm starts converge from it.

    Why: a deterministic rough film's transient step cannot be reached by Newton from the previous
    step's solution (it stalls at a local minimum of the Fischer-Burmeister merit, ‖F‖∞ ≈ 0.1-1,
    while the asperity-pressure spikes move with the roughness), yet a few local relaxation sweeps
    move those spikes and leave a start from which Newton converges in 4-11 iterations. Relaxation
    is the multigrid smoother of C.H. Venner & A.A. Lubrecht, *Multilevel Methods in Lubrication*
    (2000), §5-6: where Poiseuille flow dominates, plain Jacobi with the film's self-influence in
    the diagonal; where the wedge term does (the film nearly closed: asperity contact, or a
    pressurised film), Gauss-Seidel or Jacobi on P is unstable (the discrete operator there is the
    derivative of the deformation integral, whose downstream coefficient outweighs the diagonal),
    so each change δ_i is distributed as δ_i at node i and −δ_i/2 at its neighbours, whose
    deformation is local. Only the smoother is used (no coarse grids): Newton takes the smooth
    part of the error."""
    n = level.n
    # d(k): dimensionless film change at node j + k per unit P at node j (Toeplitz)
    infl = {k: level.kernel_near[k + _KRYLOV_BLOCK + 2] for k in range(-3, 4)}
    spread = {k: infl[k] - 0.5 * infl[k + 1] - 0.5 * infl[k - 1] for k in _BAND}

    def scaled_reynolds(p, h):
        r, diag = level.reynolds(p, h, 1.0)
        return r / (1.0 + diag)

    cap = None if level.model.hardness is None else level.model.hardness / level.sc.ph

    def sweep(u):
        p = level.plastic(u[:n])[0]
        excess = u[:n] - p  # v − P: the plastic gap in the unknowns' units
        r, dps, dhs = _bands(scaled_reynolds, p, level.film(u))
        dp, dh = dict(zip(_BAND, dps, strict=True)), dict(zip(_BAND, dhs, strict=True))
        film_self = sum(dh[k] * infl[k] for k in _BAND)
        plain = dp[0] + film_self
        distributed = dp[0] - 0.5 * (dp[-1] + dp[1]) + sum(dh[k] * spread[k] for k in _BAND)
        dist = jnp.abs(dp[0]) < _RELAX_SWITCH * jnp.abs(film_self)
        coef = jnp.where(dist, distributed, plain)
        factor = jnp.where(dist, _RELAX_DISTRIBUTIVE, _RELAX_JACOBI)
        delta = -factor * r / jnp.where(coef != 0.0, coef, 1.0)
        delta = jnp.where(jnp.isfinite(delta), delta, 0.0).at[0].set(0.0).at[-1].set(0.0)
        shared = jnp.where(dist, delta, 0.0)
        change = delta - 0.5 * (jnp.roll(shared, 1) + jnp.roll(shared, -1))
        p_new = jnp.maximum(p + change, 0.0).at[0].set(0.0).at[-1].set(0.0)
        if cap is not None:
            p_new = jnp.minimum(p_new, cap)
        h0 = u[n] + _RELAX_LOAD_GAIN * level.load_row(p_new) * level.sc.h_ref
        if cap is not None:  # back to the unknowns v: the plastic gap kept where P stays at P_cap
            p_new = p_new + jnp.where(p_new >= cap, excess, 0.0)
        return jnp.concatenate([p_new, h0[None]])

    end = jax.lax.fori_loop(0, sweeps, lambda _, v: sweep(v), u)
    return jnp.where(jnp.all(jnp.isfinite(end)), end, u)


def _warm_args(sol: EHLSolution, window: bool = False, moved: bool = False, plastic: bool = True):
    """(X, P, H_c/H_Moes) of a solution: what ``_warm_start`` reads. Guarded so that a failed or
    placeholder solution gives a harmless start (the cold fallback follows if it does not
    converge). ``window`` (deterministic roughness): H_c is the mean film over the central window,
    and the third item is [H_c/H_Moes, (H0 − H_c)/E', moved], ``moved`` telling that the roughness
    has moved since ``sol`` (a transient step: the start is filtered and relaxed). ``plastic``:
    the start carries ``sol``'s plastic gap (False where the surfaces carry it instead: a run-in
    passage)."""
    b = jnp.where(sol.hertz_half_width > 0.0, sol.hertz_half_width, 1.0)
    ph = jnp.where(sol.hertz_pressure > 0.0, sol.hertz_pressure, 1.0)
    # the central film that carries the flow: the average gap of a statistical film (its
    # mean-plane separation, the film unknown, may be near zero or negative in deep contact,
    # where no ratio of film estimates carries it to a nearby contact); the film of the others
    hc = jnp.interp(0.0, sol.x, sol.gap)
    if window:
        w = _central_window(sol.x / b)
        hc = jnp.sum(w * sol.h) / jnp.sum(w)
    ratio = hc / jnp.where(sol.moes_film > 0.0, sol.moes_film, jnp.inf)
    ratio = jnp.where(jnp.isfinite(ratio) & (ratio > 0.0), jnp.clip(ratio, 0.05, 20.0), 1.0)
    # the total pressure: the pressure unknown of every film (a statistical film's fluid and
    # asperity pressures together; the others carry no asperity pressure)
    p = jnp.where(jnp.isfinite(sol.p), sol.p, 0.0) / ph
    # a yielded film (``EHLModel.hardness``): the unknowns v = P + δ/(c H_ref) above the limit, so
    # that the start keeps its plastic gap (zero for elastic films)
    film_scale = _PLASTIC_GAP_SCALE * jnp.where(sol.moes_film > 0.0, sol.moes_film, jnp.inf)
    if plastic:
        gap = jnp.where(jnp.isfinite(sol.plastic_gap), sol.plastic_gap, 0.0)
        p = p + gap / film_scale
    if not window:
        return sol.x / b, p, ratio
    # and (H0 − H_c)/E' in Hertz-scaled film units, b²/R = 4 b ph/E' (Hertz line contact): the
    # next contact multiplies by its E'. NaN (unused) for a failed or placeholder solution
    excess = (sol.h0 - hc) / (4.0 * b * ph)
    good = sol.converged & jnp.isfinite(excess)
    flag = jnp.asarray(1.0 if moved else 0.0, dtype=ratio.dtype)
    return sol.x / b, p, jnp.stack([ratio, jnp.where(good, excess, jnp.nan), flag])
