"""Time finite elements against the step-by-step integrators, torque-free body and heavy top.

    python benchmarks/bench_tfe.py [--out DIR] [--quick]

is `mbjax bench tfe`; the suite itself is harness/mbjax_harness/bench/tfe.py, so that the installed `mbjax`
command runs it too.
"""

import sys

from mbjax_harness.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "tfe", *sys.argv[1:]]))
