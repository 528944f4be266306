"""Peer engines, built to match mbjax scenes, for benchmarks and cross-engine tests.

Each peer is optional: `available(name)` says whether it imports.
"""

import importlib.util

import numpy as np

MUJOCO_INTEGRATORS = ("Euler", "RK4", "implicit", "implicitfast")


def available(name: str) -> bool:
    return importlib.util.find_spec(name) is not None


def mujoco_heavy_top(mass: float, inertia_pivot, com, gravity: float, dt: float,
                     integrator: str = "RK4"):
    """The heavy top as a MuJoCo ball joint. MuJoCo takes the inertia about the centre of mass:
    J_com = J_pivot - m (|c|^2 I - c c^T). Returns (model, data)."""
    import mujoco

    c = np.asarray(com, dtype=float)
    J_com = np.asarray(inertia_pivot, dtype=float) - mass * (c @ c * np.eye(3) - np.outer(c, c))
    full = " ".join(f"{v:.17g}" for v in (J_com[0, 0], J_com[1, 1], J_com[2, 2],
                                           J_com[0, 1], J_com[0, 2], J_com[1, 2]))
    xml = f"""
    <mujoco>
      <option gravity="0 0 {-gravity:.17g}" timestep="{dt:.17g}" integrator="{integrator}"/>
      <worldbody>
        <body name="top">
          <joint type="ball" damping="0" armature="0"/>
          <inertial pos="{c[0]:.17g} {c[1]:.17g} {c[2]:.17g}" mass="{mass:.17g}" fullinertia="{full}"/>
        </body>
      </worldbody>
    </mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    return model, mujoco.MjData(model)


def mujoco_rollout(model, data, quat0, Omega0, nstep: int):
    """Roll the ball-joint model out for nstep steps from unit quaternion quat0 (w, x, y, z) and
    body angular velocity Omega0 (MuJoCo's ball-joint qvel is in the body frame), batched over
    leading dimensions of quat0 / Omega0. Returns (quat, Omega) at the end, each (batch, .)."""
    import mujoco
    from mujoco import rollout

    quat0 = np.atleast_2d(quat0)
    Omega0 = np.atleast_2d(Omega0)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    states = []
    for q, w in zip(quat0, Omega0, strict=True):
        mujoco.mj_resetData(model, data)
        data.qpos[:] = q
        data.qvel[:] = w
        state = np.empty(mujoco.mj_stateSize(model, spec))
        mujoco.mj_getState(model, data, state, spec)
        states.append(state)
    out, _ = rollout.rollout(model, data, np.array(states), nstep=nstep)
    final = out[:, -1]
    # FULLPHYSICS layout: time, qpos, qvel, ...
    return final[:, 1:1 + model.nq], final[:, 1 + model.nq:1 + model.nq + model.nv]
