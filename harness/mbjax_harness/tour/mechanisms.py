"""The tour's mechanisms: closed loops, the spin-up beam (flexible bodies), the Carpal Wrist."""

import time
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness.timing import measure
from mbjax.integrate import simulate, solve_reference
from mbjax_harness.tour._common import _animate, _max_abs, _save


LOOP_STEPS = (4e-3, 2e-3, 1e-3)
QUICK_LOOP_STEPS = (2e-3,)
QUICK_LOOP_SYSTEMS = ("coupled, none", "coupled, projection", "O(n + m^3), none")


def closed_loops_tour(out: Path, quick: bool) -> dict:
    """Anderson 1993's closed chain: loop-closure methods' speed against accuracy. The chain has
    12 dof and 4 closure equations (`mbjax reproduce closed-chain` in small); the methods are the
    coupled multipliers (Jerkovsky 1978) with no stabilization, with Baumgarte's and with
    projection after every step, and Anderson 1993's O(n + m^3) route, the error being the largest
    joint-angle error after 1 s against an adaptive Dopri8 reference (rtol 1e-12), with the
    constraint residual |Phi| reached."""
    from mbjax.integrate import RK4
    from mbjax.loops import ClosedSystem, Coupled, Stabilized
    from mbjax_harness.plot.loops import closed_loops_tour_figure
    from mbjax.scenes import closed_chain as cc

    chain, q0, v0 = cc.build(12)
    duration = cc.DURATION
    saveat = np.linspace(0.0, duration, 51)
    ref = solve_reference(chain, q0, v0, jnp.asarray(saveat), rtol=1e-12, atol=1e-12)
    methods = {"coupled, none": (Coupled(), False),
               "coupled, baumgarte": (Coupled(baumgarte=(10.0, 10.0)), False),
               "coupled, projection": (Coupled(), True),
               "O(n + m^3), none": (Stabilized(), False)}
    if quick:
        methods = {name: methods[name] for name in QUICK_LOOP_SYSTEMS}
    systems = {name: ClosedSystem(chain.tree, chain.closures, method, projection)
               for name, (method, projection) in methods.items()}
    loops = chain.loops
    residual = jax.jit(jax.vmap(lambda q: jnp.linalg.norm(loops.phi(q))))
    runs, rows, drift = {}, {}, {}
    for name, system in systems.items():
        runs[name] = []
        for dt in QUICK_LOOP_STEPS if quick else LOOP_STEPS:
            sol, timing = measure(partial(simulate, system, RK4(), q0, v0, dt=dt, t1=duration,
                                          saveat=saveat), repeats=3)
            phi = np.asarray(residual(sol.qs))
            row = {"dt": dt, "error": _max_abs(np.asarray(sol.qs) - np.asarray(ref.qs)),
                   "residual": float(phi.max()), "seconds": timing.run_s}
            runs[name].append(row)
            rows[f"{name} dt={dt * 1e3:g} ms"] = {"error_rad": row["error"],
                                                  "residual": row["residual"],
                                                  "seconds": timing.run_s,
                                                  "status": sol.messages()[0]}
        drift[name] = (saveat, phi)
    fig = closed_loops_tour_figure(runs, drift, f"closed chain, 12 dof, {duration:g} s, RK4")
    _save(fig, out, "closed-loops.png")
    animation = _animate(out, "closed-loops", chain, saveat, ref.qs,
                         "closed chain (reference solution)", quick)
    return {"figure": "closed-loops.png", "animation": animation, "duration": duration,
            "reference_status": int(ref.status), "integrators": rows}


FLEX_MODES, QUICK_FLEX_MODES = (1, 2, 4), (2,)
FLEX_DURATION, QUICK_FLEX_DURATION = 10.0, 8.0
FLEX_DT, FLEX_REFERENCE_ELEMENTS = 2e-3, 4
FLEX_IMPLICIT_DT = 0.05
BEAM_MAGNIFICATION = 5


# a modal run agrees with the ANCF reference when its tip stays within this fraction of the
# reference's peak deflection over the whole run
FLEX_AGREEMENT = 0.1


