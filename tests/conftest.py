import jax
import pytest

# Accuracy work is float64 (DESIGN.md); the library itself never flips this flag.
jax.config.update("jax_enable_x64", True)


@pytest.fixture(autouse=True, scope="module")
def _free_compiled_code():
    """Drop JAX's compiled executables after each test module, so one long pytest process does
    not accumulate every module's compilations (it reached 4.4 GB at two thirds of the suite)."""
    yield
    jax.clear_caches()
