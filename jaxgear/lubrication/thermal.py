# ruff: noqa: F722  (jaxtyping shape strings)
"""Thermal kernels of the mixed EHL line contact (paper Eqs. 6-11, REFERENCE §5).

All temperatures here are **rises above the inlet (bulk) temperature**, K; the caller adds the inlet
temperature. Positions x are in the frame moving with the contact (the EHL grid), m; heat fluxes
W/m²; velocities m/s (surface j moves along +x at u_j > 0); film thickness m.

Contents:

* Steady surface temperature of a half-space moving under a heat source, high-Péclet (Jaeger)
  form of paper Eq. (9): :func:`surface_temperature_rise`, :func:`moving_source_matrices`,
  :func:`steady_surface_operator`, :func:`surface_temperature_rise_uniform` (FFT, uniform grids).
* Transient form with memory of the flux history (1-D conduction into the depth of each material
  point carried through the contact): :class:`SubsurfaceTemperature`, :func:`depth_grid`,
  :func:`transient_init`, :func:`transient_predict`, :func:`transient_update`,
  :func:`transient_step`.
* Film: parabolic temperature profile across the film, conducted fluxes, heat partition ϑ (paper
  Eqs. 10-11), mean film temperature with and without convection:
  :func:`film_temperature_profile`, :func:`conducted_fluxes`,
  :func:`surface_temperature_difference`, :func:`partition_from_temperatures`,
  :func:`mean_film_temperature`, :func:`mean_film_temperature_convective`,
  :func:`partition_fluxes`.
* :func:`solve_contact_temperatures`: the consistent set (both surface temperatures, partition,
  mean film temperature) for a given heat source Q(x) and film h(x).
"""

from __future__ import annotations

import functools

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from .._validation import check_non_negative, check_positive
from ..material import Material

# 1 pm floor on h in the partition system: far below any film (kf·A ≈ 1e-9 m on µm grids), it only
# settles the otherwise indeterminate partition at nodes with no upstream flux in either solid
# (ϑ = ½ there).
_FILM_FLOOR = 1e-12
_TINY_VELOCITY = 1e-12  # m/s; keeps 1/√|u| finite at u = 0 (the high-Péclet form is invalid there)


def _safe_sqrt(s):
    """√s for s ≥ 0 with a finite gradient at s = 0 (double-where)."""
    pos = s > 0.0
    return jnp.where(pos, jnp.sqrt(jnp.where(pos, s, 1.0)), 0.0)


def _thermal_inertia(solid: Material):
    """√(ρ c k), W s^½/(m² K)."""
    return jnp.sqrt(solid.density * solid.specific_heat * solid.thermal_conductivity)


# ------------------------------------------------------------------------------------------------
# Steady moving heat source
# ------------------------------------------------------------------------------------------------


def _upstream_left_matrix(x: Float[Array, " n"]) -> Float[Array, "n n"]:
    """K with (K q)_i = ∫_{x' < x_i} q(x') (x_i − x')^(−½) dx', q linear between nodes."""
    n = x.shape[0]
    seg = jnp.diff(x)  # (n-1,)
    s_far = x[:, None] - x[None, :-1]  # x_i − x_j        (segment's upstream end)
    s_near = x[:, None] - x[None, 1:]  # x_i − x_{j+1}    (segment's downstream end)
    upstream = s_near >= 0.0
    a = _safe_sqrt(jnp.where(upstream, s_far, 1.0))
    b = _safe_sqrt(jnp.where(upstream, s_near, 0.0))
    denom = (a + b) ** 2
    # Exact integrals of the hat functions times s^(-1/2), written without cancellation:
    #   far node weight  (2/3) Δ (a + 2b)/(a + b)²,  near node weight (2/3) Δ (2a + b)/(a + b)².
    w_far = jnp.where(upstream, (2.0 / 3.0) * seg * (a + 2.0 * b) / denom, 0.0)
    w_near = jnp.where(upstream, (2.0 / 3.0) * seg * (2.0 * a + b) / denom, 0.0)
    zeros = jnp.zeros((n, 1), dtype=w_far.dtype)
    return jnp.concatenate([w_far, zeros], axis=1) + jnp.concatenate([zeros, w_near], axis=1)


def moving_source_matrices(x: Float[Array, " n"]) -> Float[Array, "2 n n"]:
    """Influence matrices of the steady high-Péclet moving heat source on ``x`` (REFERENCE §5).

    ``K[0] @ q`` = ∫_{x' < x} q(x') (x − x')^(−½) dx' (surface moving towards +x: upstream on the
    left), ``K[1] @ q`` = ∫_{x' > x} q(x') (x' − x)^(−½) dx' (surface moving towards −x), both exact
    for a flux interpolated linearly between the nodal values q (cell integrals of the kernel done
    analytically). ``x`` must be strictly increasing (uniform or not). Units: m^½. Build once per
    grid and pass to :func:`surface_temperature_rise` / :func:`steady_surface_operator` to avoid the
    O(n²) rebuild.
    """
    x = jnp.asarray(x)
    forward = _upstream_left_matrix(x)
    backward = _upstream_left_matrix(-x[::-1])[::-1, ::-1]
    return jnp.stack([forward, backward])


