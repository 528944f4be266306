"""`mbjax reproduce carpal-wrist`: Canfield 1997's Carpal Wrist: time response, synthesis, Newton-Euler.
The time response, its stated purpose (trajectory synthesis), and the Newton-Euler check, on the
scene `mbjax.scenes.carpal_wrist`.

1. Integrators (§6.4). The chapter's scheme (eq 6.45, explicit Euler) and the foundation's
   semi-implicit Euler, RK4 and implicit midpoint, at each step dt of STEPS:
   - `error`: the largest joint-angle error after FREE_DURATION of torque-free, gravity-free motion,
     against RK4 at dt = REFERENCE_DT (whose own error is below 1e-12);
   - `energy_drift`: max |E(t) - E(0)| / E(0) over that run (E is conserved);
   - `stable`: the servoed wrist (PD servo, gravity) released from an offset loses energy over
     SERVO_DURATION at that dt (a damped system must: an unstable method gains it).
   The critical steps predicted by the linearization about the servo's equilibrium (amplification
   matrix of each method, spectral radius 1) are reported beside them.
2. Trajectory synthesis: the START -> GOAL move in DURATION with |tau| <= TORQUE_LIMIT. The
   baseline is the inverse-dynamics feed-forward along a minimum-jerk tool path; its peak torque
   exceeds the limit, and clipped to it the tool misses (both played back as 12-knot splines
   fitted to it, so every rollout here shares one compiled simulator). Gradient descent (Adam through the RK4
   simulator) from the clipped baseline gives torques inside the limit that reach the goal; the
   final pose error is measured by re-simulating them with RK4 at a 10x finer step.
3. `newton_euler_max_diff`: the largest |tau_Lagrange - tau_Newton-Euler| over random states.

JSON: {"integrators": [{"name", "dt", "error", "energy_drift", "stable"}], "critical_dt": {name:
predicted dt or null}, "newton_euler_max_diff", "trajectory": {"final_pose_error", "effort",
"iterations", "peak_torque", "discrete_pose_error", "losses"}, "baseline": {"effort",
"peak_torque", "pose_error_clipped", "pose_error_unclipped"}, "torque_limit", "duration", "seconds"}.
"""

import json
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax.control import CubicSpline
from mbjax.integrate import INTEGRATORS, RK4, simulate
from mbjax.scenes import carpal_wrist as scene
from mbjax.wrist import ToolPath, WristSystem, feedforward_torques, pose_error, synthesize
from mbjax_harness.timing import measure

NAME = "carpal-wrist"
METHODS = ("explicit_euler", "semi_implicit_euler", "rk4", "implicit_midpoint")
STEPS = (0.001, 0.002, 0.004, 0.005, 0.008, 0.01, 0.02, 0.04)
QUICK_STEPS = (0.002, 0.005, 0.01, 0.02, 0.04)
REFERENCE_DT = 1e-4
ITERATIONS, QUICK_ITERATIONS = 400, 60


def goal_pose(wrist, goal):
    """The tool's `Pose` at goal = (plunge, slope), the midplane chart's coordinates: the
    forward kinematics of the inverse kinematics' input angles."""
    return wrist.forward_kinematics(wrist.solve_inverse_kinematics(*goal)[0])


def rollout(wrist, law, theta0, duration: float, steps: int, integrator=RK4()):
    """The final (theta, theta_dot, status) of the wrist driven by the torque law `law` from rest
    at theta0, `steps` steps to `duration` (what `synthesize` scores a law by)."""
    sol = simulate(WristSystem(wrist, law), integrator, theta0, jnp.zeros_like(theta0),
                   dt=duration / steps, t1=duration, saveat=np.array([duration]))
    return sol.qs[-1], sol.vs[-1], sol.status


