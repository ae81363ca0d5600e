"""``solve_ehl``: a line-contact EHL solve from its public inputs (smooth or rough, steady or one
transient step), checked in Python and run as one compiled call (``_solve_entry``)."""

from __future__ import annotations

import functools

import equinox as eqx
import jax
import jax.numpy as jnp

from ..._inputs import canonical
from ..._validation import check_positive
from ..lubricant import Lubricant
from .discretisation import _film_at_feet, _grid_positions, _roughness_offset, transport_shift
from .model import EHLModel, LineContact, _Inputs, _split_numbers
from .outer import _solve_impl
from .solution import EHLSolution
from .starts import _warm_args


def solve_ehl(
    contact: LineContact,
    lubricant: Lubricant,
    model: EHLModel | None = None,
    surfaces=None,
    *,
    initial: EHLSolution | None = None,
    previous: EHLSolution | None = None,
    time_step=None,
    displacement=None,
    solids=None,
    temperature_rise=None,
) -> EHLSolution:
    """Solve a line-contact EHL problem: smooth or mixed (rough), isothermal or thermal, steady or
    one backward-Euler step.

    Args:
        contact: the LineContact (SI).
        lubricant: the Lubricant.
        model: static EHLModel (default ``EHLModel()``: 257 nodes, Roelands, Dowson-Higginson,
            paper Eyring, isothermal). ``EHLModel(thermal=True)`` adds the temperatures.
        surfaces: ``None`` (smooth) or a :class:`~jaxgear.lubrication.roughness.Surfaces`: mixed
            lubrication with the roughness S1 + S2 in the film (paper Eq. 5), asperity contact
            where the film closes (Hu-Zhu unified Reynolds, paper Eq. 4b/4c) and boundary friction
            μb p there. The grid must resolve the roughness: under-resolved features make
            asperity contact a resolved film does not have (a waviness needs ≳ 13 nodes a
            wavelength; studies/roughness_resolution).
            A deep mixed deterministic film whose direct solve fails (500 rpm, ground, 513 nodes
            and finer) is reached by pseudo-transient continuation (``model.pseudo_transient_steps``).
        initial: a previous EHLSolution to warm-start from (any contact; its p(x) is interpolated
            and its h0 reused). A failed warm start falls back to a cold solve.
        previous: the solution at the previous time step; with ``time_step`` Δt (s) the squeeze term
            ∂(ρh)/∂t ≈ (ρh − ρh_prev)/Δt is included (backward Euler). ρh_prev is interpolated onto
            this solve's nodes (same nodes when the contact's Hertz half-width is unchanged).
        time_step: Δt, s (required with ``previous``).
        displacement: (d1, d2), m: how far each surface has moved, ∫ uj dt; the roughness is
            Sj = scale · zj(x − xj0 − dj). Default (0, 0).
        solids: (Material of gear 1, Material of gear 2) for the surface temperatures (default:
            steel, REFERENCE §4). Used only when ``model.thermal``.
        temperature_rise: starting film temperature rise at the nodes (K), e.g. from a previous
            time step; default zero. Isothermal: the film is held at this temperature field.

    Returns:
        EHLSolution (SI, per unit width), with ``converged``, ``residual`` and ``iterations``.
    """
    from ..roughness import Surfaces

    model = EHLModel() if model is None else model
    if not isinstance(model, EHLModel):
        raise ValueError(f"model = {model!r} is not valid; valid: an EHLModel")
    if surfaces is not None and not isinstance(surfaces, Surfaces):
        raise ValueError(
            f"surfaces = {type(surfaces).__name__} is not valid; valid: None or a Surfaces"
        )
    if not isinstance(contact, LineContact):
        raise ValueError(f"contact = {type(contact).__name__} is not valid; valid: a LineContact")
    if not isinstance(lubricant, Lubricant):
        raise ValueError(f"lubricant = {type(lubricant).__name__} is not valid; valid: a Lubricant")
    dtype = jnp.result_type(float)
    if dtype != jnp.float64:
        raise ValueError(
            f"solve_ehl computes in {dtype}; EHL needs float64 (pressures ~1e9 Pa against films "
            "~1e-8 m). Enable it with jax.config.update('jax_enable_x64', True) before use"
        )
    solids = _default_solids() if solids is None else tuple(solids)
    if previous is not None:
        if time_step is None:
            raise ValueError(
                "time_step = None is not valid with previous=; valid range: (0, inf) s"
            )
        check_positive("time_step", time_step, "s")
    mixed = "smooth" if surfaces is None else model.mixed
    # float leaves become strong float64 arrays (a weakly typed one, from a Python float through
    # eqx.tree_at, compiles the call below a second time)
    contact, lubricant, surfaces, solids, initial, previous = canonical(
        (contact, lubricant, surfaces, solids, initial, previous)
    )
    # numbers become arrays (a Python float would be a static argument of the compiled call below,
    # one compilation per value)
    time_step, displacement, temperature_rise = (
        None if v is None else jnp.asarray(v, dtype=dtype)
        for v in (time_step, displacement, temperature_rise)
    )
    # everything below is array work: one compiled call, so that an eager call from Python costs
    # the solve and not dozens of dispatches
    return _solve_entry(
        model,
        mixed,
        contact,
        lubricant,
        surfaces,
        initial,
        previous,
        time_step,
        displacement,
        solids,
        temperature_rise,
    )


