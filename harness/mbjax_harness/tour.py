"""What `mbjax tour` runs for each scene: a short simulation, a figure and a few numbers.

Each entry takes (out, quick) and returns a summary dict naming the figure it wrote in out. A
scene that compares with a peer engine (MuJoCo, Pinocchio) records each one under "peers", with
the status "compared" or why not ("unavailable: mujoco is not installed", "failed: ..."): the
command's closing line names the peers skipped from there, and the scene's figure and "what to
look at" sentence say what was not compared (`look_at`).

The first sentence of each scene's docstring is its line in `mbjax tour --list`.
"""

import os
import time
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

import mbjax
from mbjax_harness import peers
from mbjax_harness.timing import measure
from mbjax.integrate import INTEGRATORS, simulate, solve_reference
from mbjax.scenes import TOLERANCE
from mbjax.scenes import heavy_top as top
from mbjax.scenes import rigid_chain as rc
from mbjax.scenes import torque_free_body as tfb


def _max_abs(x) -> float:
    """max |x| of an array, in NumPy (outside jit a JAX reduction compiles a program)."""
    return float(np.max(np.abs(np.asarray(x))))


def _save(fig, out: Path, name: str) -> str:
    """Write fig as out/name; with MBJAX_LINT_FIGURES set (the tests set it), first check that
    it reads (`mbjax_harness.plot.style.lint`: two labelled ticks on every log axis, a legend
    wherever several lines are drawn) and raise naming what does not."""
    fig.savefig(out / name, dpi=110)
    if os.environ.get("MBJAX_LINT_FIGURES"):
        from mbjax_harness.plot.style import lint

        problems = lint(fig)
        if problems:
            raise AssertionError(f"{name}: " + "; ".join(problems))
    return name


def _peer(name: str, compares: str, compute):
    """(value, record) of a comparison with peer engine `name`: compute()'s value and
    {"status": "compared", "compares": compares}, or None and the status saying why not: the
    peer is not installed (`mbjax_harness.peers.missing`), or it raised (a peer's failure is
    reported, not the scene's)."""
    why = peers.missing(name)
    if why is not None:
        return None, {"status": why, "compares": compares}
    try:
        value = compute()
    except Exception as error:  # noqa: BLE001 (any failure of the peer's run is reported)
        return None, {"status": f"failed: {type(error).__name__}: {error}"[:300],
                      "compares": compares}
    return value, {"status": "compared", "compares": compares}


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
        rel = np.asarray(body.relative_energy_error(sol.qs, sol.us))
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
            energy = system.relative_energy_error(sol.qs, sol.us)
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


def controls_tour(out: Path, quick: bool) -> dict:
    """A URDF arm under a servo and sampled torques, with jax.grad through it. The 7-dof arm
    (`mbjax.scenes.arm`) is held by a PD servo with gravity feed-forward and pushed at its
    flange for 0.1 s; driven by a torque history sampled per step as MuJoCo applies it, against
    `mujoco.rollout` (when installed); and `jax.grad` of a reach loss with respect to a torque
    spline's knots and a link mass is checked against central differences."""

    from mbjax.control import ZeroOrderHold
    from mbjax_harness.plot.scenes import controls_figure
    from mbjax.rigid import TreeSystem
    from mbjax.scenes import arm as scene

    arm = scene.model()
    duration = 0.5 if quick else 1.0
    ts = np.linspace(0.0, duration, 51)                     # every 5 steps
    q0, v0 = jnp.asarray(scene.Q_REF), jnp.zeros(arm.nv)
    run = partial(simulate, integrator=INTEGRATORS["rk4"](), q0=q0, u0=v0, dt=scene.DT, t1=duration,
                  saveat=ts)
    held = run(TreeSystem(arm, scene.servo(arm)))
    pushed, timing = measure(partial(run, scene.pushed(arm)), repeats=3)
    track = jax.jit(jax.vmap(lambda q: scene.flange(arm, q)))
    displacement = np.asarray(track(pushed.qs) - track(held.qs))

    steps = 200
    history = np.random.default_rng(0).normal(0.0, 5.0, (steps, 3))
    sampled = simulate(TreeSystem(arm, ZeroOrderHold(history, scene.DT), actuation=[1, 3, 5]),
                       INTEGRATORS["rk4"](), q0, v0, dt=scene.DT, t1=steps * scene.DT,
                       saveat=[steps * scene.DT])
    mujoco_diff, mujoco = _peer(
        "mujoco", "the sampled-torque run against mujoco.rollout",
        lambda: _max_abs(_mujoco_sampled(arm, scene.Q_REF, history, [1, 3, 5], scene.DT, steps)
                         - np.asarray(sampled.qs[-1])))

    horizon = 100 if quick else 250
    knots, mass = 0.5 * jnp.ones((6, 7)), arm.mass[3]
    loss = jax.jit(lambda k, m: scene.reach_loss(arm, k, m, horizon))
    grads, grad_timing = measure(jax.jit(jax.grad(loss, argnums=(0, 1))), knots, mass, repeats=3)
    h = 1e-4            # the loss is about 60: smaller steps drown in its round-off
    fd_knot = float(loss(knots.at[2, 1].add(h), mass) - loss(knots.at[2, 1].add(-h), mass)) / (2 * h)
    fd_mass = float(loss(knots, mass + h) - loss(knots, mass - h)) / (2 * h)
    checks = {"d loss / d knot[2, 1]": (float(grads[0][2, 1]), fd_knot),
              "d loss / d mass of link 4": (float(grads[1]), fd_mass)}
    rows = {name: {"jax_grad": g, "central_difference": fd,
                   "relative_difference": abs(g - fd) / abs(fd)} for name, (g, fd) in checks.items()}
    sampled_note = (f"sampled control vs mujoco.rollout: {mujoco_diff:.1e} rad"
                    if mujoco_diff is not None else
                    f"sampled control not compared ({peers.note('mujoco', mujoco['status'])})")
    fig = controls_figure(np.asarray(ts), np.asarray(pushed.qs - q0), displacement, checks,
                          f"7-dof arm (mbjax.data.ARM7), PD servo + gravity feed-forward, RK4 "
                          f"{scene.DT * 1e3:g} ms; {sampled_note}")
    _save(fig, out, "controls.png")
    animation = _animate(out, "controls", TreeSystem(arm), ts, pushed.qs,
                         "arm under a PD servo, pushed at its flange", quick)
    return {"figure": "controls.png", "animation": animation, "duration": duration,
            "runs": {"pushed": {"peak_flange_displacement_m": float(np.abs(displacement).max()),
                                "seconds": timing.run_s, "status": pushed.messages()[0]},
                     "sampled": {"max_abs_diff_mujoco_rad": mujoco_diff,
                                 "status": sampled.messages()[0]}},
            "gradients": rows, "grad_seconds": grad_timing.run_s,
            "grad_compile_seconds": grad_timing.compile_s, "peers": {"mujoco": mujoco}}


