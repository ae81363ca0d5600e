"""The outer iterations of a solve (``_solve_impl``): the film's temperatures from its heat
(Picard, the update relaxed by Aitken's rule), each re-solve warm-started, until they agree with
those the film was solved with."""

from __future__ import annotations

import dataclasses

import equinox as eqx
import jax
import jax.numpy as jnp

from .. import thermal as thermal_mod
from .core import (
    SKIP_HOT,
    SKIP_NONE,
    SKIP_WARM,
    _postprocess,
    _solution_structure,
    _solve_core,
)
from .model import EHLModel, _Inputs
from .solution import EHLSolution
from .starts import _warm_args


def _temperatures(inp: _Inputs, sol: EHLSolution, solids, transient=None):
    """Film and surface temperature rises of a solution's heat source (REFERENCE §5).

    ``transient``: None (steady Jaeger surfaces, quasi-steady film) or (response, film_previous,
    dt): the surfaces' diagonal responses ((offset1, gain1), (offset2, gain2)) of one transient step
    (paper Eq. 9 with memory) and the film's mean temperature rise at the previous step."""
    lub, c = inp.lubricant, inp.contact
    response, film_previous, dt = (None, None, None) if transient is None else transient
    return thermal_mod.solve_contact_temperatures(
        sol.x,
        sol.heat_flux,
        jnp.maximum(sol.gap, 0.0),
        c.u1,
        c.u2,
        solids[0],
        solids[1],
        sol.density,
        lub.specific_heat,
        lub.thermal_conductivity,
        convection=True,
        surface_response=response,
        inlet_temperature=0.0,
        previous_film_mean=film_previous,
        dt=dt,
    )


def _with_temperatures(sol: EHLSolution, temps, inlet, thermal_residual) -> EHLSolution:
    return eqx.tree_at(
        lambda s: (
            s.surface_temperature1,
            s.surface_temperature2,
            s.heat_partition,
            s.thermal_residual,
        ),
        sol,
        (inlet + temps.surface1, inlet + temps.surface2, temps.partition, thermal_residual),
    )


def _solve_impl(model, warm, mixed, inp, init_x, init_p, init_h0, solids, transient=None):
    """One solve (steady or one transient step); thermal when ``model.thermal``.

    Returns (solution, temperatures or None)."""
    n_outer = _thermal_iterations(model, mixed)
    max_step = _DETERMINISTIC_TEMPERATURE_STEP if mixed == "deterministic" else None
    # a deterministic film's re-solves know the temperatures their start was solved at
    hot = model.thermal and mixed == "deterministic" and model.temperature_steps > 0
    if not model.thermal:
        none = jnp.asarray(SKIP_NONE, init_h0.dtype)
        u, res, it, ok = _solve_core(model, warm, mixed, inp, init_x, init_p, init_h0, none)
        return _postprocess(model, mixed, inp, u, res, it, ok), None
    if hot:
        inp = dataclasses.replace(inp, temperature_rise_previous=inp.temperature_rise)

    def thermal_settled(change, rise):
        # the film temperature moved by < thermal_rtol of its largest rise (or < thermal_atol K)
        return change <= jnp.maximum(
            model.thermal_rtol * jnp.max(jnp.abs(rise)), model.thermal_atol
        )

    def updates(sol, inp_k, solids, transient, relax):
        """The inputs the solution ``sol`` implies (its temperatures, relaxed), whether they
        agree with those it was solved with (then the outer iteration has converged), and the
        temperature relaxation's new state (``_aitken``)."""
        temps = _temperatures(inp_k, sol, solids, transient)
        rise = _safe_rise(temps.film_mean)
        change = jnp.max(jnp.abs(rise - inp_k.temperature_rise))
        settled = thermal_settled(change, rise)
        relaxed, relax = _aitken(inp_k.temperature_rise, rise, relax, max_step)
        inp_next = eqx.tree_at(lambda i: i.temperature_rise, inp_k, relaxed)
        if hot:
            previous = inp_k.temperature_rise
            inp_next = eqx.tree_at(lambda i: i.temperature_rise_previous, inp_next, previous)
        return inp_next, settled, relax

    zero = jnp.zeros_like(inp.temperature_rise)
    relax0 = (jnp.ones((), zero.dtype), zero, jnp.asarray(False))
    sol, inp_last = _solve_and_update(
        model, mixed, inp, (init_x, init_p, init_h0), relax0, n_outer, updates, solids, transient,
        cold=not warm, hot=hot,
    )  # fmt: skip
    temps = _finite_temperatures(_temperatures(inp_last, sol, solids, transient))
    change = jnp.max(jnp.abs(temps.film_mean - inp_last.temperature_rise))
    change = jnp.where(jnp.isfinite(change), change, jnp.finfo(change.dtype).max)
    thermal_ok = thermal_settled(change, temps.film_mean)
    sol = eqx.tree_at(lambda s: s.converged, sol, sol.converged & thermal_ok)
    return _with_temperatures(sol, temps, inp.contact.inlet_temperature, change), temps


