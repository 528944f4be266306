"""`mbjax bench contact`: contacts that find themselves, against MuJoCo on the same MJCF files.

- Agreement: each model dropped from its file's initial state with zero controls for 1 s, by
  `mbjax.contact.ContactSystem` (the file's integrator: RK4, or Euler as semi-implicit Euler)
  and by MuJoCo; the largest difference of the root's height over the run (its z, or the
  planar models' rootz), and what mbjax leaves out of the file (`from_mujoco`'s warning).
- Primitives: a sphere, a box and a capsule dropped, slid and rolled on a plane, and a box
  dropped on a box, for 1 s by both engines (MuJoCo's Euler step, semi-implicit Euler here):
  the rest heights' and the slide distances' differences.
- Throughput: B vmapped 1 s Ant rollouts from pushed starts (random initial velocities), per
  step, against `mujoco.rollout` of the same starts on the same cores (its thread pool, one
  thread per core); MJX where it installs.
- Memory: the compiled rollout's temporary bytes at 1e3 and 1e5 steps (XLA's memory analysis),
  and the process's peak resident memory before and after a 1e5-step Ant rollout.

Compile and run times are separate (median after warm-up). JSON lines + PNG.
"""

import os
import platform
import time
import warnings
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

import mbjax
from mbjax.contact import ContactSystem
from mbjax.integrate import RK4, SemiImplicitEuler
from mbjax.model import state_from_mujoco
from mbjax.rigid import TreeSystem
from mbjax_harness.timing import measure, write_jsonl

NAME = "contact"
PEERS = ("mujoco",)
MODELS = ("ant", "hopper", "walker2d", "half_cheetah", "humanoid")
DURATION = 1.0


def _gymnasium(name: str) -> str:
    import gymnasium

    return os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets", name + ".xml")


def load(name: str):
    """(MjModel, mbjax Model, the ignored features) of gymnasium's `name`."""
    import mujoco

    m = mujoco.MjModel.from_xml_path(_gymnasium(name))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = mbjax.model.from_mujoco(m)
    ignored = "; ".join(str(w.message).split("ignored: ", 1)[-1] for w in caught)
    return m, model, ignored


def mujoco_step(m, model) -> tuple[ContactSystem, object]:
    """(system, integrator) that step as MuJoCo steps the file m: its RK4, or its Euler as
    semi-implicit Euler with the joints' damping taken implicitly (unless the file disables
    `eulerdamp`), at its timestep, with its qpos0 as the inverse inertias' reference."""
    import mujoco

    rk4 = int(m.opt.integrator) == int(mujoco.mjtIntegrator.mjINT_RK4)
    eulerdamp = not int(m.opt.disableflags) & int(mujoco.mjtDisableBit.mjDSBL_EULERDAMP)
    system = ContactSystem(TreeSystem(model), timestep=m.opt.timestep,
                           q_reference=jnp.asarray(m.qpos0),
                           implicit_damping=not rk4 and eulerdamp)
    return system, RK4() if rk4 else SemiImplicitEuler()


def agreement(name: str, common: dict) -> dict:
    import mujoco

    m, model, ignored = load(name)
    steps = int(round(DURATION / m.opt.timestep))
    d = mujoco.MjData(m)
    heights = []
    root = 2 if model.joint_types[0] == "free" else 1          # z, or the planar rootz
    for _ in range(steps):
        mujoco.mj_step(m, d)
        heights.append(d.qpos[root])
    system, integrator = mujoco_step(m, model)
    sol, timing = measure(partial(mbjax.simulate, system, integrator, jnp.asarray(m.qpos0), jnp.zeros(m.nv), dt=m.opt.timestep,
                                  t1=steps * m.opt.timestep), repeats=3)
    ours = np.asarray(sol.qs[1:, root])
    return {**common, "kind": "agreement", "model": name, "dt": float(m.opt.timestep),
            "integrator": type(integrator).__name__, "steps": steps,
            "height_error_max_m": float(np.abs(ours - np.asarray(heights)).max()),
            "height_final_mbjax_m": float(ours[-1]), "height_final_mujoco_m": float(heights[-1]),
            "compile_s": timing.compile_s, "run_s": timing.run_s,
            "status": sol.messages()[0], "mbjax_ignores": ignored}


