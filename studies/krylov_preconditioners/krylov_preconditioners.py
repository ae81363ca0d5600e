"""Why ``EHLModel(linear_solver="krylov")`` preconditions as it does: GMRES vectors to
solve one Newton system of a transient deterministic step, with each candidate preconditioner.

The system: the first Newton iteration of the second step of a passage of the held pitch contact
(700 N m, SRR 0.3, 3500 rpm, Δt = Δx/ur), from the previous step's solution (the warm start the
passage takes), the roughness profiles filtered at λs = 2.5 µm; polished (a full film) and ground
(closing). J is assembled dense (the solver's own ``_Level.jacobian``) and GMRES is SciPy's, so the
counts are those of the preconditioned operator alone, not of jaxgear's GMRES.

Candidates: none; the previous step's exact LU (a chord method across steps); J's band of
half-width w (w = 1: the tridiagonal) with the H0 column and load row; block-Jacobi LUs of J's
diagonal blocks of b nodes with the border by a Schur complement (what the solver uses, b = 128).

Run: ``python studies/krylov_preconditioners/krylov_preconditioners.py [--nodes 1025 2049]
[--rows FILE.json]``.
Writes the ``krylov_preconditioners`` section of studies/krylov_preconditioners/README.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402
import scipy.linalg as sla  # noqa: E402
import scipy.sparse.linalg as spla  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
README = Path(__file__).with_name("README.md")  # this study's sections
sys.path.insert(0, str(ROOT / "benchmarks"))  # _report
sys.path.insert(0, str(Path(__file__).parents[2] / "tests"))

from _report import ROWS_HELP, RowCache, machine, write_section  # noqa: E402
from helpers import gear_contact  # noqa: E402

import jaxgear as jg  # noqa: E402
from jaxgear.lubrication.ehl.discretisation import _fine_level, _grid_positions  # noqa: E402
from jaxgear.lubrication.ehl.model import _Inputs, _split_numbers  # noqa: E402
from jaxgear.lubrication.passage import grid_time_step  # noqa: E402
from jaxgear.paper import field_surfaces  # noqa: E402

LUB = jg.presets.mil_l_23699()
RTOL = 1e-3  # the solver's direction tolerance (ehl.newton._DIRECTION_TOLERANCE)
BANDS = (1, 4, 16, 64)
BLOCKS = (32, 64, 128, 256)


def _system(n, kind):
    """(J at the warm start of step 2, F there, J at step 1's solution) on n nodes."""
    model = jg.EHLModel(n_nodes=n, mixed="deterministic")
    contact = gear_contact(rpm=3500.0)
    surf = field_surfaces(kind)
    dt = float(grid_time_step(contact, LUB, model))
    moved = jnp.asarray([float(contact.u1) * dt, float(contact.u2) * dt])
    first = jg.solve_ehl(contact, LUB, model, surf)
    x = _grid_positions(model, contact, LUB)

    def level(displacement, previous):
        zero = jnp.zeros((n,))
        inv_dt, rho_h = (
            (jnp.zeros(()), zero)
            if previous is None
            else (jnp.asarray(1.0 / dt), jnp.interp(x, previous.x, previous.rho_h))
        )
        offset = -(
            surf.displaced_height(0, x, displacement[0])
            + surf.displaced_height(1, x, displacement[1])
        )
        numbers, static = _split_numbers(model)
        inp = _Inputs(contact, LUB, rho_h, inv_dt, offset, zero, surf.composite_rq, numbers)
        return _fine_level(static, dataclasses.replace(inp, rough=True))[1]

    steady, step = level(jnp.zeros(2), None), level(moved, first)
    film_unit = float(steady.sc.b**2 / contact.reduced_radius)
    u = jnp.concatenate(
        [first.fluid_pressure / steady.sc.ph, jnp.asarray([float(first.h0) / film_unit])]
    )
    assert float(jnp.max(jnp.abs(steady.residual(u)))) < 1e-8, "step 1 not at its solution"
    return (
        np.asarray(step.jacobian(u)),
        np.asarray(step.residual(u)),
        np.asarray(steady.jacobian(u)),
    )


def _gmres_vectors(jac, f, solve):
    count = [0]
    a = spla.LinearOperator(jac.shape, matvec=lambda v: jac @ v)
    m = spla.LinearOperator(jac.shape, matvec=solve)
    d, _ = spla.gmres(
        a,
        -f,
        M=m,
        rtol=RTOL,
        restart=200,
        maxiter=5,
        callback=lambda _: count.__setitem__(0, count[0] + 1),
        callback_type="pr_norm",
    )
    rel = np.linalg.norm(jac @ d + f) / np.linalg.norm(f)
    return count[0] if rel <= 2 * RTOL else f">{count[0]}"


def _band(jac, w):
    b = np.triu(np.tril(jac, w), -w)
    b[-1, :], b[:, -1] = jac[-1, :], jac[:, -1]
    lu = sla.lu_factor(b)
    return lambda v: sla.lu_solve(lu, v)


def _block_jacobi(jac, size):
    n = jac.shape[0] - 1
    spans = [(a, min(a + size, n)) for a in range(0, n, size)]
    lus = [sla.lu_factor(jac[a:b, a:b]) for a, b in spans]

    def inner(v):
        return np.concatenate(
            [sla.lu_solve(lu, v[a:b]) for (a, b), lu in zip(spans, lus, strict=True)]
        )

    column, row = jac[:n, n], jac[n, :n]
    y2 = inner(column)

    def solve(v):
        y1 = inner(v[:n])
        xi = (row @ y1 - v[n]) / (row @ y2)
        return np.concatenate([y1 - xi * y2, [xi]])

    return solve


def _row(n, kind):
    jac, f, previous = _system(n, kind)
    lu_prev = sla.lu_factor(previous)
    counts = [
        _gmres_vectors(jac, f, lambda v: v),
        _gmres_vectors(jac, f, lambda v: sla.lu_solve(lu_prev, v)),
        *(_gmres_vectors(jac, f, _band(jac, w)) for w in BANDS),
        *(_gmres_vectors(jac, f, _block_jacobi(jac, b)) for b in BLOCKS),
    ]
    row = f"| {kind} | {n} | {np.max(np.abs(f)):.2g} | " + " | ".join(map(str, counts)) + " |"
    print(row, flush=True)
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nodes", type=int, nargs="+", default=[1025, 2049])
    ap.add_argument("--rows", type=Path, help=ROWS_HELP)
    args = ap.parse_args(argv)
    cache = RowCache(args.rows)
    rows = [
        cache.get(f"{kind} {n}", lambda n=n, kind=kind: _row(n, kind))
        for kind in ("polished", "ground")
        for n in args.nodes
    ]
    head = (
        ["surfaces (λs 2.5 µm)", "nodes", "‖F‖∞ of the start", "none", "previous step's LU"]
        + [f"band {w}" for w in BANDS]
        + [f"blocks of {b}" for b in BLOCKS]
    )
    body = "\n".join(
        [
            "## Preconditioners of the Krylov Newton directions (`krylov_preconditioners.py`)",
            "",
            f"Machine: {machine()}. GMRES vectors (SciPy, restart 200) to ‖J d + F‖ ≤ {RTOL:g} ‖F‖ "
            "for the first Newton system of a transient step from the previous step's solution "
            "(pitch contact, 3500 rpm, Δt = Δx/ur), J assembled dense. '>k': not reached. "
            "Bands and blocks keep the H0 column and the load row.",
            "",
            "| " + " | ".join(head) + " |",
            "|" + "---|" * len(head),
            *rows,
        ]
    )
    write_section("krylov_preconditioners", body, README)


if __name__ == "__main__":
    main()