def masked_rollout(system, integrator, q0, u0, dts, duration: float, monitor, timings: dict | None = None):
    """Run `system` to `duration` at every step in `dts` in one compiled call: a scan of the
    largest step count, vmapped over dt, in which steps past each run's own count leave the
    state alone. Returns (q, u) at the end and max over the steps of monitor(q, u). With a
    `timings` dict, the call is repeated once compiled and timings["run_s"], ["compile_s"],
    ["steps"] (the scan length) are filled in."""
    dts = jnp.asarray(dts)
    counts = jnp.round(duration / dts).astype(jnp.int32)
    n_max = int(np.max(np.round(duration / np.asarray(dts))))

    def run(dt, n):
        def step(carry, k):
            q, u, worst = carry
            q1, u1, _ = integrator.step(system, k * dt, q, u, dt)
            live = k < n
            q1, u1 = jnp.where(live, q1, q), jnp.where(live, u1, u)
            return (q1, u1, jnp.maximum(worst, jnp.where(live, monitor(q1, u1), 0.0))), None
        (q, u, worst), _ = jax.lax.scan(step, (q0, u0, monitor(q0, u0)), jnp.arange(n_max))
        return q, u, worst
    fn = jax.jit(jax.vmap(run))
    if timings is None:
        return fn(dts, counts)
    out, timing = measure(fn, dts, counts, repeats=1)
    timings.update(run_s=timing.run_s, compile_s=timing.compile_s, steps=n_max)
    return out


def linear_critical_steps(system, q_eq, u_eq) -> dict:
    """Largest stable dt of each method for the linearization about (q_eq, u_eq), from the
    spectral radius of its one-step amplification matrix (None: stable for every dt tried)."""
    n = q_eq.shape[0]
    # jitted: the Jacobian compiles in one piece instead of primitive by primitive (~5x faster)
    J = np.asarray(jax.jit(jax.jacfwd(lambda y: jnp.concatenate(
        [system.kinematics(y[:n], y[n:]), system.acceleration(0.0, y[:n], y[n:])])))(
        jnp.concatenate([q_eq, u_eq])))
    eye = np.eye(2 * n)
    Aq, Au = J[n:, :n], J[n:, n:]

    def amplification(name, h):
        if name == "explicit_euler":
            return eye + h * J
        if name == "semi_implicit_euler":
            In = np.eye(n)
            return np.block([[In + h * h * Aq, h * (In + h * Au)], [h * Aq, In + h * Au]])
        if name == "rk4":
            Z = h * J
            return eye + Z + Z @ Z / 2 + Z @ Z @ Z / 6 + Z @ Z @ Z @ Z / 24
        return np.linalg.solve(eye - h * J / 2, eye + h * J / 2)          # implicit midpoint

    def radius(name, h):
        return np.max(np.abs(np.linalg.eigvals(amplification(name, h))))

    out = {}
    for name in METHODS:
        hs = np.geomspace(1e-5, 1.0, 400)
        bad = [h for h in hs if radius(name, h) > 1 + 1e-12]
        if not bad:
            out[name] = None
            continue
        lo, hi = hs[max(0, np.searchsorted(hs, bad[0]) - 1)], bad[0]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if radius(name, mid) <= 1 + 1e-12 else (lo, mid)
        out[name] = float(lo)
    return out


def integrator_study(steps, seconds: dict | None = None, methods=METHODS,
                     motion: dict | None = None) -> tuple[list[dict], dict]:
    """The rows of the JSON's "integrators" for `methods` and the predicted critical steps; with a
    `seconds` dict, each method's run time per step of the vmapped free-motion runs is stored in
    it; with a `motion` dict, the reference free motion ("ts", "qs": 41 saved states)."""
    free, q0, u0 = scene.free_motion()
    servo, s0, v0 = scene.servo()
    reference = simulate(free, RK4(), q0, u0, dt=REFERENCE_DT, t1=scene.FREE_DURATION,
                         saveat=np.linspace(0.0, scene.FREE_DURATION, 41))
    ref = reference.qs[-1]
    if motion is not None:
        motion.update(ts=np.asarray(reference.ts), qs=np.asarray(reference.qs))
    E0 = jax.jit(lambda q, u: free.model.energy(q, u))(q0, u0)
    law = servo.control

    @jax.jit
    def servo_energy(q, u):
        e = q - law.q_ref
        return 0.5 * law.kp * e @ e + 0.5 * u @ servo.model.mass_matrix(q) @ u

    rows = []
    for name in methods:
        integrator = INTEGRATORS[name]()
        timings = {} if seconds is not None else None
        q, _, drift = masked_rollout(free, integrator, q0, u0, steps, scene.FREE_DURATION,
                                     lambda q, u: jnp.abs(free.model.energy(q, u) - E0) / E0, timings)
        if seconds is not None:
            seconds[name] = timings["run_s"] / timings["steps"]
        qs, us, _ = masked_rollout(servo, integrator, s0, v0, steps, scene.SERVO_DURATION, lambda q, u: 0.0)
        final = jax.jit(jax.vmap(servo_energy))(qs, us)
        stable = np.isfinite(np.asarray(final)) & (np.asarray(final) < float(servo_energy(s0, v0)))
        err = np.max(np.abs(np.asarray(q) - np.asarray(ref)), axis=1)
        for i, dt in enumerate(steps):
            finite = np.isfinite(err[i])
            rows.append({"name": name, "dt": float(dt), "error": float(err[i]) if finite else None,
                         "energy_drift": float(drift[i]) if np.isfinite(drift[i]) else None,
                         "stable": bool(stable[i])})
    critical = linear_critical_steps(servo, law.q_ref, jnp.zeros(3))
    return rows, critical


