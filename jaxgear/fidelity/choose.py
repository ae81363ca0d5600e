"""Automatic choice of the fidelity ladder's rungs (DESIGN §4): the cheapest rungs whose
*measured* error stays under a tolerance for the scenario at hand, with the reasons in words.

Two steps, both on the host (no simulation is run):

1. :func:`scenario_indicators` evaluates the scenario's dimensionless indicators in closed form at the
   pitch point: film parameter λ (Pan & Hamrock central film over the composite roughness), Péclet
   number of the surfaces, slide-to-roll ratio range, distance of the mesh frequency (and its second
   harmonic) from the mesh-coupled natural frequencies, and the maximum Hertz pressure.
2. :func:`choose_fidelity` reads the measured error table ``jaxgear/data/fidelity_errors.json``, written
   by ``benchmarks/fidelity_trade.py``: per rung (physics × resolution) and per measured scenario, Φ̄, Ψ
   and DTE RMS, the run time per point, and the scenarios' indicators. It predicts each candidate's
   error at the query's indicators and returns the cheapest candidate under the tolerance.

How the prediction works (conservative and monotone by construction). The error of a candidate
against the table's reference is taken as the sum of one term per axis on which it departs from the
reference (first-order independence of the axes; the triangle inequality makes the sum an upper bound
when the terms are):

| axis | term measured as | indicator (harder →) |
|---|---|---|
| dynamics | the rung with only this axis changed, vs the reference physics, same resolution | resonance distance (smaller) |
| friction | 〃 | film parameter λ (smaller) |
| thermal | 〃 | Péclet number (larger) |
| transient | 〃 | film parameter λ (smaller) |
| resolution | the reference physics at that resolution, vs the reference | max Hertz pressure (larger) |

Each term is read off the measured scenarios along its indicator with a monotone envelope: take the
nearest measured scenario at least as hard as the query, and the largest error measured at any
scenario no harder than that one. A query harder than every measured scenario gets no bound (the
axis stays at the reference's rung): the table is never extrapolated. A candidate that did not converge
at a scenario counts as unbounded there. So a thinner film can only move friction up the ladder, and
coming closer to a resonance can only move the dynamics to tribo-dynamic.

Why a separate function for the reasons: ``Fidelity`` is static (hashed into every compiled program),
so it cannot carry a per-scenario text without recompiling for every new text. ``Fidelity.auto(...)``
returns the plain ``Fidelity``; ``choose_fidelity(...)`` (same arguments) returns a
:class:`FidelityChoice` with the fidelity, the ``reasons`` and the numbers behind them.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
from collections.abc import Mapping, Sequence
from importlib import resources
from pathlib import Path

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from ..dynamics.modes import mode_shapes
from ..gear.geometry import gear_geometry, hertz_half_width, hertz_pressure, normal_load
from ..gear.mesh import mesh_cycle
from ..material import reduced_modulus
from .ladder import Fidelity

#: Version of the indicator definitions; a table measured with other definitions is refused.
INDICATOR_VERSION = 1

#: Quantities whose error the table measures: Φ̄ (W), Ψ (-), DTE RMS (m). Errors are relative:
#: |x − x_ref| / |x_ref| (for Ψ that is |ΔΨ|/Ψ ≈ |ΔΨ|, a tiny number: Ψ ≈ 0.998).
QUANTITIES = ("power_loss", "efficiency", "dte_rms")

#: Ladder order of each physics axis (cheap → expensive).
AXIS_ORDER = {
    "dynamics": ("quasi_static", "tribo_dynamic"),
    "friction": ("constant", "regression", "ehl_formula", "ehl_smooth", "ehl_mixed"),
    "thermal": (False, True),
    "transient": (False, True),
}

#: Indicator that sets each axis's error, and whether a larger value is harder (+1) or easier (−1).
AXIS_INDICATOR = {
    "dynamics": ("resonance_distance", -1),
    "friction": ("film_parameter", -1),
    "thermal": ("peclet", +1),
    "transient": ("film_parameter", -1),
    "resolution": ("hertz_pressure", +1),
}

#: Resolution fields of a Fidelity that a table's resolution level sets.
RESOLUTION_FIELDS = ("n_positions", "n_nodes", "steps_per_period")

#: A mode counts as mesh-coupled (excited by the transmission error) above this share of its strain
#: energy in the mesh spring; the paper's pair: 0.64 and 0.36 for its two coupled modes, 0 otherwise.
MESH_COUPLED_FRACTION = 0.1

#: Mesh harmonics k whose frequency k f_mesh is compared with the natural frequencies: the primary
#: resonance and the super-harmonic that gives the paper's 1750 rpm peak (REFERENCE §6, §7 R1).
RESONANCE_HARMONICS = (1, 2)

#: Positions of the quasi-static mesh cycle used for the mean mesh stiffness and max Hertz pressure.
_INDICATOR_POSITIONS = 64


# -------------------------------------------------------------------------------------------------
# Indicators
# -------------------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class ScenarioIndicators:
    """Dimensionless indicators of a scenario (pitch point, quasi-static, inlet temperature).

    Attributes:
        film_parameter: λ = h_c/σ (inf for smooth surfaces).
        central_film: h_c, Pan & Hamrock (1989) central film at the pitch point, m (REFERENCE §8).
        composite_roughness: σ = √(Rq1² + Rq2²) of the (scaled) surfaces, m.
        peclet: Pe = u b/(2κ) of the slower surface at the pitch point (u its velocity, b the Hertz
            half-width, κ its thermal diffusivity): the Jaeger moving-heat-source number; 14-120 over
            500-4200 rpm for the paper's pair (REFERENCE §5).
        slide_to_roll_range: (SR at the start, SR at the end) of the path of contact, SR = us/ur.
        slide_to_roll_max: max |SR| over the path of contact.
        hertz_pressure: maximum quasi-static Hertz pressure over the mesh cycle, Pa.
        hertz_pressure_pitch: Hertz pressure at the pitch point, Pa.
        mesh_frequency: z1 n1/60, Hz.
        resonance_distance: min over mesh-coupled modes f_m and harmonics k ∈ {1, 2} of
            |k f_mesh − f_m|/f_m (0: on a resonance).
        nearest_resonance: (k, f_m in Hz) of that minimum.
        natural_frequencies: the mesh-coupled natural frequencies, Hz (linearised model, mean km).
        speed_rpm, torque, inlet_temperature: the operating point (rpm, N m, K).
    """

    film_parameter: float
    central_film: float
    composite_roughness: float
    peclet: float
    slide_to_roll_range: tuple[float, float]
    slide_to_roll_max: float
    hertz_pressure: float
    hertz_pressure_pitch: float
    mesh_frequency: float
    resonance_distance: float
    nearest_resonance: tuple[int, float]
    natural_frequencies: tuple[float, ...]
    speed_rpm: float
    torque: float
    inlet_temperature: float

    def as_dict(self) -> dict:
        """JSON-ready dict (λ = inf written as None)."""
        out = dataclasses.asdict(self)
        if not math.isfinite(out["film_parameter"]):
            out["film_parameter"] = None
        out["slide_to_roll_range"] = list(out["slide_to_roll_range"])
        out["nearest_resonance"] = list(out["nearest_resonance"])
        out["natural_frequencies"] = list(out["natural_frequencies"])
        return out

    @classmethod
    def from_dict(cls, d: Mapping) -> ScenarioIndicators:
        """Inverse of :meth:`as_dict`."""
        lam = d["film_parameter"]
        return cls(
            **{
                **{f.name: d[f.name] for f in dataclasses.fields(cls)},
                "film_parameter": math.inf if lam is None else float(lam),
                "slide_to_roll_range": tuple(d["slide_to_roll_range"]),
                "nearest_resonance": tuple(d["nearest_resonance"]),
                "natural_frequencies": tuple(d["natural_frequencies"]),
            }
        )

    def summary(self) -> str:
        """One line in words, for the reasons."""
        lam = self.film_parameter
        if math.isinf(lam):
            film = "λ = inf (smooth surfaces: full film)"
        else:
            regime = "boundary/mixed" if lam < 1 else ("mixed" if lam < 3 else "full film")
            film = (
                f"λ = {lam:.2f} (central film {self.central_film * 1e6:.3f} µm over σ = "
                f"{self.composite_roughness * 1e6:.3f} µm: {regime})"
            )
        k, fm = self.nearest_resonance
        harm = "f_mesh" if k == 1 else f"{k} f_mesh"
        return (
            f"{film}; Péclet {self.peclet:.0f}; slide-to-roll {self.slide_to_roll_range[0]:+.2f} to "
            f"{self.slide_to_roll_range[1]:+.2f}; max Hertz pressure "
            f"{self.hertz_pressure * 1e-9:.2f} GPa; mesh frequency {self.mesh_frequency:.0f} Hz, "
            f"{self.resonance_distance:.2f} from the nearest resonance ({harm} vs the {fm:.0f} Hz mode)"
        )


def _f(x) -> float:
    return float(np.asarray(x))


@eqx.filter_jit
def _cycle_and_modes(pair, lubricant, surfaces, torque, inlet_temperature):
    """The traced part of the indicators, one compiled program: mean mesh stiffness and max Hertz
    pressure of the quasi-static mesh cycle, modes at that stiffness, η0, α and σ."""

    mesh = mesh_cycle(pair, torque, _INDICATOR_POSITIONS, stiffness="potential_energy")
    modes = mode_shapes(pair, jnp.mean(mesh.mesh_stiffness))
    return {
        "hertz_max": jnp.max(mesh.hertz_pressure),
        "frequencies": modes.frequencies,
        "mesh_energy_fraction": modes.mesh_energy_fraction,
        "eta0": lubricant.base_viscosity(inlet_temperature),
        "alpha": lubricant.pressure_viscosity_coefficient(inlet_temperature),
        "sigma": surfaces.composite_rq,
    }


def _speed_free_part(pair, lubricant, surfaces, torque, inlet_temperature) -> dict:
    """Everything the indicators need that does not depend on the speed."""

    geo = gear_geometry(pair)
    s_pitch = _f(geo.pitch_point)
    loa = _f(geo.line_of_action_length)
    rho = np.array([s_pitch, loa - s_pitch])
    radius = rho[0] * rho[1] / (rho[0] + rho[1])
    e_red = _f(reduced_modulus(*pair.materials))
    # The pitch point carries the whole load where it lies in single-tooth contact, else about half.
    eps = _f(geo.roll_angle_pitch)
    single = _f(geo.roll_angle_lowest_single) <= eps <= _f(geo.roll_angle_highest_single)
    load_per_width = _f(normal_load(pair, torque)) / _f(pair.face_width) * (1.0 if single else 0.5)
    core = _cycle_and_modes(
        pair, lubricant, surfaces, jnp.asarray(torque, float), jnp.asarray(inlet_temperature, float)
    )
    freq = np.asarray(core["frequencies"])
    coupled = (np.asarray(core["mesh_energy_fraction"]) > MESH_COUPLED_FRACTION) & (freq > 0)
    path = np.array([_f(geo.path_start), _f(geo.path_end)])
    return {
        "teeth": tuple(int(z) for z in pair.teeth),
        "rho": rho,
        "path_rho": np.stack([path, loa - path], axis=-1),  # [start/end, gear]
        "radius": radius,
        "e_reduced": e_red,
        "load_per_width": load_per_width,
        "half_width": _f(hertz_half_width(load_per_width, radius, e_red)),
        "hertz_pitch": _f(hertz_pressure(load_per_width, radius, e_red)),
        "hertz_max": _f(core["hertz_max"]),
        "diffusivity": np.array([_f(m.thermal_diffusivity) for m in pair.materials]),
        "eta0": _f(core["eta0"]),
        "alpha": _f(core["alpha"]),
        "sigma": _f(core["sigma"]),
        "modes": tuple(float(f) for f in freq[coupled]),
        "torque": _f(torque),
        "inlet_temperature": _f(inlet_temperature),
    }


def _at_speed(base: dict, speed_rpm: float) -> ScenarioIndicators:
    z1, z2 = base["teeth"]
    omega = np.array([1.0, z1 / z2]) * speed_rpm * 2.0 * math.pi / 60.0
    u = base["rho"] * omega  # surface velocities at the pitch point
    um = 0.5 * float(np.sum(u))
    radius, e_red = base["radius"], base["e_reduced"]
    # Pan & Hamrock (1989) central film (REFERENCE §8): hc/R = 2.922 W^-0.166 U^0.692 G^0.470.
    speed_param = base["eta0"] * um / (e_red * radius)
    load_param = base["load_per_width"] / (e_red * radius)
    material_param = base["alpha"] * e_red
    hc = radius * 2.922 * load_param**-0.166 * speed_param**0.692 * material_param**0.470
    sigma = base["sigma"]
    lam = hc / sigma if sigma > 0 else math.inf
    peclet = float(np.min(u * base["half_width"] / (2.0 * base["diffusivity"])))
    ends = base["path_rho"] * omega  # [start/end, gear] velocities at the path ends
    sr = 2.0 * (ends[:, 0] - ends[:, 1]) / (ends[:, 0] + ends[:, 1])
    f_mesh = z1 * speed_rpm / 60.0
    best = (math.inf, (1, math.nan))
    for fm in base["modes"]:
        for k in RESONANCE_HARMONICS:
            d = abs(k * f_mesh - fm) / fm
            if d < best[0]:
                best = (d, (k, fm))
    return ScenarioIndicators(
        film_parameter=float(lam),
        central_film=float(hc),
        composite_roughness=float(sigma),
        peclet=peclet,
        slide_to_roll_range=(float(sr[0]), float(sr[1])),
        slide_to_roll_max=float(np.max(np.abs(sr))),
        hertz_pressure=max(base["hertz_max"], base["hertz_pitch"]),
        hertz_pressure_pitch=base["hertz_pitch"],
        mesh_frequency=float(f_mesh),
        resonance_distance=float(best[0]),
        nearest_resonance=(int(best[1][0]), float(best[1][1])),
        natural_frequencies=base["modes"],
        speed_rpm=float(speed_rpm),
        torque=base["torque"],
        inlet_temperature=base["inlet_temperature"],
    )


def scenario_indicators(pair, lubricant, surfaces, op) -> ScenarioIndicators:
    """The dimensionless indicators of ``pair`` running at ``op`` (see :class:`ScenarioIndicators`).

    Args:
        pair: GearPair; lubricant: Lubricant (η0 and α at the inlet temperature); surfaces: Surfaces
            (σ, scaled); op: OperatingPoint (torque N m, speed rpm, inlet temperature K).

    Closed forms only, evaluated on the host at concrete inputs (one quasi-static mesh cycle for the
    mean mesh stiffness and the max Hertz pressure, one linear modal analysis).
    """
    base = _speed_free_part(pair, lubricant, surfaces, op.torque, op.inlet_temperature)
    return _at_speed(base, _f(op.speed_rpm))


# -------------------------------------------------------------------------------------------------
# The measured error table
# -------------------------------------------------------------------------------------------------
def load_error_table(path: str | Path | None = None) -> dict:
    """The measured error table: ``path`` (JSON), or the one shipped in ``jaxgear/data``.

    Raises ValueError if the file is missing or was measured with other indicator definitions.
    """
    if path is None:
        text = resources.files("jaxgear").joinpath("data/fidelity_errors.json").read_text()
        where = "jaxgear/data/fidelity_errors.json"
    else:
        try:
            text = Path(path).read_text()
        except FileNotFoundError:
            raise ValueError(f"error table = {str(path)!r} does not exist") from None
        where = str(path)
    table = json.loads(text)
    if table.get("indicator_version") != INDICATOR_VERSION:
        raise ValueError(
            f"error table {where} has indicator_version = {table.get('indicator_version')!r}; "
            f"valid: {INDICATOR_VERSION} (regenerate it with benchmarks/fidelity_trade.py)"
        )
    return table


@functools.cache
def _shipped_table() -> dict:
    return load_error_table()


def _physics_of(entry: Mapping) -> tuple:
    return tuple(entry[a] for a in AXIS_ORDER)


#: Friction rungs that solve no EHL film: thermal and transient do not act on them, so the table
#: measures them once (thermal = transient = False) and they stand for every value of those axes.
FORMULA_FRICTION = ("constant", "regression", "ehl_formula")


def _departs(axis: str, physics, reference) -> bool:
    """Whether ``physics`` departs from the reference on ``axis`` (thermal and transient are not
    axes of a formula friction rung: its error is measured whole, on the friction axis)."""
    i = tuple(AXIS_ORDER).index(axis)
    if axis in ("thermal", "transient") and physics[1] in FORMULA_FRICTION:
        return False
    return physics[i] != reference[i]


def _hardness(axis: str, indicators: Mapping) -> float:
    name, sign = AXIS_INDICATOR[axis]
    value = indicators[name]
    value = math.inf if value is None else float(value)  # λ of smooth surfaces
    return sign * value


class _Table:
    """The JSON table, indexed: rung results by (physics, level), the reference, the scenarios."""

    def __init__(self, table: Mapping):
        self.raw = table
        self.reference = table["reference"]
        ref_fid = self.reference["fidelity"]
        self.ref_physics = _physics_of(ref_fid)
        self.anchor = table["anchor_level"]
        self.levels = dict(table["levels"])
        self.scenarios = {
            name: s for name, s in table["scenarios"].items() if s["reference_converged"]
        }
        self.rungs = {}
        for r in table["rungs"]:
            if r["available"]:
                self.rungs[(_physics_of(r), r["level"])] = r
        self.reference_results = {n: s["reference_result"] for n, s in self.scenarios.items()}

    def results(self, physics, level) -> dict | None:
        rung = self.rungs.get((physics, level))
        return None if rung is None else rung["results"]

    def axis_errors(self, axis: str, value) -> dict[str, dict[str, float]] | None:
        """Per measured scenario, the error of changing ``axis`` to ``value`` (resolution: to the
        level ``value``) and nothing else; None when the table lacks the rung."""
        if axis == "resolution":
            test = self.results(self.ref_physics, value)
            base = self.reference_results
        else:
            physics = tuple(value if a == axis else v for a, v in zip(AXIS_ORDER, self.ref_physics))
            if axis == "friction" and value in FORMULA_FRICTION:
                physics = (physics[0], value, False, False)  # measured once (FORMULA_FRICTION)
            test = self.results(physics, self.anchor)
            base = self.results(self.ref_physics, self.anchor)
        if test is None or base is None:
            return None
        out = {}
        for name in self.scenarios:
            t, b = test.get(name), base.get(name)
            if t is None or b is None or b["status"] != 0:
                continue  # no information at this scenario
            if t["status"] != 0:
                out[name] = {q: math.inf for q in QUANTITIES}
            else:
                out[name] = {q: abs(t[q] - b[q]) / abs(b[q]) for q in QUANTITIES}
        return out

    def run_seconds(self, physics, level) -> float | None:
        if physics == self.ref_physics and level == self.reference.get("level"):
            return self.reference.get("summary_run_s")
        rung = self.rungs.get((physics, level))
        if rung is None or rung.get("summary") is None:
            return None
        return rung["summary"]["run_s"]


def _envelope(axis: str, errors: Mapping[str, Mapping], scenarios: Mapping, query: Mapping):
    """Conservative monotone estimate of one axis's error at the query (see the module docstring).

    Returns (error per quantity, name of the bounding scenario or None when unbounded).
    """
    if not errors:
        return {q: math.inf for q in QUANTITIES}, None
    h_query = _hardness(axis, query)
    hard = {n: _hardness(axis, scenarios[n]["indicators"]) for n in errors}
    harder = [n for n in errors if hard[n] >= h_query]
    if not harder:
        return {q: math.inf for q in QUANTITIES}, None
    bound = min(harder, key=lambda n: hard[n])
    easier = [n for n in errors if hard[n] <= hard[bound]]
    return {q: max(errors[n][q] for n in easier) for q in QUANTITIES}, bound


# -------------------------------------------------------------------------------------------------
# The choice
# -------------------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class FidelityChoice:
    """What :func:`choose_fidelity` chose, and why.

    Attributes:
        fidelity: the chosen ``Fidelity`` (pass it to ``jg.simulate``/``jg.sweep``).
        reasons: the choice in words: the scenario's indicators, each axis's measured error and the
            reference the errors are measured against.
        predicted_error: upper estimate of the relative error per quantity against the table's
            reference (``QUANTITIES``; inf where unbounded).
        time_per_point: measured run time per point of the chosen rung on the table's machine, s.
        reference_time_per_point: the same for the table's reference, s.
        reference: label of the table's reference model.
        indicators: the scenario's indicators (one per speed for a sweep).
    """

    fidelity: Fidelity
    reasons: str
    predicted_error: dict
    time_per_point: float | None
    reference_time_per_point: float | None
    reference: str
    indicators: tuple[ScenarioIndicators, ...]


def _rank_of(tab: _Table, physics, level) -> tuple:
    return (
        *(AXIS_ORDER[a].index(v) for a, v in zip(AXIS_ORDER, physics)),
        _level_rank(tab, level),
    )


def _candidates(tab: _Table):
    """(physics, level, cost) of every candidate the table has timed.

    The cost is the measured run time per point made monotone: a candidate costs at least as much as
    any measured candidate that is cheaper-or-equal on every axis and no finer. Millisecond timings
    on a shared machine are noisy (a fine level can time below the default one); physics and
    resolution only ever add work, so the noise must not reorder them.
    """
    keys = set(tab.rungs) | {(tab.ref_physics, tab.reference.get("level"))}
    timed = []
    for physics, level in keys:
        seconds = tab.run_seconds(physics, level)
        if seconds is not None and math.isfinite(seconds):
            timed.append((physics, level, seconds, _rank_of(tab, physics, level)))
    out = []
    for physics, level, _, rank in timed:
        cost = max(t for _, _, t, r in timed if all(a <= b for a, b in zip(r, rank)))
        out.append((physics, level, cost, rank))
    return out


def _predict(tab: _Table, physics, level, query: Mapping):
    """Predicted error per quantity of (physics, level) at the query, and the per-axis terms."""
    total = {q: 0.0 for q in QUANTITIES}
    terms = {}
    changes = [(a, v) for a, v in zip(AXIS_ORDER, physics) if _departs(a, physics, tab.ref_physics)]
    if level != tab.reference.get("level"):
        changes.append(("resolution", level))
    for axis, value in changes:
        errors = tab.axis_errors(axis, value)
        est, bound = _envelope(axis, errors or {}, tab.scenarios, query)
        terms[axis] = (value, est, bound)
        for q in QUANTITIES:
            total[q] += est[q]
    return total, terms


def _fidelity_of(tab: _Table, physics, level, base: Fidelity | None = None) -> Fidelity:
    """The Fidelity of (physics, level): the ladder's fields from the table, every other field
    (μb, shear law, asperity constants, fixed-point settings...) from ``base``."""
    base = Fidelity() if base is None else base
    if physics == tab.ref_physics and level == tab.reference.get("level"):
        return base.replace(**tab.reference["fidelity"])
    return base.replace(**dict(zip(AXIS_ORDER, physics)), **tab.levels[level])


#: Fields of a Fidelity the choice sets: the physics axes and the resolution.
LADDER_FIELDS = (*AXIS_ORDER, *RESOLUTION_FIELDS)


def _check_base(base) -> Fidelity | None:
    if base is not None and not isinstance(base, Fidelity):
        raise ValueError(f"base = {base!r} is not valid; valid: a jaxgear.Fidelity or None")
    return base


def _settings_note(base: Fidelity | None) -> str | None:
    """Words on the settings kept from ``base`` that differ from the defaults the table was measured
    at (benchmarks/fidelity_trade.py runs every rung with Fidelity()'s other fields)."""
    if base is None:
        return None
    kept, default = base.flat(), Fidelity().flat()
    changed = [
        f"{name} = {kept[name]!r} (table: {default[name]!r})"
        for name in kept
        if name not in LADDER_FIELDS and kept[name] != default[name]
    ]
    if not changed:
        return None
    return (
        "Kept from base: "
        + "; ".join(changed)
        + ". The table measured every rung at the defaults in brackets, so its errors are carried "
        "over to these settings unmeasured (they move the friction level of every EHL rung alike, "
        "not the ladder's order)."
    )


def _query(indicators: ScenarioIndicators | Mapping) -> dict:
    if isinstance(indicators, ScenarioIndicators):
        return indicators.as_dict()
    return dict(indicators)


def _check_request(tolerance, quantities):
    if isinstance(tolerance, bool) or not isinstance(tolerance, int | float):
        raise ValueError(f"tolerance = {tolerance!r} is not valid; valid range: (0, 1)")
    if not 0.0 < tolerance < 1.0:
        raise ValueError(f"tolerance = {tolerance!r} is out of range; valid range: (0, 1)")
    quantities = tuple(quantities)
    bad = [q for q in quantities if q not in QUANTITIES]
    if bad or not quantities:
        raise ValueError(
            f"quantities = {quantities!r} is not valid; valid: a non-empty subset of {QUANTITIES}"
        )
    return quantities


def choose_from_indicators(
    indicators: ScenarioIndicators | Mapping,
    tolerance: float = 0.05,
    *,
    quantities: Sequence[str] = ("power_loss", "efficiency"),
    table: Mapping | str | Path | None = None,
    base: Fidelity | None = None,
) -> FidelityChoice:
    """:func:`choose_fidelity` for given indicators (a ``ScenarioIndicators`` or a dict with at least
    the axis indicators of ``AXIS_INDICATOR``); the pure part of the choice, for tests and sweeps."""
    quantities = _check_request(tolerance, quantities)
    base = _check_base(base)
    raw = _shipped_table() if table is None else table
    raw = load_error_table(raw) if isinstance(raw, str | Path) else raw
    tab = _Table(raw)
    query = _query(indicators)
    best = None
    for physics, level, seconds, rank in _candidates(tab):
        total, terms = _predict(tab, physics, level, query)
        if all(total[q] <= tolerance for q in quantities):
            worst = max(total[q] for q in quantities)
            key = (seconds, worst, rank)
            if best is None or key < best[0]:
                best = (key, physics, level, tab.run_seconds(physics, level), total, terms)
    _, physics, level, seconds, total, terms = best  # the reference itself always qualifies
    fid = _fidelity_of(tab, physics, level, base)
    reasons = _reasons(
        tab, fid, physics, level, seconds, total, terms, query, tolerance, quantities
    )
    note = _settings_note(base)
    if note:
        reasons += "\n" + note
    ind = (indicators,) if isinstance(indicators, ScenarioIndicators) else ()
    return FidelityChoice(
        fidelity=fid,
        reasons=reasons,
        predicted_error=total,
        time_per_point=seconds,
        reference_time_per_point=tab.run_seconds(tab.ref_physics, tab.reference.get("level")),
        reference=tab.reference["label"],
        indicators=ind,
    )


def _scenario_summary(query: Mapping) -> str:
    try:
        return ScenarioIndicators.from_dict(query).summary()
    except (KeyError, TypeError):  # a partial dict of indicators (tests, hand-made queries)
        return ", ".join(f"{k} {v}" for k, v in query.items())


def _fmt_err(x: float) -> str:
    return "unbounded" if not math.isfinite(x) else f"{100 * x:.2g} %"


_NAMES = {"power_loss": "Φ̄", "efficiency": "Ψ", "dte_rms": "DTE RMS"}


def _describe(fid: Fidelity, level) -> str:
    return (
        f"{fid.dynamics} dynamics, {fid.friction} friction, "
        f"{'thermal' if fid.thermal else 'iso-thermal'}, "
        f"{'transient' if fid.transient else 'quasi-steady'} contacts; resolution "
        f"{level or 'of the reference'} ({fid.n_positions} positions per mesh cycle, "
        f"{fid.n_nodes} EHL nodes, {fid.steps_per_period} steps per mesh period)"
    )


def _axis_lines(tab: _Table, physics, level, query, tolerance, quantities) -> list[str]:
    lines = []
    chosen = dict(zip(AXIS_ORDER, physics))
    axes = [*AXIS_ORDER, "resolution"]
    for axis in axes:
        ref_value = tab.ref_physics[list(AXIS_ORDER).index(axis)] if axis in AXIS_ORDER else None
        values = AXIS_ORDER[axis] if axis in AXIS_ORDER else list(tab.levels)
        ind_name, sign = AXIS_INDICATOR[axis]
        parts = []
        for v in values:
            if axis in AXIS_ORDER and v == ref_value:
                continue
            errors = tab.axis_errors(axis, v)
            if errors is None:
                continue
            if axis == "resolution" and v == tab.reference.get("level"):
                continue
            est, bound = _envelope(axis, errors, tab.scenarios, query)
            worst = max(est[q] for q in quantities)
            if bound is None:
                where = f"not bounded: {ind_name} is beyond the measured scenarios"
            else:
                val = tab.scenarios[bound]["indicators"][ind_name]
                shown = "inf" if val is None else f"{val:.3g}"
                where = f"bound from {bound}, {ind_name} {shown}"
            est_txt = ", ".join(f"{_NAMES[q]} {_fmt_err(est[q])}" for q in quantities)
            mark = (
                " (chosen)"
                if (chosen.get(axis) == v or (axis == "resolution" and v == level))
                else ""
            )
            verdict = "within" if worst <= tolerance else "over"
            parts.append(f"{v}{mark}: {est_txt} ({where}; {verdict} the tolerance alone)")
        ref_txt = (
            f"reference rung {ref_value!r}"
            if axis in AXIS_ORDER
            else f"reference resolution {tab.reference.get('level') or 'of Fidelity.paper()'}"
        )
        if axis in AXIS_ORDER:
            pick = chosen[axis]
            head = f"- {axis} → {pick!r}" + (" (the reference's)" if pick == ref_value else "")
        else:
            head = f"- resolution → {level or 'the reference'}"
        if parts:
            lines.append(f"{head}; measured alternatives: " + "; ".join(parts) + ".")
        else:
            lines.append(f"{head}; the table has no measured alternative to the {ref_txt}.")
    return lines


def _reasons(tab, fid, physics, level, seconds, total, terms, query, tolerance, quantities) -> str:
    t_ref = tab.run_seconds(tab.ref_physics, tab.reference.get("level"))
    speedup = (
        f" ({t_ref / seconds:.3g}× cheaper)"
        if t_ref and seconds and t_ref > 1.0001 * seconds
        else ""
    )
    pred = ", ".join(f"{_NAMES[q]} {_fmt_err(total[q])}" for q in QUANTITIES)
    lines = [
        f"Fidelity.auto chose {_describe(fid, level)}.",
        f"Predicted error against the reference: {pred} (tolerance {100 * tolerance:g} % on "
        f"{', '.join(_NAMES[q] for q in quantities)}); measured {seconds:.3g} s per point against "
        f"{t_ref:.3g} s for the reference{speedup}.",
    ]
    lines.append(f"Scenario: {_scenario_summary(query)}.")
    lines.append("Per axis (each alternative's own error at this scenario, from the table):")
    lines += _axis_lines(tab, physics, level, query, tolerance, quantities)
    raw = tab.raw
    ref = tab.reference
    lines.append(
        f"Reference of the table: {ref['label']} (measured {raw.get('generated', '?')}, "
        f"{raw.get('mode', '?')} mode, on {raw.get('machine', '?')})."
    )
    if not ref.get("paper"):
        lam = query.get("film_parameter")
        lam = math.inf if lam is None else lam
        caveat = (
            "Fidelity.paper() was not available when the table was measured, so these errors say "
            "how far the choice is from the best model that ran, not from the paper's thermal mixed "
            "model."
        )
        if ref["fidelity"]["friction"] != "ehl_mixed" and lam < 3.0:
            caveat += (
                f" At λ = {lam:.2f} (< 3) asperity contact, which that reference lacks, carries "
                "part of the load."
            )
        lines.append(caveat)
    if fid.dynamics == "quasi_static" and "dte_rms" not in quantities:
        lines.append(
            "DTE RMS was not asked for: a quasi-static result's dte_rms is the static transmission "
            "error, not the dynamic one (add 'dte_rms' to quantities to bound it)."
        )
    return "\n".join(lines)


def _level_rank(tab: _Table, level) -> int:
    order = list(tab.levels)
    return len(order) if level is None or level not in order else order.index(level)


def choose_fidelity(
    pair,
    lubricant,
    surfaces,
    op,
    tolerance: float = 0.05,
    *,
    quantities: Sequence[str] = ("power_loss", "efficiency"),
    table: Mapping | str | Path | None = None,
    speeds_rpm: Sequence[float] | None = None,
    base: Fidelity | None = None,
) -> FidelityChoice:
    """The cheapest fidelity whose measured error stays under ``tolerance``, and why.

    Args:
        pair, lubricant, surfaces, op: the scenario (GearPair, Lubricant, Surfaces, OperatingPoint).
        tolerance: largest acceptable relative error of each quantity in ``quantities`` against the
            error table's reference, in (0, 1) (0.05 = 5 %).
        quantities: which of "power_loss" (Φ̄), "efficiency" (Ψ, relative) and "dte_rms" must meet
            the tolerance. Ψ's relative error is Φ̄'s times (1 − Ψ)/Ψ ≈ 0.002, so it never binds;
            add "dte_rms" when the dynamic transmission error matters (it rules out quasi-static).
        table: the measured error table (dict or JSON path); default the one shipped with jaxgear.
        speeds_rpm: for a sweep, the speeds (rpm) that ``op``'s speed stands in for: the choice is
            made at each speed and the most demanding rung of each axis is kept, so one Fidelity
            (one compiled program) serves the whole sweep.
        base: a Fidelity whose fields other than the ladder's (``LADDER_FIELDS``: the four physics
            axes and the resolution) the choice keeps, e.g. ``Fidelity(boundary_friction=0.08,
            shear="eyring_exact")``; default ``Fidelity()``'s. The reasons name the kept settings
            that differ from the defaults the table was measured at.

    Returns:
        FidelityChoice (``.fidelity``, ``.reasons``, ``.predicted_error``, ``.time_per_point``, ...).
    """
    quantities = _check_request(tolerance, quantities)
    base = _check_base(base)
    raw = _shipped_table() if table is None else table
    raw = load_error_table(raw) if isinstance(raw, str | Path) else raw
    part = _speed_free_part(pair, lubricant, surfaces, op.torque, op.inlet_temperature)
    if speeds_rpm is None:
        ind = _at_speed(part, _f(op.speed_rpm))
        return choose_from_indicators(ind, tolerance, quantities=quantities, table=raw, base=base)
    speeds = [float(v) for v in np.atleast_1d(np.asarray(speeds_rpm, dtype=float))]
    if not speeds or not all(math.isfinite(v) and v > 0 for v in speeds):
        raise ValueError(f"speeds_rpm = {speeds_rpm!r} is not valid; valid: positive rpm values")
    inds = [_at_speed(part, v) for v in speeds]
    choices = [
        choose_from_indicators(i, tolerance, quantities=quantities, table=raw, base=base)
        for i in inds
    ]
    tab = _Table(raw)
    # The most demanding rung of each axis over the speeds, and the finest resolution.
    physics = tuple(
        max((_physics_of(_fields(c.fidelity))[k] for c in choices), key=AXIS_ORDER[a].index)
        for k, a in enumerate(AXIS_ORDER)
    )
    levels = [_level_of(tab, c.fidelity) for c in choices]
    level = max(levels, key=lambda lv: _level_rank(tab, lv))
    fid = _fidelity_of(tab, physics, level, base)
    totals = [_predict(tab, physics, level, _query(i))[0] for i in inds]
    worst = {q: max(t[q] for t in totals) for q in QUANTITIES}
    seconds = tab.run_seconds(physics, level)
    k_worst = max(range(len(inds)), key=lambda i: max(totals[i][q] for q in quantities))
    counts = []
    for k, a in enumerate(AXIS_ORDER):
        need = sum(1 for c in choices if _physics_of(_fields(c.fidelity))[k] == physics[k])
        counts.append(f"{a} {physics[k]!r} (the choice at {need} of {len(speeds)} speeds)")
    header = [
        f"Sweep of {len(speeds)} speeds ({min(speeds):g}-{max(speeds):g} rpm): one fidelity for all, "
        f"the most demanding choice per axis — {'; '.join(counts)}; resolution {level or 'of the reference'}.",
        "Predicted error over the sweep: "
        + ", ".join(f"{_NAMES[q]} {_fmt_err(worst[q])}" for q in QUANTITIES)
        + (f"; measured {seconds:.3g} s per point." if seconds else "."),
        f"The most demanding speed, {speeds[k_worst]:g} rpm:",
    ]
    return FidelityChoice(
        fidelity=fid,
        reasons="\n".join(header) + "\n" + choices[k_worst].reasons,
        predicted_error=worst,
        time_per_point=seconds,
        reference_time_per_point=choices[0].reference_time_per_point,
        reference=tab.reference["label"],
        indicators=tuple(inds),
    )


def _fields(fid: Fidelity) -> dict:
    return {a: getattr(fid, a) for a in LADDER_FIELDS}


def _level_of(tab: _Table, fid: Fidelity):
    res = {f: getattr(fid, f) for f in RESOLUTION_FIELDS}
    for name, lv in tab.levels.items():
        if all(lv[f] == res[f] for f in RESOLUTION_FIELDS):
            return name
    return None  # the reference's own resolution


def auto_fidelity(pair, lubricant, surfaces, op, tolerance: float = 0.05, **kwargs) -> Fidelity:
    """``choose_fidelity(...).fidelity``: what ``Fidelity.auto`` returns."""
    return choose_fidelity(pair, lubricant, surfaces, op, tolerance, **kwargs).fidelity