def _mujoco_sampled(arm, q0, history, actuated, dt, steps):
    """The final qpos of `mujoco.rollout` with `history` as qfrc_applied on `actuated` and RK4
    (MuJoCo installed: `_peer` asks first)."""
    import mujoco
    from mujoco import rollout

    from mbjax.model import to_urdf

    mj = mujoco.MjModel.from_xml_string(to_urdf(arm))
    mj.opt.timestep, mj.opt.integrator = dt, mujoco.mjtIntegrator.mjINT_RK4
    mj.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT     # limits: data in mbjax
    data = mujoco.MjData(mj)
    data.qpos[:] = q0
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(mj, spec))
    mujoco.mj_getState(mj, data, state, spec)
    qfrc = np.zeros((steps, mj.nv))
    qfrc[:, actuated] = history
    out, _ = rollout.rollout(mj, data, state[None], qfrc[None],
                             control_spec=mujoco.mjtState.mjSTATE_QFRC_APPLIED)
    return out[0, -1, 1:1 + mj.nq]


def models_tour(out: Path, quick: bool) -> dict:
    """A URDF arm as a user brings it: frames, joint limits, peers' dynamics. The arm
    (`mbjax.data.ARM7`) has its links and fixed joints as named frames, the flange's pose and
    Jacobian by name, its joint limits as data that `simulate`'s status checks (the unpowered arm
    falls through them), and the same arm through MuJoCo's compiler (`mbjax.model.from_mujoco`)
    and Pinocchio, when installed, against their dynamics."""
    from mbjax_harness.plot.scenes import models_figure
    from mbjax.rigid import TreeSystem, frame_jacobian, frame_pose
    from mbjax.scenes import arm as scene

    arm = scene.model()
    duration = 0.6 if quick else 1.5
    ts = np.round(np.arange(0.0, duration + 0.005, 0.01), 10)     # on the 2 ms step grid
    q0 = jnp.asarray(scene.Q_REF)
    fall = simulate(TreeSystem(arm), INTEGRATORS["rk4"](), q0, jnp.zeros(arm.nv), dt=scene.DT,
                    t1=duration, saveat=ts)
    flange = jax.jit(jax.vmap(lambda q: frame_pose(arm, q, "flange")[1]))(fall.qs)
    # how far each saved state lies beyond the arm's position and velocity limits (`Model.lower`,
    # `upper`, `velocity_limit`; what `simulate`'s status checks)
    qs, us = np.asarray(fall.qs), np.asarray(fall.us)
    beyond = np.concatenate([np.maximum(np.asarray(arm.lower) - qs, 0.0)
                             + np.maximum(qs - np.asarray(arm.upper), 0.0),
                             np.maximum(np.abs(us) - np.asarray(arm.velocity_limit), 0.0)], axis=1)
    first = int(np.argmax(np.asarray(beyond).max(axis=1) > 0))
    J = frame_jacobian(arm, q0, "flange")
    manipulability = float(jnp.sqrt(jnp.linalg.det(J[3:] @ J[3:].T)))
    compared = _model_peers()
    fig = models_figure(np.asarray(ts), np.asarray(fall.qs), np.asarray(arm.lower),
                        np.asarray(arm.upper), np.asarray(flange), compared,
                        f"{len(arm.frame_names)} named frames; status: {fall.messages()[0]}")
    _save(fig, out, "models.png")
    animation = _animate(out, "models", TreeSystem(arm), ts, fall.qs,
                         "the URDF arm falling unpowered", quick)
    return {"figure": "models.png", "animation": animation, "frames": list(arm.frame_names),
            "flange_at_start_m": np.asarray(flange[0]).tolist(),
            "flange_manipulability": manipulability, "status": fall.messages()[0],
            "first_limit_exceeded_s": float(ts[first]) if np.asarray(beyond).any() else None,
            "peers": compared}


