# ruff: noqa: F722  (jaxtyping shape strings)
"""Rough surfaces: 1-D roughness height profiles of both gears, carried with the moving surfaces.

The film thickness of paper Eq. (5) contains S1(x, t) and S2(x, t), the roughness of each surface,
which moves with that surface's velocity uj (REFERENCE §1, §6). A :class:`Surfaces` holds one
periodic height profile per gear, sampled on a uniform grid of spacing ``dx``, and a traced
roughness ``scale`` (a design variable). Heights are evaluated by periodic cubic B-spline
interpolation (C² smooth, exact at the samples), so S_j is differentiable in ``scale``, t, u_j and
x.

The paper's measured profiles are not public; :func:`gaussian_profile` synthesises Gaussian profiles
with an exponential autocorrelation R(τ) = Rq² exp(−|τ|/β) by spectral filtering of white noise
(REFERENCE §6). The correlation length quoted everywhere is the 10 % decay length ℓ = β ln 10.

Such a profile has no finest scale: its spectrum falls only as 1/f², so its rms slope grows as
1/√Δx with the sampling (0.19-0.20 rad by central differences at the default 0.5 µm for the ground
preset) and a finer EHL grid always meets sharper asperities. A measured profile has one: the
stylus instrument's short-wave cutoff λs (ISO 3274; 2.5 µm with the 0.8 mm long-wave cutoff of
ground gear flanks) removes what is shorter. ``short_cutoff`` applies that filter (the Gaussian
profile filter of ISO 16610-21, amplitude transmission exp(−π (α λs/λ)²), α = √(ln 2/π): 50 % at
λ = λs) to the synthetic profile, whose rms slope then no longer depends on a sampling finer than
~λs/10. An EHL grid needs more still: under-resolved roughness makes asperity contact a resolved
film does not have, and a waviness is resolved from ~13 nodes a wavelength
(studies/roughness_resolution). The default (None) keeps the unfiltered profile.
"""

from __future__ import annotations

import functools
import math
import os

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from .._validation import check_finite, check_non_negative, check_positive, is_concrete

DEFAULT_SPACING = 0.5e-6  # m; resolves a 20 µm correlation length with ~17 samples per β
DEFAULT_POINTS = 8192  # 4.1 mm periodic length: longer than the contact domain of the paper's pair
DEFAULT_CORRELATION_LENGTH = 20e-6  # m, 10 % decay length [typical], REFERENCE §6


def _check_profile(name: str, z) -> None:
    arr = np.asarray(z) if is_concrete(z) else None
    if arr is None:
        return
    if arr.ndim != 1 or arr.size < 4:
        raise ValueError(
            f"{name} has shape {arr.shape}; valid: a 1-D array of at least 4 heights (m)"
        )
    check_finite(name, arr)


