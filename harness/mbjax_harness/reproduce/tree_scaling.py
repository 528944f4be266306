"""`mbjax reproduce tree-scaling`: CPU time against n for the O(n) and O(n^3) formulations.

In the spirit of Anderson 1993 Fig. 8 (§3.3), where the O(n) recursion and a conventional O(n^3)
Kane formulation simulate the same chain for 1 s and the CPU time is plotted against the number
of degrees of freedom n (n = 4 ... 44, a closed (n/2)-body chain of Hooke's joints). Here: an
open n-link revolute chain (`mbjax.model.chain(n)`, n degrees of freedom; closed loops are in
`mbjax reproduce closed-chain`), the CPU time of one forward-dynamics evaluation, and n up to 384 so that both asymptotic
slopes show. An mbjax time is that of one evaluation among many in a jitted loop
(`mbjax_harness.common.looped_fn`; the median of timed loops after a compiling warm-up, over the
evaluations per loop), as a simulation meets it, free of the per-call dispatch of a lone jitted
call (tens of microseconds on CPU, which would hide the small-n end of the chart):

- recursive_s: `forward_dynamics(..., method=Recursive())`, Anderson 1993 §2.3, O(n);
- dense_s: `method="dense"`, Jerkovsky 1978's transformation operator and a Cholesky solve, O(n^3);
- pinocchio_aba_s (when Pinocchio is installed): `pin.aba` on the same chain loaded from
  `to_urdf`, the median of single calls from Python (so it includes under 1 us of binding).

Writes tree-scaling.json, exactly {"n", "recursive_s", "dense_s", "pinocchio_aba_s"}, and
tree-scaling.png (log-log, with slope-1 and slope-3 guide lines). A time is only worth charting
if the computation timed is right: the accelerations each timed loop returns are checked against
each other and against Pinocchio's (to `AGREEMENT`, relative to the largest; measured 5e-16 at
n = 2 ... 3e-11 at n = 384), and a disagreement stops the run with an error.
"""

import json
import statistics
import time
from pathlib import Path

import jax.numpy as jnp
import numpy as np

from mbjax_harness import peers
from mbjax_harness.common import loop_length, looped_fn, states
from mbjax_harness.timing import timed
from mbjax.model import chain, to_urdf

NAME = "tree-scaling"
# the peers compared with where installed, left out of the records where not: the
# command's closing line names those missing (`mbjax_harness.cli._declared`)
PEERS = ("pinocchio",)
NS = (2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128, 192, 256, 384)
QUICK_NS = (2, 16, 128)
AGREEMENT = 1e-8


def check_agreement(n: int, accelerations: dict) -> None:
    """Raise if the timed routes' accelerations differ by more than AGREEMENT (relative)."""
    (first, a), *others = accelerations.items()
    scale = float(np.max(np.abs(a)))
    for name, b in others:
        gap = float(np.max(np.abs(np.asarray(b) - np.asarray(a)))) / scale
        if not gap <= AGREEMENT:
            raise RuntimeError(f"tree-scaling: at n = {n} the {name} accelerations differ from "
                               f"the {first} ones by {gap:.2e} (relative; at most {AGREEMENT:g})")


def pinocchio_aba_time(n: int, repeats: int) -> tuple[float, np.ndarray]:
    """(median time of one `pin.aba` call on the n-link chain, from Python; its accelerations).
    (Pinocchio's Data allocates O(n^3) memory: 3.6 GB at n = 384, which bounds NS.)"""
    import pinocchio as pin

    model = pin.buildModelFromXML(to_urdf(chain(n)))
    data = model.createData()
    q, v, tau = (x[0] for x in states(n, 1))
    accelerations = np.array(pin.aba(model, data, q, v, tau))
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        pin.aba(model, data, q, v, tau)
        samples.append(time.perf_counter() - start)
    return statistics.median(samples), accelerations


def reproduce(out: Path, quick: bool = False) -> dict:
    """Time every size, write out/tree-scaling.json and out/tree-scaling.png, return the JSON."""
    from mbjax_harness.plot.trees import tree_scaling_figure

    ns = QUICK_NS if quick else NS
    repeats, budget = (3, 0.3) if quick else (15, 2.0)
    data = {"n": list(ns), "recursive_s": [], "dense_s": []}
    with_pinocchio = peers.available("pinocchio")
    if with_pinocchio:
        data["pinocchio_aba_s"] = []
    for n in ns:
        model = chain(n)
        q, v, tau = (jnp.asarray(x[0]) for x in states(n, 1))
        accelerations = {}
        for method in ("recursive", "dense"):
            accelerations[method], timing = timed(looped_fn(method, loop_length(n)), model, q, v,
                                                  tau, repeats=repeats, budget_s=budget)
            data[f"{method}_s"].append(timing.run_s / loop_length(n))
        if with_pinocchio:
            seconds, accelerations["Pinocchio"] = pinocchio_aba_time(n, 20 if quick else 200)
            data["pinocchio_aba_s"].append(seconds)
        check_agreement(n, accelerations)
        print(f"n = {n:4d}: " + "  ".join(f"{k} {data[k][-1] * 1e6:10.1f} us"
                                           for k in data if k != "n"))
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1))
    tree_scaling_figure(data).savefig(out / f"{NAME}.png", dpi=120)
    return data
