"""`mbjax bench throughput`: batched dynamics, rollouts and their gradients on revolute chains.
Forward dynamics, rollouts and rollout gradients, against Pinocchio, MuJoCo and MJX in one run.

For regular n-link chains (`mbjax.model.chain(n)`, n = 7, 30, 100; float64 unless said, CPU):

1. Forward dynamics of B = 1 ... 4096 states: mbjax's throughput layout `batch_aba`
   (`mbjax.rigid.batched_forward_dynamics`: batch last inside, structure of arrays; its source is
   mbjax/_src/rigid/batched.py), in float64 and float32, and
   `jit(vmap(forward_dynamics))` of the one-state recursion; against Pinocchio's `aba` called once
   per state from Python, and Pinocchio's batched API `abaInParallel` (OpenMP, one thread per
   core). Time per state; accelerations checked against Pinocchio's.
2. Rollouts of ROLLOUT_STEPS RK4 steps (dt = 1 ms, zero torque: the chain falls) of B states:
   one trajectory's `simulate(TreeSystem)` mapped over chunks of the batch (`mbjax_rollout_fn`)
   against `mujoco.rollout` (multi-threaded C, RK4, one MjData per core) and MJX
   (`jit(vmap(scan(mjx.step)))`, RK4; one batch size, fewer steps). Steps per second
   (B x steps / run time); the final states of mbjax and MuJoCo are compared.
3. The gradient of loss = sum q(T)^2 over a 1000-step rollout of one trajectory
   (`simulate(TreeSystem)`) with respect to (q0, v0), against
   the forward rollout: run time and XLA's temporary memory (`memory_analysis`) of `jax.grad`
   plain and with `simulate(checkpoint=True)`, also at 250 and 4000 steps, where the memory's
   growth in T is fitted; and of forward mode (`jax.jacfwd`, 2n tangents carried with the state),
   the cheaper route for few inputs.

With more than one CPU device (`mbjax bench throughput` starts one per core, `cli`), the rollouts
and a "vmap sharded" series (`jit(vmap(forward_dynamics))` with its batch split by
`jax.shard_map`) split the batch over them, as the peers use one thread per core.

JSON lines + PNG; the last record (kind "summary") holds the throughput targets, each met or
missed with its ratio.
"""

import os
import platform
import time
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax import Recursive
from mbjax_harness import peers
from mbjax_harness.bench.rigid import pinocchio_loop, relative_difference
from mbjax_harness.common import states
from mbjax_harness.timing import timed, write_jsonl
from mbjax.integrate import RK4, simulate
from mbjax.model import chain, to_urdf
from mbjax.rigid import TreeSystem, batched_forward_dynamics, forward_dynamics

NAME = "throughput"
# the peers compared with where installed, left out of the records where not: the
# command's closing line names those missing (`mbjax_harness.cli._declared`)
PEERS = ("pinocchio", "mujoco")
NS, QUICK_NS = (7, 30, 100), (7,)
BATCHES, QUICK_BATCHES = (1, 4, 16, 64, 256, 1024, 4096), (1, 64, 1024)
DT = 1e-3
ROLLOUT_STEPS, QUICK_ROLLOUT_STEPS = 1000, 100
ROLLOUT_BATCHES, QUICK_ROLLOUT_BATCHES = (1, 16, 64, 256, 1024, 4096), (16, 256)
ROLLOUT_CHUNK = 128                # states per chunk of a batch of rollouts (`mbjax_rollout_fn`)
ROLLOUT_MAX_WORK = 64 * 100       # B n at most, for n > 7 (rollouts at n = 100 cost seconds)
MJX_BATCH, MJX_STEPS = 64, 20
GRAD_N, GRAD_STEPS = 7, 1000
MEMORY_STEPS = (250, 1000, 4000)
PEER_STATES = 256
THREADS = os.cpu_count() or 1
# targets
TARGET_MJX_RATIO, TARGET_GRAD_RATIO, TARGET_GPU_EVALS = 10.0, 4.0, 1e8