def trajectory_optimisation_tour(out: Path, quick: bool) -> dict:
    """The 7-dof arm's reach solved by iLQR: cost, flange approach and torques. The problem
    (`mbjax.scenes.arm.reach_problem`) asks the flange 0.4 m sideways at rest after 1 s, in
    100 knots of 0.01 s; iLQR (`mbjax.trajopt`) starts from the torques that hold the start
    pose."""
    from mbjax_harness.plot.trajopt import reach_figure
    from mbjax.scenes import arm
    from mbjax.trajopt import ILQR, solve

    problem = arm.reach_problem()
    result, timing = measure(partial(solve, problem, ILQR(), arm.hold(problem)), repeats=3)
    model = problem.system.model
    target = np.asarray(arm.reach_target(model))
    flange = np.asarray(jax.jit(jax.vmap(lambda q: arm.flange(model, q)))(result.qs))
    iterations = int(result.iterations)
    ts = np.arange(problem.horizon + 1) * problem.dt
    error = float(np.linalg.norm(flange[-1] - target))
    fig = reach_figure(np.asarray(result.costs)[:iterations + 1], ts, flange, target,
                       np.asarray(result.us),
                       f"arm reach by iLQR: {iterations} iterations in {timing.run_s:.2f} s, "
                       f"final error {error:.1e} m ({result.messages()[0]})")
    _save(fig, out, "trajectory-optimisation.png")
    animation = _animate(out, "trajectory-optimisation", problem.system, ts, result.qs,
                         "arm reach by iLQR", quick)
    return {"figure": "trajectory-optimisation.png", "animation": animation,
            "runs": {"ilqr": {"iterations": iterations, "seconds": timing.run_s,
                              "compile_seconds": timing.compile_s, "final_error_m": error,
                              "cost": float(result.cost), "status": result.messages()[0]}}}


def floating_base_tour(out: Path, quick: bool) -> dict:
    """Crocoddyl's quadrotor solved by iLQR on SE(3): cost, path and thrusts. The hector
    quadrotor (`mbjax_harness.crocoddyl_examples`) is a free base driven by four thrusters
    through an actuation matrix, its thrusts bounded to [0.1, 5] N, flown from hover 1 m over
    and 1 m up in 33 knots of 0.03 s."""
    from mbjax_harness.crocoddyl_examples import TARGET, hector, quadrotor_problem
    from mbjax_harness.plot.trajopt import floating_base_figure
    from mbjax.trajopt import ILQR, solve

    model = hector()
    problem, us0 = quadrotor_problem(model, bounded=True)
    result, timing = measure(partial(solve, problem, ILQR(), jnp.asarray(us0)), repeats=3)
    iterations = int(result.iterations)
    ts = np.arange(problem.horizon + 1) * problem.dt
    qs = np.asarray(result.qs)
    # the pose left to go: the SE(3) logarithm of the target's inverse times the last pose
    goal = np.r_[TARGET, 1.0, 0.0, 0.0, 0.0]
    left = np.asarray(model.difference(jnp.asarray(goal), jnp.asarray(qs[-1])))
    pitch = np.asarray(jax.vmap(lambda q: model.difference(model.neutral(), q))(qs))[:, 1]
    fig = floating_base_figure(
        np.asarray(result.costs)[:iterations + 1], ts, qs[:, :3], pitch, np.asarray(result.us),
        (float(problem.lower[0]), float(problem.upper[0])), TARGET,
        f"quadrotor by iLQR on SE(3): {iterations} iterations in {timing.run_s:.2f} s, "
        f"{np.linalg.norm(left[3:]):.1e} m and {np.linalg.norm(left[:3]):.1e} rad from the target "
        f"({result.messages()[0]})")
    _save(fig, out, "floating-base.png")
    animation = _animate(out, "floating-base", problem.system, ts, result.qs,
                         "quadrotor by iLQR", quick)
    return {"figure": "floating-base.png", "animation": animation,
            "runs": {"ilqr": {"iterations": iterations, "seconds": timing.run_s,
                              "compile_seconds": timing.compile_s,
                              "final_position_error_m": float(np.linalg.norm(left[3:])),
                              "final_rotation_error_rad": float(np.linalg.norm(left[:3])),
                              "thrust_range_n": [float(np.min(result.us)),
                                                 float(np.max(result.us))],
                              "cost": float(result.cost), "status": result.messages()[0]}}}


