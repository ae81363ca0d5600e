import os

import jax
import pytest

from jaxgear.cli import enable_compilation_cache, enable_fast_cpu_compilation
from jaxgear.cli.main import _jaxlib_knows

# XLA's classic CPU emitters, as the CLI uses them (about half the compile time of the fusion
# emitters on these programs); set before the first computation starts the backend.
enable_fast_cpu_compilation()
# ... and without LLVM's optimisation of the machine code (XLA's backend level 0 instead of its
# default 3): the default run is mostly compilation, which this cuts by about a third (9.5 against
# 13.3 min from an empty cache on 2 cores), for slower code where a test runs long. The numbers
# differ from the optimised code's by round-off only, which
# tests/cli/test_xla_flags.py checks against a process compiling as users do. A caller's own
# level in $XLA_FLAGS is kept.
_TEST_OPT_LEVEL = "xla_backend_optimization_level"
if _TEST_OPT_LEVEL not in os.environ.get("XLA_FLAGS", "") and _jaxlib_knows(_TEST_OPT_LEVEL):
    os.environ["XLA_FLAGS"] = f"{os.environ.get('XLA_FLAGS', '')} --{_TEST_OPT_LEVEL}=0".strip()
# Tests run in float64 (EHL needs it); the library never flips this itself.
jax.config.update("jax_enable_x64", True)
# Compiled programs on disk from the first test on, as `jaxgear` keeps them ($JAXGEAR_CACHE_DIR,
# default ~/.cache/jaxgear/xla; "off" disables).
enable_compilation_cache()


def _read(path: str) -> str:
    try:
        with open(path) as f:
            return f.read()
    except OSError:
        return ""


def _memory_maps() -> int:
    return _read(f"/proc/{os.getpid()}/maps").count("\n")


def _resident_bytes() -> int:
    for line in _read(f"/proc/{os.getpid()}/status").splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    return 0


def _physical_bytes() -> int:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError):
        return 8 << 30


# Compiled programs stay in memory across test modules: a program compiled in one module is reused
# by the next without tracing and compiling it again. They are dropped when a worker holds a
# quarter of the machine's memory or a quarter of the kernel's limit on memory maps
# (vm.max_map_count): XLA's CPU executables map memory of their own, a heavy EHL module adds up to
# ~34k maps, and a process at the limit cannot map more, so its next compilation aborts the
# interpreter ("Fatal Python error: Aborted", what a full run that never released them did). A
# quarter leaves room for the heaviest module on top.
_MAP_BUDGET = (int(_read("/proc/sys/vm/max_map_count") or 65530)) // 4
_MEMORY_BUDGET = _physical_bytes() // 4


@pytest.fixture(autouse=True, scope="module")
def _release_compiled_programs_near_the_limits(request):
    yield
    maps, resident = _memory_maps(), _resident_bytes()
    log = os.environ.get("JAXGEAR_TEST_MAPS_LOG")
    if log:  # what each test module leaves behind, to check the budgets against
        with open(log, "a") as f:
            f.write(f"{os.getpid()} {request.module.__name__} {maps} {resident >> 20}\n")
    if maps > _MAP_BUDGET or resident > _MEMORY_BUDGET:
        jax.clear_caches()
