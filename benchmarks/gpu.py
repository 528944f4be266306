"""The GPU items of the throughput, trajopt, gait and MPC issues, as one prepared script for a
lent accelerator (15 minutes of device time: each part checks the time left before it starts).

    python benchmarks/gpu.py OUT_DIR [DATA_DIR] [BUDGET_S]

1. Forward dynamics per second: the 7-link chain and the Panda (DATA_DIR/panda.urdf) at
   B = 65 536 and 1 048 576 states, `jit(vmap(forward_dynamics))` and the throughput layout
   (`batched_forward_dynamics`), float64 and float32; the accelerations compared with the same
   program on the host's CPU (the first 256 states, float64).
2. Rollouts: the 7-link chain's RK4 rollouts (1 000 steps) of 16 384 and 65 536 states, one
   vmapped scan.
3. The gradient of a 1 000-step rollout (sum q(T)^2 with respect to q0, v0) against the rollout.
4. Model-predictive control: 64 and 1 024 arms each tracking its own circle, 100 ticks, the closed
   loops vmapped (`jit(vmap(trajopt.closed_loop))`).
5. The arm reaching 64 targets: one batched `trajopt.solve` (1 024 targets at the end).
6. 16 ANYmal walks of different step lengths in one batched solve, built with `mbjax.gaits` from
   DATA_DIR/anymal.npz (the URDF's text, the standing pose and the rotors' armature, saved from
   example-robot-data on a machine that has it: `python benchmarks/gpu.py --save-data DATA_DIR`).

Every record goes to OUT_DIR/gpu.jsonl as soon as it is measured. Crocoddyl, Pinocchio and MuJoCo
have no GPU: the peers' figures are their CPU runs in benchmarks/README.md.
"""

import json
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

START = time.perf_counter()


def save_data(folder: Path) -> None:
    """The robots' files the GPU machine cannot install, from example-robot-data."""
    import example_robot_data

    from mbjax_harness.common import corpus_paths

    folder.mkdir(parents=True, exist_ok=True)
    (folder / "panda.urdf").write_text({p.stem: p for p in corpus_paths()}["panda"].read_text())
    robot = example_robot_data.load("anymal")
    np.savez(folder / "anymal.npz", urdf=Path(robot.urdf).read_text(),
             standing=robot.model.referenceConfigurations["standing"],
             armature=np.asarray(robot.model.armature))


