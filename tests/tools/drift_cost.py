"""The default drift check over the tour's scenes: which systems have invariants, their drift,
the status, and what the check costs (compile + run of `simulate`'s first call, with the check
and without it). Run as `python tests/tools/drift_cost.py [--quick]`; prints a table.

"without" replaces the check's program by nothing (`simulate` as it was before the check ran
by default); each timing starts from empty caches (`jax.clear_caches`), so it includes the
rollout's compile; no persistent compilation cache is used. The machine's noise is tens of
percent: compare the columns of one row.
"""

import argparse
import os
import sys
import time

os.environ.setdefault("JAX_ENABLE_X64", "1")

import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402

jax.config.update("jax_enable_x64", True)

import mbjax  # noqa: E402
from mbjax.integrate import RK4  # noqa: E402
from mbjax.model import chain  # noqa: E402
from mbjax.rigid import TreeSystem  # noqa: E402
from mbjax import scenes  # noqa: E402

SIMULATE = sys.modules["mbjax._src.integrate.simulate"]


def cases(quick: bool) -> dict:
    """name -> (system, q0, u0, dt, t1, saveat): the tour's simulate calls, by default check."""
    out = {}
    model, q0, v0 = scenes.rigid_chain.build()
    duration = 1.0 if quick else scenes.rigid_chain.DURATION
    for dt in (0.02, 5e-3):
        out[f"rigid chain RK4 dt={dt:g}"] = (TreeSystem(model), q0, v0, dt, duration,
                                             np.linspace(0.0, duration, 11))
    out["rigid chain animation dt=0.005"] = (TreeSystem(model), q0, v0, 5e-3, duration,
                                             np.round(np.arange(0.0, duration + 1e-9, 0.02), 10))
    body, q0, u0 = scenes.torque_free_body.build()
    out["torque-free body dt=0.005"] = (body, q0, u0, 5e-3, scenes.torque_free_body.DURATION,
                                        np.linspace(0.0, scenes.torque_free_body.DURATION, 121))
    body, q0, u0 = scenes.heavy_top.build()
    duration = 5.0 if quick else scenes.heavy_top.DURATION
    out["heavy top dt=0.001"] = (body, q0, u0, 1e-3, duration, np.linspace(0.0, duration, 501))
    system, q0, v0 = scenes.closed_chain.build(12)
    out["closed chain (12) dt=0.002"] = (system, q0, v0, 2e-3, scenes.closed_chain.DURATION,
                                         np.linspace(0.0, scenes.closed_chain.DURATION, 51))
    from mbjax.loops import ClosedSystem, Coupled, Stabilized
    for label, method, projection in (("baumgarte", Coupled(baumgarte=(10.0, 10.0)), False),
                                      ("projection", Coupled(), True),
                                      ("O(n + m^3)", Stabilized(), False)):
        out[f"closed chain (12) {label} dt=0.004"] = (
            ClosedSystem(system.tree, system.closures, method, projection), q0, v0, 4e-3,
            scenes.closed_chain.DURATION, np.linspace(0.0, scenes.closed_chain.DURATION, 51))
    system, q0, u0 = scenes.carpal_wrist.free_motion()
    out["carpal wrist free dt=0.001"] = (system, q0, u0, 1e-3, scenes.carpal_wrist.FREE_DURATION,
                                         None)
    system, q0, v0 = scenes.four_bar.build()
    out["four-bar dt=0.002"] = (system, q0, v0, 2e-3, 2.0, None)
    system, q0, v0 = scenes.slider_crank.build(driven=False)
    out["slider-crank free dt=0.001"] = (system, q0, v0, 1e-3, 1.0, None)
    system, q0, v0 = scenes.bricard.build(phi_dot0=1.0)
    out["bricard dt=0.002"] = (system, q0, v0, 2e-3, 2.0 if quick else scenes.bricard.DURATION,
                               None)
    arm = scenes.arm.model()
    out["arm7 falling (models tour)"] = (TreeSystem(arm), jnp.asarray(scenes.arm.Q_REF),
                                         jnp.zeros(arm.nv), scenes.arm.DT, 1.5,
                                         np.round(np.arange(0.0, 1.5 + 0.005, 0.01), 10))
    system, q0, u0 = scenes.arm.build()
    out["arm7 servo (controls tour)"] = (system, q0, u0, scenes.arm.DT, 1.0, None)
    ant = mbjax.load_mjcf(mbjax.data.ANT)
    out["ant free fall (floating)"] = (TreeSystem(ant), ant.neutral(), 0.1 * jnp.ones(ant.nv),
                                       2e-3, 0.5, None)
    q0 = jnp.full(7, 0.4)
    for dt in (0.04, 5e-3):
        out[f"chain(7) q0=0.4 dt={dt:g}, 10 s (issue 60)"] = (TreeSystem(chain(7)), q0,
                                                              jnp.zeros(7), dt, 10.0, None)
    return out


def _first_call(system, q0, u0, dt, t1, saveat):
    jax.clear_caches()
    start = time.perf_counter()
    sol = mbjax.simulate(system, RK4(), q0, u0, dt=dt, t1=t1, saveat=saveat)
    jax.block_until_ready(sol)
    return sol, time.perf_counter() - start


def measure(quick: bool = False) -> list[dict]:
    """One row per case: drift, status, first-call seconds with and without the check."""
    rows = []
    check = SIMULATE._drift
    for name, (system, q0, u0, dt, t1, saveat) in cases(quick).items():
        try:
            SIMULATE._drift = lambda *args, **kwargs: None
            _, without = _first_call(system, q0, u0, dt, t1, saveat)
        finally:
            SIMULATE._drift = check
        sol, with_check = _first_call(system, q0, u0, dt, t1, saveat)
        rows.append(dict(name=name, invariants=", ".join(sol.invariant_names) or "none",
                         drift=float(sol.drift), status=sol.messages()[0],
                         without=without, with_check=with_check))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="the tour's quick durations")
    args = parser.parse_args()
    print(f"default drift limit {SIMULATE.DEFAULT_DRIFT_LIMIT:g}")
    print("| scene | invariants | drift | status | first call without check [s] | with [s] |"
          " check [s] |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for r in measure(args.quick):
        print(f"| {r['name']} | {r['invariants'][:40]} | {r['drift']:.3g} | {r['status'][:70]} | "
              f"{r['without']:.2f} | {r['with_check']:.2f} | {r['with_check'] - r['without']:+.2f} |",
              flush=True)


if __name__ == "__main__":
    main()
