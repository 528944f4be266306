"""Flexible bodies: the spin-up beam, modal model against the nonlinear ANCF beam and exudyn.

    python benchmarks/bench_flexible.py [--out DIR] [--quick]

is `mbjax bench flexible`; the suite itself is harness/mbjax_harness/bench/flexible.py, so that the installed `mbjax`
command runs it too.
"""

import sys

from mbjax_harness.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "flexible", *sys.argv[1:]]))
