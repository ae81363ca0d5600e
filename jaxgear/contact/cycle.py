"""The contacts of one mesh cycle at the rung a fidelity asks for."""

from __future__ import annotations

from .ehl import ehl_contact_forces
from .formula import formula_contact_forces, formula_ehl_contact_forces


def contact_forces(
    pair,
    lubricant,
    surfaces,
    mesh,
    fidelity,
    load,
    u1,
    u2,
    inlet_temperature,
    initial=None,
    period=None,
):
    """The ``ContactForces`` [M, 2] of the cycle's contacts at tooth forces ``load`` (N) and surface
    velocities ``u1``, ``u2`` (m/s), by ``fidelity.friction`` (a static choice: unused rungs are
    never traced).

    Returns (ContactForces, contact state): the contact state is the batch of EHL solutions on the
    EHL rungs (a warm start for the next evaluation, and the fields), None on the formula rungs.
    ``initial``: EHL solutions to warm-start from; ``period``: the mesh period, s (transient rung).
    """
    if fidelity.friction in ("constant", "regression", "ehl_formula"):
        closed_form = (
            formula_ehl_contact_forces
            if fidelity.friction == "ehl_formula"
            else formula_contact_forces
        )
        forces = closed_form(
            pair, lubricant, surfaces, mesh, fidelity, load, u1, u2, inlet_temperature
        )
        return forces, None
    return ehl_contact_forces(
        pair, lubricant, surfaces, mesh, fidelity, load, u1, u2, inlet_temperature, initial, period
    )
