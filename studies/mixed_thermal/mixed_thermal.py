"""Benchmark of the thermal mixed EHL solve: what each switch costs per contact, and the
transient passage per step and per engagement.

Contacts: the paper's pitch-point contact carrying the whole 700 N m load (ph ≈ 1.19 GPa), slide-to-roll
ratio 0.3, at 500 and 3500 rpm, ground surfaces. Compile (first call) and run (median of repeats)
are timed separately. This default run is the performance benchmark: it writes the
``mixed_thermal`` section of benchmarks/RESULTS.md. The options below are the study: each writes its
section of studies/mixed_thermal/README.md.

Run: ``python studies/mixed_thermal/mixed_thermal.py [--repeats 3] [--steps 40]``

``--engagement``: one whole engagement actually marched (not extrapolated from a few steps): the
~900 grid-tied steps of the smooth, statistical thermal and deterministic passages at 500 and
3500 rpm, with the memory XLA reserves for the compiled passage (arguments, outputs,
temporaries) and the process's peak resident memory; the deterministic passage runs along the
path only (the pitch-point contact held costs as much a step).
Writes the ``mixed_engagement`` section.

``--engagement-grid``: the deterministic passage's engagement (iso-thermal, along the path) on
each grid of ``--nodes``, the time step tied to each grid (Δt = Δx/ur: twice the steps on twice the
nodes), at 500 and 3500 rpm: how its cost and loss move towards the issue's Δx ≤ 1 µm. Writes the
``mixed_engagement_grid`` section.

``--held-steps K [--thermal] [--polished] [--krylov] [--sweeps S] [--rows FILE]``: the
deterministic passage's cost a step on each grid of ``--nodes`` (K steps of the held pitch-point
contact, 3500 rpm, iso-thermal or with ``--thermal`` the thermal passage; ``--polished``: the
polished surfaces filtered at λs = 2.5 µm, a full film; ``--krylov``: GMRES Newton directions
instead of the dense LU; ``--sweeps``: the warm starts' relaxation sweeps), and the engagement it
implies, where the whole engagement is out of reach (2049 nodes: Δx 0.78 µm, the issue's ≤ 1 µm).
``--rows`` keeps the rows of all these passages in one table across runs. Writes the
``mixed_held_steps`` section.

``--engagement-fine [--rpm R ...] [--sweeps S] [--time-scheme S] [--transport T] [--courant C]
[--tolerance T] [--thermal] [--rows FILE]``:
one whole engagement of the polished film (λs 2.5 µm) along the path on each grid of ``--nodes``
with ``EHLModel(linear_solver="krylov")``, by backward Euler or BDF2 (Eulerian or along the
characteristics) at Δt = C Δx/ur, marched, not extrapolated. Writes the ``mixed_engagement_fine`` section.

``--engagement-transport [--rows FILE]``: one engagement along the path (257 nodes, ground,
Δt = Δx/ur) of the deterministic film, iso-thermal and thermal, with the Eulerian transport
(backward Euler, as ``--engagement``) and along the characteristics (BDF2,
``EHLModel.transport``), beside the statistical film's, at 500 and 3500 rpm: cost, converged
steps, and the loss split into sliding, asperity and rolling parts. Writes the
``mixed_engagement_transport`` section.

``--film-transport [--rows FILE]``: the smooth and statistical (ground) thermal engagements
along the path (257 nodes, Δt = Δx/ur) by backward Euler and BDF2 with the Eulerian transport
and by BDF2 along the characteristics: cost, loss split, peak pressure and mid-engagement h_min.
Writes the ``mixed_film_transport`` section.

``--passage-iterations``: where the deterministic passage spends its time: the Newton iterations
of each step (all attempts) with the warm-start budget of the default model (12) and with 60, at
500 and 3500 rpm on 257 nodes; writes the ``mixed_passage_iterations`` section.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
README = Path(__file__).with_name("README.md")  # this study's sections
sys.path.insert(0, str(ROOT / "benchmarks"))  # _report
sys.path.insert(0, str(Path(__file__).parents[2] / "tests"))

from _report import (  # noqa: E402
    RESULTS,
    ROWS_HELP,
    RowCache,
    compile_then_run,
    machine,
    time_call,
    write_section,
)
from helpers import gear_contact  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.lubrication.passage import grid_time_step, solve_ehl_passage  # noqa: E402

LUB = jg.presets.mil_l_23699()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--steps", type=int, default=40, help="passage steps timed")
    ap.add_argument("--nodes", type=int, nargs="+", default=[257, 513], help="grid sizes")
    ap.add_argument(
        "--passage-iterations",
        action="store_true",
        help="per-step Newton iterations of the deterministic passage",
    )
    ap.add_argument(
        "--engagement",
        action="store_true",
        help="one whole engagement marched, with its memory",
    )
    ap.add_argument(
        "--engagement-grid",
        action="store_true",
        help="the deterministic engagement on each grid of --nodes",
    )
    ap.add_argument(
        "--held-steps",
        type=int,
        default=0,
        help="the deterministic passage's cost a step on each grid of --nodes (this many steps "
        "of the held pitch-point contact at 3500 rpm; iso-thermal unless --thermal)",
    )
    ap.add_argument(
        "--thermal",
        action="store_true",
        help="with --held-steps or --engagement-fine: the thermal deterministic passage instead of "
        "the iso-thermal",
    )
    ap.add_argument(
        "--polished",
        action="store_true",
        help="with --held-steps: the polished surfaces filtered at the stylus cutoff λs = 2.5 µm "
        "(a full film) instead of the ground ones",
    )
    ap.add_argument(
        "--engagement-transport",
        action="store_true",
        help="the ground engagement along the path, Eulerian and along the characteristics "
        "(--rows)",
    )
    ap.add_argument(
        "--film-transport",
        action="store_true",
        help="the smooth and statistical thermal engagements along the path under each time "
        "scheme and transport (--rows)",
    )
    ap.add_argument(
        "--engagement-fine",
        action="store_true",
        help="one polished engagement on each grid of --nodes with the Krylov directions "
        "(--sweeps; --rpm)",
    )
    ap.add_argument("--rpm", type=float, nargs="+", default=[3500.0], help="--engagement-fine")
    ap.add_argument(
        "--krylov",
        action="store_true",
        help='with --held-steps: EHLModel(linear_solver="krylov"), GMRES Newton directions on '
        "grids from 1025 nodes instead of the dense LU",
    )
    ap.add_argument(
        "--sweeps",
        type=int,
        default=None,
        help="with --held-steps: EHLModel.relaxation_sweeps (default: the model's)",
    )
    ap.add_argument(
        "--time-scheme",
        default="backward_euler",
        help="with --engagement-fine: EHLModel.time_scheme (backward_euler, bdf2)",
    )
    ap.add_argument(
        "--transport",
        default="eulerian",
        help="with --engagement-fine: EHLModel.transport (eulerian, characteristic)",
    )
    ap.add_argument(
        "--courant",
        type=float,
        default=1.0,
        help="with --engagement-fine: the time step Δt = C Δx/ur (C = 1: one cell a step)",
    )
    ap.add_argument(
        "--tolerance",
        type=float,
        default=1e-9,
        help="with --engagement-fine: EHLModel.tolerance, the Newton solves' ‖F‖∞",
    )
    ap.add_argument(
        "--rows",
        type=Path,
        help=ROWS_HELP
        + " (--held-steps, --engagement-fine, --engagement-transport, --film-transport)",
    )
    args = ap.parse_args(argv)
    if args.engagement:
        return engagement()
    if args.engagement_grid:
        return engagement_grid(args.nodes)
    if args.engagement_transport:
        return engagement_transport(RowCache(args.rows))
    if args.film_transport:
        return film_transport(RowCache(args.rows))
    if args.engagement_fine:
        return engagement_fine(
            args.nodes,
            args.rpm,
            RowCache(args.rows),
            args.sweeps,
            args.time_scheme,
            args.courant,
            args.tolerance,
            args.transport,
            args.thermal,
        )
    if args.held_steps:
        return held_steps(
            args.nodes,
            args.held_steps,
            args.thermal,
            RowCache(args.rows),
            args.polished,
            args.krylov,
            args.sweeps,
        )
    if args.passage_iterations:
        return passage_iterations(args.steps)
    surf = jg.presets.ground()
    rows = []
    cases = [
        ("smooth, iso-thermal", dict(), None),
        ("smooth, thermal", dict(thermal=True), None),
        ("statistical mixed, iso-thermal", dict(mixed="statistical"), surf),
        ("statistical mixed, thermal", dict(mixed="statistical", thermal=True), surf),
        ("deterministic mixed, iso-thermal", dict(mixed="deterministic"), surf),
    ]
    for n in args.nodes:
        for label, kw, s in cases:
            model = jg.EHLModel(n_nodes=n, **kw)
            for rpm in (500.0, 3500.0):
                c = gear_contact(rpm=rpm)
                fn = lambda c, model=model, s=s: jg.solve_ehl(c, LUB, model, s)  # noqa: E731
                first, run = time_call(fn, c, repeats=args.repeats)
                sol = fn(c)
                rows.append(
                    f"| {n} | {label} | {rpm:.0f} | {first:.1f} | {run * 1e3:.0f} | "
                    f"{bool(sol.converged)} | {int(sol.iterations)} | "
                    f"{float(sol.power_loss) * 0.02:.1f} | {float(sol.contact_load_share):.3f} |"
                )
                print(rows[-1], flush=True)
    # transient passage: per step, and extrapolated to one engagement (Δt = Δx/ur)
    prow = []
    for rpm in (500.0, 3500.0):
        for label, kw, s in cases[1:4:2] + cases[4:]:
            model = jg.EHLModel(n_nodes=257, **kw)
            c = gear_contact(rpm=rpm)
            dt = float(grid_time_step(c, LUB, model))
            k = args.steps
            contacts = jax.tree_util.tree_map(lambda a, k=k: jnp.full((k,), a), c)
            times = jnp.arange(k) * dt
            fn = lambda cs, t, model=model, s=s: solve_ehl_passage(  # noqa: E731
                cs, LUB, model, s, times=t
            )
            first, run = time_call(fn, contacts, times, repeats=1)
            # one engagement of the paper's pair: the contact crosses the 15.5 mm path of contact
            # while each surface rolls ~5.6 mm through it (ur = ω L/2 < rb ω); until 11-26 this
            # took 15 mm of rolling, 2.7× too many steps
            steps_engagement = _path_contacts(rpm, model)[1].shape[0]
            prow.append(
                f"| {label} | {rpm:.0f} | {first:.0f} | {run / k * 1e3:.0f} | "
                f"{steps_engagement:.0f} | {run / k * steps_engagement:.0f} |"
            )
            print(prow[-1], flush=True)
    body = "\n".join(
        [
            "## Thermal mixed EHL: what each switch costs a contact "
            "(`studies/mixed_thermal/mixed_thermal.py`)",
            "",
            f"Machine: {machine()}. Pitch-point contact, 700 N m, SRR 0.3, ground surfaces.",
            "Loss is per contact over the 20 mm face width.",
            "",
            "| nodes | model | rpm | compile+first, s | run, ms | converged | Newton its | "
            "loss, W | contact load share |",
            "|---|---|---|---|---|---|---|---|---|",
            *rows,
            "",
            f"Transient passage, 257 nodes, {args.steps} steps timed (Δt = Δx/ur); one engagement "
            "extrapolated from them (its steps: the 15.5 mm path of contact crossed at "
            "rb ω1 while the surfaces roll ~5.6 mm at ur):",
            "",
            "| model | rpm | compile+first, s | per step, ms | steps per engagement | "
            "engagement, s |",
            "|---|---|---|---|---|---|",
            *prow,
        ]
    )
    write_section("mixed_thermal", body, RESULTS)  # a benchmark: benchmarks/RESULTS.md


def _mib(nbytes):
    return nbytes / 2**20


def _path_contacts(rpm, model, courant=1.0, torque=700.0):
    """The contact states of one tooth pair's whole engagement on the paper's calibrated pair
    (``torque``, 700 N m by default, 90 °C), quasi-static load sharing, at the time steps
    Δt = C Δx/ur of the pitch-point contact (C = ``courant``): (contacts, times, Δt)."""
    import numpy as np

    from jaxgear.material import reduced_modulus

    pair = jg.presets.li2015_pair_calibrated()
    m = 256
    mc = jg.mesh_cycle(pair, torque, n_positions=m)
    geo = jg.gear_geometry(pair)
    # slot 0 over one mesh period, then slot 1 over the next: one pair's engagement
    seq = lambda a: np.concatenate([np.asarray(a)[:, 0], np.asarray(a)[:, 1]])  # noqa: E731
    s_path, w_path, on = seq(mc.contact_position), seq(mc.normal_load), seq(mc.in_contact)
    # the loaded part (the smoothed contact edges carry no load at their ends)
    keep = (on > 0.5) & (w_path > 0.01 * w_path.max())
    s_path, w_path = s_path[keep], w_path[keep]
    omega1 = rpm * 2.0 * np.pi / 60.0
    t_path = (s_path - s_path[0]) / (float(geo.base_radius[0]) * omega1)
    dt = courant * float(grid_time_step(gear_contact(rpm=rpm), LUB, model))
    times = np.arange(0.0, t_path[-1], dt)
    s_t = np.interp(times, t_path, s_path)
    kin = jg.kinematics(pair, geo, jnp.asarray(s_t), omega1)
    rho1, rho2 = s_t, float(geo.line_of_action_length) - s_t
    k = times.shape[0]
    contacts = jg.LineContact(
        reduced_radius=jnp.asarray(rho1 * rho2 / (rho1 + rho2)),
        load_per_width=jnp.asarray(np.interp(times, t_path, w_path) / float(pair.face_width)),
        u1=kin.u1,
        u2=kin.u2,
        e_reduced=jnp.full((k,), float(reduced_modulus(*pair.materials))),
        inlet_temperature=jnp.full((k,), 363.15),
    )
    return contacts, jnp.asarray(times), dt


def engagement():
    """One engagement marched step by step (Δt = Δx/ur of the pitch-point contact, for the time
    the contact takes to cross the path of contact), 257 nodes: run time of the compiled passage,
    and its memory (XLA's buffer sizes of the compiled program; the process's peak resident set,
    compilation included)."""
    import resource
    import time

    surf = jg.presets.ground()
    cases = [
        ("smooth, thermal", dict(thermal=True), None, True),
        ("statistical mixed, thermal", dict(mixed="statistical", thermal=True), surf, True),
        ("deterministic mixed, iso-thermal", dict(mixed="deterministic"), surf, False),
        ("deterministic mixed, thermal", dict(mixed="deterministic", thermal=True), surf, False),
    ]
    rows = []
    path_cases = [(f"{label}, along the path", kw, s, True) for label, kw, s, _ in cases]
    for rpm in (500.0, 3500.0):
        for label, kw, s, run_it in cases + path_cases:
            model = jg.EHLModel(n_nodes=257, **kw)
            if label.endswith("along the path"):
                contacts, times, dt = _path_contacts(rpm, model)
                k = times.shape[0]
            else:
                # the pitch-point contact held for as many steps as one engagement takes
                c = gear_contact(rpm=rpm)
                _, path_times, dt = _path_contacts(rpm, model)
                k = path_times.shape[0]
                contacts = jax.tree_util.tree_map(lambda a, k=k: jnp.full((k,), a), c)
                times = jnp.arange(k) * dt
            fn = jax.jit(
                lambda cs, t, model=model, s=s: solve_ehl_passage(cs, LUB, model, s, times=t)
            )
            t0 = time.perf_counter()
            compiled = fn.lower(contacts, times).compile()
            t_compile = time.perf_counter() - t0
            mem = compiled.memory_analysis()
            arg, out = mem.argument_size_in_bytes, mem.output_size_in_bytes
            temp = mem.temp_size_in_bytes
            if run_it:
                t0 = time.perf_counter()
                sols = jax.block_until_ready(compiled(contacts, times))
                t_run = time.perf_counter() - t0
                conv = int(jnp.sum(sols.converged))
                # over the converged steps: a failed step reports its (meaningless) values with
                # converged = False
                ok = sols.converged
                loss = float(jnp.sum(jnp.where(ok, sols.power_loss, 0.0)) / jnp.sum(ok)) * 0.02
                bad = [int(i) for i in jnp.nonzero(~ok)[0]]
                print(label, rpm, "not converged at steps", bad[:5], "…" if len(bad) > 5 else "")
                run = f"{t_run:.1f} | {t_run / k * 1e3:.1f} | {conv} of {k} | {loss:.1f}"
            else:
                run = "– | – | – | –"
            peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # KiB → MiB
            rows.append(
                f"| {label} | {rpm:.0f} | {k} | {t_compile:.0f} | {run} | {_mib(arg):.2f} | "
                f"{_mib(out):.1f} | {_mib(temp):.1f} | {peak:.0f} |"
            )
            print(rows[-1], flush=True)
    body = "\n".join(
        [
            "## One whole engagement, marched, and its memory (`--engagement`)",
            "",
            f"Machine: {machine()}. Pitch-point contact, 700 N m, SRR 0.3, ground surfaces, 257 "
            "nodes, Δt = Δx/ur of the pitch-point contact for the time the contact takes to cross "
            "the 15.5 mm path of contact (each surface rolls ~5.6 mm through it): the pitch-point "
            "contact held that long, and the states along the path (quasi-static load sharing of "
            "the calibrated pair, radii and surface velocities of each position). Memory: what "
            "XLA reserves for the compiled passage (arguments, "
            "outputs: every step's solution, and temporaries), and the process's peak resident set "
            "since it started (compilation and the earlier rows included, so it only grows down "
            "the table). Loss: the mean over the converged steps, per contact over the 20 mm face "
            "width.",
            "",
            "| model | rpm | steps | compile, s | run, s | per step, ms | converged | loss, W | "
            "arguments, MiB | outputs, MiB | temporaries, MiB | peak RSS, MiB |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("mixed_engagement", body, README)


def _converged_mean(sols, ok, field):
    """A passage's ``field`` averaged over its converged steps, × the 20 mm face width (W per
    contact for a loss per width)."""
    import numpy as np

    return float(np.sum(np.where(ok, getattr(sols, field), 0.0)) / max(ok.sum(), 1)) * 0.02


def _march_path(model, rpm, surf, courant=1.0):
    """One engagement along the path (``_path_contacts``) with ``model``, compiled then run:
    (steps, compile s, run s, solutions, converged, iterations, mean loss over the converged
    steps in W over the 20 mm face width, x at mid-engagement)."""

    import numpy as np

    contacts, times, _ = _path_contacts(rpm, model, courant)
    k = times.shape[0]
    sols, t_compile, t_run = compile_then_run(
        lambda cs, t: solve_ehl_passage(cs, LUB, model, surf, times=t), contacts, times
    )
    ok = np.asarray(sols.converged)
    loss = _converged_mean(sols, ok, "power_loss")
    return (
        k,
        t_compile,
        t_run,
        sols,
        ok,
        np.asarray(sols.iterations),
        loss,
        np.asarray(sols.x[k // 2]),
    )


def engagement_grid(sizes):
    """The deterministic passage along the path (iso-thermal, ground, 700 N m) on each grid:
    compile and run time, converged steps, Newton iterations (all attempts, summed over the
    steps) and the mean loss over the converged steps."""
    surf = jg.presets.ground()
    rows = []
    for rpm in (3500.0, 500.0):
        for n in sizes:
            model = jg.EHLModel(n_nodes=n, mixed="deterministic")
            k, t_compile, t_run, sols, ok, its, loss, x_mid = _march_path(model, rpm, surf)
            rows.append(
                f"| {n} | {(x_mid[1] - x_mid[0]) * 1e6:.2f} | {rpm:.0f} | {k} | {t_compile:.0f} | {t_run:.1f} | "
                f"{t_run / k * 1e3:.0f} | {int(ok.sum())} of {k} | {int(its.sum())} | "
                f"{t_run / its.sum() * 1e3:.2f} | {loss:.0f} |"
            )
            print(rows[-1], flush=True)
    body = "\n".join(
        [
            "## The deterministic engagement on finer grids (`--engagement-grid`)",
            "",
            f"Machine: {machine()}. One engagement along the path of contact (as "
            "`mixed_engagement`), ground, 700 N m, iso-thermal, the default `EHLModel` "
            "(deterministic) on each grid; Δt = Δx/ur of the pitch-point contact, so a grid with "
            "twice the nodes marches twice the steps. Newton iterations: all attempts of all steps. "
            "Loss: the mean over the converged steps, per contact over the 20 mm face width.",
            "",
            "| nodes | Δx mid-engagement, µm | rpm | steps | compile, s | run, s | per step, ms | "
            "converged | Newton its | per iteration, ms | loss, W |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("mixed_engagement_grid", body, README)


def engagement_transport(cache):
    """The ground engagement along the path (257 nodes, Δt = Δx/ur, 700 N m) of the deterministic
    film with the Eulerian transport and along the characteristics, iso-thermal and thermal, and
    the statistical film (thermal) beside them: cost and the loss split. Rows kept in ``cache``."""

    surf = jg.presets.ground()
    cases = (
        ("statistical, thermal", dict(mixed="statistical", thermal=True)),
        ("deterministic, iso-thermal, Eulerian (backward Euler)", dict(mixed="deterministic")),
        (
            "deterministic, iso-thermal, characteristic (BDF2)",
            dict(mixed="deterministic", transport="characteristic", time_scheme="bdf2"),
        ),
        (
            "deterministic, thermal, Eulerian (backward Euler)",
            dict(mixed="deterministic", thermal=True),
        ),
        (
            "deterministic, thermal, characteristic (BDF2)",
            dict(
                mixed="deterministic", thermal=True, transport="characteristic", time_scheme="bdf2"
            ),
        ),
    )

    def measure(label, kw, rpm):
        model = jg.EHLModel(n_nodes=257, **kw)
        k, t_compile, t_run, sols, ok, its, loss, _ = _march_path(model, rpm, surf)

        def mean(field):
            return _converged_mean(sols, ok, field)

        asperity = mean("power_loss_asperity")
        fluid = mean("power_loss_sliding") - asperity
        row = (
            f"| {label} | {rpm:.0f} | {k} | {t_compile:.0f} | {t_run:.1f} | "
            f"{int(ok.sum())} of {k} | {its[1:].mean():.1f} | {loss:.0f} | {fluid:.0f} | "
            f"{asperity:.0f} | {mean('power_loss_rolling'):.0f} |"
        )
        print(row, flush=True)
        return row

    rows = []
    for rpm in (3500.0, 500.0):
        for label, kw in cases:
            key = f"{label} {rpm:.0f}"
            rows.append(cache.get(key, lambda label=label, kw=kw, rpm=rpm: measure(label, kw, rpm)))
    body = "\n".join(
        [
            "## The ground engagement along the characteristics (`--engagement-transport`)",
            "",
            f"Machine: {machine()}. One engagement along the path of contact (as "
            "`mixed_engagement`: ground, 700 N m, 257 nodes, Δt = Δx/ur of the pitch-point "
            "contact), the deterministic film with the Eulerian transport (the default, backward "
            'Euler) and along the characteristics (`EHLModel(transport="characteristic", '
            'time_scheme="bdf2")`), and the statistical film (the contact model of '
            "`Fidelity.paper()`). "
            "Its: Newton iterations a step (all attempts, steps 2…). Losses: means over the "
            "converged steps, per contact over the 20 mm face width: the total and its fluid "
            "sliding, asperity (boundary friction) and rolling (Poiseuille) parts.",
            "",
            "| film | rpm | steps | compile, s | run, s | converged | its a step | loss, W | "
            "fluid sliding, W | asperity, W | rolling, W |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("mixed_engagement_transport", body, README)


def film_transport(cache):
    """The smooth and statistical (ground) thermal engagements along the path (257 nodes,
    Δt = Δx/ur, 700 N m) under backward Euler and BDF2 with the Eulerian transport and BDF2 along
    the characteristics: whether the transport that moves a deterministic film's loss several-fold
    moves these films, the ones the coupled model's contacts use. Rows kept in ``cache``."""
    import numpy as np

    schemes = (
        ("Eulerian, backward Euler", {}),
        ("Eulerian, BDF2", dict(time_scheme="bdf2")),
        ("characteristic, BDF2", dict(transport="characteristic", time_scheme="bdf2")),
    )
    films = (
        ("smooth", None, {}),
        ("statistical (ground)", jg.presets.ground(), dict(mixed="statistical")),
    )

    def measure(film, surf, kw, scheme, rpm):
        model = jg.EHLModel(n_nodes=257, thermal=True, **kw)
        k, t_compile, t_run, sols, ok, its, loss, _ = _march_path(model, rpm, surf)

        def mean(field):
            return _converged_mean(sols, ok, field)

        peak = float(np.max(np.where(ok, sols.p_max, 0.0))) / 1e9
        row = (
            f"| {film} | {scheme} | {rpm:.0f} | {t_compile:.0f} | {t_run:.1f} | "
            f"{int(ok.sum())} of {k} | {its[1:].mean():.2f} | {loss:.2f} | "
            f"{mean('power_loss_sliding'):.2f} | {mean('power_loss_rolling'):.2f} | "
            f"{peak:.3f} | {float(sols.h_min[k // 2]) * 1e9:.1f} |"
        )
        print(row, flush=True)
        return row

    rows = []
    for rpm in (3500.0, 500.0):
        for film, surf, kw in films:
            for scheme, extra in schemes:
                key = f"{film} {scheme} {rpm:.0f}"
                rows.append(
                    cache.get(
                        key,
                        lambda film=film, surf=surf, kw={**kw, **extra}, scheme=scheme, rpm=rpm: (
                            measure(film, surf, kw, scheme, rpm)
                        ),
                    )
                )
    body = "\n".join(
        [
            "## Smooth and statistical films under each transport (`--film-transport`)",
            "",
            f"Machine: {machine()}. One thermal engagement along the path of contact (as "
            "`mixed_engagement`: 700 N m, 257 nodes, Δt = Δx/ur of the pitch-point contact) of "
            "the smooth film and of the statistical mixed film (ground; the contact model of "
            "`Fidelity.paper()`), by backward Euler and BDF2 with the Eulerian transport and by "
            'BDF2 along the characteristics (`EHLModel(transport="characteristic")`). Its: '
            "Newton iterations a step (all attempts, steps 2…). Losses: means over the converged "
            "steps, per contact over the 20 mm face width. Peak p: the largest over the "
            "engagement; h_min: at mid-engagement.",
            "",
            "| film | transport, scheme | rpm | compile, s | run, s | converged | its a step | "
            "loss, W | sliding, W | rolling, W | peak p, GPa | h_min, nm |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("mixed_film_transport", body, README)


def engagement_fine(
    sizes,
    rpms,
    cache,
    sweeps=None,
    scheme="backward_euler",
    courant=1.0,
    tolerance=1e-9,
    transport="eulerian",
    thermal=False,
):
    """One whole engagement of the polished film (λs 2.5 µm, iso-thermal, 700 N m) marched along
    the path on the grids the roughness needs, with the Krylov Newton directions (and ``sweeps``
    relaxation sweeps), by ``scheme`` (``EHLModel.time_scheme``) at Δt = ``courant`` Δx/ur, the
    Newton solves to ``tolerance``: measured, not extrapolated from held steps. Rows kept in
    ``cache``."""

    import numpy as np

    from jaxgear.paper import field_surfaces

    surf = field_surfaces("polished")

    def measure(n, rpm):
        kw = {} if sweeps is None else {"relaxation_sweeps": sweeps}
        model = jg.EHLModel(
            n_nodes=n,
            mixed="deterministic",
            linear_solver="krylov",
            time_scheme=scheme,
            tolerance=tolerance,
            transport=transport,
            thermal=thermal,
            **kw,
        )
        k, t_compile, t_run, sols, ok, its, loss, x_mid = _march_path(model, rpm, surf, courant)
        row = (
            f"| {n} | {(x_mid[1] - x_mid[0]) * 1e6:.2f} | {rpm:.0f} | "
            f"{'default' if sweeps is None else sweeps} | {scheme.replace('_', ' ')}"
            f"{'' if transport == 'eulerian' else ', ' + transport}"
            f"{', thermal' if thermal else ''} | "
            f"{courant:g} | {tolerance:g} | {k} | {t_compile:.0f} | {t_run:.0f} | "
            f"{t_run / k * 1e3:.0f} | {int(ok.sum())} of {k} | {its[1:].mean():.1f} | "
            f"{float(np.max(np.asarray(sols.p))) / 1e9:.2f} | {loss:.0f} |"
        )
        print(row, flush=True)
        return row

    for rpm in rpms:
        for n in sizes:
            # rows of backward Euler at Δx/ur keep the keys they were measured under
            key = f"{n} {rpm:.0f} {sweeps}"
            key += "" if (scheme, courant) == ("backward_euler", 1.0) else f" {scheme} {courant:g}"
            key += "" if tolerance == 1e-9 else f" tol {tolerance:g}"
            key += "" if transport == "eulerian" else f" {transport}"
            key += " thermal" if thermal else ""
            cache.get(key, lambda n=n, rpm=rpm: measure(n, rpm))
    rows = list(cache.saved.values())
    body = "\n".join(
        [
            "## The polished engagement on the issue's grid, Krylov directions "
            "(`--engagement-fine`)",
            "",
            f"Machine: {machine()}. One engagement along the path of contact (as "
            "`mixed_engagement`), polished surfaces filtered at λs = 2.5 µm (a full film), 700 N m, "
            "iso-thermal unless marked thermal, "
            '`EHLModel(mixed="deterministic", linear_solver="krylov")` with the '
            "warm starts' relaxation sweeps, the time scheme and the Newton tolerance given; "
            "Δt = C Δx/ur of the pitch-point contact. Its: "
            "Newton iterations a step (all attempts, steps 2…). Loss: the mean over the converged "
            "steps, over the 20 mm face width.",
            "",
            "| nodes | Δx mid-engagement, µm | rpm | sweeps | scheme | C | tolerance | steps | "
            "compile, s | run, s | per step, ms | converged | its a step | max p, GPa | loss, W |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("mixed_engagement_fine", body, README)


def held_steps(sizes, k, thermal, cache, polished=False, krylov=False, sweeps=None):
    """The deterministic passage's cost a step on finer grids, where a whole engagement is out of
    reach: k steps of the held pitch-point contact (3500 rpm, iso-thermal or thermal, Δt = Δx/ur),
    the compiled passage called twice; the time of a step from the second call's time per Newton
    iteration and each step's iterations (the first, steady, solve left out). Rows kept in
    ``cache`` (``--rows``) so that iso-thermal and thermal runs share one table. ``polished``: the
    polished surfaces filtered at λs = 2.5 µm (a full film) instead of the ground ones. ``krylov``:
    the GMRES Newton directions (``EHLModel.linear_solver``); ``sweeps``: the relaxation sweeps of
    each warm start (None: the model's default)."""
    label = "thermal" if thermal else "iso-thermal"
    label += ", polished (λs 2.5 µm)" if polished else ""
    label += ", Krylov" if krylov else ""
    label += f", {sweeps} sweeps" if sweeps is not None else ""
    group = int(thermal) + (2 if polished else 0) + (4 if krylov else 0)
    group += 0 if sweeps is None else 8 * (sweeps + 1)
    kw = {"linear_solver": "krylov"} if krylov else {}
    kw |= {} if sweeps is None else {"relaxation_sweeps": sweeps}
    for n in sizes:
        cache.get(f"{group} {n}", lambda n=n: _held_row(n, k, thermal, label, polished, **kw))
    rows = [
        cache.saved[key] for key in sorted(cache.saved, key=lambda s: tuple(map(int, s.split())))
    ]
    _write_held(rows, k)


def _held_row(n, k, thermal, label, polished=False, **model_options):
    import time

    import numpy as np

    from jaxgear.paper import field_surfaces  # λs = 2.5 µm, the figures' stylus cutoff

    model = jg.EHLModel(n_nodes=n, mixed="deterministic", thermal=thermal, **model_options)
    c = gear_contact(rpm=3500.0)
    dt = float(grid_time_step(c, LUB, model))
    contacts = jax.tree_util.tree_map(lambda a, k=k: jnp.full((k,), a), c)
    times = jnp.arange(k) * dt
    surf = field_surfaces("polished") if polished else jg.presets.ground()
    fn = jax.jit(lambda cs, t, model=model: solve_ehl_passage(cs, LUB, model, surf, times=t))
    t0 = time.perf_counter()
    jax.block_until_ready(fn(contacts, times).p)
    first = time.perf_counter() - t0
    t0 = time.perf_counter()
    sol = fn(contacts, times * (1.0 + 1e-7))
    jax.block_until_ready(sol.p)
    run = time.perf_counter() - t0
    its = np.asarray(sol.iterations)
    per_it = run / its.sum()
    per_step = per_it * its[1:].mean()
    steps = _path_contacts(3500.0, model)[1].shape[0]
    dx = float(sol.x[0, 1] - sol.x[0, 0])
    row = (
        f"| {label} | {n} | {dx * 1e6:.2f} | {first - run:.0f} | {int(its[0])} | "
        f"{its[1:].mean():.0f} | {per_it * 1e3:.1f} | {per_step:.2f} | "
        f"{int(np.sum(np.asarray(sol.converged)))} of {k} | {steps} | "
        f"{per_step * steps / 3600.0:.2f} |"
    )
    print(row, flush=True)
    return row


def _write_held(rows, k):
    body = "\n".join(
        [
            "## The deterministic passage a step on finer grids (`--held-steps`)",
            "",
            f"Machine: {machine()}. The pitch-point contact held (700 N m, SRR 0.3, 3500 rpm), "
            f"ground (polished rows: Rq 0.05 µm, filtered at λs = 2.5 µm), the default "
            f"deterministic `EHLModel` on each grid; {k} steps of "
            "Δt = Δx/ur, the first a steady solve. Compile: first call − second. A step: the "
            "second call's time per Newton iteration × the mean iterations of steps 2…k. "
            "Engagement: that × the steps of one engagement along the path on that grid (the "
            "held contact costs about as much a step as the path's, `mixed_engagement`).",
            "",
            "| model | nodes | Δx, µm | compile, s | steady its | its a step | per iteration, ms | "
            "per step, s | converged | steps per engagement | engagement, h |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("mixed_held_steps", body, README)


def passage_iterations(k):
    """Per-step Newton iterations of the deterministic transient passage (iso-thermal, 257 nodes,
    Δt = Δx/ur). The first step is a steady cold solve; every later one tries a warm start from the
    step before within ``warm_iterations`` and falls back to a cold solve (smooth film, then
    continuation in the roughness amplitude) when that fails. A warm start that converged would
    cost at most ``warm_iterations``; the excess over the budget is the cold fallback."""
    surf = jg.presets.ground()
    rows = []
    for rpm in (500.0, 3500.0):
        for warm in (12, 60):
            model = jg.EHLModel(n_nodes=257, mixed="deterministic", warm_iterations=warm)
            c = gear_contact(rpm=rpm)
            dt = float(grid_time_step(c, LUB, model))
            contacts = jax.tree_util.tree_map(lambda a, k=k: jnp.full((k,), a), c)
            times = jnp.arange(k) * dt
            fn = lambda cs, t, model=model: solve_ehl_passage(  # noqa: E731
                cs, LUB, model, surf, times=t
            )
            first, run = time_call(fn, contacts, times, repeats=1)
            sols = fn(contacts, times)
            its = [int(i) for i in sols.iterations]
            later = its[1:]
            warm_ok = sum(i <= warm for i in later)
            rows.append(
                f"| {rpm:.0f} | {warm} | {k} | {run / k * 1e3:.0f} | {its[0]} | "
                f"{min(later)}-{max(later)} (median {sorted(later)[len(later) // 2]}) | "
                f"{warm_ok} of {len(later)} | {int(sum(bool(v) for v in sols.converged))} of {k} |"
            )
            print(rows[-1], flush=True)
    body = "\n".join(
        [
            "## Deterministic transient passage: where the steps go (`--passage-iterations`)",
            "",
            f"Machine: {machine()}. Pitch-point contact, 700 N m, SRR 0.3, ground, 257 nodes, "
            "iso-thermal, Δt = Δx/ur. Newton iterations per step, all attempts counted; a warm "
            "start converges within its budget or the step falls back to a cold solve.",
            "",
            "| rpm | warm budget | steps | per step, ms | first (steady, cold) | later steps | "
            "warm start enough | converged |",
            "|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("mixed_passage_iterations", body, README)


if __name__ == "__main__":
    main()
