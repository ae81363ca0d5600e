"""The one status enumeration: every code has its words, every result type's codes belong to it,
and a result's ``converged`` is its status read as success."""

from __future__ import annotations

import numpy as np
import pytest

import jaxgear as jg
from jaxgear import optimise
from jaxgear.design import calibrate
from jaxgear.dynamics import response
from jaxgear.results import MESSAGES, Status, message, messages
from jaxgear.tribodynamics import result


def test_every_code_has_distinct_words():
    assert set(MESSAGES) == set(Status)
    assert len(set(MESSAGES.values())) == len(Status)
    assert [int(s) for s in Status] == list(range(len(Status)))  # no gaps, no reuse


def test_each_result_types_codes_are_codes_of_the_enumeration():
    for names in (result.STATUS_NAMES, optimise.STATUS_NAMES, calibrate.STATUS_NAMES):
        assert set(names) <= {int(s) for s in Status}
    dynamic = (
        response.STATUS_CONVERGED,
        response.STATUS_NOT_CONVERGED,
        response.STATUS_NOT_FINITE,
        response.STATUS_UNSTABLE,
    )
    assert all(isinstance(code, Status) for code in dynamic) and len(set(dynamic)) == 4
    # the simulation's codes keep the numbers written in sweeps' CSV files
    assert (result.STATUS_ATTRACTOR, result.STATUS_PENDING) == (6, 7)


def test_message_reads_ints_arrays_and_batches():
    assert message(6) == message(np.asarray(6)) == Status.ATTRACTOR.message
    assert messages(np.array([0, 5])) == [MESSAGES[Status.OK], MESSAGES[Status.FAILED]]
    with pytest.raises(ValueError):
        message(99)


def test_a_simulations_converged_is_its_status_zero():
    pair = jg.presets.li2015_pair_calibrated()
    op = jg.OperatingPoint(torque=700.0, speed_rpm=2000.0)
    fid = jg.Fidelity(dynamics="quasi_static", friction="constant", n_positions=24)
    res = jg.simulate(pair, jg.presets.mil_l_23699(), jg.presets.ground(), op, fidelity=fid)
    assert int(res.status) == Status.OK and bool(res.converged) and res.message == "ok"
