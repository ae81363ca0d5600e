"""The fidelity ladder measured: error against time of every rung, and grid/time-step convergence.

For a fixed scenario set (the paper's baseline — 700 N m, 90 °C, ground — at speeds near both
resonance peaks and away from them; 60 °C; 1500 N m; polished) this computes every combination of
the ladder (DESIGN §4: dynamics × friction × thermal × transient × resolution level) that runs, its
error in Φ̄ (power_loss), Ψ (efficiency) and DTE RMS against the highest-fidelity reference that runs,
and its time per point (compile and run timed separately: ``lower().compile()``, then the compiled
program, after ``block_until_ready``). Reference: ``Fidelity.paper()`` when it runs; otherwise the
highest rung that runs (tribo-dynamic first, then friction, thermal, transient from the top) at the
reference resolution. The output states which.

Also convergence studies with the observed order: EHL nodes per contact (quasi-static smooth EHL),
positions per mesh cycle and dynamics steps per mesh period (tribo-dynamic regression rung, whose
run is cheap; the step and position counts act the same way on every friction rung).

Writes: the section ``fidelity_trade`` of benchmarks/RESULTS.md (tables, reference, machine, date,
convergence, defaults), the Pareto plot docs/figures/fidelity_pareto.png, and the measured-error
table jaxgear/data/fidelity_errors.json that ``jg.Fidelity.auto`` reads.

Run (from the repository root):
    PYTHONPATH=. python benchmarks/fidelity_trade.py --quick --cache /tmp/fidelity_cache.json
``--quick`` measures fewer scenarios, the EHL rungs at the coarse and default levels only, the
reference at the default level (the nodes/positions studies bound its resolution error) and shorter
convergence ladders. Without it: every scenario, every level, the reference at the fine level. The
cache (optional) keeps every finished point, so an interrupted run resumes, and a rerun after a change
of the report only recomputes nothing. Rerun without ``--quick`` when the paper rung exists: the
reference switches to ``Fidelity.paper()`` by itself.
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime
import json
import math
import os
import statistics
import sys
import time
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import equinox as eqx  # noqa: E402
from _report import machine, write_section  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.fidelity.choose import (  # noqa: E402
    AXIS_ORDER,
    INDICATOR_VERSION,
    QUANTITIES,
    scenario_indicators,
)

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_JSON = ROOT / "jaxgear" / "data" / "fidelity_errors.json"
DEFAULT_FIGURE = ROOT / "docs" / "figures" / "fidelity_pareto.png"

#: Where the shipped measured-error table comes from and who reads it: the one place this is
#: written down (the section's first paragraph).
PROVENANCE = (
    "This run also writes `jaxgear/data/fidelity_errors.json`, the measured-error table shipped "
    "with the package: the rungs, scenarios, reference, convergence studies, machine and date of "
    "this section (`--json PATH` writes it elsewhere; `--smoke`, a pipeline check, writes it too "
    "unless `--json` points elsewhere). `Fidelity.auto` and `choose_fidelity` read it "
    "(`jaxgear/fidelity/choose.py`, `load_error_table`, which refuses a table of another "
    "`INDICATOR_VERSION`); `benchmarks/coupling_trade.py` takes the reference's results and run "
    "times from it, `benchmarks/fast_vs_paper.py` its run time per point. Regenerate both after a change to the physics, the "
    "rungs or the indicators: `PYTHONPATH=. python benchmarks/fidelity_trade.py --quick --cache "
    "/tmp/fidelity_cache.json`."
)

#: Resolution levels of the ladder. "default" is ``Fidelity()``'s resolution.
LEVELS = {
    "coarse": {"n_positions": 24, "n_nodes": 65, "steps_per_period": 32},
    "default": {"n_positions": 32, "n_nodes": 129, "steps_per_period": 64},
    "fine": {"n_positions": 48, "n_nodes": 257, "steps_per_period": 128},
}


@dataclasses.dataclass(frozen=True)
class Scenario:
    name: str
    torque: float  # N m
    speed_rpm: float
    inlet_c: float  # °C
    surfaces: str  # preset name
    note: str
    quick: bool  # part of the --quick set

    def inputs(self, pair):
        lub = jg.presets.mil_l_23699()
        surf = getattr(jg.presets, self.surfaces)()
        op = jg.OperatingPoint(
            torque=self.torque, speed_rpm=self.speed_rpm, inlet_temperature=self.inlet_c + 273.15
        )
        return pair, lub, surf, op

    def key(self) -> str:
        return f"{self.torque:g}Nm/{self.speed_rpm:g}rpm/{self.inlet_c:g}C/{self.surfaces}"


# The calibrated pair (li2015_pair_calibrated) peaks at 1750 rpm (2nd mesh harmonic on the 2917 Hz
# mode) and around 3375-3500 rpm; from a cold start its period-1 orbit is unstable at 3400-3550 and
# 3775-4050 rpm (benchmarks/RESULTS.md, dynamics), so the points near the high peak sit just below it.
SCENARIOS = (
    Scenario("base_1000", 700.0, 1000.0, 90.0, "ground", "away from both peaks, low speed", False),
    Scenario("base_1750", 700.0, 1750.0, 90.0, "ground", "on the 1750 rpm peak", True),
    Scenario("base_2500", 700.0, 2500.0, 90.0, "ground", "between the peaks (C)", True),
    Scenario("base_3300", 700.0, 3300.0, 90.0, "ground", "just below the 3500 rpm peak (D)", True),
    Scenario("base_3375", 700.0, 3375.0, 90.0, "ground", "at the high peak (E)", False),
    Scenario("base_4200", 700.0, 4200.0, 90.0, "ground", "top of the sweep, above the peak", False),
    Scenario("oil60_2500", 700.0, 2500.0, 60.0, "ground", "inlet 60 °C", True),
    Scenario("torque1500_2500", 1500.0, 2500.0, 90.0, "ground", "1500 N m", True),
    Scenario("polished_2500", 700.0, 2500.0, 90.0, "polished", "polished surfaces", True),
)

#: Physics of the ladder, (dynamics, friction, thermal, transient); thermal and transient are options
#: of the EHL rungs only (the formula rungs ignore them), so the formula rungs appear once.
FORMULA_PHYSICS = [
    (d, f, False, False)
    for d in AXIS_ORDER["dynamics"]
    for f in ("constant", "regression", "ehl_formula")
]
EHL_PHYSICS = [
    (d, f, th, tr)
    for d in AXIS_ORDER["dynamics"]
    for f in ("ehl_smooth", "ehl_mixed")
    for th in (False, True)
    for tr in (False, True)
]


def _rank(physics):
    """Sort key: the most complete physics first (tribo-dynamic, then friction, thermal, transient)."""
    d, f, th, tr = physics
    return (
        AXIS_ORDER["dynamics"].index(d),
        AXIS_ORDER["friction"].index(f),
        int(th),
        int(tr),
    )


def physics_label(physics) -> str:
    d, f, th, tr = physics
    return f"{d}/{f}/{'thermal' if th else 'iso'}/{'transient' if tr else 'steady'}"


def fidelity_fields(fid: jg.Fidelity) -> dict:
    names = ("dynamics", "friction", "thermal", "transient", "n_positions", "n_nodes")
    return {n: getattr(fid, n) for n in (*names, "steps_per_period")}


SIM = eqx.filter_jit(jg.simulate)


class Runner:
    """Compiles each fidelity once (timed), runs points (timed), keeps everything in a cache file."""

    def __init__(self, pair, cache_path: Path | None):
        self.pair = pair
        self.cache_path = cache_path
        self.cache = {"points": {}, "compile": {}, "errors": {}}
        if cache_path is not None and cache_path.exists():
            self.cache.update(json.loads(cache_path.read_text()))
        self.compiled = {}

    def seed(self, table: dict) -> None:
        """Cache the points of an earlier table (``--seed-from-table``): every available rung's and
        the reference's results per scenario, and their compile times."""
        by_name = {s.name: s for s in SCENARIOS}
        entries = [(r["fidelity"], r["results"], r.get("compile_s")) for r in table["rungs"]]
        ref = table["reference"]
        ref_results = {n: s["reference_result"] for n, s in table["scenarios"].items()}
        entries.append((ref["fidelity"], ref_results, ref.get("compile_s")))
        seeded = 0
        for fields, results, compile_s in entries:
            key = json.dumps(fields, sort_keys=True)
            for name, res in results.items():
                if name in by_name and res is not None:
                    self.cache["points"].setdefault(key + "|" + by_name[name].key(), res)
                    seeded += 1
            if compile_s is not None:
                self.cache["compile"].setdefault(key, compile_s)
                self.cache.setdefault("available", {})[key] = True
        self.seeded_from = table.get("generated")
        print(f"seeded {seeded} points from the table of {self.seeded_from}", flush=True)
        self._save()

    def _save(self):
        if self.cache_path is not None:
            tmp = self.cache_path.with_suffix(".tmp")
            tmp.write_text(json.dumps(self.cache))
            tmp.replace(self.cache_path)

    @staticmethod
    def fid_key(fid: jg.Fidelity) -> str:
        return json.dumps(fidelity_fields(fid), sort_keys=True)

    def available(self, fid: jg.Fidelity, probe: Scenario) -> str | None:
        """None if ``fid`` runs; else why not: the ValueError of a rung not implemented yet, or a
        switch that traces to the same program as without it (a piece that is silently ignored)."""
        key = self.fid_key(fid)
        if key in self.cache["errors"]:
            return self.cache["errors"][key]
        if key in self.cache["compile"] or self.cache.get("available", {}).get(key):
            return None
        try:
            lowered = SIM.lower(*probe.inputs(self.pair), fid)
            why = self._no_effect(fid, lowered, probe)
        except ValueError as err:
            why = f"ValueError: {err}"
        if why is not None:
            self.cache["errors"][key] = why
            self._save()
            print(f"  not available: {key}: {why}", flush=True)
            return why
        # Compiled when first run (one program held at a time: ~45 compiled programs at once
        # exhaust the process's memory mappings, vm.max_map_count, and LLVM aborts).
        self.cache.setdefault("available", {})[key] = True
        self._save()
        return None

    def _no_effect(self, fid, lowered, probe) -> str | None:
        """A switch above the cheaper rung (thermal, transient, mixed) that leaves the traced program
        unchanged is not implemented: the rung would be mislabelled, so it is not available."""
        for field, cheaper in (
            ("thermal", False),
            ("transient", False),
            ("friction", "ehl_smooth"),
        ):
            if field == "friction" and fid.friction != "ehl_mixed":
                continue
            if field != "friction" and not getattr(fid, field):
                continue
            alt = fid.replace(**{field: cheaper})
            try:
                same = SIM.lower(*probe.inputs(self.pair), alt).as_text() == lowered.as_text()
            except ValueError:
                continue
            if same:
                return (
                    f"{field}={getattr(fid, field)!r} traces to the same program as "
                    f"{field}={cheaper!r}: the switch has no effect yet (silently ignored)"
                )
        return None

    def _compile(self, fid, scenario, lowered=None, lower_s=0.0):
        key = self.fid_key(fid)
        if key not in self.compiled:
            # one compiled program at a time (see ``available``); jax's own caches hold every
            # program compiled so far, and their memory maps too
            self.compiled.clear()
            jax.clear_caches()
            t0 = time.perf_counter()
            if lowered is None:
                lowered = SIM.lower(*scenario.inputs(self.pair), fid)
            self.compiled[key] = lowered.compile()
            seconds = time.perf_counter() - t0 + lower_s
            self.cache["compile"][key] = seconds
            self._save()
            print(f"  compiled {key} in {seconds:.1f} s", flush=True)
        return self.compiled[key]

    def compile_seconds(self, fid) -> float | None:
        return self.cache["compile"].get(self.fid_key(fid))

    def point(self, fid: jg.Fidelity, scenario: Scenario) -> dict:
        key = self.fid_key(fid) + "|" + scenario.key()
        if key in self.cache["points"]:
            return self.cache["points"][key]
        program = self._compile(fid, scenario)
        t0 = time.perf_counter()
        res = jax.block_until_ready(program(*scenario.inputs(self.pair), fid))
        seconds = time.perf_counter() - t0
        out = {
            "power_loss": float(res.power_loss),
            "power_loss_rolling": float(res.power_loss_rolling),
            "efficiency": float(res.efficiency),
            "dte_rms": float(res.dte_rms),
            "status": int(res.status),
            "fixed_point_iterations": int(res.fixed_point_iterations),
            "run_s": seconds,
        }
        print(
            f"  {scenario.name:16s} {fid.dynamics}/{fid.friction} M={fid.n_positions} "
            f"N={fid.n_nodes} steps={fid.steps_per_period}: Φ̄ {out['power_loss']:.2f} W, "
            f"DTE {out['dte_rms'] * 1e6:.3f} µm, status {out['status']}, {seconds:.2f} s",
            flush=True,
        )
        self.cache["points"][key] = out
        self._save()
        return out


