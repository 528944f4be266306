"""The tour's single bodies and chains: the torque-free body, the heavy top, the rigid chain, the
time elements' sleeping top."""

from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness.timing import measure
from mbjax.integrate import INTEGRATORS, simulate, solve_reference
from mbjax.scenes import TOLERANCE
from mbjax.scenes import heavy_top as top
from mbjax.scenes import rigid_chain as rc
from mbjax.scenes import torque_free_body as tfb
from mbjax_harness.tour._common import _animate, _animate_body, _animate_tops, _max_abs, _save


def torque_free_body_tour(out: Path, quick: bool) -> dict:
    """Every integrator against the closed form of Borri 1990 §8.1, one step size."""
    from mbjax_harness.plot.scenes import error_history_figure

    dt = 0.01 if quick else 0.005
    body, q0, u0 = tfb.build()
    saveat = np.linspace(0.0, tfb.DURATION, 121)
    histories, rows, motions = {}, {}, {}
    for name, cls in INTEGRATORS.items():
        sol, timing = measure(partial(simulate, body, cls(), q0, u0, dt=dt, t1=tfb.DURATION,
                                      saveat=saveat, **TOLERANCE), repeats=3)
        err = np.asarray(tfb.rotation_errors(body, sol.qs, sol.ts))
        histories[name] = (np.asarray(sol.ts), err)
        motions[name] = sol.qs
        rows[name] = {"final_error_rad": float(err[-1]), "error_estimate": float(sol.error),
                      "invariant_drift": float(sol.drift), "seconds": timing.run_s, "status": sol.messages()[0]}
    fig = error_history_figure(histories, f"torque-free body (Borri 1990 §8.1), dt = {dt} s: "
                               "rotation error against the closed form")
    _save(fig, out, "torque-free-body.png")
    animation = _animate_body(out, "torque-free-body", body, saveat, motions["rk4"],
                              "torque-free body (RK4)", quick)
    return {"figure": "torque-free-body.png", "animation": animation, "dt": dt, "integrators": rows}


def heavy_top_tour(out: Path, quick: bool) -> dict:
    """The Simo-Wong heavy top: each integrator's axis path and energy error."""
    from mbjax_harness.plot.scenes import heavy_top_figure

    dt = 2e-3 if quick else 1e-3
    duration = 5.0 if quick else top.DURATION
    body, q0, u0 = top.build()
    saveat = np.linspace(0.0, duration, 501)
    runs, rows, motions = {}, {}, {}
    symmetry_axis = jax.jit(jax.vmap(lambda q: body.rotation_matrix(q)[:, 2]))
    for name, cls in INTEGRATORS.items():
        sol, timing = measure(partial(simulate, body, cls(), q0, u0, dt=dt, t1=duration,
                                      saveat=saveat, **TOLERANCE), repeats=3)
        rel = np.asarray(body.relative_energy_error(sol.qs, sol.vs))
        axis = np.asarray(symmetry_axis(sol.qs))
        runs[name] = (np.asarray(sol.ts), axis, rel)
        motions[name] = sol.qs
        rows[name] = {"energy_drift": float(np.max(np.abs(rel))),
                      "error_estimate": float(sol.error), "invariant_drift": float(sol.drift),
                      "seconds": timing.run_s,
                      "status": sol.messages()[0]}
    fig = heavy_top_figure(runs, f"heavy top (Simo-Wong), dt = {dt * 1e3:g} ms, {duration:g} s")
    _save(fig, out, "heavy-top.png")
    animation = _animate_body(out, "heavy-top", body, saveat, motions["rkmk4"], "heavy top (RKMK4)",
                              quick)
    return {"figure": "heavy-top.png", "animation": animation, "dt": dt, "duration": duration,
            "integrators": rows}


# Steps of the rigid chain per integrator: from visible error down to about 1e-8 rad for RK4.
CHAIN_STEPS = {"rk4": (0.02, 0.01, 5e-3, 2e-3, 1e-3), "rkmk4": (0.01, 5e-3, 2e-3),
               "implicit_midpoint": (0.01, 5e-3, 2e-3)}
QUICK_CHAIN_STEPS = {"rk4": (0.02, 5e-3), "implicit_midpoint": (0.01,)}


