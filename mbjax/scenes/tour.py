"""What `mbjax tour` runs for each scene: a short simulation, a figure and a few numbers.

Each entry takes (out, quick) and returns a summary dict naming the figure it wrote in out.
"""

from functools import partial
from pathlib import Path

import jax
import numpy as np

from mbjax.bench.timing import measure
from mbjax.integrate import INTEGRATORS, simulate
from mbjax.scenes import heavy_top as top
from mbjax.scenes import torque_free_body as tfb


def torque_free_body_tour(out: Path, quick: bool) -> dict:
    """Every integrator against the closed form of seed 000 §8.1, one step size."""
    from mbjax.plot.scenes import error_history_figure

    dt = 0.01 if quick else 0.005
    body, q0, u0 = tfb.build()
    saveat = np.linspace(0.0, tfb.DURATION, 121)
    histories, rows = {}, {}
    for name, cls in INTEGRATORS.items():
        sol, timing = measure(partial(simulate, body, cls(), q0, u0, dt=dt, t1=tfb.DURATION,
                                      saveat=saveat), repeats=3)
        err = np.asarray(tfb.rotation_errors(body, sol.qs, sol.ts))
        histories[name] = (np.asarray(sol.ts), err)
        rows[name] = {"final_error_rad": float(err[-1]), "seconds": timing.run_s,
                      "status": sol.messages()[0]}
    fig = error_history_figure(histories, f"torque-free body (seed 000 §8.1), dt = {dt} s: "
                               "rotation error against the closed form")
    fig.savefig(out / "torque-free-body.png", dpi=110)
    return {"figure": "torque-free-body.png", "dt": dt, "integrators": rows}


def heavy_top_tour(out: Path, quick: bool) -> dict:
    """The Simo-Wong top: path of the symmetry axis and energy error of each integrator."""
    from mbjax.plot.scenes import heavy_top_figure

    dt = 2e-3 if quick else 1e-3
    duration = 5.0 if quick else top.DURATION
    body, q0, u0 = top.build()
    saveat = np.linspace(0.0, duration, 501)
    runs, rows = {}, {}
    for name, cls in INTEGRATORS.items():
        sol, timing = measure(partial(simulate, body, cls(), q0, u0, dt=dt, t1=duration,
                                      saveat=saveat), repeats=3)
        rel = np.asarray(body.relative_energy_error(sol.qs, sol.us))
        axis = np.asarray(jax.vmap(lambda q: body.rotation_matrix(q)[:, 2])(sol.qs))
        runs[name] = (np.asarray(sol.ts), axis, rel)
        rows[name] = {"energy_drift": float(np.max(np.abs(rel))),
                      "seconds": timing.run_s, "status": sol.messages()[0]}
    fig = heavy_top_figure(runs, f"heavy top (Simo-Wong), dt = {dt * 1e3:g} ms, {duration:g} s")
    fig.savefig(out / "heavy-top.png", dpi=110)
    return {"figure": "heavy-top.png", "dt": dt, "duration": duration, "integrators": rows}


TOUR = {
    "torque-free-body": torque_free_body_tour,
    "heavy-top": heavy_top_tour,
}
