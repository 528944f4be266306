"""Batched forward dynamics, rollouts and rollout gradients of revolute chains, mbjax against
Pinocchio (aba per call, abaInParallel), mujoco.rollout and MJX, in one run.

    python benchmarks/bench_throughput.py [--out DIR] [--quick]

is `mbjax bench throughput`; the suite itself is harness/mbjax_harness/bench/throughput.py. On a machine with a
GPU (jax[cuda]) the same command runs the mbjax side there.
"""

import sys

from mbjax_harness.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "throughput", *sys.argv[1:]]))
