"""`mbjax reproduce integrators`: speed against accuracy of every integrator on the single body.

1. Torque-free symmetric body of Borri 1990 §8.1 (6 s, about 100 rad of rotation): error of the
   final rotation against the closed form (eqs 8.7-8.8) and run time, for each integrator over
   a range of steps: a work-precision chart and the fitted convergence orders.
2. Heavy top of Simo and Wong (10 s): relative energy drift against the step, where explicit
   Euler gains energy at every step, and the step at which RK4 goes unstable (bisection).
"""

import json
from functools import partial
from pathlib import Path

import jax.numpy as jnp
import numpy as np

from mbjax_harness.timing import measure
from mbjax.integrate import INTEGRATORS, simulate
from mbjax.scenes import TOLERANCE
from mbjax.scenes import heavy_top as top
from mbjax.scenes import torque_free_body as tfb

NAME = "integrators"

# Steps per integrator, each range reaching from visible error down to the asymptotic regime.
STEPS = {
    "explicit_euler": (1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5),
    "semi_implicit_euler": (1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5),
    "rk4": (0.3, 0.2, 0.1, 0.05, 0.02, 0.01, 5e-3, 2e-3, 1e-3),
    "implicit_midpoint": (0.2, 0.1, 0.05, 0.02, 0.01, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4),
    "rkmk4": (0.3, 0.2, 0.1, 0.05, 0.02, 0.01, 5e-3, 2e-3, 1e-3),
}
QUICK_STEPS = {
    "explicit_euler": (5e-5, 2e-5, 1e-5),
    "semi_implicit_euler": (5e-5, 2e-5, 1e-5),
    "rk4": (0.02, 0.01, 5e-3),
    "implicit_midpoint": (5e-3, 2e-3, 1e-3),
    "rkmk4": (0.02, 0.01, 5e-3),
}
TOP_STEPS = (0.1, 0.05, 0.02, 0.01, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4)
QUICK_TOP_STEPS = (0.02, 5e-3, 1e-3)
HISTORY_DT = 1e-3  # small enough that every method stays finite over the 10 s
# The asymptotic range used to fit orders: above round-off, below O(1) errors (in radians).
FIT_RANGE = (1e-10, 0.5)


def fit_order(dts, errors) -> float | None:
    """Slope of log(error) against log(dt) over the points inside FIT_RANGE (None if < 2)."""
    dts, errors = np.asarray(dts), np.asarray(errors)
    keep = np.isfinite(errors) & (errors > FIT_RANGE[0]) & (errors < FIT_RANGE[1])
    if keep.sum() < 2:
        return None
    return float(np.polyfit(np.log(dts[keep]), np.log(errors[keep]), 1)[0])


def relative_energy_drift(body, sol) -> float:
    """max |E/E0 - 1| over the saved states."""
    return float(jnp.max(jnp.abs(body.relative_energy_error(sol.qs, sol.vs))))


def torque_free_sweep(steps: dict, repeats: int) -> list[dict]:
    body, q0, u0 = tfb.build()
    saveat = np.linspace(0.0, tfb.DURATION, 11)
    records = []
    for name, dts in steps.items():
        integrator = INTEGRATORS[name]()
        for dt in dts:
            sol, timing = measure(
                partial(simulate, body, integrator, q0, u0, dt=dt, t1=tfb.DURATION, saveat=saveat),
                repeats=repeats)
            # the accuracy status, from one more run (its estimate is not in the timing)
            checked = simulate(body, integrator, q0, u0, dt=dt, t1=tfb.DURATION, saveat=saveat,
                               **TOLERANCE)
            records.append({
                "integrator": name, "dt": dt,
                "error": float(tfb.rotation_error(body, sol.qs[-1], tfb.DURATION)),
                "seconds": timing.run_s, "compile_seconds": timing.compile_s,
                "energy_drift": relative_energy_drift(body, sol),
                "error_estimate": float(checked.error), "invariant_drift": float(checked.drift),
                "status": checked.messages()[0],
            })
    return records


