"""`mbjax bench integrators`: the heavy top over 10 s, mbjax against MuJoCo in one run.

For each step size: every mbjax integrator (`simulate`, one jitted rollout) and every MuJoCo
integrator (`mujoco.rollout`, C, one thread) from the same initial state; run time (median after
warm-up), compile time, steps per second, the rotation error at 10 s against an adaptive Dopri8
reference (rtol 1e-12) and the relative energy error at 10 s. Then a batch of B initial states:
mbjax `jit(vmap(simulate))` against MuJoCo's rollout of the same batch. JSON lines + PNG.
"""

import platform
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax import lie
from mbjax_harness import peers
from mbjax_harness.timing import measure, write_jsonl
from mbjax.integrate import INTEGRATORS, RKMK4, simulate, solve_reference
from mbjax.scenes import heavy_top as top

NAME = "integrators"
# the peers compared with where installed, left out of the records where not: the
# command's closing line names those missing (`mbjax_harness.cli._declared`)
PEERS = ("mujoco",)


def run(out: Path, quick: bool = False) -> list[dict]:
    body, q0, u0 = top.build()
    T = top.DURATION
    ref = solve_reference(body, q0, u0, jnp.array([0.0, T]), rtol=1e-12, atol=1e-12)
    R_ref = body.rotation_matrix(ref.qs[-1])
    E0 = float(body.energy(q0, u0))
    repeats = 3 if quick else 10

    def scores(quat, Omega):
        """Rotation error and energy error at T; NaN for a run that diverged."""
        if not (np.all(np.isfinite(quat)) and np.all(np.isfinite(Omega))):
            return float("nan"), float("nan")
        # the top's coordinates are (unit quaternion, body angular velocity), as MuJoCo's ball joint
        quat, Omega = body.project(jnp.asarray(quat)), jnp.asarray(Omega)
        err = float(jnp.linalg.norm(lie.log(body.rotation_matrix(quat) @ R_ref.T)))
        drift = abs(float(body.energy(quat, Omega)) / E0 - 1.0)
        return err, drift

    records = []
    common = {"scene": "heavy top", "duration_s": T, "machine": platform.machine(),
              "jax": jax.__version__}
    for dt in ((2e-3,) if quick else (4e-3, 2e-3, 1e-3, 5e-4)):
        n = round(T / dt)
        for name, cls in INTEGRATORS.items():
            sol, timing = measure(partial(simulate, body, cls(), q0, u0, dt=dt, t1=T, saveat=[T]),
                                  repeats=repeats)
            err, drift = scores(sol.qs[-1], sol.vs[-1])
            records.append({**common, "engine": "mbjax", "integrator": name, "dt": dt,
                            "batch": 1, "compile_s": timing.compile_s, "run_s": timing.run_s,
                            "steps_per_s": n / timing.run_s, "error": err, "energy_drift": drift,
                            "status": sol.messages()[0]})
        if peers.available("mujoco"):
            for name in peers.MUJOCO_INTEGRATORS:
                model, data = peers.mujoco_heavy_top(float(body.mass), np.asarray(body.inertia),
                                                     np.asarray(body.com), top.GRAVITY, dt, name)
                (quat, Omega), timing = measure(
                    partial(peers.mujoco_rollout, model, data, np.asarray(q0), np.asarray(u0), n),
                    repeats=repeats)
                err, drift = scores(quat[0], Omega[0])
                records.append({**common, "engine": "mujoco", "integrator": name, "dt": dt,
                                "batch": 1, "compile_s": 0.0, "run_s": timing.run_s,
                                "steps_per_s": n / timing.run_s, "error": err,
                                "energy_drift": drift})

    # A batch of tops with different initial tilts: throughput of one rollout call.
    dt = 2e-3
    n = round(T / dt)
    for batch in ((64,) if quick else (64, 1024)):
        tilt = np.linspace(0.02, 0.3, batch)
        # the quaternions (w, x, y, z) of the turns by `tilt` about x
        quats = jnp.stack([np.cos(tilt / 2), np.sin(tilt / 2), 0 * tilt, 0 * tilt], axis=1)
        Omegas = jnp.broadcast_to(u0, (batch, 3))
        batched = jax.jit(jax.vmap(lambda q, u: simulate(body, RKMK4(), q, u, dt=dt, t1=T,
                                                          saveat=[T]).qs[-1]))
        _, timing = measure(batched, quats, Omegas, repeats=max(3, repeats // 3))
        records.append({**common, "engine": "mbjax", "integrator": "rkmk4", "dt": dt,
                        "batch": batch, "compile_s": timing.compile_s, "run_s": timing.run_s,
                        "steps_per_s": batch * n / timing.run_s})
        if peers.available("mujoco"):
            model, data = peers.mujoco_heavy_top(float(body.mass), np.asarray(body.inertia),
                                                 np.asarray(body.com), top.GRAVITY, dt, "RK4")
            _, timing = measure(partial(peers.mujoco_rollout, model, data, np.asarray(quats),
                                        np.asarray(Omegas), n), repeats=max(3, repeats // 3))
            records.append({**common, "engine": "mujoco", "integrator": "RK4", "dt": dt,
                            "batch": batch, "compile_s": 0.0, "run_s": timing.run_s,
                            "steps_per_s": batch * n / timing.run_s})

    out.mkdir(parents=True, exist_ok=True)
    write_jsonl(out / f"{NAME}.jsonl", records)
    from mbjax_harness.plot.bench import integrators_bench_figure
    integrators_bench_figure(records).savefig(out / f"{NAME}.png", dpi=120)
    for r in records:
        print(f"{r['engine']:6s} {r['integrator']:20s} dt={r['dt']:<7g} B={r['batch']:<5d} "
              f"{r['steps_per_s']:12.4g} steps/s" +
              (f"  error {r['error']:.3g} rad  energy {r['energy_drift']:.3g}" if "error" in r else ""))
    return records
