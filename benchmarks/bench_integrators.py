"""Heavy top over 10 s, every mbjax integrator against MuJoCo's, in one process.

    python benchmarks/bench_integrators.py [--out DIR] [--quick]

is `mbjax bench integrators`; the suite itself is harness/mbjax_harness/bench/integrators.py, so that the
installed `mbjax` command runs it too.
"""

import sys

from mbjax_harness.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "integrators", *sys.argv[1:]]))