def legged_gait_tour(out: Path, quick: bool) -> dict:
    """ANYmal's trot by iLQR through contact: forces in their cones, and FDDP. The
    trot of Crocoddyl's example (`mbjax_harness.crocoddyl_gaits.anymal_trot`: the diagonal
    pairs of feet step 0.25 m in turn, a multi-phase problem of stances and touchdown impulses)
    solved from its quasi-static guess; the ground's force on each foot along the solution; the
    same problem solved by Crocoddyl's FDDP from the same guess where Crocoddyl is installed."""
    from mbjax.trajopt import CROCODDYL_SCHEDULE, ILQR, knot_wrenches, solve
    from mbjax_harness.crocoddyl_gaits import FEET, MU, anymal_trot
    from mbjax_harness.plot.animate import gait_animation
    from mbjax_harness.plot.trajopt import gait_figure

    # ANYmal's URDF and its standing pose (SRDF) come from example-robot-data, through Pinocchio
    needs = {name: peers.missing(name) for name in ("example_robot_data", "pinocchio")}
    if any(needs.values()):
        return _without_robot(out, {name: {"status": why, "compares": "ANYmal's URDF and pose"}
                                    for name, why in needs.items() if why})
    example = anymal_trot()         # 56 knots: the compile, not the knots, is the cost
    problem, us0 = example.problem, jnp.asarray(example.us0)
    result, timing = measure(partial(solve, problem, ILQR(iterations=100, **CROCODDYL_SCHEDULE),
                                     us0), repeats=1)
    iterations = int(result.iterations)
    xs = jnp.concatenate([result.qs, result.vs], axis=1)
    forces = np.asarray(knot_wrenches(problem, xs, result.us))[..., 3:]
    ts = np.asarray(problem.times())
    histories = {"mbjax iLQR": np.asarray(result.costs)[:iterations + 1]}

    def fddp():
        from mbjax_harness.bench.trajopt import CrocoddylSolver

        croc = example.crocoddyl()
        to_croc = example.controls(croc)
        solver = CrocoddylSolver(croc, to_croc(example.us0))
        history = solver.history()
        start = time.perf_counter()
        solver.solve(100)
        seconds = time.perf_counter() - start
        us = to_croc(result.us)
        return {"iterations": int(solver.solver.iter), "seconds": seconds,
                "cost": float(solver.solver.cost), "history": history,
                "mbjax_cost_in_crocoddyl": float(croc.calc(croc.rollout(us), us))}

    peer, record = _peer("crocoddyl", "FDDP on the same trot from the same guess", fddp)
    if peer is not None:
        histories["Crocoddyl FDDP"] = np.asarray(peer.pop("history"))
        record.update(peer, relative_cost=(float(result.cost) - peer["cost"]) / peer["cost"])
    title = (f"ANYmal's trot by iLQR: {iterations} iterations in {timing.run_s:.1f} s "
             f"(compiled in {timing.compile_s:.0f} s), cost {float(result.cost):.6g}"
             + (f", FDDP's {peer['cost']:.6g}" if peer is not None
                else f"; {peers.note('crocoddyl', record['status'])}"))
    _save(gait_figure(histories, ts, forces, MU, FEET, title), out, "legged-gait.png")
    animation = gait_animation(out / "legged-gait.gif", problem.knots.knot(0, 0).system.tree,
                               ts, result.qs[:-1], FEET, forces, MU,
                               title="ANYmal trotting", frames=30 if quick else 60)
    normal = forces[..., 2]
    return {"figure": "legged-gait.png", "animation": Path(animation).name,
            "peers": {"crocoddyl": record},
            "runs": {"ilqr": {"knots": problem.horizon, "phases": len(problem.knots.templates),
                              "iterations": iterations, "seconds": timing.run_s,
                              "compile_seconds": timing.compile_s, "cost": float(result.cost),
                              "status": result.messages()[0],
                              "largest_normal_force_n": float(normal.max()),
                              "least_normal_force_on_the_ground_n":
                                  float(normal[normal > 0].min())}}}


CONTACT_ROBOTS = ("Ant", "HalfCheetah")