def relative_errors(values: dict, ref: dict) -> dict:
    """Relative errors |x − x_ref|/|x_ref| of Φ̄, Ψ, DTE RMS."""
    return {q: abs(values[q] - ref[q]) / abs(ref[q]) for q in QUANTITIES}


def choose_reference(runner, probe, reference_level, physics_set):
    """``Fidelity.paper()`` when it runs, else the highest physics that runs at ``reference_level``."""
    paper = jg.Fidelity.paper()
    why = runner.available(paper, probe) if physics_set is not FORMULA_PHYSICS else "smoke run"
    if why is None:
        return paper, "Fidelity.paper()", True, "Fidelity.paper() runs"
    for physics in sorted(physics_set, key=_rank, reverse=True):
        d, f, th, tr = physics
        fid = jg.Fidelity(
            dynamics=d, friction=f, thermal=th, transient=tr, **LEVELS[reference_level]
        )
        if runner.available(fid, probe) is None:
            note = (
                f"Fidelity.paper() is not available (ValueError: {why}); the reference is the highest "
                f"rung that runs, {physics_label(physics)}, at the {reference_level} resolution"
            )
            return fid, f"{physics_label(physics)} @ {reference_level}", False, note
    raise RuntimeError("no rung runs")


# -------------------------------------------------------------------------------------------------
# Convergence studies
# -------------------------------------------------------------------------------------------------
def observed_orders(values, ratio=2.0):
    """p from consecutive triples of a refinement sequence with a constant ratio:
    p = log(|Q1 − Q2|/|Q2 − Q3|)/log(ratio)."""
    out = []
    for a, b, c in zip(values, values[1:], values[2:]):
        num, den = abs(a - b), abs(b - c)
        out.append(math.log(num / den) / math.log(ratio) if num > 0 and den > 0 else float("nan"))
    return out