class Surfaces(eqx.Module):
    """Roughness of both gear surfaces (paper Eq. 5's S1, S2).

    Attributes:
        profile1: z1, heights of gear 1's surface, m, shape (n1,), periodic with period n1·dx.
        profile2: z2, heights of gear 2's surface, m, shape (n2,), periodic with period n2·dx.
        dx: sample spacing of both profiles, m (> 0).
        scale: roughness scale factor (≥ 0, traced: a design variable). S_j = scale · z_j.
        offset: x_j0 of each profile (shape (2,), m): the surface coordinate of profile sample 0 at
            x = 0, t = 0.

    Sign convention: S_j > 0 is a peak (it reduces the film, h = … − S1 − S2).
    """

    profile1: Float[Array, " n1"] = eqx.field(converter=jnp.asarray)
    profile2: Float[Array, " n2"] = eqx.field(converter=jnp.asarray)
    dx: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=DEFAULT_SPACING)
    scale: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=1.0)
    offset: Float[Array, "2"] = eqx.field(
        converter=lambda v: jnp.asarray(v, dtype=float), default=(0.0, 0.0)
    )

    def __check_init__(self):
        _check_profile("Surfaces.profile1", self.profile1)
        _check_profile("Surfaces.profile2", self.profile2)
        check_positive("Surfaces.dx", self.dx, "m")
        check_non_negative("Surfaces.scale", self.scale)
        check_finite("Surfaces.offset", self.offset)
        if jnp.shape(self.offset) != (2,):
            raise ValueError(
                f"Surfaces.offset has shape {jnp.shape(self.offset)}; valid: shape (2,), one "
                "offset per gear (m)"
            )

    # -- statistics -------------------------------------------------------------------------------
    @property
    def rq(self) -> Float[Array, "2"]:
        """Root-mean-square roughness of each surface (scaled, about its mean), m."""
        return jnp.stack([_rms(self.profile1), _rms(self.profile2)]) * jnp.abs(self.scale)

    @property
    def composite_rq(self) -> Float[Array, ""]:
        """Composite roughness σ = √(Rq1² + Rq2²), m."""
        return jnp.sqrt(jnp.sum(self.rq**2))

    @property
    def rms_slope(self) -> Float[Array, "2"]:
        """Root-mean-square slope Δq of each surface (scaled), rad: of the periodic samples, by
        central differences over 2 dx (so it depends on the sampling unless the profile is
        band-limited well above 2 dx, e.g. by ``short_cutoff``)."""

        def slope(z):
            return _rms((jnp.roll(z, -1) - jnp.roll(z, 1)) / (2.0 * self.dx))

        return jnp.stack([slope(self.profile1), slope(self.profile2)]) * jnp.abs(self.scale)

    # -- moving heights ---------------------------------------------------------------------------
    def height(self, index: int, x, t, velocity) -> Float[Array, ...]:
        """Roughness of surface ``index`` (0: gear 1, 1: gear 2) at contact-frame positions ``x``.

        S_j(x, t) = scale · z_j(x − x_j0 − u_j t): the profile is carried with the surface moving at
        the constant ``velocity`` u_j (m/s) along +x. Periodic cubic B-spline interpolation.

        Args:
            index: 0 or 1 (static).
            x: positions, m, any shape.
            t: time, s (scalar).
            velocity: u_j, m/s (scalar).

        Returns:
            Heights, m, shape of ``x``.
        """
        return self.displaced_height(index, x, velocity * t)

    def displaced_height(self, index: int, x, displacement) -> Float[Array, ...]:
        """S_j = scale · z_j(x − x_j0 − d_j) for a surface displaced by d_j = ∫ u_j dt (m).

        Use this form when u_j varies in time (a gear mesh): carry d_j in the time-stepping state.
        Shapes and units as :meth:`height`.
        """
        if index not in (0, 1):
            raise ValueError(f"index = {index!r} is not valid; valid choices: 0, 1")
        z = self.profile1 if index == 0 else self.profile2
        xi = jnp.asarray(x) - self.offset[index] - displacement
        return self.scale * periodic_cubic_interpolate(z, self.dx, xi)

    def heights(self, x, t, u1, u2) -> tuple[Float[Array, ...], Float[Array, ...]]:
        """(S1, S2) at positions ``x`` (m) and time ``t`` (s) for surface velocities u1, u2
        (m/s)."""
        return self.height(0, x, t, u1), self.height(1, x, t, u2)


def _rms(z):
    return jnp.sqrt(jnp.mean((z - jnp.mean(z)) ** 2))


