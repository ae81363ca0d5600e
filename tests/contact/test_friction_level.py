"""The open parameters of the friction level (REFERENCE §4, §6): the Greenwood-Tripp nβσ and σ/β
reach the statistical mixed-EHL rung from ``Fidelity`` and the ``[fidelity]`` TOML table, and act as
the Greenwood-Tripp model says (their sensitivity on the mesh loss:
``benchmarks/friction_sensitivity.py``).

Contacts are the paper's pitch-point contact from ``helpers``; roughness the synthetic ground
(Rq 0.40 µm per surface) and polished (0.05 µm) presets (REFERENCE §6). Every EHLModel is a new
compilation (~25 s of CPU each), so the default run compiles one; the monotone sweep is ``slow``.
"""

import re
import tomllib

import equinox as eqx
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import gear_contact, greenwood_tripp_pressure

import jaxgear as jg
from jaxgear.cli.config import fidelity_from_config, sweep_from_config
from jaxgear.contact.ehl import ehl_model_of

LUB = jg.presets.mil_l_23699()
RANGES = {"asperity_density_product": "[0.0001, 1]", "asperity_slope_ratio": "[1e-06, 1]"}

# The statistical rung at test resolution (65 nodes, iso-thermal), with both parameters well above
# their defaults (K′ ∝ (nβσ)² √(σ/β): 5.7 × the default's), from the TOML route.
TOML = """
[fidelity]
dynamics = "quasi_static"
friction = "ehl_mixed"
n_nodes = 65
n_positions = 24
asperity_density_product = 0.08
asperity_slope_ratio = 0.05
"""


@pytest.fixture(scope="module")
def toml_model():
    fid, _ = fidelity_from_config(tomllib.loads(TOML))
    return ehl_model_of(fid)


# --------------------------------------------------------------------------------------------------
# Validation and the configuration route
# --------------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "field, value",
    [
        ("asperity_density_product", 2.0),
        ("asperity_density_product", 0.0),
        ("asperity_density_product", True),
        ("asperity_slope_ratio", 0.0),
        ("asperity_slope_ratio", 1.5),
        ("asperity_slope_ratio", "0.01"),
    ],
)
def test_asperity_parameters_are_validated_naming_the_field(field, value):
    message = (
        rf"Fidelity\.{field} = {re.escape(repr(value))} is out of range; "
        rf"valid range: {re.escape(RANGES[field])}"
    )
    for build in (jg.Fidelity, jg.Fidelity.paper, jg.Fidelity.fast, jg.Fidelity().replace):
        with pytest.raises(ValueError, match=message):
            build(**{field: value})
    # and from TOML, under the table's name (a wrong type is caught there, before the range)
    with pytest.raises(ValueError, match=rf"fidelity\.{field} = "):
        fidelity_from_config({"fidelity": {field: value}})


def test_range_ends_are_accepted_and_defaults_are_the_solver_defaults():
    for field, (low, high) in {
        "asperity_density_product": (1e-4, 1.0),
        "asperity_slope_ratio": (1e-6, 1.0),
    }.items():
        for value in (low, high):
            assert getattr(ehl_model_of(jg.Fidelity(**{field: value})), field) == value
    # the Fidelity defaults leave the EHL model as it was before the fields existed
    model, solver = ehl_model_of(jg.Fidelity.paper()), jg.EHLModel()
    assert model.asperity_density_product == solver.asperity_density_product == 0.05
    assert model.asperity_slope_ratio == solver.asperity_slope_ratio == 0.01


def test_toml_route_reaches_the_ehl_model(toml_model):
    fid, echo = fidelity_from_config(tomllib.loads(TOML))
    assert (fid.asperity_density_product, fid.asperity_slope_ratio) == (0.08, 0.05)
    assert echo["asperity_density_product"] == 0.08 and echo["asperity_slope_ratio"] == 0.05
    assert toml_model.asperity_density_product == 0.08
    assert toml_model.asperity_slope_ratio == 0.05
    assert toml_model.mixed == "statistical" and toml_model.n_nodes == 65
    # over a preset, and through the whole ``jaxgear sweep`` configuration
    cfg = tomllib.loads(
        '[fidelity]\npreset = "paper"\nasperity_slope_ratio = 0.001\n'
        "[sweep]\nspeeds_rpm = [1800.0]\n"
    )
    sweep = sweep_from_config(cfg)
    assert sweep.fidelity.asperity_slope_ratio == 0.001
    assert sweep.fidelity.asperity_density_product == 0.05  # the default, untouched
    assert ehl_model_of(sweep.fidelity).asperity_slope_ratio == 0.001
    assert sweep.fidelity.friction == "ehl_mixed" and sweep.fidelity.n_nodes == 257
    assert sweep.echo["fidelity"]["asperity_slope_ratio"] == 0.001


