"""Fidelity.auto (issue 7): indicators against hand computations, monotone choices, tolerance met on
scenarios the error table never saw, and ``jaxgear run --fidelity auto``."""

import argparse
import math

import equinox as eqx
import numpy as np
import pytest

import jaxgear as jg
from jaxgear.fidelity.choose import (
    AXIS_ORDER,
    QUANTITIES,
    choose_fidelity,
    choose_from_indicators,
    load_error_table,
    scenario_indicators,
)

CALIBRATED = jg.presets.li2015_pair_calibrated()
PAIR = CALIBRATED  # the paper's geometry (REFERENCE §3); its blanks only move the resonances
LUB = jg.presets.mil_l_23699()


def _op(rpm=1000.0, torque=700.0, inlet_c=90.0):
    return jg.OperatingPoint(torque=torque, speed_rpm=rpm, inlet_temperature=inlet_c + 273.15)


# -------------------------------------------------------------------------------------------------
# Indicators against hand computations (REFERENCE §3-§8 numbers, not the code's path)
# -------------------------------------------------------------------------------------------------
def test_indicators_match_hand_computation():
    ind = scenario_indicators(PAIR, LUB, jg.presets.ground(), _op(1000.0))
    # REFERENCE §3: Hertz at the pitch, one pair, 700 N m: ph = 1.184 GPa, b = 267 µm.
    assert ind.hertz_pressure_pitch == pytest.approx(1.184e9, rel=2e-3)
    # The pitch lies in single-tooth contact; the maximum over the cycle is the pitch-zone value
    # (R is largest at the pitch, but the single zone is narrow): within 3 %.
    assert ind.hertz_pressure_pitch <= ind.hertz_pressure * (1 + 1e-9)
    assert ind.hertz_pressure == pytest.approx(ind.hertz_pressure_pitch, rel=0.03)
    # REFERENCE §3: ur = 2.686 m/s per 1000 rpm; |us| = 1.627 m/s at the path ends: SR = ±0.606,
    # negative at the start of the path (gear 1's surface is the slower one there).
    assert ind.slide_to_roll_range[0] == pytest.approx(-1.627 / 2.686, rel=2e-3)
    assert ind.slide_to_roll_range[1] == pytest.approx(1.627 / 2.686, rel=2e-3)
    assert ind.slide_to_roll_max == pytest.approx(1.627 / 2.686, rel=2e-3)
    # Péclet u b/(2κ): steel κ = 46.7/(7850·470); REFERENCE §5 quotes 14-120 over 500-4200 rpm.
    kappa = 46.7 / (7850.0 * 470.0)
    assert ind.peclet == pytest.approx(2.686 * 267e-6 / (2 * kappa), rel=5e-3)
    # Pan-Hamrock central film (REFERENCE §8) from the REFERENCE §4 oil numbers at 90 °C:
    # η0 = 6.0 mPa s, α = 11.3 GPa⁻¹; E' = 227.5 GPa; R = 12.826 mm; w' = 9932 N / 20 mm.
    e_red, radius = 207e9 / (1 - 0.3**2), 12.826e-3
    u = 6.0e-3 * 2.686 / (e_red * radius)
    w = 9932.0 / 0.020 / (e_red * radius)
    g = 11.3e-9 * e_red
    hc = radius * 2.922 * w**-0.166 * u**0.692 * g**0.470
    assert ind.central_film == pytest.approx(hc, rel=0.01)  # η0 = 6.0 is rounded (5.97)
    assert ind.composite_roughness == pytest.approx(0.4e-6 * math.sqrt(2), rel=1e-6)
    assert ind.film_parameter == pytest.approx(hc / (0.4e-6 * math.sqrt(2)), rel=0.01)
    # REFERENCE §6: λ ≈ 0.1-0.4 for the ground baseline.
    assert 0.1 < ind.film_parameter < 0.4