def shard_batch(x, devices, axis: int = -1):
    """x placed with its batch axis (the last by default) split over `devices` (one per core, see
    `run`), or unchanged on one device or where B does not divide."""
    if len(devices) < 2 or x.shape[axis] % len(devices):
        return x
    names = [None] * x.ndim
    names[axis] = "batch"
    spec = jax.sharding.PartitionSpec(*names)
    return jax.device_put(x, jax.sharding.NamedSharding(jax.sharding.Mesh(devices, ("batch",)), spec))


def _batch_fn(dtype):
    def run(model, q, v, tau):
        # batched_forward_dynamics(...).T: the throughput layout's own (n, B) result, as the
        # records have always timed it (the transposes cancel in the compiled program)
        return batched_forward_dynamics(model, q, v, tau).T
    return jax.jit(run) if dtype == "float64" else jax.jit(
        lambda model, q, v, tau: run(model, *(x.astype(jnp.float32) for x in (q, v, tau))))


def _split(fn, devices, in_specs, out_specs):
    """jit(fn) with its "batch" axis split over `devices` by `jax.shard_map`: each device runs its
    part as the one-device program does. check_vma=False: mbjax's scans start from constants
    (the ground's values), which shard_map's check of varying axes would reject as carries of
    another type."""
    return jax.jit(jax.shard_map(fn, mesh=jax.sharding.Mesh(devices, ("batch",)),
                                 in_specs=in_specs, out_specs=out_specs, check_vma=False))


def _sharded_fn(devices):
    """`jit(vmap(forward_dynamics))` with the batch (first axis) split over `devices` (`_split`;
    a jit of the whole batch left the partitioning to XLA, which did not split the chunked loop:
    1.69 against 1.58 us per state on one device). The vmap's own route on each device, not
    `batch_aba` split by its last axis: 7-link chain, B = 4096, 0.70 against 0.93 us per state
    (one A/B script, two devices)."""
    spec = jax.sharding.PartitionSpec("batch")
    fd = jax.vmap(partial(forward_dynamics, method=Recursive()), in_axes=(None, 0, 0, 0))
    return _split(fd, devices, (jax.sharding.PartitionSpec(), spec, spec, spec), spec)


def _vmap_fn():
    return jax.jit(jax.vmap(partial(forward_dynamics, method=Recursive()), in_axes=(None, 0, 0, 0)))


def pinocchio_parallel(urdf: str, Q, V, T, repeats: int, budget_s: float) -> dict:
    """`pin.abaInParallel` over the whole batch, THREADS threads: per-state time and the result."""
    import pinocchio as pin

    model = pin.buildModelFromXML(urdf)
    pool = pin.ModelPool(model, THREADS)
    q, v, t = (np.asfortranarray(np.asarray(x).T) for x in (Q, V, T))
    out = np.zeros_like(v)
    _, timing = timed(lambda: pin.abaInParallel(THREADS, pool, q, v, t, out), repeats=repeats,
                      budget_s=budget_s)
    return {"per_state_s": timing.run_s / len(Q), "runs": timing.runs, "acc": out.T.copy()}


