"""`mbjax bench loops`: the closed-loop routes, speed against accuracy and scaling in n.

- Work-precision on Anderson 1993's closed chain (12 dof, 4 closure equations, 1 s, RK4): Jerkovsky 1978's
  coupled multipliers (velocity form with no stabilization, with Baumgarte's (10, 10), with
  projection after every step; the momentum form) and Anderson 1993's O(n + m^3) route, at the steps
  STEPS; error = largest joint-angle error over the run against an adaptive Dopri8 reference
  (rtol 1e-12), residual = largest |Phi|.
- Scaling (Anderson 1993 Fig. 8): run time of 1 s of simulation (1 ms steps; above n = 44 timed over
  0.1 s and scaled) for the O(n + m^3) and the dense O(n^3) routes, n = NS.

Compile and run times are separate (median after warm-up). No peer engine is measured here:
MuJoCo's equality constraints are soft (regularized), a different problem from the exact
closures of Jerkovsky 1978 and Anderson 1993. JSON lines + PNG.
"""

import platform
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness.timing import measure, write_jsonl
from mbjax.integrate import RK4, simulate, solve_reference
from mbjax.loops import ClosedSystem, Coupled, Momentum, Stabilized
from mbjax.scenes import closed_chain

NAME = "loops"
STEPS = (4e-3, 2e-3, 1e-3, 5e-4)
NS = (12, 28, 44, 100, 200, 400)


def routes(chain: ClosedSystem) -> dict:
    tree, closures = chain.tree, chain.closures
    return {"coupled": ClosedSystem(tree, closures, Coupled()),
            "coupled + baumgarte": ClosedSystem(tree, closures, Coupled(baumgarte=(10.0, 10.0))),
            "coupled + projection": ClosedSystem(tree, closures, Coupled(), projection=True),
            "momentum form": ClosedSystem(tree, closures, Momentum()),
            "O(n + m^3)": ClosedSystem(tree, closures, Stabilized())}


def work_precision(repeats: int, steps, names, common: dict) -> list[dict]:
    chain, q0, v0 = closed_chain.build(12)
    T = closed_chain.DURATION
    saveat = np.linspace(0.0, T, 21)
    ref = solve_reference(chain, q0, v0, jnp.asarray(saveat), rtol=1e-12, atol=1e-12)
    residual = jax.jit(jax.vmap(lambda q: jnp.linalg.norm(chain.loops.phi(q))))
    records = []
    for name, system in routes(chain).items():
        if name not in names:
            continue
        u0 = system.initial_state(q0, v0)
        for dt in steps:
            sol, timing = measure(partial(simulate, system, RK4(), q0, u0, dt=dt, t1=T,
                                          saveat=saveat), repeats=repeats)
            records.append({**common, "kind": "work-precision", "route": name, "n": 12, "dt": dt,
                            "duration": T, "compile_s": timing.compile_s, "run_s": timing.run_s,
                            "error": float(jnp.max(jnp.abs(sol.qs - ref.qs))),
                            "residual": float(jnp.max(residual(sol.qs))),
                            "status": sol.messages()[0]})
    return records


def scaling(repeats: int, ns, common: dict) -> list[dict]:
    records = []
    for n in ns:
        chain, q0, v0 = closed_chain.build(n)
        window = 1.0 if n <= 44 else 0.1
        qs = {}
        for name in ("O(n + m^3)", "coupled"):
            system = routes(chain)[name]
            sol, timing = measure(partial(simulate, system, RK4(), q0, v0, dt=1e-3, t1=window,
                                          saveat=[window]), repeats=repeats)
            qs[name] = sol.qs[-1]
            records.append({**common, "kind": "scaling", "route": name, "n": n, "dt": 1e-3,
                            "duration": window, "compile_s": timing.compile_s,
                            "run_s": timing.run_s, "run_s_per_simulated_s": timing.run_s / window,
                            "us_per_step": timing.run_s / round(window / 1e-3) * 1e6,
                            "status": sol.messages()[0]})
        difference = float(jnp.max(jnp.abs(qs["O(n + m^3)"] - qs["coupled"])))
        for r in records[-2:]:
            r["max_abs_diff"] = difference
    return records


def run(out: Path, quick: bool = False) -> list[dict]:
    common = {"machine": platform.machine(), "jax": jax.__version__}
    repeats = 1 if quick else 3
    names = ("coupled", "O(n + m^3)") if quick else tuple(routes(closed_chain.build(12)[0]))
    records = (work_precision(repeats, STEPS[1:3] if quick else STEPS, names, common)
               + scaling(repeats, NS[:2] if quick else NS, common))
    out.mkdir(parents=True, exist_ok=True)
    write_jsonl(out / f"{NAME}.jsonl", records)
    from mbjax_harness.plot.bench import loops_bench_figure
    loops_bench_figure(records).savefig(out / f"{NAME}.png", dpi=120)
    for r in records:
        extra = (f"error {r['error']:.3g} rad, |Phi| {r['residual']:.3g}" if r["kind"] == "work-precision"
                 else f"{r['run_s_per_simulated_s']:.3g} s per simulated s, diff {r['max_abs_diff']:.2g}")
        print(f"{r['kind']:14s} {r['route']:22s} n={r['n']:<4d} dt={r['dt']:<7.4g} "
              f"{r['run_s'] * 1e3:9.2f} ms (compile {r['compile_s']:5.1f} s)  {extra}  {r['status']}")
    return records
