"""Trajectory optimisation: mbjax's iLQR against Crocoddyl's FDDP on identical problems, one at
a time and 64 reach targets at once.

    python benchmarks/bench_trajopt.py [--out DIR] [--quick]

is `mbjax bench trajopt`; the suite itself is harness/mbjax_harness/bench/trajopt.py. Its GPU side:
benchmarks/trajopt_gpu.py.
"""

import sys

from mbjax_harness.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "trajopt", *sys.argv[1:]]))