def steady_surface_operator(
    x: Float[Array, " n"], velocity, solid: Material, matrices=None
) -> Float[Array, "n n"]:
    """Matrix A (K m²/W) with Δϕ = A q: steady Jaeger surface temperature of ``solid`` moving at
    ``velocity`` (m/s) under the nodal heat flux q (W/m²) conducted into it (paper Eq. 9, steady
    form).
    """
    k = moving_source_matrices(x) if matrices is None else matrices
    kernel = jnp.where(velocity >= 0.0, k[0], k[1])
    speed = jnp.maximum(jnp.abs(velocity), _TINY_VELOCITY)
    return kernel / (jnp.sqrt(jnp.pi * speed) * _thermal_inertia(solid))


def surface_temperature_rise(
    x: Float[Array, " n"],
    heat_flux: Float[Array, " n"],
    velocity,
    solid: Material,
    *,
    matrices: Float[Array, "2 n n"] | None = None,
) -> Float[Array, " n"]:
    """Steady surface temperature rise of a moving half-space (Jaeger; paper Eq. 9 steady form).

    Δϕ(x) = (1/√(π ρ c k |u|)) ∫_upstream^x q(x') |x − x'|^(−½) dx',

    the upstream side following the sign of ``velocity`` (u > 0: material arrives from smaller x).
    Valid at high Péclet number |u| a/κ ≫ 1 (a: source half-width); no conduction along x.

    Args:
        x: node positions, m, shape (n,), strictly increasing (uniform or not).
        heat_flux: q at the nodes, W/m², shape (n,) (linear between nodes, zero outside the grid).
        velocity: u, m/s (scalar; ≠ 0).
        solid: the moving body's :class:`~jaxgear.Material` (ρ, c, k).
        matrices: optional precomputed :func:`moving_source_matrices` of ``x``.

    Returns:
        Δϕ at the nodes, K, shape (n,).
    """
    k = moving_source_matrices(x) if matrices is None else matrices
    q = jnp.asarray(heat_flux)
    # one mat-vec, no matrix copy (under vmap over velocity the cond becomes a select of both)
    integral = jax.lax.cond(velocity >= 0.0, lambda: k[0] @ q, lambda: k[1] @ q)
    speed = jnp.maximum(jnp.abs(velocity), _TINY_VELOCITY)
    return integral / (jnp.sqrt(jnp.pi * speed) * _thermal_inertia(solid))


def uniform_source_kernel(n: int, dx) -> tuple[Float[Array, " n"], Float[Array, " n"]]:
    """Toeplitz kernel of :func:`moving_source_matrices` on a uniform grid of spacing ``dx`` (m^½).

    On a uniform grid ``K[0][i, j] = far[i − j] + near[i − j]`` (0 for j > i): the far-end hat weight
    of segment j (s from (m − 1)Δ to mΔ, m = i − j ≥ 1) plus the near-end weight of segment j − 1
    (s from mΔ to (m + 1)Δ), with the cancellation-free closed forms of the matrix. Column 0 has no
    segment −1 (no flux outside the grid): ``K[0][i, 0] = far[i]``.

    Returns:
        (far, near), each shape (n,).
    """
    m = jnp.arange(n, dtype=jnp.result_type(float))
    a_far = _safe_sqrt(m * dx)
    b_far = _safe_sqrt(jnp.maximum(m - 1.0, 0.0) * dx)
    far = jnp.where(m >= 1.0, (2.0 / 3.0) * dx * (a_far + 2.0 * b_far) / (a_far + b_far) ** 2, 0.0)
    a_near = _safe_sqrt((m + 1.0) * dx)
    b_near = _safe_sqrt(m * dx)
    near = (2.0 / 3.0) * dx * (2.0 * a_near + b_near) / (a_near + b_near) ** 2
    return far, near