PRIMITIVES = {   # name: (the body's geom, its initial qvel)
    "sphere-drop": ('<geom type="sphere" size="0.1" mass="1"/>', None),
    "box-drop": ('<geom type="box" size="0.1 0.2 0.05" mass="1"/>', None),
    "capsule-drop": ('<geom type="capsule" size="0.05 0.2" euler="0 80 0" mass="1"/>', None),
    "box-slide": ('<geom type="box" size="0.1 0.2 0.05" mass="1"/>', [1.0, 0.3, 0, 0, 0, 0]),
    "sphere-roll": ('<geom type="sphere" size="0.1" mass="1"/>', [1.0, 0.0, 0, 0, 0, 0]),
    "box-on-box": ('<geom type="box" size="0.1 0.1 0.1" mass="1"/>', None),
}


def primitive(name: str, common: dict) -> dict:
    """A body dropped (or slid, rolled) on a plane, or on a fixed box, for 1 s: mbjax against
    MuJoCo (its Euler step: semi-implicit Euler)."""
    import mujoco

    geom, qvel = PRIMITIVES[name]
    under = '<geom type="box" size="0.2 0.2 0.1" pos="0 0 0.1"/>' if "on-box" in name else ""
    xml = (f'<mujoco><worldbody><geom type="plane" size="5 5 .1"/>{under}'
           f'<body pos="0 0 0.45"><freejoint/>{geom}</body></worldbody></mujoco>')
    m = mujoco.MjModel.from_xml_string(xml)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = mbjax.model.from_mujoco(m)
    steps = int(round(DURATION / m.opt.timestep))
    d = mujoco.MjData(m)
    if qvel is not None:
        d.qvel[:] = qvel
    positions = []
    for _ in range(steps):
        mujoco.mj_step(m, d)
        positions.append(d.qpos[:3].copy())
    positions = np.asarray(positions)
    system, integrator = mujoco_step(m, model)
    v0 = jnp.zeros(6) if qvel is None else state_from_mujoco(model, m.qpos0, np.asarray(qvel))[1]
    sol = mbjax.simulate(system, integrator, jnp.asarray(m.qpos0), v0, dt=m.opt.timestep,
                         t1=steps * m.opt.timestep)
    ours = np.asarray(sol.qs[1:, :3])
    slide = lambda p: float(np.linalg.norm(p[-1, :2] - p[0, :2]))  # noqa: E731
    return {**common, "kind": "primitive", "model": name, "steps": steps,
            "rest_height_mbjax_m": float(ours[-1, 2]), "rest_height_mujoco_m": float(positions[-1, 2]),
            "rest_height_error_m": float(abs(ours[-1, 2] - positions[-1, 2])),
            "slide_mbjax_m": slide(ours), "slide_mujoco_m": slide(positions),
            "slide_error_m": abs(slide(ours) - slide(positions)),
            "position_error_max_m": float(np.abs(ours - positions).max()),
            "status": sol.messages()[0]}


def memory(common: dict) -> dict:
    """The Ant's rollout compiled for 1e3 and 1e5 steps (XLA's temporary bytes: the same), and
    the process's peak resident memory across a 1e5-step run (saving its last state)."""
    import resource

    m, model, _ = load("ant")
    system, integrator = mujoco_step(m, model)
    q0, dt = jnp.asarray(m.qpos0), float(m.opt.timestep)

    def rollout(steps):
        return jax.jit(lambda v: mbjax.simulate(system, integrator, q0, v, dt=dt, t1=steps * dt,
                                                saveat=[steps * dt]).qs[-1])

    v0 = jnp.zeros(m.nv)
    temp = {steps: rollout(steps).lower(v0).compile().memory_analysis().temp_size_in_bytes
            for steps in (1_000, 100_000)}
    run = rollout(100_000)
    jax.block_until_ready(run(v0 + 1e-3))                        # compiled, and one run
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    start = time.perf_counter()
    jax.block_until_ready(run(v0))
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return {**common, "kind": "memory", "model": "ant", "steps": 100_000,
            "temp_bytes_1e3_steps": int(temp[1_000]), "temp_bytes_1e5_steps": int(temp[100_000]),
            "peak_rss_growth_kb": int(after - before), "seconds": seconds}