@functools.cache
def _default_solids():
    """(steel, steel): built once (constructing and validating a Material costs ~1 ms eagerly).
    Built with concrete values even when first called inside a trace (a cached tracer would leak
    into later compilations)."""
    from ...material import steel

    with jax.ensure_compile_time_eval():
        return steel(), steel()


@eqx.filter_jit
def _solve_entry(
    model,
    mixed,
    contact,
    lubricant,
    surfaces,
    initial,
    previous,
    time_step,
    displacement,
    solids,
    temperature_rise,
):
    numbers, model = _split_numbers(model)
    n = model.n_nodes
    dtype = jnp.result_type(float)
    x_here = _grid_positions(model, contact, lubricant)
    d = jnp.zeros((2,), dtype=dtype) if displacement is None else jnp.asarray(displacement)
    if previous is not None:
        dt = jnp.asarray(time_step, dtype=dtype)
        inv_dt = 1.0 / dt
        shift = transport_shift(model, contact.rolling_velocity * dt)
        # the surfaces stood a step back at the previous solution
        d_prev = d - jnp.stack([contact.u1, contact.u2]) * dt
        rho_h_prev = _film_at_feet(
            model,
            mixed,
            surfaces,
            x_here,
            shift,
            previous.x,
            previous.rho_h,
            previous.density,
            d_prev,
            contact.reduced_radius,
        )
    else:
        inv_dt = jnp.zeros((), dtype=dtype)
        rho_h_prev = jnp.zeros((n,), dtype=dtype)
    sigma = jnp.zeros((), dtype=dtype) if surfaces is None else surfaces.composite_rq
    offset = _roughness_offset(mixed, surfaces, x_here, d)
    rise = (
        jnp.zeros((n,), dtype=dtype)
        if temperature_rise is None
        else jnp.broadcast_to(jnp.asarray(temperature_rise, dtype=dtype), (n,))
    )
    inp = _Inputs(
        contact,
        lubricant,
        rho_h_prev,
        inv_dt,
        offset,
        rise,
        sigma,
        numbers,
        mean_plane=mixed == "statistical",
    )
    if initial is not None:
        args = _warm_args(initial, mixed == "deterministic", moved=previous is not None)
        return _solve_impl(model, True, mixed, inp, *args, solids)[0]
    z = jnp.zeros((2,), dtype=dtype)
    return _solve_impl(model, False, mixed, inp, z, z, jnp.zeros((), dtype=dtype), solids)[0]
