"""JAX's persistent compilation cache, on by default in the `mbjax` command and the notebooks
(not in `mbjax bench`, whose compile times must be compiles).

Compiling dominates a first run (a scene compiles for seconds and runs for milliseconds); with the
cache, a second run loads the compiled programs from disk. The folder is the argument, else
JAX_COMPILATION_CACHE_DIR, else $XDG_CACHE_HOME/mbjax/jax (~/.cache/mbjax/jax). MBJAX_NO_CACHE=1
(or `mbjax --no-cache ...`) leaves JAX's default, no cache, in place. A cached program is the same
binary XLA would compile. An entry that cannot be read (truncated, overwritten) is removed when
it fails to load, so that the program compiled in its place is written anew: JAX itself warns,
recompiles, and never replaces an existing entry, so a corrupt one would cost a compile on every
run.
"""

import os
import warnings
from pathlib import Path

# Programs that compile faster than this are not written. JAX's default is 1 s, but a tour compiles
# hundreds of small programs (arrays handled op by op outside jit) beside its large ones, and
# keeping them all makes a second run markedly faster; see benchmarks/README.md.
MIN_COMPILE_SECONDS = 0.0


def cache_folder() -> Path:
    """Where `use_compilation_cache` keeps compiled programs by default."""
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "mbjax" / "jax"


def use_compilation_cache(folder: str | os.PathLike | None = None) -> Path | None:
    """Turn on JAX's persistent compilation cache.

    On by default in the `mbjax` command and the notebooks (not in `mbjax bench`, whose compile
    times must be compiles).

    Args:
        folder: where to keep compiled programs; None for JAX_COMPILATION_CACHE_DIR, else
            `cache_folder()`: $XDG_CACHE_HOME/mbjax/jax (~/.cache/mbjax/jax). Created if missing.

    Returns:
        The folder in use, or None where MBJAX_NO_CACHE is set (the cache stays off).

    The cache:
        Compiling dominates a first run (a scene compiles for seconds and runs for
        milliseconds); with the cache, a second run loads the compiled programs from disk.
        MBJAX_NO_CACHE=1 (or `mbjax --no-cache ...`) leaves JAX's default, no cache, in place. A
        cached program is the same binary XLA would compile. An entry that cannot be read
        (truncated, overwritten) is removed, with a warning, when it fails to load, so that the
        program compiled in its place is written anew: JAX itself warns, recompiles, and never
        replaces an existing entry, so a corrupt one would cost a compile on every run.
    """
    if os.environ.get("MBJAX_NO_CACHE", "") not in ("", "0"):
        return None
    import jax

    path = Path(folder or os.environ.get("JAX_COMPILATION_CACHE_DIR") or cache_folder())
    path.mkdir(parents=True, exist_ok=True)
    jax.config.update("jax_compilation_cache_dir", str(path))
    _replace_unreadable_entries()
    if "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS" not in os.environ:
        jax.config.update("jax_persistent_cache_min_compile_time_secs", MIN_COMPILE_SECONDS)
    return path


def _replace_unreadable_entries() -> None:
    """Wrap JAX's cache lookup so that an entry that fails to load is removed, with a warning,
    and read as a miss: the program is compiled and its entry written anew (see the module).
    JAX's lookup is private API; where it is not found, its own behaviour stays."""
    try:
        from jax._src import compilation_cache
    except ImportError:                                   # pragma: no cover
        return
    lookup = getattr(compilation_cache, "get_executable_and_time", None)
    if lookup is None or getattr(lookup, "replaces_unreadable", False):
        return

    def get_executable_and_time(cache_key, *args, **kwargs):
        try:
            return lookup(cache_key, *args, **kwargs)
        except Exception as error:                        # any failure to read or load it
            import jax

            entry = Path(jax.config.jax_compilation_cache_dir or ".") / f"{cache_key}-cache"
            entry.unlink(missing_ok=True)
            warnings.warn(f"mbjax: a compiled program in the cache could not be read "
                          f"({type(error).__name__}); its entry {entry} was removed and the "
                          "program is compiled and written anew", stacklevel=2)
            return None, None

    get_executable_and_time.replaces_unreadable = True
    compilation_cache.get_executable_and_time = get_executable_and_time
