"""What the default accuracy check catches and what it costs.

    python benchmarks/bench_accuracy.py [--out DIR] [--quick]

is `mbjax bench accuracy`; the suite itself is harness/mbjax_harness/bench/accuracy.py, so that the
installed `mbjax` command runs it too.
"""

import sys

from mbjax_harness.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "accuracy", *sys.argv[1:]]))
