"""Every status the `mbjax` command's runs report, with the default accuracy check's measure.

    python tests/tools/status_census.py LOG.jsonl tour [--out DIR] [--jobs 1]
    python tests/tools/status_census.py LOG.jsonl reproduce NAME [--out DIR]

runs the command in this process with every `simulate`, `solve_tfe` and `mbjax.trajopt.solve`
result logged to LOG.jsonl as it is made (its type, the harness line that made it, its
`resolution` and status), then prints, per log, the largest resolution and the runs the
default check flagged. This is how benchmarks/README.md (section "accuracy") counts
the check's false alarms over every scene and reproduction: a run flagged by it whose error
the scene itself shows to be small would be one. Run the tour with --jobs 1 (workers are other
processes, which this script does not reach).
"""

import importlib
import json
import os
import sys
import traceback

import jax
import numpy as np


def _where() -> str:
    """The last harness and scene lines on the stack: which run made the result."""
    frames = [f for f in traceback.extract_stack()[:-3]
              if "mbjax_harness" in f.filename or "scenes" in f.filename]
    return " < ".join(f"{os.path.basename(f.filename)}:{f.lineno}" for f in frames[-3:])


def _logged(log, kind: str, make):
    def made(*args, **kwargs):
        out = make(*args, **kwargs)
        if not isinstance(out.status, jax.core.Tracer):     # made under an outer jit: not here
            log.write(json.dumps({"type": kind, "where": _where(),
                                  "resolution": np.asarray(out.resolution, float).ravel()
                                  .tolist()[:16],
                                  "messages": out.messages()[:16]}) + "\n")
            log.flush()
        return out
    return made


def census(path: str) -> None:
    """The largest resolution and the runs flagged by the default check, from a log."""
    rows = [json.loads(line) for line in open(path)]
    flagged = {(r["where"], m) for r in rows for m in r["messages"] if "do not resolve" in m}
    largest = max((x for r in rows for x in r["resolution"] if x == x), default=0.0)
    print(f"{path}: {len(rows)} results, largest resolution {largest:.3g}, flagged by the "
          f"default check: {len(flagged)}")
    for where, words in sorted(flagged):
        print(f"  {where}: {words}")


def main(argv: list[str]) -> int:
    path, command = argv[0], argv[1:]
    with open(path, "a") as log:
        # the names each driver calls at run time (a caller's own `from ... import simulate`
        # binds the function itself, which no patch reaches)
        for module, name in (("mbjax._src.integrate.simulate", "Solution"),
                             ("mbjax._src.tfe.solve", "_checked"),
                             ("mbjax._src.trajopt.solve", "_solve"),
                             ("mbjax._src.trajopt.solve", "_solve_batch")):
            module = importlib.import_module(module)
            setattr(module, name, _logged(log, name, getattr(module, name)))
        from mbjax_harness.cli import main as mbjax
        code = mbjax(command)
    census(path)
    return code


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
