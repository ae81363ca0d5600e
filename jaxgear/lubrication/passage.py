"""Transient passage of one contact through a sequence of states (paper Eqs. 4-9).

A tooth pair's contact changes along the path of contact: load, radius of curvature and surface
velocities follow the mesh position, and each surface's roughness moves with its own velocity. The
passage marches the EHL problem through a given sequence of contact states with ``lax.scan``:

- Reynolds with the squeeze term ∂(ρh)/∂t by backward Euler or BDF2 (``EHLModel.time_scheme``),
  ρh of the previous steps interpolated onto this step's nodes (the grid follows the Hertz
  half-width), or, along the characteristics (``EHLModel.transport = "characteristic"``), the
  wedge and squeeze terms together as D(ρh)/Dt, the previous films read where the mean velocity
  carried them from (their roughness evaluated from the profiles there);
- roughness Sj(x, t) = scale · zj(x − xj0 − dj(t)), dj = ∫ uj dt by the trapezoidal rule;
- thermal (``model.thermal``): the surface temperatures by the transient moving-heat-source model
  with memory (paper Eq. 9; :class:`~jaxgear.lubrication.thermal.SubsurfaceTemperature`, carried
  from step to step with each solid), the film temperature with its time derivative ∂ϕm/∂t; both
  by the passage's time scheme (under BDF2 the solids' earlier fields read at their material
  points' feet by cubic interpolation, ``_advect_cubic``), the film's earlier temperatures read at
  this step's nodes and extrapolated past the earlier grid's ends (``_film_rise_at``);
- a warm start from the previous step.

The time step is the caller's choice. Tied to the grid, Δt = Δx/ur moves the roughness about one
cell per step (EHL_NOTES "Transient"); :func:`grid_time_step` gives it. Backward Euler is first
order in Δt: halving Δt halves the time-discretisation error; BDF2 is second order (both tested).
A roughness whose shortest wavelength spans a few cells passes a node in a few such steps, so with
the Eulerian terms a rough film's friction needs Δt below Δx/ur; along the characteristics it
does not, up to a few Δx/ur (studies/time_steps).
"""

from __future__ import annotations

import dataclasses

import equinox as eqx
import jax
import jax.numpy as jnp

from .._inputs import canonical
from .._validation import is_concrete
from ..material import steel
from . import thermal as thermal_mod
from .ehl import EHLModel, EHLSolution, LineContact, transport_shift
from .ehl.discretisation import _film_at_feet, _grid_positions, _roughness_offset
from .ehl.model import _Inputs, _split_numbers
from .ehl.outer import _solve_impl
from .ehl.starts import _warm_args
from .lubricant import Lubricant
from .roughness import Surfaces


def grid_time_step(contact: LineContact, lubricant: Lubricant, model: EHLModel):
    """Δt = Δx/ur, s: the step that moves the roughness one grid cell at the rolling velocity.

    It ties the step to the grid but does not resolve a roughness of a few cells' wavelength in
    time: a deterministic rough film's friction wants a fraction of it, by BDF2
    (``EHLModel(time_scheme="bdf2")``; studies/time_steps: Δt/2 within 6 % of the
    Δt → 0 loss on the polished film at 2049 nodes, backward Euler at Δt 36 % above)."""
    x = _grid_positions(model, contact, lubricant)
    return (x[1] - x[0]) / contact.rolling_velocity


