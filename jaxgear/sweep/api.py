"""Sweeps of the tribo-dynamic model over speeds (and any other traced input).

``mode="parallel"`` vmaps independent points (chunked, sharded over devices, checkpointed);
``mode="continuation"`` marches through the points in order with ``lax.scan``, starting each point from
its neighbour's converged state (the dynamic orbit and the mesh interface), as the paper's stepwise
speed increase does: near jump regions of the dynamics it follows one branch and can show hysteresis.
"""

from __future__ import annotations

import csv
import os
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._inputs import canonical, validate
from .._validation import check_non_negative, check_positive, check_range
from ..fidelity import Fidelity
from ..gear.pair import MAX_RELIEF_PER_MODULE
from ..operating import OperatingPoint
from ..results import Status, messages
from ..tribodynamics import (
    STATUS_ATTRACTOR,
    STATUS_PENDING,
    check_inputs,
    cold_start,
    finish,
    first_pass,
    needs_second_pass,
)
from .engine import STATUS_NAMES as POINT_STATUS_NAMES
from .engine import run_continuation, run_points

#: Inputs a sweep may vary, besides the speed.
SWEEPABLE = (
    "speed_rpm",
    "torque",
    "inlet_temperature",
    "roughness_scale",
    "tip_relief_amount",
    "backlash",
    "mesh_damping_ratio",
)

_SCALARS = (
    "power_loss",
    "power_loss_sliding",
    "power_loss_rolling",
    "efficiency",
    "dte_rms",
    "fixed_point_residual",
    "power_loss_back",
    "back_contact_share",
    "mesh_damping_power",
)
# Per-position outputs kept for every point (paper Figs. 5-7, 12 need them at chosen speeds).
_PER_POSITION = ("power_loss_position", "tooth_force", "surface_velocity", "hertz_pressure")


class SweepResult(eqx.Module):
    """Results of a sweep: one row per point.

    Attributes:
        inputs: dict of the varied inputs (SI; speed in rpm) [N].
        power_loss, power_loss_sliding, power_loss_rolling (W), efficiency, dte_rms (m),
        fixed_point_residual: [N] (NaN where a point failed).
        power_loss_back: [N] the back flanks' part of Φ̄, W; back_contact_share: [N] share of the
            mesh cycle in back-flank contact (``SimulationResult``; NaN where a point failed).
        mesh_damping_power: [N] the mesh damper's mean power, W (``SimulationResult``; not in Φ̄).
        failed_contacts: [N] loaded contacts per point whose EHL solve failed (0 where a point's
            chunk failed: see ``status``).
        power_loss_position: Φ(t_i) per point, W [N, M].
        tooth_force: W_T per point, position and pair slot, N [N, M, 2]; surface_velocity: uj, m/s
            [N, M, 2, 2]; hertz_pressure: Hertz pressure of W_T, Pa [N, M, 2] (as in SimulationResult).
        status: per point, the simulation status (0 ok; ``jaxgear.results.Status``), or 5 (FAILED) where
            the point's chunk raised or its outputs were not finite.
        converged: status == 0; on_attractor: status 6 (no stable periodic orbit: means over the
            attractor); failed: neither.
        messages: errors of failed chunks.
    """

    inputs: dict
    power_loss: np.ndarray
    power_loss_sliding: np.ndarray
    power_loss_rolling: np.ndarray
    efficiency: np.ndarray
    dte_rms: np.ndarray
    fixed_point_residual: np.ndarray
    failed_contacts: np.ndarray
    power_loss_back: np.ndarray
    back_contact_share: np.ndarray
    mesh_damping_power: np.ndarray
    power_loss_position: np.ndarray
    tooth_force: np.ndarray
    surface_velocity: np.ndarray
    hertz_pressure: np.ndarray
    status: np.ndarray
    messages: tuple[str, ...] = eqx.field(static=True, default=())

    @property
    def converged(self) -> np.ndarray:
        return np.asarray(self.status) == 0

    @property
    def on_attractor(self) -> np.ndarray:
        """No stable periodic orbit: the point's values are means over the attractor the gears
        settle on (status 6, ``Fidelity.attractor_periods``)."""
        return np.asarray(self.status) == STATUS_ATTRACTOR

    @property
    def failed(self) -> np.ndarray:
        """Neither converged nor an attractor mean: a real failure (flagged)."""
        return ~self.converged & ~self.on_attractor

    def status_names(self) -> list[str]:
        """Each point's status in words (``jaxgear.results``)."""
        return messages(self.status)

    def to_csv(self, path: str | Path) -> Path:
        """One row per point; SI except speed (rpm), efficiency (%), DTE (µm), temperature (°C)."""
        path = Path(path)
        cols = {}
        for k, v in self.inputs.items():
            if k == "inlet_temperature":
                cols["inlet_temperature_C"] = np.asarray(v) - 273.15
            elif k == "tip_relief_amount":
                cols["tip_relief_um"] = np.asarray(v) * 1e6
            elif k == "backlash":
                cols["backlash_um"] = np.asarray(v) * 1e6
            else:
                cols[k] = np.asarray(v)
        cols.update(
            power_loss_W=self.power_loss,
            power_loss_sliding_W=self.power_loss_sliding,
            power_loss_rolling_W=self.power_loss_rolling,
            efficiency_percent=100.0 * np.asarray(self.efficiency),
            dte_rms_um=1e6 * np.asarray(self.dte_rms),
            fixed_point_residual=self.fixed_point_residual,
            failed_contacts=self.failed_contacts,
            power_loss_back_W=self.power_loss_back,
            back_contact_share=self.back_contact_share,
            mesh_damping_power_W=self.mesh_damping_power,
            status=self.status,
        )
        names = list(cols)
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow([*names, "status_name"])
            for i, label in enumerate(self.status_names()):
                w.writerow([f"{np.asarray(cols[n])[i]:.10g}" for n in names] + [label])
        return path