def main(out: Path, data: Path, budget_s: float) -> None:
    import equinox as eqx
    import jax
    import jax.numpy as jnp

    jax.config.update("jax_enable_x64", True)
    from functools import partial

    from mbjax import Recursive, Status, load_urdf, trajopt
    from mbjax.integrate import RK4, SemiImplicitEuler, simulate
    from mbjax.model import chain
    from mbjax.rigid import TreeSystem, batched_forward_dynamics, forward_dynamics
    from mbjax.scenes import arm
    from mbjax.trajopt import CROCODDYL_SCHEDULE, ILQR, solve
    from mbjax_harness.common import states
    from mbjax_harness.timing import measure

    warnings.filterwarnings("ignore", category=UserWarning)     # the Panda's meshes, mimics
    out.mkdir(parents=True, exist_ok=True)
    path = out / "gpu.jsonl"
    gpu = jax.devices()[0]
    cpu = jax.devices("cpu")[0]
    common = {"jax": jax.__version__, "device": gpu.device_kind, "backend": jax.default_backend()}
    print(common, flush=True)

    def starts(by: float, needs: float = 0.0) -> bool:
        """Whether a part may start: before `by` of the budget has passed, with `needs`
        seconds (a smaller run's time, scaled) still to spare before the budget ends."""
        elapsed = time.perf_counter() - START
        return elapsed < by * budget_s and elapsed + needs < budget_s

    def record(**fields) -> None:
        line = json.dumps({**common, **fields, "elapsed_s": round(time.perf_counter() - START, 1)})
        print(line, flush=True)
        with open(path, "a") as f:
            f.write(line + "\n")

    def timed(fn, *args, repeats=5):
        """(result, run_s, compile_s): the harness's `measure`, its figures unpacked."""
        result, timing = measure(fn, *args, repeats=repeats)
        return result, timing.run_s, timing.compile_s

    def ahead(fn, *args):
        """fn compiled ahead of time, then run once: (result, run_s, compile_s)."""
        start = time.perf_counter()
        compiled = fn.lower(*args).compile()
        compile_s = time.perf_counter() - start
        start = time.perf_counter()
        result = jax.block_until_ready(compiled(*args))
        return result, time.perf_counter() - start, compile_s

    quick = bool(os.environ.get("QUICK"))
    sizes = (64, 256) if quick else (65536, 1 << 20)

    # -- 1. forward dynamics per second ------------------------------------------------------
    def forward():
        robots = [("chain7", chain(7))]
        if (data / "panda.urdf").exists():
            robots.append(("panda", load_urdf((data / "panda.urdf").read_text())))
        vmapped = jax.jit(jax.vmap(partial(forward_dynamics, method=Recursive()),
                                   in_axes=(None, 0, 0, 0)))
        layout = jax.jit(lambda m, q, v, t: batched_forward_dynamics(m, q, v, t))
        for name, model in robots:
            n = model.nv
            Q, V, T = (np.asarray(x) for x in states(n, max(sizes), seed=3))
            if model.nq != n:
                raise ValueError(f"{name}: the script's states assume nq = nv")
            # the same program on the host's CPU: it runs where its inputs are
            exact = np.asarray(vmapped(jax.device_put(model, cpu),
                                       *(jax.device_put(x[:256], cpu) for x in (Q, V, T))))
            for method, fn in (("vmap", vmapped), ("batch_aba", layout)):
                for dtype in ("float64", "float32"):
                    m = model if dtype == "float64" else jax.tree.map(
                        lambda x: x.astype(jnp.float32) if eqx.is_array(x) and
                        jnp.issubdtype(x.dtype, jnp.floating) else x, model)
                    for batch in sizes:
                        if not starts(0.3):
                            break
                        args = [jnp.asarray(x[:batch], dtype) for x in (Q, V, T)]
                        acc, run_s, compile_s = timed(fn, m, *args, repeats=10)
                        acc = np.asarray(acc, np.float64)
                        acc = acc.T if acc.shape[0] != batch else acc
                        k = min(batch, 256)
                        scale = np.maximum(np.abs(exact[:k]), 1.0)
                        record(kind="forward", robot=name, n=n, method=method, dtype=dtype,
                               batch=batch, run_s=run_s, compile_s=compile_s,
                               evaluations_per_s=batch / run_s,
                               max_rel_diff_cpu=float(np.max(np.abs(acc[:k] - exact[:k]) / scale)))

    # -- 2. rollouts, 3. the rollout's gradient ------------------------------------------------
    def rollouts():
        model = chain(7)
        steps, dt = 1000, 1e-3

        def final_q(q0, v0):
            return simulate(TreeSystem(model), RK4(), q0, v0, dt=dt, t1=steps * dt,
                            saveat=np.array([steps * dt])).qs[-1]

        rollouts = jax.jit(jax.vmap(final_q))
        Q, V, _ = (np.asarray(x) for x in states(7, 1 << 16 if not quick else 64, seed=1))
        for batch in ((16, 64) if quick else (16384, 65536)):
            if not starts(0.4):
                break
            _, run_s, compile_s = timed(rollouts, jnp.asarray(Q[:batch]),
                                        jnp.asarray(0.1 * V[:batch]), repeats=3)
            record(kind="rollout", robot="chain7", steps=steps, batch=batch, run_s=run_s,
                   compile_s=compile_s, steps_per_s=batch * steps / run_s)
        q0, v0 = jnp.asarray(np.linspace(0.3, 1.0, 7)), jnp.zeros(7)

        def loss(q0, v0, checkpoint=False):
            sol = simulate(TreeSystem(model), RK4(), q0, v0, dt=dt, t1=steps * dt,
                           saveat=np.array([steps * dt]), checkpoint=checkpoint)
            return jnp.sum(sol.qs[-1] ** 2)

        _, forward_s, forward_compile = timed(jax.jit(loss), q0, v0)
        for checkpoint in (False, True):
            grads, grad_s, grad_compile = timed(jax.jit(jax.grad(partial(loss, checkpoint=checkpoint),
                                                                 argnums=(0, 1))), q0, v0)
            record(kind="gradient", robot="chain7", steps=steps, checkpoint=checkpoint,
                   forward_s=forward_s, grad_s=grad_s, grad_over_forward=grad_s / forward_s,
                   forward_compile_s=forward_compile, grad_compile_s=grad_compile,
                   finite=bool(all(np.all(np.isfinite(g)) for g in grads)))

    # -- 4. MPC: vmapped closed loops ----------------------------------------------------------
    def mpc():
        from mbjax_harness.bench.mpc import ARM_PAYLOAD, _centres

        plant = arm.tracking_plant(payload=ARM_PAYLOAD)
        q0, v0 = jnp.asarray(arm.Q_REF), jnp.zeros(7)

        def first(centre):
            return arm.first_plan(arm.tracking_controller(centre=centre))

        def loop(inputs):
            centre, plan = inputs
            result = trajopt.closed_loop(arm.tracking_controller(centre=centre), plant, q0, v0,
                                         ticks=100, dt=arm.PLANT_DT, plan=plan)
            return result.qs, result.status

        firsts, loops = jax.jit(jax.vmap(first)), jax.jit(jax.vmap(loop))
        spent = 0.0
        for robots_n in ((2, 4) if quick else (64, 1024)):
            if not starts(0.6, 2 * spent):
                break
            begun = time.perf_counter()
            centres = jnp.asarray(_centres(robots_n))
            plans, plans_s, plans_compile = ahead(firsts, centres)
            (qs, status), run_s, compile_s = ahead(loops, (centres, plans))
            record(kind="mpc-batch", problem="arm-track-batch", robots=robots_n, ticks=100,
                   seconds=run_s, compile_s=compile_s, first_plans_s=plans_s,
                   first_plans_compile_s=plans_compile,
                   failed=int(np.sum((np.asarray(status) & int(Status.failures())) != 0)),
                   noted=int(np.sum(np.asarray(status) != 0)),
                   finite=bool(np.all(np.isfinite(np.asarray(qs)))))
            spent = time.perf_counter() - begun

    # -- 5. the arm's reach to many targets -------------------------------------------------
    def reach(sizes=(2,) if quick else (64,)):
        from mbjax_harness.bench.trajopt import ITERATIONS, arm_reach, targets

        problem, us0, _, _ = arm_reach()
        shipped = problem.system.model
        solver = ILQR(iterations=ITERATIONS, **CROCODDYL_SCHEDULE)
        run = eqx.filter_jit(lambda p, u: solve(p, solver, u))
        spent = 0.0
        for n in sizes:
            if not starts(0.75, 300.0 if n >= 1024 else 2 * spent):
                break
            begun = time.perf_counter()
            problems = eqx.filter_vmap(lambda o: arm.reach_problem(
                o, arm=shipped, integrator=SemiImplicitEuler()))(jnp.asarray(targets(n)))
            guesses = jnp.broadcast_to(jnp.asarray(us0), (n, *np.shape(us0)))
            results, run_s, compile_s = ahead(run, problems, guesses)
            record(kind="trajopt-many", problem="arm-reach", targets=n, run_s=run_s,
                   compile_s=compile_s, per_target_s=run_s / n,
                   iterations_mean=float(np.mean(results.iterations)),
                   converged=int(np.sum(np.asarray(results.status) == 0)))
            spent = time.perf_counter() - begun

    # -- 6. 16 ANYmal walks ----------------------------------------------------------------
    def walks():
        if not (data / "anymal.npz").exists() or not starts(0.75):
            record(kind="walk-batch", skipped="out of time" if (data / "anymal.npz").exists()
                   else "no anymal.npz")
            return
        from mbjax.gaits import QUADRUPED, Gait, walk
        from mbjax.model import state_from_pinocchio

        saved = np.load(data / "anymal.npz")
        anymal = load_urdf(str(saved["urdf"]), floating_base=True)
        anymal = eqx.tree_at(lambda m: m.damping, anymal, jnp.zeros(anymal.nv))
        anymal = eqx.tree_at(lambda m: m.armature, anymal, jnp.asarray(saved["armature"])[:anymal.nv])
        q_stand, _ = state_from_pinocchio(anymal, saved["standing"], np.zeros(anymal.nv))
        nj = anymal.nv - 6
        lower = np.r_[[-np.inf] * 6, [-9.42] * nj, [-np.inf] * 6, [-15.0] * nj]
        gait = Gait(anymal, q_stand, ("LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"), mu=0.7,
                    weights=QUADRUPED, bounds=(lower, -lower))
        count = 2 if quick else 16
        walks = [walk(gait, float(s), 0.15, 1e-2, 5 if quick else 25, 2)
                 for s in np.linspace(0.15, 0.35, count)]
        parts = [eqx.partition(p, eqx.is_array) for p in walks]
        leaves = [jnp.stack(a) for a in zip(*[jax.tree.leaves(p) for p, _ in parts])]
        batch = eqx.combine(jax.tree.unflatten(jax.tree.structure(parts[0][0]), leaves), parts[0][1])
        guesses = jnp.stack([trajopt.quasi_static(p) for p in walks])
        walker = ILQR(iterations=100, **CROCODDYL_SCHEDULE)
        run = eqx.filter_jit(lambda p, u: solve(p, walker, u))
        results, run_s, compile_s = ahead(run, batch, guesses)
        record(kind="walk-batch", problem="anymal-walk", walks=count, knots=walks[0].horizon,
               run_s=run_s, compile_s=compile_s,
               iterations=[int(i) for i in np.asarray(results.iterations)],
               costs=[float(c) for c in np.asarray(results.cost)],
               converged=int(np.sum(np.asarray(results.status) == 0)))

    # the 1 024 targets last: on the H200 they ran past four minutes (the 64 took 72 s)
    many = partial(reach, (4,) if quick else (1024,))
    many.__name__ = "reach"
    for part in (forward, rollouts, mpc, reach, walks, many):
        try:
            part()
        except Exception as error:       # one part's failure leaves the others to run
            record(kind=part.__name__, error=f"{type(error).__name__}: {error}"[:2000])


if __name__ == "__main__":
    if sys.argv[1] == "--save-data":
        save_data(Path(sys.argv[2]))
    else:
        main(Path(sys.argv[1]), Path(sys.argv[2] if len(sys.argv) > 2 else "."),
             float(sys.argv[3]) if len(sys.argv) > 3 else float(os.environ.get("BUDGET_S", 480)))