def test_indicators_scale_as_the_closed_forms_say():
    ground = scenario_indicators(PAIR, LUB, jg.presets.ground(), _op(1000.0))
    fast = scenario_indicators(PAIR, LUB, jg.presets.ground(), _op(4000.0))
    polished = scenario_indicators(PAIR, LUB, jg.presets.polished(), _op(1000.0))
    smooth = scenario_indicators(PAIR, LUB, jg.presets.smooth(), _op(1000.0))
    # hc ∝ U^0.692, Pe ∝ u; SR does not depend on speed.
    assert fast.central_film / ground.central_film == pytest.approx(4.0**0.692, rel=1e-9)
    assert fast.peclet / ground.peclet == pytest.approx(4.0, rel=1e-9)
    assert fast.slide_to_roll_max == pytest.approx(ground.slide_to_roll_max, rel=1e-12)
    # Same film, σ eight times smaller; smooth surfaces: full film, λ = inf.
    assert polished.film_parameter / ground.film_parameter == pytest.approx(8.0, rel=1e-6)
    assert math.isinf(smooth.film_parameter)
    assert smooth.as_dict()["film_parameter"] is None


def test_resonance_distance_of_the_calibrated_pair():
    # The preset puts its dominant mesh-coupled mode at 3500 rpm of mesh excitation, 2916.7 Hz
    # (presets.py), and the other at 400 rpm (333 Hz): 1750 rpm is on the 2nd-harmonic peak.
    on_peak = scenario_indicators(CALIBRATED, LUB, jg.presets.ground(), _op(1750.0))
    assert on_peak.mesh_frequency == pytest.approx(50 * 1750 / 60)
    assert on_peak.resonance_distance < 1e-3
    assert on_peak.nearest_resonance[0] == 2
    assert on_peak.nearest_resonance[1] == pytest.approx(2916.7, rel=1e-3)
    between = scenario_indicators(CALIBRATED, LUB, jg.presets.ground(), _op(2500.0))
    # |f_mesh − 2916.7|/2916.7 with f_mesh = 2083.3 Hz; 2 f_mesh is farther (0.43).
    assert between.resonance_distance == pytest.approx((2916.7 - 2083.33) / 2916.7, rel=2e-3)
    freqs = sorted(between.natural_frequencies)
    assert len(freqs) == 2 and freqs[0] == pytest.approx(333.3, rel=2e-3)


# -------------------------------------------------------------------------------------------------
# A synthetic error table: known errors, so the choices can be checked exactly
# -------------------------------------------------------------------------------------------------
LEVELS = {
    "coarse": {"n_positions": 24, "n_nodes": 65, "steps_per_period": 32},
    "default": {"n_positions": 32, "n_nodes": 129, "steps_per_period": 64},
}
REF = ("tribo_dynamic", "ehl_smooth", False, False)
# name: (λ, resonance distance, Pe, ph)
SCEN = {
    "s_rough_resonant": (0.2, 0.0, 50.0, 1.2e9),
    "s_rough_near": (0.3, 0.06, 90.0, 1.2e9),
    "s_mid": (0.6, 0.25, 70.0, 1.2e9),
    "s_far": (0.35, 0.43, 30.0, 1.2e9),
    "s_smooth": (2.7, 0.25, 70.0, 1.2e9),
    "s_heavy": (0.3, 0.25, 100.0, 1.7e9),
}
# (physics, level): (time per point s, {scenario: relative Φ̄ error})
RUNGS = {
    (("quasi_static", "ehl_smooth", False, False), "default"): (
        30.0,
        {
            "s_rough_resonant": 0.20,
            "s_rough_near": 0.12,
            "s_mid": 0.03,
            "s_far": 0.02,
            "s_smooth": 0.03,
            "s_heavy": 0.03,
        },
    ),
    (("tribo_dynamic", "regression", False, False), "default"): (
        0.05,
        {
            "s_rough_resonant": 0.40,
            "s_rough_near": 0.30,
            "s_mid": 0.10,
            "s_far": 0.25,
            "s_smooth": 0.03,
            "s_heavy": 0.30,
        },
    ),
    (("quasi_static", "regression", False, False), "default"): (
        0.01,
        {
            "s_rough_resonant": 0.50,
            "s_rough_near": 0.40,
            "s_mid": 0.12,
            "s_far": 0.26,
            "s_smooth": 0.05,
            "s_heavy": 0.32,
        },
    ),
    (REF, "coarse"): (
        100.0,
        {s: (0.08 if s == "s_heavy" else 0.01) for s in SCEN},
    ),
}