def heavy_top_sweep(dts) -> list[dict]:
    body, q0, u0 = top.build()
    saveat = np.linspace(0.0, top.DURATION, 101)
    records = []
    for name, cls in INTEGRATORS.items():
        for dt in dts:
            sol = simulate(body, cls(), q0, u0, dt=dt, t1=top.DURATION, saveat=saveat,
                           **TOLERANCE)
            drift = relative_energy_drift(body, sol)
            records.append({"integrator": name, "dt": dt, "energy_drift": drift,
                            "stable": bool(np.isfinite(drift) and drift < 1.0),
                            "error_estimate": float(sol.error),
                            "invariant_drift": float(sol.drift), "status": sol.messages()[0]})
    return records


def stability_limit(name: str, n_low: int = 10, n_high: int = 10_000) -> float:
    """Largest stable step of an integrator on the heavy top over 10 s, by bisection on the step
    count (stable: finite, relative energy drift below 1)."""
    body, q0, u0 = top.build()
    integrator = INTEGRATORS[name]()

    def stable(n):
        sol = simulate(body, integrator, q0, u0, dt=top.DURATION / n, t1=top.DURATION,
                       saveat=[0.0, top.DURATION])
        drift = relative_energy_drift(body, sol)
        return bool(np.isfinite(drift) and drift < 1.0)

    if stable(n_low) or not stable(n_high):
        raise RuntimeError(f"{name}: the bracket [{n_low}, {n_high}] steps does not bound the limit")
    while n_high - n_low > 1:
        mid = (n_low + n_high) // 2
        n_low, n_high = (n_low, mid) if stable(mid) else (mid, n_high)
    return top.DURATION / n_high


def energy_histories(dt: float):
    """E(t)/E0 - 1 for every integrator on the heavy top, for the figure."""
    body, q0, u0 = top.build()
    saveat = np.linspace(0.0, top.DURATION, 201)
    out = {}
    for name, cls in INTEGRATORS.items():
        sol = simulate(body, cls(), q0, u0, dt=dt, t1=top.DURATION, saveat=saveat)
        out[name] = (np.asarray(sol.ts), np.asarray(body.relative_energy_error(sol.qs, sol.vs)))
    return out


def reproduce(out: Path, quick: bool = False) -> dict:
    """Run everything, write out/integrators.json and out/integrators.png, return the JSON."""
    from mbjax_harness.plot.integrators import integrators_figure

    results = torque_free_sweep(QUICK_STEPS if quick else STEPS, repeats=3 if quick else 5)
    orders = {name: fit_order([r["dt"] for r in results if r["integrator"] == name],
                              [r["error"] for r in results if r["integrator"] == name])
              for name in INTEGRATORS}
    top_records = heavy_top_sweep(QUICK_TOP_STEPS if quick else TOP_STEPS)
    data = {
        "scene": "torque-free symmetric body, Borri 1990 §8.1: J_t/J_a = 1.875, "
                 "Omega0 = (10, 0, 15) rad/s, 6 s; error = angle of R_num R_exact^T at 6 s",
        "results": results,
        "orders": orders,
        "expected_orders": {name: cls.order for name, cls in INTEGRATORS.items()},
        "heavy_top": {
            "scene": "Simo-Wong heavy top: J = diag(5, 5, 1), m g l = 20, W0 = (0, 0, 50), 10 s",
            "results": top_records,
            "rk4_stability_limit_dt": stability_limit("rk4"),
            "rkmk4_stability_limit_dt": stability_limit("rkmk4"),
            "explicit_euler_stable_dts": [r["dt"] for r in top_records
                                          if r["integrator"] == "explicit_euler" and r["stable"]],
        },
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1))
    integrators_figure(data, energy_histories(HISTORY_DT), HISTORY_DT).savefig(out / f"{NAME}.png", dpi=120)
    return data
