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


def exudyn_spin_up_beam(n_elements: int, dt: float, ts, *, length=10.0, E=7.0e10, A=4.0e-4,
                        I=2.0e-7, mass=12.0, T_s=15.0, omega_s=6.0,  # noqa: E741 (the paper's I)
                        spectral_radius=0.8):
    """Kane's spin-up beam (as `mbjax.flex.references.spin_up_beam_reference`) in exudyn: n
    `ObjectANCFCable2D` elements along x, the root's position fixed and its slope direction
    prescribed by theta(t) through a `GenericJoint` (x, y and the rotation about z locked) with an
    offset user function, so the root's stretch stays free; implicit generalized-alpha at fixed
    step dt with spectral radius 0.8 (at 1, no numerical damping, Newton fails near t = 11-12 s
    at every step tried, 1e-2 ... 2e-3 s), Newton's absolute tolerance raised to 1e-6 N (with
    EA = 2.8e7 N the default 1e-10 stalls in round-off at the first step). Returns the tip deflection along the rotating y axis at the times ts
    (multiples of the sensor period ts[1] - ts[0])."""
    import exudyn as exu
    from exudyn.itemInterface import (GenericJoint, MarkerBodyRigid, NodePoint2DSlope1,
                                      ObjectANCFCable2D, ObjectGround, SensorNode)

    c = T_s / (2 * np.pi)

    def ramp(t):   # NumPy, not spin_up_theta's jnp: exudyn calls it per Newton iteration
        return omega_s / T_s * (t**2 / 2 + c**2 * (np.cos(t / c) - 1))

    def theta(t):
        return ramp(t) if t < T_s else ramp(T_s) + omega_s * (t - T_s)

    ts = np.asarray(ts, float)
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    le = length / n_elements
    nodes = [mbs.AddNode(NodePoint2DSlope1(referenceCoordinates=[i * le, 0.0, 1.0, 0.0]))
             for i in range(n_elements + 1)]
    cables = [mbs.AddObject(ObjectANCFCable2D(length=le, massPerLength=mass / length,
                                              bendingStiffness=E * I, axialStiffness=E * A,
                                              nodeNumbers=[nodes[i], nodes[i + 1]]))
              for i in range(n_elements)]
    ground = mbs.AddMarker(MarkerBodyRigid(bodyNumber=mbs.AddObject(ObjectGround())))
    root = mbs.AddMarker(MarkerBodyRigid(bodyNumber=cables[0], localPosition=[0.0, 0.0, 0.0]))
    mbs.AddObject(GenericJoint(markerNumbers=[ground, root], constrainedAxes=[1, 1, 0, 0, 0, 1],
                               offsetUserFunction=lambda mbs, t, item, p: [0, 0, 0, 0, 0, theta(t)]))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], storeInternal=True,
                                      outputVariableType=exu.OutputVariableType.Coordinates))
    mbs.Assemble()

    settings = exu.SimulationSettings()
    settings.timeIntegration.endTime = float(ts[-1])
    settings.timeIntegration.numberOfSteps = int(round(ts[-1] / dt))
    settings.timeIntegration.generalizedAlpha.spectralRadius = spectral_radius
    settings.timeIntegration.adaptiveStep = False
    settings.timeIntegration.newton.absoluteTolerance = 1e-6
    settings.timeIntegration.verboseMode = 0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = float(ts[1] - ts[0])
    mbs.SolveDynamic(settings)

    data = mbs.GetSensorStoredData(sensor)        # t, displacements (x, y, x', y') of the tip
    t = data[:, 0]
    th = np.array([theta(s) for s in t])
    deflection = -np.sin(th) * (length + data[:, 1]) + np.cos(th) * data[:, 2]
    return np.interp(ts, t, deflection)