def _indicators(lam, d, pe, ph):
    return {
        "film_parameter": lam,
        "resonance_distance": d,
        "peclet": pe,
        "hertz_pressure": ph,
    }


def synthetic_table(rungs=None, scen=None):
    rungs = RUNGS if rungs is None else rungs
    scen = SCEN if scen is None else scen
    ref_vals = {"power_loss": 100.0, "efficiency": 0.998, "dte_rms": 5e-6, "status": 0}
    table = {
        "indicator_version": 1,
        "generated": "synthetic",
        "mode": "test",
        "machine": "none",
        "levels": LEVELS,
        "anchor_level": "default",
        "reference": {
            "label": "synthetic reference",
            "paper": False,
            "level": "default",
            "fidelity": {**dict(zip(AXIS_ORDER, REF)), **LEVELS["default"]},
            "summary_run_s": 200.0,
        },
        "scenarios": {
            n: {
                "indicators": _indicators(*v),
                "reference_result": ref_vals,
                "reference_converged": True,
            }
            for n, v in scen.items()
        },
        "rungs": [],
    }
    all_rungs = {**rungs, (REF, "default"): (200.0, {s: 0.0 for s in scen})}
    for (physics, level), (seconds, errs) in all_rungs.items():
        results = {
            s: {**ref_vals, "power_loss": 100.0 * (1 + e), "efficiency": 0.998 - 0.002 * e}
            for s, e in errs.items()
        }
        table["rungs"].append(
            {
                **dict(zip(AXIS_ORDER, physics)),
                "level": level,
                "available": True,
                "results": results,
                "summary": {"run_s": seconds},
            }
        )
    return table


def _rank(fid, axis):
    return AXIS_ORDER[axis].index(getattr(fid, axis))


def test_synthetic_choices_are_the_expected_rungs():
    table = synthetic_table()
    # Thick film far from resonance: the cheap regression rung is within 5 % (λ ≥ 2.7 measured 3 %).
    c = choose_from_indicators(_indicators(3.0, 0.29, 70.0, 1.2e9), 0.05, table=table)
    assert (c.fidelity.dynamics, c.fidelity.friction) == ("tribo_dynamic", "regression")
    # Quasi-static + regression once the tolerance admits the sum of the two axes' errors,
    # 3 % (quasi-static, d ≥ 0.25) + 3 % (regression, λ ≥ 2.7).
    c = choose_from_indicators(_indicators(3.0, 0.29, 70.0, 1.2e9), 0.061, table=table)
    assert (c.fidelity.dynamics, c.fidelity.friction) == ("quasi_static", "regression")
    assert c.predicted_error["power_loss"] == pytest.approx(0.06)
    # Thin film on a resonance: nothing cheaper than the reference physics is within 5 %; the coarse
    # level (1 % at 1.2 GPa) is cheaper than the reference's default level.
    c = choose_from_indicators(_indicators(0.2, 0.0, 50.0, 1.2e9), 0.05, table=table)
    assert (c.fidelity.dynamics, c.fidelity.friction) == ("tribo_dynamic", "ehl_smooth")
    assert c.fidelity.n_nodes == 65
    # Heavier than any measured scenario: resolution is not extrapolated, the reference level stays.
    c = choose_from_indicators(_indicators(0.2, 0.0, 50.0, 2.0e9), 0.05, table=table)
    assert c.fidelity.n_nodes == 129 and c.fidelity.friction == "ehl_smooth"
    assert "not bounded" in c.reasons
    # Thinner film than any measured: friction stays at the reference rung even at 90 % tolerance.
    c = choose_from_indicators(_indicators(0.1, 0.43, 50.0, 1.2e9), 0.9, table=table)
    assert c.fidelity.friction == "ehl_smooth"


@pytest.mark.parametrize("tolerance", [0.02, 0.05, 0.11, 0.3])
def test_thinner_film_never_lowers_the_friction_rung(tolerance):
    table = synthetic_table()
    ranks = [
        _rank(
            choose_from_indicators(
                _indicators(lam, 0.29, 70.0, 1.2e9), tolerance, table=table
            ).fidelity,
            "friction",
        )
        for lam in (5.0, 2.7, 1.0, 0.6, 0.4, 0.3, 0.2, 0.1)  # thinner and thinner
    ]
    assert ranks == sorted(ranks), ranks