def surface_temperature_rise_uniform(
    dx, heat_flux: Float[Array, " n"], velocity, solid: Material
) -> Float[Array, " n"]:
    """:func:`surface_temperature_rise` on a uniform grid of spacing ``dx`` (m), by FFT convolution.

    Same discretisation (flux linear between nodes, exact cell integrals of the kernel) and the same
    result to round-off, in O(n log n) time and O(n) memory instead of the O(n²) matrices: use it
    for the fine grids of rough contacts. Shapes and units as :func:`surface_temperature_rise`.
    """
    q = jnp.asarray(heat_flux)
    n = q.shape[0]
    far, near = uniform_source_kernel(n, dx)
    size = 2 * n  # zero padding: linear (not circular) convolution
    g_hat = jnp.fft.rfft(far + near, size)

    def convolve(f):
        full = jnp.fft.irfft(g_hat * jnp.fft.rfft(f, size), size)[:n]
        return full - near * f[0]  # the upstream end node has only half a hat

    integral = jax.lax.cond(velocity >= 0.0, lambda: convolve(q), lambda: convolve(q[::-1])[::-1])
    speed = jnp.maximum(jnp.abs(velocity), _TINY_VELOCITY)
    return integral / (jnp.sqrt(jnp.pi * speed) * _thermal_inertia(solid))


# ------------------------------------------------------------------------------------------------
# Transient: 1-D conduction into the depth of each material point (high Péclet), with memory
# ------------------------------------------------------------------------------------------------


class SubsurfaceTemperature(eqx.Module):
    """State of the transient surface temperature model of one solid.

    Model (high Péclet, conduction only into the depth z, each material point carried through the
    contact at the surface velocity u(t)):

        ρ c (∂T/∂t + u ∂T/∂x) = k ∂²T/∂z²,   −k ∂T/∂z|_{z=0} = q(x, t),
        T → 0 at depth and in material entering the grid.

    Its Green's function gives the surface temperature of a material point as

        Δϕ = (1/√(π ρ c k)) ∫ q(along its path, t') (t − t')^(−½) dt'

    (paper Eq. 9 with the memory of the flux history; for constant u and steady q it equals
    :func:`surface_temperature_rise`). Discretisation: semi-Lagrangian advection (linear
    interpolation; exact shift when |u| dt/dx = 1) and backward-Euler finite volumes on a
    geometric depth grid; the step is unconditionally stable.

    Attributes:
        temperature: T(x_i, z_k), rise above bulk, K, shape (n, nz) (contact grid × depth grid).
        depth: z_k, m, shape (nz,), z_0 = 0 (the surface), increasing (see :func:`depth_grid`).
    """

    temperature: Float[Array, "n nz"]
    depth: Float[Array, " nz"]

    @property
    def surface(self) -> Float[Array, " n"]:
        """Surface temperature rise, K, shape (n,)."""
        return self.temperature[:, 0]


def depth_grid(
    n_depth: int = 48, first_spacing: float = 0.05e-6, depth: float = 3e-3
) -> np.ndarray:
    """Geometric depth grid: z_0 = 0, z_1 = ``first_spacing``, …, z_{n−1} = ``depth`` (m).

    Choose ``first_spacing`` ≪ √(κ Δt) of the shortest time step and ``depth`` ≫ √(κ t_dwell) of the
    slowest contact (defaults cover 0.05-50 m/s across a ~0.5 mm steel contact).
    """
    check_positive("first_spacing", first_spacing, "m")
    check_positive("depth", depth, "m")
    if not isinstance(n_depth, int | np.integer) or n_depth < 4:
        raise ValueError(f"n_depth = {n_depth!r} is not valid; valid range: integer ≥ 4")
    if depth <= first_spacing * (n_depth - 1):
        raise ValueError(
            f"depth = {depth:g} m is out of range; valid range: > first_spacing·(n_depth − 1) = "
            f"{first_spacing * (n_depth - 1):g} m"
        )
    m = n_depth - 1
    lo, hi = 1.0 + 1e-12, 2.0
    while first_spacing * (hi**m - 1.0) / (hi - 1.0) < depth:
        hi *= 2.0
    for _ in range(200):  # bisection for the growth ratio r: first·(r^m − 1)/(r − 1) = depth
        mid = 0.5 * (lo + hi)
        if first_spacing * (mid**m - 1.0) / (mid - 1.0) < depth:
            lo = mid
        else:
            hi = mid
    r = 0.5 * (lo + hi)
    z = first_spacing * (r ** np.arange(n_depth) - 1.0) / (r - 1.0)
    z[-1] = depth
    return z


def transient_init(n: int, depth=None) -> SubsurfaceTemperature:
    """Zero subsurface temperature on ``n`` contact nodes and the given (default) depth grid."""
    z = jnp.asarray(depth_grid() if depth is None else depth)
    return SubsurfaceTemperature(temperature=jnp.zeros((n, z.shape[0]), z.dtype), depth=z)


def _advect(temperature, shift_cells):
    """T(x_i − shift·dx), linear interpolation; material entering from outside the grid is at 0."""
    n = temperature.shape[0]
    zero = jnp.zeros((1, temperature.shape[1]), temperature.dtype)
    padded = jnp.concatenate([zero, temperature, zero], axis=0)  # row r ↔ node r − 1
    s = jnp.arange(n) - shift_cells
    i0 = jnp.floor(s)
    f = (s - i0)[:, None]
    i0 = i0.astype(jnp.int32)
    lo = padded[jnp.clip(i0 + 1, 0, n + 1)]
    hi = padded[jnp.clip(i0 + 2, 0, n + 1)]
    return (1.0 - f) * lo + f * hi