def flexible_bodies_tour(out: Path, quick: bool) -> dict:
    """Kane's spin-up beam: modal models, stiffened or not, against an ANCF beam. As in Anderson
    1993 §3.2 (`mbjax reproduce spin-up-beam` in small), the modal model (RK4, 2 ms, Anderson
    1993's O(n + m^3) route) with 1, 2, 4 bending modes (quick: 2), each with and without
    geometric stiffening, runs against the geometrically nonlinear ANCF beam (4 elements): speed
    against accuracy, the error being the largest tip-deflection difference over the run.
    The window (10 s, quick 8 s) holds the peak lag (0.57 m at 6.8 s) and the unstiffened run's
    runaway as omega nears the first bending frequency (3.8 rad/s at 8.5 s). Stiffening is data in
    the flexible body, so each mode count compiles once for both runs. Then the most modes once
    more with the simplified implicit midpoint at 50 ms, 14 times RK4's limit (the axial mode's
    759 rad/s bounds RK4's step, not the tip's motion)."""
    from mbjax.integrate import ImplicitMidpoint
    from mbjax_harness.plot.flex import flexible_tour_figure
    from mbjax.scenes import spin_up_beam as sub

    duration = QUICK_FLEX_DURATION if quick else FLEX_DURATION
    saveat_every = 0.1
    runs, rows, histories, tips = [], {}, {}, {}
    for n_bending in QUICK_FLEX_MODES if quick else FLEX_MODES:
        for stiffening in (True, False):
            (ts, tip, _, sol), timing = measure(
                partial(sub.run, n_bending=n_bending, stiffening=stiffening, dt=FLEX_DT,
                        t1=duration, every=saveat_every), repeats=1)
            tips[(n_bending, stiffening)] = np.asarray(tip)
            name = f"{n_bending} mode{'s' * (n_bending != 1)}, " + ("stiffened" if stiffening
                                                                    else "no stiffening")
            histories[name] = (np.asarray(ts), np.asarray(tip))
            if stiffening:
                motion = (n_bending, np.asarray(ts), sol.qs)
            runs.append({"n_bending": n_bending, "stiffening": stiffening, "seconds": timing.run_s})
            rows[name] = {"seconds": timing.run_s, "compile_seconds": timing.compile_s,
                          "status": sol.messages()[0]}
    # the stiff modes stepped over: the simplified implicit midpoint at 14 times RK4's limit
    n_bending = max(QUICK_FLEX_MODES if quick else FLEX_MODES)
    (ts, tip, _, sol), timing = measure(
        partial(sub.run, n_bending=n_bending, dt=FLEX_IMPLICIT_DT, t1=duration, every=saveat_every,
                integrator=ImplicitMidpoint(simplified=True)), repeats=1)
    name = f"{n_bending} modes, stiffened, implicit midpoint {FLEX_IMPLICIT_DT * 1e3:g} ms"
    tips[name] = np.asarray(tip)
    histories[name] = (np.asarray(ts), np.asarray(tip))
    runs.append({"n_bending": n_bending, "stiffening": True, "seconds": timing.run_s,
                 "integrator": "implicit", "key": name})
    rows[name] = {"seconds": timing.run_s, "compile_seconds": timing.compile_s,
                  "status": sol.messages()[0], "dt": FLEX_IMPLICIT_DT}
    start = time.perf_counter()
    ref = sub.reference(n_elements=FLEX_REFERENCE_ELEMENTS, ts=np.asarray(ts))
    ref_seconds = time.perf_counter() - start
    ref_tip = np.asarray(ref.tip_deflection)
    ref_peak = float(ref_tip.min())
    for run, (name, row) in zip(runs, rows.items(), strict=True):
        tip = tips[run.get("key", (run["n_bending"], run["stiffening"]))]
        with np.errstate(invalid="ignore", over="ignore"):
            error = float(np.max(np.abs(tip - ref_tip)))
        run["error"] = error if np.isfinite(error) else float("inf")
        row["max_error_m"] = error if np.isfinite(error) else None
        row["peak_m"] = float(np.min(tip)) if np.all(np.isfinite(tip)) else None
        row["peak_relative_error"] = (abs(row["peak_m"] - ref_peak) / abs(ref_peak)
                                      if row["peak_m"] is not None else None)
        # the run's status is the integration's; whether the model follows the reference is a
        # verdict of its own (the unstiffened beam runs away, accurately integrated)
        row["against_reference"] = ("agrees" if run["error"] <= FLEX_AGREEMENT * abs(ref_peak)
                                    else "departs")
    fig = flexible_tour_figure(runs, histories, (np.asarray(ref.ts), ref_tip, FLEX_REFERENCE_ELEMENTS),
                               f"Kane's spin-up beam, {duration:g} s, RK4 {FLEX_DT * 1e3:g} ms: "
                               f"modal model against the ANCF beam ({ref_seconds:.0f} s)")
    _save(fig, out, "flexible-bodies.png")
    animation = _animate_beam(out, *motion, quick)
    return {"figure": "flexible-bodies.png", "animation": animation, "duration": duration,
            "dt": FLEX_DT,
            "reference": {"n_elements": FLEX_REFERENCE_ELEMENTS, "peak_m": ref_peak,
                          "seconds": ref_seconds},
            "runs": rows}