def _advect_to(temperature, x_old, feet, cubic=False, entering=True):
    """An earlier (n, nz) field on x_old at ``feet`` (m; a solid's material points' feet, or the
    film's nodes): linear or cubic (``_advect_cubic``) interpolation; past the last node
    extrapolated from the end nodes up to one cell and held beyond; before the first node 0
    where material ``entering`` there comes at the bulk temperature (the solids), else
    extrapolated in the same way (the film, ``_film_rise_at``).

    Why past the outlet: the grid follows the Hertz width, so where the load rises fast its outlet
    moves further in a step than the material does, and material that stood past the earlier
    grid's outlet enters this one. Read as 0 (the bulk temperature), it would leave a cold dip in
    the solids behind the outlet (after a load doubled in one step, surfaces near the bulk
    temperature at the nodes past the old outlet, where the outlet stood about 2 K above it), and
    the dip would travel out over the next steps. That material left the contact at about the
    outlet's temperature, and keeps it over a step: it cools by conduction into the depth over
    many."""
    dx = x_old[1] - x_old[0]
    at = jnp.clip(feet, x_old[0] - dx, x_old[-1] + dx)
    if cubic:
        values = _advect_cubic(temperature, x_old, at, extend=1)
    else:
        inside = jax.vmap(lambda col: jnp.interp(at, x_old, col), in_axes=1, out_axes=1)(
            temperature
        )
        before = temperature[0] + (at - x_old[0])[:, None] * (temperature[1] - temperature[0]) / dx
        after = (
            temperature[-1] + (at - x_old[-1])[:, None] * (temperature[-1] - temperature[-2]) / dx
        )
        values = jnp.where(
            (at < x_old[0])[:, None], before, jnp.where((at > x_old[-1])[:, None], after, inside)
        )
    if entering:
        values = jnp.where((feet < x_old[0])[:, None], 0.0, values)
    return values


def _advect_cubic(temperature, x_old, feet, extend=0):
    """T at ``feet`` (m) from the (n, nz) field on the uniform grid x_old: cubic Lagrange
    interpolation on the four nodes around each foot, the stencil shifted inwards in the end
    cells (O(Δx⁴) up to the ends), and extrapolating up to ``extend`` cells past either end; 0
    further out (material entering at the bulk temperature)."""
    n = x_old.shape[0]
    dx = x_old[1] - x_old[0]
    s = (feet - x_old[0]) / dx
    base = jnp.clip(jnp.floor(s).astype(jnp.int32) - 1, 0, n - 4)
    t = (s - base)[:, None]  # in [0, 3] inside the grid; the stencil's nodes at 0, 1, 2, 3
    weights = (
        -(t - 1.0) * (t - 2.0) * (t - 3.0) / 6.0,
        t * (t - 2.0) * (t - 3.0) / 2.0,
        -t * (t - 1.0) * (t - 3.0) / 2.0,
        t * (t - 1.0) * (t - 2.0) / 6.0,
    )
    out = sum(w * temperature[base + j] for j, w in enumerate(weights))
    inside = (feet >= x_old[0] - extend * dx) & (feet <= x_old[-1] + extend * dx)
    return jnp.where(inside[:, None], out, 0.0)


def _film_rise_at(x, x_old, rise_old, cubic):
    """An earlier step's film temperature rise (K, on its nodes ``x_old``) at this step's nodes
    ``x``, for the film's ∂ϕm/∂t: linear (backward Euler) or cubic (BDF2) interpolation, and past
    the end nodes extrapolated from them, up to one cell (held beyond).

    Why past the ends: the grid follows the Hertz width, so under a rising load its end nodes lie
    past the previous step's. Read as 0 there (the inlet temperature), the outlet node's ∂ϕm/∂t
    would pull its film towards the inlet temperature (under a rising load, a rise of 0.12 K
    where the node two cells upstream has 2.8 K), the film's largest error, converging in Δt at
    order 0.7 only. The film leaves through the outlet, so what stood just past it continues what
    stood at it; at the inlet the rise is small either way."""
    return _advect_to(rise_old[:, None], x_old, x, cubic, entering=False)[:, 0]


def _temperature_start(mixed, prev, x, inlet, shift):
    """The film temperature rise (K, on this step's nodes ``x``) a step's temperature iteration
    starts from: the previous step's solution ``prev``, and, with deterministic roughness, moved
    downstream by ``shift`` = ur Δt (the inlet at 0); read past the previous grid's outlet as the
    film's ∂ϕm/∂t reads it (``_advect_to``). The start decides only where the updates stop within
    their tolerance, not the temperature iteration's fixed point.

    Why the shift: a deterministic rough film's hot spots stand at its asperity contacts and thin
    films, which move with the surfaces, about one cell a step (Δt = Δx/ur); left where they were,
    the temperature updates have to move them, at the nodes they left and reached. The shifted
    start saves 5-7 % of the Newton iterations of a thermal engagement along the path (257 nodes,
    ground), with the same steps converged. Smooth and statistical films, whose temperatures vary
    over the Hertz width, keep the unshifted start."""
    rise = (prev.temperature - inlet)[:, None]
    if mixed != "deterministic":
        return _advect_to(rise, prev.x, x, entering=False)[:, 0]
    return _advect_to(rise, prev.x, x - shift)[:, 0]