def _depth_system(depth, dt, solid: Material):
    """Backward-Euler finite-volume tridiagonal rows (scaled by dt/V_k) and the unit-flux rhs."""
    kappa = solid.thermal_diffusivity
    dz = jnp.diff(depth)  # (nz-1,)
    vol = jnp.concatenate([dz[:1] / 2.0, (dz[:-1] + dz[1:]) / 2.0])  # (nz-1,) control volumes
    up = kappa * dt / (vol * dz)  # coupling to k+1
    down = jnp.concatenate([jnp.zeros(1), kappa * dt / (vol[1:] * dz[:-1])])  # coupling to k-1
    diag = jnp.concatenate([1.0 + up + down, jnp.ones(1)])  # last row: T = 0 at the bottom
    du = jnp.concatenate([-up, jnp.zeros(1)])
    dl = jnp.concatenate([jnp.zeros(1), -down[1:], jnp.zeros(1)])
    unit_rhs = jnp.zeros_like(depth).at[0].set(dt / (solid.density * solid.specific_heat * vol[0]))
    return dl, diag, du, unit_rhs


def transient_predict(
    state: SubsurfaceTemperature, dx, velocity, dt, solid: Material
) -> tuple[Float[Array, "n nz"], Float[Array, " nz"]]:
    """First half of one implicit time step, independent of the new heat flux.

    The step is linear in the new flux q: T_new(x, z) = free(x, z) + q(x) · unit(z). So the new
    surface temperature is ``free[:, 0] + unit[0] * q`` — a diagonal response the EHL fixed point
    can use without re-solving (see :func:`solve_contact_temperatures` ``surface_response``).

    Args:
        state: subsurface temperature at the previous time.
        dx: spacing of the (uniform) contact grid, m.
        velocity: surface velocity u over the step, m/s (any sign; moves ``velocity·dt`` per step).
        dt: time step, s (> 0).
        solid: the body's material.

    Returns:
        ``free`` (n, nz), K: advected and diffused field with zero new flux; ``unit`` (nz,), K m²/W:
        the temperature response to a unit flux over the step.
    """
    advected = _advect(state.temperature, velocity * dt / dx)
    dl, d, du, unit_rhs = _depth_system(state.depth, dt, solid)
    rhs = jnp.concatenate([advected.T, unit_rhs[:, None]], axis=1)  # (nz, n+1)
    sol = jax.lax.linalg.tridiagonal_solve(dl, d, du, rhs)
    return sol[:, :-1].T, sol[:, -1]


def transient_update(free, unit, heat_flux, depth) -> SubsurfaceTemperature:
    """Second half of the step: the state after adding the response to the new nodal heat flux.

    Args:
        free, unit: from :func:`transient_predict`.
        heat_flux: q over the step, W/m², shape (n,).
        depth: the state's depth grid, m, shape (nz,).
    """
    return SubsurfaceTemperature(
        temperature=free + jnp.asarray(heat_flux)[:, None] * unit[None, :], depth=depth
    )


def transient_step(
    state: SubsurfaceTemperature, heat_flux, dx, velocity, dt, solid: Material
) -> tuple[SubsurfaceTemperature, Float[Array, " n"]]:
    """One backward-Euler step of the transient surface temperature model (usable in ``lax.scan``).

    Args:
        state: subsurface temperature at t.
        heat_flux: q(x) over (t, t + dt], W/m², shape (n,) on the uniform contact grid.
        dx: grid spacing, m. velocity: u, m/s. dt: s. solid: Material.

    Returns:
        (state at t + dt, surface temperature rise at t + dt in K, shape (n,)).
    """
    free, unit = transient_predict(state, dx, velocity, dt, solid)
    new = transient_update(free, unit, heat_flux, state.depth)
    return new, new.surface


# ------------------------------------------------------------------------------------------------
# Film: parabolic temperature profile, conducted fluxes, partition (paper Eqs. 6-11, REFERENCE §5)
# ------------------------------------------------------------------------------------------------


def film_temperature_profile(zeta, phi1, phi2, phim):
    """Parabolic temperature across the film (paper Eq. 8, REFERENCE §5), K.

    ϕf(ζ) = (3ϕ1 + 3ϕ2 − 6ϕm) ζ² − (4ϕ1 + 2ϕ2 − 6ϕm) ζ + ϕ1, with ζ = z/h ∈ [0, 1] from surface 1
    (ζ = 0) to surface 2 (ζ = 1); its mean over ζ is ϕm. Arguments broadcast.
    """
    return (
        (3.0 * phi1 + 3.0 * phi2 - 6.0 * phim) * zeta**2
        - (4.0 * phi1 + 2.0 * phi2 - 6.0 * phim) * zeta
        + phi1
    )


