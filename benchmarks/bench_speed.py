"""The cost users feel (one call, one evaluation in a rollout, a vmapped batch, the gradient of a
rollout, compile time) on chains and real robots, mbjax against Pinocchio, jaxsim and adam in one
process.

    python benchmarks/bench_speed.py [--out DIR] [--quick]

is `mbjax bench speed`; the suite itself is harness/mbjax_harness/bench/speed.py, so that the installed `mbjax`
command runs it too.
"""

import sys

from mbjax_harness.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "speed", *sys.argv[1:]]))