def _squeeze_history(model, rho_h_prev, inv_dt, older, usable, dt, read_older):
    """The squeeze term's (1/Δt, ρh_prev) for ``model.time_scheme``.

    Backward Euler: ∂(ρh)/∂t ≈ (ρh − ρhⁿ)/Δt. BDF2 with variable steps (ω = Δt/Δt_prev):
    ∂(ρh)/∂t ≈ [a0 ρh − (1 + ω) ρhⁿ + ω²/(1 + ω) ρhⁿ⁻¹]/Δt, a0 = (1 + 2ω)/(1 + ω); the term is
    linear in ρh, so it is one backward-Euler-shaped term with 1/Δt × a0 and the reference
    [(1 + ω) ρhⁿ − ω²/(1 + ω) ρhⁿ⁻¹]/a0 (the residual is unchanged). ``older`` carries step
    n − 1 (its ``[-1]`` Δt_prev), ``read_older(older)`` its ρh where this step reads it; where
    it is not ``usable`` (the first transient step, or after a failed step) the step is backward
    Euler."""
    if model.time_scheme != "bdf2":
        return inv_dt, rho_h_prev
    a0, blend = _bdf2(older, usable, dt)
    return inv_dt * a0, blend(rho_h_prev, read_older(older))


def _bdf2(older, usable, dt):
    """BDF2 with variable steps as a backward-Euler-shaped term: (a0, blend), with
    ∂y/∂t ≈ a0 [y − blend(yⁿ, yⁿ⁻¹)]/Δt (``_squeeze_history``); backward Euler where not
    ``usable``."""
    w = dt / jnp.maximum(older[-1], 1e-300)
    a0 = jnp.where(usable, (1.0 + 2.0 * w) / (1.0 + w), 1.0)

    def blend(y_prev, y_old):
        blended = ((1.0 + w) * y_prev - w * w / (1.0 + w) * y_old) / a0
        return jnp.where(usable, blended, y_prev)

    return a0, blend


def _runs_in(model: EHLModel, mixed: str) -> bool:
    """Whether a passage carries its surfaces' plastic flattening from step to step
    (``_run_in``): deterministic roughness under a pressure limit."""
    return model.hardness is not None and mixed == "deterministic"