def conducted_fluxes(phi1, phi2, phim, film_thickness, film_conductivity):
    """Heat fluxes conducted from the film into solid 1 and solid 2, W/m² (REFERENCE §5).

    Q1 = (kf/h)(6ϕm − 4ϕ1 − 2ϕ2), Q2 = (kf/h)(6ϕm − 2ϕ1 − 4ϕ2): −kf ∂ϕf/∂z at each wall of the
    parabolic profile, positive into the solid. h in m, kf in W/(m K), temperatures in K.
    """
    g = film_conductivity / film_thickness
    return g * (6.0 * phim - 4.0 * phi1 - 2.0 * phi2), g * (6.0 * phim - 2.0 * phi1 - 4.0 * phi2)


def surface_temperature_difference(partition, heat_flux, film_thickness, film_conductivity):
    """ϕ1 − ϕ2 = (h/(2 kf)) (1 − 2ϑ) Q (paper Eq. 11), K. ϑ = Q1/Q is the share conducted into
    solid 1."""
    return film_thickness / (2.0 * film_conductivity) * (1.0 - 2.0 * partition) * heat_flux


def partition_from_temperatures(phi1, phi2, heat_flux, film_thickness, film_conductivity):
    """Invert paper Eq. (11): ϑ = ½ − kf (ϕ1 − ϕ2)/(h Q); ϑ = ½ where h Q = 0 (gradient-safe)."""
    hq = film_thickness * heat_flux
    ok = hq != 0.0
    return 0.5 - jnp.where(ok, film_conductivity * (phi1 - phi2) / jnp.where(ok, hq, 1.0), 0.0)


def mean_film_temperature(phi1, phi2, heat_flux, film_thickness, film_conductivity):
    """Mean film temperature without convection, K: ϕm = (ϕ1 + ϕ2)/2 + h Q/(12 kf) (REFERENCE
    §5)."""
    return 0.5 * (phi1 + phi2) + film_thickness * heat_flux / (12.0 * film_conductivity)


def _upwind_difference(x, f, inlet_value, forward):
    """Backward (forward=True) or forward difference of f with a ghost inlet value, per node."""
    if forward:
        dx = jnp.concatenate([x[1:2] - x[0:1], jnp.diff(x)])
        prev = jnp.concatenate([jnp.reshape(inlet_value, (1,)), f[:-1]])
        return (f - prev) / dx
    dx = jnp.concatenate([jnp.diff(x), x[-1:] - x[-2:-1]])
    nxt = jnp.concatenate([f[1:], jnp.reshape(inlet_value, (1,))])
    return (nxt - f) / dx


def _convection(x, h, phim, phi1, phi2, ur, us, rho_c, inlet, previous, dt):
    """C = ρ cf h [ur ∂x ϕm + (us/12) ∂x(ϕ1 − ϕ2) + ∂t ϕm] with the marching scheme's
    differences."""
    forward = ur >= 0.0
    dphim = jnp.where(
        forward,
        _upwind_difference(x, phim, inlet, True),
        _upwind_difference(x, phim, inlet, False),
    )
    term = ur * dphim + (us / 12.0) * jnp.gradient(phi1 - phi2, x)
    if dt is not None:
        term = term + (phim - previous) / dt
    return rho_c * h * term