# --------------------------------------------------------------------------------------------------
# Physics (one compiled model in the default run)
# --------------------------------------------------------------------------------------------------
def test_deep_mixed_asperity_pressure_is_greenwood_tripp_of_the_given_parameters(toml_model):
    """At a ground contact at 500 rpm (λ ≈ 0.1-0.4: deep mixed) the converged statistical solution
    carries, at every node, the Greenwood-Tripp pressure K′ E′ F_{5/2}(h/σ) of ITS film with the
    parameters given in the TOML (closed form and quadrature here, not the solver's), and not the
    one of the default parameters (5.7 × smaller)."""
    c = gear_contact(rpm=500.0)
    surf = jg.presets.ground()
    sol = jg.solve_ehl(c, LUB, toml_model, surf)
    assert bool(sol.converged), float(sol.residual)
    ph = float(sol.hertz_pressure)
    sigma, e_red = float(surf.composite_rq), float(c.e_reduced)
    given = greenwood_tripp_pressure(sol.h, sigma, e_red, 0.08, 0.05)
    default = greenwood_tripp_pressure(sol.h, sigma, e_red, 0.05, 0.01)
    carried = np.asarray(sol.asperity_pressure)
    # a deep mixed contact: asperities carry a large share of the load (measured 0.47)
    assert float(sol.contact_load_share) > 0.2
    assert carried.max() > 0.1 * ph
    # the asperity pressure is solved with the film (one Newton system): agreement to 1e-6 ph (the
    # library's Gauss-Legendre F_{5/2} against scipy's adaptive quadrature); the default
    # parameters' pressure is off by ~0.3 ph
    assert np.max(np.abs(carried - given)) < 1e-6 * ph
    assert np.max(np.abs(carried - default)) > 0.1 * ph


def test_thick_film_parameters_change_nothing(toml_model):
    """Polished at 8000 rpm (λ ≈ 4: full film) the asperities carry nothing even with K′ 5.7 × the
    default's: the solution equals the one with K′ 64 × smaller (nβσ 0.01) on the same surfaces
    (the same flow factor). Since p_a ∝ K′ at a given film, every K′ between, the defaults
    included, lies between the two: the parameters change nothing there. (Much smaller K′, nβσ ≲
    1e-3, leaves the statistical film without asperity support and its Newton solve fails: a known
    limitation, reported as not converged.)"""
    c = gear_contact(rpm=8000.0)
    rough = jg.solve_ehl(c, LUB, toml_model, jg.presets.polished())
    off = eqx.tree_at(lambda m: m.asperity_density_product, toml_model, jnp.asarray(0.01))
    none = jg.solve_ehl(c, LUB, off, jg.presets.polished())
    assert bool(rough.converged) and bool(none.converged)
    sigma = float(jg.presets.polished().composite_rq)
    lam = float(rough.h_min) / sigma
    assert lam > 3.5, lam
    # The closed-form asperity pressure at the thinnest film bounds the asperity load: p_a/ph below
    # 1e-6 here. Its boundary friction μb p_a over the ~2b contact changes the sliding friction
    # (μ_fluid ≈ 0.005 × the load (π/2) ph b) by < (4/π)(μb/μ_fluid)(p_a/ph) ≈ 3e-5 relative;
    # rtol 1e-4 allows for that.
    pa_max = greenwood_tripp_pressure([rough.h_min], sigma, float(c.e_reduced), 0.08, 0.05)[0]
    assert pa_max < 1e-6 * float(rough.hertz_pressure)
    assert float(rough.contact_load_share) < 1e-5
    for name in ("friction_sliding", "power_loss_sliding", "power_loss_rolling", "h_central"):
        np.testing.assert_allclose(getattr(rough, name), getattr(none, name), rtol=1e-4)


@pytest.mark.slow
def test_raising_the_asperity_constant_raises_load_share_and_sliding_loss():
    """Deep mixed ground contact (500 rpm): K′ ∝ (nβσ)² √(σ/β) scales the asperity pressure at a
    given film, so raising nβσ (0.03 → 0.05 → 0.08, σ/β = 0.01) and then σ/β (→ 0.05) must raise the
    asperity load share, lift the mean film (the asperities hold the surfaces apart) and, with
    μb = 0.1 far above the fluid's μ ≈ 0.005, raise the sliding loss. Measured (65 nodes): share
    0.04 / 0.10 / 0.25 / 0.47, sliding loss 1.8 / 3.1 / 6.0 / 10.0 kW/m; the margins (×1.3 and
    ×1.2 per step) sit far below the measured steps (×1.9-2.7 and ×1.7-1.9)."""
    c = gear_contact(rpm=500.0)
    surf = jg.presets.ground()
    share, sliding, film = [], [], []
    for density, slope in ((0.03, 0.01), (0.05, 0.01), (0.08, 0.01), (0.08, 0.05)):
        fid = jg.Fidelity(
            dynamics="quasi_static",
            friction="ehl_mixed",
            n_nodes=65,
            n_positions=24,
            asperity_density_product=density,
            asperity_slope_ratio=slope,
        )
        sol = jg.solve_ehl(c, LUB, ehl_model_of(fid), surf)
        assert bool(sol.converged), (density, slope, float(sol.residual))
        share.append(float(sol.contact_load_share))
        sliding.append(float(sol.power_loss_sliding))
        film.append(float(sol.h_central))
    assert all(b > 1.3 * a for a, b in zip(share, share[1:])), share
    assert all(b > 1.2 * a for a, b in zip(sliding, sliding[1:])), sliding
    assert all(b > a for a, b in zip(film, film[1:])), film
