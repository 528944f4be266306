"""mbjax's side of `mbjax bench trajopt` on an accelerator: the single problems and the 64 reach
targets as one vmapped solve (no loop of single solves: on a GPU each is thousands of small
kernels). Crocoddyl has no GPU; compare with its CPU loop in benchmarks/trajopt/.

    python benchmarks/trajopt_gpu.py OUT_DIR
"""

import json
import sys
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

from mbjax_harness.bench import trajopt  # noqa: E402


def main(out: Path) -> None:
    common = {"jax": jax.__version__, "device": jax.devices()[0].device_kind,
              "backend": jax.default_backend()}
    records = []
    for name in trajopt.PROBLEMS:
        records += [r for r in trajopt.single(name, 3, common) if r["engine"] == "mbjax"]
    records += [r for r in trajopt.many(trajopt.N_TARGETS, 2, common, loop=False)
                if r["engine"] == "mbjax"]
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "trajopt_gpu.jsonl", "w") as f:
        for r in records:
            r.pop("history", None)
            f.write(json.dumps(r) + "\n")
            print(json.dumps(r))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
