"""One status enumeration for every result jaxgear returns (as optimistix's ``RESULTS``).

A result's ``status`` is an int32 array (a batch of them in sweeps) holding a ``Status`` code: 0 is
success, anything else says what went wrong; ``message(code)`` (or ``Status(code).message``) says it
in words. Each result type uses the codes that apply to it:

| code | name | used by |
|---|---|---|
| 0 | OK | every result |
| 1 | FIXED_POINT | SimulationResult |
| 2 | DYNAMICS | SimulationResult, DynamicResponse |
| 3 | CONTACT | SimulationResult |
| 4 | NON_FINITE | SimulationResult, DynamicResponse, OptimisationResult, CalibrationResult |
| 5 | FAILED | SweepResult |
| 6 | ATTRACTOR | SimulationResult |
| 7 | PENDING | SimulationResult (first pass only) |
| 8 | UNSTABLE | DynamicResponse |
| 9 | MAX_STEPS | OptimisationResult, DesignResult, CalibrationResult |
| 10 | SIMULATION | OptimisationResult, DesignResult, CalibrationResult |
| 11 | START | OptimisationResult, DesignResult, CalibrationResult |
| 12 | INFEASIBLE | DesignResult |
| 13 | RANGE | CalibrationResult |
"""

from __future__ import annotations

import enum

import numpy as np


class Status(enum.IntEnum):
    """The status codes of jaxgear's results (see the module docstring for which result uses
    which)."""

    OK = 0
    FIXED_POINT = 1
    DYNAMICS = 2
    CONTACT = 3
    NON_FINITE = 4
    FAILED = 5
    ATTRACTOR = 6
    PENDING = 7
    UNSTABLE = 8
    MAX_STEPS = 9
    SIMULATION = 10
    START = 11
    INFEASIBLE = 12
    RANGE = 13

    @property
    def message(self) -> str:
        return MESSAGES[self]


MESSAGES = {
    Status.OK: "ok",
    Status.FIXED_POINT: "tribo-dynamic fixed point not converged",
    Status.DYNAMICS: "dynamic periodic orbit not converged or unstable",
    Status.CONTACT: "contact solver not converged",
    Status.NON_FINITE: "non-finite result",
    Status.FAILED: "failed (chunk raised or non-finite)",
    Status.ATTRACTOR: "no stable periodic orbit: means over the attractor (time integration)",
    Status.PENDING: "the orbit strikes the back flanks: their loss is left to the second pass",
    Status.UNSTABLE: "periodic orbit converged but unstable (Floquet multiplier above 1)",
    Status.MAX_STEPS: "step cap reached before the gradient tolerance",
    Status.SIMULATION: "stopped: a simulation point did not converge (best converged point kept)",
    Status.START: "the start point did not converge; nothing optimised",
    Status.INFEASIBLE: "stopped with a constraint violated beyond its tolerance (limits not attained)",
    Status.RANGE: "a fitted value lies outside its valid range",
}


def message(code) -> str:
    """The words for a status ``code`` (an int, a 0-d array or a Status)."""
    return MESSAGES[Status(int(np.asarray(code)))]


def messages(codes) -> list[str]:
    """The words for each code of an array of statuses (e.g. a sweep's)."""
    return [message(c) for c in np.ravel(np.asarray(codes))]