def mean_film_temperature_convective(
    x: Float[Array, " n"],
    heat_flux,
    film_thickness,
    phi1,
    phi2,
    rolling_velocity,
    sliding_velocity,
    film_density,
    film_specific_heat,
    film_conductivity,
    *,
    inlet_temperature=0.0,
    previous=None,
    dt=None,
) -> Float[Array, " n"]:
    """Mean film temperature ϕm with convection, K (film-averaged energy equation, REFERENCE §5):

        (12 kf/h)(ϕm − (ϕ1+ϕ2)/2) = Q − ρ cf h [ur ∂x ϕm + (us/12) ∂x(ϕ1 − ϕ2) + ∂t ϕm],

    the left side being Q1 + Q2 of :func:`conducted_fluxes`. Multiplied by h (so h → 0 gives ϕm →
    (ϕ1+ϕ2)/2 without division) and solved by implicit first-order upwind marching from the inlet
    (the side ur comes from), as a linear recurrence ϕm_i = α_i ϕm_{i−1} + β_i run by
    ``lax.scan``. ∂x(ϕ1 − ϕ2) by central differences; ∂t ϕm by backward Euler when
    ``dt`` (s) and ``previous`` (ϕm at t − dt) are given, otherwise quasi-steady.

    Args:
        x: nodes, m, shape (n,), increasing. heat_flux Q: W/m². film_thickness h: m (≥ 0).
        phi1, phi2: surface temperature rises, K. rolling_velocity ur = (u1+u2)/2 and
        sliding_velocity us = u1 − u2: m/s (scalars). film_density ρ kg/m³, film_specific_heat cf
        J/(kg K), film_conductivity kf W/(m K) (scalars or (n,)). inlet_temperature: ϕm upstream of
        the grid, K.

    Returns:
        ϕm at the nodes, K, shape (n,).
    """
    x = jnp.asarray(x)
    n = x.shape[0]
    h = jnp.broadcast_to(film_thickness, (n,))
    rho_c = film_density * film_specific_heat
    kf = film_conductivity
    forward = rolling_velocity >= 0.0
    dx_back = jnp.concatenate([x[1:2] - x[0:1], jnp.diff(x)])
    dx_fwd = jnp.concatenate([jnp.diff(x), x[-1:] - x[-2:-1]])
    dx_up = jnp.where(forward, dx_back, dx_fwd)
    adv = rho_c * h**2 * jnp.abs(rolling_velocity) / dx_up
    rhs = (
        h * heat_flux
        + 6.0 * kf * (phi1 + phi2)
        - rho_c * h**2 * (sliding_velocity / 12.0) * jnp.gradient(phi1 - phi2, x)
    )
    denom = 12.0 * kf + adv
    if dt is not None:
        unsteady = rho_c * h**2 / dt
        rhs = rhs + unsteady * previous
        denom = denom + unsteady
    alpha = jnp.broadcast_to(adv / denom, (n,))
    beta = jnp.broadcast_to(rhs / denom, (n,))
    # March from the inlet side: reverse the arrays when ur < 0.
    alpha_m = jnp.where(forward, alpha, alpha[::-1])
    beta_m = jnp.where(forward, beta, beta[::-1])

    def march(previous_node, coefficients):
        a, b = coefficients
        value = a * previous_node + b
        return value, value

    # sequential lax.scan: on CPU it compiles ~10× faster and runs faster than associative_scan
    _, phim_m = jax.lax.scan(march, jnp.asarray(inlet_temperature, beta_m.dtype), (alpha_m, beta_m))
    return jnp.where(forward, phim_m, phim_m[::-1])


def partition_fluxes(
    heat_flux, film_thickness, film_conductivity, operator1, operator2, offset1=0.0, offset2=0.0
):
    """Conducted fluxes (Q1, Q2), W/m², consistent with the film and both solids' surface responses.

    Solids: ϕ_j = offset_j + A_j Q_j (A_j an (n, n) matrix such as :func:`steady_surface_operator`,
    or an (n,) diagonal such as the transient ``unit[0]``). Film (REFERENCE §5, no convection in Q,
    which the caller may pass as Q − C): Q1 = Q/2 − (kf/h)(ϕ1 − ϕ2), Q2 = Q − Q1 (equivalent to
    paper Eq. 11). Eliminating gives the linear system

        [h I + kf (A1 + A2)] Q1 = h Q/2 + kf (A2 Q + offset2 − offset1),

    well posed down to h = 0 (dry/asperity contact), where it enforces ϕ1 = ϕ2 (Blok's postulate).
    """
    h = jnp.maximum(film_thickness, _FILM_FLOOR)
    rhs = 0.5 * h * heat_flux + film_conductivity * (offset2 - offset1)
    if jnp.ndim(operator1) == 2 or jnp.ndim(operator2) == 2:
        n = jnp.shape(heat_flux)[0]
        a1 = operator1 if jnp.ndim(operator1) == 2 else jnp.diag(jnp.broadcast_to(operator1, (n,)))
        a2 = operator2 if jnp.ndim(operator2) == 2 else jnp.diag(jnp.broadcast_to(operator2, (n,)))
        kf = jnp.broadcast_to(film_conductivity, (n,))
        rhs = rhs + kf * (a2 @ heat_flux)
        system = jnp.diag(jnp.broadcast_to(h, (n,))) + kf[:, None] * (a1 + a2)
        q1 = jnp.linalg.solve(system, rhs)
    else:
        rhs = rhs + film_conductivity * operator2 * heat_flux
        q1 = rhs / (h + film_conductivity * (operator1 + operator2))
    return q1, heat_flux - q1


