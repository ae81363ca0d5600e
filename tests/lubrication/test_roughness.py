"""Rough surfaces: profile statistics, moving heights, file loading, validation."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
from jaxgear.lubrication import roughness as rough


def _circular_acf(z):
    z = np.asarray(z) - np.mean(z)
    n = z.size
    return np.fft.irfft(np.abs(np.fft.rfft(z)) ** 2, n) / n / np.var(z)


def test_rq_and_mean_match_target():
    # Rq is normalised exactly after mean removal (documented): tolerance is round-off.
    for seed in range(3):
        z = rough.gaussian_profile(jax.random.PRNGKey(seed), 4096, 0.5e-6, 0.4e-6, 20e-6)
        z = np.asarray(z)
        assert abs(z.mean()) < 1e-12 * 0.4e-6
        assert np.std(z) == pytest.approx(0.4e-6, rel=1e-12)
    s = jg.presets.ground()
    assert np.allclose(np.asarray(s.rq), 0.40e-6, rtol=1e-12)
    assert float(s.composite_rq) == pytest.approx(math.sqrt(2.0) * 0.40e-6, rel=1e-12)
    assert float(jg.presets.polished().composite_rq) == pytest.approx(
        math.sqrt(2.0) * 0.05e-6, rel=1e-12
    )


def test_autocorrelation_is_exponential_with_target_length():
    # Ensemble of 8 profiles of 16.4 mm (32768 × 0.5 µm). The standard error of a circular ACF
    # estimate is ≈ √(2β/L)/√8 ≈ 0.012 (β = ℓ/ln10 = 8.7 µm), so an absolute tolerance of 0.04 on
    # the ACF is ≈ 3.5 σ, and the 10 % decay length (σ ≈ 1 µm, 5 %) is held to 15 %.
    n, dx, ell = 32768, 0.5e-6, 20e-6
    beta = ell / math.log(10.0)
    acfs = [
        _circular_acf(rough.gaussian_profile(jax.random.PRNGKey(100 + s), n, dx, 1e-6, ell))
        for s in range(8)
    ]
    acf = np.mean(acfs, axis=0)
    lags = dx * np.arange(int(3 * ell / dx))
    np.testing.assert_allclose(acf[: lags.size], np.exp(-lags / beta), atol=0.04)
    i = int(np.argmax(acf < 0.1))  # first lag below 10 %
    crossing = dx * (i - 1 + (acf[i - 1] - 0.1) / (acf[i - 1] - acf[i]))
    assert crossing == pytest.approx(ell, rel=0.15)


def test_reproducible_with_seed():
    a = jg.presets.ground(seed=7)
    b = jg.presets.ground(seed=7)
    c = jg.presets.ground(seed=8)
    assert np.array_equal(np.asarray(a.profile1), np.asarray(b.profile1))
    assert np.array_equal(np.asarray(a.profile2), np.asarray(b.profile2))
    assert not np.allclose(np.asarray(a.profile1), np.asarray(c.profile1))
    # the two gears' profiles are independent draws
    assert abs(np.corrcoef(np.asarray(a.profile1), np.asarray(a.profile2))[0, 1]) < 0.1


def test_scale_scales_heights_exactly():
    s1 = jg.presets.ground(scale=1.0, seed=3)
    s2 = jg.presets.ground(scale=2.5, seed=3)
    x = jnp.linspace(0.0, 300e-6, 257)
    h1 = s1.height(0, x, 1e-5, 3.0)
    h2 = s2.height(0, x, 1e-5, 3.0)
    np.testing.assert_allclose(np.asarray(h2), 2.5 * np.asarray(h1), rtol=1e-14, atol=1e-25)
    assert np.allclose(np.asarray(s2.rq), 2.5 * np.asarray(s1.rq), rtol=1e-14)
    # d S / d scale = S / scale (linear), through jit
    g = jax.jit(jax.grad(lambda sc: jnp.sum(eqx_replace_scale(s1, sc).height(1, x, 0.0, 1.0))))
    assert float(g(1.7)) == pytest.approx(float(jnp.sum(s1.height(1, x, 0.0, 1.0))), rel=1e-12)


def eqx_replace_scale(s, scale):
    return rough.Surfaces(s.profile1, s.profile2, s.dx, scale, s.offset)


def test_interpolation_exact_at_samples_and_accurate_between():
    dx = 0.5e-6
    n = 512
    period = n * dx
    xs = dx * np.arange(n)
    z = 1e-6 * np.sin(2 * np.pi * 8 * xs / period)  # 64 samples per wavelength
    # exact at samples
    out = rough.periodic_cubic_interpolate(jnp.asarray(z), dx, jnp.asarray(xs))
    np.testing.assert_allclose(np.asarray(out), z, atol=1e-12 * 1e-6)
    # between samples: cubic spline error O((k dx)^4) ≈ 1e-7 relative here; tolerance 1e-5
    xq = np.linspace(-period, 2 * period, 1001) + 0.123 * dx
    out = rough.periodic_cubic_interpolate(jnp.asarray(z), dx, jnp.asarray(xq))
    np.testing.assert_allclose(
        np.asarray(out), 1e-6 * np.sin(2 * np.pi * 8 * xq / period), atol=1e-11
    )


def test_moving_profile_is_carried_with_the_surface():
    s = jg.presets.ground(seed=1)
    x = jnp.linspace(-200e-6, 200e-6, 401)
    for index, u in ((0, 3.1), (1, -1.7)):
        t = 2.3e-5
        np.testing.assert_allclose(
            np.asarray(s.height(index, x, t, u)),
            np.asarray(s.height(index, x - u * t, 0.0, u)),
            rtol=0,
            atol=1e-9 * 0.4e-6,
        )
    # time-varying velocity: the displacement form with d = ∫u dt equals the constant-u form
    np.testing.assert_allclose(
        np.asarray(s.displaced_height(0, x, 3.1 * 2.3e-5)),
        np.asarray(s.height(0, x, 2.3e-5, 3.1)),
        rtol=0,
        atol=1e-12 * 0.4e-6,
    )
    # a whole number m of samples travelled: heights at the samples are the rolled profile
    m = 37
    u = 2.0
    t = m * float(s.dx) / u
    xs = float(s.dx) * jnp.arange(200)
    expect = np.roll(np.asarray(s.profile1), m)[:200]
    np.testing.assert_allclose(np.asarray(s.height(0, xs, t, u)), expect, atol=1e-12 * 0.4e-6)


def test_height_gradients_match_finite_differences():
    s = jg.presets.ground(seed=2)
    x = jnp.linspace(-50e-6, 50e-6, 11)

    def f(t, u):
        return jnp.sum(jnp.sin(1e6 * s.height(1, x, t, u)))

    t0, u0 = 1.3e-5, 2.7
    gt, gu = jax.grad(f, argnums=(0, 1))(t0, u0)
    # Steps shift the profile by 0.27 nm and 0.13 nm (≪ dx = 0.5 µm), so the O((step/dx)²) error of
    # central differences across the spline's piecewise-cubic pieces stays below 1e-6 relative.
    ht, hu = 1e-10, 1e-5
    fd_t = (f(t0 + ht, u0) - f(t0 - ht, u0)) / (2 * ht)
    fd_u = (f(t0, u0 + hu) - f(t0, u0 - hu)) / (2 * hu)
    assert float(gt) == pytest.approx(float(fd_t), rel=1e-5)
    assert float(gu) == pytest.approx(float(fd_u), rel=1e-5)


def test_smooth_is_zero_with_same_structure():
    sm = jg.presets.smooth()
    gr = jg.presets.ground()
    assert jax.tree_util.tree_structure(sm) == jax.tree_util.tree_structure(gr)
    assert [np.shape(a) for a in jax.tree_util.tree_leaves(sm)] == [
        np.shape(a) for a in jax.tree_util.tree_leaves(gr)
    ]
    x = jnp.linspace(-1e-3, 1e-3, 101)
    s1, s2 = sm.heights(x, 1e-4, 2.0, 3.0)
    assert float(jnp.max(jnp.abs(s1))) == 0.0 and float(jnp.max(jnp.abs(s2))) == 0.0
    assert float(sm.composite_rq) == 0.0


def test_vmap_over_scale_equals_loop():
    s = jg.presets.ground(seed=4)
    x = jnp.linspace(0.0, 1e-4, 33)
    scales = jnp.array([0.0, 0.5, 1.0, 2.0])
    f = lambda sc: eqx_replace_scale(s, sc).height(0, x, 0.0, 1.0)
    batched = jax.vmap(f)(scales)
    for i, sc in enumerate(scales):
        np.testing.assert_allclose(np.asarray(batched[i]), np.asarray(f(sc)), rtol=1e-14)


def test_file_round_trip_with_resampling(tmp_path):
    # A known smooth profile sampled non-uniformly in µm-scale steps, saved in metres.
    rng = np.random.default_rng(0)
    x = np.cumsum(rng.uniform(0.2e-6, 0.4e-6, 3000))
    wave = lambda xx: (
        0.3e-6 * np.sin(2 * np.pi * xx / 80e-6) + 0.1e-6 * np.cos(2 * np.pi * xx / 23e-6)
    )
    z = wave(x) + 1e-6  # offset: removed on loading
    path = tmp_path / "profile.txt"
    np.savetxt(path, np.column_stack([x, z]), header="position_m height_m")
    dx = 0.5e-6
    loaded = rough.load_profile(path, dx)
    grid = x[0] + dx * np.arange(loaded.size)
    assert grid[-1] <= x[-1] + 1e-15 and grid[-1] + dx > x[-1]
    expect = wave(grid)
    expect = expect - expect.mean()
    # linear interpolation of data sampled every ≤ 0.4 µm: error ≤ (0.4 µm)²/8 · max|z"| ≈ 1.9e-10
    np.testing.assert_allclose(loaded, expect, atol=2e-10)
    assert abs(loaded.mean()) < 1e-20
    # exact round trip of a profile already on the grid (comma-separated this time)
    s = jg.presets.polished(seed=5)
    p1 = tmp_path / "g1.csv"
    p2 = tmp_path / "g2.csv"
    for p, prof in ((p1, s.profile1), (p2, s.profile2)):
        xs = float(s.dx) * np.arange(prof.shape[0])
        np.savetxt(p, np.column_stack([xs, np.asarray(prof)]), delimiter=",", fmt="%.17e")
    back = rough.from_files(p1, p2, dx=float(s.dx), scale=2.0)
    np.testing.assert_allclose(np.asarray(back.profile1), np.asarray(s.profile1), atol=1e-22)
    np.testing.assert_allclose(np.asarray(back.profile2), np.asarray(s.profile2), atol=1e-22)
    assert float(back.scale) == 2.0


@pytest.mark.parametrize(
    ("content", "match"),
    [
        ("1 2 3\n4 5 6\n7 8 9\n1 1 1\n", "two columns|shape"),
        ("0 1e-7\n1e-6 abc\n2e-6 0\n3e-6 0\n", "could not parse"),
        ("0 0\n2e-6 1e-7\n1e-6 0\n3e-6 0\n", "strictly increasing"),
        ("0 0\n1e-6 0.2\n2e-6 0\n3e-6 0.1\n", "metres"),
        ("0 0\n1e-6 nan\n2e-6 0\n3e-6 0\n", "non-finite"),
        ("0 0\n1e-7 0\n", "shape"),
    ],
)
def test_bad_files_raise(tmp_path, content, match):
    p = tmp_path / "bad.txt"
    p.write_text(content)
    with pytest.raises(ValueError, match=match):
        rough.load_profile(p, 0.5e-6)


def test_missing_file_raises(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        rough.load_profile(tmp_path / "nope.txt")


def test_bad_inputs_raise():
    z = np.zeros(16)
    with pytest.raises(ValueError, match="scale"):
        rough.Surfaces(z, z, 0.5e-6, -1.0)
    with pytest.raises(ValueError, match="dx"):
        rough.Surfaces(z, z, 0.0, 1.0)
    with pytest.raises(ValueError, match="profile1"):
        rough.Surfaces(np.array([0.0, np.nan, 0.0, 0.0]), z, 0.5e-6, 1.0)
    with pytest.raises(ValueError, match="profile2"):
        rough.Surfaces(z, np.zeros((2, 8)), 0.5e-6, 1.0)
    with pytest.raises(ValueError, match="rq"):
        rough.gaussian_profile(jax.random.PRNGKey(0), 64, 0.5e-6, -1e-6)
    with pytest.raises(ValueError, match="correlation_length"):
        rough.gaussian_profile(jax.random.PRNGKey(0), 64, 0.5e-6, 1e-6, 0.0)
    with pytest.raises(ValueError, match="index"):
        jg.presets.smooth().height(2, jnp.zeros(3), 0.0, 1.0)


# -- the stylus short-wave cutoff (ISO 3274 λs, ISO 16610-21 Gaussian filter) ---------------------


def test_short_cutoff_is_the_iso_gaussian_filter():
    # The same white noise with and without the filter: their spectra differ by the transmission
    # times one constant (the Rq normalisation). ISO 16610-21 defines the Gaussian profile filter by
    # 50 % amplitude transmission at the cutoff wavelength and a Gaussian shape, so a wavelength
    # λs/2 passes 0.5⁴. The periodic length 4 mm holds both as rfft bins (k = 1600, 3200).
    # Tolerance: round-off of two FFTs (1e-9 relative).
    n, dx, cutoff = 8000, 0.5e-6, 2.5e-6
    key = jax.random.PRNGKey(3)
    zf = np.fft.rfft(np.asarray(rough.gaussian_profile(key, n, dx, 0.4e-6, 20e-6, cutoff)))
    zu = np.fft.rfft(np.asarray(rough.gaussian_profile(key, n, dx, 0.4e-6, 20e-6)))
    ratio = np.abs(zf[1:]) / np.abs(zu[1:])
    ratio = ratio / ratio[0]  # bin 1: transmission 1 − 4e-7
    assert ratio[1600 - 1] == pytest.approx(0.5, rel=1e-6)
    assert ratio[3200 - 1] == pytest.approx(0.5**4, rel=1e-6)
    # Rq is still set exactly after filtering
    assert np.std(np.fft.irfft(zf, n)) == pytest.approx(0.4e-6, rel=1e-12)


def _filtered_slope_closed_form(rq, beta, cutoff):
    """Δq of the continuum exponential-autocorrelation profile through the Gaussian filter.

    Two-sided spectrum S(f) = 2β Rq² / (1 + (2πβf)²), transmission A(f)² = exp(−a f²),
    a = 2π α² λs²: Δq² = ∫ (2πf)² S A² df = (2 Rq²/β) [√(π/a) − ∫ A²/(1 + (2πβf)²) df], and
    ∫ exp(−a f²)/(1 + b² f²) df = (π/b) exp(a/b²) erfc(√a/b), b = 2πβ. The filter removes a few %
    of the variance, which the Rq normalisation restores: Δq² is divided by the transmitted share
    ∫ S A² df / Rq² = 2β ∫ A²/(1 + b² f²) df, the same integral."""
    alpha = math.sqrt(math.log(2.0) / math.pi)
    a = 2.0 * math.pi * alpha**2 * cutoff**2
    b = 2.0 * math.pi * beta
    tail = math.pi / b * math.exp(a / b**2) * math.erfc(math.sqrt(a) / b)
    slope2 = 2.0 * rq**2 / beta * (math.sqrt(math.pi / a) - tail)
    variance_kept = 2.0 * beta * tail  # ∫ S A² df / Rq²
    return math.sqrt(slope2 / variance_kept)


def test_short_cutoff_gives_a_finite_rms_slope_independent_of_sampling():
    # Unfiltered, the exponential autocorrelation's rms slope grows as 1/√Δx: halving the sample
    # spacing raises it by ~√2. Filtered at λs = 2.5 µm it is the closed form above, whatever the
    # sampling finer than λs/10. Ensemble of 16 profiles 8.2 mm long: one profile's Δq scatters by
    # ≈ 3.5 % (measured over 96 profiles), so the ensemble mean's standard error is ≈ 0.9 % and 4 %
    # is ≈ 4.5 σ. The spectral derivative is exact for the periodic samples; the sampled
    # spectrum's aliasing adds 0.3 % at Δx = 0.25 µm (2.6 % at 0.5 µm, which is why the test
    # samples finer).
    rq, ell, cutoff, length = 0.4e-6, 20e-6, 2.5e-6, 8.192e-3
    beta = ell / math.log(10.0)
    expected = _filtered_slope_closed_form(rq, beta, cutoff)

    def spectral_slope(z, dx):
        k = 2.0 * np.pi * np.fft.rfftfreq(z.size, dx)
        return np.sqrt(np.mean(np.fft.irfft(1j * k * np.fft.rfft(z), z.size) ** 2))

    def mean_slope(dx, cut):
        n = int(round(length / dx))
        keys = [jax.random.PRNGKey(40 + s) for s in range(16)]
        return np.mean(
            [
                spectral_slope(np.asarray(rough.gaussian_profile(k, n, dx, rq, ell, cut)), dx)
                for k in keys
            ]
        )

    for dx in (0.25e-6, 0.125e-6):
        assert mean_slope(dx, cutoff) == pytest.approx(expected, rel=0.04)
    coarse, fine = mean_slope(0.25e-6, None), mean_slope(0.125e-6, None)
    assert fine / coarse == pytest.approx(math.sqrt(2.0), rel=0.05)
    assert coarse > 2.0 * expected


def test_rms_slope_of_a_sine():
    # Central differences over 2 dx of A sin(2π x/λ): A sin(2π dx/λ)/dx · cos(…), rms /√2.
    n, dx, amp = 256, 0.5e-6, 0.3e-6
    lam = n * dx / 8.0
    z = amp * np.sin(2.0 * np.pi * dx * np.arange(n) / lam)
    s = rough.Surfaces(z, 2.0 * z, dx, 0.5)
    exact = amp * np.sin(2.0 * np.pi * dx / lam) / dx / math.sqrt(2.0) * 0.5
    np.testing.assert_allclose(np.asarray(s.rms_slope), [exact, 2.0 * exact], rtol=1e-12)


def test_short_cutoff_passes_through_the_presets():
    a = jg.presets.ground(short_cutoff=2.5e-6)
    b = jg.presets.ground()
    np.testing.assert_allclose(np.asarray(a.rq), 0.40e-6, rtol=1e-12)
    # at the presets' 0.5 µm sampling (measured: 0.14 against 0.19-0.20 rad)
    assert np.all(np.asarray(a.rms_slope) < 0.8 * np.asarray(b.rms_slope))
    with pytest.raises(ValueError, match="short_cutoff"):
        jg.presets.polished(short_cutoff=0.0)


def test_short_cutoff_from_a_sweep_config():
    # the TOML key is in µm (units at the edges); the echo carries it into the sweep's summary
    from jaxgear.cli.config import surfaces_from_config

    surf, echo = surfaces_from_config({"surfaces": {"preset": "ground", "short_cutoff_um": 2.5}})
    ref = jg.presets.ground(short_cutoff=2.5e-6)
    # 2.5 × 1e-6 and 2.5e-6 differ in the last bit: round-off tolerance (1e-18 m of 0.4 µm heights)
    np.testing.assert_allclose(np.asarray(surf.profile1), np.asarray(ref.profile1), atol=1e-18)
    assert echo["short_cutoff_um"] == 2.5
    with pytest.raises(ValueError, match="surfaces.short_cutoff_um"):
        surfaces_from_config({"surfaces": {"short_cutoff_um": -1.0}})