def _step(model, numbers, mixed, lubricant, surfaces, solids, depth, carry, contact, t, first):
    prev, temp1, temp2, d, t_prev, u_prev, older, older_ok, worn = carry
    # under a pressure limit the surfaces carried from the previous steps (run in), else the given
    surfaces = surfaces if worn is None else worn
    bdf2 = model.time_scheme == "bdf2"
    dt = jnp.maximum(t - t_prev, 1e-300)
    u_now = jnp.stack([contact.u1, contact.u2])
    d_prev = d
    # the film's transport in this step along the characteristics (0 for the Eulerian term)
    shift = transport_shift(model, 0.25 * jnp.sum(u_prev + u_now) * (t - t_prev))
    if not first:
        # the first state is at ``times[0]``, where the surfaces stand at the given displacement
        # (the carry's t_prev = times[0] − Δt0 only gives the first step a Δt to read)
        d = d + 0.5 * (u_prev + u_now) * (t - t_prev)
    x = _grid_positions(model, contact, lubricant)
    dx = x[1] - x[0]
    inlet = contact.inlet_temperature
    if first:
        rho_h_prev = jnp.zeros_like(x)
        inv_dt = jnp.zeros(())
        rise = jnp.zeros_like(x)
    else:
        # A failed previous step (reported by its ``converged``) carries no usable film: this step
        # restarts as a steady solve (no squeeze, film at the inlet temperature) instead of
        # inheriting its state, so one failure (e.g. a near-zero load where the teeth separate)
        # does not fail every later step.
        prev_ok = prev.converged & jnp.all(jnp.isfinite(prev.rho_h))
        prev_ok = prev_ok & jnp.all(jnp.isfinite(prev.temperature))
        # along the characteristics (``EHLModel.transport``) the previous films are read where
        # the mean velocity carried them from: x − ∫ ur dt
        radius = contact.reduced_radius
        rho_h_prev = _film_at_feet(
            model, mixed, surfaces, x, shift, prev.x, prev.rho_h, prev.density, d_prev, radius
        )
        rho_h_prev = jnp.where(prev_ok, rho_h_prev, 0.0)
        inv_dt = jnp.where(prev_ok, 1.0 / dt, 0.0)

        def read_older(older):
            # step n − 1, carried along the characteristics over that step and this one (its
            # roughness as the surfaces stood after it: the film it solved, flattening included)
            x_old, rho_h_old, rho_old, d_old, shift_old = older[:5]
            return _film_at_feet(
                model,
                mixed,
                surfaces if older[9] is None else older[9],
                x,
                shift + shift_old,
                x_old,
                rho_h_old,
                rho_old,
                d_old,
                radius,
            )

        inv_dt, rho_h_prev = _squeeze_history(
            model, rho_h_prev, inv_dt, older, prev_ok & older_ok, dt, read_older
        )
        rise = _film_rise_at(x, prev.x, prev.temperature - inlet, cubic=bdf2)
        rise = jnp.where(prev_ok, rise, 0.0)
        start = _temperature_start(mixed, prev, x, inlet, contact.rolling_velocity * dt)
        start = jnp.where(prev_ok, start, 0.0)
    sigma = jnp.zeros(()) if surfaces is None else surfaces.composite_rq
    inp = _Inputs(
        contact,
        lubricant,
        rho_h_prev,
        inv_dt,
        _roughness_offset(mixed, surfaces, x, d),
        # the temperature iteration starts here (the film's ∂ϕm/∂t term reads ``rise``: the
        # previous temperature where it stood)
        rise if first else start,
        sigma,
        numbers,
        # where the roughness stood at the previous step: a deterministic step's start generator
        _roughness_offset(mixed, surfaces, x, d_prev) if mixed == "deterministic" else None,
        mean_plane=mixed == "statistical",
    )
    transient = None
    # how far each surface's material moved in this step: by the trapezoidal rule under BDF2
    # (second order along a path whose velocities change), by the step's end velocity otherwise
    solid_shift = (0.5 * (u_prev + u_now) if bdf2 else u_now) * dt
    if model.thermal:
        # the solids' backward-Euler-shaped step: BDF2 is the same depth system with Δt/a0 from
        # the blended start (``_bdf2``), its two previous levels read at their material points'
        # feet by cubic interpolation. Why cubic: with linear interpolation the error depends on
        # the fraction of a cell a step moves the material more than on Δt, and BDF2 loses its
        # second order in Δt. Backward Euler keeps the linear reads.
        a0, blend = (1.0, None) if first or not bdf2 else _bdf2(older, prev_ok & older_ok, dt)
        frees = []
        for k, temp in enumerate((temp1, temp2)):
            if bdf2 and not first:
                start_temp = blend(
                    _advect_to(temp, prev.x, x - solid_shift[k], cubic=True),
                    _advect_to(
                        older[6 + k], older[0], x - solid_shift[k] - older[8][k], cubic=True
                    ),
                )
            else:
                start_temp = _advect_to(temp, prev.x, x - solid_shift[k])
            state = thermal_mod.SubsurfaceTemperature(temperature=start_temp, depth=depth)
            frees.append(thermal_mod.transient_predict(state, dx, 0.0, dt / a0, solids[k]))
        response = tuple((f[:, 0], jnp.full_like(x, g[0])) for f, g in frees)
        film_rise, film_dt = rise, dt
        if bdf2 and not first:
            # the film's ∂ϕm/∂t by BDF2 as well (step n − 1's rise read where the previous is)
            rise_old = _film_rise_at(x, older[0], older[5] - inlet, cubic=True)
            film_rise, film_dt = blend(rise, rise_old), dt / a0
        transient = (response, None if first else film_rise, None if first else film_dt)
    if first:
        sol, temps = _solve_impl(
            model, False, mixed, inp, x[:2], x[:2], jnp.zeros(()), solids, transient
        )
    else:
        # run-in surfaces carry the previous plastic gap in their heights, so the start does not
        args = _warm_args(
            prev, mixed == "deterministic", moved=True, plastic=not _runs_in(model, mixed)
        )
        sol, temps = _solve_impl(model, True, mixed, inp, *args, solids, transient)
    # step n − 1 as BDF2's older level for the next step: usable if it was a solution (not the
    # first step's placeholder) that converged
    older = (
        prev.x,
        prev.rho_h,
        prev.density,
        d_prev,
        shift,
        prev.temperature,
        temp1,
        temp2,
        solid_shift,
        worn,
        dt,
    )
    if model.thermal:
        temp1 = thermal_mod.transient_update(
            frees[0][0], frees[0][1], temps.flux1, depth
        ).temperature
        temp2 = thermal_mod.transient_update(
            frees[1][0], frees[1][1], temps.flux2, depth
        ).temperature
    older_ok = jnp.asarray(False) if first else prev_ok
    if worn is not None:
        worn = _run_in(surfaces, sol, d)
    return (sol, temp1, temp2, d, t, u_now, older, older_ok, worn), sol