def _apply(pair, surfaces, op, point):
    """The point's pair, surfaces and operating point with the varied inputs substituted."""
    op = OperatingPoint(
        torque=point.get("torque", op.torque),
        speed_rpm=point.get("speed_rpm", op.speed_rpm),
        inlet_temperature=point.get("inlet_temperature", op.inlet_temperature),
    )
    if "roughness_scale" in point:
        surfaces = eqx.tree_at(lambda s: s.scale, surfaces, jnp.asarray(point["roughness_scale"]))
    if "tip_relief_amount" in point:
        amount = jnp.stack([point["tip_relief_amount"], point["tip_relief_amount"]])
        pair = eqx.tree_at(lambda p: p.tip_relief.amount, pair, amount)
    if "backlash" in point:
        pair = eqx.tree_at(lambda p: p.backlash, pair, jnp.asarray(point["backlash"]))
    if "mesh_damping_ratio" in point:
        ratio = jnp.asarray(point["mesh_damping_ratio"])
        pair = eqx.tree_at(lambda p: p.mesh_damping_ratio, pair, ratio)
    return pair, surfaces, op


def _outputs(result):
    out = {k: getattr(result, k) for k in _SCALARS}
    for k in _PER_POSITION:
        out[k] = getattr(result, k)
    out["sim_status"] = result.status
    out["failed_contacts"] = result.failed_contacts
    out["converged"] = result.converged
    return out


def _first_outputs(result, pending, fidelity):
    out = _outputs(result)
    out["later"] = needs_second_pass(pending, fidelity)
    if pending is not None:
        out["pending"] = pending
    return out


# Module-level point and step functions taking the shared inputs as an argument: the sweep engine keeps
# their compiled chunks, so a second sweep (another torque, lubricant, surface finish...) with the same
# fidelity and shapes does not compile again.
def _point(point, shared):
    pair, lubricant, surfaces, op, fidelity = shared
    p, s, o = _apply(pair, surfaces, op, point)
    result, _, pending = first_pass(p, lubricant, s, o, fidelity)
    return _first_outputs(result, pending, fidelity)


def _step(warm, point, shared):
    pair, lubricant, surfaces, op, fidelity = shared
    p, s, o = _apply(pair, surfaces, op, point)
    result, new_warm, pending = first_pass(p, lubricant, s, o, fidelity, warm)
    # A failed point must not poison the rest of the march: keep the last good state (a stable
    # orbit whose back-flank loss the second pass adds is a good state).
    good = result.converged | (result.status == STATUS_PENDING)
    carry = jax.tree_util.tree_map(lambda a, b: jnp.where(good, a, b), new_warm, warm)
    return carry, _first_outputs(result, pending, fidelity)


@eqx.filter_jit
def _finish_point(point, pending, warm_attractor, shared):
    pair, lubricant, surfaces, op, fidelity = shared
    p, s, o = _apply(pair, surfaces, op, point)
    result, handover = finish(p, lubricant, s, o, fidelity, pending, warm_attractor)
    return _outputs(result), handover


def _chains(idx, continuation: bool):
    """The flagged points as chains that must run in order: in a continuation sweep, runs of
    neighbouring points (each continues from the one before); otherwise one point each."""
    chains = []
    for i in idx:
        if continuation and chains and chains[-1][-1] == i - 1:
            chains[-1].append(int(i))
        else:
            chains.append([int(i)])
    return sorted(chains, key=len, reverse=True)