class ContactTemperatures(eqx.Module):
    """Consistent temperatures of one line contact (rises above the inlet temperature).

    Attributes (shape (n,) unless stated):
        surface1, surface2: ϕ1, ϕ2, surface temperature rises of gear 1 and gear 2, K.
        film_mean: ϕm, mean film temperature rise, K.
        flux1, flux2: Q1, Q2, heat fluxes conducted into solid 1 and 2, W/m².
        partition: ϑ = Q1/(Q1 + Q2) (½ where no heat flows).
        convected: C = Q − Q1 − Q2, heat carried away by the film, W/m².
        residual: scalar, max |ΔC| of the last fixed-point iteration relative to max |Q| (0 without
            convection).
    """

    surface1: Float[Array, " n"]
    surface2: Float[Array, " n"]
    film_mean: Float[Array, " n"]
    flux1: Float[Array, " n"]
    flux2: Float[Array, " n"]
    partition: Float[Array, " n"]
    convected: Float[Array, " n"]
    residual: Float[Array, ""]

    def film_profile(self, zeta):
        """Film temperature ϕf(ζ) at fractions ζ of the film (shape (m,)), K, shape (m, n)."""
        zeta = jnp.asarray(zeta)[:, None]
        return film_temperature_profile(zeta, self.surface1, self.surface2, self.film_mean)


def solve_contact_temperatures(
    x: Float[Array, " n"],
    heat_flux: Float[Array, " n"],
    film_thickness,
    u1,
    u2,
    solid1: Material,
    solid2: Material,
    film_density,
    film_specific_heat,
    film_conductivity,
    *,
    convection: bool = True,
    surface_response=None,
    matrices=None,
    inlet_temperature=0.0,
    previous_film_mean=None,
    dt=None,
    n_iterations: int = 12,
) -> ContactTemperatures:
    """Temperatures of a line contact given its heat source Q(x) and film h(x) (paper Eqs. 6-11).

    Unknowns Q1, Q2 (conducted into the solids), ϕ1, ϕ2, ϕm. Equations: each solid's surface
    temperature from its conducted flux (steady Jaeger operator of :func:`steady_surface_operator`,
    or the transient diagonal response of :func:`transient_predict` via ``surface_response``); the
    film's parabolic-profile fluxes (:func:`conducted_fluxes`); the film-averaged energy equation.
    With C = ρ cf h [ur ∂x ϕm + (us/12) ∂x(ϕ1 − ϕ2) + ∂t ϕm], the system is linear: for given C,
    :func:`partition_fluxes` with Q − C gives Q1, Q2 exactly; ϕm then follows by upwind marching
    (:func:`mean_film_temperature_convective`) and C is updated — a fixed point iterated
    ``n_iterations`` times (``lax.fori_loop``, reverse-differentiable). The iteration
    contracts by ≈ 0.03 per step when C/Q ≈ 0.14 (h = 1 µm, Hertzian source, steel): 12 steps reach
    round-off there; thicker films contract more slowly, so ``residual`` reports the last change.
    Without convection (``convection=False``) C = 0 and one linear solve is exact.

    Args:
        x: nodes, m, shape (n,), increasing (uniform for transient responses).
        heat_flux: Q generated in the contact, W/m², shape (n,) (paper Eq. 12).
        film_thickness: h, m, shape (n,) or scalar (≥ 0; 0 in asperity contact).
        u1, u2: surface velocities, m/s (scalars).
        solid1, solid2: materials of gear 1 and 2.
        film_density, film_specific_heat, film_conductivity: ρ (kg/m³), cf (J/(kg K)), kf (W/(m K)),
            scalars or (n,).
        convection: include the convective term C (static).
        surface_response: optional ((offset1, gain1), (offset2, gain2)) with ϕj = offset_j + gain_j
        Q_j;
            gains (n,) diagonal or (n, n). Default: steady Jaeger operators (offsets 0).
        matrices: optional :func:`moving_source_matrices` of ``x`` (for the default response).
        inlet_temperature: ϕm upstream of the grid, K.
        previous_film_mean, dt: ϕm at t − dt and the time step (s) for ∂t ϕm; quasi-steady if None.
        n_iterations: fixed-point iterations on C (static).

    Returns:
        :class:`ContactTemperatures`.
    """
    check_film_properties(film_density, film_specific_heat, film_conductivity)
    check_film_thickness(film_thickness)
    return _solve_contact_temperatures(
        x,
        heat_flux,
        film_thickness,
        u1,
        u2,
        solid1,
        solid2,
        film_density,
        film_specific_heat,
        film_conductivity,
        surface_response,
        matrices,
        inlet_temperature,
        previous_film_mean,
        dt,
        convection=convection,
        n_iterations=n_iterations,
    )