def _forward_records(ns, batches, repeats: int, budget_s: float, common: dict) -> list[dict]:
    records = []
    for n in ns:
        model = chain(n)
        urdf = to_urdf(model)
        Q, V, T = (jnp.asarray(x) for x in states(n, max(batches)))
        ref = None
        if peers.available("pinocchio"):
            k = min(PEER_STATES, len(Q))
            loop = pinocchio_loop(urdf, *(np.asarray(x[:k]) for x in (Q, V, T)), repeats=repeats,
                                  budget_s=budget_s)
            ref = loop.pop("acc")
            records.append({**common, "kind": "forward", "engine": "pinocchio", "method": "aba",
                            "n": n, "batch": 1, "dtype": "float64", **loop})
            for batch in batches:
                par = pinocchio_parallel(urdf, Q[:batch], V[:batch], T[:batch], repeats, budget_s)
                diff = relative_difference(par.pop("acc")[:k], ref[:min(k, batch)])
                records.append({**common, "kind": "forward", "engine": "pinocchio",
                                "method": "abaInParallel", "threads": THREADS, "n": n,
                                "batch": batch, "dtype": "float64", "rel_diff_aba": diff, **par})
        f64 = _batch_fn("float64")
        for method, dtype, fn in (("batch_aba", "float64", f64),
                                  ("batch_aba", "float32", _batch_fn("float32")),
                                  ("vmap", "float64", _vmap_fn()),
                                  ("vmap sharded", "float64", _sharded_fn(jax.devices()))):
            if method == "vmap sharded" and len(jax.devices()) < 2:
                continue
            for batch in batches:
                if method == "vmap sharded" and batch % len(jax.devices()):
                    continue
                args = (model, Q[:batch], V[:batch], T[:batch])
                if method == "vmap sharded":
                    args = (model, *(shard_batch(x[:batch], jax.devices(), axis=0)
                                     for x in (Q, V, T)))
                acc, timing = timed(fn, *args, repeats=repeats, budget_s=budget_s)
                acc = np.asarray(acc)
                if method.startswith("batch_aba"):
                    acc = acc.T
                record = {**common, "kind": "forward", "engine": "mbjax", "method": method,
                          "devices": len(jax.devices()) if "sharded" in method else 1,
                          "n": n, "batch": batch, "dtype": dtype, "per_state_s": timing.run_s / batch,
                          "compile_s": timing.compile_s, "runs": timing.runs}
                if ref is not None:
                    k = min(len(ref), batch)
                    record["rel_diff_pinocchio"] = relative_difference(acc[:k], ref[:k])
                if method == "batch_aba" and dtype == "float32":
                    exact = np.asarray(f64(model, Q[:batch], V[:batch], T[:batch])).T
                    record["rel_diff_float64"] = relative_difference(acc, exact)
                records.append(record)
    return records


# -- rollouts --------------------------------------------------------------------------------------

def _mujoco_model(n: int):
    import mujoco

    model = mujoco.MjModel.from_xml_string(to_urdf(chain(n)))
    model.opt.timestep = DT
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    return model


def mujoco_rollout_run(n: int, Q, V, steps: int, repeats: int, budget_s: float) -> dict:
    """`mujoco.rollout` of B states, one MjData per thread: run time and the final qpos."""
    import mujoco
    from mujoco import rollout

    model = _mujoco_model(n)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    data = mujoco.MjData(model)
    initial = np.zeros((len(Q), mujoco.mj_stateSize(model, spec)))
    for b, (q, v) in enumerate(zip(np.asarray(Q), np.asarray(V), strict=True)):
        data.qpos[:], data.qvel[:] = q, v
        mujoco.mj_getState(model, data, initial[b], spec)
    datas = [mujoco.MjData(model) for _ in range(THREADS)]
    out, timing = timed(lambda: rollout.rollout(model, datas, initial, nstep=steps)[0],
                        repeats=repeats, budget_s=budget_s)
    return {"run_s": timing.run_s, "runs": timing.runs, "threads": THREADS,
            "final_q": out[:, -1, 1:1 + n].copy()}


def mjx_rollout_run(n: int, Q, V, steps: int) -> dict:
    """MJX on the CPU: jit(vmap(scan(mjx.step))), RK4; compile time and run time."""
    from mujoco import mjx

    model = mjx.put_model(_mujoco_model(n))
    data0 = mjx.make_data(model)

    def roll(q, v):
        def body(d, _):
            return mjx.step(model, d), None
        return jax.lax.scan(body, data0.replace(qpos=q, qvel=v), None, length=steps)[0].qpos

    out, timing = timed(jax.jit(jax.vmap(roll)), jnp.asarray(Q), jnp.asarray(V), repeats=3,
                        budget_s=20.0)
    return {"run_s": timing.run_s, "compile_s": timing.compile_s, "runs": timing.runs,
            "final_q": np.asarray(out)}