def mpc_tour(out: Path, quick: bool) -> dict:
    """The arm tracking a circle by MPC at 100 Hz under a push and a payload.

    The flange is pushed (30 N for 0.1 s at t = 1 s) and carries 0.3 kg that its controller
    does not know of. `mbjax.scenes.arm.tracking_controller` re-solves a 0.5 s horizon at 100 Hz from the
    measured state, one FDDP iteration a tick warm-started from the last plan; the plant is RK4
    at 1 ms with the plan's feedback gains between ticks. The ticks run one at a time, so each
    solve is timed; where Crocoddyl is installed its MPC loop runs on the same plant
    (`mbjax bench mpc` has the full comparison)."""
    from mbjax.rigid import TreeSystem
    from mbjax.scenes import arm
    from mbjax_harness.bench import mpc
    from mbjax_harness.plot.mpc import tracking_figure

    ticks = 150 if quick else 300
    scenario = mpc.arm_track()
    dt, steps = arm.PLANT_DT, int(round(arm.MPC_DT / arm.PLANT_DT))
    period = mpc.plant_period(scenario, dt, steps)
    qs, vs, us, seconds = mpc.mbjax_loop(scenario, ticks, period, dt, steps)
    ts = np.arange(ticks + 1) * arm.MPC_DT
    problem = scenario.controller.problem
    flange = np.asarray(jax.jit(jax.vmap(lambda q: arm.flange(problem.arm, q)))(qs))
    target = np.asarray(arm.track_target(problem.centre, ts))
    error = np.linalg.norm(flange - target, axis=1)
    solve_ms = 1e3 * np.asarray(seconds)
    runs = {"mbjax": {"solve_ms_median": float(np.median(solve_ms)),
                      "solve_ms_max": float(solve_ms.max()),
                      "tracking_error_rms_m": float(np.sqrt(np.mean(error**2))),
                      "tracking_error_max_m": float(error.max()),
                      "real_time": bool(solve_ms.max() < 1e3 * arm.MPC_DT)}}
    peers_record = {}
    why = peers.crocoddyl_working()
    if why is None:
        cqs, _, _, cseconds, _ = mpc.crocoddyl_loop(scenario, ticks, period, dt, steps)
        cflange = np.asarray(jax.jit(jax.vmap(lambda q: arm.flange(problem.arm, q)))(cqs))
        cerror = np.linalg.norm(cflange - target, axis=1)
        peers_record["crocoddyl"] = {
            "status": "compared", "compares": "its MPC loop on the same plant",
            "solve_ms_median": 1e3 * float(np.median(cseconds)),
            "tracking_error_rms_m": float(np.sqrt(np.mean(cerror**2)))}
    else:
        peers_record["crocoddyl"] = {"status": why, "compares": "its MPC loop on the same plant"}
    fig = tracking_figure(ts, flange, target, error, solve_ms, 1e3 * arm.MPC_DT, (1.0, 1.1),
                          f"arm tracking by MPC at 100 Hz: solve {np.median(solve_ms):.2f} ms "
                          f"median, {solve_ms.max():.2f} ms worst; error "
                          f"{1e3 * runs['mbjax']['tracking_error_rms_m']:.1f} mm rms")
    _save(fig, out, "mpc.png")
    animation = _animate(out, "mpc", TreeSystem(problem.arm), ts, jnp.asarray(qs),
                         f"MPC at 100 Hz, {np.median(solve_ms):.1f} ms a tick", quick)
    return {"figure": "mpc.png", "animation": animation, "runs": runs, "peers": peers_record}