def _run_in(surfaces: Surfaces, sol: EHLSolution, d) -> Surfaces:
    """The surfaces after a step whose contact yielded (``EHLModel.hardness``): each profile
    lowered by half the step's plastic gap δ (both surfaces equally hard) at the material points
    that stood at the film's nodes, its surface displaced by d_j. The flattening is plastic, so
    it stays, and it travels with the surface that yielded; the next step's δ is only what more
    yields. A failed step flattens nothing.

    Why: without it each step starts from the original roughness, and an asperity that yielded
    springs back one step later, an elastic-perfectly plastic solid recovering what it cannot."""
    gap = jnp.where(sol.converged & jnp.all(jnp.isfinite(sol.plastic_gap)), sol.plastic_gap, 0.0)
    scale = jnp.where(surfaces.scale > 0.0, surfaces.scale, 1.0)
    profiles = []
    for j, z in enumerate((surfaces.profile1, surfaces.profile2)):
        n = z.shape[0]
        # contact positions x = ξ + x_j0 + d_j of the profile's samples, on the period that starts
        # at the film's first node (``Surfaces.displaced_height``'s map, inverted)
        x = jnp.arange(n) * surfaces.dx + surfaces.offset[j] + d[j]
        x = sol.x[0] + jnp.mod(x - sol.x[0], n * surfaces.dx)
        delta = jnp.interp(x, sol.x, gap, left=0.0, right=0.0)
        profiles.append(z - 0.5 * delta / scale)
    return eqx.tree_at(lambda s: (s.profile1, s.profile2), surfaces, tuple(profiles))


@eqx.filter_jit
def _passage(model, mixed, contacts, lubricant, surfaces, times, displacement0, solids):
    numbers, model = _split_numbers(model)
    n = model.n_nodes
    depth = jnp.asarray(thermal_mod.depth_grid())
    first_contact = jax.tree_util.tree_map(lambda a: a[0], contacts)
    zeros_t = jnp.zeros((n, depth.shape[0]))
    u0 = jnp.stack([first_contact.u1, first_contact.u2])
    x0 = _grid_positions(model, first_contact, lubricant)
    # a placeholder "previous" solution for the first step: only its grid is read (for the empty
    # subsurface fields)
    dt0 = times[1] - times[0]
    proto = eqx.filter_eval_shape(
        lambda: _solve_impl(
            model,
            False,
            mixed,
            _Inputs(
                first_contact,
                lubricant,
                x0,
                jnp.zeros(()),
                x0,
                x0,
                jnp.zeros(()),
                numbers,
                mean_plane=mixed == "statistical",
            ),
            x0[:2],
            x0[:2],
            jnp.zeros(()),
            solids,
        )[0]
    )
    placeholder = jax.tree_util.tree_map(lambda s: jnp.zeros(s.shape, s.dtype), proto)
    placeholder = eqx.tree_at(lambda s: s.x, placeholder, x0)
    older = (
        x0,
        jnp.zeros_like(x0),
        jnp.zeros_like(x0),
        jnp.asarray(displacement0),
        jnp.zeros_like(dt0),
        jnp.zeros_like(x0),
        zeros_t,
        zeros_t,
        jnp.zeros_like(u0),
        surfaces if _runs_in(model, mixed) else None,
        dt0,
    )
    carry = (
        placeholder,
        zeros_t,
        zeros_t,
        jnp.asarray(displacement0),
        times[0] - dt0,
        u0,
        older,
        jnp.asarray(False),
        surfaces if _runs_in(model, mixed) else None,
    )
    carry, sol0 = _step(
        model,
        numbers,
        mixed,
        lubricant,
        surfaces,
        solids,
        depth,
        carry,
        first_contact,
        times[0],
        True,
    )
    rest = jax.tree_util.tree_map(lambda a: a[1:], contacts)

    def body(carry, xs):
        contact, t = xs
        return _step(
            model, numbers, mixed, lubricant, surfaces, solids, depth, carry, contact, t, False
        )

    carry, sols = jax.lax.scan(body, carry, (rest, times[1:]))
    sols = jax.tree_util.tree_map(lambda a, b: jnp.concatenate([a[None], b]), sol0, sols)
    return sols, carry[8]


