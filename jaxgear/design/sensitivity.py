"""The sensitivity report: the derivative of a point's design quantities with respect to every
physical input and model constant, from one compiled reverse-mode program.

``sensitivity(pair, lubricant, surfaces, op)`` differentiates the named outputs of one simulated
operating point (``design.metrics``: efficiency, power loss and its parts, DTE RMS, and the peaks of
the Hertz pressure and Blok flash temperature fields) with respect to

- every traced float field of the ``GearPair``: module, pressure angle, face width, profile shifts,
  basic rack coefficients, backlash, mesh damping ratio, each gear's material, the bearings, the
  tip relief amount and start, and the derived quantities the pair overrides (``pair.overrides``:
  e.g. the calibrated pair's ``pair.blank_mass[1]``; a derived quantity that is not overridden is a
  function of the other fields and has no derivative of its own);
- every float field of the ``Lubricant``;
- the ``Surfaces``' roughness scale, sample spacing and offsets (not the sampled heights
  ``profile1``/``profile2``: they are data, whose amplitude is the scale);
- the ``OperatingPoint`` (torque, speed, inlet temperature);
- the fidelity's contact constants (``fidelity.contact.constants``: ``fidelity.constant_mu``,
  ``fidelity.boundary_friction``, ...; each acts only on the rungs that use it, and is zero
  elsewhere).

The inputs are found generically, by flattening the float leaves of the inputs with their paths, so
a new field is listed without code here; its unit comes from ``UNITS`` (a test fails for a leaf
without one). Names are dotted paths (``pair.tip_relief.amount[1]``, ``pair.materials[2].density``,
``lubricant.eyring_stress``, ``op.torque``, ``fidelity.boundary_friction``), with per-gear values
split into gear 1 (``[1]``) and gear 2 (``[2]``). Every unit is SI except ``op.speed_rpm``, the
field as the OperatingPoint holds it, in rpm.

Cost: one program is compiled per fidelity and tuple of outputs, and it runs one forward solve and
one reverse (vector-Jacobian) pass per output, so the derivatives with respect to all inputs cost
about K + 1 forward solves for K outputs; a new input value reuses the program. As ``simulate``,
it holds the first pass only; the second pass (the attractor where no stable periodic orbit exists,
the back flanks' loss where the orbit strikes them) is compiled only for a point that needs it.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._inputs import canonical, validate
from .._validation import check_non_negative, is_concrete
from ..fidelity import Fidelity
from ..gear.geometry import gear_geometry
from ..results import Status, message
from ..tribodynamics import (
    STATUS_PENDING,
    check_inputs,
    first_pass,
    needs_second_pass,
    simulate_with_state,
)
from ..tribodynamics.passes import _finish_jit
from . import metrics

#: The outputs a report can differentiate → unit: every scalar of ``metrics.SCALARS`` and the peak
#: of every field of ``metrics.FIELDS``.
OUTPUTS = {name: unit for name, (unit, _) in metrics.QUANTITIES.items()}
DEFAULT_OUTPUTS = ("efficiency", "power_loss", "dte_rms")

#: Unit of every input, by its name with the gear indices removed ("-": dimensionless).
UNITS = {
    "pair.module": "m",
    "pair.pressure_angle": "rad",
    "pair.face_width": "m",
    "pair.profile_shift": "-",
    "pair.addendum_coefficient": "-",
    "pair.dedendum_coefficient": "-",
    "pair.backlash": "m",
    "pair.materials.youngs_modulus": "Pa",
    "pair.materials.poisson_ratio": "-",
    "pair.materials.density": "kg/m^3",
    "pair.materials.thermal_conductivity": "W/(m K)",
    "pair.materials.specific_heat": "J/(kg K)",
    "pair.bearings.ky": "N/m",
    "pair.bearings.cy": "N s/m",
    "pair.bearings.kx": "N/m",
    "pair.bearings.cx": "N s/m",
    "pair.bearings.ct": "N m s/rad",
    "pair.tip_relief.amount": "m",
    "pair.tip_relief.start_roll_angle": "rad",
    "pair.mesh_damping_ratio": "-",
    "pair.tip_radius": "m",
    "pair.root_radius": "m",
    "pair.centre_distance": "m",
    "pair.blank_mass": "kg",
    "pair.blank_inertia": "kg m^2",
    "pair.bore_radius": "m",
    "lubricant.kinematic_viscosity_40": "m^2/s",
    "lubricant.kinematic_viscosity_100": "m^2/s",
    "lubricant.density": "kg/m^3",
    "lubricant.roelands_z": "-",
    "lubricant.roelands_s0": "-",
    "lubricant.roelands_reference_temperature": "K",
    "lubricant.thermal_expansion": "1/K",
    "lubricant.density_temperature": "K",
    "lubricant.eyring_stress": "Pa",
    "lubricant.thermal_conductivity": "W/(m K)",
    "lubricant.specific_heat": "J/(kg K)",
    "surfaces.dx": "m",
    "surfaces.scale": "-",
    "surfaces.offset": "m",
    "op.torque": "N m",
    "op.speed_rpm": "rpm",
    "op.inlet_temperature": "K",
    "fidelity.constant_mu": "-",
    "fidelity.boundary_friction": "-",
    "fidelity.asperity_density_product": "-",
    "fidelity.asperity_slope_ratio": "-",
    "fidelity.limiting_shear_coefficient": "-",
}
#: Marks an input whose unit ``UNITS`` lacks.
UNKNOWN_UNIT = "?"

_GROUPS = ("pair", "lubricant", "surfaces", "op", "fidelity")
_OVERRIDE = "_override"
# sampled data, not parameters (their amplitude is ``surfaces.scale``)
_NOT_INPUTS = ("surfaces.profile1", "surfaces.profile2")
_NO_DERIVATIVE = "no derivative exists at this point"


def derivative_unit(output_unit: str, input_unit: str) -> str:
    """The unit of ∂y/∂x from the units of y and x ("-": dimensionless), e.g. "W/m", "1/K";
    "-" where they are the same unit."""

    def wrapped(unit):
        return unit if all(c.isalnum() or c == "^" for c in unit) else f"({unit})"

    if input_unit == "-":
        return output_unit
    if input_unit == output_unit:
        return "-"
    numerator = "1" if output_unit == "-" else output_unit
    return f"{numerator}/{wrapped(input_unit)}"


class SensitivityReport:
    """The values of a point's outputs and their derivatives with respect to its inputs.

    Attributes:
        output_names: the outputs, in the order asked for.
        output_values: their values at the point (SI: ``OUTPUTS`` gives each unit) [K].
        input_names: the inputs (dotted names, see the module docstring) [N].
        input_values: their values at the point, SI (``op.speed_rpm`` in rpm) [N].
        input_units: their units [N].
        derivatives: ∂y/∂x, in the output's unit per the input's unit [K, N]; all NaN unless
            ``status`` is 0.
        status: the simulation's status (``jaxgear.results.Status``; 0 ok). At any other status no
            derivative is reported (at status 6, a mean over an attractor, none exists; where a
            solve did not converge, the tangents of its solution are not the model's).
        message: the status in words.

    ``elasticity`` is d ln y/d ln x = (x/y) ∂y/∂x, dimensionless: the relative change of the output
    per relative change of the input. It is NaN where x = 0 (an input at zero, such as a zero
    profile shift, offset or mesh damping ratio, has no relative change: read its derivative) or
    y = 0.
    """

    def __init__(
        self,
        output_names: Sequence[str],
        output_values,
        input_names: Sequence[str],
        input_values,
        input_units: Sequence[str],
        derivatives,
        status: int = 0,
        message_text: str | None = None,
    ):
        self.output_names = tuple(output_names)
        self.output_values = np.asarray(output_values, dtype=float).reshape(len(output_names))
        self.input_names = tuple(input_names)
        self.input_values = np.asarray(input_values, dtype=float).reshape(len(input_names))
        self.input_units = tuple(input_units)
        derivatives = np.asarray(derivatives, dtype=float).reshape(
            len(self.output_names), len(self.input_names)
        )
        self.status = int(status)
        if self.status != 0:
            derivatives = np.full_like(derivatives, np.nan)
        self.derivatives = derivatives
        self.message = message_text if message_text is not None else _status_message(self.status)

    @property
    def converged(self) -> bool:
        """The point converged (status 0): the derivatives exist."""
        return self.status == 0

    @property
    def outputs(self) -> dict[str, tuple[float, str]]:
        """output name → (value, unit)."""
        return {
            name: (float(v), OUTPUTS[name])
            for name, v in zip(self.output_names, self.output_values)
        }

    @property
    def inputs(self) -> dict[str, tuple[float, str]]:
        """input name → (value, unit), in the report's order."""
        return {
            name: (float(v), unit)
            for name, v, unit in zip(self.input_names, self.input_values, self.input_units)
        }

    @property
    def elasticities(self) -> np.ndarray:
        """d ln y/d ln x = (x/y) ∂y/∂x [K, N]; NaN where x = 0 or y = 0."""
        x = self.input_values[None, :]
        y = self.output_values[:, None]
        ok = (x != 0.0) & (y != 0.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(ok, x * self.derivatives / np.where(ok, y, 1.0), np.nan)

    def _output_index(self, output: str) -> int:
        if output not in self.output_names:
            raise ValueError(
                f"output {output!r} is not in this report; its outputs: "
                f"{', '.join(self.output_names)}"
            )
        return self.output_names.index(output)

    def _indices(self, output: str, input: str) -> tuple[int, int]:
        i = self._output_index(output)
        name = resolve_input(input, self.input_names, "in this report")
        return i, self.input_names.index(name)

    def derivative(self, output: str, input: str) -> float:
        """∂output/∂input in ``derivative_unit(output unit, input unit)`` (NaN unless converged);
        ``input`` a full name or one without its group where unambiguous ("torque")."""
        i, j = self._indices(output, input)
        return float(self.derivatives[i, j])

    def elasticity(self, output: str, input: str) -> float:
        """d ln output/d ln input, dimensionless (NaN where the input or the output is 0)."""
        i, j = self._indices(output, input)
        return float(self.elasticities[i, j])

    @property
    def table(self) -> list[dict]:
        """One row per (output, input): output, output_value, output_unit, input, input_value,
        input_unit, derivative, derivative_unit, elasticity."""
        rows = []
        elasticities = self.elasticities
        for i, out in enumerate(self.output_names):
            for j, name in enumerate(self.input_names):
                rows.append(
                    {
                        "output": out,
                        "output_value": float(self.output_values[i]),
                        "output_unit": OUTPUTS[out],
                        "input": name,
                        "input_value": float(self.input_values[j]),
                        "input_unit": self.input_units[j],
                        "derivative": float(self.derivatives[i, j]),
                        "derivative_unit": derivative_unit(OUTPUTS[out], self.input_units[j]),
                        "elasticity": float(elasticities[i, j]),
                    }
                )
        return rows

    def ranked(self, output: str) -> list[dict]:
        """The rows of ``output`` by decreasing |elasticity|; rows whose elasticity is NaN (input
        at zero) last, in the report's order."""
        self._output_index(output)
        rows = [r for r in self.table if r["output"] == output]
        finite = [r for r in rows if math.isfinite(r["elasticity"])]
        rest = [r for r in rows if not math.isfinite(r["elasticity"])]
        return sorted(finite, key=lambda r: -abs(r["elasticity"])) + rest

    def to_dict(self) -> dict:
        """A JSON-ready dict (NaN as None): status, message, outputs, inputs, and per output and
        input the derivative, its unit and the elasticity."""
        return {
            "status": self.status,
            "message": self.message,
            "outputs": {k: {"value": _json(v), "unit": u} for k, (v, u) in self.outputs.items()},
            "inputs": {k: {"value": _json(v), "unit": u} for k, (v, u) in self.inputs.items()},
            "derivatives": {
                out: {
                    r["input"]: {
                        "derivative": _json(r["derivative"]),
                        "unit": r["derivative_unit"],
                        "elasticity": _json(r["elasticity"]),
                    }
                    for r in self.table
                    if r["output"] == out
                }
                for out in self.output_names
            },
        }

    def to_json(self, path: str | Path) -> Path:
        """Write ``to_dict()`` as JSON to ``path``; returns the path."""
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=1))
        return path

    def to_csv(self, path: str | Path) -> Path:
        """Write ``table`` as CSV (a header row, then one row per output and input, with the
        status in every row); returns the path."""
        path = Path(path)
        rows = self.table
        fields = [*(rows[0] if rows else {"output": None}), "status"]
        with path.open("w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=fields)
            writer.writeheader()
            for row in rows:
                writer.writerow({**row, "status": self.status})
        return path

    def __repr__(self) -> str:
        return (
            f"SensitivityReport(outputs={list(self.output_names)}, {len(self.input_names)} "
            f"inputs, status={self.status} ({self.message}))"
        )


def _json(value: float):
    return value if math.isfinite(value) else None


def _status_message(status: int) -> str:
    if status == 0:
        return message(Status.OK)
    try:
        words = message(status)
    except ValueError:
        words = f"status {status}"
    return f"{words}: {_NO_DERIVATIVE}"


# -- the inputs ------------------------------------------------------------------------------------
def _leaf_names(path, overrides) -> tuple[str, str] | None:
    """(name, unit key) of the float leaf at ``path`` in (pair, lubricant, surfaces, op,
    fidelity), or None where the leaf is not an input (an unused override, a roughness profile)."""
    group = _GROUPS[path[0].idx]
    parts: list[str] = []
    for key in path[1:]:
        if isinstance(key, jax.tree_util.GetAttrKey):
            parts.append(key.name)
        elif isinstance(key, jax.tree_util.SequenceKey) and parts:
            parts[-1] = f"{parts[-1]}[{key.idx + 1}]"  # a gear's material: 1-based as elsewhere
        else:
            parts.append(str(key))
    if group == "fidelity" and parts[:2] == ["contact", "constants"]:
        parts = parts[2:]
    if group == "pair" and len(parts) == 1 and parts[0].endswith(_OVERRIDE):
        derived = parts[0][: -len(_OVERRIDE)]
        if derived not in overrides:
            return None
        parts = [derived]
    name = ".".join([group, *parts])
    if name in _NOT_INPUTS:
        return None
    unit_key = ".".join([group, *(p.split("[")[0] for p in parts)])
    return name, unit_key


class _Input(NamedTuple):
    name: str
    unit: str
    leaf: int  # index among the differentiated leaves
    element: int | None  # the gear (0, 1) of a per-gear leaf, None for a scalar


def _enumerate(params, overrides) -> list[_Input]:
    """Every input in ``params`` (the differentiated leaves), in flattening order."""
    entries = []
    for leaf_index, (path, leaf) in enumerate(jax.tree_util.tree_flatten_with_path(params)[0]):
        named = _leaf_names(path, overrides)
        if named is None:
            continue
        name, unit_key = named
        unit = UNITS.get(unit_key, UNKNOWN_UNIT)
        shape = np.shape(leaf)
        if shape == ():
            entries.append(_Input(name, unit, leaf_index, None))
        elif shape == (2,):  # per gear
            for gear in range(2):
                entries.append(_Input(f"{name}[{gear + 1}]", unit, leaf_index, gear))
        else:
            raise ValueError(
                f"{name} has shape {shape}; the sensitivity report knows scalars and per-gear "
                "pairs: add it to design.sensitivity's _NOT_INPUTS or split it"
            )
    return entries


def _differentiated(inputs):
    """(params, rest): the float leaves that are inputs (an unused override is kept, its
    derivative is zero and not reported), and everything else (the roughness profiles too)."""
    spec = jax.tree_util.tree_map(eqx.is_inexact_array, inputs)
    spec = eqx.tree_at(lambda t: (t[2].profile1, t[2].profile2), spec, replace=(False, False))
    return eqx.partition(inputs, spec)


def input_names(pair, lubricant, surfaces, op, fidelity: Fidelity | None = None) -> list[str]:
    """The names of every input a report of these inputs differentiates, in its order."""
    fidelity = Fidelity.fast() if fidelity is None else fidelity
    params, _ = _differentiated(canonical((pair, lubricant, surfaces, op, fidelity)))
    return [e.name for e in _enumerate(params, pair.overrides)]


# -- the program -----------------------------------------------------------------------------------
def _outputs_of(result, pair, outputs):
    return jnp.stack([metrics.peak(n, metrics.quantity(n, result, pair)) for n in outputs])


def _values_and_derivatives(params, rest, outputs: tuple[str, ...], second_pass: bool = False):
    """(outputs [K], status, ∂outputs/∂params: params' tree with a leading axis K, and the first
    pass's (Pending, whether the point needs the second pass)): one forward solve, then one
    vector-Jacobian product per unit cotangent, in a loop of the same program.

    ``second_pass`` False: the first pass only, as ``simulate`` compiles it (where the point needs
    the second pass, its derivatives are NaN and the caller goes on); True: both passes
    (``simulate_with_state``), for a periodic orbit that strikes the back flanks."""

    def forward(p):
        pair, lubricant, surfaces, op, fidelity = eqx.combine(p, rest)
        if second_pass:
            result, _ = simulate_with_state(pair, lubricant, surfaces, op, fidelity)
            pending, later = None, jnp.asarray(False)
        else:
            result, _, pending = first_pass(pair, lubricant, surfaces, op, fidelity)
            later = needs_second_pass(pending, fidelity)
        return _outputs_of(result, pair, outputs), (result.status, pending, later)

    values, pullback, (status, pending, later) = jax.vjp(forward, params, has_aux=True)
    # lax.map, not vmap: each reverse pass runs as it would alone (a batched while loop would run
    # every member until the last stops, a batched cond both branches)
    (derivatives,) = jax.lax.map(pullback, jnp.eye(len(outputs), dtype=values.dtype))
    return values, status, derivatives, (pending, later)


_program = eqx.filter_jit(_values_and_derivatives)


def _check_outputs(outputs) -> tuple[str, ...]:
    if isinstance(outputs, str):
        outputs = (outputs,)
    outputs = tuple(outputs)
    if not outputs:
        raise ValueError(f"outputs is empty; valid names: {', '.join(OUTPUTS)}")
    for name in outputs:
        if name not in OUTPUTS:
            raise ValueError(f"unknown output {name!r}; valid names: {', '.join(OUTPUTS)}")
    if len(set(outputs)) != len(outputs):
        raise ValueError(f"outputs = {outputs!r} names an output twice")
    return outputs


def resolve_input(name: str, names: Sequence[str], where: str = "") -> str:
    """The full name of the input ``name`` among ``names``: itself, or the one name it ends with
    after its group (``"torque"`` → ``"op.torque"``, ``"tip_relief.amount[1]"`` →
    ``"pair.tip_relief.amount[1]"``, ``"boundary_friction"`` → ``"fidelity.boundary_friction"``).

    Raises:
        ValueError: an unknown or ambiguous name, naming it and the valid names.
    """
    if name in names:
        return name
    matches = [n for n in names if n.split(".", 1)[-1] == name]
    if len(matches) == 1:
        return matches[0]
    place = f" {where}" if where else ""
    if matches:
        raise ValueError(f"input {name!r} is ambiguous{place}; it may be: {', '.join(matches)}")
    raise ValueError(f"unknown input {name!r}{place}; valid names: {', '.join(names)}")


def _selected(entries: list[_Input], inputs) -> list[_Input]:
    if inputs is None:
        return entries
    if isinstance(inputs, str):
        inputs = (inputs,)
    by_name = {e.name: e for e in entries}
    chosen = [resolve_input(name, list(by_name)) for name in inputs]
    return [by_name[name] for name in dict.fromkeys(chosen)]


def sensitivity(
    pair,
    lubricant,
    surfaces,
    op,
    *,
    fidelity: Fidelity | None = None,
    outputs: Sequence[str] = DEFAULT_OUTPUTS,
    inputs: Sequence[str] | None = None,
) -> SensitivityReport:
    """The derivatives of a point's outputs with respect to its inputs and model constants.

    Args:
        pair: GearPair.
        lubricant: Lubricant.
        surfaces: Surfaces.
        op: OperatingPoint (torque N m, speed rpm, inlet temperature K).
        fidelity: Fidelity (default ``Fidelity.fast()``); its contact constants are inputs.
        outputs: names from ``OUTPUTS`` (default efficiency, power_loss, dte_rms): the scalars of
            ``metrics.SCALARS``, and ``hertz_pressure``/``flash_temperature`` as the peak of their
            field over the mesh cycle (a peak's derivative is that of the entry where it is
            reached).
        inputs: the names to report (default every input; ``input_names`` lists them; a name
            may leave out its group where that is unambiguous: "torque" for "op.torque"). The
            program is the same whichever are chosen: reverse mode gives all at once.

    Returns:
        SensitivityReport. Where the simulation's status is not 0 the report carries it, its
        message says that no derivative exists, and every derivative is NaN.

    Raises:
        ValueError: an unknown output or input name (naming it and the valid ones), or an input
            that ``simulate`` rejects.

    One program per fidelity and outputs tuple (``eqx.filter_jit``): a forward solve and one
    reverse pass per output; other input values reuse it. The derivatives are those of
    ``jaxgear.simulate``'s implicit rules (the converged fixed point and periodic orbit, never the
    iterations), in float64.
    """
    outputs = _check_outputs(outputs)
    fidelity = Fidelity.fast() if fidelity is None else fidelity
    # simulate's boundary: types, float64 arrays, every Module's checks, the geometry
    check_inputs(pair, lubricant, surfaces, op, fidelity)
    pair, lubricant, surfaces, op, fidelity = canonical((pair, lubricant, surfaces, op, fidelity))
    validate((pair, lubricant, surfaces, op, fidelity))
    if not is_concrete((pair, lubricant, surfaces, op, fidelity)):
        raise ValueError("sensitivity needs concrete inputs (it compiles its own program)")
    check_non_negative("surfaces.composite_rq", surfaces.composite_rq, "m")
    gear_geometry(pair)

    params, rest = _differentiated((pair, lubricant, surfaces, op, fidelity))
    chosen = _selected(_enumerate(params, pair.overrides), inputs)
    values, status, grads, (pending, later) = _program(params, rest, outputs)
    if bool(later):
        # as simulate: what few points need is compiled only where it is reached
        if int(status) == STATUS_PENDING:
            # a periodic orbit striking the back flanks: their loss and its derivatives
            values, status, grads, _ = _program(params, rest, outputs, True)
        else:
            # no stable periodic orbit: the values are means over the attractor; no derivative
            result = _finish_jit(pair, lubricant, surfaces, op, fidelity, pending)
            values, status = _outputs_of(result, pair, outputs), result.status
    leaves = jax.tree_util.tree_leaves(params)
    grad_leaves = [np.asarray(g) for g in jax.tree_util.tree_leaves(grads)]
    x, d = [], []
    for e in chosen:
        value = np.asarray(leaves[e.leaf])
        grad = grad_leaves[e.leaf]  # [K, ...]
        if e.element is None:
            x.append(float(value))
            d.append(grad.reshape(len(outputs)))
        else:
            x.append(float(value[e.element]))
            d.append(grad[:, e.element])
    derivatives = np.stack(d, axis=1) if d else np.zeros((len(outputs), 0))
    return SensitivityReport(
        outputs,
        np.asarray(values),
        [e.name for e in chosen],
        x,
        [e.unit for e in chosen],
        derivatives,
        status=int(status),
    )


def plot_tornado(report: SensitivityReport, output: str, path: str | Path, top: int = 15) -> Path:
    """A tornado chart of ``output``: the ``top`` inputs by |elasticity|, as signed bars.

    Inputs at zero value (or an output at zero) have no elasticity; they are left out of the chart
    and counted in a note under it (their derivatives are in the report's table). Matplotlib, Agg
    backend; writes ``path`` (PNG by its suffix) and returns it.

    Raises:
        ValueError: an output the report lacks, or a report without derivatives (status not 0).
    """
    from ..plotting import _pyplot

    report._output_index(output)
    if not report.converged:
        raise ValueError(f"no tornado chart of {output!r}: {report.message}")
    rows = report.ranked(output)
    shown = [r for r in rows if math.isfinite(r["elasticity"])][: int(top)]
    left_out = sum(1 for r in rows if not math.isfinite(r["elasticity"]))
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 0.32 * max(len(shown), 4) + 1.6))
    labels = [r["input"] for r in reversed(shown)]
    values = [r["elasticity"] for r in reversed(shown)]
    colours = ["tab:blue" if v >= 0 else "tab:red" for v in values]
    ax.barh(range(len(shown)), values, color=colours)
    ax.set_yticks(range(len(shown)), labels, fontsize=8)
    ax.axvline(0.0, color="k", lw=0.8)
    value, unit = report.outputs[output]
    ax.set_xlabel(f"elasticity d ln({output}) / d ln(input)")
    ax.set_title(f"{output} = {value:.6g} {unit}: top {len(shown)} inputs", fontsize=10)
    if left_out:
        fig.text(
            0.01,
            0.01,
            f"{left_out} inputs at zero value left out (no elasticity; see the table)",
            fontsize=7,
        )
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
