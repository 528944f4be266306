"""`mbjax reproduce closed-chain`: a chain with both ends fixed under each stabilization. Its loop
is held by each stabilization, and unstabilized integration fails (Anderson 1993 §3.3, Fig. 8).

The (n/2)-body chain with both ends fixed (`mbjax.scenes.closed_chain`), simulated (RK4, 1 ms;
1 s for n <= 44, 0.1 s above, the time then scaled to 1 s) by Anderson 1993's O(n + m^3) route (`Stabilized()`: the O(n) recursion, m + 1
passes) and by the coupled Lagrange multipliers with the dense mass matrix, O(n^3)
(`Coupled()`, Jerkovsky 1978 eqs 89-93); run time of each after compilation (median of 3 calls), and
the largest difference between their joint angles over the run.

Then the constraint drift |Phi(q(t))| over 10 s of the 12-dof chain (1 ms steps) for no
stabilization, Baumgarte's (alpha = beta = 10 / s), projection onto Phi = 0 and A v + B = 0
after every step (all RK4) and Anderson 1993's epsilon-dynamics (`EPSILONS`): the paper's form
(loads started by eq 89), whose velocity error epsilon f_c makes Phi grow under gravity, and the
position feedback kappa, which bounds Phi by epsilon |f_c - f_c(0)| / kappa. The load equation
is stiff (explicit RK4 needs dt < 2.8 epsilon / max eig(A Gamma), and max eig(A Gamma) =
267 / s here), so the small epsilon of the full run uses the implicit midpoint rule.

JSON: {"n": [...], "recursive_s": [...], "dense_s": [...], "max_abs_diff": [...],
"drift": {"<method>": [[t, residual], ...], ...}, "drift_status": {"<method>":
{"error_estimate", "energy_drift", "status"}}}: each drift run's accuracy status (`simulate`
with the scenes' `TOLERANCE`; its energy is conserved, so a stabilization that works against
the motion shows in "energy_drift", and a residual above 1e-6 in "constraint violated").
"""

import json
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness.timing import measure
from mbjax.integrate import RK4, ImplicitMidpoint, simulate
from mbjax.loops import ClosedSystem, Coupled, Stabilized
from mbjax.scenes import TOLERANCE, closed_chain

NAME = "closed-chain"
NS = (4, 12, 20, 28, 36, 44, 100, 200, 400)
QUICK_NS = (4, 12, 28, 44)
DRIFT_N = 12
DRIFT_DURATION = 10.0
DRIFT_DT = 1e-3
# Anderson 1993's epsilon-dynamics: (epsilon, kappa, integrator). RK4 needs dt < 2.8 epsilon /
# max eig(A Gamma), 267 / s here; smaller epsilon takes the A-stable implicit midpoint rule.
EPSILONS = ((1.0, 0.0, "rk4"), (0.2, 0.0, "rk4"), (0.2, 10.0, "rk4"))
STIFF_EPSILONS = ((0.01, 10.0, "implicit_midpoint"),)       # full run only (about 5 min)


def timing(n: int, repeats: int) -> tuple[float, float, float]:
    """(recursive_s, dense_s, max_abs_diff) per 1 s of the n-dof chain."""
    chain, q0, v0 = closed_chain.build(n)
    window = closed_chain.DURATION if n <= 44 else 0.1 * closed_chain.DURATION
    run = partial(simulate, integrator=RK4(), q0=q0, v0=v0, dt=1e-3, t1=window,
                  saveat=np.linspace(0.0, window, 11))
    stabilized = ClosedSystem(chain.tree, chain.closures, Stabilized())
    recursive, t_rec = measure(partial(run, stabilized), repeats=repeats)
    dense, t_dense = measure(partial(run, chain), repeats=repeats)
    scale = closed_chain.DURATION / window
    return scale * t_rec.run_s, scale * t_dense.run_s, float(jnp.abs(recursive.qs - dense.qs).max())


def drift(duration: float, stiff: bool) -> dict:
    chain, q0, v0 = closed_chain.build(DRIFT_N)
    tree, closures, loops = chain.tree, chain.closures, chain.loops
    ts = np.linspace(0.0, duration, 101)
    runs = {"none": (chain, RK4()),
            "baumgarte": (ClosedSystem(tree, closures, Coupled(baumgarte=(10.0, 10.0))), RK4()),
            "projection": (ClosedSystem(tree, closures, Coupled(), projection=True), RK4())}
    for eps, kappa, integrator in EPSILONS + (STIFF_EPSILONS if stiff else ()):
        name = f"epsilon={eps:g}" + (f",kappa={kappa:g}" if kappa else "")
        runs[name] = (ClosedSystem(tree, closures, Stabilized(epsilon=eps, kappa=kappa)),
                      RK4() if integrator == "rk4" else ImplicitMidpoint())
    out, checks = {}, {}
    for name, (system, integrator) in runs.items():
        # The paper's eq 89 starts the loads from zero; with kappa the algebraic loads are used
        # so that the bound epsilon |f_c - f_c(0)| / kappa is about the load's change.
        u0 = system.initial_state(q0, v0, consistent=bool(getattr(system.method, "kappa", 0.0)))
        sol = simulate(system, integrator, q0, u0, dt=DRIFT_DT, t1=duration, saveat=ts,
                       **TOLERANCE)
        residual = jax.jit(jax.vmap(lambda q: jnp.linalg.norm(loops.phi(q))))(sol.qs)
        out[name] = [[float(t), float(r)] for t, r in zip(sol.ts, residual)]
        checks[name] = {"error_estimate": float(sol.error), "energy_drift": float(sol.drift),
                        "status": sol.messages()[0]}
    return out, checks


def reproduce(out: Path, quick: bool = False) -> dict:
    """Fig. 8 (quick: n up to 44) and the drift chart (quick: 2 s); writes JSON and PNG."""
    from mbjax_harness.plot.loops import closed_chain_figure

    ns = QUICK_NS if quick else NS
    rows = [timing(n, repeats=1 if quick else 3) for n in ns]
    drifts, checks = drift(2.0 if quick else DRIFT_DURATION, stiff=not quick)
    data = {"n": list(ns), "recursive_s": [r[0] for r in rows], "dense_s": [r[1] for r in rows],
            "max_abs_diff": [r[2] for r in rows],
            "drift": drifts, "drift_status": checks}
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1))
    closed_chain_figure(data).savefig(out / f"{NAME}.png", dpi=120)
    return data
