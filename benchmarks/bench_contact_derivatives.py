"""A four-foot stance's derivatives, mbjax against Pinocchio in the same process (issue 57).

    python benchmarks/bench_contact_derivatives.py [--robots anymal solo12] [--batch 64]

For each robot of example-robot-data: `jax.jit(jax.vmap(jax.jacfwd(...)))` of the stance's
accelerations and contact forces in (dq, v, tau) over a batch of states (per state, median of
10 calls after the compiling one, compile time apart), against Pinocchio's `constraintDynamics`
plus `computeConstraintDynamicsDerivatives` per state on the same contacts (Baumgarte Kd = 50,
Crocoddyl's). Prints one JSON line per robot.
"""

import argparse
import json
import time

import jax
import jax.numpy as jnp
import numpy as np

ROBOTS = {"anymal": ("anymal", ["LF_FOOT", "LH_FOOT", "RF_FOOT", "RH_FOOT"]),
          "solo12": ("solo12", ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"])}


def _median(f, repeats=10):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def run(robot: str, batch: int) -> dict:
    import example_robot_data as erd
    import pinocchio as pin

    import mbjax
    from mbjax.contact import PointContact, stance
    from mbjax.control import Constant
    from mbjax.rigid import TreeSystem
    from mbjax_harness.peers import pinocchio_point_contacts

    name, feet = ROBOTS[robot]
    r = erd.load(name)
    model = mbjax.load_urdf(r.urdf, floating_base=True)
    q0 = model.home()
    contacts = [PointContact(f) for f in feet]

    def both(dq, v, tau):
        phase = stance(TreeSystem(model, Constant(tau)), q0, contacts)
        q = model.integrate(q0, dq)
        return phase.acceleration(0.0, q, v), phase.multipliers(0.0, q, v)

    rng = np.random.default_rng(0)
    xs = [jnp.asarray(rng.normal(size=(batch, model.nv))) * s for s in (0.05, 1.0, 1.0)]
    J = jax.jit(jax.vmap(jax.jacfwd(both, argnums=(0, 1, 2))))
    start = time.perf_counter()
    jax.block_until_ready(J(*xs))
    compile_s = time.perf_counter() - start
    mbjax_s = _median(lambda: jax.block_until_ready(J(*xs))) / batch

    pm = r.model
    pd = pm.createData()
    models, datas, settings = pinocchio_point_contacts(pm, feet, 50.0)
    pin.initConstraintDynamics(pm, pd, models, datas)
    states = [(pin.integrate(pm, r.q0, 0.05 * rng.normal(size=pm.nv)), rng.normal(size=pm.nv),
               rng.normal(size=pm.nv)) for _ in range(batch)]

    def pinocchio():
        for q, v, tau in states:
            pin.constraintDynamics(pm, pd, q, v, tau, models, datas, settings)
            pin.computeConstraintDynamicsDerivatives(pm, pd, models, datas, settings)

    pin_s = _median(pinocchio) / batch
    return {"robot": robot, "nv": model.nv, "batch": batch, "mbjax_us": mbjax_s * 1e6,
            "pinocchio_us": pin_s * 1e6, "ratio": mbjax_s / pin_s, "compile_s": compile_s}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="+", default=list(ROBOTS))
    parser.add_argument("--batch", type=int, default=64)
    args = parser.parse_args()
    jax.config.update("jax_enable_x64", True)
    for robot in args.robots:
        print(json.dumps(run(robot, args.batch)), flush=True)


if __name__ == "__main__":
    main()
