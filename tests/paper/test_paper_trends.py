"""The paper's reported trends R5-R9 (REFERENCE §7) from the contact physics that produces them:
thermal statistical-mixed EHL in every tooth contact of the quasi-static mesh cycle, at a reduced
resolution (24 positions per cycle, 65 nodes per contact, quasi-steady contacts).

Why quasi-static: R5-R9 compare operating conditions (inlet temperature, torque, surface finish,
speed) through the contacts' friction; the dynamics add the resonances on top (R1-R3, in the
tribo-dynamic tests and ``docs/figures/paper``). One parallel sweep over eight points compiles the
model once (~25 s on 2 cores).

Measured here (2026-11-22), Φ̄ in W at 1000 / 3500 rpm: ground 90 °C 700 N m 111 / 316 (rolling share
4 % / 13 %); 60 °C 101 / 283; 1500 N m 206 / 573; polished (Rq 0.05 µm) 55 / 174; iso-thermal
112 / 318 (slow test). The paper-fidelity run (``docs/figures/paper``) gives the same directions.
What this model does not reproduce, stated in the README: R5's gap does not grow with speed
(+0.9 % and +0.8 % here), and R7's efficiency comes out slightly *higher* at 1500 N m (Φ̄ grows by
1.8-1.9×, less than the torque's 2.14×), where the paper's is slightly lower.
"""

import numpy as np
import pytest

import jaxgear as jg

PAIR = jg.presets.li2015_pair_calibrated()
LUB = jg.presets.mil_l_23699()
SPEEDS = (1000.0, 3500.0)
# (inlet K, torque N m, roughness scale of the ground preset) per case, each at both speeds.
# Scale 0.125 gives Rq 0.05 µm per surface, the polished preset's: the statistical asperity model
# sees the surfaces only through σ (the correlation length enters the deterministic solve only).
CASES = {
    "ground": (363.15, 700.0, 1.0),
    "cold_inlet": (333.15, 700.0, 1.0),
    "high_torque": (363.15, 1500.0, 1.0),
    "polished": (363.15, 700.0, 0.125),
}


def _fidelity(thermal):
    return jg.Fidelity.paper(
        dynamics="quasi_static", thermal=thermal, transient=False, n_positions=24, n_nodes=65
    )


def _sweep(thermal, cases):
    op = jg.OperatingPoint(torque=700.0, speed_rpm=SPEEDS[0], inlet_temperature=363.15)
    points = [(c, v) for c in cases for v in SPEEDS]
    res = jg.sweep(
        PAIR,
        LUB,
        jg.presets.ground(),
        op,
        speeds_rpm=[v for _, v in points],
        inlet_temperature=[CASES[c][0] for c, _ in points],
        torque=[CASES[c][1] for c, _ in points],
        roughness_scale=[CASES[c][2] for c, _ in points],
        fidelity=_fidelity(thermal),
    )
    assert np.all(np.asarray(res.status) == 0), res.status
    out = {}
    for i, (c, v) in enumerate(points):
        out[c, v] = {
            "loss": float(res.power_loss[i]),
            "sliding": float(res.power_loss_sliding[i]),
            "rolling": float(res.power_loss_rolling[i]),
            "efficiency": float(res.efficiency[i]),
        }
    return out


@pytest.fixture(scope="module")
def thermal():
    return _sweep(True, tuple(CASES))


def test_polished_strongly_below_ground_with_higher_efficiency(thermal):
    # R8: polished surfaces run in (nearly) full film: measured × 0.49 / × 0.55. "Strongly lower"
    # judged as below 0.75 × ground, far outside the ~1e-3 reproducibility of the Picard loops.
    for v in SPEEDS:
        g, p = thermal["ground", v], thermal["polished", v]
        assert p["loss"] < 0.75 * g["loss"], (v, p["loss"], g["loss"])
        assert p["efficiency"] > g["efficiency"]


def test_cold_inlet_lowers_loss_and_raises_efficiency(thermal):
    # R6: at 60 °C the thicker film (η0 13.3 against 6.0 mPa s) carries more of the load than the
    # asperities: measured −10 % at both speeds, against a reproducibility of ~1e-3.
    for v in SPEEDS:
        g, c = thermal["ground", v], thermal["cold_inlet", v]
        assert c["loss"] < 0.97 * g["loss"], (v, c["loss"], g["loss"])
        assert c["efficiency"] > g["efficiency"]


def test_high_torque_raises_loss_much_and_efficiency_little(thermal):
    # R7: Φ̄ "much higher" (measured × 1.85 / × 1.82 for × 2.14 torque) and Ψ only slightly changed.
    # Slightly: within 0.1 percentage point (measured +0.02, of the opposite sign to the paper's).
    for v in SPEEDS:
        g, h = thermal["ground", v], thermal["high_torque", v]
        assert h["loss"] > 1.5 * g["loss"], (v, h["loss"], g["loss"])
        assert abs(h["efficiency"] - g["efficiency"]) < 1e-3


def test_sliding_dominates_at_low_speed_and_rolling_share_grows(thermal):
    # R9: the rolling (Poiseuille) part of Eq. 12 grows with the film, i.e. with speed; the sliding
    # part dominates at low speed. Measured share 4 % at 1000 rpm and 13 % at 3500 rpm (REFERENCE
    # §7 does not quantify "significant"; the paper-fidelity run gives 3 % → 15 % over 500-4200).
    share = {v: thermal["ground", v]["rolling"] / thermal["ground", v]["loss"] for v in SPEEDS}
    assert share[1000.0] < 0.1
    assert share[3500.0] > 2.0 * share[1000.0]
    for v in SPEEDS:  # the parts add up to the total (Eq. 16-17)
        g = thermal["ground", v]
        assert g["sliding"] + g["rolling"] == pytest.approx(g["loss"], rel=1e-12)


@pytest.mark.slow
def test_iso_thermal_loss_above_thermal(thermal):
    # R5, sign only: the film's temperature rise (6-8 K at these contacts) lowers its viscosity and
    # the fluid friction. Measured +0.9 % at 1000 rpm and +0.8 % at 3500 rpm: the gap does not grow
    # with speed here (README). 0.3 % margin against the Picard loops' ~1e-3 reproducibility.
    iso = _sweep(False, ("ground",))
    for v in SPEEDS:
        assert iso["ground", v]["loss"] > 1.003 * thermal["ground", v]["loss"], v