def contacts_tour(out: Path, quick: bool) -> dict:
    """gymnasium's Ant and HalfCheetah dropped on the floor, beside MuJoCo's runs. Each file
    (`mbjax.data.ANT`, `mbjax.data.HALF_CHEETAH`) is read by `mbjax.model.from_mujoco`, its
    geoms finding their own contacts in `mbjax.contact.ContactSystem` (MuJoCo's soft
    constraints, limited joints held), and dropped from its initial state with zero controls by
    the file's integrator (`mbjax_harness.bench.contact.mujoco_step`: RK4, or Euler as
    semi-implicit Euler with the damping implicit); MuJoCo runs the same files."""
    import warnings

    from mbjax.data import ANT, HALF_CHEETAH
    from mbjax.rigid import forward_kinematics
    from mbjax_harness.bench.contact import mujoco_step
    from mbjax_harness.plot.animate import geom_animation
    from mbjax_harness.plot.contact import drop_figure

    why = peers.missing("mujoco")
    if why is not None:                  # MuJoCo reads the MJCF files: nothing runs without it
        return _needs(out, "contacts", "The Ant and the HalfCheetah are MJCF files",
                      {"mujoco": {"status": why, "compares": "the same drops"}})
    import mujoco

    duration = 1.0 if quick else 2.0
    runs, plotted, panels = {}, {}, []
    for name, path in zip(CONTACT_ROBOTS, (ANT, HALF_CHEETAH)):
        m = mujoco.MjModel.from_xml_path(str(path))
        with warnings.catch_warnings(record=True) as caught:   # what mbjax leaves out: below
            warnings.simplefilter("always")
            model = mbjax.model.from_mujoco(m)
        dt = float(m.opt.timestep)
        steps = int(round(duration / dt))
        system, integrator = mujoco_step(m, model)
        sol, timing = measure(partial(mbjax.simulate, system, integrator, jnp.asarray(m.qpos0),
                                      jnp.zeros(m.nv), dt=dt, t1=steps * dt), repeats=3)
        d = mujoco.MjData(m)
        shown = np.flatnonzero(np.isin(m.geom_type, (int(mujoco.mjtGeom.mjGEOM_SPHERE),
                                                     int(mujoco.mjtGeom.mjGEOM_CAPSULE))))
        history = [(d.qpos.copy(), d.geom_xpos[shown].copy(), d.geom_xmat[shown].copy())]
        start = time.perf_counter()
        for _ in range(steps):
            mujoco.mj_step(m, d)
            history.append((d.qpos.copy(), d.geom_xpos[shown].copy(), d.geom_xmat[shown].copy()))
        mujoco_seconds = time.perf_counter() - start
        qpos, xpos, xmat = (np.asarray(x) for x in zip(*history))
        root = 2 if model.joint_types[0] == "free" else 1        # z, or the planar rootz
        ours = np.asarray(sol.qs[:, root])
        gap = np.abs(ours - qpos[:, root])
        ts = np.asarray(sol.ts)
        plotted[name] = {"ts": ts, "mbjax": ours, "mujoco": qpos[:, root],
                         "mbjax_seconds": timing.run_s / duration,
                         "mujoco_seconds": mujoco_seconds / duration}
        runs[name] = {"integrator": type(integrator).__name__, "dt": dt,
                      "steps": steps, "seconds": timing.run_s, "compile_seconds": timing.compile_s,
                      "mujoco_seconds": mujoco_seconds, "height_error_max_m": float(gap.max()),
                      "final_height_m": float(ours[-1]), "mujoco_final_height_m":
                          float(qpos[-1, root]), "status": sol.messages()[0],
                      "mbjax_ignores": "; ".join(str(w.message).split("ignored: ", 1)[-1]
                                                 for w in caught)}
        # the geoms along each run: capsules end to end, spheres as points
        R, p = (np.asarray(x) for x in jax.jit(jax.vmap(
            lambda q, model=model: forward_kinematics(model, q)))(sol.qs))
        geoms = model.geoms
        mine = [g for g, kind in enumerate(geoms.kinds) if kind in ("sphere", "capsule")]
        body = np.asarray(geoms.bodies)[mine]
        rot, pos = np.asarray(geoms.rotation)[mine], np.asarray(geoms.position)[mine]
        half = np.asarray(geoms.size)[mine, 1] * [geoms.kinds[g] == "capsule" for g in mine]
        centre = p[:, body] + np.einsum("tgij,gj->tgi", R[:, body], pos)
        axis = np.einsum("tgij,gj->tgi", R[:, body], rot[:, :, 2])
        ours_geoms = np.stack([centre - half[:, None] * axis, centre + half[:, None] * axis], 2)
        half_mj = m.geom_size[shown, 1] * (m.geom_type[shown] == int(mujoco.mjtGeom.mjGEOM_CAPSULE))
        axis_mj = xmat.reshape(*xmat.shape[:2], 3, 3)[..., 2]
        theirs = np.stack([xpos - half_mj[:, None] * axis_mj, xpos + half_mj[:, None] * axis_mj], 2)
        panels += [(f"{name}: mbjax", ours_geoms, np.asarray(geoms.size)[mine, 0]),
                   (f"{name}: MuJoCo", theirs, m.geom_size[shown, 0])]
    worst = max(run["height_error_max_m"] for run in runs.values())
    _save(drop_figure(plotted, f"dropped on the floor, contacts found each step: mbjax's root "
                               f"heights within {worst:.1e} m of MuJoCo's on the same files"),
          out, "contacts.png")
    animation = geom_animation(out / "contacts.gif", plotted[CONTACT_ROBOTS[0]]["ts"], panels,
                               title="dropped with zero controls", frames=30 if quick else 60)
    return {"figure": "contacts.png", "animation": Path(animation).name,
            "peers": {"mujoco": {"status": "compared", "compares": "the same drops"}},
            "runs": runs}


def _needs(out: Path, name: str, what: str, records: dict) -> dict:
    """A scene that cannot run without an optional package: a figure that says what to
    install, the missing packages recorded as skipped peers."""
    from mbjax_harness.plot.style import Figure

    fig = Figure(figsize=(8, 2.5), layout="constrained")
    ax = fig.add_subplot()
    ax.axis("off")
    ax.text(0.5, 0.5, f"{what}: " + "; ".join(peers.note(peer, r["status"])
                                             for peer, r in records.items()),
            ha="center", va="center", wrap=True)
    _save(fig, out, f"{name}.png")
    return {"figure": f"{name}.png", "peers": records}


def _without_robot(out: Path, records: dict) -> dict:
    """The legged-gait scene where ANYmal's model cannot be had (`_needs`)."""
    return _needs(out, "legged-gait", "ANYmal's trot needs its model", records)


