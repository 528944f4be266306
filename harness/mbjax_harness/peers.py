"""Peer engines, built to match mbjax scenes, for the benchmarks and the cross-engine tests (one
place for both): MuJoCo and exudyn scenes, and mbjax's coordinates in Pinocchio's order
(Crocoddyl's problems are in `mbjax_harness.crocoddyl`).

Each peer is optional: `available(name)` says whether it imports, `missing(name)` why not, in
the words a command's closing line and its records use ("unavailable: mujoco is not installed"),
`note(name, status)` in a figure's ("MuJoCo not installed: pip install mujoco").
"""

import importlib.util

import jax.numpy as jnp
import numpy as np


MUJOCO_INTEGRATORS = ("Euler", "RK4", "implicit", "implicitfast")


# the package that installs each peer, where its name differs from the module's
PIP_NAMES = {"pinocchio": "pin", "mujoco.mjx": "mujoco-mjx", "adam": "adam-robotics",
             "example_robot_data": "example-robot-data",
             "dm_control": "dm_control"}


def available(name: str) -> bool:
    """Whether module `name` (a peer, or a submodule such as "mujoco.mjx") can be imported; a
    module set to None in `sys.modules`, as tests do to hide one, cannot."""
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):          # a parent missing or hidden
        return False


# how figures and sentences name each peer
TITLES = {"mujoco": "MuJoCo", "pinocchio": "Pinocchio", "crocoddyl": "Crocoddyl",
          "mujoco.mjx": "MJX"}


def note(name: str, status: str) -> str:
    """Peer `name`'s status in a figure's or a sentence's words: "MuJoCo not installed: pip
    install mujoco" for a peer `missing` says is unavailable, else "MuJoCo <status>"."""
    title = TITLES.get(name, name)
    if status.startswith("unavailable"):
        return f"{title} not installed: pip install {PIP_NAMES.get(name, name)}"
    return f"{title} {status}"


def missing(name: str) -> str | None:
    """None when peer `name` imports, else a status saying so: "unavailable: mujoco is not
    installed" (`note` adds what to install)."""
    if available(name):
        return None
    return f"unavailable: {name} is not installed"


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


def _exudyn_solve(mbs, ts, dt: float, spectral_radius: float, absolute_tolerance: float) -> None:
    """exudyn's implicit generalized-alpha over [0, ts[-1]] at the fixed step dt, sensors kept
    every ts[1] - ts[0], Newton's absolute tolerance as given, nothing written to disk."""
    import exudyn as exu

    settings = exu.SimulationSettings()
    settings.timeIntegration.endTime = float(ts[-1])
    settings.timeIntegration.numberOfSteps = int(round(ts[-1] / dt))
    settings.timeIntegration.generalizedAlpha.spectralRadius = spectral_radius
    settings.timeIntegration.adaptiveStep = False
    settings.timeIntegration.newton.absoluteTolerance = absolute_tolerance
    settings.timeIntegration.verboseMode = 0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = float(ts[1] - ts[0])
    mbs.SolveDynamic(settings)


