"""Closed loops: every route on the closed chain, speed against accuracy and scaling in n.

    python benchmarks/bench_loops.py [--out DIR] [--quick]

is `mbjax bench loops`; the suite itself is harness/mbjax_harness/bench/loops.py, so that the installed `mbjax`
command runs it too.
"""

import sys

from mbjax_harness.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "loops", *sys.argv[1:]]))
