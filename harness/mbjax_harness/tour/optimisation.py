"""The tour's optimal control: the arm's reach, Crocoddyl's quadrotor (floating base), ANYmal's
trot (legged gait), MPC at 100 Hz."""

import time
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness import peers
from mbjax_harness.crocoddyl.terms import crocoddyl_working
from mbjax_harness.timing import measure
from mbjax_harness.tour._common import _animate, _peer, _save, _without_robot


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
    quadrotor (`mbjax_harness.crocoddyl.examples`) is a free base driven by four thrusters
    through an actuation matrix, its thrusts bounded to [0.1, 5] N, flown from hover 1 m over
    and 1 m up in 33 knots of 0.03 s."""
    from mbjax_harness.crocoddyl.examples import TARGET, hector, quadrotor_problem
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
    trot of Crocoddyl's example (`mbjax_harness.crocoddyl.gaits.anymal_trot`: the diagonal
    pairs of feet step 0.25 m in turn, a multi-phase problem of stances and touchdown impulses)
    solved from its quasi-static guess; the ground's force on each foot along the solution; the
    same problem solved by Crocoddyl's FDDP from the same guess where Crocoddyl is installed."""
    from mbjax.trajopt import CROCODDYL_SCHEDULE, ILQR, knot_wrenches, solve
    from mbjax_harness.crocoddyl.gaits import FEET, MU, anymal_trot
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
    xs = result.xs
    forces = np.asarray(knot_wrenches(problem, xs, result.us))[..., 3:]
    ts = np.asarray(problem.times())
    histories = {"mbjax iLQR": np.asarray(result.costs)[:iterations + 1]}

    def fddp():
        from mbjax_harness.crocoddyl.solver import CrocoddylSolver

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
    why = crocoddyl_working()
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
