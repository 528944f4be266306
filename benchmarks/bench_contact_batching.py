"""Batching gymnasium's Ant (issue 58's throughput target): B contact rollouts from pushed starts
as one `jax.vmap` against `jax.lax.map` over chunks of 64 and 256, in turns in one process.

    python benchmarks/bench_contact_batching.py [ROBOTS] [STEPS]

Prints each variant's compile-and-first-run time, then its time per robot and step twice.
"""

import sys
import time

import jax
import jax.numpy as jnp
import numpy as np

import mbjax
from mbjax.model import state_from_mujoco
from mbjax_harness.bench import contact

jax.config.update("jax_enable_x64", True)


def main(robots: int = 1024, steps: int = 50) -> None:
    m, model, _ = contact.load("ant")
    system, integrator = contact.mujoco_step(m, model)
    t1 = steps * m.opt.timestep
    pushes = np.random.default_rng(0).normal(scale=0.5, size=(robots, m.nv))
    q0 = jnp.asarray(m.qpos0)
    v0s = jnp.stack([state_from_mujoco(model, m.qpos0, p)[1] for p in pushes])

    def one(v):
        return mbjax.simulate(system, integrator, q0, v, dt=m.opt.timestep, t1=t1,
                              saveat=[t1]).qs[-1]

    variants = {"vmap": jax.jit(jax.vmap(one))}
    for size in (64, 256):
        variants[f"chunks of {size}"] = jax.jit(
            lambda vs, size=size: jax.lax.map(one, vs, batch_size=size))
    for name, run in variants.items():
        start = time.perf_counter()
        jax.block_until_ready(run(v0s))
        print(f"{name}: compile and first run {time.perf_counter() - start:.1f} s", flush=True)
    for _ in range(2):
        for name, run in variants.items():
            start = time.perf_counter()
            jax.block_until_ready(run(v0s))
            seconds = time.perf_counter() - start
            print(f"{name}: {seconds / robots / steps * 1e6:.0f} us per robot and step",
                  flush=True)


if __name__ == "__main__":
    main(*map(int, sys.argv[1:]))