def newton_euler_check(n: int = 64) -> float:
    w = scene.wrist()
    rng = np.random.default_rng(0)
    theta = np.asarray(scene.home(w)) + rng.uniform(-0.35, 0.35, (n, 3))
    qd, qdd = rng.normal(0, 2.0, (n, 3)), rng.normal(0, 20.0, (n, 3))
    routes_gap = jax.jit(jax.vmap(lambda *x: w.inverse_dynamics(*x) - w.newton_euler_torques(*x)))
    return float(jnp.max(jnp.abs(routes_gap(theta, qd, qdd))))


def trajectory_study(iterations: int) -> dict:
    w = scene.wrist()
    theta0 = w.solve_inverse_kinematics(*scene.START)[0]
    path = ToolPath(scene.START, scene.GOAL, scene.DURATION)
    ts = np.linspace(0.0, scene.DURATION, 201)
    tau_ff = np.asarray(feedforward_torques(w, path, ts))
    goal = goal_pose(w, scene.GOAL)

    def miss(law, steps):
        q, _, _ = rollout(w, law, theta0, scene.DURATION, steps, RK4())
        return float(pose_error(w, w.forward_kinematics(q), goal))

    init = CubicSpline.fit(ts, tau_ff, 12, scene.DURATION, scene.TORQUE_LIMIT)
    result = synthesize(w, theta0, scene.GOAL, duration=scene.DURATION, torque_limit=scene.TORQUE_LIMIT,
                        iterations=iterations, init=init)
    tau_syn = np.asarray(jax.jit(jax.vmap(lambda t: result.spline(t, theta0, theta0)))(ts))
    return {
        "trajectory": {"final_pose_error": miss(result.spline, 500), "effort": float(result.effort),
                       "iterations": iterations, "peak_torque": float(result.peak_torque),
                       "discrete_pose_error": float(result.final_pose_error),
                       "losses": np.asarray(result.losses).tolist()},
        "baseline": {"effort": float(np.trapezoid(np.sum(tau_ff**2, axis=1), ts)),
                     "peak_torque": float(np.abs(tau_ff).max()),
                     "pose_error_clipped": miss(init, 500),
                     "pose_error_unclipped": miss(CubicSpline.fit(ts, tau_ff, 12, scene.DURATION,
                                                                   10 * scene.TORQUE_LIMIT), 500)},
        "_curves": {"t": ts, "tau_ff": tau_ff, "tau_syn": tau_syn},
    }


def reproduce(out: Path, quick: bool = False) -> dict:
    from mbjax_harness.plot.wrist import carpal_wrist_figure

    start = time.perf_counter()
    rows, critical = integrator_study(QUICK_STEPS if quick else STEPS)
    traj = trajectory_study(QUICK_ITERATIONS if quick else ITERATIONS)
    curves = traj.pop("_curves")
    result = {"integrators": rows, "critical_dt": critical, "newton_euler_max_diff": newton_euler_check(),
              **traj, "torque_limit": scene.TORQUE_LIMIT, "duration": scene.DURATION,
              "seconds": time.perf_counter() - start}
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(result, indent=1))
    carpal_wrist_figure(result, curves).savefig(out / f"{NAME}.png", dpi=110)
    return result