@pytest.mark.parametrize("tolerance", [0.02, 0.05, 0.15, 0.3])
def test_closer_to_resonance_never_lowers_the_dynamics_rung(tolerance):
    table = synthetic_table()
    ranks = [
        _rank(
            choose_from_indicators(
                _indicators(2.7, d, 70.0, 1.2e9), tolerance, table=table
            ).fidelity,
            "dynamics",
        )
        for d in (0.6, 0.43, 0.29, 0.1, 0.06, 0.03, 0.0)  # closer and closer
    ]
    assert ranks == sorted(ranks), ranks


def test_scenario_path_rougher_and_resonant_go_up_the_ladder():
    """Through the real indicators: rougher surfaces (scale) and speeds approaching the 1750 rpm
    peak move up the ladder, never down."""
    table = synthetic_table()
    base = jg.presets.ground()
    friction = []
    for scale in (0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 3.0):
        surf = jg.presets.ground(scale=scale)
        c = choose_fidelity(CALIBRATED, LUB, surf, _op(2500.0), 0.05, table=table)
        friction.append(_rank(c.fidelity, "friction"))
    assert friction == sorted(friction) and friction[0] < friction[-1], friction
    dynamics = []
    # Towards the 1750 rpm peak (d = 0.29, 0.26, 0.14, 0.06, 0); smooth surfaces (λ = inf) and a
    # tolerance that admits quasi-static + regression far from the peaks (3 % + 3 %).
    for rpm in (2500.0, 2200.0, 2000.0, 1850.0, 1750.0):
        c = choose_fidelity(CALIBRATED, LUB, jg.presets.smooth(), _op(rpm), 0.065, table=table)
        dynamics.append(_rank(c.fidelity, "dynamics"))
    assert dynamics == sorted(dynamics) and dynamics[0] < dynamics[-1], dynamics
    c = choose_fidelity(CALIBRATED, LUB, base, _op(1750.0), 0.05, table=table)
    assert c.fidelity.dynamics == "tribo_dynamic"
    assert "λ = 0.27" in c.reasons and "from the nearest resonance" in c.reasons


def test_sweep_choice_is_the_most_demanding_per_axis():
    table = synthetic_table()
    speeds = [1750.0, 2500.0, 3000.0]
    sweep = choose_fidelity(
        CALIBRATED, LUB, jg.presets.smooth(), _op(2500.0), 0.05, table=table, speeds_rpm=speeds
    )
    single = [
        choose_fidelity(CALIBRATED, LUB, jg.presets.smooth(), _op(v), 0.05, table=table)
        for v in speeds
    ]
    for axis in AXIS_ORDER:
        assert _rank(sweep.fidelity, axis) == max(_rank(c.fidelity, axis) for c in single)
    assert len(sweep.indicators) == 3 and "Sweep of 3 speeds" in sweep.reasons


def test_cost_noise_does_not_reorder_the_ladder():
    # The coarse level timed slower than the default one (timing noise): the default level then
    # costs at least as much as the coarse one (finer never costs less), and at equal cost the
    # smaller predicted error (the reference's own level, 0) wins.
    rungs = dict(RUNGS)
    rungs[(REF, "coarse")] = (300.0, {s: 0.01 for s in SCEN})
    table = synthetic_table(rungs)
    c = choose_from_indicators(_indicators(0.2, 0.0, 50.0, 1.2e9), 0.05, table=table)
    assert c.fidelity.n_nodes == 129