def _model_peers() -> dict:
    """{peer: record}: the arm against Pinocchio from the same URDF
    (`mbjax_harness.reproduce.urdf_corpus`: forward and inverse dynamics, mass matrix, frames) and
    against MuJoCo through MuJoCo's compiler and `from_mujoco` (`mbjax_harness.reproduce.mjcf_corpus`:
    accelerations), each record with its status (`_peer`) and, where compared, the largest
    relative difference."""
    from mbjax.data import ARM7

    def pinocchio():
        from mbjax_harness.reproduce import urdf_corpus
        return urdf_corpus.compare(ARM7, floating=False)["max_relative_difference"]

    def mujoco():
        import mujoco

        from mbjax.model import from_mujoco
        from mbjax_harness.reproduce import mjcf_corpus
        mj = mujoco.MjModel.from_xml_path(str(ARM7))
        return mjcf_corpus.compare(mj, from_mujoco(mj))["qacc"]

    out = {}
    for name, compares, compute in (
            ("pinocchio", "forward and inverse dynamics, mass matrix, frames from the URDF", pinocchio),
            ("mujoco", "accelerations through MuJoCo's compiler and from_mujoco", mujoco)):
        value, record = _peer(name, compares, compute)
        out[name] = {**record, "max_relative_difference": None if value is None else float(value)}
    return out


# what a reader should look at in each scene's figure and tables (`summary.md`), for the scenes
# that compare with no peer; `look_at` writes the others' from what ran
LOOK_AT = {
    "mpc": "the flange stays on its circle through the push and the unknown payload (middle "
           "panel), every tick's solve well inside the 10 ms control period (right panel)",
    "torque-free-body": "at the same step RK4 and RKMK4 land within 1e-4 rad of the closed form "
                        "while both Euler methods are off by more than a radian; the error "
                        "estimate column tracks the true error, and the status says which runs "
                        "to trust.",
    "heavy-top": "the energy drift: the implicit midpoint keeps the energy to round-off, RK4 and "
                 "RKMK4 to 1e-10, the Euler methods gain or lose tens of percent.",
    "rigid-chain": "error against run time: quartering RK4's step cuts its error about "
                   "250-fold (fourth order); the implicit midpoint costs more per step here.",
    "time-elements": "the tilt: the primal time element's grows at the rate its transition "
                     "matrix predicts, the mixed element's stays with the physical motion.",
    "closed-loops": "the constraint residual |Phi|: without stabilization it drifts, Baumgarte "
                    "bounds it, projection holds it at round-off; accuracy against run time per "
                    "method.",
    "flexible-bodies": "the tip histories: with geometric stiffening the modal beam follows the "
                       "nonlinear ANCF beam, without it the tip runs away once the spin passes "
                       "the first bending frequency; the implicit midpoint reaches the same "
                       "accuracy at 25 times RK4's step.",
    "carpal-wrist": "the stability column against the step: the chapter's explicit Euler goes "
                    "unstable past its critical step (about 7 ms) while RK4 stays stable to "
                    "about 35 ms, as their linearizations predict (the critical steps below).",
    "trajectory-optimisation": "the cost falling over the iterations and the flange reaching its "
                               "target at rest.",
    "floating-base": "the quadrotor pitching forward to fly over and back level to stop at its "
                     "target, the thrusts held inside their bounds; the same problem in "
                     "Crocoddyl is `mbjax bench trajopt`'s quadrotor-bounded.",
}



def look_at(name: str, scene: dict) -> str | None:
    """The "what to look at" sentence of scene `name` given its summary `scene`: `LOOK_AT`'s, or,
    for a scene that compares with peers, one that describes the comparisons that ran and says
    which did not, and why (`mbjax_harness.peers.note`)."""
    records = scene.get("peers", {})
    ran = [peers.TITLES[p] for p in ("mujoco", "pinocchio")
           if records.get(p, {}).get("status") == "compared"]
    not_run = "; ".join(peers.note(p, r["status"]) for p, r in records.items()
                        if r.get("status") != "compared")
    if name == "controls":
        text = ("the servo catching the push within millimetres (middle panel) and jax.grad "
                "agreeing with central differences (right panel)")
        if ran:
            return text + ("; the sampled-torque run ends where mujoco.rollout ends (its "
                           "difference is in the title and the runs table).")
        return text + f"; the sampled-torque run is not compared with MuJoCo ({not_run})."
    if name == "legged-gait":
        if "runs" not in scene:
            return f"nothing: ANYmal's model is not here ({not_run})."
        text = ("the feet taking turns on the ground in diagonal pairs, each pushing up to the "
                "edge of the cost's friction cone (right panel: 1 is the cone, whose barrier "
                "prices a small excess rather than forbidding it, in Crocoddyl's problem too)")
        record = records.get("crocoddyl", {})
        if record.get("status") == "compared":
            return text + (f"; Crocoddyl's FDDP on the same problem reaches the same cost "
                           f"(relative difference {record['relative_cost']:.1e}).")
        return text + f"; not compared with Crocoddyl ({peers.note('crocoddyl', record['status'])})."
    if name == "contacts":
        if "runs" not in scene:
            return f"nothing: the robots are MJCF files, which MuJoCo reads ({not_run})."
        worst = max(run["height_error_max_m"] for run in scene["runs"].values())
        return ("the Ant and the HalfCheetah landing on their legs and settling, their geoms "
                "finding their own contacts each step; MuJoCo's runs of the same files (dashed) "
                f"stay within {worst:.1e} m of mbjax's root heights (middle panel).")
    if name == "models":
        text = "the unpowered arm falls through its joint limits (left panel) and the status says so"
        if not ran:
            return text + f"; its dynamics are compared with no peer here ({not_run})."
        return (text + f"; the arm loaded from a URDF agrees with {' and '.join(ran)} on its "
                "dynamics (right panel)" + (f"; not compared: {not_run}." if not_run else "."))
    return LOOK_AT.get(name)


