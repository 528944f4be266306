import os
import tempfile
from pathlib import Path

# One persistent XLA compilation cache for the whole run, shared by both xdist workers, the
# notebook kernels and the CLI subprocesses they start (they inherit the environment): the tour,
# the reproductions, the notebooks and the unit tests build many of the same scenes, and on the
# CI machine compiling them is most of the suite's time. A cached executable is the same binary.
# The first process to import this file (the xdist controller) names the folder; the workers it
# starts inherit the variable, so setdefault keeps that one name for the whole run.
os.environ.setdefault("JAX_COMPILATION_CACHE_DIR",
                      str(Path(tempfile.gettempdir()) / f"mbjax-xla-cache-{os.getpid()}"))
os.environ.setdefault("JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS", "0.3")

import jax  # noqa: E402  (after the cache's environment, which jax reads on import)
import pytest  # noqa: E402

# Accuracy work is float64 (DESIGN.md); the library itself never flips this flag.
jax.config.update("jax_enable_x64", True)
# (again in case a plugin imported jax before this file set the environment)
jax.config.update("jax_compilation_cache_dir", os.environ["JAX_COMPILATION_CACHE_DIR"])
jax.config.update("jax_persistent_cache_min_compile_time_secs",
                  float(os.environ["JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS"]))


def pytest_configure(config):
    """The default suite (`-m "not slow"`) is compile-bound: most of its tests compile a program to
    run it a few times. There, XLA compiles without LLVM's optimization passes
    (`--xla_backend_optimization_level=0`, set before JAX starts its backend; the workers, notebook
    kernels and command-line subprocesses inherit it): 21 % less wall time on tests/rigid and
    tests/lie. The passes keep IEEE semantics but may round a few operations differently (as XLA's
    two fusion emitters do, `mbjax._src.runtime`), so the slow tests, full-length runs whose
    solvers stop at a tolerance, and any other selection compile at XLA's default, as users and
    the benchmarks do."""
    if (config.option.markexpr == "not slow"
            and "--xla_backend_optimization_level" not in os.environ.get("XLA_FLAGS", "")):
        os.environ["XLA_FLAGS"] = " ".join([os.environ.get("XLA_FLAGS", ""),
                                            "--xla_backend_optimization_level=0"]).strip()


@pytest.fixture(autouse=True, scope="module")
def _free_compiled_code():
    """Drop JAX's compiled executables after each test module, so one long pytest process does
    not accumulate every module's compilations (it reached 4.4 GB at two thirds of the suite)."""
    yield
    jax.clear_caches()


# The longest modules (the notebooks, the README's blocks and the guide, then the CLI's tour) go
# first, so the two xdist workers (`-n 2 --dist loadgroup --no-loadscope-reorder` in
# pyproject.toml: xdist's own reorder, by the number of tests in a group, put these one-test groups
# last) start on them and fill in with the short ones, instead of finishing on a long module while
# the other idles. Each module is one xdist group (its
# compiled programs shared by its tests), except the notebooks and the README's blocks, whose
# every test runs in a process of its own and may go to either worker.
_SHARED_OUT = ("test_notebooks.py", "test_readme.py")
_LONG_FIRST = ("test_notebooks.py", "test_readme.py", "test_cli.py")


@pytest.hookimpl(tryfirst=True)     # before xdist's own, which reads the groups to schedule them
def pytest_collection_modifyitems(config, items):
    def rank(item):
        name = item.path.name
        return _LONG_FIRST.index(name) if name in _LONG_FIRST else len(_LONG_FIRST)

    items.sort(key=rank)          # stable: the order within each group is kept
    for item in items:
        if item.path.name not in _SHARED_OUT:
            item.add_marker(pytest.mark.xdist_group(str(item.path.relative_to(config.rootpath))))
    for item in items:            # the slow tests (full-length runs) get an hour, not the default
        if item.get_closest_marker("slow") and not item.get_closest_marker("timeout"):
            item.add_marker(pytest.mark.timeout(3600))


def example_robots(names=None) -> list[Path]:
    """The URDFs of example-robot-data (those whose corpus name is in `names`, or all), or skip
    the test where the package is not installed."""
    from mbjax_harness.reproduce import urdf_corpus
    try:
        paths = urdf_corpus.corpus_paths()
    except Exception as err:          # PackageNotFoundError
        pytest.skip(f"example-robot-data is not installed ({err})")
    return [p for p in paths if names is None or urdf_corpus.name(p) in names]