def test_unconverged_rung_is_never_certified_there():
    table = synthetic_table()
    for r in table["rungs"]:
        if (r["dynamics"], r["friction"], r["level"]) == ("tribo_dynamic", "regression", "default"):
            r["results"]["s_smooth"]["status"] = 2
    c = choose_from_indicators(_indicators(3.0, 0.29, 70.0, 1.2e9), 0.05, table=table)
    assert c.fidelity.friction == "ehl_smooth"


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"tolerance": 0.0}, "tolerance"),
        ({"tolerance": 1.5}, "tolerance"),
        ({"tolerance": True}, "tolerance"),
        ({"quantities": ("power",)}, "quantities"),
        ({"quantities": ()}, "quantities"),
    ],
)
def test_bad_requests_name_the_field(kwargs, needle):
    args = {"tolerance": 0.05, **kwargs}
    tol = args.pop("tolerance")
    with pytest.raises(ValueError, match=needle):
        choose_from_indicators(
            _indicators(1.0, 0.3, 50.0, 1.2e9), tol, table=synthetic_table(), **args
        )


def test_table_with_other_indicator_definitions_is_refused(tmp_path):
    import json

    table = synthetic_table()
    table["indicator_version"] = 999
    path = tmp_path / "t.json"
    path.write_text(json.dumps(table))
    with pytest.raises(ValueError, match="indicator_version"):
        load_error_table(path)
    with pytest.raises(ValueError, match="does not exist"):
        load_error_table(tmp_path / "missing.json")


# -------------------------------------------------------------------------------------------------
# The shipped table (written by benchmarks/fidelity_trade.py)
# -------------------------------------------------------------------------------------------------
def test_shipped_table_is_consistent():
    table = load_error_table()
    ref = table["reference"]
    assert ref["label"] and isinstance(ref["paper"], bool)
    ref_fid = jg.Fidelity(**ref["fidelity"])  # a valid Fidelity
    assert ref_fid.uses_ehl or ref_fid.friction == "regression"
    assert table["scenarios"] and table["rungs"]
    for r in table["rungs"]:
        if r["available"]:
            jg.Fidelity(**r["fidelity"])
            assert set(r["results"]) <= set(table["scenarios"])


def test_shipped_table_envelope_dominates_its_own_measurements():
    """At a measured scenario, a rung that departs from the reference on one axis only is never
    predicted better than it measured there (the envelope is conservative on its own data)."""
    from jaxgear.fidelity.choose import _predict, _Table

    tab = _Table(load_error_table())
    checked = 0
    for (physics, level), rung in tab.rungs.items():
        changed = [a for a, v, r in zip(AXIS_ORDER, physics, tab.ref_physics) if v != r]
        single_axis = (len(changed) == 1 and level == tab.anchor) or (
            not changed and level != tab.reference.get("level")
        )
        if not single_axis:
            continue
        # What the rung departs from: the reference (resolution), or the reference physics at the
        # anchor level (a physics axis).
        base = tab.reference_results if not changed else tab.results(tab.ref_physics, tab.anchor)
        for name, scen in tab.scenarios.items():
            res, ref = rung["results"].get(name), base.get(name)
            if res is None or ref is None or res["status"] != 0 or ref["status"] != 0:
                continue
            pred, _ = _predict(tab, physics, level, scen["indicators"])
            for q in QUANTITIES:
                measured = abs(res[q] - ref[q]) / abs(ref[q])
                assert pred[q] >= measured * (1 - 1e-12), (physics, level, name, q)
            checked += 1
    assert checked > 0


@pytest.mark.parametrize("rpm", [1750.0, 2500.0])
def test_fidelity_auto_returns_a_static_fidelity_and_reasons(rpm):
    op = _op(rpm)
    fid = jg.Fidelity.auto(CALIBRATED, LUB, jg.presets.ground(), op)
    choice = jg.choose_fidelity(CALIBRATED, LUB, jg.presets.ground(), op)
    assert isinstance(fid, jg.Fidelity) and fid == choice.fidelity
    # the choices (all but the traced constants) are static: hashable, the same program
    choices = lambda f: eqx.partition(f, eqx.is_array)[1]
    assert hash(choices(fid)) == hash(choices(choice.fidelity))
    assert all(choice.predicted_error[q] <= 0.05 for q in ("power_loss", "efficiency"))
    assert "Reference of the table" in choice.reasons and "λ =" in choice.reasons
    assert choice.time_per_point is not None and choice.time_per_point > 0


