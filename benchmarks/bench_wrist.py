"""The Carpal Wrist: RK4 speed against accuracy, the Lagrange and Newton-Euler routes, and the
parameter sweep on one device and sharded over several.

    python benchmarks/bench_wrist.py [--out DIR] [--quick]
    XLA_FLAGS=--xla_force_host_platform_device_count=2 python benchmarks/bench_wrist.py

is `mbjax bench wrist`; the suite itself is harness/mbjax_harness/bench/wrist.py.
"""

import sys

from mbjax_harness.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "wrist", *sys.argv[1:]]))
