"""Elastic deformation of a line contact on a uniform grid (Hertz-scaled variables).

With X = x/b, P = p/ph and H = h R/b², the elastic displacement of the two half-spaces under a
pressure P(X) enters the film as V(X) = −(1/π) ∫ P(X') ln|X − X'| dX' (plus a constant absorbed by
the film offset H0). With P piecewise constant on cells of width Δ centred on the nodes, the cell
integral is exact: ∫ over a cell of ln|X_i − s| ds = F(u+) − F(u−), F(u) = u ln|u| − u,
u± = X_i − X_j ± Δ/2. On a uniform grid this is Δ (ln Δ + k(i − j)) with the unit-grid kernel
k(m) = F(m + ½) − F(m − ½): a symmetric Toeplitz matrix built once per node count.

Two ways to apply it, equal to round-off: the dense matrix (O(N²)) and DC-FFT (discrete convolution
by zero-padded FFT, Liu, Wang & Liu, Wear 243 (2000) 101-111; O(N log N)).
"""

from __future__ import annotations

import functools

import jax.numpy as jnp
import numpy as np


def _f(u):
    au = np.abs(u)
    return np.where(au > 0, u * np.log(np.where(au > 0, au, 1.0)), 0.0) - u


@functools.lru_cache(maxsize=32)
def unit_kernel(n: int) -> np.ndarray:
    """k(m) = ∫_{m−½}^{m+½} ln|t| dt for m = 0 … n−1 (float64 NumPy, cached per n)."""
    m = np.arange(n, dtype=np.float64)
    return _f(m + 0.5) - _f(m - 0.5)


@functools.lru_cache(maxsize=16)
def unit_matrix(n: int) -> np.ndarray:
    """Dense Toeplitz matrix k(|i − j|), shape (n, n)."""
    k = unit_kernel(n)
    idx = np.arange(n)
    return k[np.abs(idx[:, None] - idx[None, :])]


def influence_matrix(n: int, spacing):
    """Dense influence matrix D with (D @ P)_i = −(1/π) Σ_j P_j ∫_cell j ln|X_i − s| ds.

    Args:
        n: number of nodes (static).
        spacing: Δ, node spacing in Hertz half-widths (traced).

    Returns:
        (n, n) array; the film is H = H0 + X²/2 + D @ P.
    """
    k = jnp.asarray(unit_kernel(n))
    idx = jnp.arange(n)
    k0 = k[
        jnp.abs(idx[:, None] - idx[None, :])
    ]  # gathered at run time: no N² constant in the program
    return -(spacing / jnp.pi) * (k0 + jnp.log(spacing))


def influence_vector(n: int, spacing, pad: int = 0):
    """The Toeplitz generator d(m) of ``influence_matrix`` (D[i, j] = d(i − j)) for
    m = −(n − 1 + pad) … n − 1 + pad, as a 1-D array of length 2(n + pad) − 1."""
    k = unit_kernel(n + pad)
    full = np.concatenate([k[:0:-1], k])
    return -(spacing / jnp.pi) * (jnp.asarray(full) + jnp.log(spacing))


def influence_rows(n: int, spacing, before: int = 0, after: int = 0):
    """Rows i = −before … n − 1 + after of the Toeplitz influence matrix (D[i, j] = d(i − j), j =
    0 … n − 1), shape (n + before + after, n): the rows outside 0 … n − 1 are those of the same
    kernel continued past the grid (what a shifted stencil reads)."""
    pad = max(before, after)
    d = influence_vector(n, spacing, pad=pad)  # d(m), m = −(n − 1 + pad) … n − 1 + pad
    i = jnp.arange(-before, n + after)
    j = jnp.arange(n)
    return d[(i[:, None] - j[None, :]) + (n - 1 + pad)]


def deformation_dense(pressure, spacing):
    """V = D @ P with the dense influence matrix (Hertz-scaled)."""
    return influence_matrix(pressure.shape[-1], spacing) @ pressure


def deformation_fft(pressure, spacing):
    """V = D @ P by DC-FFT: the Toeplitz product as a circular convolution of length 2n (exact for
    the
    discrete problem, O(n log n))."""
    n = pressure.shape[-1]
    k = unit_kernel(n)
    circ = np.concatenate([k, [0.0], k[:0:-1]])  # k(0..n−1), pad, k(n−1..1)
    k_hat = jnp.asarray(np.fft.rfft(circ))
    p_hat = jnp.fft.rfft(jnp.concatenate([pressure, jnp.zeros_like(pressure)]), n=2 * n)
    conv = jnp.fft.irfft(k_hat * p_hat, n=2 * n)[:n]
    return -(spacing / jnp.pi) * (conv + jnp.log(spacing) * jnp.sum(pressure))