def test_auto_keeps_the_base_fidelitys_other_fields():
    """The choice sets only the ladder's fields (physics axes, resolution): μb, the shear law, the
    asperity constants and the fixed-point settings of ``base`` survive, and the reasons name the
    ones that differ from the defaults the table was measured at."""
    op = _op(2500.0)
    plain = jg.choose_fidelity(CALIBRATED, LUB, jg.presets.ground(), op)
    base = jg.Fidelity(
        boundary_friction=0.08,
        shear="newtonian",
        asperity_density_product=0.08,
        max_fixed_point_iterations=60,
        # ladder fields of the base are replaced by the choice
        friction="constant",
        n_nodes=513,
    )
    kept = jg.choose_fidelity(CALIBRATED, LUB, jg.presets.ground(), op, base=base)
    ladder = ("dynamics", "friction", "thermal", "transient", "n_positions", "n_nodes")
    ladder += ("steps_per_period",)
    assert {f: getattr(kept.fidelity, f) for f in ladder} == {
        f: getattr(plain.fidelity, f) for f in ladder
    }
    assert kept.fidelity.boundary_friction == 0.08 and kept.fidelity.shear == "newtonian"
    assert kept.fidelity.asperity_density_product == 0.08
    assert kept.fidelity.max_fixed_point_iterations == 60
    assert kept.predicted_error == plain.predicted_error
    for words in ("boundary_friction = 0.08 (table: 0.1)", "shear = 'newtonian'"):
        assert words in kept.reasons
    assert "Kept from base" not in plain.reasons
    # A base at the defaults changes nothing, and a sweep keeps the base too.
    assert jg.Fidelity.auto(CALIBRATED, LUB, jg.presets.ground(), op, base=jg.Fidelity()) == (
        plain.fidelity
    )
    sweep = jg.choose_fidelity(
        CALIBRATED, LUB, jg.presets.ground(), op, speeds_rpm=[1000.0, 2500.0], base=base
    )
    assert sweep.fidelity.boundary_friction == 0.08 and "Kept from base" in sweep.reasons
    with pytest.raises(ValueError, match="base = 'fast' is not valid"):
        jg.choose_fidelity(CALIBRATED, LUB, jg.presets.ground(), op, base="fast")


# -------------------------------------------------------------------------------------------------
# Held-out scenarios: the choice against the table's reference, simulated
# -------------------------------------------------------------------------------------------------
def _relative_errors(a, b):
    return {
        q: abs(float(getattr(a, q)) - float(getattr(b, q))) / abs(float(getattr(b, q)))
        for q in QUANTITIES
    }


def _measure_table(scenarios, fidelities, reference):
    """A table in the benchmark's format, measured here (quasi-static rungs: cheap)."""
    table = {
        "indicator_version": 1,
        "generated": "test",
        "mode": "test",
        "machine": "test",
        "levels": LEVELS,
        "anchor_level": "default",
        "reference": {
            "label": "quasi_static/regression @ default",
            "paper": False,
            "level": "default",
            "fidelity": {
                **{a: getattr(reference, a) for a in AXIS_ORDER},
                **LEVELS["default"],
            },
            "summary_run_s": 1.0,
        },
        "scenarios": {},
        "rungs": [],
    }
    for name, (surf, op) in scenarios.items():
        res = jg.simulate(CALIBRATED, LUB, surf, op, reference)
        table["scenarios"][name] = {
            "indicators": scenario_indicators(CALIBRATED, LUB, surf, op).as_dict(),
            "reference_result": {q: float(getattr(res, q)) for q in QUANTITIES}
            | {"status": int(res.status)},
            "reference_converged": bool(res.converged),
        }
    for (physics, level), (fid, seconds) in fidelities.items():
        results = {}
        for name, (surf, op) in scenarios.items():
            res = jg.simulate(CALIBRATED, LUB, surf, op, fid)
            results[name] = {q: float(getattr(res, q)) for q in QUANTITIES} | {
                "status": int(res.status)
            }
        table["rungs"].append(
            {
                **dict(zip(AXIS_ORDER, physics)),
                "level": level,
                "available": True,
                "results": results,
                "summary": {"run_s": seconds},
            }
        )
    return table