def solve_ehl_passage(
    contacts: LineContact,
    lubricant: Lubricant,
    model: EHLModel | None = None,
    surfaces: Surfaces | None = None,
    *,
    times,
    displacement=(0.0, 0.0),
    solids=None,
    return_surfaces: bool = False,
) -> EHLSolution | tuple[EHLSolution, Surfaces | None]:
    """March one contact through ``K`` states (transient EHL, ``lax.scan``).

    Args:
        contacts: a LineContact whose fields have a leading axis of length K ≥ 2 (the states at
            ``times``; e.g. built with ``jax.vmap`` or by passing arrays).
        lubricant: the Lubricant.
        model: static EHLModel (``thermal=True`` for the transient temperatures).
        surfaces: None (smooth) or Surfaces (mixed; roughness moving with each surface).
        times: (K,) increasing, s. The first state is solved steadily (no squeeze; the surfaces
            enter at the bulk temperature); each later one is a step of ``model.time_scheme``
            from the ones before.
        displacement: (d1, d2) of the surfaces at ``times[0]``, m.
        solids: (Material, Material) of gears 1 and 2 (default steel).
        return_surfaces: also return the surfaces as the passage left them.

    Under a pressure limit (``EHLModel.hardness``) with deterministic roughness the surfaces run
    in: after each step both profiles are lowered by half its plastic gap where their material
    stood, and the flattening travels with each surface into the later steps (``_run_in``).

    Returns:
        EHLSolution with a leading axis K (per-step ``converged``; the grid of each step is in x);
        with ``return_surfaces``, (that, the run-in Surfaces), the second None where nothing runs
        in (no pressure limit, or no deterministic roughness: ``surfaces`` unchanged then).
    """
    model = EHLModel() if model is None else model
    if not isinstance(model, EHLModel):
        raise ValueError(f"model = {model!r} is not valid; valid: an EHLModel")
    if not isinstance(contacts, LineContact):
        raise ValueError(f"contacts = {type(contacts).__name__} is not valid; valid: a LineContact")
    if surfaces is not None and not isinstance(surfaces, Surfaces):
        raise ValueError(
            f"surfaces = {type(surfaces).__name__} is not valid; valid: None or a Surfaces"
        )
    times = jnp.asarray(times, dtype=float)
    k = times.shape[0] if times.ndim == 1 else 0
    if k < 2:
        raise ValueError(f"times has shape {times.shape}; valid: (K,) with K ≥ 2 increasing times")
    contacts = jax.tree_util.tree_map(
        lambda a: jnp.broadcast_to(jnp.asarray(a, dtype=float), (k,)), contacts
    )
    if is_concrete(times) and not bool(jnp.all(jnp.diff(times) > 0)):
        raise ValueError("times are not increasing; valid: strictly increasing times, s")
    solids = (steel(), steel()) if solids is None else tuple(solids)
    # float leaves become strong float64 arrays: one compiled passage whatever the caller passed
    lubricant, surfaces, solids = canonical((lubricant, surfaces, solids))
    mixed = "smooth" if surfaces is None else model.mixed
    # the steps of a passage do not end in the pseudo-time march of a steady deterministic film
    # (``ehl.continuation._pseudo_march``): along an engagement it rescues no failed step and
    # costs ~50 % more run time
    model = dataclasses.replace(model, pseudo_transient_steps=0)
    sols, worn = _passage(
        model,
        mixed,
        contacts,
        lubricant,
        surfaces,
        times,
        jnp.asarray(displacement, dtype=float),
        solids,
    )
    return (sols, worn) if return_surfaces else sols
