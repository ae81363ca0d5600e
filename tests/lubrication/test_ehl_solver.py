"""The EHL solver on the paper's gear contacts: convergence, load balance, Hertz limit, squeeze,
warm
starts, batching, retracing, robustness and bad input.

Most tests share one model (``STANDARD``: 129 nodes, Roelands, Dowson-Higginson, the paper's Eyring
η*) so the suite compiles it once; accuracy against film formulas is in ``test_ehl_validation.py``.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import dimensionless, gear_contact, moes_contact, pan_hamrock

import jaxgear as jg

STANDARD = jg.EHLModel(n_nodes=129)
LUB = jg.presets.mil_l_23699()


@pytest.fixture(scope="module")
def pitch_solution():
    return jg.solve_ehl(gear_contact(), LUB, STANDARD)


def test_pitch_contact_converges_balances_load_and_cavitates_without_negative_pressure(
    pitch_solution,
):
    s = pitch_solution
    c = gear_contact()
    assert bool(s.converged)
    assert float(s.residual) < STANDARD.tolerance
    # load balance: trapezoidal ∫ p dx against w' (the bordered Newton row), to 1e-6 relative
    w = float(c.load_per_width)
    x, p = np.asarray(s.x), np.asarray(s.p)
    assert abs(np.trapezoid(p, x) / w - 1.0) < 1e-6
    # cavitation by complementarity: the smoothed FB keeps P·(−R) = δ²/2 > 0, so pressures stay
    # non-negative up to the smoothing (δ ph).
    ph = float(c.hertz_pressure)
    assert p.min() > -STANDARD.smoothing(rough=False) * ph
    # the outlet holds a cavitated zone (p ≈ 0 downstream of the contact) and the minimum film lies
    # at the outlet constriction, below the central film
    b = float(c.hertz_half_width)
    assert np.all(p[x > 1.2 * b] < 1e-3 * ph)
    assert float(s.h_min) < float(s.h_central)
    assert x[np.argmin(np.asarray(s.h))] > 0.5 * b
    for field in ("p", "h", "heat_flux", "friction_sliding", "damping", "power_loss"):
        assert np.all(np.isfinite(np.asarray(getattr(s, field))))


def test_power_split_and_friction_signs(pitch_solution):
    s = pitch_solution
    c = gear_contact()
    # paper Eq. (15): Fs = ∫ η*(u2 − u1)/h dx has the sign of u2 − u1 (here u1 > u2)
    assert float(s.friction_sliding) < 0.0
    # the paper's η* caps the shear stress below τ0 (REFERENCE §4): |Fs| < τ0 × (wetted length)
    length = float(s.x[-1] - s.x[0])
    assert abs(float(s.friction_sliding)) < float(LUB.eyring_stress) * length
    # sliding heat equals the sliding friction power, both from η*: ∫ η* us²/h = |Fs| |us|
    us = float(c.u1 - c.u2)
    assert float(s.power_loss_sliding) == pytest.approx(
        abs(float(s.friction_sliding)) * abs(us), 1e-9
    )
    assert float(s.power_loss) == pytest.approx(
        float(s.power_loss_sliding) + float(s.power_loss_rolling), rel=1e-12
    )
    assert float(s.damping) > 0.0


def test_high_load_pressure_tends_to_hertz():
    # 1500 N m at 500 rpm: M ≈ 156 (computed below), close to a dry Hertzian contact. 257 nodes (129
    # collapse the film at this M, which the solver then reports as not converged).
    c = gear_contact(torque=1500.0, rpm=500.0, slide_to_roll=0.0)
    _, _, _, m, _ = dimensionless(c, LUB)
    assert m > 150
    s = jg.solve_ehl(c, LUB, jg.EHLModel(n_nodes=257))
    assert bool(s.converged)
    ph, b = float(c.hertz_pressure), float(c.hertz_half_width)
    x = np.asarray(s.x) / b
    p = np.asarray(s.p) / ph
    core = np.abs(x) < 0.8
    # Hertz ellipse √(1 − X²) within 5 % of ph in the core; compressible Roelands: small spike,
    # so p_max within 5 % of ph
    assert np.max(np.abs(p[core] - np.sqrt(1 - x[core] ** 2))) < 0.05
    assert float(s.p_max) / ph == pytest.approx(1.0, abs=0.05)
    assert abs(float(s.load_error)) < 1e-6


def test_squeeze_step_direction_and_magnitude(pitch_solution):
    """Load steps up by 20 % over one backward-Euler step Δt.

    Expected: the film in the contact (mean of h over |x| < b) falls from the old steady value
    towards
    the new one; the squeeze term delays it, so the step lands in between, monotone in Δt. As Δt → 0
    the lubricant content ρh is frozen (mass conservation); as Δt → ∞ the step is the new steady
    solution. In between, the film relaxes like ḣ = −(h − h_new)/τ with τ of the order of the time
    the
    lubricant takes to cross the contact (a few b/um). (The central film alone is not monotone: the
    squeeze pressure is centre-peaked and dents the film, the entrapment effect.)
    """
    old = pitch_solution
    c_old = gear_contact()
    c_new = eqx.tree_at(lambda c: c.load_per_width, c_old, c_old.load_per_width * 1.2)
    new = jg.solve_ehl(c_new, LUB, STANDARD)
    b, um = float(c_new.hertz_half_width), float(c_new.rolling_velocity)
    xs = np.linspace(-b, b, 401)

    def mean(sol, field="h"):
        return np.interp(xs, np.asarray(sol.x), np.asarray(getattr(sol, field))).mean()

    h_old, h_new = mean(old), mean(new)
    assert h_new < h_old
    t_ref = b / um
    steps = {}
    for factor in (1e-5, 0.5, 2.0, 1e5):
        s = jg.solve_ehl(c_new, LUB, STANDARD, previous=old, time_step=factor * t_ref)
        assert bool(s.converged)
        assert abs(float(s.load_error)) < 1e-6  # load balance holds in the transient step too
        steps[factor] = s
    h = {k: mean(v) for k, v in steps.items()}
    # direction: between the old and the new steady films, monotone in Δt
    assert h_new < h[1e5] <= h[2.0] < h[0.5] < h[1e-5] < h_old
    # Δt → 0: ρh frozen; what remains is the linear interpolation of the previous ρh onto this
    # step's
    # nodes (b grew by √1.2, 129 nodes): 5e-3. Δt → ∞: the steady solution.
    assert mean(steps[1e-5], "rho_h") == pytest.approx(mean(old, "rho_h"), rel=5e-3)
    assert h[1e5] == pytest.approx(h_new, rel=1e-4)
    # magnitude: a single time constant τ fitted to the Δt = 0.5 b/um step predicts the change at
    # Δt = 2 b/um. The response has more than one time scale (inlet and contact transits), so the
    # one-constant model is a ±25 % estimate of the change; τ must be a few transit times.
    frac = (h[1e-5] - h[0.5]) / (h[1e-5] - h_new)  # = (Δt/τ)/(1 + Δt/τ)
    tau = 0.5 * t_ref * (1 - frac) / frac
    frac2 = (2.0 * t_ref / tau) / (1 + 2.0 * t_ref / tau)
    assert (h[1e-5] - h[2.0]) == pytest.approx(frac2 * (h[1e-5] - h_new), rel=0.25)
    assert 0.3 < tau / t_ref < 30.0


def test_warm_start_matches_cold_with_fewer_iterations(pitch_solution):
    # neighbouring mesh position: load +3 %, radius +2 %, speed +1 %
    c = gear_contact(torque=721.0, rpm=2020.0, radius=1.02 * 12.826e-3)
    cold = jg.solve_ehl(c, LUB, STANDARD)
    warm = jg.solve_ehl(c, LUB, STANDARD, initial=pitch_solution)
    assert bool(warm.converged) and bool(cold.converged)
    # the same discrete solution (both converged to ‖F‖∞ < 1e-9)
    assert float(warm.h_central) == pytest.approx(float(cold.h_central), rel=1e-7)
    assert float(warm.friction_sliding) == pytest.approx(float(cold.friction_sliding), rel=1e-7)
    assert int(warm.iterations) <= 6 < int(cold.iterations)


ROBUST_CASES = [
    # (M, L, slide-to-roll): corners of M 1-1000, L 1-20, SR 0-2 (SR = 2: one surface at rest)
    (1.0, 1.0, 0.0),
    (1.0, 20.0, 2.0),
    (1000.0, 1.0, 1.0),
    (1000.0, 20.0, 0.0),
    (30.0, 10.0, 2.0),
    (300.0, 5.0, 0.5),
]


def _stack(contacts):
    return jax.tree.map(lambda *xs: jnp.stack(xs), *contacts)


@eqx.filter_jit
@eqx.debug.assert_max_traces(max_traces=1)
def _batched(contacts):
    return jax.vmap(lambda c: jg.solve_ehl(c, LUB, STANDARD))(contacts)


def test_vmap_equals_loop_one_trace_and_robust_corners():
    contacts = [moes_contact(m, l, LUB, sr) for m, l, sr in ROBUST_CASES]
    # a few nanometre film: the paper's pair at 100 N m and 10 rpm (Pan-Hamrock h_min ≈ 5 nm)
    contacts += [gear_contact(100.0, rpm=10.0, slide_to_roll=1.0), gear_contact(rpm=4200.0)]
    batch = _batched(_stack(contacts))
    status_differs = 0
    for i, c in enumerate(contacts):
        single = jg.solve_ehl(c, LUB, STANDARD)
        if bool(batch.converged[i]) != bool(single.converged):
            # batched and single LU differ at round-off; on a case at the edge of the iteration cap
            # that can flip the outcome. Allowed once, on the extreme corners only.
            assert i < len(ROBUST_CASES), i
            status_differs += 1
            continue
        if not bool(single.converged):
            continue  # an unconverged iterate is not a solution: only its status must agree
        # same algorithm per member: vmap must agree with the loop to round-off
        for field in ("h_central", "h_min", "friction_sliding", "power_loss"):
            a, b = float(getattr(batch, field)[i]), float(getattr(single, field))
            assert a == pytest.approx(b, rel=1e-6, abs=1e-12 * max(abs(b), 1e-30)), (i, field)
        # residuals agree to round-off (they are ~1e-14 when converged)
        assert abs(float(batch.residual[i]) - float(single.residual)) < 1e-3 * STANDARD.tolerance
    assert status_differs <= 1
    # robustness: never NaN; converged or honestly reported with its residual
    for field in ("p", "h", "h_min", "friction_sliding", "power_loss", "residual"):
        assert np.all(np.isfinite(np.asarray(getattr(batch, field)))), field
    conv = np.asarray(batch.converged)
    res = np.asarray(batch.residual)
    assert np.all(res[conv] < STANDARD.tolerance)
    closed = np.min(np.asarray(batch.h), axis=1) <= 0.0
    # a failure is reported either by its residual or by a closed film (under-resolved high M on
    # this 129-node grid: the film collapses, and the solver says so instead of returning it)
    assert np.all((res >= STANDARD.tolerance) | closed | conv)
    # the moderate corners and both gear contacts converge on this grid
    assert np.all(conv[[0, 1, 4, 6, 7]]), (conv, res)
    # the thin-film case is a few nanometres and converged
    assert bool(conv[-2]) and 1e-9 < float(batch.h_min[-2]) < 2e-8
    # a converged solution has an open film everywhere (closed films are reported as failures)
    assert np.all(np.asarray(batch.h)[conv] > 0)
    # second call with other values must not retrace (assert_max_traces would raise)
    contacts2 = [
        eqx.tree_at(lambda c: c.load_per_width, c, c.load_per_width * 1.1) for c in contacts
    ]
    _batched(_stack(contacts2))


def test_light_load_thick_film_at_engagement_entry_converges_on_any_inlet():
    """The first contact of a tooth pair's engagement at 3500 rpm: 102 N m of the 700 on that pair,
    the radius and slide-to-roll of the path's entry (M ≈ 4.2, L ≈ 6.6), the paper's physics,
    257 nodes. Both continuation attempts used to fail here (the engagement benchmark's smooth
    thermal passage lost its first step): from the Hertz start at a quarter of the piezo-viscous
    exponent, Newton let the film offset run away (to 10³ µm on −7 … 1.5 half-widths; ‖F‖∞ ≈ 0.08
    on the default domain). The cold attempt without continuation converges."""
    c = gear_contact(torque=102.3, rpm=3500.0, slide_to_roll=-0.6, radius=11.66e-3)
    _, _, _, m, l = dimensionless(c, LUB)
    assert 4.0 < m < 4.5 and 6.3 < l < 6.8  # the regime this test is about
    hmin_ph, hc_ph = pan_hamrock(c, LUB)
    films = []
    for kw in (dict(), dict(x_in=-7.0, auto_domain=False)):
        s = jg.solve_ehl(c, LUB, jg.EHLModel(n_nodes=257, **kw))
        assert bool(s.converged), (kw, float(s.residual))
        # measured: h_min +1.1 %, h_c −2.1 % of Pan-Hamrock; REFERENCE §8 expects ~5 % and ~10 %
        # for Roelands + Dowson-Higginson
        assert float(s.h_min) == pytest.approx(hmin_ph, rel=0.05)
        assert float(s.h_central) == pytest.approx(hc_ph, rel=0.10)
        films.append(float(s.h_central))
    # a solution, not an artefact of the domain: the longer inlet changes h_c by 0.7 % (measured)
    assert films[1] == pytest.approx(films[0], rel=0.015)
    hot = jg.solve_ehl(c, LUB, jg.EHLModel(n_nodes=257, thermal=True))
    assert bool(hot.converged), (float(hot.residual), float(hot.thermal_residual))
    # shear heating thins the film (measured −3.5 %)
    assert float(hot.h_central) < films[0]


@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(load_per_width=-1.0), "LineContact.load_per_width"),
        (dict(reduced_radius=0.0), "LineContact.reduced_radius"),
        (dict(u1=float("nan")), "LineContact.u1"),
        (dict(e_reduced=-2e11), "LineContact.e_reduced"),
        (dict(inlet_temperature=1000.0), "LineContact.inlet_temperature"),
        (dict(u1=-3.0, u2=1.0), "LineContact.u1, u2"),
    ],
)
def test_bad_contact_raises_naming_the_field(kwargs, field):
    base = dict(reduced_radius=0.0128, load_per_width=5e5, u1=5.0, u2=4.0)
    with pytest.raises(ValueError, match=field.replace(".", r"\.")):
        jg.LineContact(**{**base, **kwargs})


def test_bad_model_and_arguments_raise():
    with pytest.raises(ValueError, match="EHLModel.viscosity"):
        jg.EHLModel(viscosity="sutherland")
    with pytest.raises(ValueError, match="EHLModel.n_nodes"):
        jg.EHLModel(n_nodes=4)
    with pytest.raises(ValueError, match="EHLModel.shear"):
        jg.EHLModel(shear="carreau")
    with pytest.raises(
        ValueError, match=r"EHLModel\.thermal_rtol = 0 is out of range; valid range: \(0, 0\.5\]"
    ):
        jg.EHLModel(thermal_rtol=0.0)
    with pytest.raises(
        ValueError, match=r"EHLModel\.thermal_atol = -1 is out of range; valid range: \(0, 10\]"
    ):
        jg.EHLModel(thermal_atol=-1.0)
    c = gear_contact()
    with pytest.raises(ValueError, match="surfaces"):
        jg.solve_ehl(c, LUB, STANDARD, surfaces="ground")
    with pytest.raises(ValueError, match="time_step"):
        jg.solve_ehl(c, LUB, STANDARD, previous=object())
    with pytest.raises(ValueError, match="time_step"):
        jg.solve_ehl(c, LUB, STANDARD, previous=object(), time_step=-1.0)


def test_float32_is_refused_with_a_clear_error():
    # a fresh interpreter without x64: the solver must refuse rather than return float32 garbage
    import subprocess
    import sys

    code = (
        "import jaxgear as jg\n"
        "c = jg.LineContact(reduced_radius=0.0128, load_per_width=5e5, u1=5.0, u2=4.0)\n"
        "try:\n"
        "    jg.solve_ehl(c, jg.presets.mil_l_23699())\n"
        "except ValueError as e:\n"
        "    print('ValueError:', e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert "ValueError" in out.stdout and "float64" in out.stdout, out.stdout + out.stderr


@pytest.mark.parametrize("n_nodes", [65, 257])
def test_thick_film_below_the_robust_range_stays_finite(n_nodes):
    """M ≪ 1 (10 N m at 20000 rpm in 20 °C oil: M ≈ 0.05, L ≈ 28) is below the solver's range
    (M 1-1000): the film is ~500 Hertz units thick and the domain widens to ~200 half-widths, so a
    coarse grid holds no node inside the Hertz zone. Regression: the cold start normalised an empty
    Hertz ellipse (0/0) and every output was NaN. Now: converged, or flagged with a finite
    residual, and every output finite."""
    c = moes_contact(0.05, 28.0, LUB, slide_to_roll=0.1, t_in=293.15)
    s = jg.solve_ehl(c, LUB, jg.EHLModel(n_nodes=n_nodes))
    for leaf in jax.tree_util.tree_leaves(s):
        assert np.all(np.isfinite(np.asarray(leaf)))
    assert bool(s.converged) or float(s.residual) >= jg.EHLModel().tolerance


def test_default_solids_first_built_inside_a_trace_do_not_leak():
    """solve_ehl caches its default (steel, steel) pair. Regression: when the cache was first
    filled inside a jit trace it held that trace's tracers, and the next call of the same
    compiled function failed ("Execution supplied 21 arguments but compiled program expected
    24")."""
    from jaxgear.lubrication.ehl.solve import _default_solids

    _default_solids.cache_clear()
    model = jg.EHLModel(n_nodes=65)
    f = eqx.filter_jit(lambda c: jg.solve_ehl(c, LUB, model).h_central)
    c = gear_contact()
    assert float(f(c)) == float(f(c))
    assert float(jg.solve_ehl(c, LUB, model).h_central) == pytest.approx(float(f(c)), rel=1e-12)


@pytest.mark.slow
def test_rolling_heat_converges_with_the_grid():
    # (slow: ~20-40 s, two fine solves.) The Poiseuille (rolling) heat of paper Eq. 12 at 1000 rpm, SRR 0.3: on 257 and 513 nodes
    # 146.4 and 148.2 W/m (measured; 1025 and 2049 nodes: 148.6, 148.8). Bound 3 % between the
    # two grids, the second-order discretisation's change being ~1 %. What it guards: with the
    # complementarity smoothed at δ = 1e-6 ph (the default until 2026-11-29) the first node past
    # the inlet's P = 0 sat at ~3 kPa on every grid, and the Poiseuille heat of that one-cell jump
    # under the thick inlet film grew as 1/Δx: 158.6 / 191.6 / 308.4 / 753.8 W/m on 257-2049
    # nodes (21 % between these two). The pressure there must follow the inlet's own gradient,
    # so it halves with the cell (measured 508 and 254 Pa); bound: below 0.6 of the coarser's.
    c = gear_contact(rpm=1000.0, slide_to_roll=0.3)
    sols = [jg.solve_ehl(c, LUB, jg.EHLModel(n_nodes=n)) for n in (257, 513)]
    assert all(bool(s.converged) for s in sols)
    coarse, fine = (float(s.power_loss_rolling) for s in sols)
    assert abs(fine - coarse) < 0.03 * fine
    first = [float(s.p[1]) for s in sols]
    assert 0.0 < first[1] < 0.6 * first[0]
