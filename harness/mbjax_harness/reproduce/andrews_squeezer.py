"""`mbjax reproduce andrews-squeezer`: Andrews' squeezing mechanism against the IVP test set.

The seven-body mechanism of Hairer & Wanner II §VII.7 (test set problem `andrews`), built from
mbjax bodies, revolute joints, three `PointOnLine()` cut joints, a spring and a motor torque
(`mbjax.scenes.andrews_squeezer`), integrated by RK4 with the coupled Lagrange multipliers
(`ClosedSystem` with `Coupled()`, Jerkovsky 1978 eqs 89-93) from the test set's initial values to t = 0.03 s, and compared
with the test set's reference solution (its `SOLN`, PSIDE at tolerance 1e-14).

Convergence: the error against the reference for several steps dt, and the difference from the
finest run (the self-convergence, which shows RK4's order 4 without the floor below). The error
against the reference stops falling near 1e-9 rad: integrating the test set's own index-1
equations with scipy's DOP853 (rtol = atol = 1e-13 ... 3e-14) and with RK4 at dt = 1e-6 gives the
same end state to about 1e-11, which differs from the published reference by 1.4e-9 in beta and
Theta (1e-10 relative), the floor of the published values.

Full run: dt = DT (5 us) and the study STEPS, plus the same run by projection after every step
(`projection=True`) and by Anderson 1993's O(n + m^3) route (`Stabilized()`);
quick: dt = QUICK_DT (10 us) and QUICK_STEPS, no second routes.

JSON: {"t", "q" (beta, Theta, gamma, Phi, delta, Omega, epsilon at t), "reference", "max_abs_error",
"seconds" (run time after compilation), "compile_seconds", "dt", "steps", "error_estimate"
(`simulate`'s step-doubling estimate of the end state's largest error, angles and rates),
"status" (the state held to 1e-7, relative or absolute),
"constraint_residual", "convergence": [{"dt", "steps", "max_abs_error", "diff_from_finest"}],
"observed_order", "history": {"t", "q"}, and (full run) "routes": {"projection", "stabilized"}
(largest difference from the plain run's end state)}.
"""

import json
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness.timing import measure
from mbjax.integrate import RK4, simulate
from mbjax.loops import Coupled, Stabilized
from mbjax.scenes import andrews_squeezer as scene

NAME = "andrews-squeezer"
STEPS_PER_SAVE = 60                       # the history: 61 states, every 0.5 ms
DT_STEPS = 6000                           # dt = 5 us: at the reference's own accuracy
QUICK_DT_STEPS = 3000                     # dt = 10 us: error 2.7e-9
STEPS = (300, 600, 1200, 3000, 6000, 12000)
QUICK_STEPS = (1000, 3000)


def run(system, steps: int, history: bool = True, repeats: int = 0, **tolerance):
    """(Solution, Timing or None): RK4 over [0, T1] in `steps` steps, saving the history (every
    T1 / STEPS_PER_SAVE) or only the end state. `repeats` > 0 times the run after compiling;
    `tolerance` (rtol, atol) asks `simulate` for its error estimate."""
    saveat = (np.linspace(0.0, scene.T1, STEPS_PER_SAVE + 1) if history else np.array([scene.T1]))
    q0, v0 = scene.from_testset(scene.Y0), jnp.zeros(7)

    def go():
        return simulate(system, RK4(), q0, v0, dt=scene.T1 / steps, t1=scene.T1, saveat=saveat,
                        **tolerance)

    if repeats:
        return measure(go, repeats=repeats)
    return jax.block_until_ready(go()), None


def end_error(sol) -> np.ndarray:
    """The end state in the test set's order minus the reference."""
    return np.asarray(scene.to_testset(sol.qs[-1])) - np.asarray(scene.REFERENCE)


def convergence(system, steps: tuple, known: dict) -> list[dict]:
    """Rows {dt, steps, max_abs_error, diff_from_finest} for each step count; `known` maps step
    counts already run to their end states (test set order)."""
    ends = dict(known)
    for n in steps:
        if n not in ends:
            ends[n] = np.asarray(scene.to_testset(run(system, n, history=False)[0].qs[-1]))
    finest = ends[max(steps)]
    reference = np.asarray(scene.REFERENCE)
    return [{"dt": scene.T1 / n, "steps": n,
             "max_abs_error": float(np.abs(ends[n] - reference).max()),
             "diff_from_finest": float(np.abs(ends[n] - finest).max())} for n in steps]


def observed_order(rows: list[dict]) -> float:
    """Slope of log(diff_from_finest) against log(dt) over the rows before the finest two (the
    finest is the yardstick, the next one is also hit by its error)."""
    rows = sorted(rows, key=lambda r: r["dt"])[2:]
    dt = np.log([r["dt"] for r in rows])
    diff = np.log([r["diff_from_finest"] for r in rows])
    return float(np.polyfit(dt, diff, 1)[0])


def reproduce(out: Path, quick: bool = False) -> dict:
    """Simulate, compare with the reference, study dt; write NAME.json and NAME.png."""
    from mbjax_harness.plot.mechanisms import andrews_figure

    squeezer = scene.build()
    system = squeezer.system(Coupled())
    steps = QUICK_DT_STEPS if quick else DT_STEPS
    sol, timing = run(system, steps, repeats=1 if quick else 3)
    # the accuracy status, from one more run (its estimate is not in the timing): the state to
    # 1e-7, relative or absolute (against 24000 steps the quick run's rates, up to 1400 rad/s,
    # are off by 1e-6 and its angles by 2e-9: 0.29 of that tolerance, estimated 0.54)
    checked = run(system, steps, history=False, rtol=1e-7, atol=1e-7)[0]
    q = np.asarray(scene.to_testset(sol.qs[-1]))
    rows = convergence(system, QUICK_STEPS if quick else STEPS, {steps: q})
    data = {"t": scene.T1, "q": q.tolist(), "reference": list(scene.REFERENCE),
            "max_abs_error": float(np.abs(end_error(sol)).max()), "seconds": timing.run_s,
            "compile_seconds": timing.compile_s, "dt": scene.T1 / steps, "steps": steps,
            "error_estimate": float(checked.error), "status": checked.messages()[0],
            "constraint_residual": float(jnp.linalg.norm(system.loops.phi(sol.qs[-1]))),
            "convergence": rows,
            "observed_order": observed_order(rows) if len(rows) >= 4 else None,
            "history": {"t": np.asarray(sol.ts).tolist(),
                        "q": np.asarray(scene.to_testset(sol.qs)).tolist()}}
    if not quick:
        routes = {"projection": squeezer.system(Coupled(), projection=True),
                  "stabilized": squeezer.system(Stabilized())}
        data["routes"] = {name: float(jnp.abs(run(other, steps)[0].qs[-1] - sol.qs[-1]).max())
                          for name, other in routes.items()}
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1))
    andrews_figure(data).savefig(out / f"{NAME}.png", dpi=120)
    return data
