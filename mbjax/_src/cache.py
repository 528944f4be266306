"""JAX's persistent compilation cache, on by default in the `mbjax` command and the notebooks
(not in `mbjax bench`, whose compile times must be compiles).

Compiling dominates a first run (a scene compiles for seconds and runs for milliseconds); with the
cache, a second run loads the compiled programs from disk. The folder is the argument, else
JAX_COMPILATION_CACHE_DIR, else $XDG_CACHE_HOME/mbjax/jax (~/.cache/mbjax/jax). MBJAX_NO_CACHE=1
(or `mbjax --no-cache ...`) leaves JAX's default, no cache, in place. A cached program is the same
binary XLA would compile.
"""

import os
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
    """Turn on JAX's persistent compilation cache (see the module).

    Args:
        folder: where to keep compiled programs; None for JAX_COMPILATION_CACHE_DIR, else
            `cache_folder()`. Created if missing.

    Returns:
        The folder in use, or None where MBJAX_NO_CACHE is set (the cache stays off).
    """
    if os.environ.get("MBJAX_NO_CACHE", "") not in ("", "0"):
        return None
    import jax

    path = Path(folder or os.environ.get("JAX_COMPILATION_CACHE_DIR") or cache_folder())
    path.mkdir(parents=True, exist_ok=True)
    jax.config.update("jax_compilation_cache_dir", str(path))
    if "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS" not in os.environ:
        jax.config.update("jax_persistent_cache_min_compile_time_secs", MIN_COMPILE_SECONDS)
    return path
