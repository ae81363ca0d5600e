"""The ehl_formula rung (closed-form mixed EHL) against the EHL solver it stands in for, its limits,
gradients, and the coupled model on it.

The solver is the independent reference: the closed-form model evaluates published closed forms
(Pan-Hamrock film, Greenwood-Tripp asperity pressure, Eyring traction over a Hertz pressure,
Goksem-Hargreaves rolling traction) and never calls it."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import E_REDUCED, FACE_WIDTH, gear_contact

import jaxgear as jg
from jaxgear.lubrication.ehl_formula import ehl_formula_contact

LUB = jg.presets.mil_l_23699()
GROUND = jg.presets.ground()


def _closed_form(contact, surfaces, **kw):
    c = contact
    return ehl_formula_contact(
        c.reduced_radius,
        c.load_per_width,
        c.u1,
        c.u2,
        c.e_reduced,
        LUB,
        c.inlet_temperature,
        surfaces.composite_rq,
        **kw,
    )


# (torque N m, rpm, slide-to-roll, inlet K): the paper's pitch contact from slow to fast, light to
# heavy load, 60 and 90 °C; film parameter λ from ~0.15 to ~0.8 (asperity share 1-16 %).
CASES = [
    (700.0, 500.0, 0.3, 363.15),
    (700.0, 3300.0, 0.3, 363.15),
    (1500.0, 2500.0, 0.3, 363.15),
    (700.0, 2500.0, 0.3, 333.15),
    (300.0, 4200.0, 0.5, 363.15),
    (200.0, 500.0, 0.3, 363.15),
    (1500.0, 4200.0, 0.3, 333.15),
]


@pytest.fixture(scope="module")
def solved():
    mixed = jg.EHLModel(n_nodes=257, mixed="statistical")
    out = []
    for torque, rpm, sr, t_in in CASES:
        c = gear_contact(torque, rpm, sr, t_in=t_in)
        s = jg.solve_ehl(c, LUB, mixed, GROUND)
        assert bool(s.converged)
        out.append((c, s, _closed_form(c, GROUND)))
    return out


def test_asperity_load_and_fluid_traction_match_statistical_mixed_ehl(solved):
    # Measured (257 nodes): asperity load −0.4 … +19 %, fluid traction −12.5 … +3.6 %, damping the
    # same, sliding loss +0.1 … +17 %. The largest errors are all at the deepest mixed contact
    # (200 N m, 500 rpm: λ = 0.14, 23 % of the load on the asperities), whose central average gap
    # the closed form's fitted thickening puts 6 % below the solver's (0.338 against 0.359 σ);
    # elsewhere within 11, 4, 4 and 7 %. The closed forms also leave out the outlet constriction
    # and the local coupling of asperity and fluid pressure. Bounds: 0.22, 0.15, 0.15, 0.2.
    for c, s, a in solved:
        w = float(c.load_per_width)
        us = abs(float(c.u1 - c.u2))
        wa_ehl = float(s.contact_load_share) * w
        assert float(a.asperity_load) == pytest.approx(wa_ehl, rel=0.22)
        fluid_ehl = (float(s.power_loss_sliding) - float(s.power_loss_asperity)) / us
        fluid = float(a.power_sliding) / us - abs(float(a.friction_asperity))
        assert fluid == pytest.approx(fluid_ehl, rel=0.15)
        assert float(a.damping) == pytest.approx(float(s.damping), rel=0.15)
        assert float(a.power_sliding) == pytest.approx(float(s.power_loss_sliding), rel=0.2)
        # signs of paper Eq. 15: sliding friction along u2 − u1, rolling friction positive
        assert np.sign(float(a.friction_sliding)) == np.sign(float(s.friction_sliding))
        assert float(a.friction_rolling) > 0 and float(s.friction_rolling) > 0


def test_rolling_loss_matches_the_solvers_poiseuille_heat(solved):
    # Goksem-Hargreaves against the solver's ∫ φx h³ p'²/(12 η*) dx: measured −6 … +13 % (sliding
    # thins η* and adds Poiseuille heat the formula, fitted to
    # rolling contacts, does not have). Its load exponent (W′^0.0126) is weaker than the solver's with
    # Roelands and Dowson-Higginson: under at 1500 N m, over at 200 N m. The rolling loss is 3-25 %
    # of the total at these contacts, so this bounds the total's error by ~4 %.
    for _, s, a in solved:
        assert float(a.power_rolling) == pytest.approx(float(s.power_loss_rolling), rel=0.2)


def test_limits():
    c = gear_contact(700.0, 2000.0, 0.3)
    smooth = _closed_form(c, jg.presets.smooth())
    assert float(smooth.asperity_load) == 0.0 and float(smooth.friction_asperity) == 0.0
    # film parameter λ ≈ 3 (polished, 4200 rpm): asperity contact negligible
    fast = _closed_form(gear_contact(700.0, 4200.0, 0.3), jg.presets.polished())
    assert 0.0 <= float(fast.asperity_load) < 1e-3 * float(c.load_per_width)
    # pure rolling: no sliding friction or sliding loss; the rolling loss stays
    roll = _closed_form(gear_contact(700.0, 2000.0, 0.0), GROUND)
    assert float(roll.friction_sliding) == 0.0 and float(roll.power_sliding) == 0.0
    assert float(roll.power_rolling) > 0.0
    # reversing the sliding reverses the sliding friction and keeps the losses
    u1, u2 = float(c.u1), float(c.u2)
    fwd = _closed_form(c, GROUND)
    back = ehl_formula_contact(
        c.reduced_radius, c.load_per_width, u2, u1, E_REDUCED, LUB, 363.15, GROUND.composite_rq
    )
    assert float(back.friction_sliding) == pytest.approx(-float(fwd.friction_sliding), rel=1e-12)
    assert float(back.power_sliding) == pytest.approx(float(fwd.power_sliding), rel=1e-12)
    # sliding loss is the friction work: Φs = Fs (u2 − u1)
    assert float(fwd.power_sliding) == pytest.approx(
        float(fwd.friction_sliding) * (u2 - u1), rel=1e-12
    )
    # λ → 0 (roughness ×20): the asperities carry at most the load, everything finite
    rough = _closed_form(c, jg.presets.ground(scale=20.0), density_product=1.0)
    assert 0.0 < float(rough.asperity_load) <= float(c.load_per_width)
    assert all(np.isfinite(float(x)) for x in jax.tree_util.tree_leaves(rough))


def test_shear_laws_order():
    # η* (paper) caps the fluid shear stress at τ0, exact Eyring grows like asinh, Newtonian without
    # bound: the fluid traction must order the same way at a sliding contact.
    c = gear_contact(700.0, 2000.0, 0.3)
    smooth = jg.presets.smooth()
    f = {law: abs(float(_closed_form(c, smooth, shear=law).friction_sliding)) for law in
         ("eyring_paper", "eyring_exact", "newtonian")}  # fmt: skip
    assert f["eyring_paper"] < f["eyring_exact"] < f["newtonian"]
    # η* traction is below τ0 times the Hertz width
    b = float(c.reduced_radius) * np.sqrt(
        8 * float(c.load_per_width) / (E_REDUCED * float(c.reduced_radius)) / np.pi
    )
    assert f["eyring_paper"] < float(LUB.eyring_stress) * 2 * b


def test_gradients_against_central_differences():
    c = gear_contact(700.0, 2000.0, 0.3)

    def loss(w, rq, t_in):
        a = ehl_formula_contact(
            c.reduced_radius, w, c.u1, c.u2, E_REDUCED, LUB, t_in, rq, boundary_friction=0.1
        )
        return a.power_sliding + a.power_rolling

    args = (jnp.asarray(float(c.load_per_width)), GROUND.composite_rq, jnp.asarray(363.15))
    grads = jax.grad(loss, argnums=(0, 1, 2))(*args)
    for i, step in enumerate((1e2, 1e-10, 1e-3)):
        plus = list(args)
        minus = list(args)
        plus[i] = args[i] + step
        minus[i] = args[i] - step
        fd = (float(loss(*plus)) - float(loss(*minus))) / (2 * step)
        # smooth closed forms: central differences agree to their truncation, ~1e-6 here
        assert float(grads[i]) == pytest.approx(fd, rel=1e-5), i


def test_coupled_rung_consistency_and_fast_preset():
    assert jg.Fidelity.fast().friction == "ehl_formula"
    assert jg.Fidelity.fast().models_rolling and not jg.Fidelity.fast().uses_ehl
    pair = jg.presets.li2015_pair_calibrated()
    op = jg.OperatingPoint(torque=700.0, speed_rpm=2500.0, inlet_temperature=363.15)
    qs = jg.simulate(pair, LUB, GROUND, op, jg.Fidelity.fast(dynamics="quasi_static"))
    td = jg.simulate(pair, LUB, GROUND, op, jg.Fidelity.fast())
    for r in (qs, td):
        assert bool(r.converged)
        assert float(r.power_loss) == pytest.approx(
            float(r.power_loss_sliding) + float(r.power_loss_rolling), rel=1e-12
        )
        # the sliding loss is the friction forces' work at the surface velocities (Eq. 15, 16)
        u = np.asarray(r.surface_velocity)
        fs_work = np.asarray(r.power_sliding_pair)
        assert float(r.power_loss_rolling) > 0.0 and np.all(fs_work >= 0.0)
        assert np.all(np.asarray(r.damping) >= 0.0)
        assert np.all(np.isfinite(u))
    # the quasi-static cycle's loss from the per-contact closed forms, summed here independently
    mesh = jg.mesh_cycle(pair, torque=700.0, n_positions=32)
    omega = 2500.0 * 2 * np.pi / 60
    rho = np.asarray(mesh.radius_of_curvature)
    load = np.asarray(mesh.normal_load)
    total = 0.0
    for i in range(32):
        for j in range(2):
            if load[i, j] > 0:
                a = ehl_formula_contact(
                    float(mesh.reduced_radius[i, j]), load[i, j] / FACE_WIDTH,
                    rho[i, j, 0] * omega, rho[i, j, 1] * omega, E_REDUCED, LUB, 363.15,
                    GROUND.composite_rq, sign_width=0.01 * (rho[i, j, 0] + rho[i, j, 1]) * omega,
                )  # fmt: skip
                total += (float(a.power_sliding) + float(a.power_rolling)) * FACE_WIDTH
    assert float(qs.power_loss) == pytest.approx(total / 32, rel=1e-9)


# REFERENCE §7 R3 around the lower resonance and below the higher one, at the fast preset (this
# rung; 9-13 % above Fidelity.paper()'s Φ̄ over the baseline sweep, benchmarks/fast_vs_paper.py):
# the tribo-dynamic loss lower than the quasi-static one at A and D, higher at B (the paper 257
# against 276 W at A, 343 against 302 W at B, 431 against 526 W at D). The calibrated pair's DTE
# peaks sit at 1750 and 3375 rpm, so A 1700, B 1800, D 3325 rpm, as `jaxgear figures` places them
# on the paper's 25 rpm grid; all three have a stable periodic orbit (status 0), so these are
# orbits, not attractor means. The reference is what the dynamics did not produce: the same
# contacts at the static loads and kinematic velocities. Measured (2026-11-25, again 2026-12-01):
# A −3.30 %, B +3.96 %, D −12.24 % (the paper fidelity −2.2, +5.7, −10.7 %, docs/figures/paper).
# Point E (the paper +78 %) is not reproduced at this preset (README); it is tested at the
# calibrated one (tests/paper/test_paper_calibrated.py, slow). Same inputs as the test above, so the
# compiled simulate is reused when both run in one process.
R3_POINTS = {"A": 1700.0, "B": 1800.0, "D": 3325.0}


@pytest.fixture(scope="module")
def r3_ratios():
    pair = jg.presets.li2015_pair_calibrated()
    ratios = {}
    for name, rpm in R3_POINTS.items():
        op = jg.OperatingPoint(torque=700.0, speed_rpm=rpm, inlet_temperature=363.15)
        td = jg.simulate(pair, LUB, GROUND, op, jg.Fidelity.fast())
        qs = jg.simulate(pair, LUB, GROUND, op, jg.Fidelity.fast(dynamics="quasi_static"))
        assert int(td.status) == 0 and int(qs.status) == 0, (name, int(td.status))
        ratios[name] = float(td.power_loss) / float(qs.power_loss)
    return ratios


# Margins: the signs of R3 with room for the fixed point's tolerance (tables to 1e-4 of their
# largest entry) and for the rung's few-percent difference from the paper fidelity, whose ratios
# at A, B, D are within 0.8 points of these; not the paper's magnitudes (A −7 %, B +14 %, D −18 %),
# which the model does not claim at these points.
def test_r3_tribo_dynamic_loss_below_quasi_static_at_a(r3_ratios):
    assert r3_ratios["A"] < 0.99, r3_ratios


def test_r3_tribo_dynamic_loss_above_quasi_static_at_b(r3_ratios):
    assert r3_ratios["B"] > 1.01, r3_ratios


def test_r3_tribo_dynamic_loss_well_below_quasi_static_at_d(r3_ratios):
    assert r3_ratios["D"] < 0.95, r3_ratios


def test_slivers_of_load_at_the_relief_edge_carry_nothing():
    # Tip relief can leave a slot with a load like 1e-289 N (10 N m, 50 µm relief: found by the
    # extremes matrix). The closed forms have no meaning there (unbounded film, 0/0 in the asperity
    # share); the rung counts a slot as loaded above 1e-4 of the total load, as the EHL rungs do.
    from jaxgear.contact import formula_ehl_contact_forces, kinematic_velocities
    from jaxgear.contact.base import LOADED_SHARE

    pair = jg.presets.li2015_pair_calibrated()
    mesh = jg.mesh_cycle(pair, torque=700.0, n_positions=8)
    velocity = kinematic_velocities(pair, mesh, 2500.0 * 2 * np.pi / 60)
    total = float(mesh.total_load)
    load = np.asarray(mesh.normal_load).copy()
    slivers = [1e-289, 1e-30, 0.5 * LOADED_SHARE * total]
    load[: len(slivers), 1] = slivers
    forces = formula_ehl_contact_forces(
        pair, LUB, GROUND, mesh, jg.Fidelity.fast(), jnp.asarray(load),
        velocity[..., 0], velocity[..., 1], 363.15,
    )  # fmt: skip
    for name in ("friction_sliding", "friction_rolling", "damping", "power_sliding"):
        arr = np.asarray(getattr(forces, name))
        assert np.all(np.isfinite(arr)), name
        np.testing.assert_array_equal(arr[: len(slivers), 1], 0.0, err_msg=name)
    np.testing.assert_array_equal(np.asarray(forces.power_rolling)[: len(slivers), 1], 0.0)
    # a slot just above the threshold is a loaded contact with a finite, positive loss
    load[0, 1] = 2.0 * LOADED_SHARE * total
    forces = formula_ehl_contact_forces(
        pair, LUB, GROUND, mesh, jg.Fidelity.fast(), jnp.asarray(load),
        velocity[..., 0], velocity[..., 1], 363.15,
    )  # fmt: skip
    assert 0.0 < float(forces.power_rolling[0, 1]) < np.inf
    assert np.isfinite(float(forces.power_sliding[0, 1]))