def _solve_and_update(
    model, mixed, inp, args, relax, n_outer, updates, solids, transient, cold, hot
):
    """The outer (Picard) iteration of a thermal solve, its first solve its first step:
    ``n_outer`` + 1 steps of (the temperatures the last solution implies, none before the first;
    Reynolds at them, Newton warm started from that solution), ending once they agree with those
    it was solved with, so the Newton solve appears once in the program. The remaining steps are
    skipped by lax.cond: no work when solved one contact at a time; a scan, not a while loop, so
    that reverse-mode differentiation works. Under vmap the skipped steps still run; the vmap-lazy
    ``cond_any_member`` is slower here (30-40 % on a parallel thermal transient mixed sweep), so
    it is kept to the solver's fallback attempts, where it pays.

    ``cold``: the first solve is a cold one, the warm solve with its warm attempts skipped
    (``args``, the cold solve's placeholders, are then replaced by a warm start's, never read).
    ``hot``: a deterministic film's re-solves continue in the temperatures from the last solve's
    (``inp.temperature_rise_previous``); its first solve does not. Returns (the last solution, the
    inputs it was solved with).

    The temperatures are updated at the start of a step, outside the branch that solves: with the
    update after the solve in the same branch, XLA's optimised CPU code evaluated the temperatures
    of a 257-node statistical film differently inside the loop than after it (film mean rises 0.4 %
    apart on identical inputs, equal with ``--xla_backend_optimization_level=0``), and the
    iteration settled on the wrong temperatures."""
    det = mixed == "deterministic"

    first_skip = SKIP_WARM if cold else (SKIP_HOT if hot else SKIP_NONE)

    def solve(sol_prev, inp_k, args_k, first):
        skip = jnp.where(first, first_skip, SKIP_NONE).astype(inp_k.temperature_rise.dtype)
        u, res, it, ok = _solve_core(model, True, mixed, inp_k, *args_k, skip)
        new = _postprocess(model, mixed, inp_k, u, res, it, ok)
        new = eqx.tree_at(lambda s: s.iterations, new, new.iterations + sol_prev.iterations)
        # a deterministic film whose re-solve failed (every attempt) ends the iteration, reported
        # not converged: the temperatures of a film that is not a Reynolds solution lead nowhere,
        # and each further re-solve runs every cold attempt (~500 Newton iterations each): a
        # thermal engagement along the path costs 15-30 % less than going on to the last update,
        # with about as many steps converged. A failed first solve still gets its updates: new
        # temperatures can make it solvable. Not two failed solves in a row as the stop: that
        # cascades (the failed step's successor restarts steady, and its restarts can fail in
        # turn).
        stop = (~new.converged & ~first) if det else jnp.asarray(False)
        return new, stop

    def begin(op):  # the first step: the caller's inputs and start
        _, inp_k, relax = op
        return inp_k, jnp.asarray(False), relax, args

    def update(op):
        sol, inp_k, relax = op
        inp_next, settled, relax_next = updates(sol, inp_k, solids, transient, relax)
        return inp_next, settled, relax_next, _warm_args(sol, det)

    def step(op):
        sol, inp_k, relax, first = op
        # ``first`` is the same for every member of a vmapped batch: a cond, never a select, so the
        # placeholder's update is never evaluated
        inp_next, settled, relax_next, args_k = jax.lax.cond(
            first, begin, update, (sol, inp_k, relax)
        )

        def stay(op):  # ``sol`` is the answer for the inputs it was solved with: keep both
            return op[0], op[1], jnp.asarray(True), relax

        def resolve(op):
            new, stop = solve(op[0], inp_next, args_k, first)
            return new, inp_next, stop, relax_next

        return jax.lax.cond(settled, stay, resolve, (sol, inp_k))

    def picard(carry, _):
        sol, inp_k, done, relax, first = carry
        out = jax.lax.cond(
            done,
            lambda op: (op[0], op[1], jnp.asarray(True), op[2]),
            step,
            (sol, inp_k, relax, first),
        )
        return (*out, jnp.asarray(False)), None

    first = jnp.asarray(True)
    # what the first step replaces: a solution of the right structure, never read but for its
    # iteration count (0)
    shape = _solution_structure(model, mixed, inp)
    placeholder = jax.tree_util.tree_map(lambda a: jnp.zeros(a.shape, a.dtype), shape)
    if cold:  # a warm start of the right structure (guarded: finite), never read
        args = _warm_args(placeholder, det)
    init = (placeholder, inp, jnp.asarray(False), relax, first)
    (sol, inp_solved, *_), _ = jax.lax.scan(picard, init, None, length=n_outer + 1)
    return sol, inp_solved