def convergence_study(runner, name, scenario, fids, parameter, values):
    points = [runner.point(f, scenario) for f in fids]
    rows = []
    for q in ("power_loss", "dte_rms"):
        seq = [p[q] for p in points]
        best = seq[-1]
        rows.append(
            {
                "quantity": q,
                "values": seq,
                "error_vs_finest": [abs(v - best) / abs(best) for v in seq],
                "observed_order": observed_orders(seq),
            }
        )
    return {
        "study": name,
        "scenario": scenario.name,
        "parameter": parameter,
        "levels": values,
        "rung": physics_label((fids[0].dynamics, fids[0].friction, False, False)),
        "status": [p["status"] for p in points],
        "run_s": [p["run_s"] for p in points],
        "quantities": rows,
    }


def convergence(runner, quick, scen, smoke=False):
    studies = []
    if smoke:  # pipeline check: one cheap study
        td = jg.Fidelity(dynamics="tribo_dynamic", friction="regression")
        fids = [td.replace(n_positions=32, steps_per_period=k) for k in (32, 64, 128)]
        s = scen["base_2500"]
        return [convergence_study(runner, "time steps", s, fids, "steps_per_period", [32, 64, 128])]
    # EHL nodes per contact: the contacts alone set this error, so quasi-static smooth EHL.
    nodes = [65, 129, 257, 513]
    base = jg.Fidelity(dynamics="quasi_static", friction="ehl_smooth", n_positions=32)
    for s in [scen["base_2500"]] + ([] if quick else [scen["torque1500_2500"]]):
        fids = [base.replace(n_nodes=n) for n in nodes]
        studies.append(convergence_study(runner, "EHL nodes", s, fids, "n_nodes", nodes))
    # Positions per mesh cycle and steps per mesh period: tribo-dynamic regression rung.
    positions = [24, 48, 96] if quick else [24, 48, 96, 192]
    steps = [32, 64, 128, 256] if quick else [16, 32, 64, 128, 256, 512]
    td = jg.Fidelity(dynamics="tribo_dynamic", friction="regression")
    for s in (scen["base_2500"], scen["base_1750"]):
        fids = [td.replace(n_positions=m, steps_per_period=64) for m in positions]
        studies.append(convergence_study(runner, "positions", s, fids, "n_positions", positions))
        fids = [td.replace(n_positions=32, steps_per_period=k) for k in steps]
        studies.append(convergence_study(runner, "time steps", s, fids, "steps_per_period", steps))
    if not quick:  # positions with EHL: the rolling loss is sampled the same way
        fids = [base.replace(n_positions=m) for m in (24, 48, 96)]
        studies.append(
            convergence_study(
                runner, "positions (EHL)", scen["base_2500"], fids, "n_positions", [24, 48, 96]
            )
        )
    return studies


