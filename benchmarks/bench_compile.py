"""What compiling costs a user: `mbjax tour --quick` from a cold and a warm compilation cache,
scene by scene with the programs each compiles, and the first calls of the public functions
outside `jax.jit`.

    python benchmarks/bench_compile.py [--out DIR]

is `mbjax bench compile`; the suite itself is harness/mbjax_harness/bench/compile_time.py, so that the installed
`mbjax` command runs it too.
"""

import sys

from mbjax_harness.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "compile", *sys.argv[1:]]))
