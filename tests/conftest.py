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


# The longest tests (the notebooks, then the CLI's reproductions and tour) go first, so the two
# xdist workers (`-n 2 --maxschedchunk 1` in pyproject.toml) start on them and fill in with the
# short ones, instead of finishing on one long notebook while the other worker idles.
_LONG_FIRST = ("test_notebooks.py", "test_cli.py")


def pytest_collection_modifyitems(config, items):
    def rank(item):
        name = item.path.name
        return _LONG_FIRST.index(name) if name in _LONG_FIRST else len(_LONG_FIRST)

    items.sort(key=rank)          # stable: the order within each group is kept
