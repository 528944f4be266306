import os

# The suite is correctness, not speed, and most of its time is compilation: LLVM's cheapest
# optimization level saves about a fifth of it (IEEE semantics are unchanged; benchmarks, which
# are scripts, keep the default). Set before JAX starts its backend; notebook kernels and
# subprocesses inherit it.
os.environ["XLA_FLAGS"] = " ".join(filter(None, [os.environ.get("XLA_FLAGS"),
                                                 "--xla_backend_optimization_level=0"]))

import jax  # noqa: E402
import pytest  # noqa: E402

# Accuracy work is float64 (DESIGN.md); the library itself never flips this flag.
jax.config.update("jax_enable_x64", True)


@pytest.fixture(autouse=True, scope="module")
def _free_compiled_code():
    """Drop JAX's compiled executables after each test module, so one long pytest process does
    not accumulate every module's compilations (it reached 4.4 GB at two thirds of the suite)."""
    yield
    jax.clear_caches()


# The longest tests (the notebooks, then the CLI's reproductions and tour) go first, so the two
# xdist workers (`-n 2 --maxschedchunk 1` in pyproject.toml) start on them and fill in with the
# short ones, instead of finishing on one long notebook while the other worker idles.
_LONG_FIRST = ("test_notebooks.py", "test_cli.py")


def pytest_collection_modifyitems(config, items):
    def rank(item):
        name = item.path.name
        return _LONG_FIRST.index(name) if name in _LONG_FIRST else len(_LONG_FIRST)

    items.sort(key=rank)          # stable: the order within each group is kept
