"""The paper's figure set (S. Li 2015, Figs. 3-12) and its reported results (REFERENCE §7, R1-R11).

``reproduce_paper`` runs the sweeps the figures need — the baseline speed sweep tribo-dynamic and
quasi-static, and the paper's variants (inlet 60 °C, 1500 N m, polished surfaces, iso-thermal) — and
the contact fields at the paper's roll angles; ``figure`` draws one figure from it (a matplotlib
Figure), ``save_figures`` writes all of them, ``paper_table`` compares R1-R11 with the paper.

What a figure shows depends on the fidelity: pressure and film profiles need an EHL friction rung,
temperatures the thermal rung, asperity pressures the mixed (rough-surface) rung, the iso-thermal
comparison a thermal run to compare with. A figure (or table row) the fidelity cannot give is not
drawn from something else: ``figure`` raises ``FigureUnavailable`` with the reason, ``save_figures``
records it, the table row says "not evaluated" and why.

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

from .fidelity import Fidelity

#: Figures of the paper this module reproduces (Fig. 9 is not described by REFERENCE §7).
FIGURES = (3, 4, 5, 6, 7, 8, 9, 10, 11, 12)

#: The paper's reported results, REFERENCE §7.
PAPER_RESULTS = {
    "R1": "(εd)rms peaks at 1750 rpm and 3500 rpm, the 3500 rpm peak much larger (Fig. 3)",
    "R2": "Φ̄ thermal tribo-dynamic at A, B, D, E = 257, 343, 431, 948 W; quasi-static = 276, 302, "
    "526, 532 W",
    "R3": "tribo-dynamic Φ̄ lower than quasi-static at A and D, higher at B and E, nearly equal at C",
    "R4": "efficiency Ψ within 99.6-99.85 % over the sweep (Fig. 4b)",
    "R5": "iso-thermal Φ̄ > thermal Φ̄, the gap growing with speed (Fig. 6)",
    "R6": "inlet 60 °C: lower Φ̄ and higher Ψ than 90 °C, ground surfaces (Fig. 8)",
    "R7": "1500 N m: Φ̄ much higher, Ψ only slightly lower than 700 N m (Fig. 10)",
    "R8": "polished: Φ̄ strongly lower, Ψ higher than ground (Fig. 11)",
    "R9": "sliding loss dominates at low speed; the rolling loss grows with speed to a significant share",
    "R10": "roll angle 17°, speed E: ground gives asperity pressures above 3 GPa; polished a full film "
    "with p well below 2 GPa (Fig. 12)",
    "R11": "roll angle 25°, speeds B and E: tribo-dynamic ph ≈ 0.8 GPa at both; temperature rise much "
    "higher at E (Fig. 7)",
}
PAPER_TRIBO_DYNAMIC_W = {"A": 257.0, "B": 343.0, "D": 431.0, "E": 948.0}
PAPER_QUASI_STATIC_W = {"A": 276.0, "B": 302.0, "D": 526.0, "E": 532.0}
PAPER_R3 = {"A": "lower", "B": "higher", "C": "nearly equal", "D": "lower", "E": "higher"}

#: Where points A-E sit when the sweep cannot locate the resonance peaks (REFERENCE §6: A just below
#: the 1750 rpm peak, B just above it, C away from both peaks, D just below 3500 rpm, E at it).
NOMINAL_POINTS_RPM = {"A": 1700.0, "B": 1800.0, "C": 2600.0, "D": 3400.0, "E": 3500.0}
#: Speeds of the quick run: the nominal points plus the ends of the paper's sweep.
QUICK_SPEEDS_RPM = (500.0, 1700.0, 1800.0, 2600.0, 3400.0, 3500.0, 4200.0)
#: |Φ̄_TD − Φ̄_QS| / Φ̄_QS below which tribo-dynamic and quasi-static count as "nearly equal" (R3).
NEARLY_EQUAL = 0.03
#: Roll angles of the paper's contact-field figures, degrees of gear 1.
FIELD_ROLL_ANGLE_DEG = {7: 25.0, 12: 17.0}
#: Fig. 12 (and R10) solve the contact with the roughness profiles themselves (deterministic mixed
#: EHL), as the paper does; the coupled model's statistical mixed rung gives the mean film only, with
#: no asperity pressures to show. The profiles are the runs' synthetic surfaces as a stylus
#: instrument measures them (``field_surfaces``): band-limited at λs = 2.5 µm, the ISO 3274 cutoff
#: for λc = 0.8 mm (the paper put measured profiles in its film). Unfiltered, the exponential
#: autocorrelation has no finest scale and the film moves with the grid (RESULTS
#: ``roughness_resolution``). Filtered, this contact settles by 2049 nodes (Δx ≈ 0.5 µm at 17°):
#: at the quasi-static 17° contact at 3500 rpm (RESULTS ``fig12_resolution``) polished p_max 1.750
#: / 1.745 / 1.737 GPa and h_min 0.188 / 0.190 / 0.189 µm on 1025 / 2049 / 4097 nodes, ground
#: p_max 4.94 / 4.86 GPa on 1025 / 2049 (29 s for the ground solve on 2049 nodes). The ground
#: film's asperity load is what still moves (1.6 % of the load on 1025 nodes, none on 2049: the
#: > 3 GPa peaks are micro-EHL pressure in a film 26 nm thin at its thinnest), as at the pitch
#: contact, where that film needs Δx ≲ λs/13 (``roughness_resolution``); a ground solve on 4097
#: nodes at the pitch contact did not finish in 20 min. (On 513 unfiltered nodes, the setting
#: before 2026-11-27, the polished p_max came out 1.80 GPa here and 2.00 GPa at the paper
#: fidelity's speed E.) Steady and iso-thermal: the thermal deterministic film's Poiseuille heat
#: is not grid-converged (README, Deterministic roughness); and the roughness is frozen at the
#: instant (moving roughness: ``solve_ehl_passage``).
FIELD_DETERMINISTIC_NODES = 2049
FIELD_SHORT_CUTOFF = 2.5e-6  # m, λs of ISO 3274 for λc = 0.8 mm (ground and polished flanks)

BASELINE_INLET_C, VARIANT_INLET_C = 90.0, 60.0
BASELINE_TORQUE, VARIANT_TORQUE = 700.0, 1500.0


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
    from . import presets
    from .gear.mesh import mesh_cycle
    from .operating import OperatingPoint

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
        from .sweep import sweep

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
    from ._validation import check_positive

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
    from .gear.geometry import gear_geometry

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
    from .lubrication.ehl import LineContact
    from .material import reduced_modulus

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
    from . import presets

    make = {"ground": presets.ground, "polished": presets.polished}[kind]
    return make(short_cutoff=short_cutoff)


def _solve_contact(repro, result, index, i, slot, label, deterministic=False):
    """(EHLSolution, description, thermal) of one tooth contact of ``result``."""
    from .contact.ehl import ehl_model_of
    from .lubrication.ehl import EHLModel, solve_ehl

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


# --------------------------------------------------------------------------------------------------
# Figures


def figure(repro: PaperReproduction, number: int):
    """The paper's Fig. ``number`` (3-12) drawn from ``repro``: a matplotlib Figure.

    Raises:
        FigureUnavailable: the fidelity or the run cannot give what the figure shows (``.reason``).
        ValueError: ``number`` is not one of FIGURES.
    """
    if number not in FIGURES:
        raise ValueError(f"number = {number!r} is not valid; valid choices: {FIGURES}")
    return _DRAW[number](repro)


def _pyplot():
    from .plotting import _pyplot as plt

    return plt()


def _mark_points(ax, repro, values, scale=1.0):
    for name, i in repro.points.items():
        y = float(np.asarray(values)[i]) * scale
        if np.isfinite(y):
            ax.annotate(
                name,
                (repro.speeds[i], y),
                textcoords="offset points",
                xytext=(0, 6),
                ha="center",
                fontsize=8,
                color="C3",
            )
            ax.plot(repro.speeds[i], y, "o", ms=4, color="C3")


def _flag(ax, speeds, values, result, scale=1.0):
    """Mark the points of ``result`` that failed (x) and those reported as attractor means (o)."""
    marks = (
        (np.asarray(result.failed), "x", "not converged (kept, flagged)"),
        (np.asarray(result.on_attractor), "o", "no stable periodic orbit (attractor mean)"),
    )
    for mask, marker, label in marks:
        if mask.any():
            ax.plot(
                np.asarray(speeds)[mask],
                np.asarray(values)[mask] * scale,
                marker,
                mfc="none",
                color="k",
                ms=6,
                zorder=5,
                label=label if label not in ax.get_legend_handles_labels()[1] else None,
            )


def _finish(fig, ax_list, title):
    for ax in ax_list:
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


def _subtitle(repro):
    fid = repro.fidelity
    thermal = "thermal" if fid.thermal else "iso-thermal"
    quick = ", quick run" if repro.quick else ""
    return (
        f"jaxgear, friction {fid.friction!r}, {thermal}, {fid.n_positions} positions/cycle"
        f"{_contact_parameters(fid)}{quick}"
    )


def _contact_parameters(fid):
    """The open contact parameters where they differ from the defaults (e.g. those of
    ``Fidelity.paper_calibrated()``), as ", shear 'eyring_split', nβσ 0.08"; else ""."""
    default = type(fid)()
    parts = []
    if fid.shear != default.shear:
        parts.append(f"shear {fid.shear!r}")
    if fid.asperity_density_product != default.asperity_density_product:
        parts.append(f"nβσ {float(fid.asperity_density_product):g}")
    if fid.asperity_slope_ratio != default.asperity_slope_ratio:
        parts.append(f"σ/β {float(fid.asperity_slope_ratio):g}")
    if fid.boundary_friction != default.boundary_friction:
        parts.append(f"μb {float(fid.boundary_friction):g}")
    return "".join(", " + p for p in parts)


def _fig3(repro):
    plt = _pyplot()
    td = repro.tribo_dynamic
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(repro.speeds, 1e6 * td.dte_rms, ".-", ms=3, label="tribo-dynamic")
    _mark_points(ax, repro, td.dte_rms, 1e6)
    _flag(ax, repro.speeds, td.dte_rms, td, 1e6)
    for rpm in (1750.0, 3500.0):
        ax.axvline(rpm, color="0.6", lw=0.8, ls=":", label="paper's peaks" if rpm < 2000 else None)
    ax.set(xlabel="gear 1 speed (rpm)", ylabel="(εd)rms (µm)")
    ax.legend(fontsize=8)
    return _finish(fig, [ax], f"Fig. 3: RMS dynamic transmission error\n{_subtitle(repro)}")


def _parts(result):
    return {
        "total": np.asarray(result.power_loss),
        "sliding": np.asarray(result.power_loss_sliding),
        "rolling": np.asarray(result.power_loss_rolling),
    }


def _fig4(repro):
    plt = _pyplot()
    td, qs = repro.tribo_dynamic, repro.quasi_static
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
    for key, ls in (("total", "-"), ("sliding", "--"), ("rolling", ":")):
        a.plot(repro.speeds, _parts(td)[key], ls, color="C0", label=f"{key}, tribo-dynamic")
        a.plot(repro.speeds, _parts(qs)[key], ls, color="C1", label=f"{key}, quasi-static")
    _flag(a, repro.speeds, td.power_loss, td)
    _mark_points(a, repro, td.power_loss)
    if not repro.fidelity.models_rolling:
        a.text(
            0.02,
            0.97,
            f"rolling loss: not modelled by the {repro.fidelity.friction!r} rung",
            transform=a.transAxes,
            va="top",
            fontsize=8,
        )
    a.set(xlabel="gear 1 speed (rpm)", ylabel="Φ̄ (W)", title="(a) mesh power loss")
    a.legend(fontsize=7, ncol=2, loc="lower right")
    b.plot(repro.speeds, 100 * td.efficiency, "-", label="tribo-dynamic")
    b.plot(repro.speeds, 100 * qs.efficiency, "--", label="quasi-static")
    b.axhspan(99.6, 99.85, color="0.9", label="paper's band (R4)")
    _flag(b, repro.speeds, td.efficiency, td, 100)
    b.set(xlabel="gear 1 speed (rpm)", ylabel="Ψ (%)", title="(b) mesh efficiency")
    b.legend(fontsize=8)
    return _finish(fig, [a, b], f"Fig. 4: power loss and efficiency\n{_subtitle(repro)}")


def _fig5(repro):
    plt = _pyplot()
    roll = np.degrees(np.asarray(repro.mesh.roll_angle))
    fig, axes = plt.subplots(1, 5, figsize=(16, 3.6), sharey=True)
    for ax, (name, i) in zip(axes, repro.points.items()):
        td = repro.tribo_dynamic.power_loss_position[i]
        qs = repro.quasi_static.power_loss_position[i]
        ax.plot(roll, td, "-", label="tribo-dynamic")
        ax.plot(roll, qs, "--", label="quasi-static")
        flag = _mark(repro.tribo_dynamic, i, " (attractor mean)", " (not converged)")
        ax.set(
            title=f"{name}: {repro.speeds[i]:.0f} rpm{flag}",
            xlabel="roll angle of the entering pair (°)",
        )
    axes[0].set_ylabel("Φ(t) (W)")
    axes[0].legend(fontsize=8)
    how = "around the DTE peaks" if repro.points_source == "peaks" else "at nominal speeds"
    return _finish(
        fig,
        axes,
        f"Fig. 5: power loss over one mesh cycle at points A-E ({how})\n{_subtitle(repro)}",
    )


def _compare(repro, number, key, label_base, label_variant, what):
    if key not in repro.variants:
        raise FigureUnavailable(number, repro.unavailable.get(key, f"{key} was not run"))
    plt = _pyplot()
    base, var = repro.variants["baseline"], repro.variants[key]
    v = repro.variant_speeds
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
    for res, color, label in ((base, "C0", label_base), (var, "C2", label_variant)):
        parts = _parts(res)
        a.plot(v, parts["total"], "-", color=color, label=f"total, {label}")
        a.plot(v, parts["sliding"], "--", color=color, label=f"sliding, {label}")
        a.plot(v, parts["rolling"], ":", color=color, label=f"rolling, {label}")
        _flag(a, v, res.power_loss, res)
        b.plot(v, 100 * res.efficiency, "-", color=color, label=label)
        _flag(b, v, res.efficiency, res, 100)
    a.set(xlabel="gear 1 speed (rpm)", ylabel="Φ̄ (W)", title="(a) mesh power loss")
    a.legend(fontsize=7, ncol=2)
    b.set(xlabel="gear 1 speed (rpm)", ylabel="Ψ (%)", title="(b) mesh efficiency")
    b.legend(fontsize=8)
    return _finish(fig, [a, b], f"Fig. {number}: {what}, tribo-dynamic\n{_subtitle(repro)}")


def _fig6(repro):
    if "isothermal" not in repro.variants:
        raise FigureUnavailable(6, repro.unavailable["isothermal"])
    plt = _pyplot()
    base, iso = repro.variants["baseline"], repro.variants["isothermal"]
    v = repro.variant_speeds
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
    a.plot(v, iso.power_loss, "-", color="C3", label="iso-thermal")
    a.plot(v, base.power_loss, "-", color="C0", label="thermal")
    a.set(xlabel="gear 1 speed (rpm)", ylabel="Φ̄ (W)", title="(a) mesh power loss")
    a.legend(fontsize=8)
    gap = 100 * (np.asarray(iso.power_loss) - base.power_loss) / base.power_loss
    b.plot(v, gap, ".-")
    b.set(xlabel="gear 1 speed (rpm)", ylabel="(Φ̄_iso − Φ̄_thermal)/Φ̄_thermal (%)", title="(b) gap")
    return _finish(fig, [a, b], f"Fig. 6: iso-thermal against thermal\n{_subtitle(repro)}")


def _fields_figure(repro, number, keys, title):
    fields = [repro.fields.get(k) for k in keys]
    missing = [f for f in fields if f is None or f.solution is None]
    if missing:
        reason = next((f.reason for f in missing if f is not None and f.reason), "")
        if not reason:
            reason = "; ".join(repro.unavailable.get(k, "") for k in keys if k in repro.unavailable)
        raise FigureUnavailable(number, reason or "the contact fields were not computed")
    plt = _pyplot()
    thermal = all(f.thermal for f in fields)
    rows = 3 if thermal else 2
    fig, axes = plt.subplots(
        rows, len(fields), figsize=(5.5 * len(fields), 2.6 * rows), squeeze=False
    )
    for col, f in enumerate(fields):
        sol = f.solution
        b = float(sol.hertz_half_width)
        x = np.asarray(sol.x) / b
        axes[0, col].plot(x, np.asarray(sol.p) / 1e9)
        axes[0, col].set(
            ylabel="p (GPa)",
            title=f"{f.label}: {f.speed_rpm:.0f} rpm, {f.roll_angle_deg:.2f}°, "
            f"ph {f.hertz_pressure / 1e9:.2f} GPa",
        )
        h = np.asarray(sol.h) * 1e6
        axes[1, col].plot(x, h)
        # The inlet gap grows to tens of µm: scale to the film inside the contact.
        inside = np.abs(x) <= 1.0
        top = 3.0 * float(np.max(h[inside])) if inside.any() else float(np.max(h))
        # (deterministic roughness: h < 0 where asperities are in contact, Hu-Zhu)
        bottom = min(0.0, 1.1 * float(np.min(h[inside]))) if inside.any() else 0.0
        axes[1, col].set(ylabel="h (µm)", ylim=(bottom, top))
        if thermal:
            rise = np.asarray(sol.temperature) - float(repro.op.inlet_temperature)
            axes[2, col].plot(x, rise)
            axes[2, col].set(ylabel="film temperature rise (K)")
        axes[-1, col].set(xlabel="x / b (Hertz half-widths)")
        for ax in axes[:, col]:
            ax.set_xlim(-2.5, 1.5)
    note = "" if thermal else " (no temperatures: iso-thermal solve)"
    models = sorted({f.model for f in fields if f.model})
    how = "".join(f"\n{m}" for m in models)
    return _finish(fig, axes.flat, f"Fig. {number}: {title}{note}\n{_subtitle(repro)}{how}")


def _fig7(repro):
    return _fields_figure(
        repro, 7, ("fig7_B", "fig7_E"), "pressure, film and temperature at roll angle 25°"
    )


def _fig8(repro):
    return _compare(repro, 8, "inlet_60C", "90 °C", "60 °C", "inlet temperature 60 against 90 °C")


def _fig9(repro):
    raise FigureUnavailable(
        9, "REFERENCE §7 does not say what the paper's Fig. 9 shows, so there is nothing to match"
    )


def _fig10(repro):
    return _compare(repro, 10, "torque_1500", "700 N m", "1500 N m", "torque 1500 against 700 N m")


def _fig11(repro):
    return _compare(repro, 11, "polished", "ground", "polished", "polished against ground")


def _fig12(repro):
    if repro.fidelity.friction != "ehl_mixed":
        raise FigureUnavailable(
            12,
            f"asperity contact pressures need the mixed EHL rung (rough surfaces); the "
            f"{repro.fidelity.friction!r} rung would draw ground and polished alike",
        )
    return _fields_figure(
        repro,
        12,
        ("fig12_ground", "fig12_polished"),
        "pressure and film at roll angle 17°, speed E, ground against polished",
    )


_DRAW = {
    3: _fig3,
    4: _fig4,
    5: _fig5,
    6: _fig6,
    7: _fig7,
    8: _fig8,
    9: _fig9,
    10: _fig10,
    11: _fig11,
    12: _fig12,
}
FIGURE_FILES = {
    3: "fig03_dte_rms.png",
    4: "fig04_power_loss_efficiency.png",
    5: "fig05_mesh_cycle_loss.png",
    6: "fig06_isothermal_vs_thermal.png",
    7: "fig07_fields_25deg.png",
    8: "fig08_inlet_temperature.png",
    9: "fig09.png",
    10: "fig10_torque.png",
    11: "fig11_surfaces.png",
    12: "fig12_fields_17deg.png",
}


def save_figures(repro: PaperReproduction, out_dir: str | Path) -> tuple[dict, dict]:
    """Write every figure that ``repro`` can give as PNG into ``out_dir``.

    Returns:
        (written: figure number → path, skipped: figure number → reason).
    """
    plt = _pyplot()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written, skipped = {}, {}
    for n in FIGURES:
        try:
            fig = figure(repro, n)
        except FigureUnavailable as err:
            skipped[n] = err.reason
            continue
        path = out / FIGURE_FILES[n]
        fig.savefig(path, dpi=100)
        plt.close(fig)
        written[n] = path
    return written, skipped


# --------------------------------------------------------------------------------------------------
# R1-R11 against the paper


def _row(rid, jaxgear, agrees, note=""):
    return {
        "id": rid,
        "paper": PAPER_RESULTS[rid],
        "jaxgear": jaxgear,
        "agrees": agrees,
        "note": note,
    }


def _not_evaluated(rid, reason):
    return _row(rid, "not evaluated", None, reason)


def _mark(result, i, attractor="‡", failed="†"):
    """The flag of point ``i``: none when converged, ``attractor`` for a mean over the attractor
    (no stable periodic orbit), ``failed`` otherwise."""
    if bool(result.converged[i]):
        return ""
    return attractor if bool(result.on_attractor[i]) else failed


def _at(result, i):
    return f"{float(result.power_loss[i]):.0f}{_mark(result, i)}"


def _ok_both(a, b):
    return _usable(a) & _usable(b)


def paper_table(repro: PaperReproduction) -> list[dict]:
    """R1-R11 (REFERENCE §7): per row the paper's statement, jaxgear's value, whether they agree
    (True/False, or None where the fidelity or the run cannot say) and a note with the criterion.
    "†" marks values at points whose solution did not converge."""
    td, qs, P = repro.tribo_dynamic, repro.quasi_static, repro.points
    fid = repro.fidelity
    rows = []

    # R1
    if repro.points_source == "peaks":
        dte = _resonance_dte(td)
        low = int(np.nanargmax(np.where(repro.speeds < repro.point_speed("C"), dte, np.nan)))
        high = P["E"]
        lo_rpm, hi_rpm = repro.speeds[low], repro.speeds[high]
        ok = (
            abs(lo_rpm - 1750.0) <= 150.0
            and abs(hi_rpm - 3500.0) <= 200.0
            and dte[high] > 1.2 * dte[low]
        )
        value = (
            f"peaks at {lo_rpm:.0f} rpm ({1e6 * dte[low]:.1f} µm) and {hi_rpm:.0f} rpm "
            f"({1e6 * dte[high]:.1f} µm)"
        )
        # the back-flank rattle, kept out of the peaks, must not exceed the higher one unnoticed:
        # the paper's 3500 rpm peak is its largest DTE
        every = np.where(_usable(td), np.asarray(td.dte_rms), np.nan)
        top = int(np.nanargmax(every))
        if every[top] > dte[high]:
            ok = False
            value += (
                f"; the back-flank rattle reaches {1e6 * every[top]:.1f} µm at "
                f"{repro.speeds[top]:.0f} rpm"
            )
        rows.append(
            _row(
                "R1",
                value,
                bool(ok),
                "criterion: peaks within 150 rpm of 1750 and 200 rpm of 3500, the higher one "
                "> 1.2× the lower and the largest DTE of the sweep (converged points and attractor "
                "means; speeds whose teeth strike the back flanks are not peaks but count as DTE)",
            )
        )
    else:
        values = ", ".join(f"{k} {1e6 * float(td.dte_rms[i]):.1f}" for k, i in P.items())
        rows.append(
            _row(
                "R1",
                f"(εd)rms at A-E (µm): {values}",
                None,
                "not evaluated: the speed grid cannot locate the peaks (run without --quick)",
            )
        )

    # R2
    td_vals = ", ".join(f"{k} {_at(td, P[k])}" for k in PAPER_TRIBO_DYNAMIC_W)
    qs_vals = ", ".join(f"{k} {_at(qs, P[k])}" for k in PAPER_QUASI_STATIC_W)
    ratios = [float(td.power_loss[P[k]]) / v for k, v in PAPER_TRIBO_DYNAMIC_W.items()] + [
        float(qs.power_loss[P[k]]) / v for k, v in PAPER_QUASI_STATIC_W.items()
    ]
    speeds = ", ".join(f"{k} {repro.point_speed(k):.0f}" for k in P)
    rows.append(
        _row(
            "R2",
            f"tribo-dynamic {td_vals} W; quasi-static {qs_vals} W",
            None,
            f"values, not a trend: jaxgear/paper from {min(ratios):.2f} to {max(ratios):.2f}; "
            f"speeds (rpm): {speeds}",
        )
    )

    # R3
    words, agree = [], True
    for k, i in P.items():
        rel = (float(td.power_loss[i]) - float(qs.power_loss[i])) / float(qs.power_loss[i])
        word = "nearly equal" if abs(rel) < NEARLY_EQUAL else ("higher" if rel > 0 else "lower")
        agree &= word == PAPER_R3[k]
        flag = _mark(td, i)
        words.append(f"{k} {word} ({100 * rel:+.1f} %){flag}")
    rows.append(
        _row(
            "R3",
            "; ".join(words),
            bool(agree),
            f"'nearly equal' means within ±{100 * NEARLY_EQUAL:.0f} %",
        )
    )

    # R4
    eff = 100 * np.asarray(td.efficiency)[_usable(td)]
    if eff.size:
        rows.append(
            _row(
                "R4",
                f"Ψ {eff.min():.3f}-{eff.max():.3f} % over {eff.size} usable speeds "
                f"({repro.speeds[0]:.0f}-{repro.speeds[-1]:.0f} rpm)",
                bool(eff.min() >= 99.6 and eff.max() <= 99.85),
                "criterion: every usable speed (converged or attractor mean) inside 99.6-99.85 %",
            )
        )
    else:
        rows.append(_not_evaluated("R4", "no usable speed"))

    # R5
    if "isothermal" in repro.variants:
        base, iso = repro.variants["baseline"], repro.variants["isothermal"]
        ok = _ok_both(base, iso)
        gap = (np.asarray(iso.power_loss) - base.power_loss) / base.power_loss
        g = gap[ok]
        agrees = bool(g.size >= 2 and np.all(g > 0) and g[-1] > g[0])
        rows.append(
            _row(
                "R5",
                f"(Φ̄_iso − Φ̄_thermal)/Φ̄_thermal from {100 * g[0]:+.1f} % to {100 * g[-1]:+.1f} %"
                if g.size
                else "no usable common speed",
                agrees if g.size else None,
                "criterion: iso-thermal above thermal at every speed, gap larger at the highest "
                "speed than at the lowest",
            )
        )
    else:
        rows.append(_not_evaluated("R5", repro.unavailable["isothermal"]))

    # R6-R8
    rows.append(_variant_row(repro, "R6", "inlet_60C", "60 °C", "90 °C"))
    rows.append(_variant_row(repro, "R7", "torque_1500", "1500 N m", "700 N m"))
    rows.append(_variant_row(repro, "R8", "polished", "polished", "ground"))

    # R9
    if not fid.models_rolling:
        rows.append(
            _not_evaluated(
                "R9",
                f"the friction rung {fid.friction!r} models the sliding loss only (no rolling "
                "loss); use the ehl_formula or an EHL rung",
            )
        )
    else:
        ok = _usable(td)
        share = np.asarray(td.power_loss_rolling) / np.asarray(td.power_loss)
        s = share[ok]
        if s.size >= 2:
            agrees = bool(s[0] < 0.5 and s[-1] > s[0] and s[-1] >= 0.2)
            rows.append(
                _row(
                    "R9",
                    f"rolling share {100 * s[0]:.0f} % at {repro.speeds[ok][0]:.0f} rpm, "
                    f"{100 * s[-1]:.0f} % at {repro.speeds[ok][-1]:.0f} rpm",
                    agrees,
                    "criterion: sliding > rolling at the lowest speed; the rolling share grows to "
                    "≥ 20 % at the highest",
                )
            )
        else:
            rows.append(_not_evaluated("R9", "fewer than two usable speeds"))

    # R10
    g, p = repro.fields.get("fig12_ground"), repro.fields.get("fig12_polished")
    if fid.friction != "ehl_mixed":
        rows.append(
            _not_evaluated(
                "R10",
                f"asperity pressures need the mixed EHL rung; the fidelity's friction is "
                f"{fid.friction!r}",
            )
        )
    elif g is None or p is None or g.solution is None or p.solution is None:
        reason = (g.reason if g is not None else "") or (p.reason if p is not None else "")
        rows.append(_not_evaluated("R10", reason or repro.unavailable.get("fig12_polished", "")))
    else:
        pg, pp = float(np.max(g.solution.p)) / 1e9, float(np.max(p.solution.p)) / 1e9
        hp = float(p.solution.h_min) * 1e6
        share = float(g.solution.contact_load_share)
        converged = bool(g.solution.converged) and bool(p.solution.converged)
        rows.append(
            _row(
                "R10",
                f"max p ground {pg:.2f} GPa ({100 * share:.0f} % of the load on asperities), "
                f"polished {pp:.2f} GPa (h_min {hp:.3f} µm)" + ("" if converged else " †"),
                bool(converged and pg > 3.0 and pp < 2.0 and hp > 0.0),
                f"criterion: ground above 3 GPa, polished below 2 GPa with a film; {g.model}",
            )
        )

    # R11
    b, e = repro.fields["fig7_B"], repro.fields["fig7_E"]
    ph_ok = all(abs(f.hertz_pressure / 1e9 - 0.8) <= 0.12 for f in (b, e))
    text = (
        f"ph {b.hertz_pressure / 1e9:.2f} GPa at B ({b.roll_angle_deg:.2f}°), "
        f"{e.hertz_pressure / 1e9:.2f} GPa at E"
    )
    criterion = "criterion: dynamic ph within 0.8 ± 0.12 GPa at B and E"
    if fid.thermal and b.solution is not None and e.solution is not None:
        t0 = float(repro.op.inlet_temperature)
        rb = float(np.max(b.solution.temperature)) - t0
        re = float(np.max(e.solution.temperature)) - t0
        rows.append(
            _row(
                "R11",
                f"{text}; film temperature rise {rb:.1f} K at B, {re:.1f} K at E",
                bool(ph_ok and re > 1.5 * rb),
                criterion + "; temperature rise at E > 1.5× that at B",
            )
        )
    else:
        why = (
            "iso-thermal fidelity"
            if not fid.thermal
            else (b.reason or e.reason or "no contact solution")
        )
        rows.append(
            _row(
                "R11",
                text,
                bool(ph_ok),
                f"{criterion}; temperature part not evaluated ({why})",
            )
        )
    return rows


def _variant_row(repro, rid, key, name, base_name):
    if key not in repro.variants:
        return _not_evaluated(rid, repro.unavailable.get(key, f"{key} was not run"))
    base, var = repro.variants["baseline"], repro.variants[key]
    ok = _ok_both(base, var)
    if not ok.any():
        return _not_evaluated(rid, "no usable speed in both runs")
    lb, lv = np.asarray(base.power_loss)[ok], np.asarray(var.power_loss)[ok]
    eb, ev = 100 * np.asarray(base.efficiency)[ok], 100 * np.asarray(var.efficiency)[ok]
    ratio = float(np.mean(lv / lb))
    d_eff = float(np.mean(ev - eb))
    text = (
        f"Φ̄ {name}/{base_name} {ratio:.2f} (mean over {int(ok.sum())} speeds); "
        f"ΔΨ {d_eff:+.3f} percentage points"
    )
    if rid == "R6":
        agrees = bool(np.all(lv < lb) and np.all(ev > eb))
        crit = "criterion: lower Φ̄ and higher Ψ at every usable speed"
    elif rid == "R7":
        agrees = bool(ratio > 1.5 and np.all(ev < eb) and d_eff > -0.1)
        crit = (
            "criterion: Φ̄ ratio > 1.5; Ψ lower at every speed, by less than 0.1 points on average"
        )
    else:
        agrees = bool(ratio < 0.8 and np.all(ev > eb))
        crit = "criterion: Φ̄ ratio < 0.8; Ψ higher at every usable speed"
    return _row(rid, text, agrees, crit)


def table_markdown(rows: list[dict]) -> str:
    """The R1-R11 rows as a Markdown table."""
    mark = {True: "yes", False: "no", None: "—"}
    lines = [
        "| # | paper (REFERENCE §7) | jaxgear | agrees | note |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        cells = [r["id"], r["paper"], r["jaxgear"], mark[r["agrees"]], r["note"]]
        lines.append("| " + " | ".join(str(c).replace("|", "/") for c in cells) + " |")
    return "\n".join(lines)


def write_report(repro: PaperReproduction, out_dir: str | Path) -> dict:
    """Write the figures (PNG), ``paper_table.md`` / ``paper_table.json`` (R1-R11), the sweeps as CSV
    (``data/``) and ``figures.json`` (what was written, what was skipped and why, the points, the
    timings) into ``out_dir``. Returns the contents of figures.json."""
    import json

    out = Path(out_dir)
    written, skipped = save_figures(repro, out)
    rows = paper_table(repro)
    fid = repro.fidelity
    header = (
        f"# The paper's results (S. Li 2015, REFERENCE §7) beside jaxgear\n\n"
        f"{_subtitle(repro)}; points A-E "
        + ", ".join(f"{k} {repro.point_speed(k):.0f} rpm" for k in repro.points)
        + f" ({repro.points_source}). † = not converged (kept, flagged); ‡ = no stable periodic "
        "orbit, mean over the attractor (status 6).\n\n"
    )
    (out / "paper_table.md").write_text(header + table_markdown(rows) + "\n")
    data = out / "data"
    data.mkdir(exist_ok=True)
    csvs = [repro.tribo_dynamic.to_csv(data / "baseline_tribo_dynamic.csv")]
    csvs.append(repro.quasi_static.to_csv(data / "baseline_quasi_static.csv"))
    for name, result in repro.variants.items():
        if name != "baseline":
            csvs.append(result.to_csv(data / f"variant_{name}.csv"))
    (out / "paper_table.json").write_text(json.dumps(rows, indent=1))
    manifest = {
        "fidelity": fid.flat(),
        "quick": repro.quick,
        "speeds_rpm": [float(repro.speeds[0]), float(repro.speeds[-1]), int(repro.speeds.size)],
        "variant_speeds_rpm": [
            float(repro.variant_speeds[0]),
            float(repro.variant_speeds[-1]),
            int(repro.variant_speeds.size),
        ],
        "points": {
            k: {
                "speed_rpm": repro.point_speed(k),
                "converged": bool(repro.tribo_dynamic.converged[i]),
                "attractor_mean": bool(repro.tribo_dynamic.on_attractor[i]),
            }
            for k, i in repro.points.items()
        },
        "points_source": repro.points_source,
        "written": {f"Fig. {n}": p.name for n, p in written.items()},
        "skipped": {f"Fig. {n}": reason for n, reason in skipped.items()},
        "tables": ["paper_table.md", "paper_table.json"],
        "data": [f"data/{p.name}" for p in csvs],
        "timings_s": repro.timings,
        "on_attractor": {
            name: int(np.sum(np.asarray(r.on_attractor)))
            for name, r in [("tribo_dynamic", repro.tribo_dynamic)] + list(repro.variants.items())
        },
        "not_converged": {
            name: int(np.sum(np.asarray(r.failed)))
            for name, r in [
                ("tribo_dynamic", repro.tribo_dynamic),
                ("quasi_static", repro.quasi_static),
            ]
            + list(repro.variants.items())
        },
    }
    (out / "figures.json").write_text(json.dumps(manifest, indent=1))
    return manifest


__all__ = [
    "FIGURES",
    "PAPER_RESULTS",
    "ContactField",
    "FigureUnavailable",
    "PaperReproduction",
    "figure",
    "paper_table",
    "reproduce_paper",
    "save_figures",
    "table_markdown",
    "write_report",
]
