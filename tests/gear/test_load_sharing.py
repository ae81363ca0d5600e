"""Quasi-static load sharing and static TE: closed forms, REFERENCE §6 values, gradients."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
from jaxgear.gear.load_sharing import share_load


def _between(mesh, geo, lo, hi):
    ang = np.asarray(mesh.roll_angle)
    return (ang > float(lo) + 1e-4) & (ang < float(hi) - 1e-4)


@pytest.fixture(scope="module")
def paper_mesh():
    pair = jg.presets.li2015_pair()
    return pair, jg.gear_geometry(pair), jg.mesh_cycle(pair, 700.0, 256)


def test_shares_sum_to_one_and_single_contact(paper_mesh):
    pair, geo, mesh = paper_mesh
    np.testing.assert_allclose(mesh.load_share.sum(axis=1), 1.0, atol=1e-10)
    np.testing.assert_allclose(mesh.normal_load.sum(axis=1), mesh.total_load, rtol=1e-10)
    # Single-tooth contact: slot 0 between the lowest and highest points of single contact.
    lo = geo.roll_angle_lowest_single
    hi = geo.roll_angle_highest_single
    single = _between(mesh, geo, lo, hi)
    assert single.sum() > 10
    np.testing.assert_allclose(mesh.load_share[single, 0], 1.0, atol=1e-9)


def test_closed_form_two_pairs():
    # Both pairs loaded: k1(d − e1) + k2(d − e2) = W → d = (W + k1 e1 + k2 e2)/(k1 + k2).
    k = jnp.asarray([2.1e8, 1.7e8])
    e = jnp.asarray([3e-6, 1e-6])
    w = 9000.0
    d, loads, km = share_load(k, e, jnp.ones(2), w)
    d_ref = (w + float(k[0] * e[0] + k[1] * e[1])) / float(k.sum())
    assert float(d) == pytest.approx(d_ref, rel=1e-9)
    np.testing.assert_allclose(loads, k * (d_ref - e), rtol=1e-7)
    assert float(km) == pytest.approx(float(k.sum()), rel=1e-9)
    # A pair whose relief exceeds the approach carries nothing (beyond the 0.02 µm smoothing).
    d2, loads2, _ = share_load(k, jnp.asarray([200e-6, 0.0]), jnp.ones(2), w)
    assert float(d2) == pytest.approx(w / float(k[1]), rel=1e-9)
    assert float(loads2[0]) < 1e-6 * w


def test_reference_constant_stiffness_sharing():
    # REFERENCE §6 [computed] with a constant pair stiffness (ISO, 2.8e8 N/m) and sharp corners:
    # share 0.38 at the path ends, ~0.5 at 17.2°, ph ≈ 0.76 / 0.85 / 1.18 / 0.83 GPa at
    # 14.5° / 17.2° / single contact / 25°. Tolerance 0.01 on shares and 2 % on ph: the reference
    # figures are rounded to two digits and used k = 2.8e8 where ISO gives 2.81e8.
    pair = jg.presets.li2015_pair()
    geo = jg.gear_geometry(pair)
    mesh = jg.mesh_cycle(pair, 700.0, 4096, stiffness="iso", edge_width=0.0)
    ang = np.degrees(np.asarray(mesh.roll_angle))
    s0 = np.asarray(mesh.load_share[:, 0])
    ph0 = np.asarray(mesh.hertz_pressure[:, 0])
    assert s0[0] == pytest.approx(0.38, abs=0.01)
    i17 = np.argmin(np.abs(ang - 17.2))
    assert s0[i17] == pytest.approx(0.5, abs=0.02)
    assert ph0[0] / 1e9 == pytest.approx(0.76, rel=0.02)
    assert ph0[i17] / 1e9 == pytest.approx(0.85, rel=0.02)
    mid_single = np.argmin(np.abs(ang - math.degrees(float(geo.roll_angle_pitch))))
    assert ph0[mid_single] / 1e9 == pytest.approx(1.18, rel=0.02)
    # 25° on gear 1: the same tooth in slot 1, 7.2° (one base pitch) after the slot-0 angle.
    ang1 = ang + math.degrees(float(geo.base_pitch / geo.base_radius[0]))
    i25 = np.argmin(np.abs(ang1 - 25.0))
    assert mesh.hertz_pressure[i25, 1] / 1e9 == pytest.approx(0.83, rel=0.02)


def test_relief_lowers_te_variation_and_end_shares():
    relieved = jg.presets.li2015_pair(tip_relief=10e-6)
    plain = jg.presets.li2015_pair(tip_relief=0.0)
    mr = jg.mesh_cycle(relieved, 700.0, 512)
    mp = jg.mesh_cycle(plain, 700.0, 512)
    p2p = lambda m: float(jnp.max(m.static_te) - jnp.min(m.static_te))
    assert p2p(mr) < p2p(mp)
    # Near the start of the path (slot 0, a few positions in), the entering pair carries less.
    idx = 8
    assert float(mr.load_share[idx, 0]) < float(mp.load_share[idx, 0]) - 0.05


@pytest.mark.parametrize("which", ["amount", "start"])
def test_gradients_match_finite_differences(which):
    base = jg.presets.li2015_pair(tip_relief=10e-6)
    m = 64
    idx = 10  # a double-contact position, slot 0 inside gear 2's relief zone

    def outputs(value):
        tr = base.tip_relief
        if which == "amount":
            tr = jg.TipRelief(amount=value, start_roll_angle=tr.start_roll_angle, shape=tr.shape)
        else:
            tr = jg.TipRelief(amount=tr.amount, start_roll_angle=value, shape=tr.shape)
        pair = jg.GearPair(
            teeth=base.teeth,
            module=base.module,
            pressure_angle=base.pressure_angle,
            face_width=base.face_width,
            tip_radius=base.tip_radius,
            root_radius=base.root_radius,
            centre_distance=base.centre_distance,
            backlash=base.backlash,
            bearings=base.bearings,
            tip_relief=tr,
        )
        mesh = jg.mesh_cycle(pair, 700.0, m)
        return jnp.stack(
            [mesh.load_share[idx, 0], mesh.static_te[idx] * 1e6, jnp.std(mesh.static_te) * 1e6]
        )

    x0 = 10e-6 if which == "amount" else math.radians(20.9)
    h = 1e-8 if which == "amount" else 1e-5
    jac = jax.jacfwd(outputs)(jnp.asarray(x0))
    fd = (outputs(jnp.asarray(x0 + h)) - outputs(jnp.asarray(x0 - h))) / (2 * h)
    # Central differences in float64 on a smooth map: 1e-5 relative (truncation ~h², round-off
    # ~1e-16/h relative to the values).
    np.testing.assert_allclose(jac, fd, rtol=1e-5, atol=1e-8 * float(jnp.max(jnp.abs(fd))))
    assert float(jnp.max(jnp.abs(jac))) > 0


def test_pair_without_tip_relief_has_a_finite_mesh_where_the_path_meets_a_tip():
    # A GearPair's default relief starts at the tip: no length. At a position where the contact
    # stands exactly on a tip (here τ = 0 of a 23/47 pair with profile shifts, where the path
    # starts at gear 2's tip to the last bit) its 0/0 once made the whole position NaN; the
    # unshifted pair missed it only by round-off. With no relief the mesh must be the unrelieved
    # one everywhere: finite, shares summing to 1 and no relief separation in the static TE.
    pair = jg.GearPair(
        teeth=(23, 47),
        module=4e-3,
        pressure_angle=math.radians(25.0),
        face_width=0.03,
        profile_shift=(0.3, -0.1),
    )
    mesh = jg.mesh_cycle(pair, 700.0, 32)
    for name in ("mesh_stiffness", "static_te", "te_excitation", "normal_load"):
        assert np.all(np.isfinite(np.asarray(getattr(mesh, name)))), name
    np.testing.assert_allclose(mesh.load_share.sum(axis=1), 1.0, atol=1e-10)
    # single contact at τ = 0 (slot 0 only just touching): W = k (d − 0), e = 0 there
    k = float(mesh.pair_stiffness[0, 1])
    assert float(mesh.static_te[0]) == pytest.approx(float(mesh.total_load) / k, rel=1e-6)