def test_auto_meets_tolerance_on_held_out_points_cheap():
    """Cheap sibling of the slow test below: a quasi-static regression ladder (coarse and default
    resolution) measured here on two scenarios, then Fidelity.auto at two others."""
    qs = jg.Fidelity(dynamics="quasi_static")
    reference = qs.replace(**LEVELS["default"])
    phys = ("quasi_static", "regression", False, False)
    fids = {
        (phys, "default"): (reference, 1.0),
        (phys, "coarse"): (qs.replace(**LEVELS["coarse"]), 0.5),
    }
    fitted = {
        "a": (jg.presets.ground(), _op(1000.0)),
        "b": (jg.presets.polished(), _op(3000.0, torque=1500.0, inlet_c=60.0)),
    }
    table = _measure_table(fitted, fids, reference)
    held_out = [
        (jg.presets.ground(scale=0.5), _op(2000.0, torque=1000.0, inlet_c=75.0)),
        (jg.presets.ground(), _op(1500.0, torque=700.0)),
    ]
    for surf, op in held_out:
        choice = choose_fidelity(CALIBRATED, LUB, surf, op, 0.05, table=table)
        assert choice.fidelity.dynamics == "quasi_static"
        got = jg.simulate(CALIBRATED, LUB, surf, op, choice.fidelity)
        ref = jg.simulate(CALIBRATED, LUB, surf, op, reference)
        err = _relative_errors(got, ref)
        assert err["power_loss"] <= 0.05 and err["efficiency"] <= 0.05, err
        assert choice.fidelity.n_positions == 24  # the coarse level was certified and is cheaper


@pytest.mark.slow
@pytest.mark.parametrize(
    "surfaces, rpm, torque, inlet_c",
    [("ground", 2000.0, 1000.0, 75.0), ("polished", 3000.0, 700.0, 90.0)],
)
def test_auto_meets_tolerance_on_held_out_points(surfaces, rpm, torque, inlet_c):
    """The shipped table's choice at scenarios it never measured, against its reference rung."""
    table = load_error_table()
    measured = {
        (s["torque"], s["speed_rpm"], s["inlet_temperature_C"], s["surfaces"])
        for s in table["scenarios"].values()
    }
    assert (torque, rpm, inlet_c, surfaces) not in measured
    surf = getattr(jg.presets, surfaces)()
    op = _op(rpm, torque=torque, inlet_c=inlet_c)
    choice = choose_fidelity(CALIBRATED, LUB, surf, op, 0.05)
    reference = jg.Fidelity(**table["reference"]["fidelity"])
    ref = jg.simulate(CALIBRATED, LUB, surf, op, reference)
    assert bool(ref.converged)
    got = jg.simulate(CALIBRATED, LUB, surf, op, choice.fidelity)
    err = _relative_errors(got, ref)
    assert err["power_loss"] <= 0.05 and err["efficiency"] <= 0.05, (err, choice.reasons)


# -------------------------------------------------------------------------------------------------
# Command line
# -------------------------------------------------------------------------------------------------
def test_cli_run_help_lists_auto(capsys):
    from jaxgear.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["run", "--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "auto" in out and "--tolerance" in out and "paper" in out


def test_cli_auto_prints_its_reasons(capsys):
    from jaxgear.cli.commands.run import _fidelity

    args = argparse.Namespace(fidelity="auto", tolerance=0.05)
    speeds = np.array([1500.0, 2000.0])
    fid, reasons = _fidelity(args, CALIBRATED, LUB, jg.presets.ground(), _op(1500.0), speeds)
    assert isinstance(fid, jg.Fidelity)
    out = capsys.readouterr().out
    assert reasons and reasons in out and "Sweep of 2 speeds" in out
    fast, none = _fidelity(
        argparse.Namespace(fidelity="fast", tolerance=0.05), None, None, None, None, speeds
    )
    assert fast == jg.Fidelity.fast() and none is None


def test_cli_auto_bad_tolerance_exits_2(tmp_path, capsys):
    from jaxgear.cli import main

    code = main(
        [
            "run",
            "--fidelity",
            "auto",
            "--tolerance",
            "2",
            "--speeds",
            "1000:1000:1",
            "--out",
            str(tmp_path),
            "--no-progress",
        ]
    )
    assert code == 2
    err = capsys.readouterr().err
    assert "tolerance" in err and "Traceback" not in err
