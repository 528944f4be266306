"""`mbjax reproduce trajopt`: trajectory-optimisation problems solved by each of mbjax's solvers.

Each problem (a `mbjax.trajopt.Problem` built by its scene) is solved from the same first guess
by iLQR (`ILQR`), multiple shooting (`MultipleShooting`: Gauss-Newton on an augmented
Lagrangian of the defects), single shooting with L-BFGS (`Shooting(optax.lbfgs())`) and Adam
(`Shooting(cosine_adam(0.01, 1000))`, the first-order baseline). Each solve is one compiled
program, timed after compiling (`mbjax_harness.timing.measure`); the cost after each iteration is plotted against the time it
was reached, taken as the iteration's share of the solve's run time (iterations of one solver
cost about the same). Each problem's iLQR solution is animated, NAME-PROBLEM.gif (JSON
"animations"). Per problem and solver the JSON gives
{"name", "solver", "iterations", "seconds", "compile_seconds", "final_error", "cost", "status"}:
final_error is the problem's own task error at the end (the flange's distance to its target
[m] for the arm).

Problems: `arm-reach`, the 7-dof arm (`mbjax.data.ARM7`) from rest to a flange target
0.4 m away, at rest after 1 s (dt = 0.01 s, 100 knots; `mbjax.scenes.arm.reach_problem`);
`acrobot-swingup`, the double pendulum driven at its elbow from hanging to upright at rest in
3 s (dt = 0.01 s, 300 knots, zero torque as the first guess; `mbjax.scenes.acrobot`);
`carpal-wrist`, the Carpal Wrist from START to GOAL at rest in 0.5 s under its 1.8 N m torque
limit (100 knots; the inverse-dynamics feed-forward along a minimum-jerk path, clipped, as the
first guess; `mbjax.scenes.carpal_wrist.synthesis_problem`), final_error the pose error
(`mbjax.wrist.pose_error`), by iLQR only (see SHOOTING); `four-bar`, the closed
loop on a table turned by its crank a quarter turn, rest to rest in 1 s with least effort,
projection on (`mbjax.scenes.four_bar.crank_problem`), final_error the crank angle's miss
[rad]; `slewing-beam`, the hub of a flexible arm slewed a quarter turn in 1 s with least torque
and no vibration left (`mbjax.scenes.slewing_beam`; the rigid arm's least-effort torque as the
first guess), final_error the tip's largest deflection [m] while the arm coasts for 1 s after.
"""

import json
from pathlib import Path

import jax.numpy as jnp
import numpy as np
import optax

from mbjax_harness.timing import measure
from mbjax.trajopt import ILQR, MultipleShooting, Shooting, cosine_adam, solve

NAME = "trajopt"
SOLVERS = {"ilqr": ILQR(iterations=300), "multiple-shooting": MultipleShooting(iterations=600),
           "lbfgs": Shooting(optax.lbfgs(), iterations=1000),
           "adam": Shooting(cosine_adam(0.01, 1000), iterations=1000)}
# The quick run (the test suite's) leaves out the first-order baselines: their reverse-mode
# programs took 26 s of its 130 s to compile, to show costs 3 to 4 orders above iLQR's (the
# full run has them; `tests/trajopt/test_ilqr.py` and notebook 11 run them by default).
QUICK_SOLVERS = {"ilqr": ILQR(iterations=300),
                 "multiple-shooting": MultipleShooting(iterations=600)}


def arm_reach():
    """(problem, first guess, final_error(result))."""
    from mbjax.scenes import arm

    problem = arm.reach_problem()
    model = problem.system.model
    target = arm.reach_target(model)

    def final_error(result):
        return float(jnp.linalg.norm(arm.flange(model, result.qs[-1]) - target))

    return problem, arm.hold(problem), final_error


def acrobot_swingup():
    """(problem, first guess, final_error(result)): the tip's distance to upright [m]."""
    from mbjax.scenes import acrobot

    problem = acrobot.swingup_problem()
    model = problem.system.model
    upright = jnp.array([0.0, 0.0, 2 * acrobot.LENGTH])

    def final_error(result):
        return float(jnp.linalg.norm(acrobot.tip(model, result.qs[-1]) - upright))

    return problem, None, final_error


