"""A parameter sweep across processes with `jax.distributed`: one sweep, every process's devices.

Each process runs this script with its own id; together they form one JAX program whose devices
are all the processes' devices (`jax.devices()`), and `mbjax.trajopt.sweep` splits the variants
over them. The sweep: the 7-dof arm (`mbjax.data.ARM7`) with its link masses scaled by a factor
per variant, the joint torques that hold it at the scene's pose (inverse dynamics). Process 0
gathers the outputs and writes them, with the variants, to --out as JSON.

On one machine (CPU devices, one per process; gloo carries the gather between them):

    python benchmarks/sweep_distributed.py --process-id 0 --processes 2 --out sweep.json &
    python benchmarks/sweep_distributed.py --process-id 1 --processes 2

On several hosts, the same with --coordinator HOST:PORT of process 0's host. tests/trajopt/
test_sweep.py starts two local processes and checks the gathered result against the sweep run
in one process.
"""

import argparse
import json


def variants(n: int):
    """The swept parameters: {"scale": (n,)} mass factors from 0.5 to 2."""
    import jax.numpy as jnp

    return {"scale": jnp.linspace(0.5, 2.0, n)}


def holding_torques(params):
    """The torques (7,) that hold the arm, its link masses scaled by params["scale"], at rest at
    the scene's pose (`mbjax.scenes.arm.Q_REF`)."""
    import equinox as eqx
    import jax.numpy as jnp

    from mbjax.rigid import inverse_dynamics
    from mbjax.scenes import arm

    model = arm.model()
    model = eqx.tree_at(lambda m: m.mass, model, model.mass * params["scale"])
    q, zero = jnp.asarray(arm.Q_REF), jnp.zeros(model.nv)
    return inverse_dynamics(model, q, zero, zero)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--process-id", type=int, required=True)
    parser.add_argument("--processes", type=int, required=True)
    parser.add_argument("--coordinator", default="localhost:12355", help="HOST:PORT of process 0")
    parser.add_argument("--variants", type=int, default=64)
    parser.add_argument("--out", default="sweep.json", help="where process 0 writes the result")
    args = parser.parse_args(argv)

    import jax

    jax.config.update("jax_enable_x64", True)
    jax.config.update("jax_cpu_collectives_implementation", "gloo")   # CPU processes' gather
    jax.distributed.initialize(coordinator_address=args.coordinator,
                               num_processes=args.processes, process_id=args.process_id)
    import numpy as np
    from jax.experimental import multihost_utils

    from mbjax.trajopt import sweep

    params = variants(args.variants)
    out = sweep(holding_torques, params, devices=jax.devices(), trim=False)
    gathered = np.asarray(multihost_utils.process_allgather(out, tiled=True))[:args.variants]
    if jax.process_index() == 0:
        with open(args.out, "w") as f:
            json.dump({"processes": jax.process_count(), "devices": len(jax.devices()),
                       "scale": np.asarray(params["scale"]).tolist(),
                       "torques": gathered.tolist()}, f)
    jax.distributed.shutdown()


if __name__ == "__main__":
    main()