def mbjax_rollout_fn(model, steps: int, devices=None):
    """B states (B, nv) through `steps` RK4 steps, the final q (B, nv): one trajectory's
    `simulate(TreeSystem(model))`, mapped over the batch in chunks of ROLLOUT_CHUNK states
    (`jax.lax.map(..., batch_size=)`: within a chunk the rollout is vmapped, so each step runs
    `batch_aba` on the chunk, whose states stay in cache for the whole rollout, where all B states
    advancing step by step fall out of it: 7-link chain, B = 4096, one core, 0.95e5 -> 2.3e5
    steps/s). With several `devices` (one per core) and B divisible by their number, the batch is
    split over them (`_split`, inputs placed by `shard_batch(x, devices, axis=0)`)."""
    def one(q0, v0):
        return simulate(TreeSystem(model), RK4(), q0, v0, dt=DT, t1=steps * DT,
                        saveat=np.array([steps * DT])).qs[-1]

    def chunks(Q, V):
        return jax.lax.map(lambda s: one(*s), (Q, V), batch_size=min(ROLLOUT_CHUNK, Q.shape[0]))

    devices = jax.devices() if devices is None else devices
    local = jax.jit(chunks)
    if len(devices) < 2:
        return local
    spec = jax.sharding.PartitionSpec("batch")
    split = _split(chunks, devices, (spec, spec), spec)

    def run(Q, V):
        return (local if Q.shape[0] % len(devices) else split)(Q, V)
    return run


def _rollout_records(ns, batches, steps: int, repeats: int, budget_s: float, mjx: bool,
                     common: dict) -> list[dict]:
    records = []
    for n in ns:
        sizes = [b for b in batches if n == 7 or b * n <= ROLLOUT_MAX_WORK]
        Q, V, _ = (jnp.asarray(x) for x in states(n, max(sizes), seed=1))
        V = 0.1 * V
        fn = mbjax_rollout_fn(chain(n), steps)
        base = {**common, "kind": "rollout", "n": n, "steps": steps, "dt": DT, "integrator": "rk4"}
        devices = jax.devices()
        for batch in sizes:
            final, timing = timed(fn, shard_batch(Q[:batch], devices, axis=0),
                                  shard_batch(V[:batch], devices, axis=0), repeats=repeats, budget_s=budget_s)
            used = len(devices) if batch % len(devices) == 0 else 1
            record = {**base, "engine": "mbjax", "batch": batch, "devices": used, "run_s": timing.run_s,
                      "compile_s": timing.compile_s, "runs": timing.runs,
                      "steps_per_s": batch * steps / timing.run_s}
            if peers.available("mujoco"):
                mj = mujoco_rollout_run(n, Q[:batch], V[:batch], steps, repeats, budget_s)
                diff = float(np.max(np.abs(np.asarray(final) - mj.pop("final_q"))))
                records.append({**base, "engine": "mujoco", "batch": batch, **mj,
                                "steps_per_s": batch * steps / mj["run_s"]})
                record["max_diff_mujoco_rad"] = diff
            records.append(record)
        if mjx and n == 7 and peers.available("mujoco.mjx"):
            mx = mjx_rollout_run(n, Q[:MJX_BATCH], V[:MJX_BATCH], MJX_STEPS)
            short = mbjax_rollout_fn(chain(n), MJX_STEPS, devices[:1])(Q[:MJX_BATCH], V[:MJX_BATCH])
            diff = float(np.max(np.abs(np.asarray(short) - mx.pop("final_q"))))
            records.append({**base, "engine": "mjx", "batch": MJX_BATCH, "steps": MJX_STEPS, **mx,
                            "steps_per_s": MJX_BATCH * MJX_STEPS / mx["run_s"],
                            "max_diff_mbjax_rad": diff})
    return records


# -- gradients ------------------------------------------------------------------------------------

def _loss_fn(model, steps: int, checkpoint: bool):
    """sum q(T)^2 of one trajectory through `TreeSystem`, whose forward dynamics carries the
    derivatives of mbjax/_src/rigid/adjoint.py (the batched layout has none of its own)."""
    def loss(q0, v0):
        sol = simulate(TreeSystem(model), RK4(), q0, v0, dt=DT, t1=steps * DT,
                       saveat=np.array([steps * DT]), checkpoint=checkpoint)
        return jnp.sum(sol.qs[-1] ** 2)
    return loss


