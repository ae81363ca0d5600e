"""Elastic deformation kernel against quadrature, DC-FFT against dense, and the Hertz line
contact."""

import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import quad

from jaxgear.lubrication import deformation


def test_unit_kernel_against_quadrature():
    k = deformation.unit_kernel(6)
    for m in range(6):
        # ∫_{m−½}^{m+½} ln|t| dt, singular at t = 0 for m = 0 (split there)
        if m == 0:
            ref = 2 * quad(np.log, 0.0, 0.5)[0]
        else:
            ref = quad(lambda t: np.log(abs(t)), m - 0.5, m + 0.5)[0]
        assert k[m] == pytest.approx(ref, abs=1e-12)


@pytest.mark.parametrize("n", [17, 128, 1025])
def test_dc_fft_equals_dense(n):
    rng = np.random.default_rng(0)
    p = jnp.asarray(rng.random(n))
    spacing = 6.0 / (n - 1)
    dense = deformation.deformation_dense(p, spacing)
    fft = deformation.deformation_fft(p, spacing)
    # same discrete convolution; FFT round-off ~ n ε max|V|
    assert np.max(np.abs(np.asarray(fft - dense))) < 1e-12 * n * np.max(np.abs(np.asarray(dense)))


def test_hertz_pressure_gives_the_hertz_gap():
    # P = √(1 − X²) (load π/2) must give a flat film inside |X| < 1 and, outside, the classical
    # Hertz
    # line-contact gap G(X) = ½[|X|√(X² − 1) − ln(|X| + √(X² − 1))] (K.L. Johnson, Contact
    # Mechanics,
    # §5.6, in Hertz-scaled units). Error O(Δ) from piecewise-constant pressure cells.
    n = 1201
    x = np.linspace(-3.0, 3.0, n)
    spacing = x[1] - x[0]
    p = np.sqrt(np.clip(1 - x**2, 0, None))
    h = 0.5 * x**2 + np.asarray(deformation.deformation_dense(jnp.asarray(p), spacing))
    h = h - h[n // 2]
    inside = np.abs(x) < 0.95
    assert np.max(np.abs(h[inside])) < 2 * spacing
    out = np.abs(x) > 1.05
    ax = np.abs(x[out])
    gap = 0.5 * (ax * np.sqrt(ax**2 - 1) - np.log(ax + np.sqrt(ax**2 - 1)))
    assert np.max(np.abs(h[out] - gap)) < 2 * spacing
    # and the result is not trivially flat: the gap at |X| = 3 is ~3.3
    assert gap.max() > 3.0