def _second_pass(out, raw_status, inputs, shared, continuation: bool):
    """Run ``finish`` on the points whose first pass asks for it (no stable orbit, back-flank
    strikes) and put their outputs in place. In a continuation sweep a point without a stable
    orbit right after another continues from that one's attractor record (the paper's stepwise
    speed increase); chains of such points, and independent points, run side by side on the host's
    cores (each a sequential time integration that one core runs), with the same results as one
    after the other."""
    later = np.asarray(out.pop("later")).astype(bool) & (np.asarray(raw_status) < 2)
    pending_all = out.pop("pending", None)
    idx = np.nonzero(later)[0]
    if idx.size == 0 or pending_all is None:
        return out
    dtype = np.asarray(out["power_loss"]).dtype
    cold = (jnp.zeros(13, dtype), jnp.zeros((), dtype))

    def run_chain(chain, handover):
        results = []
        for i in chain:
            point = {k: jnp.asarray(v[i]) for k, v in inputs.items()}
            pending = jax.tree_util.tree_map(lambda a, i=i: jnp.asarray(a[i]), pending_all)
            new, handover = _finish_point(point, pending, handover, shared)
            results.append((i, jax.block_until_ready(new)))
        return results, handover

    chains = _chains(idx, continuation)
    # the first point alone compiles the program; the rest share it
    results, handover = run_chain(chains[0][:1], cold)
    rest = [(chains[0][1:], handover)] + [(c, cold) for c in chains[1:]]
    rest = [(c, h) for c, h in rest if c]
    if rest:
        workers = min(len(rest), os.cpu_count() or 1)
        with ThreadPoolExecutor(max_workers=workers) as pool:
            for part, _ in pool.map(lambda job: run_chain(*job), rest):
                results += part
    for i, new in results:
        for k, v in new.items():
            arr = np.array(out[k])
            arr[i] = np.asarray(v)
            out[k] = arr
    return out


