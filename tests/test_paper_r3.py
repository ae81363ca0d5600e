"""REFERENCE §7 R3 at the points around the lower resonance and below the higher one: the
tribo-dynamic loss lower than the quasi-static one at A and D, higher at B (the paper: 257 against
276 W at A, 343 against 302 W at B, 431 against 526 W at D).

At ``Fidelity.fast()`` (within 6.1 % of ``Fidelity.paper()``'s Φ̄ over the baseline sweep,
benchmarks/fast_vs_paper.py) on the calibrated pair, whose DTE peaks sit at 1750 and 3375 rpm:
A 1700, B 1800 and D 3325 rpm, the points as ``jaxgear figures`` places them on the paper's 25 rpm
grid (README). All three have a stable periodic orbit (status 0), so these are orbits, not
attractor means. Measured (2026-11-25 and again 2026-12-01): A −3.3 %, B +4.0 %, D −12.2 %; the
paper fidelity gives −4.1 %, +3.4 %, −12.1 % (docs/figures/paper). What the model does not
reproduce, point E's +78 % (3500 rpm: over the attractor, lower here), is stated in the README and
tested at the calibrated preset (tests/test_paper_calibrated.py, slow).

The comparison is what the dynamics did not produce: the same contacts at the static tooth loads
and kinematic velocities (``dynamics="quasi_static"``).
"""

import numpy as np
import pytest

import jaxgear as jg

SPEEDS = {"A": 1700.0, "B": 1800.0, "D": 3325.0}


@pytest.fixture(scope="module")
def ratios():
    pair = jg.presets.li2015_pair_calibrated()
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    op = jg.OperatingPoint(torque=700.0, speed_rpm=1000.0, inlet_temperature=363.15)
    fast = jg.Fidelity.fast()
    speeds = list(SPEEDS.values())
    td = jg.sweep(pair, lub, surf, op, speeds_rpm=speeds, fidelity=fast)
    qs = jg.sweep(
        pair, lub, surf, op, speeds_rpm=speeds, fidelity=fast.replace(dynamics="quasi_static")
    )
    assert np.all(np.asarray(td.status) == 0), np.asarray(td.status)
    assert np.all(np.asarray(qs.status) == 0), np.asarray(qs.status)
    ratio = np.asarray(td.power_loss) / np.asarray(qs.power_loss)
    return dict(zip(SPEEDS, ratio))


# Margins: the signs of R3 with room for the fixed point's tolerance (tables to 1e-4 of their
# largest entry: Φ̄ to ~1e-4) and the fast rung's few-percent difference from the paper fidelity,
# whose ratios at A, B, D are within 0.8 points of these; not the paper's magnitudes, which the
# model does not claim at these points (A −7 %, B +14 %, D −18 %).
def test_tribo_dynamic_loss_below_quasi_static_at_a(ratios):
    assert ratios["A"] < 0.99, ratios


def test_tribo_dynamic_loss_above_quasi_static_at_b(ratios):
    assert ratios["B"] > 1.01, ratios


def test_tribo_dynamic_loss_well_below_quasi_static_at_d(ratios):
    assert ratios["D"] < 0.95, ratios