@functools.partial(jax.jit, static_argnames=("convection", "n_iterations"))
def _solve_contact_temperatures(
    x,
    heat_flux,
    film_thickness,
    u1,
    u2,
    solid1,
    solid2,
    film_density,
    film_specific_heat,
    film_conductivity,
    surface_response,
    matrices,
    inlet_temperature,
    previous_film_mean,
    dt,
    *,
    convection,
    n_iterations,
):
    x = jnp.asarray(x)
    q = jnp.asarray(heat_flux)
    n = x.shape[0]
    h = jnp.broadcast_to(jnp.asarray(film_thickness, dtype=q.dtype), (n,))
    kf = jnp.broadcast_to(film_conductivity, (n,))
    if surface_response is None:
        mats = moving_source_matrices(x) if matrices is None else matrices
        op1 = steady_surface_operator(x, u1, solid1, mats)
        op2 = steady_surface_operator(x, u2, solid2, mats)
        off1 = off2 = jnp.zeros_like(q)
    else:
        (off1, op1), (off2, op2) = surface_response
    ur = 0.5 * (u1 + u2)
    us = u1 - u2
    hp = jnp.maximum(h, _FILM_FLOOR)  # partition system only (see _FILM_FLOOR)
    rho_c = film_density * film_specific_heat

    dense = jnp.ndim(op1) == 2 or jnp.ndim(op2) == 2
    if dense:
        a1 = op1 if jnp.ndim(op1) == 2 else jnp.diag(jnp.broadcast_to(op1, (n,)))
        a2 = op2 if jnp.ndim(op2) == 2 else jnp.diag(jnp.broadcast_to(op2, (n,)))
        system = jnp.diag(hp) + kf[:, None] * (a1 + a2)
        if surface_response is None:
            # Jaeger operators are triangular (lower when the solids move towards +x, upper towards
            # −x): an O(n²) triangular solve, no factorisation. Opposite directions: dense solve.
            branch = jnp.where(
                (u1 >= 0.0) & (u2 >= 0.0), 0, jnp.where((u1 < 0.0) & (u2 < 0.0), 1, 2)
            )

            def solve(rhs):
                return jax.lax.switch(
                    branch,
                    [
                        lambda r: jax.scipy.linalg.solve_triangular(system, r, lower=True),
                        lambda r: jax.scipy.linalg.solve_triangular(system, r, lower=False),
                        lambda r: jnp.linalg.solve(system, r),
                    ],
                    rhs,
                )
        else:
            # A general operator: factor once, reuse for every C.
            lu = jax.scipy.linalg.lu_factor(system)

            def solve(rhs):
                return jax.scipy.linalg.lu_solve(lu, rhs)

        def fluxes(q_eff):
            rhs = 0.5 * hp * q_eff + kf * (a2 @ q_eff + off2 - off1)
            q1 = solve(rhs)
            return q1, q_eff - q1, off1 + a1 @ q1, off2 + a2 @ (q_eff - q1)
    else:

        def fluxes(q_eff):
            q1 = (0.5 * hp * q_eff + kf * (op2 * q_eff + off2 - off1)) / (hp + kf * (op1 + op2))
            return q1, q_eff - q1, off1 + op1 * q1, off2 + op2 * (q_eff - q1)

    def film_mean(phi1, phi2):
        if not convection:
            return mean_film_temperature(phi1, phi2, q, h, kf)
        return mean_film_temperature_convective(
            x,
            q,
            h,
            phi1,
            phi2,
            ur,
            us,
            film_density,
            film_specific_heat,
            kf,
            inlet_temperature=inlet_temperature,
            previous=previous_film_mean,
            dt=dt,
        )

    def update(conv):
        q1, q2, phi1, phi2 = fluxes(q - conv)
        phim = film_mean(phi1, phi2)
        if convection:
            new = _convection(
                x, h, phim, phi1, phi2, ur, us, rho_c, inlet_temperature, previous_film_mean, dt
            )
        else:
            new = jnp.zeros_like(q)
        return new, (q1, q2, phi1, phi2, phim)

    def body(_, carry):
        conv, _ = carry
        new, _ = update(conv)
        return new, jnp.max(jnp.abs(new - conv))

    conv0 = jnp.zeros_like(q)
    iters = n_iterations if convection else 0
    conv, change = jax.lax.fori_loop(0, iters, body, (conv0, jnp.zeros((), q.dtype)))
    _, (q1, q2, phi1, phi2, phim) = update(conv)
    qsum = q1 + q2
    ok = qsum != 0.0
    partition = jnp.where(ok, q1 / jnp.where(ok, qsum, 1.0), 0.5)
    scale = jnp.maximum(jnp.max(jnp.abs(q)), jnp.finfo(q.dtype).tiny)
    return ContactTemperatures(
        surface1=phi1,
        surface2=phi2,
        film_mean=phim,
        flux1=q1,
        flux2=q2,
        partition=partition,
        convected=q - qsum,
        residual=change / scale,
    )


def check_film_properties(film_density, film_specific_heat, film_conductivity) -> None:
    """Boundary check of film properties (ValueError naming the field, value and range)."""
    check_positive("film_density", film_density, "kg/m^3")
    check_positive("film_specific_heat", film_specific_heat, "J/(kg K)")
    check_positive("film_conductivity", film_conductivity, "W/(m K)")


def check_film_thickness(film_thickness) -> None:
    """Boundary check: h ≥ 0 and finite, m."""
    check_non_negative("film_thickness", film_thickness, "m")
