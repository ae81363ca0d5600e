"""Tooth stiffness: numerical potential-energy integration against Tian's closed-form α-integrals,
ISO 6336 values, and the ISO sanity band of REFERENCE §6."""

import math

import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import quad

import jaxgear as jg
from jaxgear.gear.stiffness import (
    base_half_angle,
    iso_mesh_stiffness,
    iso_single_stiffness,
    pair_stiffness,
    tooth_compliances,
)


def _tian_compliances(e_mod, nu, width, a1, a2):
    """Tian (2004) closed α-integrals for a tooth whose root is its base circle (independent of the
    library's integration over the involute geometry)."""
    den = lambda a: math.sin(a) + (a2 - a) * math.cos(a)
    bend = quad(
        lambda a: (
            3
            * (1 + math.cos(a1) * ((a2 - a) * math.sin(a) - math.cos(a))) ** 2
            * (a2 - a)
            * math.cos(a)
            / (2 * e_mod * width * den(a) ** 3)
        ),
        -a1,
        a2,
        epsabs=0,
        epsrel=1e-12,
    )[0]
    shear = quad(
        lambda a: (
            1.2 * (1 + nu) * (a2 - a) * math.cos(a) * math.cos(a1) ** 2 / (e_mod * width * den(a))
        ),
        -a1,
        a2,
        epsabs=0,
        epsrel=1e-12,
    )[0]
    axial = quad(
        lambda a: (a2 - a) * math.cos(a) * math.sin(a1) ** 2 / (2 * e_mod * width * den(a)),
        -a1,
        a2,
        epsabs=0,
        epsrel=1e-12,
    )[0]
    return bend, shear, axial


@pytest.mark.parametrize("roll_deg", [16.0, 20.0, 24.0, 27.0])
def test_potential_energy_matches_tian_closed_form(roll_deg):
    # Root on the base circle, so the library's straight root section has zero length and both
    # descriptions model the same tooth.
    base = jg.presets.li2015_pair()
    rb = 0.075 * math.cos(math.radians(20))
    pair = jg.GearPair(
        teeth=(50, 50),
        module=3e-3,
        pressure_angle=math.radians(20),
        face_width=0.02,
        tip_radius=0.078,
        root_radius=rb,
        centre_distance=0.15,
        bearings=base.bearings,
    )
    eps = math.radians(roll_deg)
    parts = tooth_compliances(pair, 0, jnp.asarray(eps))
    a2 = float(base_half_angle(pair)[0])
    ref = _tian_compliances(207e9, 0.3, 0.02, eps - a2, a2)
    # 24-point Gauss-Legendre against adaptive quadrature: agreement to 1e-6 relative.
    assert float(parts["bending"]) == pytest.approx(ref[0], rel=1e-6)
    assert float(parts["shear"]) == pytest.approx(ref[1], rel=1e-6)
    assert float(parts["axial"]) == pytest.approx(ref[2], rel=1e-6)


def test_iso_single_and_mesh_stiffness_paper_pair():
    pair = jg.presets.li2015_pair()
    geo = jg.gear_geometry(pair)
    # REFERENCE §6 [computed]: c' ≈ 14.05 N/(mm µm), cγα ≈ 22.0 N/(mm µm).
    assert float(iso_single_stiffness(pair)) / 1e9 == pytest.approx(14.05, rel=2e-3)
    assert float(iso_mesh_stiffness(pair, geo)) / pair.face_width / 1e9 == pytest.approx(
        22.0, rel=3e-3
    )


def test_mean_mesh_stiffness_in_iso_sanity_band():
    pair = jg.presets.li2015_pair()
    mesh = jg.mesh_cycle(pair, 700.0, 256)
    km_mean = float(jnp.mean(mesh.mesh_stiffness))
    # REFERENCE §6: a mean mesh stiffness of 3-4.4e8 N/m is the sanity band for this pair
    # (potential-energy models typically land below ISO's 4.4e8).
    assert 3.0e8 <= km_mean <= 4.4e8, km_mean
    iso = jg.mesh_cycle(pair, 700.0, 256, stiffness="iso")
    assert 3.0e8 <= float(jnp.mean(iso.mesh_stiffness)) <= 5.0e8


def test_pair_stiffness_symmetry_and_shape():
    pair = jg.presets.li2015_pair()
    geo = jg.gear_geometry(pair)
    s = jnp.linspace(geo.path_start, geo.path_end, 21)
    k = pair_stiffness(pair, geo, s)
    # Equal gears: the pair stiffness is symmetric about the middle of the line of action.
    np.testing.assert_allclose(
        k, pair_stiffness(pair, geo, geo.line_of_action_length - s), rtol=1e-10
    )
    # Largest near mid-path, smallest where one tooth is loaded at its tip.
    assert float(k[10]) > float(k[0]) * 1.2
    # All compliance terms scale with 1/face width: doubling the width doubles the stiffness.
    wide = jg.GearPair(
        teeth=(50, 50),
        module=3e-3,
        pressure_angle=math.radians(20),
        face_width=0.04,
        tip_radius=0.078,
        root_radius=0.070,
        centre_distance=0.15,
    )
    np.testing.assert_allclose(pair_stiffness(wide, geo, s), 2 * k, rtol=1e-10)


def test_km_and_static_te_periodic_and_continuous():
    pair = jg.presets.li2015_pair()

    def max_jump(m, edge):
        mc = jg.mesh_cycle(pair, 700.0, m, edge_width=edge)
        km = np.asarray(mc.mesh_stiffness)
        te = np.asarray(mc.static_te)
        # Wrap-around included: the cycle is periodic.
        return (
            np.max(np.abs(np.diff(np.append(km, km[0])))) / km.mean(),
            np.max(np.abs(np.diff(np.append(te, te[0])))) / te.mean(),
        )

    smooth_coarse, smooth_fine = max_jump(256, 0.01), max_jump(1024, 0.01)
    sharp_coarse, sharp_fine = max_jump(256, 0.0), max_jump(1024, 0.0)
    # Continuous: the largest step between neighbours shrinks with the spacing (factor 4 in M gives
    # 3-3.5× smaller steps here, → 4× once the 0.01-pitch edge ramp is resolved; ≥ 2.5× asked);
    # with sharp tooth corners the step stays (~0.45 of the mean: a true jump).
    assert smooth_fine[0] < smooth_coarse[0] / 2.5 and smooth_fine[1] < smooth_coarse[1] / 2.5
    assert sharp_fine[0] > 0.8 * sharp_coarse[0]
