"""MJX on the CPU against issue 58's Ant throughput target: B rollouts of gymnasium's Ant
(`mbjax.data.ANT`, RK4 at 10 ms) from the same pushed starts as `mbjax bench contact`, as one
`jax.vmap` of `mjx.step` under `lax.scan`.

MJX releases pair with their MuJoCo (mujoco-mjx 3.3.7 needs mujoco 3.3.7), while the test
extra's MuJoCo is 4.0.0, which MJX has no release for yet; run this in an environment of its
own, beside `mbjax bench contact` on the same machine:

    python -m venv /tmp/mjx && /tmp/mjx/bin/pip install "mujoco-mjx==3.3.7" "mujoco==3.3.7"
    /tmp/mjx/bin/python benchmarks/bench_contact_mjx.py [ROBOTS] [STEPS]

Prints the compile time and the time per robot and step (the best of three runs).
"""

import sys
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
from mujoco import mjx

ANT = Path(__file__).resolve().parent.parent / "mbjax" / "data" / "ant.xml"


def main(robots: int = 1024, steps: int = 100) -> None:
    m = mujoco.MjModel.from_xml_path(str(ANT))
    model = mjx.put_model(m)
    data = mjx.put_data(m, mujoco.MjData(m))
    pushes = np.random.default_rng(0).normal(scale=0.5, size=(robots, m.nv))

    def rollout(qvel):
        def step(d, _):
            return mjx.step(model, d), None
        final, _ = jax.lax.scan(step, data.replace(qvel=qvel), None, length=steps)
        return final.qpos

    run = jax.jit(jax.vmap(rollout))
    qvel = jnp.asarray(pushes)
    start = time.perf_counter()
    final = jax.block_until_ready(run(qvel))
    first = time.perf_counter() - start
    times = []
    for _ in range(3):
        start = time.perf_counter()
        jax.block_until_ready(run(qvel))
        times.append(time.perf_counter() - start)
    best = min(times)
    print(f"MJX {mujoco.__version__}, JAX {jax.__version__}: {robots} Ant rollouts of {steps} "
          f"steps: compile and first run {first:.1f} s, run {best:.2f} s, "
          f"{best / robots / steps * 1e6:.0f} us per robot and step; torso heights "
          f"{float(final[:, 2].min()):.3f}-{float(final[:, 2].max()):.3f} m")


if __name__ == "__main__":
    main(*map(int, sys.argv[1:]))