# -------------------------------------------------------------------------------------------------
# Report
# -------------------------------------------------------------------------------------------------
def pct(x, digits=2):
    if x is None or not math.isfinite(x):
        return "–"
    return f"{100 * x:.{digits}f}"


def sig(x):
    """A relative error in percent, 2 significant digits (small ones in full)."""
    if x is None or not math.isfinite(x):
        return "–"
    return f"{100 * x:.2g}"


def rung_summary(rung, scen_names):
    bad = [s for s in scen_names if s in rung["results"] and rung["results"][s]["status"] != 0]
    # Errors over the scenarios where the rung converged: a flagged point's value is not an answer
    # (it is listed under "not converged"; Fidelity.auto never certifies a rung there).
    errs = [rung["errors"][s] for s in scen_names if s in rung["errors"] and s not in bad]
    runs = [rung["results"][s]["run_s"] for s in scen_names if s in rung["results"]]
    return {
        "max": {q: max((e[q] for e in errs), default=float("nan")) for q in QUANTITIES},
        "median": {
            q: statistics.median([e[q] for e in errs]) if errs else float("nan") for q in QUANTITIES
        },
        "run_s": statistics.median(runs) if runs else float("nan"),
        "not_converged": bad,
    }


def pareto_plot(rungs, reference, path: Path):
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    colours = {
        "constant": "tab:gray",
        "regression": "tab:blue",
        "ehl_formula": "tab:purple",
        "ehl_smooth": "tab:green",
        "ehl_mixed": "tab:red",
    }
    markers = {"quasi_static": "o", "tribo_dynamic": "s"}
    fills = {"coarse": "none", "default": None, "fine": None}
    sizes = {"coarse": 40, "default": 40, "fine": 90}
    floor = 1e-5
    for ax, q, title in (
        (axes[0], "power_loss", "mean power loss Φ̄"),
        (axes[1], "dte_rms", "DTE RMS"),
    ):
        pts = []
        for r in rungs:
            if not r["available"] or r.get("is_reference"):
                continue
            t, e = r["summary"]["run_s"], max(r["summary"]["max"][q], floor)
            if not (math.isfinite(t) and math.isfinite(e)):
                continue
            pts.append((t, e))
            ax.scatter(
                t,
                e * 100,
                marker=markers[r["dynamics"]],
                s=sizes[r["level"]],
                facecolors=fills[r["level"]] or colours[r["friction"]],
                edgecolors=colours[r["friction"]],
            )
        # Pareto front: no other rung both cheaper and more accurate.
        pts.sort()
        front, best = [], math.inf
        for t, e in pts:
            if e < best:
                front.append((t, e))
                best = e
        if front:
            ax.step(
                [p[0] for p in front],
                [p[1] * 100 for p in front],
                where="post",
                color="k",
                lw=0.8,
                alpha=0.6,
                label="Pareto front",
            )
        t_ref = reference["summary_run_s"]
        if math.isfinite(t_ref):
            ax.axvline(t_ref, color="k", ls=":", lw=1, label=f"reference ({t_ref:.3g} s)")
        ax.set(
            xscale="log",
            yscale="log",
            xlabel="run time per point (s, median over scenarios, compiled)",
            ylabel=f"max error over scenarios, {title} (%)",
            title=f"{title}: error vs time",
        )
        ax.grid(True, which="both", alpha=0.3)
    from matplotlib.lines import Line2D

    handles = [
        Line2D([], [], ls="", marker="s", color="k", label="tribo-dynamic"),
        Line2D([], [], ls="", marker="o", color="k", label="quasi-static"),
        Line2D([], [], ls="", marker="o", mfc="none", color="k", label="coarse (open)"),
        Line2D([], [], ls="", marker="o", ms=10, color="k", label="fine (large)"),
    ] + [
        Line2D([], [], ls="", marker="o", color=c, label=f)
        for f, c in colours.items()
        if any(r["friction"] == f and r["available"] for r in rungs)
    ]
    axes[0].legend(handles=handles + axes[0].get_legend_handles_labels()[0], fontsize=8)
    axes[1].legend(fontsize=8)
    fig.suptitle(f"Fidelity ladder: error against the reference ({reference['label']})")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def convergence_rows(studies) -> list[str]:
    """Rows of the convergence table (Φ̄ and DTE RMS; nodes: Φ̄ only, the contacts do not move DTE)."""
    lines = []
    for st in studies:
        for row in st["quantities"]:
            if row["quantity"] != "power_loss" and st["parameter"] == "n_nodes":
                continue
            lv = st["levels"]
            errs = ", ".join(f"{v}: {sig(e)} %" for v, e in zip(lv, row["error_vs_finest"]))
            orders = ", ".join(f"{p:.2f}" for p in row["observed_order"] if math.isfinite(p))
            lines.append(
                f"| {st['study']} | {st['scenario']} | {row['quantity']} | {errs} | "
                f"{orders or '–'} | {' '.join(str(s) for s in st['status'])} |"
            )
    return lines


