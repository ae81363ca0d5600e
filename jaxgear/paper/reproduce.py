"""The runs behind the paper's figures and table: ``reproduce_paper`` runs the baseline speed sweep
tribo-dynamic and quasi-static, the paper's variants (inlet 60 °C, 1500 N m, polished surfaces,
iso-thermal) and the contact fields at the paper's roll angles, into a ``PaperReproduction``.

Contact fields (Figs. 7 and 12, R10, R11's temperatures) are the EHL solution of that tooth contact at
the converged tribo-dynamic tooth force and surface velocities, solved once more with the EHL model
the fidelity uses (quasi-steady: at the transient rung the coupled solution also carries the squeeze
term of its march through the engagement). Fig. 12 and R10 (asperity pressures) are the exception:
at the mixed rung they solve the contact with the roughness profiles themselves (deterministic,
``FIELD_DETERMINISTIC_NODES``), as the paper does, since the statistical rung has no asperity
pressures to show.
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from .. import presets
from .._validation import check_positive
from ..contact.ehl import ehl_model_of
from ..fidelity import Fidelity
from ..gear.geometry import gear_geometry
from ..gear.mesh import mesh_cycle
from ..lubrication.ehl import EHLModel, LineContact, solve_ehl
from ..material import reduced_modulus
from ..operating import OperatingPoint
from ..sweep import sweep
from .reference import (
    BASELINE_INLET_C,
    BASELINE_TORQUE,
    FIELD_DETERMINISTIC_NODES,
    FIELD_SHORT_CUTOFF,
    NOMINAL_POINTS_RPM,
    QUICK_SPEEDS_RPM,
    VARIANT_INLET_C,
    VARIANT_TORQUE,
)


class FigureUnavailable(Exception):
    """The fidelity (or the run) cannot give what this figure shows; ``reason`` says why."""

    def __init__(self, number: int, reason: str):
        super().__init__(f"Fig. {number}: {reason}")
        self.number = number
        self.reason = reason


@dataclasses.dataclass
class ContactField:
    """One tooth contact's EHL solution at a roll angle and speed (SI), or why there is none.

    Attributes:
        label: e.g. "B, ground". roll_angle_deg: the mesh position used (nearest to the target).
        speed_rpm, hertz_pressure (Pa, of the dynamic tooth force), load (N).
        solution: the EHLSolution (x, p, h, temperature, ...) or None; reason: why it is None.
        model: how the contact was solved (shown on the figure); thermal: it has temperatures.
    """

    label: str
    roll_angle_deg: float
    speed_rpm: float
    hertz_pressure: float
    load: float
    solution: Any = None
    reason: str = ""
    model: str = ""
    thermal: bool = False


@dataclasses.dataclass
class PaperReproduction:
    """Everything the paper's figures and table are drawn from (see ``reproduce_paper``).

    Attributes:
        fidelity: the Fidelity of the tribo-dynamic runs. quick: reduced run.
        speeds: baseline speeds, rpm [N]. tribo_dynamic, quasi_static: SweepResults over them.
        points: A-E → index into ``speeds``; points_source: "peaks" (placed around the DTE peaks of
            the sweep) or "nominal" (NOMINAL_POINTS_RPM; the grid cannot locate the peaks).
        variant_speeds: rpm [K]; variants: "baseline", "inlet_60C", "torque_1500", "polished",
            "isothermal" → SweepResult over ``variant_speeds`` (missing where unavailable).
        fields: "fig7_B", "fig7_E", "fig12_ground", "fig12_polished" → ContactField.
        unavailable: what could not be computed → reason. timings: seconds per stage.
        mesh: the quasi-static MeshCycle (roll angles, contact positions) at the baseline torque.
    """

    fidelity: Fidelity
    quick: bool
    pair: Any
    lubricant: Any
    surfaces: Any
    polished: Any
    op: Any
    mesh: Any
    speeds: np.ndarray
    tribo_dynamic: Any
    quasi_static: Any
    points: dict[str, int]
    points_source: str
    variant_speeds: np.ndarray
    variants: dict[str, Any]
    fields: dict[str, ContactField]
    unavailable: dict[str, str]
    timings: dict[str, float]

    def point_speed(self, name: str) -> float:
        return float(self.speeds[self.points[name]])


# --------------------------------------------------------------------------------------------------
# Running the model


def reproduce_paper(
    fidelity: Fidelity | None = None,
    *,
    quick: bool = False,
    speeds_rpm=None,
    variant_speeds_rpm=None,
    mode: str | None = None,
    pair=None,
    lubricant=None,
    checkpoint_dir: str | Path | None = None,
    progress: bool = False,
) -> PaperReproduction:
    """Run what the paper's Figs. 3-12 and R1-R11 need, at ``fidelity``.

    Args:
        fidelity: Fidelity of the runs (default ``Fidelity.fast()``); the quasi-static and iso-thermal
            comparisons use it with ``dynamics="quasi_static"`` / ``thermal=False``.
        quick: reduced run: the speeds QUICK_SPEEDS_RPM (the points A-E at their nominal speeds and
            the ends of the sweep), 24 positions per mesh cycle, independent points (parallel mode).
        speeds_rpm: baseline speeds, rpm (default the paper's 500-4200 rpm in 25 rpm steps).
        variant_speeds_rpm: speeds of the variant sweeps, rpm (default every 100 rpm of the
            baseline range; the quick speeds when ``quick``). Speed E is added when the baseline
            grid places it between two of them (at its DTE peak), for Fig. 12 and R10.
        mode: "continuation" (the paper's stepwise speed increase; default) or "parallel" (default
            when ``quick``) for the tribo-dynamic sweeps.
        pair: GearPair (default ``presets.li2015_pair_calibrated()``); lubricant (default
            ``presets.mil_l_23699()``). Surfaces: ``presets.ground()`` and ``presets.polished()``
            (Fig. 12 and R10 solve their contact with the same profiles filtered at the stylus
            cutoff: ``field_surfaces``).
        checkpoint_dir: keep finished chunks here (one subdirectory per sweep) to resume.
        progress: progress bars on stderr.

    Raises:
        ValueError: bad input, or a fidelity whose rungs are not available (every point failed).
    """

    fid = Fidelity.fast() if fidelity is None else fidelity
    if not isinstance(fid, Fidelity):
        raise ValueError(f"fidelity must be a jaxgear.Fidelity; got {type(fid).__name__}")
    if quick:
        fid = fid.replace(n_positions=24)
    mode = mode or ("parallel" if quick else "continuation")
    if mode not in ("parallel", "continuation"):
        raise ValueError(f"mode = {mode!r} is not valid; valid choices: 'continuation', 'parallel'")
    default = np.asarray(QUICK_SPEEDS_RPM) if quick else np.arange(500.0, 4201.0, 25.0)
    speeds = _speed_array("speeds_rpm", default if speeds_rpm is None else speeds_rpm)
    if variant_speeds_rpm is None:
        variant_speeds = speeds if quick else _every_100_rpm(speeds)
    else:
        variant_speeds = _speed_array("variant_speeds_rpm", variant_speeds_rpm)
    pair = presets.li2015_pair_calibrated() if pair is None else pair
    lub = presets.mil_l_23699() if lubricant is None else lubricant
    ground, polished = presets.ground(), presets.polished()
    op = OperatingPoint(
        torque=BASELINE_TORQUE,
        speed_rpm=float(speeds[0]),
        inlet_temperature=BASELINE_INLET_C + 273.15,
    )
    # One chunk shape for every tribo-dynamic sweep, so they share one compiled chunk.
    chunk = max(speeds.size, variant_speeds.size) if quick else 50
    timings: dict[str, float] = {}
    unavailable: dict[str, str] = {}

    def run(name, speeds_, fid_, mode_, op_=op, surf=ground):

        t0 = time.perf_counter()
        res = sweep(
            pair,
            lub,
            surf,
            op_,
            speeds_rpm=speeds_,
            fidelity=fid_,
            mode=mode_,
            chunk_size=chunk,
            checkpoint_dir=None if checkpoint_dir is None else Path(checkpoint_dir) / name,
            progress=progress,
        )
        timings[name] = round(time.perf_counter() - t0, 2)
        if res.messages and np.all(np.asarray(res.status) == 5):
            raise ValueError(f"{name} sweep: every point failed; first error: {res.messages[0]}")
        return res

    td = run("tribo_dynamic", speeds, fid, mode)
    qs = run("quasi_static", speeds, fid.replace(dynamics="quasi_static"), "parallel")
    points, source = _place_points(speeds, td)
    variant_speeds = _with_speed_e(variant_speeds, float(speeds[points["E"]]))

    variants: dict[str, Any] = {}
    subset = _indices_of(speeds, variant_speeds)
    if subset is not None:
        variants["baseline"] = _take(td, subset)
    else:
        variants["baseline"] = run("baseline_variant_speeds", variant_speeds, fid, mode)
    variants["inlet_60C"] = run(
        "inlet_60C",
        variant_speeds,
        fid,
        mode,
        op_=dataclasses.replace(op, inlet_temperature=VARIANT_INLET_C + 273.15),
    )
    variants["torque_1500"] = run(
        "torque_1500", variant_speeds, fid, mode, op_=dataclasses.replace(op, torque=VARIANT_TORQUE)
    )
    variants["polished"] = run("polished", variant_speeds, fid, mode, surf=polished)
    if fid.thermal:
        variants["isothermal"] = run("isothermal", variant_speeds, fid.replace(thermal=False), mode)
    else:
        unavailable["isothermal"] = (
            "the fidelity is iso-thermal (thermal=False): there is no thermal solution to compare "
            "the iso-thermal one with; use the paper fidelity"
        )

    t0 = time.perf_counter()
    mesh = mesh_cycle(pair, op.torque, fid.n_positions, stiffness=fid.stiffness)
    repro = PaperReproduction(
        fidelity=fid,
        quick=quick,
        pair=pair,
        lubricant=lub,
        surfaces=ground,
        polished=polished,
        op=op,
        mesh=mesh,
        speeds=speeds,
        tribo_dynamic=td,
        quasi_static=qs,
        points=points,
        points_source=source,
        variant_speeds=variant_speeds,
        variants=variants,
        fields={},
        unavailable=unavailable,
        timings=timings,
    )
    _contact_fields(repro)
    timings["contact_fields"] = round(time.perf_counter() - t0, 2)
    return repro


def _speed_array(name, values) -> np.ndarray:

    arr = np.atleast_1d(np.asarray(values, dtype=float))
    if arr.size == 0:
        raise ValueError(f"{name} is empty; valid: at least one speed (rpm)")
    check_positive(name, arr, "rpm")
    if arr.size > 1 and not np.all(np.diff(arr) > 0):
        raise ValueError(f"{name} must be strictly increasing (the paper's stepwise sweep)")
    return arr


def _every_100_rpm(speeds):
    grid = np.arange(math.ceil(speeds[0] / 100.0) * 100.0, speeds[-1] + 1e-9, 100.0)
    return grid if grid.size else speeds


def _with_speed_e(variant_speeds, e_speed):
    """The variant speeds with speed E added when it lies strictly between two of them. Fig. 12 and
    R10 compare the ground and polished contacts at E; a fine baseline grid places E at its DTE
    peak, usually between the variant speeds (3375 rpm on the paper's 25 rpm grid against variants
    every 100 or 200 rpm). Outside their range it is not added: a continuation sweep would jump."""
    v = np.asarray(variant_speeds, dtype=float)
    if _indices_of(v, np.asarray([e_speed])) is not None or not (v[0] < e_speed < v[-1]):
        return v
    return np.union1d(v, [e_speed])


def _indices_of(speeds, wanted):
    idx = np.searchsorted(speeds, wanted)
    idx = np.clip(idx, 0, speeds.size - 1)
    return idx if np.allclose(speeds[idx], wanted, rtol=0.0, atol=1e-6) else None


def _take(result, idx):
    """The rows ``idx`` of a SweepResult (a SweepResult again)."""
    rows = {
        f.name: np.asarray(getattr(result, f.name))[idx]
        for f in dataclasses.fields(result)
        if f.name not in ("inputs", "messages")
    }
    rows["inputs"] = {k: np.asarray(v)[idx] for k, v in result.inputs.items()}
    return dataclasses.replace(result, **rows)


def _usable(result):
    """Points whose values stand: converged, or means over the attractor where no stable periodic
    orbit exists (status 6, ``Fidelity.attractor_periods``)."""
    return np.asarray(result.converged) | np.asarray(result.on_attractor)


def _resonance_dte(td):
    """DTE RMS of the usable points away from back-flank strikes (NaN elsewhere): the mesh
    resonances' curve. Where the rattling teeth strike the back flanks (``back_contact_share``
    > 0) the gears are in a double-sided vibro-impact regime, which the paper does not report and
    whose DTE depends on the attractor a sweep arrives on (coexisting attractors); its DTE can
    exceed the resonance peak (3950-4050 rpm of the calibrated pair's baseline), so it is kept out
    of the peaks that place A-E and reported apart in R1."""
    back = np.asarray(getattr(td, "back_contact_share", np.zeros_like(td.dte_rms)))
    return np.where(_usable(td) & (back <= 0.0), np.asarray(td.dte_rms), np.nan)


def _place_points(speeds, td):
    """Points A-E around the two DTE-RMS peaks of the sweep (REFERENCE §6: the mesh resonances,
    ``_resonance_dte``), or at their nominal speeds when the grid cannot resolve the peaks (steps
    above 50 rpm or not covering 1500-3600 rpm)."""
    dte = _resonance_dte(td)
    steps = np.diff(speeds)
    resolved = (
        speeds.size > 10
        and speeds[0] <= 1500.0
        and speeds[-1] >= 3600.0
        and np.max(steps) <= 50.0
        and np.sum(np.isfinite(dte)) > 10
    )
    if resolved:
        mid = (speeds > 1900.0) & (speeds < 3100.0) & np.isfinite(dte)
        split = speeds[np.argmin(np.where(mid, dte, np.inf))] if mid.any() else 2600.0
        low = int(np.nanargmax(np.where(speeds < split, dte, -np.inf)))
        high = int(np.nanargmax(np.where(speeds >= split, dte, -np.inf)))
        nearest = lambda rpm: int(np.argmin(np.abs(speeds - rpm)))
        return {
            "A": nearest(speeds[low] - 50.0),
            "B": nearest(speeds[low] + 50.0),
            "C": nearest(0.5 * (speeds[low] + speeds[high])),
            "D": nearest(speeds[high] - 50.0),
            "E": high,
        }, "peaks"
    return {k: int(np.argmin(np.abs(speeds - v))) for k, v in NOMINAL_POINTS_RPM.items()}, "nominal"


def _slot_at(repro, roll_angle_deg, forces):
    """(position, slot) of the loaded contact nearest to a gear 1 roll angle."""

    mesh = repro.mesh
    rb1 = float(gear_geometry(repro.pair).base_radius[0])
    roll = np.degrees(np.asarray(mesh.contact_position) / rb1)  # [M, 2]
    ok = (np.asarray(mesh.in_contact) > 0) & (np.asarray(forces) > 0)
    dist = np.where(ok, np.abs(roll - roll_angle_deg), np.inf)
    i, slot = np.unravel_index(np.argmin(dist), dist.shape)
    return int(i), int(slot), float(roll[i, slot])


def _contact_fields(repro: PaperReproduction) -> None:
    """Figs. 7 and 12: the contact at 25° (speeds B, E) and at 17° (speed E, ground vs polished)."""
    fid = repro.fidelity
    td = repro.tribo_dynamic
    wanted = [
        ("fig7_B", 25.0, td, repro.points["B"], "B, ground"),
        ("fig7_E", 25.0, td, repro.points["E"], "E, ground"),
        ("fig12_ground", 17.0, td, repro.points["E"], "E, ground"),
    ]
    pol = repro.variants.get("polished")
    e_speed = repro.point_speed("E")
    k = _indices_of(repro.variant_speeds, np.asarray([e_speed]))
    if k is not None:
        wanted.append(("fig12_polished", 17.0, pol, int(k[0]), "E, polished"))
    else:
        repro.unavailable["fig12_polished"] = (
            f"speed E ({e_speed:g} rpm) is not among the variant speeds, where the polished "
            "surfaces were run"
        )
    reason = ""
    if not fid.uses_ehl:
        reason = (
            f"the friction rung {fid.friction!r} solves no EHL contact, so there are no pressure or "
            "film profiles; use an EHL rung (the paper fidelity)"
        )
    for key, angle, result, index, label in wanted:
        deterministic = key.startswith("fig12") and fid.friction == "ehl_mixed"
        i, slot, roll = _slot_at(repro, angle, result.tooth_force[index])
        field = ContactField(
            label=label,
            roll_angle_deg=roll,
            speed_rpm=float(result.inputs["speed_rpm"][index]),
            hertz_pressure=float(result.hertz_pressure[index, i, slot]),
            load=float(result.tooth_force[index, i, slot]),
        )
        if reason:
            field.reason = reason
        else:
            try:
                field.solution, field.model, field.thermal = _solve_contact(
                    repro, result, index, i, slot, label, deterministic
                )
            except ValueError as err:
                field.reason = f"the EHL solve of this contact is not available: {err}"
        repro.fields[key] = field


def field_contact(repro: PaperReproduction, result, index: int, i: int, slot: int):
    """The LineContact of tooth pair ``slot`` at mesh position ``i`` of point ``index`` of
    ``result`` (a SweepResult of ``repro``): its dynamic load, radii and surface velocities."""

    u = result.surface_velocity[index, i, slot]
    return LineContact(
        reduced_radius=float(repro.mesh.reduced_radius[i, slot]),
        load_per_width=float(result.tooth_force[index, i, slot]) / float(repro.pair.face_width),
        u1=float(u[0]),
        u2=float(u[1]),
        e_reduced=reduced_modulus(*repro.pair.materials),
        inlet_temperature=repro.op.inlet_temperature,
    )


def field_surfaces(kind: str, short_cutoff: float | None = FIELD_SHORT_CUTOFF):
    """The roughness profiles Fig. 12 and R10 put in the film: the runs' synthetic surfaces
    (``presets.ground()`` / ``presets.polished()``: the same seed, Rq and correlation length) as a
    stylus instrument measures them, band-limited at λs = ``short_cutoff`` (m; default
    FIELD_SHORT_CUTOFF, see FIELD_DETERMINISTIC_NODES for why; None: unfiltered)."""

    make = {"ground": presets.ground, "polished": presets.polished}[kind]
    return make(short_cutoff=short_cutoff)


def _solve_contact(repro, result, index, i, slot, label, deterministic=False):
    """(EHLSolution, description, thermal) of one tooth contact of ``result``."""

    fid = repro.fidelity
    surfaces = None
    model = ehl_model_of(fid)
    if deterministic:
        model = EHLModel(
            n_nodes=FIELD_DETERMINISTIC_NODES,
            mixed="deterministic",
            thermal=False,
            boundary_friction=fid.boundary_friction,
            shear=fid.shear,
            limiting_shear_coefficient=fid.flat()["limiting_shear_coefficient"],
        )
        what = (
            f"deterministic roughness (profiles filtered at λs = {FIELD_SHORT_CUTOFF * 1e6:g} "
            f"µm), {FIELD_DETERMINISTIC_NODES} nodes, steady, iso-thermal snapshot at the "
            "coupled model's dynamic load"
        )
    else:
        what = f"{fid.friction} rung of the coupled model, {fid.n_nodes} nodes"
        if fid.friction == "ehl_mixed":
            what += f" ({fid.mixed_model} roughness)"
    if fid.friction == "ehl_mixed":
        polished = "polished" in label
        if deterministic:
            surfaces = field_surfaces("polished" if polished else "ground")
        else:
            surfaces = repro.polished if polished else repro.surfaces
    contact = field_contact(repro, result, index, i, slot)
    sol = solve_ehl(contact, repro.lubricant, model, surfaces)
    if not bool(sol.converged):
        what += f"; NOT CONVERGED (residual {float(sol.residual):.1e})"
    return sol, what, bool(model.thermal)


def _mark(result, i, attractor="‡", failed="†"):
    """The flag of point ``i``: none when converged, ``attractor`` for a mean over the attractor
    (no stable periodic orbit), ``failed`` otherwise."""
    if bool(result.converged[i]):
        return ""
    return attractor if bool(result.on_attractor[i]) else failed