def exudyn_spin_up_beam(n_elements: int, dt: float, ts, *, length=10.0, E=7.0e10, A=4.0e-4,
                        I=2.0e-7, mass=12.0, T_s=15.0, omega_s=6.0,  # noqa: E741 (the paper's I)
                        spectral_radius=0.8):
    """Kane's spin-up beam (as `mbjax.scenes.spin_up_beam.reference`) in exudyn: n
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

    _exudyn_solve(mbs, ts, dt, spectral_radius, absolute_tolerance=1e-6)

    data = mbs.GetSensorStoredData(sensor)        # t, displacements (x, y, x', y') of the tip
    t = data[:, 0]
    th = np.array([theta(s) for s in t])
    deflection = -np.sin(th) * (length + data[:, 1]) + np.cos(th) * data[:, 2]
    return np.interp(ts, t, deflection)


def exudyn_slider_crank(n_elements: int, dt: float, ts, *, crank=6 * 0.0254, rod=12 * 0.0254,
                        diameter=0.25 * 0.0254, E=3.0e7 * 4.4482216152605 / 0.0254**2,
                        mass=0.1667 * 0.45359237, Omega=125.6, spectral_radius=0.8):
    """Anderson 1993's flexible slider-crank (as `mbjax.scenes.flexible_slider_crank.reference`) in
    exudyn: the rod as n `ObjectANCFCable2D` elements from P to Q, P's coordinates prescribed on
    the crank circle (two `CoordinateConstraint`s with offset user functions), Q's y held at 0
    (the massless slider), both slopes and Q's x free; started straight and unstrained with the
    rigid mechanism's velocities (at t = 0 a pure translation, P's velocity (-crank Omega, 0));
    implicit generalized-alpha at fixed step dt. Returns the midpoint deflection from the chord
    PQ [in], positive away from O at t = 0, at the times ts (multiples of ts[1] - ts[0])."""
    import exudyn as exu
    from exudyn.itemInterface import (CoordinateConstraint, MarkerNodeCoordinate,
                                      MarkerNodePosition, NodePoint2DSlope1, NodePointGround,
                                      ObjectANCFCable2D, SensorMarker, SensorNode)

    inch = 0.0254
    area, inertia = np.pi * diameter**2 / 4, np.pi * diameter**4 / 64
    p0 = np.array([0.0, crank])
    q0 = np.array([np.sqrt(rod**2 - crank**2), 0.0])
    u = (q0 - p0) / rod
    le = rod / n_elements
    v0 = np.array([-crank * Omega, 0.0])
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    nodes = [mbs.AddNode(NodePoint2DSlope1(referenceCoordinates=[*(p0 + i * le * u), *u],
                                           initialVelocities=[*v0, 0.0, 0.0]))
             for i in range(n_elements + 1)]
    for i in range(n_elements):
        mbs.AddObject(ObjectANCFCable2D(length=le, massPerLength=mass / rod,
                                        bendingStiffness=E * inertia, axialStiffness=E * area,
                                        nodeNumbers=[nodes[i], nodes[i + 1]]))
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()),
                                                coordinate=0))

    def prescribe(node, coordinate, displacement):
        marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[node], coordinate=coordinate))
        mbs.AddObject(CoordinateConstraint(
            markerNumbers=[ground, marker],
            offsetUserFunction=lambda mbs, t, item, offset: displacement(t)))

    prescribe(0, 0, lambda t: crank * np.cos(np.pi / 2 + Omega * t) - p0[0])
    prescribe(0, 1, lambda t: crank * np.sin(np.pi / 2 + Omega * t) - p0[1])
    prescribe(n_elements, 1, lambda t: 0.0)
    at = [mbs.AddMarker(MarkerNodePosition(nodeNumber=nodes[i])) for i in (0, n_elements)]
    sensors = [mbs.AddSensor(SensorMarker(markerNumber=m, storeInternal=True,
                                          outputVariableType=exu.OutputVariableType.Position))
               for m in at]
    mid = n_elements // 2 if n_elements % 2 == 0 else None
    if mid is None:
        raise ValueError("exudyn_slider_crank: n_elements must be even (the midpoint is a node)")
    sensors.append(mbs.AddSensor(SensorNode(nodeNumber=nodes[mid], storeInternal=True,
                                            outputVariableType=exu.OutputVariableType.Position)))
    mbs.Assemble()

    ts = np.asarray(ts, float)
    _exudyn_solve(mbs, ts, dt, spectral_radius, absolute_tolerance=1e-8)

    P, Q, M = (mbs.GetSensorStoredData(s) for s in sensors)
    t = P[:, 0]
    chord = Q[:, 1:3] - P[:, 1:3]
    chord /= np.linalg.norm(chord, axis=1, keepdims=True)
    d = np.sum((M[:, 1:3] - P[:, 1:3]) * np.stack([-chord[:, 1], chord[:, 0]], 1), axis=1)
    return np.interp(ts, t, d / inch)


def pinocchio_maps(model, pin_model):
    """(q -> Pinocchio q, v_index): mbjax dof i is Pinocchio dof v_index[i]. Joints are matched
    by name. Pinocchio's free flyer has q = (xyz, quaternion xyzw) and v = (v_local; omega_local),
    mbjax's (xyz, wxyz) and (omega; v); a continuous joint has q = (cos, sin) in Pinocchio."""
    v_index, q_parts = [], []
    nvs = np.bincount(model.dof_body(), minlength=model.n)        # each joint's velocities
    for k, kind in enumerate(model.joint_types):
        jid = pin_model.getJointId(model.joint_names[k])
        assert jid < pin_model.njoints, model.joint_names[k]
        iv, iq, nq = pin_model.idx_vs[jid], pin_model.idx_qs[jid], pin_model.nqs[jid]
        v_index += [iv + j for j in ((3, 4, 5, 0, 1, 2) if kind == "free" else range(nvs[k]))]
        q_parts.append((iq, nq, kind))

    # each joint's positions: its velocities, and one more where a quaternion stands for a
    # rotation's three (spherical and free joints)
    nqs = nvs + np.isin(model.joint_types, ("spherical", "free"))
    q_start = np.cumsum([0, *nqs])

    def to_pin(q):
        q = np.asarray(q)
        out = np.zeros(pin_model.nq)
        for k, (iq, nq, kind) in enumerate(q_parts):
            qk = q[q_start[k]:q_start[k + 1]]
            if kind == "free":
                qk = np.concatenate([qk[:3], qk[4:7], qk[3:4]])
            elif nq == 2:                                    # continuous: (cos, sin)
                qk = np.array([np.cos(qk[0]), np.sin(qk[0])])
            out[iq:iq + nq] = qk
        return out

    return to_pin, np.asarray(v_index)


def random_state(model, seed):
    """(q, v, tau) with q normalized, from `numpy.random.default_rng(seed)`."""
    rng = np.random.default_rng(seed)
    q = np.asarray(model.neutral()) + rng.normal(size=model.nq)
    q = np.asarray(model.normalize(jnp.asarray(q)))
    return q, rng.normal(size=model.nv), rng.normal(size=model.nv)


def pinocchio_point_contacts(pin_model, feet, kd: float):
    """Pinocchio's point contacts (`CONTACT_3D`, LOCAL_WORLD_ALIGNED) on the named frames, with
    the Baumgarte gains (0, kd) of Crocoddyl's contact models, their data and solver settings,
    initialised for `constraintDynamics` and `impulseDynamics`: (models, datas, settings)."""
    import pinocchio as pin

    models = []
    for foot in feet:
        frame = pin_model.frames[pin_model.getFrameId(foot)]
        model = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, pin_model, frame.parentJoint,
                                         frame.placement, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        model.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(0.0, kd))
        models.append(model)
    models = pin.StdVec_RigidConstraintModel(models)
    datas = pin.StdVec_RigidConstraintData([m.createData() for m in models])
    return models, datas, pin.ProximalSettings(1e-14, 1e-14, 1)