def rigid_chain_tour(out: Path, quick: bool) -> dict:
    """A 7-link chain falling: three integrators' speed against accuracy. The chain is a
    `TreeSystem` (method "auto"), run by RK4, RKMK4 and implicit midpoint at a few steps, the
    error being the largest joint angle error at the end against an adaptive Dopri8 reference
    (rtol 1e-12). On a revolute chain the configuration space is a vector space, so RKMK4 is RK4
    and lands on the same points."""
    from mbjax_harness.plot.trees import rigid_chain_figure
    from mbjax.rigid import TreeSystem, forward_kinematics

    model, q0, v0 = rc.build()
    system = TreeSystem(model)
    route = type(system.method.resolve(model.nv)).__name__.lower()   # what Auto() runs here
    duration = 1.0 if quick else rc.DURATION
    saveat = np.linspace(0.0, duration, 11)
    ref = solve_reference(system, q0, v0, jnp.linspace(0.0, duration, 5), rtol=1e-12, atol=1e-12)
    runs, rows = {}, {}
    for name, dts in (QUICK_CHAIN_STEPS if quick else CHAIN_STEPS).items():
        runs[name] = []
        for dt in dts:
            sol, timing = measure(partial(simulate, system, INTEGRATORS[name](), q0, v0, dt=dt,
                                          t1=duration, saveat=saveat, **TOLERANCE), repeats=3)
            energy = system.relative_energy_error(sol.qs, sol.vs)
            row = {"dt": dt, "error": _max_abs(np.asarray(sol.qs)[-1] - np.asarray(ref.qs)[-1]),
                   "energy_error": _max_abs(energy),
                   "seconds": timing.run_s}
            runs[name].append(row)
            rows[f"{name} dt={dt * 1e3:g} ms"] = {"error_rad": row["error"],
                                                  "error_estimate": float(sol.error),
                                                  "invariant_drift": float(sol.drift),
                                                  "energy_error": row["energy_error"],
                                                  "seconds": timing.run_s, "status": sol.messages()[0]}

    @jax.jit
    @jax.vmap
    def points(q):
        R, p = forward_kinematics(model, q)
        tip = p[-1] + R[-1] @ jnp.array([0.0, 0.0, -rc.LINK_LENGTH])
        return jnp.concatenate([jnp.zeros((1, 3)), p[1:], tip[None]])

    snapshots = list(zip(np.asarray(ref.ts).tolist(), np.asarray(points(ref.qs)), strict=True))
    fig = rigid_chain_figure(snapshots, runs, f"{rc.N_LINKS}-link chain falling under gravity, "
                             f"{duration:g} s, forward dynamics \"{route}\"")
    _save(fig, out, "rigid-chain.png")
    frames = np.round(np.arange(0.0, duration + 1e-9, 0.02), 10)
    motion = simulate(system, INTEGRATORS["rk4"](), q0, v0, dt=5e-3, t1=duration, saveat=frames)
    animation = _animate(out, "rigid-chain", system, frames, motion.qs,
                         f"{rc.N_LINKS}-link chain falling", quick)
    return {"figure": "rigid-chain.png", "animation": animation, "duration": duration,
            "method": route,
            "reference_status": int(ref.status), "integrators": rows}


def time_elements_tour(out: Path, quick: bool) -> dict:
    """Borri 1990's time elements on a sleeping top: primal against mixed form. As in a shortened
    `mbjax reproduce top-long-run`, the primal form of eq 4.1 grows at the rate its transition
    matrix predicts, the mixed form of eq 4.9 keeps the physical tilt."""
    from mbjax_harness.plot.tfe import top_long_run_figure
    from mbjax_harness.reproduce import top_long_run as tlr

    duration = 20.0 if quick else 40.0
    runs = [tlr.run(name, form, quadrature, "steady", duration, repeats=1, rotations=True)
            for name, form, quadrature in tlr.FORMS if name in ("primal", "mixed")]
    animation = _animate_tops(out, runs, quick)
    data = {"scene": f"time elements: vertical top at {tlr.SPIN_RATIO:g} Omega_c, {tlr.NODES}-node "
                     f"elements {tlr.DT:g} s between nodes, {duration:g} s (Borri 1990 §6-7)",
            "physical": tlr.physical(duration), "runs": runs}
    _save(top_long_run_figure(data), out, "time-elements.png")
    return {"figure": "time-elements.png", "animation": animation, "duration": duration,
            "runs": {r["form"]: {k: r[k] for k in ("predicted_growth", "measured_growth", "max_tilt",
                                                   "seconds", "status")} for r in runs},
            "physical_max_tilt": float(np.max(data["physical"]["tilt"]))}