def throughput(batch: int, common: dict) -> list[dict]:
    import mujoco
    from mujoco import rollout

    m, model, _ = load("ant")
    steps = int(round(DURATION / m.opt.timestep))
    rng = np.random.default_rng(0)
    pushes = rng.normal(scale=0.5, size=(batch, m.nv))
    contact, integrator = mujoco_step(m, model)
    q0 = jnp.asarray(m.qpos0)
    v0s = jnp.stack([state_from_mujoco(model, m.qpos0, p)[1] for p in pushes])
    t1 = steps * m.opt.timestep
    run = jax.jit(jax.vmap(lambda v: mbjax.simulate(contact, integrator, q0, v,
                                                    dt=m.opt.timestep, t1=t1,
                                                    saveat=[t1]).qs[-1]))
    final, timing = measure(run, v0s, repeats=3)
    records = [{**common, "kind": "throughput", "engine": "mbjax", "model": "ant",
                "robots": batch, "steps": steps, "compile_s": timing.compile_s,
                "seconds": timing.run_s, "us_per_robot_step": timing.run_s / batch / steps * 1e6}]
    d = mujoco.MjData(m)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.zeros((batch, mujoco.mj_stateSize(m, spec)))
    for b in range(batch):
        mujoco.mj_resetData(m, d)
        d.qvel[:] = pushes[b]
        mujoco.mj_getState(m, d, state[b], spec)
    threads = os.cpu_count() or 1
    with rollout.Rollout(nthread=threads) as pool:
        datas = [mujoco.MjData(m) for _ in range(threads)]
        pool.rollout(m, datas, state, nstep=steps)                  # warm-up
        times = []
        for _ in range(3):
            start = time.perf_counter()
            states, _ = pool.rollout(m, datas, state, nstep=steps)
            times.append(time.perf_counter() - start)
    seconds = sorted(times)[1]
    records.append({**common, "kind": "throughput", "engine": "mujoco.rollout", "model": "ant",
                    "robots": batch, "steps": steps, "threads": threads, "seconds": seconds,
                    "us_per_robot_step": seconds / batch / steps * 1e6})
    heights = states[:, -1, 1 + 2]                    # (time, qpos...) of the last step: z
    records[0]["final_height_gap_to_mujoco_m"] = float(np.abs(np.asarray(final[:, 2])
                                                              - heights).max())
    return records


def plot(records: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
    rows = [r for r in records if r["kind"] == "agreement"]
    left.bar([r["model"] for r in rows], [r["height_error_max_m"] * 1e3 for r in rows])
    left.axhline(10.0, color="k", lw=0.8, ls="--", label="1 cm")
    left.set_yscale("log")
    left.set_ylabel("max |root height - MuJoCo's| over 1 s [mm]")
    left.set_title("A 1 s drop with zero controls, against MuJoCo")
    left.legend()
    rows = [r for r in records if r["kind"] == "throughput"]
    right.bar([r["engine"] for r in rows], [r["us_per_robot_step"] for r in rows])
    right.set_ylabel("us per robot and step")
    right.set_title(f"{rows[0]['robots'] if rows else 0} Ant rollouts, 1 s" if rows else "")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def run(out: Path, quick: bool = False) -> list[dict]:
    from mbjax_harness import peers

    for needed in ("mujoco", "gymnasium"):
        if (why := peers.missing(needed)) is not None:
            return [{"suite": NAME, "library": needed,
                     "skipped": f"{why}: the models are gymnasium's MJCF files, read by MuJoCo"}]
    common = {"suite": NAME, "machine": platform.machine(), "cpus": os.cpu_count(),
              "jax": jax.__version__, "date": time.strftime("%Y-%m-%d")}
    records = []
    for name in (("ant", "hopper") if quick else MODELS):
        records.append(agreement(name, common))
    for name in (("sphere-drop", "box-on-box") if quick else PRIMITIVES):
        records.append(primitive(name, common))
    records += throughput(64 if quick else 1024, common)
    if not quick:
        records.append(memory(common))
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_jsonl(out / f"{NAME}.jsonl", records)
    plot(records, out / f"{NAME}.png")
    return records
