"""The ``jaxgear`` command line: the parser and its subcommands (``commands/``), and the TOML
configuration they read (``config.py``)."""

from .main import COMMANDS as COMMANDS
from .main import build_parser as build_parser
from .main import enable_compilation_cache as enable_compilation_cache
from .main import enable_fast_cpu_compilation as enable_fast_cpu_compilation
from .main import enable_float64 as enable_float64
from .main import main as main
