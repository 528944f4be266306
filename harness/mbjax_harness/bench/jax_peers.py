"""JAX peer engines (jaxsim, adam-robotics) as pure forward-dynamics functions of a URDF.

Both peers load the same URDF file and are driven in Pinocchio's conventions, so their answers
compare entry for entry with `pinocchio.aba` on the model of `pinocchio.buildModelFromUrdf`:

* joint vectors q, v, tau are in Pinocchio's joint order (`joint_names(urdf_path)`; URDF mimic
  joints are independent joints, as Pinocchio loads them);
* gravity is (0, 0, -9.81) m/s^2, Pinocchio's default (adam's own default is -9.80665);
* floating base (`floating=True`): `fd(base_pose7, q, base_vel6, v, tau)` with
  base_pose7 = (x, y, z, qx, qy, qz, qw), the root link's pose in the world (Pinocchio's free-flyer
  q), base_vel6 = (linear, angular) velocity of the root link in its own frame (Pinocchio's
  free-flyer v), returning (6 + nv,): the time derivative of base_vel6 (Pinocchio's free-flyer
  acceleration, the body-frame spatial acceleration) followed by the joint accelerations.

URDF damping and friction are ignored by every engine here (as by `pinocchio.aba`). The returned
functions are pure JAX: jit, vmap and jax.grad go through both peers.
"""

import xml.etree.ElementTree as ET

import jax
import jax.numpy as jnp
import numpy as np

GRAVITY = 9.81


def _require(name: str, pip_name: str):
    import importlib

    try:
        return importlib.import_module(name)
    except ImportError as err:
        raise ImportError(f"the JAX peer {name!r} is not installed (pip install {pip_name})") from err


def joint_names(urdf_path: str) -> list[str]:
    """The movable joints of the URDF in Pinocchio's order (`buildModelFromUrdf`, fixed base)."""
    pin = _require("pinocchio", "pin")
    return list(pin.buildModelFromUrdf(str(urdf_path)).names[1:])


def _root_link(root: ET.Element) -> str:
    children = {j.find("child").attrib["link"] for j in root.findall("joint")}
    roots = [link.attrib["name"] for link in root.findall("link") if link.attrib["name"] not in children]
    if len(roots) != 1:
        raise ValueError(f"the URDF has {len(roots)} root links: {roots}")
    return roots[0]


def _floats(element, attribute: str, default: str) -> list[float]:
    text = element.attrib.get(attribute, default) if element is not None else default
    return [float(x) for x in text.split()]


