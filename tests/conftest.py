import jax
import pytest

from jaxgear.cli import enable_compilation_cache

# Tests run in float64 (EHL needs it); the library never flips this itself.
jax.config.update("jax_enable_x64", True)
# Compiled programs on disk from the first test on, as `jaxgear` keeps them ($JAXGEAR_CACHE_DIR,
# default ~/.cache/jaxgear/xla; "off" disables). The suite compiles the same programs in many
# modules (each module's in-memory programs are dropped when it ends, below). Before, only the
# in-process `jaxgear run` test switched the cache on, halfway through one worker's share: a run
# then took 30 min with an empty cache and 17 min with the one the previous run had left.
enable_compilation_cache()


@pytest.fixture(autouse=True, scope="module")
def _release_compiled_programs():
    """Drop each test module's compiled programs when it ends, so a full run does not hold every
    program it compiled. One full default run aborted ("Fatal Python error: Aborted") inside a
    compilation near its end without this; with it the run completes. The cause was not
    established (the process's memory-map count is a suspect: XLA maps memory per executable)."""
    yield
    jax.clear_caches()
