"""The ``jaxgear`` command line.

Each subcommand lives in ``jaxgear/cli/commands/<name>.py`` and exposes ``register(subparsers)``, which adds
its parser and sets ``func`` (a callable taking the parsed namespace and returning an exit code).
Invalid input (``ValueError``) ends with a one-line message on stderr and exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

# Subcommand modules, in the order shown by --help.
COMMANDS = (
    "run", "sweep", "figures", "mesh", "ehl", "optimise", "pareto", "sensitivity", "calibrate",
)  # fmt: skip


class _Parser(argparse.ArgumentParser):
    """Usage errors (a bad number, an unknown choice) as one line on stderr and exit code 2, like
    every other invalid input: argparse's default prints the whole usage block first."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="jaxgear",
        description=(
            "Differentiable thermal tribo-dynamic power loss model of spur gear pairs "
            "(S. Li, Tribology International 88, 2015)."
        ),
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"jaxgear.cli.commands.{name}").register(sub)
    return parser


def enable_float64() -> None:
    """The CLI computes in float64 (EHL needs it); the library itself never flips jax.config."""
    import jax

    jax.config.update("jax_enable_x64", True)


# XLA's CPU flag that selects its classic elemental emitters over the newer fusion emitters
_CPU_EMITTER_FLAG = "xla_cpu_use_fusion_emitters"
# the --fidelity choices whose programs compile faster with XLA's default CPU emitters
_PAPER_FIDELITIES = ("paper", "paper_calibrated")


def _jaxlib_knows(flag: str) -> bool:
    """Whether this jaxlib registers the XLA flag ``flag``: its name, as a string of its own
    (NUL before and after: not the prefix of a longer name), is in one of jaxlib's shared
    libraries. XLA aborts the process on an unknown flag in ``$XLA_FLAGS``."""
    import glob
    import mmap
    import os

    try:
        import jaxlib
    except ImportError:
        return False
    needle = b"\0" + flag.encode() + b"\0"
    for path in glob.glob(os.path.join(os.path.dirname(jaxlib.__file__), "*.so")):
        try:
            with open(path, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as m:
                if m.find(needle) >= 0:
                    return True
        except (OSError, ValueError):
            continue
    return False


def enable_fast_cpu_compilation() -> bool:
    """Compile for the CPU with XLA's classic elemental emitters instead of its fusion emitters
    (``--xla_cpu_use_fusion_emitters=false`` appended to ``$XLA_FLAGS``). On jaxgear's programs
    the classic emitters compile a ``Fidelity.fast()`` ``simulate`` in about 0.6 of the time and
    run it in about 0.7, with results equal to the fixed point's tolerance
    (``benchmarks/compile.py``); the tests use them, and the CLI does unless its ``--fidelity``
    is ``paper`` or ``paper_calibrated``: the paper fidelity's programs compile more slowly with
    them (a tribo-dynamic point: ~1.4 times; ``benchmarks/paper_point.py`` with and without the
    flag) and run no faster.

    Takes effect only before JAX starts its CPU backend (the first computation). Leaves
    ``$XLA_FLAGS`` as it is where it already names the flag (the caller's choice), and where this
    jaxlib does not register the flag (XLA aborts on an unknown one). Set
    ``JAXGEAR_FAST_CPU_COMPILATION=off`` to keep XLA's default. Returns whether it added the flag.
    """
    import os

    if os.environ.get("JAXGEAR_FAST_CPU_COMPILATION", "").lower() in ("off", "0", "false"):
        return False
    flags = os.environ.get("XLA_FLAGS", "")
    if _CPU_EMITTER_FLAG in flags or not _jaxlib_knows(_CPU_EMITTER_FLAG):
        return False
    os.environ["XLA_FLAGS"] = f"{flags} --{_CPU_EMITTER_FLAG}=false".strip()
    return True


def enable_compilation_cache() -> None:
    """Keep compiled programs on disk (``$JAXGEAR_CACHE_DIR``, default ~/.cache/jaxgear/xla), so a
    second ``jaxgear run`` skips most of the compilation. Set JAXGEAR_CACHE_DIR=off to disable."""
    import os
    from pathlib import Path

    import jax

    where = os.environ.get("JAXGEAR_CACHE_DIR", str(Path.home() / ".cache" / "jaxgear" / "xla"))
    if where.lower() in ("off", "none", ""):
        return
    try:
        Path(where).mkdir(parents=True, exist_ok=True)
    except OSError:
        return  # read-only home: run without the cache
    jax.config.update("jax_compilation_cache_dir", where)
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 1.0)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 0
    # the paper fidelity's programs compile more slowly with the classic emitters (above)
    if getattr(args, "fidelity", None) not in _PAPER_FIDELITIES:
        enable_fast_cpu_compilation()
    enable_float64()
    enable_compilation_cache()
    try:
        return int(args.func(args) or 0)
    except ValueError as err:
        print(f"jaxgear {args.command}: error: {err}", file=sys.stderr)
        return 2
    except FileNotFoundError as err:
        print(f"jaxgear {args.command}: error: {err}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into `head` and the like
        sys.stderr.close()
        return 0