def carpal_wrist_tour(out: Path, quick: bool) -> dict:
    """The Carpal Wrist: each integrator's error and stability against the step. As in Canfield
    1997 §6.4, the chapter's explicit Euler (eq 6.45) and the foundation's integrators (quick: RK4
    only) run on the torque-free tool (error against RK4 at 0.1 ms, energy drift) and on the
    servoed wrist under gravity (stable or not), against the step; the run time of each method is
    per step of the free-motion runs (all steps vmapped in one call)."""
    from mbjax_harness.plot.wrist import integrator_figure
    from mbjax_harness.plot.animate import wrist_animation
    from mbjax_harness.reproduce import carpal_wrist as cwr
    from mbjax.scenes import carpal_wrist as cws

    seconds = {}
    # quick: the chapter's explicit Euler against RK4 only (each method compiles two wrist rollouts)
    methods = ("explicit_euler", "rk4") if quick else cwr.METHODS
    motion = {}
    rows, critical = cwr.integrator_study(cwr.QUICK_STEPS if quick else cwr.STEPS, seconds, methods,
                                          motion)
    fig = integrator_figure(rows, critical, seconds)
    _save(fig, out, "carpal-wrist.png")
    wrist_animation(out / "carpal-wrist.gif", cws.wrist(), motion["ts"], motion["qs"],
                    title="Carpal Wrist, torque-free tool", frames=30 if quick else 40)
    animation = "carpal-wrist.gif"
    table = {f"{r['name']} dt={r['dt'] * 1e3:g} ms": {k: r[k] for k in ("error", "energy_drift", "stable")}
             for r in rows}
    return {"figure": "carpal-wrist.png", "animation": animation, "integrators": table,
            "critical_dt": critical,
            "seconds_per_step": seconds}




def _animate_beam(out: Path, n_bending: int, ts, qs, quick: bool) -> str:
    """Write flexible-bodies.gif: the spun beam's centreline in the hub's rotating frame seen from
    above (21 points along it, the deformation magnified `BEAM_MAGNIFICATION` times, as the title
    says), q = (hub angle, modal coordinates)."""
    from mbjax.flex import centreline
    from mbjax_harness.plot.animate import stick_animation
    from mbjax.scenes import spin_up_beam as sub

    structure = sub.beam(sub.N_ELEMENTS)                # the mesh behind `sub.run`'s modes
    basis = sub.modes(structure, n_bending, 1)
    p = np.asarray(centreline(structure, basis, np.asarray(qs)[:, 1:], 21, BEAM_MAGNIFICATION))
    R = np.broadcast_to(np.eye(3), (*p.shape[:2], 3, 3))
    stick_animation(out / "flexible-bodies.gif", ts, R, p, [-1, *range(20)],
                    title=f"spin-up beam seen in the hub frame, deflection x{BEAM_MAGNIFICATION}",
                    triads=False, frames=30 if quick else 60, view=(90, -90))
    return "flexible-bodies.gif"
