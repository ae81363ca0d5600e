import jax
import pytest

# Tests run in float64 (EHL needs it); the library never flips this itself.
jax.config.update("jax_enable_x64", True)


@pytest.fixture(autouse=True, scope="module")
def _release_compiled_programs():
    """Drop each test module's compiled programs when it ends, so a full run does not hold every
    program it compiled. One full default run aborted ("Fatal Python error: Aborted") inside a
    compilation near its end without this; with it the run completes. The cause was not
    established (the process's memory-map count is a suspect: XLA maps memory per executable)."""
    yield
    jax.clear_caches()