def carpal_wrist():
    """(problem, first guess, final_error(result)): the pose error (`mbjax.wrist.pose_error`) of
    the final pose against GOAL."""
    from mbjax.scenes import carpal_wrist as cw
    from mbjax.wrist import pose_error
    from mbjax_harness.reproduce.carpal_wrist import goal_pose

    problem = cw.synthesis_problem()
    wrist = problem.system.model
    goal = goal_pose(wrist, cw.GOAL)

    def final_error(result):
        return float(pose_error(wrist, wrist.forward_kinematics(result.qs[-1]), goal))

    return problem, cw.synthesis_guess(problem), final_error


def four_bar():
    """(problem, first guess, final_error(result)): the crank angle's miss [rad]."""
    from mbjax.scenes import four_bar as fb

    problem = fb.crank_problem()

    def final_error(result):
        return float(abs(result.qs[-1, 0] - fb.CRANK_GOAL))

    return problem, None, final_error


def slewing_beam():
    """(problem, first guess, final_error(result)): the residual vibration, the tip's largest
    deflection [m] while the arm coasts for 1 s after the slew."""
    from mbjax.scenes import slewing_beam as sb

    problem = sb.slew_problem()

    def final_error(result):
        xN = jnp.concatenate([result.qs[-1], result.vs[-1]])
        return float(sb.residual_vibration(problem, xN))

    return problem, sb.rigid_guess(problem), final_error


PROBLEMS = {"arm-reach": arm_reach, "acrobot-swingup": acrobot_swingup, "four-bar": four_bar,
            "slewing-beam": slewing_beam, "carpal-wrist": carpal_wrist}
# Single shooting differentiates the rollout in reverse mode: through the Carpal Wrist's
# autodiff Lagrangian (third derivatives of its kinematics) XLA did not compile that program
# within 10 minutes, so the wrist is solved by iLQR alone (its forward-mode linearization
# compiles in about 10 s); through the four-bar's projection and the flexible recursion it
# compiles in about 50 s each, so the quick run leaves them to iLQR. Multiple shooting (forward
# mode only) runs on the same problems; the quick run (the test suite's) on the arm alone, to
# keep its compilations few.
SHOOTING = ("arm-reach", "acrobot-swingup", "four-bar", "slewing-beam")
QUICK_SHOOTING = ("arm-reach",)


def _animate(out: Path, name: str, problem, result, quick: bool) -> str:
    """Write NAME-PROBLEM.gif, the iLQR solution moving (`mbjax_harness.plot.animate`); the slewing beam
    as its centreline seen from above, the deflection magnified 10 times."""
    from mbjax_harness.plot.animate import animate, stick_animation

    path = out / f"{NAME}-{name}.gif"
    ts = np.arange(problem.horizon + 1) * problem.dt
    title, frames = f"{name} by iLQR", 20 if quick else 50
    if name == "slewing-beam":
        from mbjax.scenes import slewing_beam as sb

        p = sb.centreline(problem.system.model, result.qs, magnification=10.0)
        R = np.broadcast_to(np.eye(3), (*p.shape[:2], 3, 3))
        stick_animation(path, ts, R, p, [-1, *range(p.shape[1] - 1)], triads=False,
                        title=f"{title}, deflection x10", frames=frames, view=(90, -90))
    else:
        animate(path, problem.system, ts, result.qs, title=title, frames=frames)
    return path.name


def reproduce(out: Path, quick: bool = False) -> dict:
    from mbjax_harness.plot.trajopt import trajopt_figure

    rows, histories, animations = [], {}, {}
    for name, build in PROBLEMS.items():
        problem, guess, final_error = build()
        for solver_name, solver in (QUICK_SOLVERS if quick else SOLVERS).items():
            if solver_name != "ilqr" and name not in (QUICK_SHOOTING if quick else SHOOTING):
                continue
            result, timing = measure(solve, problem, solver, guess, repeats=1 if quick else 3)
            iterations = int(result.iterations)
            rows.append({"name": name, "solver": solver_name, "iterations": iterations,
                         "seconds": timing.run_s, "compile_seconds": timing.compile_s,
                         "final_error": final_error(result), "cost": float(result.cost),
                         "status": result.messages()[0]})
            if solver_name == "ilqr":
                animations[name] = _animate(out, name, problem, result, quick)
            costs = np.asarray(result.costs)[:iterations + 1]
            histories[(name, solver_name)] = (np.arange(iterations + 1) * timing.run_s
                                              / max(iterations, 1), costs)
    data = {"problems": rows, "animations": animations,
            "histories": [{"name": n, "solver": s, "seconds": t.tolist(), "cost": c.tolist()}
                          for (n, s), (t, c) in histories.items()]}
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1))
    trajopt_figure(data).savefig(out / f"{NAME}.png", dpi=120)
    return data