def _bspline_coefficients(z: Float[Array, " n"]) -> Float[Array, " n"]:
    """Periodic cubic B-spline coefficients c with (c[i-1] + 4 c[i] + c[i+1]) / 6 = z[i]."""
    n = z.shape[0]
    k = jnp.arange(n // 2 + 1)
    symbol = (4.0 + 2.0 * jnp.cos(2.0 * jnp.pi * k / n)) / 6.0  # ≥ 1/3: always invertible
    return jnp.fft.irfft(jnp.fft.rfft(z) / symbol, n=n)


def periodic_cubic_interpolate(z: Float[Array, " n"], dx, xi) -> Float[Array, ...]:
    """Periodic cubic B-spline interpolant of samples ``z`` (spacing ``dx``, sample i at i·dx) at
    ``xi``.

    C² in ``xi``, exact at the samples; differentiable in z, dx and xi. Units follow z and xi.
    """
    z = jnp.asarray(z)
    n = z.shape[0]
    c = _bspline_coefficients(z)
    s = jnp.asarray(xi) / dx
    i0 = jnp.floor(s)
    f = s - i0
    i0 = i0.astype(jnp.int32)
    w = (
        (1.0 - f) ** 3 / 6.0,
        (3.0 * f**3 - 6.0 * f**2 + 4.0) / 6.0,
        (-3.0 * f**3 + 3.0 * f**2 + 3.0 * f + 1.0) / 6.0,
        f**3 / 6.0,
    )
    out = jnp.zeros_like(f)
    for m, wm in zip(range(-1, 3), w):
        out = out + wm * c[jnp.mod(i0 + m, n)]
    return out


_GAUSSIAN_FILTER_ALPHA = math.sqrt(math.log(2.0) / math.pi)  # ISO 16610-21: 50 % at the cutoff


def gaussian_filter_transmission(n: int, dx, cutoff) -> Float[Array, " n//2+1"]:
    """Amplitude transmission of the ISO 16610-21 Gaussian low-pass profile filter of cutoff
    wavelength ``cutoff`` (m) at the rfft bins of a periodic profile of ``n`` samples at spacing
    ``dx``: exp(−π (α λs f)²), f = k/(n dx), α = √(ln 2/π), so 50 % at f = 1/λs. ``cutoff`` 0 passes
    everything."""
    f = jnp.arange(n // 2 + 1) / (n * dx)
    return jnp.exp(-jnp.pi * (_GAUSSIAN_FILTER_ALPHA * cutoff * f) ** 2)


def exponential_psd(n: int, dx, correlation_length) -> Float[Array, " n//2+1"]:
    """Discrete power spectrum (rfft bins) of the periodised autocorrelation exp(−|τ|/β), β = ℓ/ln
    10.

    Normalised so that white noise of unit variance filtered by √psd has unit variance.
    """
    beta = correlation_length / math.log(10.0)
    m = jnp.arange(n)
    lag = dx * jnp.minimum(m, n - m)
    acf = jnp.exp(-lag / beta)
    # The DFT of a positive-definite sequence is ≥ 0; clip round-off.
    return jnp.maximum(jnp.fft.rfft(acf).real, 0.0)


def gaussian_profile(
    key: jax.Array,
    n: int = DEFAULT_POINTS,
    dx: float = DEFAULT_SPACING,
    rq: float = 0.4e-6,
    correlation_length: float = DEFAULT_CORRELATION_LENGTH,
    short_cutoff: float | None = None,
) -> Float[Array, " n"]:
    """Synthetic Gaussian roughness profile with exponential autocorrelation (REFERENCE §6).

    White noise (``jax.random.normal(key, (n,))``) is filtered in Fourier space by the square root
    of the discrete spectrum of R(τ) = exp(−|τ|/β), β = ℓ / ln 10 (so R(ℓ) = 0.1). The mean is
    removed and the profile is rescaled so that its sample Rq equals ``rq`` exactly; the
    autocorrelation shape is a statistical property of the ensemble (the expected periodic
    autocorrelation is exactly R; with ``short_cutoff``, R smoothed at scales below λs).

    Args:
        key: ``jax.random`` key (reproducible: the same key gives the same profile).
        n: number of samples (static).
        dx: spacing, m.
        rq: target root-mean-square height, m (≥ 0).
        correlation_length: ℓ, 10 % decay length of the autocorrelation, m (> 0).
        short_cutoff: λs, m (> 0), or None (no filter): the short-wave cutoff of a stylus
            measurement (ISO 3274: 2.5 µm for ground gears), applied as the ISO 16610-21 Gaussian
            filter (:func:`gaussian_filter_transmission`) before the Rq is set. It should span a
            few samples (λs ≥ 2 dx) to act.

    Returns:
        Heights, m, shape (n,), periodic.
    """
    check_positive("dx", dx, "m")
    check_positive("correlation_length", correlation_length, "m")
    check_non_negative("rq", rq, "m")
    if short_cutoff is not None:
        check_positive("short_cutoff", short_cutoff, "m")
    if not isinstance(n, int | np.integer) or n < 4:
        raise ValueError(f"n = {n!r} is not valid; valid range: integer ≥ 4")
    cutoff = 0.0 if short_cutoff is None else short_cutoff
    return _gaussian_profile(key, n, dx, rq, correlation_length, cutoff)


@functools.partial(jax.jit, static_argnums=1)
def _gaussian_profile(key, n, dx, rq, correlation_length, cutoff):
    noise = jax.random.normal(key, (n,), dtype=jnp.result_type(float))
    psd = exponential_psd(n, dx, correlation_length)
    gain = jnp.sqrt(psd) * gaussian_filter_transmission(n, dx, cutoff)
    z = jnp.fft.irfft(jnp.fft.rfft(noise) * gain, n=n)
    z = z - jnp.mean(z)
    return rq * z / _rms(z)


def _seeded_pair(seed, n, dx, rq, correlation_length, short_cutoff=None):
    k1, k2 = jax.random.split(jax.random.PRNGKey(seed))
    return (
        gaussian_profile(k1, n, dx, rq, correlation_length, short_cutoff),
        gaussian_profile(k2, n, dx, rq, correlation_length, short_cutoff),
    )


def synthetic(
    rq: float,
    *,
    scale=1.0,
    seed: int = 0,
    n: int = DEFAULT_POINTS,
    dx: float = DEFAULT_SPACING,
    correlation_length: float = DEFAULT_CORRELATION_LENGTH,
    short_cutoff: float | None = None,
) -> Surfaces:
    """Two independent synthetic Gaussian profiles of Rq ``rq`` (m) each, seeded by ``seed``
    (``short_cutoff``: the stylus short-wave cutoff λs, m, or None; see :func:`gaussian_profile`)."""
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ValueError(f"seed = {seed!r} is out of range; valid range: integer >= 0")
    z1, z2 = _seeded_pair(seed, n, dx, rq, correlation_length, short_cutoff)
    return Surfaces(profile1=z1, profile2=z2, dx=dx, scale=scale)


def ground(scale=1.0, seed: int = 0, **kwargs) -> Surfaces:
    """Ground gear surfaces (paper's baseline): Rq 0.40 µm per surface, ℓ 20 µm [typical, REFERENCE
    §6]."""
    return synthetic(0.40e-6, scale=scale, seed=seed, **kwargs)


def polished(scale=1.0, seed: int = 0, **kwargs) -> Surfaces:
    """Polished gear surfaces: Rq 0.05 µm per surface, ℓ 20 µm [typical, REFERENCE §6]."""
    return synthetic(0.05e-6, scale=scale, seed=seed, **kwargs)


def smooth(n: int = DEFAULT_POINTS, dx: float = DEFAULT_SPACING) -> Surfaces:
    """Smooth surfaces: zero heights, with the same pytree structure and shapes as
    :func:`ground`."""
    z = jnp.zeros(n)
    return Surfaces(profile1=z, profile2=z, dx=dx, scale=1.0)


def load_profile(path: str | os.PathLike, dx: float = DEFAULT_SPACING) -> np.ndarray:
    """Read a measured profile and resample it onto a uniform grid of spacing ``dx`` (m).

    The file holds two whitespace- or comma-separated columns: position (m), height (m); lines
    starting with ``#`` are comments. Positions must be strictly increasing. The profile is linearly
    interpolated onto x0, x0 + dx, … (as many samples as fit in the measured span) and its mean
    removed. The result is used as one period of a periodic profile.

    Returns:
        Heights, m, shape (n,) (NumPy array).

    Raises:
        ValueError: missing file, wrong column count, non-numeric or non-finite values,
            non-increasing positions, a span shorter than 3 dx, or heights that look like µm
            rather than m.
    """
    check_positive("dx", dx, "m")
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ValueError(f"roughness profile file {path!r} does not exist")
    try:
        with open(path) as fh:
            text = fh.read().replace(",", " ")
        rows = [
            ln.split() for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")
        ]
        data = np.array([[float(v) for v in r] for r in rows], dtype=float)
    except ValueError as err:
        raise ValueError(
            f"roughness profile file {path!r}: could not parse numbers ({err}); expected "
            "two columns: position (m), height (m)"
        ) from None
    if data.ndim != 2 or data.shape[1] != 2 or data.shape[0] < 4:
        shape = data.shape if data.ndim == 2 else (len(rows),)
        raise ValueError(
            f"roughness profile file {path!r} has shape {shape}; valid: at least 4 rows of two "
            "columns, position (m) and height (m)"
        )
    if not np.all(np.isfinite(data)):
        raise ValueError(f"roughness profile file {path!r} contains non-finite values")
    x, z = data[:, 0], data[:, 1]
    if np.any(np.diff(x) <= 0.0):
        raise ValueError(f"roughness profile file {path!r}: positions must be strictly increasing")
    span = x[-1] - x[0]
    n = int(np.floor(span / dx + 1e-9)) + 1
    if n < 4:
        raise ValueError(
            f"roughness profile file {path!r} spans {span:g} m; valid: at least 3 dx = {3 * dx:g} m"
        )
    if np.max(np.abs(z)) > 1e-3:
        raise ValueError(
            f"roughness profile file {path!r}: heights up to {np.max(np.abs(z)):g} m; "
            "heights must be in metres (valid range: |z| ≤ 1e-3 m; convert µm to m)"
        )
    zi = np.interp(x[0] + dx * np.arange(n), x, z)
    return zi - zi.mean()


def from_files(
    path1: str | os.PathLike,
    path2: str | os.PathLike,
    *,
    dx: float = DEFAULT_SPACING,
    scale=1.0,
) -> Surfaces:
    """Surfaces from two measured profile files (see :func:`load_profile`)."""
    return Surfaces(
        profile1=load_profile(path1, dx), profile2=load_profile(path2, dx), dx=dx, scale=scale
    )
