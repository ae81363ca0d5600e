"""``jaxgear figures``: the paper's Figs. 3-12 and its reported results R1-R11, from jaxgear.

Runs the baseline speed sweep (500-4200 rpm, 25 rpm steps, ground, 700 N m, 90 °C) tribo-dynamic and
quasi-static, the paper's variants (inlet 60 °C, 1500 N m, polished; iso-thermal at a thermal
fidelity) every 100 rpm, and the contact fields at 25° and 17° roll angle; writes to ``--out``
(default ``results/figures``) the PNG figures, ``paper_table.md`` / ``paper_table.json`` (R1-R11, the
paper's value beside jaxgear's), the sweeps as CSV in ``data/`` and ``figures.json`` (what was
written, what was skipped and why).
A figure the fidelity cannot give (temperatures need the thermal rung, asperity pressures the mixed
rung) is skipped with the reason printed, never drawn from something else. ``--quick``: seven speeds
(the points A-E at nominal speeds and the sweep's ends), 24 positions per mesh cycle.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from jaxgear.dynamics.model import BACK_FLANK_KINDS
from jaxgear.fidelity import NAMED_PRESETS


def register(sub) -> None:
    p = sub.add_parser(
        "figures",
        help="the paper's Figs. 3-12 and a table of its results R1-R11 beside jaxgear's",
        description=__doc__.split("\n\n")[0] + "\n\n" + __doc__.split("\n\n")[1],
    )
    p.add_argument(
        "--fidelity",
        choices=NAMED_PRESETS,
        default="fast",
        help="fidelity preset (default fast); paper_calibrated: the paper fidelity with its open "
        "contact parameters calibrated to the paper's loss level (jg.Fidelity.paper_calibrated)",
    )
    p.add_argument("--out", type=Path, default=Path("results/figures"), help="output directory")
    p.add_argument("--quick", action="store_true", help="reduced run (seven speeds, 24 positions)")
    p.add_argument(
        "--speed-step",
        type=float,
        default=25.0,
        metavar="RPM",
        help="step of the baseline sweep over 500-4200 rpm (default 25, the paper's). Steps above "
        "50 rpm cannot locate the DTE peaks: the points A-E are then placed at their nominal speeds",
    )
    p.add_argument(
        "--variant-step",
        type=float,
        default=100.0,
        metavar="RPM",
        help="step of the variant sweeps (60 °C, 1500 N m, polished, iso-thermal), a multiple of "
        "--speed-step (default 100, or --speed-step if larger)",
    )
    p.add_argument(
        "--back-flank",
        choices=BACK_FLANK_KINDS,
        default=None,
        help="the back flanks in the dynamics (default: the preset's; paper and paper_calibrated: "
        "same, the paper's single backlash function; fast: mirrored, their own stiffness and line "
        "of action). See jg.Fidelity.back_flank",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import json
    import time

    import numpy as np

    from jaxgear.fidelity import Fidelity
    from jaxgear.paper import reproduce_paper, table_markdown, write_report

    speeds = variant_speeds = None
    if not args.quick:
        if not (5.0 <= args.speed_step <= 1850.0):
            print(
                f"jaxgear figures: --speed-step = {args.speed_step:g} rpm is not valid; valid "
                "range: 5 to 1850 rpm",
                file=sys.stderr,
            )
            return 2
        speeds = np.arange(500.0, 4200.0 + 1e-9, args.speed_step)
        step = max(args.variant_step, args.speed_step)
        ratio = step / args.speed_step
        ok = args.variant_step > 0 and np.isfinite(ratio)
        if not (ok and abs(ratio - round(ratio)) < 1e-9):
            print(
                f"jaxgear figures: --variant-step = {args.variant_step:g} rpm is not valid; valid: "
                f"a multiple of --speed-step ({args.speed_step:g} rpm)",
                file=sys.stderr,
            )
            return 2
        variant_speeds = speeds[:: int(round(ratio))]
    changes = {} if args.back_flank is None else {"back_flank": args.back_flank}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    repro = reproduce_paper(
        Fidelity.named(args.fidelity, **changes),
        quick=args.quick,
        speeds_rpm=speeds,
        variant_speeds_rpm=variant_speeds,
        checkpoint_dir=out / "checkpoint",
        progress=not args.no_progress,
    )
    manifest = write_report(repro, out)
    print(table_markdown(json.loads((out / "paper_table.json").read_text())))
    print()
    for fig, name in manifest["written"].items():
        print(f"wrote {fig}: {out / name}")
    for fig, reason in manifest["skipped"].items():
        print(f"skipped {fig}: {reason}")
    print(f"wrote {out / 'paper_table.md'}, paper_table.json, figures.json, data/*.csv")
    print(f"wall time {time.perf_counter() - t0:.0f} s")
    return 0