def write_report(table, studies, figure_path, wall, quick, write=True):
    ref = table["reference"]
    scen_names = [s for s in table["scenarios"] if table["scenarios"][s]["reference_converged"]]
    lines = [
        f"## Fidelity ladder: error against time (`benchmarks/fidelity_trade.py{' --quick' if quick else ''}`)",
        "",
        PROVENANCE,
        "",
        f"Machine: {table['machine']}; load average at the end {table['load_average']} (the 2 cores "
        "were shared with other engineers' jobs: run times are upper bounds, compare them within this "
        f"table). Mode: {'quick' if quick else 'full'}; wall time {wall / 60:.0f} min."
        + (
            f" Seeded (`--seed-from-table`) with the points of the table of {table['seeded_from']}: "
            "the rungs and reference that table had keep their results and run times from that run "
            "(same machine type); the rungs it lacked and the convergence studies ran now."
            if table.get("seeded_from")
            else ""
        ),
        "",
        f"**Reference: {ref['label']}.** {ref['note']}. Every error below is measured against it"
        + (
            ": the paper's model as jaxgear implements it (tribo-dynamic, thermal, mixed, "
            "transient), so the errors say how far a rung is from that model, not from the paper's "
            "reported numbers (see the paper comparison)."
            if ref.get("paper")
            else ", so it says how far a rung is from the best model that runs today, not from "
            "the paper's thermal mixed model."
        ),
        "",
        "Scenarios (the calibrated pair, Mil-L-23699; λ Pan-Hamrock central film over σ at the pitch "
        "point, Pe = u b/(2κ), d = distance of the mesh frequency or its 2nd harmonic from a "
        "mesh-coupled mode):",
        "",
        "| scenario | T (N m) | n (rpm) | inlet (°C) | surfaces | λ | Pe | ph max (GPa) | d | reference Φ̄ (W) | Ψ (%) | DTE RMS (µm) | status |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, s in table["scenarios"].items():
        ind, r = s["indicators"], s["reference_result"]
        lam = ind["film_parameter"]
        lines.append(
            f"| {name} | {s['torque']:g} | {s['speed_rpm']:g} | {s['inlet_temperature_C']:g} | "
            f"{s['surfaces']} | {lam if lam is None else f'{lam:.2f}'} | {ind['peclet']:.0f} | "
            f"{ind['hertz_pressure'] * 1e-9:.2f} | {ind['resonance_distance']:.3f} | "
            f"{r['power_loss']:.1f} | {100 * r['efficiency']:.3f} | {r['dte_rms'] * 1e6:.2f} | "
            f"{r['status']}{'' if s['reference_converged'] else ' (excluded)'} |"
        )
    lines += [
        "",
        f"Errors: max (median) over the {len(scen_names)} scenarios whose reference converged, "
        "leaving out those where the rung itself did not (listed in the last column); "
        "Φ̄ and DTE RMS relative, Ψ in percentage points (100 |ΔΨ|). Time per point: median run time "
        "of the compiled program over the scenarios; compile: `lower().compile()` once per rung. "
        "Levels: "
        + "; ".join(
            f"{k} = {v['n_positions']} positions, {v['n_nodes']} nodes, {v['steps_per_period']} steps"
            for k, v in table["levels"].items()
        )
        + " (nodes only matter on the EHL rungs).",
        "",
        "| dynamics | friction | thermal | transient | level | Φ̄ err % max (median) | Ψ err pp max | DTE err % max (median) | run s/point | compile s | not converged |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    unavailable = []
    for r in table["rungs"]:
        if not r["available"]:
            unavailable.append(r)
            continue
        sm = r["summary"]
        mark = " **(reference)**" if r.get("is_reference") else ""
        lines.append(
            f"| {r['dynamics']} | {r['friction']}{mark} | {r['thermal']} | {r['transient']} | "
            f"{r['level']} | {pct(sm['max']['power_loss'])} ({pct(sm['median']['power_loss'])}) | "
            f"{pct(sm['max']['efficiency'], 3)} | {pct(sm['max']['dte_rms'])} "
            f"({pct(sm['median']['dte_rms'])}) | {sm['run_s']:.3g} | "
            f"{'–' if r['compile_s'] is None else format(r['compile_s'], '.0f')} | "
            f"{', '.join(sm['not_converged']) or '–'} |"
        )
    if unavailable:
        labels = sorted(
            {
                physics_label((r["dynamics"], r["friction"], r["thermal"], r["transient"]))
                for r in unavailable
            }
        )
        lines += [
            "",
            f"Not available yet (raise ValueError when traced; listed so a rerun picks them up): "
            f"{', '.join(labels)}.",
        ]
    # Per-scenario Φ̄ errors.
    avail = [r for r in table["rungs"] if r["available"] and not r.get("is_reference")]
    lines += [
        "",
        "Φ̄ error (%) per scenario:",
        "",
        "| rung | " + " | ".join(scen_names) + " |",
        "|---|" + "---|" * len(scen_names),
    ]
    for r in avail:
        cells = []
        for s in scen_names:
            e = r["errors"].get(s)
            st = r["results"].get(s, {}).get("status", 0)
            cells.append((pct(e["power_loss"], 1) if e else "–") + ("*" if st else ""))
        lines.append(f"| {r['label']} | " + " | ".join(cells) + " |")
    lines += ["", "\\* the rung did not converge there (status ≠ 0).", ""]
    lines += [f"![fidelity Pareto plot]({os.path.relpath(figure_path, ROOT / 'benchmarks')})", ""]
    # Convergence.
    lines += [
        "### Grid and time-step convergence",
        "",
        "Relative difference from the finest level of each ladder, and the observed order "
        "p = log2(|Q(h) − Q(h/2)| / |Q(h/2) − Q(h/4)|) from consecutive triples (levels double).",
        "",
        "| study | scenario | quantity | error vs finest, per level | observed order p | status |",
        "|---|---|---|---|---|---|",
        *convergence_rows(studies),
        "",
    ]
    lines += table["defaults_justification"]
    lines += ["", *auto_and_reach(table)]
    text = "\n".join(lines)
    if write:
        write_section("fidelity_trade", text)
    return text


def auto_and_reach(table) -> list[str]:
    """Fidelity.auto on the measured scenarios (in-sample: the table was set from them) and the
    issue's Reach numbers, both against this table's reference."""
    from jaxgear.fidelity.choose import choose_from_indicators

    ref = table["reference"]
    good = [n for n, s in table["scenarios"].items() if s["reference_converged"]]
    rungs = {r["label"]: r for r in table["rungs"] if r["available"]}

    def label_of(fid):
        physics = (fid.dynamics, fid.friction, fid.thermal, fid.transient)
        level = next(
            (k for k, v in LEVELS.items() if all(getattr(fid, f) == v[f] for f in v)), None
        )
        return f"{physics_label(physics)}@{level}" if level else ref["label"]

    lines = [
        "### Fidelity.auto on these scenarios, and the issue's Reach",
        "",
        "`Fidelity.auto` at 5 % (on Φ̄ and Ψ) for each scenario, from this table. In-sample: the "
        "table was measured on these scenarios, so this checks the bookkeeping, not the "
        "generalisation (tests/fidelity/test_fidelity_auto.py checks held-out scenarios).",
        "",
        "| scenario | chosen | predicted Φ̄ err % | measured Φ̄ err % | run s/point | reference s/point | cheaper |",
        "|---|---|---|---|---|---|---|",
    ]
    ratios = []
    for name in good:
        choice = choose_from_indicators(table["scenarios"][name]["indicators"], 0.05, table=table)
        label = label_of(choice.fidelity)
        rung = rungs.get(label)
        t_ref = table["scenarios"][name]["reference_result"]["run_s"]
        if rung is not None and name in rung["errors"]:
            measured = pct(rung["errors"][name]["power_loss"], 2)
            t = rung["results"][name]["run_s"]
        else:
            measured, t = "0 (the reference)", t_ref
        ratios.append(t_ref / t)
        lines.append(
            f"| {name} | {label} | {pct(choice.predicted_error['power_loss'], 2)} | {measured} | "
            f"{t:.3g} | {t_ref:.3g} | {t_ref / t:.2g}× |"
        )
    if ratios:
        lines += [
            "",
            f"Mean speed-up of the auto choice over the reference: {statistics.mean(ratios):.2g}× "
            f"(Reach: ≥ 5× against the paper fidelity; measured here against {ref['label']}).",
        ]
    f = jg.Fidelity.fast()
    fast = rungs.get(f"{physics_label((f.dynamics, f.friction, f.thermal, f.transient))}@default")
    base = [n for n in good if n.startswith("base_")]
    if fast is not None and base:
        worst = max(fast["errors"][n]["power_loss"] for n in base if n in fast["errors"])
        t_fast = statistics.median(fast["results"][n]["run_s"] for n in base)
        t_ref = statistics.median(table["scenarios"][n]["reference_result"]["run_s"] for n in base)
        lines.append(
            f"`Fidelity.fast()` ({f.dynamics}, {f.friction}) over the baseline scenarios "
            f"({', '.join(base)}): Φ̄ within "
            f"{pct(worst, 1)} % of the reference, {t_ref / t_fast:.3g}× cheaper per point (Reach: "
            "within 15 % of the paper fidelity, ≥ 50× cheaper)."
        )
    return lines


def justify_defaults(studies, table) -> list[str]:
    def err_at(study, value, q="power_loss"):
        row = next(r for r in study["quantities"] if r["quantity"] == q)
        return row["error_vs_finest"][study["levels"].index(value)]

    out = ["**Defaults, from these numbers.**", ""]
    for st in studies:
        p = st["parameter"]
        default = LEVELS["default"][p]
        if default not in st["levels"]:
            continue
        e_phi = err_at(st, default)
        e_dte = err_at(st, default, "dte_rms")
        finest = st["levels"][-1]
        cheaper = [v for v in st["levels"] if v < default]
        cheap_txt = (
            f"; {cheaper[-1]} would give {sig(err_at(st, cheaper[-1]))} % in Φ̄"
            + ("" if p == "n_nodes" else f" and {sig(err_at(st, cheaper[-1], 'dte_rms'))} % in DTE")
            if cheaper
            else ""
        )
        dte_txt = "" if p == "n_nodes" else f", DTE RMS {sig(e_dte)} %"
        out.append(
            f"- `{p}` = {default} ({st['study']}, {st['scenario']}): Φ̄ within {sig(e_phi)} %"
            f"{dte_txt} of {p} = {finest}{cheap_txt}."
        )
    out += [
        "",
        "The defaults (32 positions, 129 nodes, 64 steps) keep every resolution error of Φ̄ well under "
        "the 5 % that `Fidelity.auto` is usually asked for while costing a fraction of the fine level; "
        "the coarse level is the cheaper choice wherever the table shows its error to be small enough "
        "(and `Fidelity.auto` takes it there).",
    ]
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="reduced scenario set and levels")
    ap.add_argument("--cache", type=Path, default=None, help="JSON cache of finished points")
    ap.add_argument("--json", type=Path, default=DEFAULT_JSON, help="measured-error table out")
    ap.add_argument("--figure", type=Path, default=DEFAULT_FIGURE, help="Pareto plot out (PNG)")
    ap.add_argument(
        "--smoke",
        action="store_true",
        help="pipeline check: formula rungs only, quick scenarios; writes no RESULTS.md section",
    )
    ap.add_argument(
        "--seed-from-table",
        type=Path,
        default=None,
        help="pre-fill the cache with the points of an earlier measured-error table (its rungs and "
        "reference), so that only rungs it lacks and the convergence studies run; their run times "
        "then come from that table's run (its machine and date are kept in the report)",
    )
    args = ap.parse_args(argv)
    quick = args.quick or args.smoke
    physics_set = FORMULA_PHYSICS if args.smoke else FORMULA_PHYSICS + EHL_PHYSICS
    t_start = time.perf_counter()
    pair = jg.presets.li2015_pair_calibrated()
    runner = Runner(pair, args.cache)
    if args.seed_from_table is not None:
        runner.seed(json.loads(args.seed_from_table.read_text()))
    scenarios = [s for s in SCENARIOS if s.quick or not quick]
    scen = {s.name: s for s in SCENARIOS}
    ehl_levels = ("coarse", "default") if quick else ("coarse", "default", "fine")
    reference_level = "default" if quick else "fine"
    probe = scen["base_2500"]

    ref_fid, ref_label, is_paper, ref_note = choose_reference(
        runner, probe, reference_level, physics_set
    )
    print(f"reference: {ref_label}\n  {ref_note}", flush=True)
    ref_results = {s.name: runner.point(ref_fid, s) for s in scenarios}

    # Every rung × level; the ones that do not trace are listed, not run.
    rungs = []
    for physics in sorted(physics_set, key=_rank):
        d, f, th, tr = physics
        levels = ehl_levels if jg.Fidelity(friction=f).uses_ehl else tuple(LEVELS)
        why = None
        for level in levels:
            fid = jg.Fidelity(dynamics=d, friction=f, thermal=th, transient=tr, **LEVELS[level])
            why = why or runner.available(fid, probe)
            rung = {
                "label": f"{physics_label(physics)}@{level}",
                "dynamics": d,
                "friction": f,
                "thermal": th,
                "transient": tr,
                "level": level,
                "fidelity": fidelity_fields(fid),
                "available": why is None,
                "is_reference": fidelity_fields(fid) == fidelity_fields(ref_fid),
                "results": {},
                "errors": {},
            }
            if why is not None:
                rung["unavailable_reason"] = why
            rungs.append(rung)
    # Cheapest first, so a long run has the informative cheap rungs early.
    order = {f: i for i, f in enumerate(AXIS_ORDER["friction"])}
    todo = sorted(
        (r for r in rungs if r["available"]),
        key=lambda r: (
            order[r["friction"]],
            r["dynamics"] != "quasi_static",
            r["level"] != "coarse",
        ),
    )
    for r in todo:
        fid = jg.Fidelity(**r["fidelity"])
        print(f"rung {r['label']}", flush=True)
        for s in scenarios:
            r["results"][s.name] = runner.point(fid, s)
        r["compile_s"] = runner.compile_seconds(fid)
    for r in rungs:
        r.setdefault("compile_s", None)

    print("convergence studies", flush=True)
    studies = convergence(runner, quick, scen, smoke=args.smoke)

    # Errors against the reference where the reference converged.
    scen_table = {}
    for s in scenarios:
        pair_, lub, surf, op = s.inputs(pair)
        ind = scenario_indicators(pair_, lub, surf, op)
        rr = ref_results[s.name]
        scen_table[s.name] = {
            "torque": s.torque,
            "speed_rpm": s.speed_rpm,
            "inlet_temperature_C": s.inlet_c,
            "surfaces": s.surfaces,
            "note": s.note,
            "indicators": ind.as_dict(),
            "reference_result": rr,
            "reference_converged": rr["status"] == 0,
        }
    good = [n for n, s in scen_table.items() if s["reference_converged"]]
    for r in rungs:
        for n in good:
            if n in r["results"]:
                r["errors"][n] = relative_errors(r["results"][n], ref_results[n])
        r["summary"] = rung_summary(r, good) if r["available"] else None
    ref_runs = [ref_results[n]["run_s"] for n in good]
    reference = {
        "label": ref_label,
        "paper": is_paper,
        "note": ref_note,
        "level": None if is_paper else reference_level,
        "fidelity": fidelity_fields(ref_fid),
        "compile_s": runner.compile_seconds(ref_fid),
        "summary_run_s": statistics.median(ref_runs) if ref_runs else float("nan"),
    }
    table = {
        "schema": "jaxgear.fidelity_errors/1",
        "indicator_version": INDICATOR_VERSION,
        "generated": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": machine(),
        "load_average": " ".join(f"{x:.1f}" for x in os.getloadavg()),
        "mode": "quick" if quick else "full",
        "pair": "li2015_pair_calibrated",
        "lubricant": "mil_l_23699",
        "quantities": list(QUANTITIES),
        "error_definition": "relative: |x - x_ref| / |x_ref| (efficiency too)",
        "levels": LEVELS,
        "anchor_level": ehl_levels[-1] if is_paper else reference_level,
        "reference": reference,
        "scenarios": scen_table,
        "rungs": rungs,
        "convergence": studies,
        "seeded_from": getattr(runner, "seeded_from", None),
    }
    table["defaults_justification"] = justify_defaults(studies, table)
    pareto_plot(rungs, reference, args.figure)
    wall = time.perf_counter() - t_start
    text = write_report(table, studies, args.figure, wall, quick, write=not args.smoke)
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(_json_safe(table), indent=1) + "\n")
    print(text)
    written = "" if args.smoke else ", benchmarks/RESULTS.md"
    print(f"wrote {args.json}, {args.figure}{written} ({wall / 60:.1f} min)")
    return 0


def _json_safe(x):
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _json_safe(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_json_safe(v) for v in x]
    return x


if __name__ == "__main__":
    sys.exit(main())
