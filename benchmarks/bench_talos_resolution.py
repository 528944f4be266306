"""Talos's step (`mbjax_harness.crocoddyl.gaits.talos_step`, Crocoddyl's biped example) at its
30 ms step and at 15 and 7.5 ms (the same timeline cut finer): whether the solution's
`inaccurate` status concerns the physical motion. Prints each solve's status, its step x rate
(`Result.resolution`), cost, and where the three solutions' CoM and soles differ from the
finest one's at common times.

    python benchmarks/bench_talos_resolution.py
"""

import time

import jax
import jax.numpy as jnp
import numpy as np

from mbjax.rigid import center_of_mass, frame_pose
from mbjax.trajopt import CROCODDYL_SCHEDULE, ILQR, solve
from mbjax_harness.crocoddyl.gaits import SOLES, talos_step

DT = 3e-2


def solved(scale: int) -> dict:
    example = talos_step(dt=DT / scale, step_knots=15 * scale, support_knots=4 * scale)
    problem = example.problem
    start = time.perf_counter()
    result = solve(problem, ILQR(iterations=200, **CROCODDYL_SCHEDULE), jnp.asarray(example.us0))
    jax.block_until_ready(result.us)
    model = problem.knots.knot(0, 0).system.tree.model
    points = {"CoM": jax.vmap(lambda q: center_of_mass(model, q))(result.qs)}
    for sole in SOLES:
        points[sole] = jax.vmap(lambda q, s=sole: frame_pose(model, q, s)[1])(result.qs)
    ts = np.round(np.r_[np.asarray(problem.times()), float(problem.times()[-1]) + DT / scale], 9)
    print(f"dt = {DT / scale * 1e3:.1f} ms: {result.messages()[0]}, step x rate "
          f"{float(result.resolution):.3f}, {int(result.iterations)} iterations, cost "
          f"{float(result.cost):.8g} ({time.perf_counter() - start:.0f} s with compiling)")
    return {"ts": ts, **{k: np.asarray(v) for k, v in points.items()}}


def main() -> None:
    runs = {scale: solved(scale) for scale in (1, 2, 4)}
    finest = runs[4]
    for scale in (1, 2):
        run = runs[scale]
        # each time's last state (after an impulse, which takes none), against the finest's
        own = np.searchsorted(run["ts"], run["ts"], side="right") - 1
        keep = own == np.arange(len(run["ts"]))
        at = np.searchsorted(finest["ts"], run["ts"][keep], side="right") - 1
        gaps = {k: np.abs(run[k][keep] - finest[k][at]).max() * 1e3 for k in ("CoM", *SOLES)}
        print(f"dt = {DT / scale * 1e3:.1f} ms against 7.5 ms, largest difference: "
              + ", ".join(f"{k} {v:.1f} mm" for k, v in gaps.items()))


if __name__ == "__main__":
    jax.config.update("jax_enable_x64", True)
    main()
