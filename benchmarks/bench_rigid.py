"""Forward dynamics of rigid chains (n = 1 ... 1000): Anderson 1993's O(n) recursion against Jerkovsky 1978's
dense form, Pinocchio and MuJoCo, batched, compile time and the gradient of a rollout, in one
process.

    python benchmarks/bench_rigid.py [--out DIR] [--quick]

is `mbjax bench rigid`; the suite itself is harness/mbjax_harness/bench/rigid.py, so that the installed `mbjax`
command runs it too.
"""

import sys

from mbjax_harness.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "rigid", *sys.argv[1:]]))