TOUR = {   # in the order the summary tells them
    "torque-free-body": torque_free_body_tour,
    "heavy-top": heavy_top_tour,
    "rigid-chain": rigid_chain_tour,
    "time-elements": time_elements_tour,
    "closed-loops": closed_loops_tour,
    "flexible-bodies": flexible_bodies_tour,
    "carpal-wrist": carpal_wrist_tour,
    "controls": controls_tour,
    "models": models_tour,
    "trajectory-optimisation": trajectory_optimisation_tour,
    "floating-base": floating_base_tour,
    "legged-gait": legged_gait_tour,
    "contacts": contacts_tour,
    "mpc": mpc_tour,
}

# Each scene's wall time in a quick tour from a cold cache, one scene at a time (benchmarks/README
# compile section): `mbjax tour` starts the longest first, which balances its workers best.
COST = {"contacts": 17.6, "time-elements": 17.0, "floating-base": 12.3, "flexible-bodies": 12.8,
        "carpal-wrist": 12.2, "closed-loops": 11.5, "rigid-chain": 10.4, "controls": 7.7, "trajectory-optimisation": 5.8,
        "torque-free-body": 5.4, "heavy-top": 4.6, "models": 4.2, "legged-gait": 85.0, "mpc": 12.0}


def _animate(out: Path, name: str, system, ts, qs, title: str, quick: bool) -> str:
    """Write the scene's animation, `name`.gif (`mbjax_harness.plot.animate.animate`), of a system
    moving through the saved states qs at times ts; returns the file name."""
    from mbjax_harness.plot.animate import animate

    animate(out / f"{name}.gif", system, ts, qs, title=title, frames=30 if quick else 60)
    return f"{name}.gif"


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


def _animate_body(out: Path, name: str, body, ts, qs, title: str, quick: bool) -> str:
    """Write `name`.gif of a single rigid body turning: its frame's triad at the fixed point and a
    stick along its symmetry axis (body z), whose tip leaves its path (nutation and precession)."""
    from mbjax_harness.plot.animate import stick_animation

    R = np.asarray(jax.jit(jax.vmap(body.rotation_matrix))(qs))
    p = np.stack([np.zeros((len(R), 3)), R[:, :, 2]], axis=1)
    stick_animation(out / f"{name}.gif", ts, np.stack([R, R], axis=1), p, [-1, 0], title=title,
                    trace=1, axis_length=0.4, frames=30 if quick else 60)
    return f"{name}.gif"


def _animate_tops(out: Path, runs: list[dict], quick: bool) -> str:
    """Write time-elements.gif: the tops of the primal (left) and mixed (right) runs side by side,
    each a stick from its pivot along its symmetry axis, whose tip leaves its path; the tilt is
    magnified (as the title says) so that the primal form's growth shows, not the mixed form's."""
    from mbjax_harness.plot.animate import stick_animation

    R = np.stack([run.pop("R") for run in runs], axis=1)                # (T, 2, 3, 3)
    axis = R[..., :, 2]
    tilt = np.arccos(np.clip(axis[..., 2], -1.0, 1.0))
    magnification = max(1, int(1.0 / max(float(tilt.max()), 1e-3)))    # the largest tilt ~ 1 rad
    azimuth = np.arctan2(axis[..., 1], axis[..., 0])
    shown = magnification * tilt
    tips = np.stack([np.sin(shown) * np.cos(azimuth), np.sin(shown) * np.sin(azimuth),
                     np.cos(shown)], axis=-1)
    pivots = np.array([[-0.8, 0.0, 0.0], [0.8, 0.0, 0.0]])
    ts = np.asarray(runs[0]["t"])
    stick_animation(out / "time-elements.gif", ts, R, pivots + tips, [-1, -1],
                    title=f"primal (left), mixed (right), tilt x{magnification}", trace=[0, 1],
                    triads=False, anchors=pivots, frames=30 if quick else 60)
    return "time-elements.gif"


def run_scene(name: str, out: Path, quick: bool) -> dict:
    """The summary of scene `name`, with what to look at (`look_at`) and its wall time
    (compiling, running and drawing)."""
    start = time.perf_counter()
    result = TOUR[name](out, quick)
    sentence = look_at(name, result)
    if sentence:
        result["look_at"] = sentence
    result["wall_seconds"] = time.perf_counter() - start
    return result