def temp_bytes(fn, *args) -> int:
    """XLA's temporary buffer size for fn(*args) (compiled ahead of time, not run)."""
    return int(jax.jit(fn).lower(*args).compile().memory_analysis().temp_size_in_bytes)


def _gradient_records(memory_steps, repeats: int, common: dict) -> list[dict]:
    model = chain(GRAD_N)
    q0 = jnp.asarray(np.linspace(0.3, 1.0, GRAD_N))
    v0 = jnp.zeros_like(q0)
    base = {**common, "kind": "gradient", "n": GRAD_N, "batch": 1, "dt": DT,
            "integrator": "rk4", "loss": "sum(q(T)^2), grad wrt (q0, v0)"}
    loss = _loss_fn(model, GRAD_STEPS, False)
    _, fwd = timed(jax.jit(loss), q0, v0, repeats=repeats, budget_s=5.0)
    forward_memory = {T: temp_bytes(_loss_fn(model, T, False), q0, v0) for T in memory_steps}
    records = []
    for mode, checkpoint in (("grad", False), ("grad", True), ("jacfwd", False)):
        derivative = jax.grad if mode == "grad" else jax.jacfwd
        grads, grad = timed(jax.jit(derivative(_loss_fn(model, GRAD_STEPS, checkpoint),
                                               argnums=(0, 1))), q0, v0, repeats=repeats,
                            budget_s=10.0)
        memory = {T: temp_bytes(derivative(_loss_fn(model, T, checkpoint), argnums=(0, 1)), q0, v0)
                  for T in memory_steps}
        slope = (float(np.polyfit(np.log(memory_steps), np.log(list(memory.values())), 1)[0])
                 if len(memory_steps) > 1 else None)
        records.append({**base, "engine": "mbjax", "mode": mode, "checkpoint": checkpoint,
                        "steps": GRAD_STEPS, "forward_s": fwd.run_s, "forward_compile_s": fwd.compile_s,
                        "grad_s": grad.run_s, "grad_compile_s": grad.compile_s,
                        "grad_over_forward": grad.run_s / fwd.run_s,
                        "finite": bool(all(np.all(np.isfinite(g)) for g in grads)),
                        "memory_steps": list(memory_steps),
                        "grad_temp_bytes": list(memory.values()),
                        "forward_temp_bytes": list(forward_memory.values()),
                        "memory_slope": slope})
    return records


# -- summary --------------------------------------------------------------------------------------

def _target(value, target, better: str) -> dict:
    """A target record: met or missed, and by what factor (>1 is how far from the target)."""
    if value is None:
        return {"value": None, "target": target, "met": None, "note": "not measured"}
    met = value <= target if better == "lower" else value >= target
    factor = value / target if better == "lower" else target / value
    return {"value": value, "target": target, "met": bool(met), "missed_by": None if met else factor}


