"""``Fidelity.paper_calibrated()``: the paper fidelity with its two open contact parameters set to
the paper's loss level (the Eyring stress as the fluid traction, Greenwood-Tripp nβσ = 0.08).

The density product was fitted to the paper's quasi-static Φ̄ at A, B, D, E, so the level is not
tested here as a check of the model; what the slow test checks is what was not fitted: the
ordering of the tribo-dynamic against the quasi-static loss at E (the paper's R3) and the
efficiency band (R4).
"""

import numpy as np
import pytest

import jaxgear as jg
from jaxgear.cli import build_parser
from jaxgear.cli.config import fidelity_from_config
from jaxgear.paper.figures import _contact_parameters


def test_preset_is_the_paper_fidelity_with_the_calibrated_contact():
    cal = jg.Fidelity.paper_calibrated()
    assert cal == jg.Fidelity.paper(shear="eyring_split", asperity_density_product=0.08)
    # everything else is the paper fidelity's (one field at a time, so a new default shows here)
    paper = jg.Fidelity.paper()
    differ = {f for f, v in paper.flat().items() if cal.flat()[f] != v}
    assert differ == {"shear", "asperity_density_product"}
    assert jg.Fidelity.named("paper_calibrated") == cal
    # keyword changes apply on top, the calibrated fields included
    assert jg.Fidelity.paper_calibrated(n_nodes=129).n_nodes == 129
    assert jg.Fidelity.paper_calibrated(shear="eyring_exact").shear == "eyring_exact"
    with pytest.raises(ValueError, match="unknown Fidelity field.*nodes"):
        jg.Fidelity.paper_calibrated(nodes=129)


def test_command_line_and_toml_accept_the_preset():
    fid, echo = fidelity_from_config({"fidelity": {"preset": "paper_calibrated", "n_nodes": 129}})
    assert fid == jg.Fidelity.paper_calibrated(n_nodes=129)
    assert echo["preset"] == "paper_calibrated"
    parser = build_parser()
    for argv in (
        ["run", "--fidelity", "paper_calibrated"],
        ["figures", "--fidelity", "paper_calibrated"],
        ["sweep", "--config", "x.toml", "--fidelity", "paper_calibrated"],
    ):
        assert parser.parse_args(argv).fidelity == "paper_calibrated"


def test_figures_name_the_contact_parameters_that_differ_from_the_defaults():
    assert _contact_parameters(jg.Fidelity.paper()) == ""
    assert _contact_parameters(jg.Fidelity.paper_calibrated()) == ", shear 'eyring_split', nβσ 0.08"
    assert _contact_parameters(jg.Fidelity.paper(boundary_friction=0.05)) == ", μb 0.05"


@pytest.mark.slow
def test_tribo_dynamic_loss_above_quasi_static_at_e_and_efficiency_in_the_papers_band():
    """Point E (3500 rpm, ground, 700 N m, 90 °C) at the full calibrated fidelity.

    Measured 2026-11-28: tribo-dynamic 542.9 W over the attractor (status 6: the teeth rattle
    there), quasi-static 511.3 W (+6.2 %; +5.9 % on 2026-11-26, benchmarks/RESULTS.md,
    shear_trends_asperity; the paper 948 against 532 W, +78 %); Ψ 99.79 % and 99.80 %.
    Margin: the tribo-dynamic loss must lie more than 2 % above the quasi-static one, a third of
    the measured gap (the contacts' Picard loops reproduce Φ̄ to ~1e-3, and two days of solver
    changes moved the gap by 0.3 points), and both efficiencies inside the paper's 99.6-99.85 %.
    With ``Fidelity.paper()``'s literal contact the tribo-dynamic loss lies 4-10 % below the
    quasi-static one at 3375-3500 rpm (README)."""
    pair = jg.presets.li2015_pair_calibrated()
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    op = jg.OperatingPoint(torque=700.0, speed_rpm=3500.0, inlet_temperature=363.15)
    fid = jg.Fidelity.paper_calibrated()
    td = jg.simulate(pair, lub, surf, op, fidelity=fid)
    qs = jg.simulate(pair, lub, surf, op, fidelity=fid.replace(dynamics="quasi_static"))
    assert int(qs.status) == 0, qs.status
    assert int(td.status) in (0, 6), td.status  # 6: a mean over the attractor
    assert int(td.failed_contacts) == 0
    ratio = float(td.power_loss) / float(qs.power_loss)
    assert ratio > 1.02, (float(td.power_loss), float(qs.power_loss))
    for res in (td, qs):
        assert 0.996 < float(res.efficiency) < 0.9985, float(res.efficiency)
    assert np.isfinite(float(td.dte_rms))