def sweep(
    pair,
    lubricant,
    surfaces,
    op: OperatingPoint,
    *,
    speeds_rpm=None,
    fidelity: Fidelity | None = None,
    mode: str = "parallel",
    chunk_size: int | None = None,
    checkpoint_dir: str | Path | None = None,
    progress: bool = False,
    devices=None,
    **vary,
) -> SweepResult:
    """Simulate many points that differ in speed (rpm) and/or other traced inputs.

    Args:
        pair, lubricant, surfaces, op: the base point (as for ``simulate``).
        speeds_rpm: gear 1 speeds, rpm [N] (or a scalar).
        fidelity: Fidelity (default ``Fidelity.fast()``).
        mode: "parallel" (vmap, chunked, sharded over ``devices``) or "continuation" (``lax.scan`` in
            the given order, each point warm-started from the previous one).
        chunk_size: points per chunk (default all); finished chunks go to ``checkpoint_dir`` if given,
            and a rerun with the same inputs resumes from them.
        progress: progress bar on stderr.
        devices: devices to shard parallel chunks over (default all local devices).
        **vary: other inputs per point, from ``SWEEPABLE``: torque (N m), inlet_temperature (K),
            roughness_scale, tip_relief_amount (m, both gears), backlash (m, total clearance 2ℓ
            along the line of action: small values bring back-side impacts), mesh_damping_ratio
            (ζ, ``GearPair.mesh_damping_ratio``); arrays of length N or scalars.

    Returns:
        SweepResult with per-point status; every good point is kept when others fail.

    Points that need the second pass (no stable periodic orbit: the attractor's time integration;
    back-flank strikes) run it after the sweep, one compiled program for all of them; independent
    points, and in a continuation sweep runs of neighbouring points, run side by side in threads on
    the host's cores.
    """
    fidelity = Fidelity.fast() if fidelity is None else fidelity
    check_inputs(pair, lubricant, surfaces, op, fidelity)
    pair, lubricant, surfaces, op, fidelity = canonical((pair, lubricant, surfaces, op, fidelity))
    validate((pair, lubricant, surfaces, op, fidelity))
    if mode not in ("parallel", "continuation"):
        raise ValueError(f"mode = {mode!r} is not valid; valid choices: 'parallel', 'continuation'")
    if chunk_size is not None and (
        isinstance(chunk_size, bool)
        or not isinstance(chunk_size, int | np.integer)
        or chunk_size < 1
    ):
        raise ValueError(
            f"chunk_size = {chunk_size!r} is out of range; valid range: integer >= 1 (or None)"
        )
    unknown = set(vary) - set(SWEEPABLE)
    if unknown:
        raise ValueError(
            f"cannot sweep {sorted(unknown)}; valid (sweepable) inputs: {', '.join(SWEEPABLE)}"
        )
    if speeds_rpm is not None:
        vary = {"speed_rpm": speeds_rpm, **vary}  # speed first: the CSV's leading column
    if not vary:
        raise ValueError("nothing to sweep: give speeds_rpm or another input from SWEEPABLE")
    arrays = {}
    for k, v in vary.items():
        name = "speeds_rpm" if k == "speed_rpm" else k  # the argument's name
        try:
            arr = np.asarray(v, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"{name} = {v!r} is not valid; valid: real numbers") from None
        if arr.ndim > 1 or arr.size == 0:
            raise ValueError(
                f"{name} has shape {arr.shape}; valid: a scalar or a non-empty 1-D array of points"
            )
        arrays[k] = arr.reshape(-1)
    n = max(arr.size for arr in arrays.values())
    inputs = {}
    for k, arr in arrays.items():
        if arr.size == 1:
            arr = np.full(n, arr[0])
        if arr.size != n:
            raise ValueError(f"{k} has {arr.size} points; expected 1 or {n}")
        inputs[k] = arr
    _validate_points(pair, surfaces, op, inputs)

    shared = (pair, lubricant, surfaces, op, fidelity)
    if mode == "parallel":
        raw = run_points(
            _point,
            inputs,
            args=shared,
            chunk_size=chunk_size,
            checkpoint_dir=checkpoint_dir,
            progress=progress,
            devices=devices,
            label="sweep",
            # EHL rungs: each point's contact solves have cold-start fallbacks behind lax.cond,
            # which a vmap over points would run for every point (measured 18x slower on a CPU)
            sequential=fidelity.uses_ehl,
        )
    else:
        # the first point starts cold through the same compiled step as the rest
        warm0 = cold_start(fidelity.n_positions, jnp.asarray(op.torque).dtype)
        raw = run_continuation(
            _step,
            warm0,
            inputs,
            args=shared,
            chunk_size=chunk_size,
            checkpoint_dir=checkpoint_dir,
            progress=progress,
            label="continuation",
        )
    out = _second_pass(dict(raw.outputs), raw.status, inputs, shared, mode == "continuation")
    status = np.where(raw.status >= 2, Status.FAILED, np.asarray(out["sim_status"])).astype(
        np.int32
    )
    return SweepResult(
        inputs=inputs,
        power_loss=np.asarray(out["power_loss"]),
        power_loss_sliding=np.asarray(out["power_loss_sliding"]),
        power_loss_rolling=np.asarray(out["power_loss_rolling"]),
        efficiency=np.asarray(out["efficiency"]),
        dte_rms=np.asarray(out["dte_rms"]),
        fixed_point_residual=np.asarray(out["fixed_point_residual"]),
        failed_contacts=np.asarray(out["failed_contacts"]),
        power_loss_back=np.asarray(out["power_loss_back"]),
        back_contact_share=np.asarray(out["back_contact_share"]),
        mesh_damping_power=np.asarray(out["mesh_damping_power"]),
        power_loss_position=np.asarray(out["power_loss_position"]),
        tooth_force=np.asarray(out["tooth_force"]),
        surface_velocity=np.asarray(out["surface_velocity"]),
        hertz_pressure=np.asarray(out["hertz_pressure"]),
        status=status,
        messages=raw.messages,
    )


def _validate_points(pair, surfaces, op, inputs):
    """Every point must be a valid operating point: check them all before any work starts."""
    if "speed_rpm" in inputs:
        check_positive("speeds_rpm", inputs["speed_rpm"], "rpm")
    if "torque" in inputs:
        check_positive("torque", inputs["torque"], "N m")
    if "inlet_temperature" in inputs:
        check_range("inlet_temperature", inputs["inlet_temperature"], 200.0, 600.0, unit="K")
    if "roughness_scale" in inputs:
        check_non_negative("roughness_scale", inputs["roughness_scale"])
    if "tip_relief_amount" in inputs:
        top = MAX_RELIEF_PER_MODULE * float(pair.module)
        check_range("tip_relief_amount", inputs["tip_relief_amount"], 0.0, top, unit="m")
    if "backlash" in inputs:
        check_non_negative("backlash", inputs["backlash"], "m")
    if "mesh_damping_ratio" in inputs:
        check_range(
            "mesh_damping_ratio", inputs["mesh_damping_ratio"], 0.0, 1.0, high_inclusive=False
        )


__all__ = ["SWEEPABLE", "SweepResult", "sweep", "POINT_STATUS_NAMES"]