def summarize(records: list[dict], common: dict) -> dict:
    def pick(**kw):
        return [r for r in records if all(r.get(k) == v for k, v in kw.items())]

    out = {**common, "kind": "summary", "targets": {}}
    pin = pick(kind="forward", engine="pinocchio", method="aba", n=7)
    ours = [r for r in pick(kind="forward", engine="mbjax", method="batch_aba", n=7, dtype="float64")
            if r["batch"] >= 1024]
    if pin and ours:
        best = min(r["per_state_s"] for r in ours)
        out["targets"]["forward_vs_pinocchio_per_call"] = {
            **_target(best / pin[0]["per_state_s"], 1.0, "lower"),
            "mbjax_per_state_s": best, "pinocchio_per_call_s": pin[0]["per_state_s"],
            "note": "mbjax batch_aba per state at B >= 1024 over Pinocchio's aba per call from Python"}
        parallel = [r for r in pick(kind="forward", engine="pinocchio", method="abaInParallel", n=7)
                    if r["batch"] >= 1024]
        if parallel:
            out["forward_vs_pinocchio_parallel"] = best / min(r["per_state_s"] for r in parallel)
    roll = pick(kind="rollout", engine="mbjax", n=7)
    mj = pick(kind="rollout", engine="mujoco", n=7)
    if roll and mj:
        batch = max(r["batch"] for r in mj)
        ours_b = next(r for r in roll if r["batch"] == batch)
        theirs = next(r for r in mj if r["batch"] == batch)
        out["targets"]["rollout_vs_mujoco"] = {
            **_target(ours_b["steps_per_s"] / theirs["steps_per_s"], 1.0, "higher"),
            "batch": batch, "mbjax_steps_per_s": ours_b["steps_per_s"],
            "mujoco_steps_per_s": theirs["steps_per_s"],
            "ratio_by_batch": {r["batch"]: next(x for x in roll if x["batch"] == r["batch"])
                               ["steps_per_s"] / r["steps_per_s"] for r in mj}}
    mx = pick(kind="rollout", engine="mjx", n=7)
    if roll and mx:
        ours_b = next((r for r in roll if r["batch"] == mx[0]["batch"]), roll[-1])
        out["targets"]["rollout_vs_mjx"] = {
            **_target(ours_b["steps_per_s"] / mx[0]["steps_per_s"], TARGET_MJX_RATIO, "higher"),
            "mbjax_steps_per_s": ours_b["steps_per_s"], "mjx_steps_per_s": mx[0]["steps_per_s"],
            "mjx_compile_s": mx[0]["compile_s"]}
    elif roll:
        out["targets"]["rollout_vs_mjx"] = {"met": None, "note": "MJX (mujoco-mjx) not installed"}
    grads = {r["checkpoint"]: r for r in pick(kind="gradient", mode="grad")}
    forward_mode = pick(kind="gradient", mode="jacfwd")
    if True in grads:
        out["targets"]["gradient_over_forward"] = {
            **_target(grads[True]["grad_over_forward"], TARGET_GRAD_RATIO, "lower"),
            "checkpoint": True, "without_checkpoint": grads[False]["grad_over_forward"],
            "memory_slope_checkpoint": grads[True]["memory_slope"],
            "memory_slope_plain": grads[False]["memory_slope"],
            "jacfwd_over_forward": forward_mode[0]["grad_over_forward"] if forward_mode else None}
    gpu = [d for d in jax.devices() if d.platform == "gpu"]
    out["targets"]["gpu_forward_evals_per_s"] = (
        {"met": None, "note": "no GPU in this run (the suite runs unchanged where one is)"}
        if not gpu else _target(1.0 / min(r["per_state_s"] for r in pick(
            kind="forward", engine="mbjax", method="batch_aba", n=7, dtype="float64")),
            TARGET_GPU_EVALS, "higher"))
    return out


def run(out: Path, quick: bool = False) -> list[dict]:
    common = {"jax": jax.__version__, "platform": platform.machine(),
              "device": jax.devices()[0].platform, "threads": THREADS, "date": time.strftime("%Y-%m-%d")}
    repeats, budget = (3, 0.5) if quick else (10, 3.0)
    records = _forward_records(QUICK_NS if quick else NS, QUICK_BATCHES if quick else BATCHES,
                               repeats, budget, common)
    records += _rollout_records(QUICK_NS if quick else NS,
                                QUICK_ROLLOUT_BATCHES if quick else ROLLOUT_BATCHES,
                                QUICK_ROLLOUT_STEPS if quick else ROLLOUT_STEPS, repeats, budget,
                                mjx=not quick, common=common)
    records += _gradient_records(MEMORY_STEPS[:2] if quick else MEMORY_STEPS, repeats, common)
    records.append(summarize(records, common))
    write_jsonl(out / f"{NAME}.jsonl", records)
    from mbjax_harness.plot.bench import throughput_figure
    throughput_figure(records).savefig(out / f"{NAME}.png", dpi=120)
    print(report(records))
    return records


def report(records: list[dict]) -> str:
    summary = records[-1]
    lines = ["throughput targets:"]
    for name, t in summary["targets"].items():
        state = {True: "met", False: "MISSED", None: "not run"}[t.get("met")]
        value = t.get("value")
        lines.append(f"  {name}: {state}" + (f" ({value:.3g} against {t['target']})"
                                             if value is not None else f" ({t.get('note', '')})"))
    return "\n".join(lines)