def _thermal_iterations(model: EHLModel, mixed: str) -> int:
    """Outer temperature updates: the model's, or by default 4 (smooth and statistical films settle
    in 1-3) and 32 for deterministic roughness (at full ground roughness, speed E: 23 updates on
    513 nodes, see ``_DETERMINISTIC_TEMPERATURE_STEP``). Updates after the temperatures settle are
    skipped (no cost, outside vmap)."""
    if model.thermal_iterations is not None:
        return model.thermal_iterations
    return 32 if mixed == "deterministic" else 4


_AITKEN_MIN = 0.05  # smallest relaxation factor of the temperature update

# K: the most a node's film temperature may move in one update of a deterministic rough film. Its
# first update comes from the iso-thermal film's heat, whose Poiseuille part is far larger than
# the hot film's: at speed E (ground, 700 N m) it asked for a film 1292 K hot on 513 nodes, the
# Reynolds solves at the 400-900 K films that followed failed, and after 16 updates the solve was
# reported as not converged. Limited to 200 K a step it settles in 23 updates to a film up to 348 K
# hot; on 257 nodes the same solutions (losses within the thermal tolerance) come out with 30-70 %
# fewer Newton iterations than unlimited; 100 K does not settle in 16 updates on 513 nodes. Smooth
# and statistical films keep the unlimited update (their first rises are tens of K).
_DETERMINISTIC_TEMPERATURE_STEP = 200.0


def _aitken(x, g, state, max_step=None):
    """One relaxed fixed-point update x ← x + ω (g − x) of the film temperature rise, with ω by
    Aitken's Δ² rule for vectors (Irons-Tuck; Küttler & Wall, Comput. Mech. 43, 2008):
    ω_k = −ω_{k−1} r_{k−1}·(r_k − r_{k−1}) / |r_k − r_{k−1}|², r = g − x, clipped to
    [``_AITKEN_MIN``, 1] and 1 at the first update. A contracting, monotone iteration keeps ω = 1
    (unrelaxed: the smooth and statistical films' usual 2-3 updates); one that oscillates gets
    ω < 1. Why: with the deterministic roughness at full ground amplitude the unrelaxed update
    swings between films 150 and 740 K hot (its Poiseuille heat falls as the viscosity does), and
    never settles (at speed E, 257 nodes: the update still moves it by 250 K after 16).

    ``max_step`` (K, optional): ω is further limited so that no node's temperature moves by more
    than this in one update (a trust region; the limited ω is the one the next Δ² step reads).

    ``state`` = (ω_{k−1}, r_{k−1}, whether there is a previous update); returns the new x and
    state."""
    omega_prev, r_prev, have = state
    r = g - x
    dr = r - r_prev
    denom = jnp.sum(dr * dr)
    safe = jnp.where(denom > 0.0, denom, 1.0)
    omega = -omega_prev * jnp.sum(r_prev * dr) / safe
    omega = jnp.where(have & (denom > 0.0) & jnp.isfinite(omega), omega, 1.0)
    # the fixed point does not depend on ω: no derivative flows through it
    omega = jnp.clip(omega, _AITKEN_MIN, 1.0)
    if max_step is not None:
        largest = jnp.max(jnp.abs(r))
        omega = jnp.minimum(omega, max_step / jnp.maximum(largest, 1e-300))
    omega = jax.lax.stop_gradient(omega)
    return x + omega * r, (omega, r, jnp.asarray(True))


# K: a temperature rise outside [_MIN_RISE, _MAX_RISE] only comes from a failed solve (converged
# films: ≤ 440 K above the inlet at their hottest node, the 1025-node thermal deterministic film; the
# heat only flows into the film, so a rise below 0 is numerical undershoot). The bounds keep the
# film within 150-1600 K for every valid inlet (200-600 K), where the lubricant models stay finite:
# the linear thermal expansion's density reaches 0 near 1700 K (Mil-L-23699), and a bound of 1500 K
# lets a failed 1025-node passage step report NaN viscosities and losses
_MAX_RISE = 1000.0
_MIN_RISE = -50.0


def _safe_rise(t):
    """Temperatures of a failed solve are kept finite and bounded (the failure is reported by
    ``converged``), so that the next Picard step and the outputs never carry NaN."""
    return jnp.where(jnp.isfinite(t), jnp.clip(t, _MIN_RISE, _MAX_RISE), 0.0)


def _finite_temperatures(temps):
    """The temperature rises bounded by ``_safe_rise``; the heat fluxes (W/m², ~1e8-1e9 in a gear
    contact: never clipped to the temperature bound) only made finite."""
    rise = ("surface1", "surface2", "film_mean")
    finite = lambda a, fill: jnp.where(jnp.isfinite(a), a, fill)
    return eqx.tree_at(
        lambda t: (t.surface1, t.surface2, t.film_mean, t.flux1, t.flux2, t.convected, t.partition),
        temps,
        tuple(_safe_rise(getattr(temps, f)) for f in rise)
        + tuple(finite(getattr(temps, f), 0.0) for f in ("flux1", "flux2", "convected"))
        + (finite(temps.partition, 0.5),),
    )