def _origin(element) -> np.ndarray:
    """The 4x4 transform of a URDF <origin> (fixed-axis roll-pitch-yaw)."""
    origin = element.find("origin")
    xyz, (r, p, y) = _floats(origin, "xyz", "0 0 0"), _floats(origin, "rpy", "0 0 0")
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    T = np.eye(4)
    T[:3, :3] = [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                 [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                 [-sp, cp * sr, cp * cr]]
    T[:3, 3] = xyz
    return T


def _rod_model(urdf_path: str, floating: bool):
    """The URDF as a `rod.Model` in URDF frame convention, which jaxsim builds from directly.

    jaxsim's own URDF loading (`rod.Sdf.load`) converts URDF to SDF with Gazebo's `gz sdf`
    executable, which is not a Python package; this reads the URDF's kinematics and inertias
    instead (visuals and collisions are left out: forward dynamics has no use for them). jaxsim
    drops massless links, so a massless link hanging from a fixed joint is merged into its parent
    here (as `gz sdf` does), and a massless root of a fixed base (welded: its inertia plays no
    part) gets a unit mass; a massless link behind a movable joint is an error. jaxsim spells a
    fixed base as a fixed joint from `world` to the root link, added here."""
    import rod

    root = ET.parse(urdf_path).getroot()
    base = _root_link(root)
    inertials = {}
    for link in root.findall("link"):
        inertial = link.find("inertial")
        if inertial is not None and float(inertial.find("mass").attrib["value"]) > 0:
            I = inertial.find("inertia").attrib          # noqa: E741
            inertials[link.attrib["name"]] = rod.Inertial(
                mass=float(inertial.find("mass").attrib["value"]),
                pose=rod.Pose.from_transform(_origin(inertial), relative_to=link.attrib["name"]),
                inertia=rod.Inertia(**{k: float(I.get(k, 0.0)) for k in
                                       ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}))
    if not floating and base != "world" and base not in inertials:
        inertials[base] = rod.Inertial(mass=1.0, inertia=rod.Inertia(ixx=1, iyy=1, izz=1))
    joints = [dict(name=j.attrib["name"], type=j.attrib["type"],
                   parent=j.find("parent").attrib["link"], child=j.find("child").attrib["link"],
                   T=_origin(j), axis=j.find("axis"), limit=j.find("limit"))
              for j in root.findall("joint")]
    while True:     # merge massless fixed-joint children into their parents
        merge = next((j for j in joints if j["type"] == "fixed" and j["child"] not in inertials
                      and j["parent"] != "world"), None)
        if merge is None:
            break
        joints.remove(merge)
        for j in joints:
            if j["parent"] == merge["child"]:
                j["parent"], j["T"] = merge["parent"], merge["T"] @ j["T"]
    for j in joints:
        if j["type"] == "floating":
            raise ValueError("jaxsim: a URDF floating joint is not supported; use floating=True")
        if j["parent"] != "world" and j["child"] not in inertials:
            raise ValueError(f"jaxsim drops the massless link {j['child']!r}, moved by a joint")
    if not floating and base != "world":
        joints.append(dict(name="mbjax_world_weld", type="fixed", parent="world", child=base,
                           T=np.eye(4), axis=None, limit=None))
    rod_joints = [rod.Joint(
        name=j["name"], type=j["type"], parent=j["parent"], child=j["child"],
        pose=rod.Pose.from_transform(j["T"], relative_to="__model__" if j["parent"] == "world"
                                     else j["parent"]),
        axis=rod.Axis(   # fixed joints too: jaxsim hashes every joint's axis
            xyz=rod.Xyz(xyz=_floats(j["axis"], "xyz", "1 0 0")),
            limit=None if j["limit"] is None else rod.Limit(
                lower=float(j["limit"].attrib.get("lower", -1e9)),
                upper=float(j["limit"].attrib.get("upper", 1e9)))))
        for j in joints]
    parent_joint = {j["child"]: j["name"] for j in joints if j["parent"] != "world"}
    canonical = base if base != "world" else next(j["child"] for j in joints
                                                  if j["parent"] == "world")
    # The root link first (rod's canonical link); the others posed by their parent joint.
    links = [rod.Link(name=canonical, inertial=inertials[canonical])] + [
        rod.Link(name=name, inertial=inertial,
                 pose=rod.Pose(pose=[0.0] * 6, relative_to=parent_joint[name]))
        for name, inertial in inertials.items() if name != canonical]
    return rod.Model(name=root.attrib.get("name", "robot"), link=links, joint=rod_joints)


def _quat_xyzw_to_matrix(quat):
    x, y, z, w = quat / jnp.linalg.norm(quat)
    return jnp.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _transform(base_pose7):
    return (jnp.eye(4).at[:3, :3].set(_quat_xyzw_to_matrix(base_pose7[3:7]))
            .at[:3, 3].set(base_pose7[:3]))


def jaxsim_forward_dynamics(urdf_path: str, floating: bool):
    """jaxsim's ABA (`jaxsim.api.model.forward_dynamics_aba`) on the URDF.

    floating=False: `fd(q, v, tau) -> qdd` (nv,); the root link is welded to the world (jaxsim makes
    a model fixed-base only through a fixed joint to a `world` link, added here). floating=True:
    `fd(base_pose7, q, base_vel6, v, tau) -> (6 + nv,)`, see the module docstring; jaxsim runs in
    its body-fixed velocity representation, which is Pinocchio's free-flyer convention. Contacts
    play no part: `forward_dynamics_aba` takes only joint torques (and link forces, left zero).
    Joints are reordered between Pinocchio's order and jaxsim's (`model.joint_names()`).
    """
    _require("jaxsim", "jaxsim")
    import jaxsim.api as js
    from jaxsim import VelRepr

    names = joint_names(urdf_path)
    model = js.model.JaxSimModel.build_from_model_description(
        model_description=_rod_model(urdf_path, floating), considered_joints=names,
        gravity=GRAVITY)
    to_js = jnp.array([names.index(n) for n in model.joint_names()])   # jaxsim <- Pinocchio
    to_pin = jnp.argsort(to_js)                                          # Pinocchio <- jaxsim

    def accelerations(pose7, q, vel6, v, tau):
        data = js.data.JaxSimModelData.build(
            model=model, base_position=pose7[:3],
            base_quaternion=jnp.concatenate([pose7[6:7], pose7[3:6]]),   # jaxsim is (w, x, y, z)
            joint_positions=q[to_js], base_linear_velocity=vel6[:3],
            base_angular_velocity=vel6[3:], joint_velocities=v[to_js],
            velocity_representation=VelRepr.Body)
        base_acc, qdd = js.model.forward_dynamics_aba(model, data, joint_forces=tau[to_js])
        return base_acc, qdd[to_pin]

    if floating:
        def fd(base_pose7, q, base_vel6, v, tau):
            base_acc, qdd = accelerations(base_pose7, q, base_vel6, v, tau)
            return jnp.concatenate([base_acc, qdd])
    else:
        pose0, vel0 = jnp.array([0.0, 0, 0, 0, 0, 0, 1]), jnp.zeros(6)

        def fd(q, v, tau):
            return accelerations(pose0, q, vel0, v, tau)[1]
    return fd


def _unit_axes(urdf_path: str) -> str:
    """The URDF text with every joint axis normalized. Pinocchio and jaxsim normalize the axis;
    adam uses it as written, so an axis rounded to float32 (|axis| = 1 +- 1e-7) scales its motion
    subspace and shifts its accelerations by ~1e-7 relative."""
    root = ET.parse(urdf_path).getroot()
    for axis in root.iter("axis"):
        xyz = np.array(_floats(axis, "xyz", "1 0 0"))
        axis.set("xyz", " ".join(repr(float(x)) for x in xyz / np.linalg.norm(xyz)))
    return ET.tostring(root, encoding="unicode")


def _patch_adam_prismatic():
    """adam 0.5.0's `StdJoint.motion_subspace` stacks three 3-vectors of zeros under a prismatic
    axis (shape error); give it the (0, 0, 0) it means. Revolute and fixed joints are untouched."""
    from adam.model.std_factories.std_joint import StdJoint

    original = StdJoint.motion_subspace
    if getattr(original, "_mbjax_fixed", False):
        return

    def motion_subspace(self):
        if self.type != "prismatic":
            return original(self)
        z = self.math.zeros(1)
        return self.math.vertcat(self.axis[0], self.axis[1], self.axis[2], z, z, z)

    motion_subspace._mbjax_fixed = True
    StdJoint.motion_subspace = motion_subspace


def adam_forward_dynamics(urdf_path: str, floating: bool):
    """adam-robotics (`adam.jax.KinDynComputations`) forward dynamics on the URDF.

    adam models every robot as floating-base. floating=True uses its ABA (`KinDynComputations.aba`,
    body-fixed representation): `fd(base_pose7, q, base_vel6, v, tau) -> (6 + nv,)`, see the
    module docstring. floating=False: adam has no fixed-base ABA, so `fd(q, v, tau)` solves
    M_jj qdd = tau - h_j with the joint block of its floating-base mass matrix (CRBA) and bias
    force (RNEA) at an identity base pose and zero base velocity (a dense O(n^3) solve, not ABA).
    adam takes the joints in the order it is given, here Pinocchio's. Joint axes are normalized
    before adam reads the URDF (as Pinocchio and jaxsim do; adam would not), and adam 0.5.0's
    prismatic-joint motion subspace is patched (see `_patch_adam_prismatic`).
    """
    _require("adam", "adam-robotics[jax]")
    from adam.core.constants import Representations
    from adam.jax import KinDynComputations

    _patch_adam_prismatic()
    kd = KinDynComputations(_unit_axes(urdf_path), joint_names(urdf_path),
                            gravity=jnp.array([0.0, 0, -GRAVITY, 0, 0, 0]))
    kd.set_frame_velocity_representation(Representations.BODY_FIXED_REPRESENTATION)
    # adam pins its arrays to the reference array's device (`asarray(..., device=...)`), which
    # jax.vmap's batched tracers reject; with no device given, jax places them as usual.
    for math in (kd.rbdalgos.math, getattr(kd.rbdalgos.math, "factory", None)):
        if hasattr(math, "_device"):
            math._device = None

    if floating:
        def fd(base_pose7, q, base_vel6, v, tau):
            return kd.aba(_transform(base_pose7), q, base_vel6, v, tau)
    else:
        def fd(q, v, tau):
            H = jnp.eye(4)
            M = kd.mass_matrix(H, q)[6:, 6:]
            h = kd.bias_force(H, q, jnp.zeros(6), v)[6:]
            return jnp.linalg.solve(M, tau - h)
    return fd


def check_against_pinocchio(urdf_path: str, floating: bool = False, n_states: int = 5,
                             seed: int = 0) -> dict[str, float]:
    """Max over n_states random states of |a_peer - a_pin|_inf / max(|a_pin|_inf, 1) per peer,
    against `pinocchio.aba` (fixed base, or a free-flyer root when floating). States: q uniform in
    [-1, 1] (joints) with a random base pose, v and tau standard normal. A peer that does not
    import is reported as nan."""
    pin = _require("pinocchio", "pin")
    model = (pin.buildModelFromUrdf(str(urdf_path), pin.JointModelFreeFlyer()) if floating
             else pin.buildModelFromUrdf(str(urdf_path)))
    data = model.createData()
    nj = len(joint_names(urdf_path))
    rng = np.random.default_rng(seed)
    states = []
    for _ in range(n_states):
        q = rng.uniform(-1, 1, nj)
        v, tau = rng.standard_normal(model.nv), rng.standard_normal(nj)
        if floating:
            quat = rng.standard_normal(4)
            pose = np.concatenate([rng.standard_normal(3), quat / np.linalg.norm(quat)])
            qpin, taupin = np.concatenate([pose, q]), np.concatenate([np.zeros(6), tau])
            args = (pose, q, v[:6], v[6:], tau)
        else:
            qpin, taupin, args = q, tau, (q, v, tau)
        states.append((args, pin.aba(model, data, qpin, v, taupin).copy()))

    errors = {}
    for name, build in (("jaxsim", jaxsim_forward_dynamics), ("adam", adam_forward_dynamics)):
        try:
            fd = jax.jit(build(urdf_path, floating))
        except ImportError:
            errors[name] = float("nan")
            continue
        errors[name] = max(
            float(np.max(np.abs(np.asarray(fd(*map(jnp.asarray, args))) - ref))
                  / max(np.max(np.abs(ref)), 1.0))
            for args, ref in states)
    return errors


def frax_forward_dynamics(urdf_path: str, floating: bool):
    """frax's forward dynamics (`frax.Robot.forward_dynamics`: a dense CRBA, an RNEA and a
    Cholesky solve) on the URDF, fixed base: `fd(q, v, tau) -> qdd` (nv,) in Pinocchio's joint
    order (frax's gravity is 9.81 m/s^2 too)."""
    import warnings
    if floating:
        raise NotImplementedError("the frax adapter here is fixed-base")
    with warnings.catch_warnings():          # frax's advice on XLA flags, printed at import
        warnings.simplefilter("ignore")
        frax = _require("frax", "frax")
        robot = frax.Robot(str(urdf_path), joint_ordering=joint_names(urdf_path))

    def fd(q, v, tau):
        return robot.forward_dynamics(q, v, tau, None)
    return fd
